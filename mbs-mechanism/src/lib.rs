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
//! This crate sits above `mbs-core` (bodies, joints, force elements), `mbs-contact`
//! (shapes, laws, strings) and `mbs-integrators` (to read events and metrics from a
//! solution): a description needs all of them, and none of them should know a file format
//! of another. The piano action, and any striking mechanism, sits above it.
//!
//! # Build your own mechanism
//!
//! 1. **Bodies and joints.** List the moving bodies, each with the joint that carries it
//!    (`[[bodies]]`, parents before children). A body's frame is its joint's frame: put
//!    the joint at the pivot (`joint.at`, in the parent's frame; the world's for a body on
//!    the ground) and give the centre of mass, the outline, the contact shapes and every
//!    point in that frame. Mass in kg, inertia about the centre of mass in kg·m².
//!    `limits` are stiff one-sided stops; `friction` is the pivot's regularised Coulomb
//!    friction. A tree only: close a loop (a four-bar, a jack in a notch) with a contact.
//! 2. **Springs.** `[[torsion_springs]]` on a joint (with a preload, as a pre-tensioned
//!    spring at its stop), `[[point_springs]]` between two points, `[[cords]]` that only
//!    pull (a tape: slack below its length).
//! 3. **Contacts.** `[[contacts]]` with a shape list on each side (`circle`, `segment` —
//!    its outward side on the left of `a → b` —, `arc` convex or concave, `profile`) and a
//!    law: a material preset (`law = { material = "action_felt" }`, see
//!    [`material_names`]) or explicit parameters (`felt`, `hertz`, `kelvin_voigt`,
//!    `hunt_crossley`, `stulov`), and friction. `[[strings]]` strike a modal string.
//! 4. **Inputs, markers, events, metrics.** Where a force or a prescribed motion drives it
//!    (`[[inputs]]`), named points (`[[markers]]`), named events (a contact's `onset` or
//!    `release`, a `coordinate` crossing a `value`) and metrics read at an event's first
//!    occurrence (a marker's `speed`, `x`, `y`, velocity, or the `time`).
//! 5. **Check, build, run.** [`Mechanism::load`] reads and checks a file;
//!    [`Mechanism::build`] gives a [`Built`] system; [`Built::drive_force`] applies an
//!    input; integrate with `mbs-integrators`; [`Mechanism::events_in`] and
//!    [`Mechanism::metrics_in`] read the solution. `piano simulate` runs a scenario with
//!    `mechanism = "FILE"` and writes a run directory, drawings and the report from it.
//!
//! Tag every number with where it comes from in the `note` fields (and in comments of a
//! TOML file): \[V\] read in a source, \[S\] secondhand, \[M\] recalled or judged, \[D\]
//! derived. The repository's `examples/mechanisms/glockenspiel.toml` is a complete small
//! description written by hand; the `upright-action` crate (`examples/upright`) writes an
//! upright piano action through the API from a sourced layout, its jack closing a four-bar
//! through two contacts; `piano describe` writes the grand action.
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
mod evaluate;
mod frame;
mod io;
pub mod toml_lines;
pub mod transform;
mod validate;

pub use build::{Built, ContactHandle, Extensions, NoExtensions, normal_law, shapes};
pub use description::*;
pub use error::{MechanismError, Result};
pub use evaluate::{EventOccurrence, MetricValue};
pub use frame::WorldFrame;
pub use io::Format;
pub use transform::{Flex, MassProps, Side, distal_contact_name, flex_spring_name};
pub use validate::material_names;
