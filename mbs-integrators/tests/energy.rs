//! Energy behaviour on a conservative pendulum over a hundred periods, and bit-for-bit
//! reproducibility of every method.
//!
//! Symplectic (semi-implicit) Euler conserves a modified energy, so its energy error is
//! O(h), oscillates and does not grow; explicit Euler (the same scheme on a system that
//! declares no position/velocity split) pumps energy in; RK4 is far more accurate at the
//! same step but drifts slowly; DOPRI5 at a tight tolerance keeps the drift tiny.

use mbs_integrators::{Method, OdeSystem, Options, Solution, SystemError, solve};

const G_OVER_L: f64 = 9.81;
const THETA0: f64 = 1.0;

/// The pendulum `θ̈ = −(g/l) sin θ`, `y = [θ, ω]`. With `split` it declares
/// `second_order_split() = Some(1)`; without, `Some(0)`: no mechanical part, so
/// semi-implicit Euler updates every state from the old derivative, i.e. explicit Euler.
struct Pendulum {
    split: bool,
}

impl OdeSystem for Pendulum {
    fn len(&self) -> usize {
        2
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = y[1];
        dy[1] = -G_OVER_L * y[0].sin();
        Ok(())
    }
    fn second_order_split(&self) -> Option<usize> {
        Some(if self.split { 1 } else { 0 })
    }
}

/// Energy per unit `m l²`.
fn energy(y: &[f64]) -> f64 {
    0.5 * y[1] * y[1] - G_OVER_L * y[0].cos()
}

/// The energy scale: the swing's potential-energy range `(g/l)(1 − cos θ0)`.
fn energy_scale() -> f64 {
    G_OVER_L * (1.0 - THETA0.cos())
}

/// The period of the pendulum released at rest from `THETA0`:
/// `T = 4 K(sin(θ0/2)) / √(g/l)`, with `K(k) = π / (2 AGM(1, √(1 − k²)))`.
fn period() -> f64 {
    let k = (0.5 * THETA0).sin();
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..10 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    4.0 * (std::f64::consts::PI / (2.0 * a)) / G_OVER_L.sqrt()
}

/// Relative energy error at every output point.
fn energy_errors(sol: &Solution) -> Vec<f64> {
    let e0 = energy(sol.state(0));
    (0..sol.len())
        .map(|i| (energy(sol.state(i)) - e0) / energy_scale())
        .collect()
}

/// Max |relative energy error| over output times in `[a, b]`.
fn max_in(sol: &Solution, errs: &[f64], a: f64, b: f64) -> f64 {
    sol.t
        .iter()
        .zip(errs)
        .filter(|(t, _)| **t >= a && **t <= b)
        .map(|(_, e)| e.abs())
        .fold(0.0, f64::max)
}

const PERIODS: f64 = 100.0;
const STEPS_PER_PERIOD: f64 = 200.0;

struct Run {
    sol: Solution,
    errs: Vec<f64>,
    first: f64,
    last: f64,
    max: f64,
}

/// Runs 100 periods with output at every step; max energy error over the first and last
/// ten periods and overall.
fn run(method: Method, split: bool, opts: &Options) -> Run {
    let t_end = PERIODS * period();
    let sol = solve(
        &mut Pendulum { split },
        method,
        0.0,
        &[THETA0, 0.0],
        t_end,
        opts,
    )
    .unwrap();
    let errs = energy_errors(&sol);
    let p = period();
    let first = max_in(&sol, &errs, 0.0, 10.0 * p);
    let last = max_in(&sol, &errs, t_end - 10.0 * p, t_end);
    let max = errs.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    println!(
        "{method:?} (split {split}): {} steps, max |ΔE|/E_swing {max:.3e}: first 10 periods \
         {first:.3e}, last 10 {last:.3e}, final {:.3e}",
        sol.stats.steps,
        errs[errs.len() - 1]
    );
    Run {
        sol,
        errs,
        first,
        last,
        max,
    }
}

fn fixed(steps_per_period: f64) -> Options {
    Options::default().fixed(period() / steps_per_period)
}

#[test]
fn symplectic_euler_energy_error_is_bounded_and_first_order() {
    let coarse = run(Method::SemiImplicitEuler, true, &fixed(STEPS_PER_PERIOD));
    // Bounded and oscillating: the same size in the first and the last ten periods.
    let ratio = coarse.last / coarse.first;
    assert!(
        (0.5..=2.0).contains(&ratio),
        "energy error {:.3e} in the first ten periods, {:.3e} in the last",
        coarse.first,
        coarse.last
    );
    // It oscillates about zero: large excursions of both signs.
    let errs = &coarse.errs;
    assert!(errs.iter().any(|&e| e > 0.5 * coarse.max));
    assert!(errs.iter().any(|&e| e < -0.5 * coarse.max));
    // O(h): twice the steps, half the error.
    let fine = run(
        Method::SemiImplicitEuler,
        true,
        &fixed(2.0 * STEPS_PER_PERIOD),
    );
    let gain = coarse.max / fine.max;
    println!("symplectic Euler: halving h divides the energy error by {gain:.3}");
    assert!((1.8..=2.2).contains(&gain), "gain {gain}");
    // A few per cent at 200 steps per period, not more.
    assert!(coarse.max < 0.05, "max energy error {:.3e}", coarse.max);
}

