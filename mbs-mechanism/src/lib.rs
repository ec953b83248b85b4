//! Planar mechanisms as data.
//!
//! A [`Mechanism`] is a description, in TOML or JSON, of a planar mechanism: bodies on a
//! tree of joints (revolute, prismatic, fixed; stops; pivot friction), torsion and point
//! springs, cords that only pull, constant loads, contact pairs (circles, segments, arcs
//! and profiles on each side; a law by material preset or by parameters; friction),
//! strikers on modal strings, inputs, markers, named events and metrics. It is checked
//! ([`Mechanism::validate`], every error naming its field, and its file and line when read
//! from one) and built into an [`mbs_core::System`] ([`Mechanism::build`]). A description
//! can be transformed into another (module [`transform`]): a body split in two on a sprung
//! joint ([`Mechanism::split_body`]), a contact's side mounted on a compliant pivot
//! ([`Mechanism::mount_compliant`]), a contact's law or friction swapped
//! ([`Mechanism::swap_law`], [`Mechanism::swap_friction`]).
//!
//! This crate sits above `mbs-core` (bodies, joints, force elements) and `mbs-contact`
//! (shapes, laws, strings), which a description needs both of; neither of them knows the
//! other's file formats, and the piano action (or any striking mechanism) sits above it.
//!
//! ```
//! use mbs_mechanism::Mechanism;
//! let text = r#"
//! name = "pendulum on a stop"
//! gravity = [0.0, -9.81]
//!
//! [[bodies]]
//! name = "arm"
//! mass = 0.1
//! com = [0.05, 0.0]
//! inertia = 1e-4
//! joint = { kind = "revolute", at = [0.0, 0.0], limits = { lower = -1.0, stiffness = 100.0, damping = 0.1 } }
//!
//! [[markers]]
//! name = "tip"
//! at = { body = "arm", point = [0.1, 0.0] }
//! "#;
//! let m = Mechanism::from_toml_str(text).unwrap();
//! let built = m.build().unwrap();
//! assert_eq!(built.system.model().nv(), 1);
//! ```

#![warn(missing_docs)]

mod build;
pub mod description;
mod error;
mod io;
pub mod toml_lines;
pub mod transform;
mod validate;

pub use build::{Built, Extensions, NoExtensions, normal_law, shapes};
pub use description::*;
pub use error::{MechanismError, Result};
pub use io::Format;
pub use transform::{Flex, MassProps, Side, distal_contact_name, flex_spring_name};
pub use validate::material_names;
