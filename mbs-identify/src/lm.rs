//! Bounded Levenberg–Marquardt least squares with a finite-difference Jacobian and the
//! covariance of the estimate: the optimiser of output-error calibration.
//!
//! Minimises `S(x) = Σ rₗ(x)²` over a box `lower ≤ x ≤ upper`, where `r` is a vector of
//! already standardised residuals (a simulation compared with a measurement, N of them)
//! and `x` a handful of parameters. A residual evaluation is expensive (a simulation), so
//! the method counts them: a Jacobian costs k (forward) or 2k (central) evaluations, run on
//! several threads, and a rejected trial costs one evaluation and no Jacobian (with secant
//! updates, one on an updated Jacobian costs a Jacobian of finite differences as well).
//!
//! Each parameter moves in its internal coordinate `z` (`z = x`, or `z = ln x` on a log
//! scale), measured in units of its `typical` size: `u = z / typical`. One iteration:
//!
//! - `J = ∂r/∂u` by finite differences, stepping inward at a bound;
//! - the free set: parameters not held at a bound by the gradient `g = Jᵀr`;
//! - the damped Gauss–Newton step on the free set, `(JᵀJ + λ D) δ = −g`, with `D` the
//!   running maximum of diag(JᵀJ), floored (Marquardt 1963; Moré 1978), solved by
//!   Cholesky; the trial point is the step projected onto the box;
//! - a trial is accepted when `S` decreases; λ follows Nielsen's rule (Madsen, Nielsen &
//!   Tingleff 2004, *Methods for non-linear least squares problems*, §3.2): on acceptance
//!   `λ ← λ·max(1/3, 1 − (2ρ − 1)³)` with `ρ` the ratio of actual to predicted decrease,
//!   on rejection `λ ← λ·ν, ν ← 2ν`.
//!
//! With [`LmOptions::secant`] an accepted step updates `J` by Broyden's rank-one formula
//! instead of new finite differences, while the update is trusted (§3.5 of the same; see
//! the option).
//!
//! At the optimum the covariance is `s² (JᵀJ)⁻¹` with `s² = S / (N − k)`, mapped from
//! internal to physical units by the delta method.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread;

use nalgebra::{DMatrix, DVector, SymmetricEigen};
use serde::{Deserialize, Serialize};

/// How a parameter is moved by the solver.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Scale {
    /// In its own units: the internal coordinate is `z = x`.
    Linear,
    /// On a log scale: the internal coordinate is `z = ln x` (needs `lower > 0`). For
    /// positive parameters that may span decades, such as a rate or a velocity scale.
    Log,
}

/// A parameter the solver moves, with its box and scale.
///
/// ```
/// use mbs_identify::lm::{FreeParam, Scale};
/// let offset = FreeParam::linear("offset_s", 0.0, -2e-3, 2e-3, 1e-4);
/// let rate = FreeParam::log("rate_1_s", 0.1, 1e-6, 10.0);
/// assert_eq!(rate.scale, Scale::Log);
/// assert_eq!(offset.typical, 1e-4);
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FreeParam {
    /// Its name, used in errors.
    pub name: String,
    /// The starting value (physical units, within the bounds).
    pub start: f64,
    /// The lower bound (physical units, finite; `> 0` on a log scale).
    pub lower: f64,
    /// The upper bound (physical units, finite, `> lower`).
    pub upper: f64,
    /// How the solver moves it.
    pub scale: Scale,
    /// Typical size of the parameter in its internal (solver) coordinate, used for the
    /// finite-difference step and for the initial damping scale: e.g. 1e-4 for a time
    /// offset in seconds (Linear), 1.0 for Log.
    pub typical: f64,
}

impl FreeParam {
    /// A parameter moved in its own units, with its typical size.
    pub fn linear(
        name: impl Into<String>,
        start: f64,
        lower: f64,
        upper: f64,
        typical: f64,
    ) -> Self {
        Self {
            name: name.into(),
            start,
            lower,
            upper,
            scale: Scale::Linear,
            typical,
        }
    }

    /// A positive parameter moved on a log scale (typical size 1 in `ln x`).
    pub fn log(name: impl Into<String>, start: f64, lower: f64, upper: f64) -> Self {
        Self {
            name: name.into(),
            start,
            lower,
            upper,
            scale: Scale::Log,
            typical: 1.0,
        }
    }
}

/// Settings of [`levenberg_marquardt`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LmOptions {
    /// The most accepted steps (default 40).
    pub max_iterations: usize,
    /// Stop when the cost can decrease by less than this, relative to the sum of squares
    /// S: the Gauss–Newton model's best gain, or both the actual and the predicted
    /// decrease of an accepted step (default 1e-6). With N standardised residuals S ≈ N,
    /// so the optimum is located to about √(tolerance·N) standard deviations (0.2 at the
    /// default for N = 50 000): lower it for long records.
    pub cost_tolerance: f64,
    /// Stop when the step is shorter than this, in units of `typical` (default 1e-6).
    pub step_tolerance: f64,
    /// Finite-difference step, as a fraction of `typical`, in internal coordinates
    /// (default 1e-4).
    pub fd_relative_step: f64,
    /// Central differences (2 evaluations per column) rather than forward (1 per column);
    /// default false.
    pub central: bool,
    /// Threads on which the Jacobian's evaluations run (default: one per core, as
    /// [`std::thread::available_parallelism`] reports; 1 = serial, 0 taken as 1). The
    /// result does not depend on it. Fits run side by side share the cores: each takes a
    /// share (two threads each still fill the gaps while one fit tries a step).
    pub threads: usize,
    /// Whether the fit returns the covariance (default true). Without it a fit that stops
    /// on its step limit or on a small step returns without evaluating the Jacobian there
    /// (one Jacobian fewer; the values are the same; `covariance` is `None`, `sd` and
    /// `ci95` NaN): for fits whose optimum alone is wanted, e.g. a screening.
    #[serde(default = "default_covariance")]
    pub covariance: bool,
    /// Batches of the sandwich covariance (default 0: none, the covariance is
    /// `s² (JᵀJ)⁻¹`). With `b ≥ 2` batches the residuals, in their order, are cut into `b`
    /// contiguous blocks and the covariance is `(JᵀJ)⁻¹ M (JᵀJ)⁻¹`, `M` the sum over
    /// blocks of the outer products of each block's score `Σ Jᵢᵀ rᵢ` (batch means, scaled
    /// by `N/(N − k)`): it holds when the residuals are correlated over stretches shorter
    /// than a block, as a model's structural error leaves them, where `s² (JᵀJ)⁻¹` takes
    /// them for independent and gives intervals far too narrow. Each parameter's variance
    /// is the larger of the two.
    #[serde(default)]
    pub score_batches: usize,
    /// How many of the residuals, from the first, are data the batches cover (default 0:
    /// all). The rows after them (a prior's terms, which are not drawn from the noise) are
    /// left out of the sandwich's meat, whose bread `JᵀJ` keeps them, and out of
    /// [`LmFit::score_inflation`] altogether.
    #[serde(default)]
    pub score_rows: usize,
    /// Broyden's rank-one update of the Jacobian after an accepted step instead of new
    /// finite differences (default false): after the secant Levenberg–Marquardt method of
    /// Madsen, Nielsen & Tingleff (2004, §3.5), for fits with many parameters whose
    /// Jacobian costs most of their evaluations. The update is kept only after a step
    /// whose actual decrease was at least [`SECANT_RHO_MIN`] of the predicted one and that
    /// moved some parameter by at least `fd_relative_step` of its typical size (a shorter
    /// step sees the residuals' noise); finite differences are taken again otherwise,
    /// after a rejected trial on an updated Jacobian (instead of more damping), after
    /// [`SECANT_UPDATES_MAX`] updates in a row, and before any stop is accepted, so that
    /// a fit stops, and reports its covariance, on a Jacobian of finite differences at its
    /// optimum, as without it. The damping's scale is taken from finite differences only.
    #[serde(default)]
    pub secant: bool,
}

