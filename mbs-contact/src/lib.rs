//! # mbs-contact: contact geometry and constitutive laws
//!
//! The piano action's behaviour lives in its contacts: felt, buckskin, cloth and wood
//! pressed together, and the hammer felt on the string. This crate makes contacts a
//! pluggable part of the planar multibody framework:
//!
//! - [`geometry`]: circles, half-planes, segments and circular arcs (convex or concave),
//!   and profiles made of them, with the closed-form narrow phase of every pair in `f64`
//!   (signed gap, normal, nearest points);
//! - [`laws`]: normal laws (Kelvin–Voigt, Hertz, Hunt–Crossley, Lankarani–Nikravesh,
//!   hysteretic power-law felt, Stulov's hereditary felt) and friction laws;
//! - [`materials`]: presets with their sources;
//! - [`Contact`]: a force element for `mbs_core::System`, mapping contact forces to the
//!   bodies, with the gap as switching function for event location;
//! - [`string`]: a taut stiff string reduced to its modes ([`TautString`]) and
//!   [`StringContact`], a felt-covered striker against it (the hammer on a piano string),
//!   whose contact duration and rebound follow from the string's motion.

#![warn(missing_docs)]

mod element;
mod error;
pub mod geometry;
pub mod laws;
pub mod materials;
pub mod string;

pub use element::{Contact, ContactOutput, ContactSide};
pub use error::{ContactError, Result};
pub use geometry::{ArcSide, Proximity, Shape, proximity};
pub use string::{BridgeForceRenderer, StringContact, StringOutput, StringSpec, TautString};
