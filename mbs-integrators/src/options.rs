//! Options of a solve, and the choice of method.

use crate::error::{IntegratorError, Result};

/// The integration method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Semi-implicit (symplectic) Euler, first order, fixed step: `v ← v + h a(q, v)`,
    /// then `q ← q + h v`. Needs [`crate::OdeSystem::second_order_split`].
    SemiImplicitEuler,
    /// Classic fourth-order Runge–Kutta, fixed step.
    Rk4,
    /// Dormand–Prince 5(4) with PI step-size control, FSAL and 4th-order dense output
    /// (Hairer, Nørsett, Wanner, *Solving ODEs I*, §II.5 and §II.6). Fixed step if
    /// [`Options::fixed_step`] is set.
    DormandPrince54,
    /// TR-BDF2, the L-stable one-step method of Bank et al. (1985) with the error estimate
    /// and implementation of Hosea & Shampine (1996): a trapezoidal stage then a BDF2 stage
    /// sharing one iteration matrix, modified Newton with the Jacobian reused across steps,
    /// second order, for stiff problems (felt contact). Fixed step if
    /// [`Options::fixed_step`] is set. Its error control is per step, so on problems that do
    /// not damp errors the global error grows like `rtol^(2/3)`: ask for a tighter `rtol`
    /// than the accuracy wanted.
    TrBdf2,
    /// ROS34PW2, the Rosenbrock–W method of Rang & Angermann (2005): four linear solves
    /// with one matrix per step and no Newton iteration, third order with a second-order
    /// error estimate, L-stable and stiffly accurate; the Jacobian is kept across steps (a
    /// W-method keeps its order with any matrix) and taken again after a rejected step.
    /// Four evaluations per step: with the system's own Jacobian it needed about half
    /// TR-BDF2's evaluations on Robertson and van der Pol; with finite differences, which
    /// it takes more often than TR-BDF2 does, it saves less, and on the piano its strike
    /// times are less accurate at the same tolerances. Fixed step if
    /// [`Options::fixed_step`] is set.
    Ros34Pw2,
}

impl Method {
    /// Classical order of the method.
    pub fn order(self) -> usize {
        match self {
            Method::SemiImplicitEuler => 1,
            Method::Rk4 => 4,
            Method::DormandPrince54 => 5,
            Method::TrBdf2 => 2,
            Method::Ros34Pw2 => 3,
        }
    }

    /// Whether the method can control its step size.
    pub fn is_adaptive(self) -> bool {
        matches!(
            self,
            Method::DormandPrince54 | Method::TrBdf2 | Method::Ros34Pw2
        )
    }
}

/// Options of a solve, with sensible defaults.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Relative tolerance of the local error (adaptive methods).
    pub rtol: f64,
    /// Absolute tolerance of the local error (adaptive methods).
    pub atol: f64,
    /// First step size; chosen automatically (Hairer's estimate) when `None`.
    pub initial_step: Option<f64>,
    /// Smallest step size allowed; below it the solve fails. `None`: 1e-14 · max(1, |t|).
    pub min_step: Option<f64>,
    /// Largest step size allowed (also bounds how far apart two events of one switching
    /// function may be and still both be seen).
    pub max_step: f64,
    /// A fixed step size: required by the fixed-step methods, and turns error control off
    /// for the adaptive ones (useful to measure convergence, or for smooth
    /// finite-difference sensitivities). TR-BDF2 still solves its stages to a precision
    /// set by `rtol` and `atol`.
    pub fixed_step: Option<f64>,
    /// Maximum number of accepted steps.
    pub max_steps: usize,
    /// Output grid spacing: the solution is reported at `t0 + k · output_step`. `None`:
    /// reported at every accepted step.
    pub output_step: Option<f64>,
    /// Events are located to within this time (absolute).
    pub event_tolerance: f64,
    /// Switching functions are sampled this many times per step on the dense output, so
    /// two crossings of one function within a step are seen when they are at least a
    /// sub-interval apart.
    pub event_samples: usize,
    /// Step ends to follow (TR-BDF2 only; strictly ascending, finite, the last at or past
    /// the solve's end, else the solve is refused): every step ends at
    /// the next of them after its start (or at `t_end`), with error control off and the
    /// stages solved as with a fixed step; a step whose stages Newton cannot solve is
    /// tried again a quarter as long, towards the same end. Take them from an adaptive
    /// solve's [`crate::Solution::step_ends`] at nearby parameters: finite differences
    /// between solves on one mesh then see no step-size decision, only the parameters
    /// (Bock's internal numerical differentiation: H. G. Bock, "Numerical treatment of
    /// inverse problems in chemical reaction kinetics", *Modelling of Chemical Reaction
    /// Systems*, Springer 1981). The steps are as accurate as that solve's only while
    /// the motion stays close to its own.
    pub mesh: Option<std::sync::Arc<[f64]>>,
    /// Whether the solution records where each accepted step ended
    /// ([`crate::Solution::step_ends`], a mesh for [`Options::mesh`]); default false (like
    /// output points, they are stored, so a step that records one may allocate).
    pub record_steps: bool,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            atol: 1e-9,
            initial_step: None,
            min_step: None,
            max_step: f64::INFINITY,
            fixed_step: None,
            max_steps: 10_000_000,
            output_step: None,
            event_tolerance: 1e-12,
            event_samples: 4,
            mesh: None,
            record_steps: false,
        }
    }
}