fn default_covariance() -> bool {
    true
}

impl Default for LmOptions {
    fn default() -> Self {
        Self {
            max_iterations: 40,
            cost_tolerance: 1e-6,
            step_tolerance: 1e-6,
            fd_relative_step: 1e-4,
            central: false,
            threads: thread::available_parallelism().map_or(2, |n| n.get()),
            covariance: true,
            score_batches: 0,
            score_rows: 0,
            secant: false,
        }
    }
}

/// Why the solver stopped.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Stop {
    /// The cost can decrease by less than `cost_tolerance`, relative (converged).
    CostTolerance,
    /// The step became shorter than `step_tolerance` (converged).
    StepTolerance,
    /// No descent direction within the box: the gradient is zero, or every parameter is
    /// held at a bound by it; also when there are no parameters (converged).
    Stationary,
    /// `max_iterations` accepted steps (not converged).
    MaxIterations,
    /// The damping grew past its limit without finding a lower cost (not converged).
    NoProgress,
}

impl Stop {
    /// Whether this is a convergence.
    pub fn converged(self) -> bool {
        matches!(
            self,
            Stop::CostTolerance | Stop::StepTolerance | Stop::Stationary
        )
    }
}

/// The result of [`levenberg_marquardt`].
#[derive(Clone, Debug, PartialEq)]
pub struct LmFit {
    /// Physical values at the optimum.
    pub values: Vec<f64>,
    /// The residual vector at the optimum.
    pub residuals: Vec<f64>,
    /// The sum of squares at the optimum.
    pub rss: f64,
    /// Covariance in physical units: `s² (JᵀJ)⁻¹` in internal coordinates, `s² = rss/(N − k)`,
    /// mapped by the delta method. `None` if `JᵀJ` is (numerically) singular or `N ≤ k`.
    pub covariance: Option<DMatrix<f64>>,
    /// Standard deviations: square roots of the covariance diagonal (NaN if none).
    pub sd: Vec<f64>,
    /// 95 % intervals: internal value ± 1.96 sd mapped back through the scale (so a log
    /// scale gives a positive asymmetric interval), clipped to the bounds (NaN if no
    /// covariance).
    pub ci95: Vec<[f64; 2]>,
    /// Whether each value is within 1 % of the bound range (in internal coordinates: in
    /// `ln x` on a log scale) of a bound.
    pub at_bound: Vec<bool>,
    /// Accepted steps.
    pub iterations: usize,
    /// Residual-function calls.
    pub evaluations: usize,
    /// Jacobians taken by finite differences (each `k` or `2k` of the evaluations, and one
    /// more for a side that failed and was tried on the other).
    pub jacobians: usize,
    /// Whether the solver converged ([`Stop::converged`]).
    pub converged: bool,
    /// Why it stopped.
    pub stop: Stop,
    /// How many times more the score varies than the residuals' own units say: with
    /// [`LmOptions::score_batches`] `b ≥ 2`, the batch-means meat's trace (as the
    /// sandwich's, in the parameters' unit-normalised coordinates, over the data's rows,
    /// [`LmOptions::score_rows`]) over its expectation for independent errors of unit
    /// variance at the same Jacobian, the residuals first projected off the data's columns
    /// (so that a prior's or a bound's pull, which leaves them a systematic score, is not
    /// read as their variance). 1 when the residuals are their noise's independent draws;
    /// about `(1 + ρ)/(1 − ρ)` for an AR(1) error of correlation `ρ` over batches long
    /// against it. For one parameter its inverse is Holmes & Walker's (2017, *Biometrika*
    /// 104(2):497–503) power of a likelihood the model does not hold exactly (the Hessian's
    /// information over the score's variance); for several it is the ratio of their traces,
    /// which the most inflated directions dominate. `None` without batches or without a
    /// Jacobian at the stop (a fit with [`LmOptions::covariance`] off may stop without one),
    /// or when no column moves a residual.
    pub score_inflation: Option<f64>,
}

