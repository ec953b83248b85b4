//! # mbs-core: the planar multibody core
//!
//! A planar rigid multibody library in the style of Pinocchio and RBDL, specialised to the
//! plane: spatial vectors have three components (`[ω, vx, vy]`, `[n, fx, fy]`), transforms
//! are stored as `(cos θ, sin θ, x, y)`, and every joint has one plain coordinate (an angle
//! or a displacement), so no Lie-group machinery is needed.
//!
//! - [`ModelBuilder`] (petgraph inside) or a JSON [`ModelDescription`] gives an immutable
//!   [`Model`]: a forest of bodies on the ground with revolute, prismatic (any in-plane axis)
//!   and fixed joints (merged into the parent), bodies in topological order.
//! - [`Data`] is the preallocated workspace; the algorithms are free functions over
//!   `(&Model, &mut Data, …)` and allocate nothing: [`rnea`] (inverse dynamics, with
//!   external forces in [`rnea_with_forces`]), [`crba`] (mass matrix), [`aba`] (forward
//!   dynamics), [`forward_dynamics_crba`] (CRBA + tree-sparse Cholesky),
//!   [`hybrid_dynamics`] (prescribed coordinates), [`nonlinear_effects`],
//!   [`gravity_torque`], energies, forward kinematics and point Jacobians.
//! - [`System`] gathers a model, [`ForceElement`]s (springs, pivot friction, applied loads,
//!   and contacts from `mbs-contact`) and prescribed coordinates ([`Drive`]s), and gives the
//!   derivative of `x = [q, v, internal states]` for an integrator.
//!
//! Conventions: SI units; world x to the right, y up, angles counter-clockwise; poses named
//! with their frames (`x_wb`: pose of body b in world).
//!
//! ```
//! use mbs_core::{Data, Model, aba, crba, rnea};
//! // A double pendulum of unit rods, from its JSON description.
//! let json = r#"{"gravity": [0.0, -9.81], "joints": [
//!   {"name": "upper", "parent": null, "kind": "revolute",
//!    "placement": {"angle": 0.0, "x": 0.0, "y": 0.0},
//!    "body": {"mass": 1.0, "com": [0.5, 0.0], "inertia": 0.08333333333333333}},
//!   {"name": "lower", "parent": "upper", "kind": "revolute",
//!    "placement": {"angle": 0.0, "x": 1.0, "y": 0.0},
//!    "body": {"mass": 1.0, "com": [0.5, 0.0], "inertia": 0.08333333333333333}}]}"#;
//! let model = Model::from_json_str(json)?;
//! let mut data = Data::new(&model);
//! let (q, v, a) = ([0.3, -0.2], [1.0, 0.5], [0.2, -0.1]);
//! let tau = rnea(&model, &mut data, &q, &v, &a)?.clone();
//! // Forward dynamics undoes inverse dynamics.
//! let qdd = aba(&model, &mut data, &q, &v, tau.as_slice())?;
//! assert!((qdd[0] - a[0]).abs() < 1e-12 && (qdd[1] - a[1]).abs() < 1e-12);
//! // The mass matrix is symmetric.
//! let m = crba(&model, &mut data, &q)?;
//! assert_eq!(m[(0, 1)], m[(1, 0)]);
//! # Ok::<(), mbs_core::CoreError>(())
//! ```

#![warn(missing_docs)]
// The algorithms index per-body arrays by body number, as the textbook recursions do.
#![allow(clippy::needless_range_loop)]

mod aba;
pub mod alloc_count;
pub mod benchmarks;
mod builder;
pub mod check;
mod crba;
mod data;
mod description;
pub mod elements;
mod energy;
mod error;
mod force;
#[doc(hidden)]
pub mod fuzzing;
pub mod inspect;
mod jacobian;
mod kinematics;
mod layout;
mod load_jacobian;
mod model;
mod rnea;
pub mod spatial;
mod system;
pub mod time_function;
mod trig;

pub use aba::{Prescribed, aba, aba_with_forces, hybrid_dynamics};
pub use builder::{BodySpec, JointKind, ModelBuilder, Placement};
pub use crba::{crba, forward_dynamics_crba};
pub use data::Data;
pub use description::{
    BodyDescription, JointDescription, JointKindName, ModelDescription, PlacementDescription,
};
pub use energy::{kinetic_energy, mechanical_energy, potential_energy};
pub use error::{CoreError, Result};
pub use force::{Crossing, ForceContext, ForceElement, Loads};
pub use jacobian::{frame_jacobian, point_jacobian};
pub use kinematics::{
    angular_velocity, forward_kinematics, forward_kinematics_acc, frame_point, frame_pose,
    point_acceleration, point_position, point_velocity, update_poses,
};
pub use load_jacobian::{LoadJacobian, Wrt, central_difference};
pub use model::{BodyId, Frame, FrameId, JointType, Model};
pub use rnea::{gravity_torque, nonlinear_effects, rnea, rnea_with_forces};
pub use spatial::{Force, Inertia, Motion, Transform};
pub use system::{Energy, System, Workspace};
pub use time_function::{Drive, DriveState, TimeFunction};
