//! Measured orders of convergence, tolerance proportionality and dense-output accuracy, on
//! problems with exact solutions.
//!
//! The order is the least-squares slope of log(global error at `t_end`) against log(h)
//! over five step sizes (four halvings), chosen in the asymptotic range: errors well above
//! round-off, steps small enough that the leading error term dominates. Adaptive runs are
//! checked to meet their tolerance, and to spend work the way a method of their order
//! should as it tightens.

use mbs_integrators::{Method, OdeSystem, Options, Solution, SystemError, solve};

/// Harmonic oscillator `q̇ = v`, `v̇ = −ω² q`, `y = [q, v]`.
struct Oscillator {
    omega: f64,
}

impl Oscillator {
    fn exact(&self, t: f64, y0: [f64; 2]) -> [f64; 2] {
        let w = self.omega;
        let (s, c) = (w * t).sin_cos();
        [y0[0] * c + y0[1] / w * s, -y0[0] * w * s + y0[1] * c]
    }
}

impl OdeSystem for Oscillator {
    fn len(&self) -> usize {
        2
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = y[1];
        dy[1] = -self.omega * self.omega * y[0];
        Ok(())
    }
    fn second_order_split(&self) -> Option<usize> {
        Some(1)
    }
}

/// A forced Riccati equation `ẏ = −y² + u(t)² + u̇(t)` with `u(t) = 2 + sin(ω t)`: its
/// solution from `y(0) = 2` is `y = u`. Nonlinear, and non-autonomous (so the stage times
/// matter). It declares a split with no mechanical part, so semi-implicit Euler is plain
/// explicit Euler on it.
struct ForcedRiccati {
    omega: f64,
}

impl ForcedRiccati {
    fn exact(&self, t: f64) -> f64 {
        2.0 + (self.omega * t).sin()
    }
}

impl OdeSystem for ForcedRiccati {
    fn len(&self) -> usize {
        1
    }
    fn derivative(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        let u = self.exact(t);
        dy[0] = -y[0] * y[0] + u * u + self.omega * (self.omega * t).cos();
        Ok(())
    }
    fn second_order_split(&self) -> Option<usize> {
        Some(0)
    }
}

/// The logistic equation `ẏ = r y (1 − y)`, solution `y = 1 / (1 + (1/y0 − 1) e^{−r t})`.
struct Logistic {
    r: f64,
}

impl Logistic {
    fn exact(&self, t: f64, y0: f64) -> f64 {
        1.0 / (1.0 + (1.0 / y0 - 1.0) * (-self.r * t).exp())
    }
}

impl OdeSystem for Logistic {
    fn len(&self) -> usize {
        1
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = self.r * y[0] * (1.0 - y[0]);
        Ok(())
    }
}

const OSC: Oscillator = Oscillator { omega: 2.0 };
const OSC_Y0: [f64; 2] = [1.0, 0.5];
const OSC_T: f64 = 5.0;
/// Max-norm amplitude of the oscillator's state: √(q0² + (v0/ω)²) · ω.
const OSC_AMPLITUDE: f64 = 2.0615528128088303;
const RIC: ForcedRiccati = ForcedRiccati { omega: 2.0 };
const RIC_T: f64 = 4.0;
const LOG: Logistic = Logistic { r: 1.5 };
const LOG_Y0: f64 = 0.1;
const LOG_T: f64 = 4.0;

/// Max-norm distance between two states.
fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Numbers in scientific notation, for messages.
fn sci(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x:.3e}")).collect();
    format!("[{}]", parts.join(", "))
}

/// Least-squares slope of `log e` against `log h`.
fn slope(h: &[f64], e: &[f64]) -> f64 {
    let x: Vec<f64> = h.iter().map(|v| v.ln()).collect();
    let y: Vec<f64> = e.iter().map(|v| v.ln()).collect();
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    sxy / sxx
}

/// A convergence study: step sizes, global errors, fitted order, order of each halving.
struct Study {
    what: String,
    errors: Vec<f64>,
    order: f64,
    pairwise: Vec<f64>,
}