/// Why [`levenberg_marquardt`] could not fit.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FitError {
    /// A parameter is ill-formed.
    #[error("parameter `{name}`: {message}")]
    InvalidParam {
        /// The parameter.
        name: String,
        /// What is wrong.
        message: String,
    },
    /// An option is ill-formed.
    #[error("options: {0}")]
    InvalidOptions(String),
    /// The residual function failed at the start, or returned no residuals.
    #[error("residual function at the start: {0}")]
    Residuals(String),
    /// A residual is not finite at the start.
    #[error("residual {index} is not finite at the start")]
    NonFiniteStart {
        /// Its index.
        index: usize,
    },
    /// The residual vector's length changed between calls.
    #[error("the residual vector had {expected} entries at the start and {found} later")]
    SizeChanged {
        /// The length at the start.
        expected: usize,
        /// The length at a later call.
        found: usize,
    },
    /// The residual function failed on both sides of a parameter in a Jacobian.
    #[error("Jacobian column of `{name}`: {message}")]
    Jacobian {
        /// The parameter.
        name: String,
        /// The residual function's errors.
        message: String,
    },
}

/// The smallest and largest damping; beyond the largest the solver gives up.
const LAMBDA_MIN: f64 = 1e-12;
const LAMBDA_MAX: f64 = 1e20;
/// Floor of the damping scale, relative to its largest entry: a column of zeros still
/// gets a finite, damped step.
const DAMPING_FLOOR: f64 = 1e-9;
/// Smallest eigenvalue ratio of the column-normalised JᵀJ below which it is singular.
const SINGULAR_RCOND: f64 = 1e-12;
/// `at_bound`: within this fraction of the bound range.
const AT_BOUND: f64 = 0.01;
/// With [`LmOptions::secant`], the most secant updates of the Jacobian in a row before
/// finite differences are taken again [D].
pub const SECANT_UPDATES_MAX: usize = 10;
/// With [`LmOptions::secant`], the least ratio of a step's actual to its predicted decrease
/// after which the Jacobian is updated rather than taken again [D]: the ratio below which
/// Marquardt-type damping rules take the linear model for a poor one (Madsen et al. 2004,
/// §2.4).
pub const SECANT_RHO_MIN: f64 = 0.25;

/// Fits `params` by minimising the sum of squares of `residuals(x)` within the bounds.
///
/// `residuals` receives physical values (in the order of `params`) and returns the
/// residual vector (the same length at every call), or `Err` where the model cannot be
/// evaluated: a trial there is rejected, and a Jacobian steps the other way.
///
/// ```
/// use mbs_identify::lm::{levenberg_marquardt, FreeParam, LmOptions};
/// // y = c t measured at t = 1, 2, 3 with unit noise: residuals c t − y.
/// let data = [(1.0, 2.1), (2.0, 3.9), (3.0, 6.0)];
/// let params = [FreeParam::linear("c", 1.0, 0.0, 10.0, 1.0)];
/// let model = |x: &[f64]| Ok(data.iter().map(|(t, y)| x[0] * t - y).collect());
/// let fit = levenberg_marquardt(&params, model, &LmOptions::default()).unwrap();
/// assert!(fit.converged);
/// assert!((fit.values[0] - 27.9 / 14.0).abs() < 1e-6); // Σty / Σt², to the step tolerance
/// ```
pub fn levenberg_marquardt<F>(
    params: &[FreeParam],
    residuals: F,
    options: &LmOptions,
) -> Result<LmFit, FitError>
where
    F: Fn(&[f64]) -> Result<Vec<f64>, String> + Sync,
{
    validate_options(options)?;
    let axes = params
        .iter()
        .map(Axis::new)
        .collect::<Result<Vec<_>, _>>()?;
    let x: Vec<f64> = params.iter().map(|p| p.start).collect();
    let z: Vec<f64> = axes.iter().zip(&x).map(|(a, &v)| a.internal(v)).collect();
    let r = residuals(&x).map_err(FitError::Residuals)?;
    if r.is_empty() {
        return Err(FitError::Residuals("no residuals".into()));
    }
    if let Some(index) = r.iter().position(|v| !v.is_finite()) {
        return Err(FitError::NonFiniteStart { index });
    }
    let mut problem = Problem {
        axes: &axes,
        f: &residuals,
        n: r.len(),
        options,
        evaluations: 1,
        jacobians: 0,
    };
    let mut at = Point::new(x, z, r);
    if axes.is_empty() {
        return Ok(problem.finish(at, Some(&[]), 0, Stop::Stationary));
    }

    let mut damping = Damping::new(axes.len());
    let mut accepted = 0;
    let mut pending: Option<Stop> = None;
    // The Jacobian at `at` (none until taken), whether it is of finite differences there
    // (rather than updated by secants), and the secant updates since it last was.
    let mut jac: Option<Vec<Vec<f64>>> = None;
    let mut fresh = false;
    let mut updates = 0;
    loop {
        let stopping = pending.is_some() || accepted >= options.max_iterations;
        // Without a covariance wanted, a fit that stops here needs no Jacobian.
        if !options.covariance && stopping {
            let stop = pending.unwrap_or(Stop::MaxIterations);
            return Ok(problem.finish(at, None, accepted, stop));
        }
        // The Jacobian at every accepted point: the next step's, or the covariance's; of
        // finite differences unless a secant update is trusted.
        if jac.is_none() || (!fresh && (stopping || updates >= SECANT_UPDATES_MAX)) {
            jac = Some(problem.jacobian(&at)?);
            fresh = true;
            updates = 0;
        }
        let Some(j) = jac.as_deref() else {
            unreachable!("the Jacobian is taken above");
        };
        if let Some(stop) = pending {
            return Ok(problem.finish(at, Some(j), accepted, stop));
        }
        let model = Model::new(j, &at, &axes, &mut damping, fresh);
        if let Some(stop) = model.converged(options.cost_tolerance * at.rss) {
            if fresh {
                return Ok(problem.finish(at, Some(j), accepted, stop));
            }
            // An updated Jacobian's claim is checked on finite differences.
            jac = None;
            continue;
        }
        if accepted >= options.max_iterations {
            return Ok(problem.finish(at, Some(j), accepted, Stop::MaxIterations));
        }
        match problem.trials(&at, &model, &mut damping, fresh)? {
            Trial::Accepted {
                next,
                small,
                rho,
                step,
            } => {
                // The Jacobian is updated only after a step it predicted well, longer than
                // a finite difference's (a shorter one sees the residuals' noise), and not
                // after a small step judged on an update. A small step stops the fit only
                // if judged on finite differences; one judged on an update is judged again
                // on finite differences at the next point.
                let trusted = options.secant
                    && rho.is_some_and(|rho| rho >= SECANT_RHO_MIN)
                    && step.iter().any(|v| v.abs() >= options.fd_relative_step)
                    && (fresh || !small);
                pending = (small && fresh).then_some(Stop::CostTolerance);
                match jac.as_mut() {
                    Some(j) if trusted => {
                        broyden(j, &step, &at.r, &next.r);
                        fresh = false;
                        updates += 1;
                    }
                    _ => jac = None,
                }
                at = next;
                accepted += 1;
            }
            Trial::Stale => jac = None,
            Trial::Stop(_) if !fresh => jac = None,
            Trial::Stop(stop) => return Ok(problem.finish(at, Some(j), accepted, stop)),
        }
    }
}

