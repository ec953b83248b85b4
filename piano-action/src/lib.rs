//! # piano-action: the grand piano action on the planar multibody framework
//!
//! **In progress.** Built so far: the parameter set (one documented TOML file, embedded as
//! the default, loaded with errors that name the field); the three progressive models
//! (simplified, single escapement, double escapement) assembled from it as
//! `mbs_core::System`s with their joints, springs, pivot friction and felt contacts;
//! keystrokes driven by a force on the key front, by a prescribed key-front motion (with
//! the hand's force reported) or by a mass dropped on the key, integrated with TR-BDF2, with
//! the piano events (let-off, string contact, key bottom, check, drop) and the strikes read
//! off the contact events; the regulation measured and regulated into the literature bands
//! ([`regulation::measure`], [`regulation::regulate`]); the static touchweight
//! ([`touchweight::measure`]); the hammer swing test ([`pendulum`]); scenarios and run
//! directories ([`scenario`]). Finger touches, drawings and `piano sweep` are still to
//! come.
//!
#![warn(missing_docs)]

mod action;
mod error;
pub mod params;
pub mod pendulum;
pub mod regulation;
pub mod scenario;
pub mod simulate;
pub mod sweep;
pub mod touchweight;

pub use action::{Action, ModelKind, Presser};
pub use error::{PianoError, Result};
pub use params::ActionParams;
pub use simulate::{Finger, Input, PianoEvent, Run, Strike, TouchStyle, simulate};