impl Options {
    /// Options with the given tolerances.
    pub fn with_tolerances(rtol: f64, atol: f64) -> Self {
        Self {
            rtol,
            atol,
            ..Self::default()
        }
    }

    /// The same options with a fixed step.
    pub fn fixed(self, h: f64) -> Self {
        Self {
            fixed_step: Some(h),
            ..self
        }
    }

    /// The same options with an output grid.
    pub fn output_every(self, dt: f64) -> Self {
        Self {
            output_step: Some(dt),
            ..self
        }
    }

    /// Checks every option, naming the bad one.
    pub fn validate(&self, method: Method) -> Result<()> {
        let bad = |option: &'static str, message: String| {
            Err(IntegratorError::InvalidOption { option, message })
        };
        let positive = |x: f64| x.is_finite() && x > 0.0;
        if !positive(self.rtol) {
            return bad(
                "rtol",
                format!("must be positive and finite, got {}", self.rtol),
            );
        }
        if !(self.atol.is_finite() && self.atol >= 0.0) || (self.atol == 0.0 && self.rtol == 0.0) {
            return bad(
                "atol",
                format!("must be non-negative and finite, got {}", self.atol),
            );
        }
        if let Some(h) = self.initial_step
            && !positive(h)
        {
            return bad("initial_step", format!("must be positive, got {h}"));
        }
        if let Some(h) = self.min_step
            && !(h.is_finite() && h >= 0.0)
        {
            return bad("min_step", format!("must be non-negative, got {h}"));
        }
        if self.max_step.is_nan() || self.max_step <= 0.0 {
            return bad(
                "max_step",
                format!("must be positive, got {}", self.max_step),
            );
        }
        match self.fixed_step {
            Some(h) if !positive(h) => {
                return bad("fixed_step", format!("must be positive, got {h}"));
            }
            None if !method.is_adaptive() => {
                return bad(
                    "fixed_step",
                    format!("{method:?} is a fixed-step method: set fixed_step"),
                );
            }
            _ => {}
        }
        if let Some(mesh) = &self.mesh {
            if method != Method::TrBdf2 {
                return bad(
                    "mesh",
                    format!("{method:?} cannot follow a mesh (TR-BDF2 can)"),
                );
            }
            if self.fixed_step.is_some() {
                return bad("mesh", "set a mesh or a fixed step, not both".into());
            }
            if let Some(i) = mesh.iter().position(|t| !t.is_finite()) {
                return bad("mesh", format!("step end {i} is {}", mesh[i]));
            }
            if let Some(i) = mesh.windows(2).position(|w| w[1] <= w[0]) {
                return bad(
                    "mesh",
                    format!(
                        "step ends must be strictly ascending: {} then {} (at {})",
                        mesh[i],
                        mesh[i + 1],
                        i + 1
                    ),
                );
            }
        }
        if let Some(dt) = self.output_step
            && !positive(dt)
        {
            return bad("output_step", format!("must be positive, got {dt}"));
        }
        if !positive(self.event_tolerance) {
            return bad(
                "event_tolerance",
                format!("must be positive, got {}", self.event_tolerance),
            );
        }
        if self.event_samples == 0 {
            return bad("event_samples", "must be at least 1".into());
        }
        if self.max_steps == 0 {
            return bad("max_steps", "must be at least 1".into());
        }
        Ok(())
    }

    /// The minimum step at time `t`.
    pub(crate) fn h_min(&self, t: f64) -> f64 {
        self.min_step.unwrap_or(1e-14 * t.abs().max(1.0))
    }
}