/// Broyden's rank-one update of `J` (columns) for the step `s` (units of typical) that
/// took the residuals from `r0` to `r1`: `J ← J + (Δr − J s) sᵀ / sᵀs`, the least change
/// of `J` (in the Frobenius norm) that makes it reproduce the step (Broyden 1965; Madsen,
/// Nielsen & Tingleff 2004, §3.5).
fn broyden(jac: &mut [Vec<f64>], s: &[f64], r0: &[f64], r1: &[f64]) {
    let ss = dot(s, s);
    if !(ss > 0.0 && ss.is_finite()) {
        return;
    }
    let miss: Vec<f64> = (0..r0.len())
        .map(|l| {
            let predicted: f64 = jac.iter().zip(s).map(|(c, si)| c[l] * si).sum();
            (r1[l] - r0[l]) - predicted
        })
        .collect();
    for (c, &si) in jac.iter_mut().zip(s) {
        if si != 0.0 {
            let w = si / ss;
            for (cl, m) in c.iter_mut().zip(&miss) {
                *cl += w * m;
            }
        }
    }
}

/// A point of the search: physical values, internal coordinates, residuals, their sum of
/// squares.
struct Point {
    x: Vec<f64>,
    z: Vec<f64>,
    r: Vec<f64>,
    rss: f64,
}

impl Point {
    fn new(x: Vec<f64>, z: Vec<f64>, r: Vec<f64>) -> Self {
        let rss = sum_sq(&r);
        Self { x, z, r, rss }
    }
}

/// The damping: λ, Nielsen's ν, and the running max of diag(JᵀJ).
struct Damping {
    lambda: f64,
    nu: f64,
    running_diag: Vec<f64>,
}

impl Damping {
    fn new(k: usize) -> Self {
        Self {
            lambda: 1e-3,
            nu: 2.0,
            running_diag: vec![0.0; k],
        }
    }

    /// After an accepted step with gain ratio ρ (Nielsen): λ ← λ·max(1/3, 1 − (2ρ − 1)³).
    fn accept(&mut self, rho: Option<f64>) {
        if let Some(rho) = rho {
            self.lambda *= (1.0 / 3.0_f64).max(1.0 - (2.0 * rho - 1.0).powi(3));
        }
        self.lambda = self.lambda.max(LAMBDA_MIN);
        self.nu = 2.0;
    }

    /// After a rejected trial: λ ← λ·ν, ν ← 2ν. False once λ is past its limit.
    fn reject(&mut self) -> bool {
        self.lambda *= self.nu;
        self.nu *= 2.0;
        self.lambda <= LAMBDA_MAX
    }
}

/// The linear model at a point, in units of typical: A = JᵀJ, g = Jᵀr, the damping
/// scale D, and the free set.
struct Model {
    a: DMatrix<f64>,
    g: Vec<f64>,
    d: Vec<f64>,
    free: Vec<usize>,
}

impl Model {
    fn new(
        jac: &[Vec<f64>],
        at: &Point,
        axes: &[Axis],
        damping: &mut Damping,
        fresh: bool,
    ) -> Self {
        let k = jac.len();
        let a = gram(jac);
        let g: Vec<f64> = jac.iter().map(|c| dot(c, &at.r)).collect();
        // D = running max of diag(A), floored relative to its largest entry; taken from
        // Jacobians of finite differences only (an update that overshoots would damp its
        // parameter for the rest of the fit).
        if fresh {
            for (running, i) in damping.running_diag.iter_mut().zip(0..k) {
                *running = running.max(a[(i, i)]);
            }
        }
        let largest = damping.running_diag.iter().fold(0.0_f64, |m, &v| m.max(v));
        let d = damping
            .running_diag
            .iter()
            .map(|&v| v.max(DAMPING_FLOOR * largest).max(f64::MIN_POSITIVE))
            .collect();
        // Free: not held at a bound by the descent direction −g.
        let free = (0..k)
            .filter(|&i| {
                let held_low = at.z[i] <= axes[i].lo && g[i] > 0.0;
                let held_high = at.z[i] >= axes[i].hi && g[i] < 0.0;
                !(held_low || held_high)
            })
            .collect();
        Self { a, g, d, free }
    }

    /// Stationary (no descent direction in the box), or the most the model can gain on the
    /// free set, gᵀA⁻¹g, is at most `gain_tolerance`.
    fn converged(&self, gain_tolerance: f64) -> Option<Stop> {
        if self.free.iter().all(|&i| self.g[i] == 0.0) {
            return Some(Stop::Stationary);
        }
        // (regularised by the least damping, so that a column of zeros does not stop it)
        let gauss_newton = self.step(LAMBDA_MIN)?;
        let gain = -dot(&self.g, &gauss_newton);
        (gain <= gain_tolerance).then_some(Stop::CostTolerance)
    }

    /// Solves (A + λ D) δ = −g on the free set (δ = 0 elsewhere) by Cholesky; `None` if
    /// it fails or gives non-finite values.
    fn step(&self, lambda: f64) -> Option<Vec<f64>> {
        let free = &self.free;
        let m = free.len();
        let h = DMatrix::from_fn(m, m, |p, q| {
            let (i, j) = (free[p], free[q]);
            self.a[(i, j)] + if p == q { lambda * self.d[i] } else { 0.0 }
        });
        let b = DVector::from_fn(m, |p, _| -self.g[free[p]]);
        let solution = h.cholesky()?.solve(&b);
        if !solution.iter().all(|v| v.is_finite()) {
            return None;
        }
        let mut delta = vec![0.0; self.g.len()];
        for (p, &i) in free.iter().enumerate() {
            delta[i] = solution[p];
        }
        Some(delta)
    }

