//! # mbs-integrators (stub)
//!
//! **Not built yet.** This crate will hold the ODE integrators of the framework:
//! semi-implicit Euler, RK4, Dormand–Prince 5(4) with dense output, an L-stable implicit
//! method for stiff felt contact, and exact event location on dense output.
//!
//! Until then it only re-exports the core so the workspace layout is in place.

#![warn(missing_docs)]

pub use mbs_core;
