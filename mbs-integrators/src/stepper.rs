//! What every method provides to the driver: one accepted step at a time, and dense output
//! over the last step.

use crate::error::{IntegratorError, Result};
use crate::ode::OdeSystem;
use crate::options::Options;
use crate::solution::Stats;

/// One method's stepping state.
pub(crate) trait Stepper {
    /// Starts (or restarts, after an event) at `(t, y)`.
    fn start(&mut self, sys: &mut dyn OdeSystem, t: f64, y: &[f64], st: &mut Stats) -> Result<()>;
    /// Takes one accepted step, not beyond `t_max`.
    fn step(&mut self, sys: &mut dyn OdeSystem, t_max: f64, st: &mut Stats) -> Result<()>;
    /// Start of the last step.
    fn t_prev(&self) -> f64;
    /// Current time (end of the last step).
    fn t(&self) -> f64;
    /// Current state.
    fn y(&self) -> &[f64];
    /// The dense-output state at `t` in `[t_prev, t]`.
    fn interpolate(&self, t: f64, out: &mut [f64]);
    /// A copy of its whole state, to go on from later ([`crate::Checkpoint`]); `None` for
    /// a method that does not offer it.
    fn boxed_clone(&self) -> Option<Box<dyn Stepper + Send + Sync>> {
        None
    }
}

/// Evaluates the derivative, counting it and naming the time of a failure. Returns
/// `Ok(false)` when the result is not finite (the caller may retry with a smaller step).
pub(crate) fn eval(
    sys: &mut dyn OdeSystem,
    t: f64,
    y: &[f64],
    dy: &mut [f64],
    st: &mut Stats,
) -> Result<bool> {
    st.derivative_evals += 1;
    sys.derivative(t, y, dy)
        .map_err(|source| IntegratorError::System { t, source })?;
    Ok(dy.iter().all(|v| v.is_finite()))
}

/// The first non-finite component of `y`, as an error at time `t`.
pub(crate) fn non_finite(t: f64, y: &[f64]) -> IntegratorError {
    let (index, value) = y
        .iter()
        .copied()
        .enumerate()
        .find(|(_, v)| !v.is_finite())
        .unwrap_or((0, f64::NAN));
    IntegratorError::NonFiniteState { t, index, value }
}

/// Tolerances and step limits, taken from the options.
#[derive(Clone, Debug)]
pub(crate) struct Control {
    pub rtol: f64,
    pub atol: f64,
    pub h_init: Option<f64>,
    pub h_max: f64,
    pub fixed: Option<f64>,
    /// Step ends to follow ([`Options::mesh`]).
    pub mesh: Option<std::sync::Arc<[f64]>>,
    opts: Options,
}

impl Control {
    pub fn new(opts: &Options) -> Self {
        Self {
            rtol: opts.rtol,
            atol: opts.atol,
            h_init: opts.initial_step,
            h_max: opts.max_step,
            fixed: opts.fixed_step,
            mesh: opts.mesh.clone(),
            opts: opts.clone(),
        }
    }

    /// Whether steps are chosen without an error estimate (a fixed step or a mesh).
    pub fn unchecked(&self) -> bool {
        self.fixed.is_some() || self.mesh.is_some()
    }

    /// On a mesh, the step from `t` to its next end after `t` (or to `t_max`).
    pub fn mesh_step(&self, t: f64, t_max: f64) -> Option<f64> {
        let mesh = self.mesh.as_ref()?;
        // An end within round-off of `t` is the one just reached.
        let reached = t + 1e-12 * t.abs().max(1e-3);
        let next = mesh[mesh.partition_point(|&e| e <= reached)..]
            .first()
            .map_or(t_max, |&e| e.min(t_max));
        Some(next - t)
    }

    pub fn h_min(&self, t: f64) -> f64 {
        self.opts.h_min(t)
    }

    /// Weighted RMS norm of an error vector (Hairer):
    /// `sqrt(mean((e_i / (atol + rtol max(|y0_i|, |y1_i|)))²))`.
    pub fn error_norm(&self, err: &[f64], y0: &[f64], y1: &[f64]) -> f64 {
        let n = err.len().max(1) as f64;
        let s: f64 = err
            .iter()
            .zip(y0.iter().zip(y1))
            .map(|(e, (a, b))| {
                let sc = self.atol + self.rtol * a.abs().max(b.abs());
                (e / sc) * (e / sc)
            })
            .sum();
        (s / n).sqrt()
    }