    /// The decrease of the sum of squares the model predicts for the step `s`:
    /// −(2 gᵀs + sᵀA s).
    fn predicted(&self, s: &[f64]) -> f64 {
        let k = s.len();
        let s_a_s: f64 = (0..k)
            .map(|i| s[i] * (0..k).map(|j| self.a[(i, j)] * s[j]).sum::<f64>())
            .sum();
        -(2.0 * dot(&self.g, s) + s_a_s)
    }
}

/// The outcome of the trials at one Jacobian.
enum Trial {
    /// A lower cost at `next`; `small` if both the actual and the predicted decrease were
    /// within the cost tolerance; `rho` the ratio of the actual to the predicted decrease
    /// (none if the model predicted none); `step` the step taken, in units of typical.
    Accepted {
        next: Point,
        small: bool,
        rho: Option<f64>,
        step: Vec<f64>,
    },
    /// A trial on a Jacobian updated by secants was rejected: take finite differences.
    Stale,
    /// No trial is worth evaluating, or the damping is exhausted.
    Stop(Stop),
}

/// One parameter's coordinates: its scale, physical and internal bounds, typical size.
struct Axis {
    name: String,
    scale: Scale,
    lower: f64,
    upper: f64,
    /// Internal bounds.
    lo: f64,
    hi: f64,
    typical: f64,
}

impl Axis {
    fn new(p: &FreeParam) -> Result<Self, FitError> {
        let bad = |message: String| FitError::InvalidParam {
            name: p.name.clone(),
            message,
        };
        for (what, v) in [
            ("start", p.start),
            ("lower", p.lower),
            ("upper", p.upper),
            ("typical", p.typical),
        ] {
            if !v.is_finite() {
                return Err(bad(format!("{what} is {v}, not finite")));
            }
        }
        if p.lower >= p.upper {
            return Err(bad(format!(
                "lower ({}) is not below upper ({})",
                p.lower, p.upper
            )));
        }
        if p.start < p.lower || p.start > p.upper {
            return Err(bad(format!(
                "start {} is outside [{}, {}]",
                p.start, p.lower, p.upper
            )));
        }
        if p.scale == Scale::Log && p.lower <= 0.0 {
            return Err(bad(format!(
                "a log-scale parameter needs lower > 0 (got {})",
                p.lower
            )));
        }
        if p.typical <= 0.0 {
            return Err(bad(format!("typical must be > 0 (got {})", p.typical)));
        }
        let mut axis = Self {
            name: p.name.clone(),
            scale: p.scale,
            lower: p.lower,
            upper: p.upper,
            lo: 0.0,
            hi: 0.0,
            typical: p.typical,
        };
        (axis.lo, axis.hi) = (axis.internal(p.lower), axis.internal(p.upper));
        Ok(axis)
    }

    fn internal(&self, x: f64) -> f64 {
        match self.scale {
            Scale::Linear => x,
            Scale::Log => x.ln(),
        }
    }

    /// The physical value at `z`, exactly a bound at a bound.
    fn physical(&self, z: f64) -> f64 {
        if z <= self.lo {
            self.lower
        } else if z >= self.hi {
            self.upper
        } else {
            match self.scale {
                Scale::Linear => z,
                Scale::Log => z.exp(),
            }
        }
    }

    /// dx/dz at the physical value `x`.
    fn dx_dz(&self, x: f64) -> f64 {
        match self.scale {
            Scale::Linear => 1.0,
            Scale::Log => x,
        }
    }
}

/// What a residual evaluation gave, short of a fatal error.
type Eval = Result<Vec<f64>, String>;

/// The fixed parts of a fit, and its evaluation count.
struct Problem<'a, F> {
    axes: &'a [Axis],
    f: &'a F,
    /// Residual count.
    n: usize,
    options: &'a LmOptions,
    evaluations: usize,
    /// Jacobians of finite differences taken.
    jacobians: usize,
}