/// Global errors at `t_end` with fixed steps `t_end / (n0 · 2^k)`, `k = 0..5`.
fn study(
    what: &str,
    sys: &mut dyn OdeSystem,
    method: Method,
    y0: &[f64],
    t_end: f64,
    exact: &[f64],
    n0: usize,
) -> Study {
    let mut hs = Vec::new();
    let mut errors = Vec::new();
    for k in 0..5 {
        let n = n0 << k;
        let h = t_end / n as f64;
        // With a fixed step the tolerances only set how far TR-BDF2's Newton iterations
        // converge: far below the discretisation error.
        let opts = Options::with_tolerances(1e-10, 1e-12).fixed(h);
        let sol = solve(sys, method, 0.0, y0, t_end, &opts).unwrap();
        assert_eq!(sol.t_final, t_end);
        // `n` steps, or `n + 1` when the accumulated round-off of `t += h` leaves a sliver
        // before `t_end` (harmless for the error).
        assert!(
            sol.stats.steps == n || sol.stats.steps == n + 1,
            "{what}: {} steps for {n} of size {h}",
            sol.stats.steps
        );
        hs.push(h);
        errors.push(dist(&sol.y_final, exact));
    }
    let order = slope(&hs, &errors);
    let pairwise: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    let what = format!("{method:?} on {what}");
    println!(
        "{what}: h {:.3e}..{:.3e}, errors {}, order {order:.3} (halvings {:.2?})",
        hs[0],
        hs[4],
        sci(&errors),
        pairwise
    );
    Study {
        what,
        errors,
        order,
        pairwise,
    }
}

/// The fitted order is `expected ± tol` and every halving's `expected ± tol_halving`.
fn assert_order(s: &Study, expected: f64, tol: f64, tol_halving: f64) {
    assert!(
        (s.order - expected).abs() <= tol,
        "{}: measured order {:.3}, expected {expected} ± {tol} (errors {})",
        s.what,
        s.order,
        sci(&s.errors)
    );
    for (k, q) in s.pairwise.iter().enumerate() {
        assert!(
            (q - expected).abs() <= tol_halving,
            "{}: halving {k} gives order {q:.3}, expected {expected} ± {tol_halving} \
             (errors {})",
            s.what,
            sci(&s.errors)
        );
    }
}

fn oscillator(method: Method, n0: usize) -> Study {
    let exact = OSC.exact(OSC_T, OSC_Y0);
    study(
        "oscillator",
        &mut { OSC },
        method,
        &OSC_Y0,
        OSC_T,
        &exact,
        n0,
    )
}

fn riccati(method: Method, n0: usize) -> Study {
    let exact = [RIC.exact(RIC_T)];
    let y0 = [RIC.exact(0.0)];
    study(
        "forced Riccati",
        &mut { RIC },
        method,
        &y0,
        RIC_T,
        &exact,
        n0,
    )
}

fn logistic(method: Method, n0: usize) -> Study {
    let exact = [LOG.exact(LOG_T, LOG_Y0)];
    study(
        "logistic",
        &mut { LOG },
        method,
        &[LOG_Y0],
        LOG_T,
        &exact,
        n0,
    )
}

#[test]
fn semi_implicit_euler_is_first_order() {
    let m = Method::SemiImplicitEuler;
    assert_order(&oscillator(m, 100), 1.0, 0.1, 0.1);
    assert_order(&riccati(m, 100), 1.0, 0.1, 0.1);
}

#[test]
fn rk4_is_fourth_order() {
    let m = Method::Rk4;
    assert_order(&oscillator(m, 20), 4.0, 0.15, 0.15);
    assert_order(&riccati(m, 40), 4.0, 0.15, 0.25);
    assert_order(&logistic(m, 10), 4.0, 0.15, 0.25);
}

#[test]
fn dormand_prince_with_a_fixed_step_is_fifth_order() {
    // DOPRI5's principal error coefficients are small by design, so on nonlinear problems
    // the O(h⁶) term is visible until the errors approach round-off: the halvings come
    // down to 5 from above. Stay above 1e-11.
    let m = Method::DormandPrince54;
    assert_order(&oscillator(m, 20), 5.0, 0.1, 0.1);
    assert_order(&riccati(m, 20), 5.0, 0.2, 0.35);
}

#[test]
fn tr_bdf2_with_a_fixed_step_is_second_order() {
    let m = Method::TrBdf2;
    assert_order(&oscillator(m, 20), 2.0, 0.1, 0.1);
    assert_order(&riccati(m, 40), 2.0, 0.1, 0.1);
    assert_order(&logistic(m, 20), 2.0, 0.1, 0.1);
}

