//! # mbs-integrators: ODE integrators with exact event location
//!
//! The piano action is stiff and event-driven: felt contacts open and close, the jack
//! escapes, the hammer strikes for a few milliseconds and is caught. This crate integrates
//! any [`OdeSystem`] (`ẏ = f(t, y)` with optional Jacobian and switching functions) with
//!
//! - [`Method::SemiImplicitEuler`] (symplectic, first order) and [`Method::Rk4`], fixed step;
//! - [`Method::DormandPrince54`], adaptive 5(4) with PI control and dense output;
//! - [`Method::TrBdf2`], L-stable, for stiff problems, with the Jacobian (analytic or by
//!   finite differences) reused across steps;
//!
//! locates events on the dense output (bracketing and Illinois refinement to a time
//! tolerance), lets a handler record, stop or reset the state at each one, reports the
//! solution on a uniform grid, and counts its work. Failures (step size below the minimum,
//! non-finite state, Newton failure) are errors that say when and why.
//!
//! A TR-BDF2 solve can keep [`Checkpoint`]s ([`solve_checkpointed`]) and go on from one
//! with another system ([`resume`]): where the two agree on everything the first was
//! evaluated at before the checkpoint (a contact whose laws have not acted yet, say), the
//! result is the other's own solve, to the last bit, for the cost of what follows it.
//!
//! [`MultibodyOde`] runs an `mbs_core::System`; its events name the element that raised them
//! ([`Event::source`]) and, like every event, the way they crossed ([`Event::direction`],
//! the core's [`Crossing`]: one crossing type for the core and the integrators).
//!
//! ```
//! use mbs_integrators::{Crossing, EventAction, Method, OdeSystem, Options, SystemError,
//!                       solve_with_events};
//! /// A ball falling from 1 m that bounces with restitution 0.5.
//! struct Ball;
//! impl OdeSystem for Ball {
//!     fn len(&self) -> usize { 2 }
//!     fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
//!         dy[0] = y[1];
//!         dy[1] = -9.81;
//!         Ok(())
//!     }
//!     fn event_count(&self) -> usize { 1 }
//!     fn events(&mut self, _t: f64, y: &[f64], g: &mut [f64]) -> Result<(), SystemError> {
//!         g[0] = y[0];
//!         Ok(())
//!     }
//!     fn event_direction(&self, _k: usize) -> Crossing { Crossing::Falling }
//! }
//! let opts = Options::with_tolerances(1e-10, 1e-12);
//! let sol = solve_with_events(&mut Ball, Method::DormandPrince54, 0.0, &[1.0, 0.0], 1.0, &opts,
//!     &mut |_, y| { y[1] = -0.5 * y[1]; EventAction::Reset }).unwrap();
//! let first = (2.0 / 9.81f64).sqrt();
//! assert!((sol.events[0].time - first).abs() < 1e-9);
//! ```

#![warn(missing_docs)]
// Numerical kernels index several arrays by the same counter.
#![allow(clippy::needless_range_loop)]

mod dopri5;
mod driver;
mod error;
mod explicit;
mod interrupt;
mod jacobian;
mod linalg;
mod multibody;
mod ode;
mod options;
pub mod problems;
mod rosenbrock;
mod solution;
mod stepper;
mod trbdf2;

pub use driver::{
    Checkpoint, resume, solve, solve_checkpointed, solve_observed, solve_with_events,
};
pub use error::{IntegratorError, Result, SystemError};
pub use interrupt::with_interrupt_check;
pub use multibody::MultibodyOde;
pub use ode::{Crossing, EventSource, OdeSystem};
pub use options::{Method, Options};
pub use solution::{Event, EventAction, Solution, Stats, Termination};