impl<F> Problem<'_, F>
where
    F: Fn(&[f64]) -> Result<Vec<f64>, String> + Sync,
{
    /// Checks one evaluation: a length change is fatal, a non-finite residual a failure.
    fn check(&self, result: Eval) -> Result<Eval, FitError> {
        match result {
            Ok(r) if r.len() != self.n => Err(FitError::SizeChanged {
                expected: self.n,
                found: r.len(),
            }),
            Ok(r) => match r.iter().position(|v| !v.is_finite()) {
                Some(i) => Ok(Err(format!("residual {i} is not finite"))),
                None => Ok(Ok(r)),
            },
            Err(e) => Ok(Err(e)),
        }
    }

    fn evaluate_one(&mut self, x: &[f64]) -> Result<Eval, FitError> {
        self.evaluations += 1;
        self.check((self.f)(x))
    }

    /// Evaluates at every point, on up to `threads` threads, each taking the next point
    /// left when it finishes one (evaluations differ in cost: a point past an event may
    /// take twice as long); results in the order of `points`, each independent of the
    /// thread it ran on.
    fn evaluate_all(&mut self, points: &[Vec<f64>]) -> Result<Vec<Eval>, FitError> {
        self.evaluations += points.len();
        let workers = self.options.threads.clamp(1, points.len().max(1));
        let f = self.f;
        let next = AtomicUsize::new(0);
        let share = || -> Vec<(usize, Eval)> {
            let mut done = Vec::new();
            loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(p) = points.get(i) else {
                    return done;
                };
                done.push((i, f(p)));
            }
        };
        let mut results: Vec<Option<Eval>> = (0..points.len()).map(|_| None).collect();
        let done = if workers == 1 {
            share()
        } else {
            thread::scope(|scope| {
                let handles: Vec<_> = (1..workers).map(|_| scope.spawn(share)).collect();
                let mut done = share();
                for h in handles {
                    done.extend(h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)));
                }
                done
            })
        };
        for (i, e) in done {
            results[i] = Some(e);
        }
        results
            .into_iter()
            .map(|e| self.check(e.expect("every point is evaluated")))
            .collect()
    }

    /// Trial steps from `at` with the model's Jacobian, more damped after each rejection
    /// (a failed evaluation, a non-finite residual or a cost not lower), until one lowers
    /// the cost; on a Jacobian not `fresh` (updated by secants) the first rejection
    /// returns [`Trial::Stale`] instead.
    fn trials(
        &mut self,
        at: &Point,
        model: &Model,
        damping: &mut Damping,
        fresh: bool,
    ) -> Result<Trial, FitError> {
        let axes = self.axes;
        let k = axes.len();
        let tolerance = self.options.cost_tolerance * at.rss;
        loop {
            let Some(delta) = model.step(damping.lambda) else {
                if !fresh {
                    return Ok(Trial::Stale);
                }
                damping.lambda = (10.0 * damping.lambda).max(LAMBDA_MIN);
                if damping.lambda > LAMBDA_MAX {
                    return Ok(Trial::Stop(Stop::NoProgress));
                }
                continue;
            };
            // Project z + δ·typical onto the box; s is the step taken (units of typical).
            let z: Vec<f64> = (0..k)
                .map(|i| (at.z[i] + delta[i] * axes[i].typical).clamp(axes[i].lo, axes[i].hi))
                .collect();
            let s: Vec<f64> = (0..k).map(|i| (z[i] - at.z[i]) / axes[i].typical).collect();
            if s.iter().all(|v| v.abs() <= self.options.step_tolerance) {
                return Ok(Trial::Stop(Stop::StepTolerance));
            }
            let predicted = model.predicted(&s);
            // Unmoved parameters keep their physical value bit for bit.
            let x: Vec<f64> = (0..k)
                .map(|i| {
                    if z[i] == at.z[i] {
                        at.x[i]
                    } else {
                        axes[i].physical(z[i])
                    }
                })
                .collect();
            if let Ok(r) = self.evaluate_one(&x)? {
                let next = Point::new(x, z, r);
                if next.rss < at.rss {
                    let actual = at.rss - next.rss;
                    let rho = (predicted > 0.0).then(|| actual / predicted);
                    damping.accept(rho);
                    let small = actual <= tolerance && predicted <= tolerance;
                    return Ok(Trial::Accepted {
                        next,
                        small,
                        rho,
                        step: s,
                    });
                }
            }
            if !fresh {
                return Ok(Trial::Stale);
            }
            if !damping.reject() {
                return Ok(Trial::Stop(Stop::NoProgress));
            }
        }
    }

    /// `J = ∂r/∂u` (columns, u = z / typical) by finite differences at `z` (physical `x`,
    /// residuals `r`). Steps stay in the box: one-sided inward at a bound (3-point when
    /// central); a failed side is replaced by the other.
    fn jacobian(&mut self, at: &Point) -> Result<Vec<Vec<f64>>, FitError> {
        self.jacobians += 1;
        let (x, z, r) = (&at.x, &at.z, &at.r);
        let k = z.len();
        let axes = self.axes;
        let point = |i: usize, zi: f64| -> Vec<f64> {
            let mut p = x.to_vec();
            p[i] = axes[i].physical(zi);
            p
        };
        // Offsets of the first round, per column: [+h, −h] central, [±h, ±2h] one-sided
        // 3-point, [±h] forward; h ≤ range/4 so one side always has room for 2h.
        let mut plans: Vec<Vec<f64>> = Vec::with_capacity(k);
        for (i, ax) in self.axes.iter().enumerate() {
            let h = (self.options.fd_relative_step * ax.typical).min(0.25 * (ax.hi - ax.lo));
            let up = z[i] + h <= ax.hi;
            let down = z[i] - h >= ax.lo;
            let s = if up { 1.0 } else { -1.0 };
            let plan = match (self.options.central, up && down) {
                (true, true) => vec![z[i] + h, z[i] - h],
                (true, false) => vec![z[i] + s * h, z[i] + 2.0 * s * h],
                (false, _) => vec![z[i] + s * h],
            };
            plans.push(plan);
        }
        let points: Vec<Vec<f64>> = plans
            .iter()
            .enumerate()
            .flat_map(|(i, plan)| plan.iter().map(move |&zi| (i, zi)))
            .map(|(i, zi)| point(i, zi))
            .collect();
        let mut evals = self.evaluate_all(&points)?.into_iter();

        // Keep what succeeded; a forward column that failed tries the other side.
        let mut done: Vec<Vec<(f64, Vec<f64>)>> = Vec::with_capacity(k);
        let mut errors: Vec<Vec<String>> = Vec::with_capacity(k);
        let mut retry: Vec<(usize, f64)> = Vec::new();
        for (i, plan) in plans.iter().enumerate() {
            let mut ok = Vec::new();
            let mut failed = Vec::new();
            for &zi in plan {
                match evals.next().expect("one result per point") {
                    Ok(v) => ok.push((zi - z[i], v)),
                    Err(e) => failed.push(format!("at {}: {e}", self.axes[i].physical(zi))),
                }
            }
            if ok.is_empty() && plan.len() == 1 {
                let other = 2.0 * z[i] - plan[0];
                if (self.axes[i].lo..=self.axes[i].hi).contains(&other) {
                    retry.push((i, other));
                }
            }
            done.push(ok);
            errors.push(failed);
        }
        if !retry.is_empty() {
            let points: Vec<Vec<f64>> = retry.iter().map(|&(i, zi)| point(i, zi)).collect();
            for (&(i, zi), e) in retry.iter().zip(self.evaluate_all(&points)?) {
                match e {
                    Ok(v) => done[i].push((zi - z[i], v)),
                    Err(e) => errors[i].push(format!("at {}: {e}", self.axes[i].physical(zi))),
                }
            }
        }

        let mut columns = Vec::with_capacity(k);
        for (i, ok) in done.iter().enumerate() {
            if ok.is_empty() {
                return Err(FitError::Jacobian {
                    name: self.axes[i].name.clone(),
                    message: errors[i].join("; "),
                });
            }
            let t = self.axes[i].typical;
            columns.push(difference(r, ok, t));
        }
        Ok(columns)
    }

    /// The fit at `at`, with its Jacobian `jac` (empty when there are no parameters).
    fn finish(&self, at: Point, jac: Option<&[Vec<f64>]>, iterations: usize, stop: Stop) -> LmFit {
        let Point {
            x: values,
            z,
            r: residuals,
            rss,
        } = at;
        let k = values.len();
        let batches = self.options.score_batches;
        let rows = match self.options.score_rows {
            0 => residuals.len(),
            m => m.min(residuals.len()),
        };
        let covariance_u = jac.and_then(|jac| {
            let plain = covariance_internal(jac, rss, self.n)?;
            if self.options.score_batches < 2 {
                return Some(plain);
            }
            let sandwich = covariance_batch_means(jac, &residuals[..rows], batches)?;
            // Each variance the larger of the two, the correlations the sandwich's.
            let sd: Vec<f64> = (0..k)
                .map(|i| plain[(i, i)].max(sandwich[(i, i)]).sqrt())
                .collect();
            let own: Vec<f64> = (0..k).map(|i| sandwich[(i, i)].sqrt()).collect();
            Some(DMatrix::from_fn(k, k, |i, j| {
                if i == j {
                    sd[i] * sd[i]
                } else {
                    sandwich[(i, j)] / (own[i] * own[j]) * sd[i] * sd[j]
                }
            }))
        });
        // Delta method: x = x(z), z = typical·u, so dx/du = typical·dx/dz.
        let grad: Vec<f64> = (0..k)
            .map(|i| self.axes[i].typical * self.axes[i].dx_dz(values[i]))
            .collect();
        let covariance = covariance_u
            .as_ref()
            .map(|c| DMatrix::from_fn(k, k, |i, j| grad[i] * c[(i, j)] * grad[j]));
        let sd = (0..k)
            .map(|i| covariance.as_ref().map_or(f64::NAN, |c| c[(i, i)].sqrt()))
            .collect();
        let ci95 = (0..k)
            .map(|i| {
                let ax = &self.axes[i];
                let Some(c) = &covariance_u else {
                    return [f64::NAN; 2];
                };
                let half = 1.96 * c[(i, i)].sqrt() * ax.typical;
                let end = |zi: f64| ax.physical(zi.clamp(ax.lo, ax.hi));
                [end(z[i] - half), end(z[i] + half)]
            })
            .collect();
        let at_bound = (0..k)
            .map(|i| {
                let ax = &self.axes[i];
                let margin = AT_BOUND * (ax.hi - ax.lo);
                z[i] - ax.lo <= margin || ax.hi - z[i] <= margin
            })
            .collect();
        let score_inflation = match jac {
            Some(jac) if batches >= 2 && k > 0 => {
                let data: Vec<Vec<f64>> = jac.iter().map(|c| c[..rows].to_vec()).collect();
                score_inflation(&data, &residuals[..rows], batches)
            }
            _ => None,
        };
        LmFit {
            values,
            residuals,
            rss,
            score_inflation,
            covariance,
            sd,
            ci95,
            at_bound,
            iterations,
            evaluations: self.evaluations,
            jacobians: self.jacobians,
            converged: stop.converged(),
            stop,
        }
    }
}