#[test]
fn explicit_euler_pumps_energy_in() {
    // The same scheme without the split: explicit Euler, whose energy grows by about
    // (1 + (ω h)²) each step. Compare with symplectic Euler at the same step.
    let symplectic = run(Method::SemiImplicitEuler, true, &fixed(STEPS_PER_PERIOD));
    let explicit = run(Method::SemiImplicitEuler, false, &fixed(STEPS_PER_PERIOD));
    let final_err = explicit.errs[explicit.errs.len() - 1];
    assert!(final_err > 0.0, "explicit Euler should gain energy");
    // Steady growth, sampled every ten periods (past about ten periods the pendulum has
    // gained enough to go over the top and rotates).
    let every = 10 * STEPS_PER_PERIOD as usize;
    let samples: Vec<f64> = explicit.errs.iter().step_by(every).copied().collect();
    assert!(
        samples.windows(2).all(|w| w[1] > w[0]),
        "energy not growing steadily: {samples:?}"
    );
    assert!(explicit.last > 5.0 * explicit.first);
    assert!(final_err > 1000.0 * symplectic.max);
}

#[test]
fn rk4_is_far_more_accurate_than_symplectic_euler_at_the_same_step() {
    let symplectic = run(Method::SemiImplicitEuler, true, &fixed(STEPS_PER_PERIOD));
    let rk4 = run(Method::Rk4, true, &fixed(STEPS_PER_PERIOD));
    println!(
        "RK4 / symplectic Euler energy error: {:.1e}",
        rk4.max / symplectic.max
    );
    assert!(rk4.max < 1e-4 * symplectic.max);
    // RK4 is not symplectic: its (tiny) energy error is a one-signed drift that grows
    // roughly linearly, not an oscillation.
    assert!(rk4.last > 5.0 * rk4.first);
}

#[test]
fn dormand_prince_at_tight_tolerance_keeps_the_drift_tiny() {
    // About 200 steps a period; local errors far below the tolerance (the estimate is of
    // the embedded 4th-order solution) add up to a slow one-signed drift.
    let opts = Options::with_tolerances(1e-10, 1e-12);
    let r = run(Method::DormandPrince54, true, &opts);
    let drift_per_period = r.max / PERIODS;
    println!("DOPRI5 energy drift per period {drift_per_period:.2e}");
    assert!(r.max < 5e-8, "DOPRI5 energy drift {:.3e}", r.max);
    // A drift, not an oscillation: it grows about linearly.
    assert!(r.last > 5.0 * r.first);
    // Each step leaves far less than rtol in energy.
    assert!(r.max < 1e-10 * r.sol.stats.steps as f64 / 10.0);
}

/// Every bit of every output is the same on a second run.
fn assert_reproducible(method: Method, opts: &Options, t_end: f64) {
    let go = || {
        solve(
            &mut Pendulum { split: true },
            method,
            0.0,
            &[THETA0, 0.0],
            t_end,
            opts,
        )
        .unwrap()
    };
    let (a, b) = (go(), go());
    assert_eq!(a, b, "{method:?}: two runs differ");
    let bits = |s: &Solution| -> Vec<u64> {
        s.t.iter()
            .chain(&s.y)
            .chain(&s.y_final)
            .map(|v| v.to_bits())
            .collect()
    };
    assert_eq!(
        bits(&a),
        bits(&b),
        "{method:?}: two runs differ in some bit"
    );
    assert!(a.len() > 10);
}

#[test]
fn every_method_is_bit_for_bit_reproducible() {
    let t_end = 3.0 * period();
    let h = period() / 100.0;
    assert_reproducible(
        Method::SemiImplicitEuler,
        &Options::default().fixed(h),
        t_end,
    );
    assert_reproducible(Method::Rk4, &Options::default().fixed(h), t_end);
    assert_reproducible(Method::DormandPrince54, &Options::default().fixed(h), t_end);
    assert_reproducible(Method::TrBdf2, &Options::default().fixed(h), t_end);
    // Adaptive, with the output interpolated on a grid.
    let adaptive = Options::with_tolerances(1e-5, 1e-8).output_every(0.05);
    assert_reproducible(Method::DormandPrince54, &adaptive, t_end);
    assert_reproducible(Method::TrBdf2, &adaptive, t_end);
}
