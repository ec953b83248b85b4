//! Identification against measured motion, for planar multibody models: what a tracked
//! experiment measured, read and checked so that a model can be calibrated against it and
//! its missing effects found (`identification.md` in the project's references).
//!
//! This crate knows nothing of pianos. It holds, so far, the **dataset** (schema version 1):
//! a directory with `dataset.json` (the camera, the tracked markers and the runs) and one
//! CSV of marker positions per run ([`Dataset::load`], [`Dataset::read_run`]). Every error
//! names the file, the line and the field ([`DatasetError`]); nothing panics on a bad file.
//! And the **camera**'s measurement model: a frame averages the motion over its exposure,
//! shifted by the camera's unknown clock offset ([`Camera`]). The calibration's optimiser
//! is [`lm`], the noise model [`noise`], whether a model explains the data to the noise
//! [`explain`] (with the χ² tail it needs in [`stats`]), and [`work`] counts a job's fits and simulations
//! per stage and reports their rates.

mod camera;
mod dataset;
mod effect;
pub mod explain;
pub mod lm;
pub mod noise;
mod rng;
pub mod stats;
pub mod work;

pub use camera::Camera;
pub use dataset::{Dataset, DatasetError, MarkerSpec, Role, RunData, RunSpec, SCHEMA_VERSION};
pub use effect::{EffectParam, EffectSpec};
pub use rng::Rng;