fn validate_options(o: &LmOptions) -> Result<(), FitError> {
    let bad = |m: &str| Err(FitError::InvalidOptions(m.into()));
    if !(o.cost_tolerance >= 0.0 && o.cost_tolerance.is_finite()) {
        return bad("cost_tolerance must be finite and ≥ 0");
    }
    if !(o.step_tolerance >= 0.0 && o.step_tolerance.is_finite()) {
        return bad("step_tolerance must be finite and ≥ 0");
    }
    if !(o.fd_relative_step > 0.0 && o.fd_relative_step.is_finite()) {
        return bad("fd_relative_step must be finite and > 0");
    }
    Ok(())
}

/// A Jacobian column `∂r/∂u` from residuals `r` at the point and `(offset in z, residuals)`
/// on one or two sides: 2-point, central, or one-sided 3-point.
fn difference(r: &[f64], sides: &[(f64, Vec<f64>)], typical: f64) -> Vec<f64> {
    match sides {
        [(h, f1)] => {
            let c = typical / h;
            f1.iter().zip(r).map(|(a, b)| c * (a - b)).collect()
        }
        [(h1, f1), (h2, f2)] if h1 * h2 < 0.0 => {
            // f' = (f1 − f2) / (h1 − h2)
            let c = typical / (h1 - h2);
            f1.iter().zip(f2).map(|(a, b)| c * (a - b)).collect()
        }
        [(h1, f1), (h2, f2)] => {
            // f' = −(h1+h2)/(h1 h2) f0 + h2/(h1 (h2−h1)) f1 − h1/(h2 (h2−h1)) f2
            let c0 = -(h1 + h2) / (h1 * h2) * typical;
            let c1 = h2 / (h1 * (h2 - h1)) * typical;
            let c2 = -h1 / (h2 * (h2 - h1)) * typical;
            (0..r.len())
                .map(|l| c0 * r[l] + c1 * f1[l] + c2 * f2[l])
                .collect()
        }
        _ => unreachable!("one or two sides"),
    }
}

/// JᵀJ from the columns of J.
fn gram(jac: &[Vec<f64>]) -> DMatrix<f64> {
    let k = jac.len();
    let mut a = DMatrix::zeros(k, k);
    for i in 0..k {
        for j in 0..=i {
            a[(i, j)] = dot(&jac[i], &jac[j]);
            a[(j, i)] = a[(i, j)];
        }
    }
    a
}

/// `(JᵀJ)⁻¹` of the unit-normalised columns and the columns' norms (so that the
/// singularity test is scale-free), or `None` if JᵀJ is numerically singular.
fn normalized_inverse(jac: &[Vec<f64>]) -> Option<(DMatrix<f64>, Vec<f64>)> {
    let k = jac.len();
    let a = gram(jac);
    let norm: Vec<f64> = (0..k).map(|i| a[(i, i)].sqrt()).collect();
    if norm.iter().any(|&v| !(v > 0.0 && v.is_finite())) {
        return None;
    }
    let unit = DMatrix::from_fn(k, k, |i, j| a[(i, j)] / (norm[i] * norm[j]));
    let eig = SymmetricEigen::new(unit.clone()).eigenvalues;
    let (lo, hi) = eig.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), &e| {
        (lo.min(e), hi.max(e))
    });
    if lo <= SINGULAR_RCOND * hi {
        return None;
    }
    Some((unit.cholesky()?.inverse(), norm))
}

