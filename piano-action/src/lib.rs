//! # piano-action: the grand piano action on the planar multibody framework
//!
//! The parameter set (one documented TOML file, embedded as the default, loaded with
//! errors that name the field, and refused when its geometry cannot work:
//! [`geometry_check`]); the three progressive models (simplified, single
//! escapement, double escapement) assembled from it as `mbs_core::System`s with their
//! joints, springs, pivot friction and felt contacts ([`Action`]); keystrokes
//! ([`simulate()`]) driven by a force on the key front (constant, ramp, table, release), a
//! prescribed key-front motion (with the hand's force reported), a finger touch (pressed
//! or struck, through a fingertip pad) or a mass dropped on the key, integrated with
//! TR-BDF2 from the action settled at rest, with the piano events (key start, let-off,
//! drop, string contact, key bottom, check, jack reset) and the strikes read off the
//! contact events; the regulation measured and regulated like a technician's
//! ([`regulation::measure`], [`regulation::regulate`]); the static touchweight
//! ([`touchweight::measure`]); the hammer swing test ([`pendulum`]); scenarios and run
//! directories with drawings to scale ([`scenario`], [`drawing`]); parallel sweeps over
//! touch levels ([`sweep`]); the interactive HTML report ([`report`]) and static figures
//! ([`plot`]); the validation against the literature ([`validate`]).
//!
#![warn(missing_docs)]

mod action;
pub mod describe;
pub mod drawing;
mod error;
#[doc(hidden)]
pub mod fuzzing;
pub mod geometry_check;
pub mod identify;
pub mod key;
pub mod measured;
pub mod mechanism_run;
pub mod param_paths;
pub mod params;
pub mod pendulum;
pub mod plot;
pub mod regulation;
pub mod report;
pub mod scenario;
pub mod simulate;
pub mod sound;
pub mod sweep;
pub mod toml_lines;
pub mod touchweight;
pub mod validate;

pub use action::{Action, ModelKind, Presser, integrate_system};
pub use drawing::action_svg;
pub use error::{InputError, InputKind, PianoError, Result};
pub use mbs_mechanism::ContactHandle;
pub use params::ActionParams;
pub use simulate::{
    BLOW_PULSE_GAP_S, Finger, Input, PianoEvent, Run, Strike, TouchStyle, simulate,
};

/// Mechanism descriptions (re-exported from `mbs-mechanism`): what an example or another
/// striking mechanism builds through this crate's public API.
pub use mbs_mechanism as mechanism;