    /// [`Control::error_norm`] of a step from `y0` to `y1`, the mean taken over the
    /// components that moved or carry an error: states frozen through the step (a
    /// string's modal amplitudes between strikes) do not dilute the others' error.
    pub fn step_error_norm(&self, err: &[f64], y0: &[f64], y1: &[f64]) -> f64 {
        self.step_error_norm_over(0..err.len(), err, y0, y1)
    }

    /// [`Control::step_error_norm`] over the components `live` alone (ascending), for
    /// callers that know the others are frozen: with every other component's error zero
    /// and its value unchanged, the same terms are added in the same order, so the norm
    /// is the same to the bit.
    pub fn step_error_norm_at(&self, live: &[usize], err: &[f64], y0: &[f64], y1: &[f64]) -> f64 {
        self.step_error_norm_over(live.iter().copied(), err, y0, y1)
    }

    fn step_error_norm_over(
        &self,
        indices: impl Iterator<Item = usize>,
        err: &[f64],
        y0: &[f64],
        y1: &[f64],
    ) -> f64 {
        let mut n = 0usize;
        let s: f64 = indices
            .map(|i| (err[i], (y0[i], y1[i])))
            .filter(|(e, (a, b))| *e != 0.0 || a != b)
            .map(|(e, (a, b))| {
                n += 1;
                let sc = self.atol + self.rtol * a.abs().max(b.abs());
                (e / sc) * (e / sc)
            })
            .sum();
        (s / n.max(1) as f64).sqrt()
    }

    /// Hairer's automatic first step for a method of order `order`.
    pub fn initial_step(
        &self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        f0: &[f64],
        order: usize,
        st: &mut Stats,
    ) -> Result<f64> {
        if let Some(h) = self.h_init {
            return Ok(h.min(self.h_max));
        }
        let zeros = vec![0.0; y.len()];
        let d0 = self.error_norm(y, &zeros, y);
        let d1 = self.error_norm(f0, &zeros, y);
        let h0 = if d0 < 1e-5 || d1 < 1e-5 {
            1e-6
        } else {
            0.01 * d0 / d1
        }
        .min(self.h_max);
        let y1: Vec<f64> = y.iter().zip(f0).map(|(a, b)| a + h0 * b).collect();
        let mut f1 = vec![0.0; y.len()];
        if !eval(sys, t + h0, &y1, &mut f1, st)? {
            return Ok(h0 * 1e-3);
        }
        let df: Vec<f64> = f1.iter().zip(f0).map(|(a, b)| (a - b) / h0).collect();
        let d2 = self.error_norm(&df, &zeros, y);
        let h1 = if d1.max(d2) <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / d1.max(d2)).powf(1.0 / (order as f64 + 1.0))
        };
        Ok((100.0 * h0).min(h1).min(self.h_max).max(self.h_min(t)))
    }
}

/// Cubic Hermite interpolation on `[t0, t0 + h]` through `(y0, f0)` and `(y1, f1)`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn hermite(
    t0: f64,
    h: f64,
    y0: &[f64],
    f0: &[f64],
    y1: &[f64],
    f1: &[f64],
    t: f64,
    out: &mut [f64],
) {
    if h == 0.0 {
        out.copy_from_slice(y1);
        return;
    }
    let s = (t - t0) / h;
    let (s2, s3) = (s * s, s * s * s);
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    for i in 0..out.len() {
        out[i] = h00 * y0[i] + h * h10 * f0[i] + h01 * y1[i] + h * h11 * f1[i];
    }
}

/// The step actually taken towards `t_max`: `h`, or what is left when that is within a
/// millionth of `h` (so no sliver step remains, even after the round-off of many fixed
/// steps has accumulated in `t`).
pub(crate) fn clip_step(t: f64, h: f64, t_max: f64) -> (f64, bool) {
    let left = t_max - t;
    if h >= left * (1.0 - 1e-6) {
        (left, true)
    } else {
        (h, false)
    }
}
