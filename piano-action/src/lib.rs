//! # piano-action: the grand piano action on the planar multibody framework
//!
//! **In progress.** Built so far: the parameter set (one documented TOML file, embedded as
//! the default, loaded with errors that name the field) and the three progressive models
//! (simplified, single escapement, double escapement) assembled from it as
//! `mbs_core::System`s with their joints, springs, pivot friction and felt contacts.
//! Regulation, inputs and touches, events and metrics, and the `piano` command are still to
//! come.

#![warn(missing_docs)]

mod action;
mod error;
pub mod params;

pub use action::{Action, ModelKind};
pub use error::{PianoError, Result};
pub use params::ActionParams;