#[test]
fn ros34pw2_with_a_fixed_step_is_third_order() {
    // The Riccati problem depends on time and the method leaves out ∂f/∂t; from its
    // coarsest steps the order comes up to 3 (halvings 2.84, 2.93, 2.97, 2.98).
    let m = Method::Ros34Pw2;
    assert_order(&oscillator(m, 40), 3.0, 0.1, 0.15);
    assert_order(&riccati(m, 160), 3.0, 0.1, 0.2);
    assert_order(&logistic(m, 80), 3.0, 0.1, 0.15);
}

/// Runs `method` adaptively at each tolerance (atol = rtol / 100), returning
/// (rtol, global error, solution).
fn adaptive(
    method: Method,
    what: &str,
    run: &mut dyn FnMut(&Options) -> (f64, Solution),
) -> Vec<(f64, f64, Solution)> {
    [1e-6, 1e-8, 1e-10]
        .iter()
        .map(|&rtol| {
            let opts = Options {
                // A wrong error estimate shows as runaway work: fail fast.
                max_steps: 100_000,
                ..Options::with_tolerances(rtol, rtol * 1e-2)
            };
            let (err, sol) = run(&opts);
            println!(
                "{method:?} on {what}, rtol {rtol:.0e}: global error {err:.3e} ({:.2} rtol), \
                 {} steps, {} rejected, {} f evals",
                err / rtol,
                sol.stats.steps,
                sol.stats.rejected,
                sol.stats.derivative_evals
            );
            (rtol, err, sol)
        })
        .collect()
}

/// As the tolerance tightens 100× at a time, the global error falls by at least
/// `min_gain`, and the number of steps grows like `100^(1/(order + 1))` (error-per-step
/// control of a method of that order), within a factor 1.5.
fn assert_tightening(what: &str, runs: &[(f64, f64, Solution)], order: f64, min_gain: f64) {
    for w in runs.windows(2) {
        let ((r0, e0, s0), (r1, e1, s1)) = (&w[0], &w[1]);
        assert!(
            e1 * min_gain <= *e0,
            "{what}: error {e0:.3e} at rtol {r0:.0e}, {e1:.3e} at rtol {r1:.0e}"
        );
        let growth = s1.stats.steps as f64 / s0.stats.steps as f64;
        let ideal = (r0 / r1).powf(1.0 / (order + 1.0));
        assert!(
            growth <= 1.5 * ideal && growth >= ideal / 1.5,
            "{what}: steps grew {growth:.2}× from rtol {r0:.0e} to {r1:.0e}, expected \
             about {ideal:.2}×"
        );
    }
}

fn oscillator_runs(m: Method) -> Vec<(f64, f64, Solution)> {
    let exact = OSC.exact(OSC_T, OSC_Y0);
    adaptive(m, "oscillator", &mut |o| {
        let s = solve(&mut { OSC }, m, 0.0, &OSC_Y0, OSC_T, o).unwrap();
        (dist(&s.y_final, &exact), s)
    })
}

fn logistic_runs(m: Method, t_end: f64) -> Vec<(f64, f64, Solution)> {
    let exact = LOG.exact(t_end, LOG_Y0);
    adaptive(m, &format!("logistic to {t_end}"), &mut |o| {
        let s = solve(&mut { LOG }, m, 0.0, &[LOG_Y0], t_end, o).unwrap();
        ((s.y_final[0] - exact).abs(), s)
    })
}

#[test]
fn adaptive_dormand_prince_meets_its_tolerance() {
    let m = Method::DormandPrince54;
    for (what, runs) in [
        ("oscillator", oscillator_runs(m)),
        ("logistic", logistic_runs(m, LOG_T)),
    ] {
        for (rtol, err, _) in &runs {
            assert!(
                *err <= 10.0 * rtol,
                "DOPRI5 {what}: global error {err:.3e} at rtol {rtol:.0e}"
            );
        }
        // Error roughly proportional to the tolerance (at least 20× smaller per 100×).
        assert_tightening(what, &runs, 5.0, 20.0);
    }
}

#[test]
fn adaptive_tr_bdf2_meets_its_tolerance() {
    // Error-per-step control of a second-order method: about tol^(−1/3) steps, each
    // leaving a local error up to the tolerance, so on a problem that does not damp them
    // (the oscillator) the global error is about (steps × tol), that is ∝ tol^(2/3), not
    // within a fixed factor of tol. On a contractive one (the logistic settling to 1) it is.
    let m = Method::TrBdf2;
    let runs = oscillator_runs(m);
    for (rtol, err, sol) in &runs {
        let bound = sol.stats.steps as f64 * rtol * OSC_AMPLITUDE;
        assert!(
            *err <= bound,
            "TR-BDF2 oscillator: global error {err:.3e} at rtol {rtol:.0e} above \
             steps × rtol × amplitude = {bound:.3e}"
        );
    }
    // tol^(2/3): 100× tighter gives about 21× smaller.
    assert_tightening("oscillator", &runs, 2.0, 10.0);
    let runs = logistic_runs(m, 10.0);
    for (rtol, err, _) in &runs {
        assert!(
            *err <= 100.0 * rtol,
            "TR-BDF2 logistic: global error {err:.3e} at rtol {rtol:.0e}"
        );
    }
    assert_tightening("logistic", &runs, 2.0, 10.0);
}

