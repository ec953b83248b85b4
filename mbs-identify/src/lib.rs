//! Identification against measured motion, for planar multibody models: what a tracked
//! experiment measured, read and checked so that a model can be calibrated against it and
//! its missing effects found (`identification.md` in the project's references).
//!
//! This crate knows nothing of pianos. It holds, so far, the **dataset** (schema version 1):
//! a directory with `dataset.json` (the camera, the tracked markers and the runs) and one
//! CSV of marker positions per run ([`Dataset::load`], [`Dataset::read_run`]). Every error
//! names the file, the line and the field ([`DatasetError`]); nothing panics on a bad file.

mod dataset;

pub use dataset::{Dataset, DatasetError, MarkerSpec, Role, RunData, RunSpec, SCHEMA_VERSION};
