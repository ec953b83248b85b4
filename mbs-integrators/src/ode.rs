//! The [`OdeSystem`] trait: what the integrators need of a system `ẏ = f(t, y)`.

use nalgebra::DMatrix;

use crate::error::SystemError;

pub use mbs_core::Crossing;

/// Where a switching function comes from in the system that declared it: for a multibody
/// system, the force element (its index in the `System`) and the function's index among
/// that element's own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EventSource {
    /// The element that raised it.
    pub element: usize,
    /// Its index among the element's switching functions.
    pub local: usize,
}

/// A first-order system `ẏ = f(t, y)` with optional Jacobian and switching functions.
///
/// Methods take `&mut self` so a system can keep its own workspace.
pub trait OdeSystem {
    /// Length of the state.
    fn len(&self) -> usize;

    /// Whether the state is empty.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Writes `f(t, y)` into `dy`.
    fn derivative(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError>;

    /// Whether [`OdeSystem::jacobian`] is implemented; otherwise the implicit method uses
    /// finite differences.
    fn has_jacobian(&self) -> bool {
        false
    }

    /// Writes `∂f/∂y` at `(t, y)` into `jac` (len × len). The columns of
    /// [`OdeSystem::states_outside_jacobian`] need not be written: the caller keeps them
    /// zero.
    fn jacobian(
        &mut self,
        _t: f64,
        _y: &[f64],
        _jac: &mut DMatrix<f64>,
    ) -> Result<(), SystemError> {
        Err(SystemError::new("this system has no analytic Jacobian"))
    }

    /// [`OdeSystem::jacobian`] when the caller also has `f = f(t, y)`, which a system may
    /// use rather than evaluate it again. Defaults to [`OdeSystem::jacobian`].
    fn jacobian_given_rate(
        &mut self,
        t: f64,
        y: &[f64],
        _f: &[f64],
        jac: &mut DMatrix<f64>,
    ) -> Result<(), SystemError> {
        self.jacobian(t, y, jac)
    }

    /// Ranges of states whose Jacobian columns the implicit method may take as zero without
    /// evaluating them: states whose rates move them only along directions that change no
    /// rate at a fixed time, so the part of the iteration matrix left out is nilpotent (at
    /// the Jacobian's time)
    /// (modal amplitudes in variation-of-constants form). None by default.
    fn states_outside_jacobian(&self) -> Vec<std::ops::Range<usize>> {
        Vec::new()
    }

    /// For a mechanical system whose state is `y = [q (n), v (n), others]` with `q̇ = v`:
    /// `Some(n)`. Needed by the semi-implicit (symplectic) Euler method.
    fn second_order_split(&self) -> Option<usize> {
        None
    }

    /// Number of switching functions.
    fn event_count(&self) -> usize {
        0
    }

    /// Writes the switching functions at `(t, y)` into `out` (length
    /// [`OdeSystem::event_count`]); an event happens where one crosses zero.
    fn events(&mut self, _t: f64, _y: &[f64], _out: &mut [f64]) -> Result<(), SystemError> {
        Ok(())
    }

    /// Which crossings of switching function `k` are events.
    fn event_direction(&self, _k: usize) -> Crossing {
        Crossing::Both
    }

    /// Where switching function `k` comes from (the element of a multibody system), if the
    /// system says.
    fn event_source(&self, _k: usize) -> Option<EventSource> {
        None
    }

    /// A name for switching function `k`, used in the event list.
    fn event_name(&self, k: usize) -> String {
        format!("event {k}")
    }
}