#[test]
fn adaptive_ros34pw2_meets_its_tolerance() {
    // Error-per-step control of a third-order method with a second-order estimate: about
    // tol^(−1/3) steps; on the oscillator the global error is at most steps × tol.
    let m = Method::Ros34Pw2;
    let runs = oscillator_runs(m);
    for (rtol, err, sol) in &runs {
        let bound = sol.stats.steps as f64 * rtol * OSC_AMPLITUDE;
        assert!(
            *err <= bound,
            "ROS34PW2 oscillator: global error {err:.3e} at rtol {rtol:.0e} above \
             steps × rtol × amplitude = {bound:.3e}"
        );
    }
    assert_tightening("oscillator", &runs, 2.0, 10.0);
    let runs = logistic_runs(m, 10.0);
    for (rtol, err, _) in &runs {
        assert!(
            *err <= 100.0 * rtol,
            "ROS34PW2 logistic: global error {err:.3e} at rtol {rtol:.0e}"
        );
    }
    assert_tightening("logistic", &runs, 2.0, 10.0);
}

#[test]
fn dormand_prince_dense_output_is_as_accurate_as_the_steps() {
    let t_end = 10.0;
    for rtol in [1e-6, 1e-9] {
        let opts = Options::with_tolerances(rtol, rtol * 1e-2).output_every(0.01);
        let sol = solve(
            &mut { OSC },
            Method::DormandPrince54,
            0.0,
            &OSC_Y0,
            t_end,
            &opts,
        )
        .unwrap();
        assert_eq!(sol.len(), 1001);
        let mut max_err: f64 = 0.0;
        for i in 0..sol.len() {
            assert!((sol.t[i] - 0.01 * i as f64).abs() < 1e-12);
            max_err = max_err.max(dist(sol.state(i), &OSC.exact(sol.t[i], OSC_Y0)));
        }
        let end_err = dist(&sol.y_final, &OSC.exact(t_end, OSC_Y0));
        println!(
            "DOPRI5 dense output, rtol {rtol:.0e}: {} steps, {} grid points, max grid error \
             {max_err:.3e}, error at t_end {end_err:.3e}",
            sol.stats.steps,
            sol.len()
        );
        // Far fewer steps than grid points: most grid values are interpolated.
        assert!(sol.stats.steps < sol.len() / 2);
        assert!(
            max_err <= 10.0 * rtol,
            "rtol {rtol:.0e}: grid error {max_err:.3e}"
        );
    }
}

#[test]
fn dormand_prince_dense_output_converges_at_fourth_order_or_better() {
    // Fixed steps, output at one and two thirds of each step. The continuous extension
    // is of order 4 (local error O(h⁵), not propagated) on top of the O(h⁵) global error,
    // so the error between steps must shrink at least like h⁴; one wrong dense-output
    // coefficient would leave an O(h) error.
    let t_end = 3.0;
    let mut hs = Vec::new();
    let mut errs = Vec::new();
    for k in 0..5 {
        let h = t_end / (6usize << k) as f64;
        let opts = Options::default().fixed(h).output_every(h / 3.0);
        let sol = solve(
            &mut { OSC },
            Method::DormandPrince54,
            0.0,
            &OSC_Y0,
            t_end,
            &opts,
        )
        .unwrap();
        let mut max_err: f64 = 0.0;
        for i in (0..sol.len()).filter(|i| i % 3 != 0) {
            max_err = max_err.max(dist(sol.state(i), &OSC.exact(sol.t[i], OSC_Y0)));
        }
        hs.push(h);
        errs.push(max_err);
    }
    let p = slope(&hs, &errs);
    println!(
        "DOPRI5 dense output between steps: errors {}, order {p:.3}",
        sci(&errs)
    );
    assert!(
        p >= 3.8,
        "dense output order {p:.3} (errors {})",
        sci(&errs)
    );
}
