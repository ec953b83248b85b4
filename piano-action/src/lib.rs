//! # piano-action (stub)
//!
//! **Not built yet.** This crate will hold the grand piano action plugin: parameters, the
//! simplified, single- and double-escapement models, regulation, touches, events, metrics
//! and the `piano` command.
//!
//! Until then it only re-exports its dependencies so the workspace layout is in place.

#![warn(missing_docs)]

pub use mbs_contact;
pub use mbs_core;
pub use mbs_integrators;