/// s² (JᵀJ)⁻¹ in units of typical, or `None` if JᵀJ is numerically singular or N ≤ k.
fn covariance_internal(jac: &[Vec<f64>], rss: f64, n: usize) -> Option<DMatrix<f64>> {
    let k = jac.len();
    if k == 0 {
        return Some(DMatrix::zeros(0, 0));
    }
    if n <= k {
        return None;
    }
    let (inverse, norm) = normalized_inverse(jac)?;
    let s2 = rss / (n - k) as f64;
    Some(DMatrix::from_fn(k, k, |i, j| {
        s2 * inverse[(i, j)] / (norm[i] * norm[j])
    }))
}

/// The batch-means sandwich covariance in internal coordinates (see
/// [`LmOptions::score_batches`]) over the first `r.len()` rows (the data; the bread
/// keeps every row); `None` where [`covariance_internal`] gives none, or with fewer
/// residuals than batches.
fn covariance_batch_means(jac: &[Vec<f64>], r: &[f64], batches: usize) -> Option<DMatrix<f64>> {
    let k = jac.len();
    let n = r.len();
    if k == 0 {
        return Some(DMatrix::zeros(0, 0));
    }
    if n <= k || n < batches {
        return None;
    }
    let (inverse, norm) = normalized_inverse(jac)?;
    // The meat: per block, the score of the unit-normalised columns.
    let mut meat = DMatrix::<f64>::zeros(k, k);
    for b in 0..batches {
        let (from, to) = (b * n / batches, (b + 1) * n / batches);
        let score: Vec<f64> = (0..k)
            .map(|i| (from..to).map(|t| jac[i][t] * r[t]).sum::<f64>() / norm[i])
            .collect();
        for i in 0..k {
            for j in 0..k {
                meat[(i, j)] += score[i] * score[j];
            }
        }
    }
    meat *= n as f64 / (n - k) as f64;
    let cov = &inverse * meat * &inverse;
    Some(DMatrix::from_fn(k, k, |i, j| {
        cov[(i, j)] / (norm[i] * norm[j])
    }))
}

/// The batch-means meat's trace in unit-normalised coordinates over its expectation for
/// independent errors of unit variance at this Jacobian (see [`LmFit::score_inflation`]);
/// `None` with fewer residuals than batches, no column that moves a residual (columns of
/// zeros, a parameter nothing depends on here, and non-finite ones are left out) or an
/// expectation lost to round-off. The residuals are first projected off the columns,
/// `r − U G⁺ Uᵀ r` (`U` the unit columns, `G = UᵀU`): at an unconstrained optimum that
/// changes nothing; where a prior or a bound holds a parameter off the data's optimum it
/// takes out the systematic score that pull leaves. The expectation is not the columns'
/// count: projected residuals are `(I − H) e`, which takes from every batch its share of
/// each column, `E sᵢ_b² = ‖uᵢ_b‖² − gᵢ_bᵀ G⁺ gᵢ_b` with `uᵢ_b` the unit column's part in
/// batch `b` and `gᵢ_b = U_bᵀ uᵢ_b` (19/20 of it for an offset over 20 equal batches,
/// about 0.6 for an exponential decay whose column lies in its first batches): a
/// leverage correction in the spirit of Bell & McCaffrey's (2002) for cluster-robust
/// variances, as one ratio of expectations.
fn score_inflation(jac: &[Vec<f64>], r: &[f64], batches: usize) -> Option<f64> {
    let n = r.len();
    let unit: Vec<Vec<f64>> = jac
        .iter()
        .filter_map(|c| {
            let norm = dot(c, c).sqrt();
            (norm > 0.0 && norm.is_finite()).then(|| c.iter().map(|v| v / norm).collect())
        })
        .collect();
    let k = unit.len();
    if k == 0 || n <= k || n < batches {
        return None;
    }
    let gram = DMatrix::from_fn(k, k, |i, j| dot(&unit[i], &unit[j]));
    let inverse = gram.pseudo_inverse(SINGULAR_RCOND).ok()?;
    let ur = DVector::from_iterator(k, unit.iter().map(|u| dot(u, r)));
    let coef = &inverse * ur;
    let projected: Vec<f64> = (0..n)
        .map(|t| r[t] - (0..k).map(|i| unit[i][t] * coef[i]).sum::<f64>())
        .collect();
    let (mut meat, mut expected) = (0.0, 0.0);
    for b in 0..batches {
        let (from, to) = (b * n / batches, (b + 1) * n / batches);
        let part = |i: usize| &unit[i][from..to];
        let block = DMatrix::from_fn(k, k, |i, j| dot(part(i), part(j)));
        for i in 0..k {
            let score = dot(part(i), &projected[from..to]);
            meat += score * score;
            let g = block.column(i);
            expected += block[(i, i)] - (g.transpose() * &inverse * g)[(0, 0)];
        }
    }
    // Each unit column's batches hold 1 in all; below a millionth of that the ratio is
    // round-off's.
    if expected.is_nan() || expected <= 1e-6 * k as f64 {
        return None;
    }
    let inflation = meat / expected;
    inflation.is_finite().then_some(inflation)
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn sum_sq(r: &[f64]) -> f64 {
    dot(r, r)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The update makes the Jacobian reproduce the step exactly, and leaves a column whose
    /// parameter did not move (held at a bound) as it was.
    #[test]
    fn broydens_update_reproduces_the_step() {
        let mut jac = vec![
            vec![1.0, 2.0, 3.0],
            vec![0.5, -1.0, 0.0],
            vec![2.0, 0.0, 1.0],
        ];
        let s = [0.3, -0.2, 0.0];
        let (r0, r1) = ([1.0, 1.0, 1.0], [1.4, 0.1, 2.0]);
        let held = jac[2].clone();
        broyden(&mut jac, &s, &r0, &r1);
        for l in 0..3 {
            let predicted: f64 = (0..3).map(|i| jac[i][l] * s[i]).sum();
            assert!((predicted - (r1[l] - r0[l])).abs() < 1e-12, "row {l}");
        }
        assert_eq!(jac[2], held);
        // A zero step changes nothing.
        let before = jac.clone();
        broyden(&mut jac, &[0.0; 3], &r0, &r1);
        assert_eq!(jac, before);
    }
}
