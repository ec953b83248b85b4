//! # mbs-contact (stub)
//!
//! **Not built yet.** This crate will hold the planar contact geometry (circles, lines,
//! segments, arcs and profiles made of them) with closed-form narrow phase in `f64`, the
//! normal and tangential constitutive laws (Kelvin–Voigt, Hertz, Hunt–Crossley,
//! Lankarani–Nikravesh, hysteretic felt, Stulov; regularized Coulomb, Stribeck), material
//! presets, and a contact force element for the [`mbs_core`] `System`.
//!
//! Until then it only re-exports the core so the workspace layout is in place.

#![warn(missing_docs)]

pub use mbs_core;
