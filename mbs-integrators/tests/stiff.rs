//! Stiff problems: Robertson's chemical kinetics and Van der Pol's oscillator against
//! published reference solutions, the work TR-BDF2 saves over an explicit method on them,
//! and L-stability on a stiff linear mass-spring chain with an exact solution.

use mbs_integrators::problems::{Robertson, VanDerPol};
use mbs_integrators::{
    IntegratorError, Method, OdeSystem, Options, Solution, Stats, SystemError, solve,
};

fn print_stats(what: &str, s: &Stats) {
    println!(
        "{what}: {} steps, {} rejected, {} derivative evals, {} Jacobian evals, {} LU, {} \
         Newton iterations, {} Newton failures",
        s.steps,
        s.rejected,
        s.derivative_evals,
        s.jacobian_evals,
        s.lu_decompositions,
        s.newton_iterations,
        s.newton_failures
    );
}

/// Numbers in scientific notation with `digits` decimals, for messages.
fn sci(v: &[f64], digits: usize) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x:.digits$e}")).collect();
    format!("[{}]", parts.join(", "))
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

const ROBER_Y0: [f64; 3] = Robertson::Y0;
const ROBER_40: [f64; 3] = Robertson::AT_40;
const ROBER_1E11: [f64; 3] = Robertson::AT_1E11;

fn robertson_opts() -> Options {
    Options {
        max_steps: 50_000,
        ..Options::with_tolerances(1e-6, 1e-10)
    }
}

fn rober(method: Method, analytic: bool, t_end: f64, opts: &Options) -> Solution {
    solve(
        &mut Robertson {
            analytic_jacobian: analytic,
        },
        method,
        0.0,
        &ROBER_Y0,
        t_end,
        opts,
    )
    .unwrap()
}

/// Robertson to t = 40 by `method`, each concentration checked against Hairer & Wanner's
/// reference to 1e-4.
fn rober_40(method: Method, name: &str, analytic: bool) -> Solution {
    let sol = rober(method, analytic, 40.0, &robertson_opts());
    let y = &sol.y_final;
    let errs: Vec<f64> = (0..3).map(|i| rel(y[i], ROBER_40[i])).collect();
    print_stats(
        &format!("{name} Robertson to t = 40, analytic Jacobian {analytic}"),
        &sol.stats,
    );
    println!("  y = {}, relative errors {}", sci(y, 10), sci(&errs, 2));
    for i in 0..3 {
        assert!(
            errs[i] < 1e-4,
            "{name}: y{} = {:e}, relative error {:e}",
            i + 1,
            y[i],
            errs[i]
        );
    }
    sol
}

#[test]
fn tr_bdf2_robertson_at_t_40_matches_hairer_wanner() {
    let mut sols = Vec::new();
    for analytic in [false, true] {
        let sol = rober_40(Method::TrBdf2, "TR-BDF2", analytic);
        let y = &sol.y_final;
        // y1 + y2 + y3 is conserved to round-off: the columns of J sum to zero, so
        // eᵀ(I − c J)⁻¹ = eᵀ and every Newton iterate already has the sum of its ψ.
        let mass = y.iter().sum::<f64>() - 1.0;
        assert!(mass.abs() < 1e-12, "mass drift {mass:e}");
        // The Jacobian is kept across steps.
        assert!(10 * sol.stats.jacobian_evals < sol.stats.steps);
        sols.push(sol);
    }
    // Analytic and finite-difference Jacobians give the same answer to far below the
    // tolerance (they only change how Newton converges).
    for i in 0..3 {
        let d = rel(sols[0].y_final[i], sols[1].y_final[i]);
        assert!(d < 1e-6, "y{}: FD and analytic runs differ by {d:e}", i + 1);
    }
}

#[test]
fn ros34pw2_robertson_at_t_40_matches_hairer_wanner() {
    for analytic in [false, true] {
        let sol = rober_40(Method::Ros34Pw2, "ROS34PW2", analytic);
        // Linearly implicit: no Newton iteration, at most four evaluations a step (three
        // for a rejected one) besides the Jacobians'.
        assert_eq!(sol.stats.newton_iterations, 0);
        let jacobian_evals = if analytic {
            0
        } else {
            3 * sol.stats.jacobian_evals
        };
        assert!(
            sol.stats.derivative_evals
                <= 4 * sol.stats.steps + 3 * sol.stats.rejected + jacobian_evals + 3,
            "{:?}",
            sol.stats
        );
        if analytic {
            // The system's own Jacobian is taken at every step.
            assert_eq!(sol.stats.jacobian_evals, sol.stats.steps, "{:?}", sol.stats);
        } else {
            // A W-method keeps its finite-difference Jacobian across steps.
            assert!(
                5 * sol.stats.jacobian_evals < sol.stats.steps,
                "{:?}",
                sol.stats
            );
        }
    }
}

#[test]
fn ros34pw2_van_der_pol_matches_the_test_set() {
    for analytic in [false, true] {
        let sol = vdp(Method::Ros34Pw2, 1e-6, analytic, &vdp_opts(50_000)).unwrap();
        let y = &sol.y_final;
        let errs: Vec<f64> = (0..2).map(|i| rel(y[i], VDP_2[i])).collect();
        print_stats(
            &format!("ROS34PW2 Van der Pol eps = 1e-6, analytic Jacobian {analytic}"),
            &sol.stats,
        );
        println!("  y = {}, relative errors {}", sci(y, 10), sci(&errs, 2));
        assert!(errs[0] < 1e-3 && errs[1] < 1e-3, "relative errors {errs:?}");
    }
}

#[test]
fn tr_bdf2_robertson_at_t_1e11_matches_the_test_set() {
    // On the long run y1 (~2e-8) and y2 (~8e-14) sit below or near atol = 1e-10, so their
    // relative accuracy is set by atol / y1 ≈ 5e-3, not by rtol: ask for 2e-2. y2 is in
    // quasi-equilibrium with y1 (3e7 y2² ≈ 0.04 y1 + ...), so it follows y1's relative
    // error. y3 ≈ 1 is held to rtol.
    for analytic in [false, true] {
        let sol = rober(Method::TrBdf2, analytic, 1e11, &robertson_opts());
        let y = &sol.y_final;
        let errs: Vec<f64> = (0..3).map(|i| rel(y[i], ROBER_1E11[i])).collect();
        let mass = y.iter().sum::<f64>() - 1.0;
        print_stats(
            &format!("TR-BDF2 Robertson to t = 1e11, analytic Jacobian {analytic}"),
            &sol.stats,
        );
        println!(
            "  y = {}, relative errors {}, mass drift {mass:.1e}",
            sci(y, 10),
            sci(&errs, 2)
        );
        assert!(
            errs[0] < 2e-2,
            "y1 = {:e}, relative error {:e}",
            y[0],
            errs[0]
        );
        assert!(
            errs[1] < 2e-2,
            "y2 = {:e}, relative error {:e}",
            y[1],
            errs[1]
        );
        assert!(
            errs[2] < 1e-8,
            "y3 = {:e}, relative error {:e}",
            y[2],
            errs[2]
        );
        assert!(mass.abs() < 1e-12, "mass drift {mass:e}");
        assert!(y.iter().all(|&v| v > 0.0), "negative concentration: {y:?}");
        assert!(sol.stats.jacobian_evals < sol.stats.steps);
    }
}

/// The Test Set's reference for VDPOL at t = 2.
const VDP_2: [f64; 2] = [1.706167732170469, -0.8928097010248125];

fn vdp(
    method: Method,
    eps: f64,
    analytic: bool,
    opts: &Options,
) -> Result<Solution, IntegratorError> {
    solve(
        &mut VanDerPol {
            eps,
            analytic_jacobian: analytic,
        },
        method,
        0.0,
        &[2.0, 0.0],
        2.0,
        opts,
    )
}

fn vdp_opts(max_steps: usize) -> Options {
    Options {
        max_steps,
        ..Options::with_tolerances(1e-6, 1e-6)
    }
}

#[test]
fn tr_bdf2_van_der_pol_matches_the_test_set() {
    let mut sols = Vec::new();
    for analytic in [false, true] {
        let sol = vdp(Method::TrBdf2, 1e-6, analytic, &vdp_opts(50_000)).unwrap();
        let y = &sol.y_final;
        let errs: Vec<f64> = (0..2).map(|i| rel(y[i], VDP_2[i])).collect();
        print_stats(
            &format!("TR-BDF2 Van der Pol eps = 1e-6, analytic Jacobian {analytic}"),
            &sol.stats,
        );
        println!("  y = {}, relative errors {}", sci(y, 10), sci(&errs, 2));
        // Second order at 1e-6 through a fast transition (at t ≈ 0.81) and back onto
        // the slow manifold: three to four digits.
        assert!(errs[0] < 1e-3 && errs[1] < 1e-3, "relative errors {errs:?}");
        assert!(
            20 * sol.stats.jacobian_evals < sol.stats.steps,
            "the Jacobian should be reused: {} evaluations for {} steps",
            sol.stats.jacobian_evals,
            sol.stats.steps
        );
        sols.push(sol);
    }
    // The analytic Jacobian only changes Newton's convergence, not the answer.
    for i in 0..2 {
        let d = (sols[0].y_final[i] - sols[1].y_final[i]).abs();
        assert!(d < 1e-5, "y{}: FD and analytic runs differ by {d:e}", i + 1);
    }
    // Without finite differences it needs fewer derivative evaluations.
    assert!(sols[1].stats.derivative_evals < sols[0].stats.derivative_evals);
    // With the system's own Jacobian every evaluation is a Newton iteration but for the
    // start (f at t0 and the automatic first step's trial) and the step-start rate each
    // Jacobian is taken with: a converged stage takes its rate from the stage equation,
    // not from one more evaluation.
    let s = &sols[1].stats;
    assert!(
        s.derivative_evals <= s.newton_iterations + s.jacobian_evals + 2,
        "{} evaluations for {} Newton iterations and {} Jacobians",
        s.derivative_evals,
        s.newton_iterations,
        s.jacobian_evals
    );
}

#[test]
fn tr_bdf2_does_far_less_work_than_dopri5_on_robertson() {
    let opts = robertson_opts();
    let implicit = rober(Method::TrBdf2, false, 40.0, &opts);
    let explicit = rober(
        Method::DormandPrince54,
        false,
        40.0,
        &Options {
            max_steps: 1_000_000,
            ..opts
        },
    );
    print_stats("TR-BDF2 Robertson to t = 40", &implicit.stats);
    print_stats("DOPRI5 Robertson to t = 40", &explicit.stats);
    let (a, b) = (
        implicit.stats.derivative_evals,
        explicit.stats.derivative_evals,
    );
    println!(
        "  DOPRI5 / TR-BDF2 derivative evaluations: {:.0}",
        b as f64 / a as f64
    );
    // DOPRI5 is stable but crawls at its stability limit: |h λ| ≤ 3.3 with the stiff
    // eigenvalue λ ≈ −(1e4 y3 + 6e7 y2) ≈ −3.4e3 by t = 40, so h ≈ 1e-3.
    assert!(10 * a < b, "TR-BDF2 {a} derivative evaluations, DOPRI5 {b}");
    // And it is accurate too (stability, not accuracy, limits its step).
    for (y, y_ref) in explicit.y_final.iter().zip(ROBER_40) {
        assert!(rel(*y, y_ref) < 1e-4, "DOPRI5: {y:e} against {y_ref:e}");
    }
}

#[test]
fn tr_bdf2_does_far_less_work_than_dopri5_on_van_der_pol() {
    // ε = 1e-5: stiff enough that DOPRI5, bound by stability on the slow manifold, takes
    // about 1e5 steps and still finishes quickly. (At ε = 1e-3 and rtol 1e-6 the problem
    // is not stiff enough for a second-order method to win: DOPRI5 is cheaper there.)
    let opts = vdp_opts(2_000_000);
    let implicit = vdp(Method::TrBdf2, 1e-5, false, &opts).unwrap();
    let explicit = vdp(Method::DormandPrince54, 1e-5, false, &opts).unwrap();
    print_stats("TR-BDF2 Van der Pol eps = 1e-5", &implicit.stats);
    print_stats("DOPRI5 Van der Pol eps = 1e-5", &explicit.stats);
    let (a, b) = (
        implicit.stats.derivative_evals,
        explicit.stats.derivative_evals,
    );
    println!(
        "  DOPRI5 / TR-BDF2 derivative evaluations: {:.0}",
        b as f64 / a as f64
    );
    assert!(10 * a < b, "TR-BDF2 {a} derivative evaluations, DOPRI5 {b}");
    // Both solve the same problem.
    for i in 0..2 {
        let d = (implicit.y_final[i] - explicit.y_final[i]).abs();
        assert!(d < 1e-3, "y{}: TR-BDF2 and DOPRI5 differ by {d:e}", i + 1);
    }
    // At ε = 1e-6 DOPRI5 would need over a million steps: bounded, it gives up early.
    match vdp(Method::DormandPrince54, 1e-6, false, &vdp_opts(200_000)) {
        Err(IntegratorError::TooManySteps { t, max_steps }) => {
            println!("DOPRI5 Van der Pol eps = 1e-6: {max_steps} steps reach only t = {t:.3}");
            assert!(t < 1.0);
        }
        other => panic!("DOPRI5 on eps = 1e-6 should run out of steps: {other:?}"),
    }
}

/// Two unit masses in a chain: a soft spring (`k_soft`) from the wall to mass 1, a very
/// stiff one (`k_stiff`) from mass 1 to mass 2, each with a dashpot `beta · k` in
/// parallel (stiffness-proportional damping, so the normal modes stay uncoupled).
/// `y = [x1, x2, v1, v2]`. Linear, with an exact modal solution.
struct StiffChain {
    k_soft: f64,
    k_stiff: f64,
    beta: f64,
}

impl OdeSystem for StiffChain {
    fn len(&self) -> usize {
        4
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        let soft = self.k_soft * (y[0] + self.beta * y[2]);
        let stiff = self.k_stiff * (y[1] - y[0] + self.beta * (y[3] - y[2]));
        dy[0] = y[2];
        dy[1] = y[3];
        dy[2] = -soft + stiff;
        dy[3] = -stiff;
        Ok(())
    }
    fn second_order_split(&self) -> Option<usize> {
        Some(2)
    }
}

/// A normal mode: natural frequency, damping ratio and unit shape.
struct Mode {
    omega: f64,
    zeta: f64,
    shape: [f64; 2],
}

impl StiffChain {
    /// The two modes of `ẍ + β K ẋ + K x = 0`, `K = [[k_s + k_f, −k_f], [−k_f, k_f]]`,
    /// slow first (the small eigenvalue as det / large, without cancellation).
    fn modes(&self) -> [Mode; 2] {
        let (ks, kf) = (self.k_soft, self.k_stiff);
        let tr = ks + 2.0 * kf;
        let det = ks * kf;
        let fast = 0.5 * (tr + (tr * tr - 4.0 * det).sqrt());
        let slow = det / fast;
        // (K − λ I) φ = 0 from the second row: φ ∝ [k_f − λ, k_f].
        let mode = |lambda: f64| {
            let (a, b) = (kf - lambda, kf);
            let n = a.hypot(b);
            let omega = lambda.sqrt();
            Mode {
                omega,
                zeta: 0.5 * self.beta * omega,
                shape: [a / n, b / n],
            }
        };
        [mode(slow), mode(fast)]
    }
}

impl Mode {
    /// Modal coordinate and velocity of the state `y`.
    fn project(&self, y: &[f64]) -> (f64, f64) {
        (
            self.shape[0] * y[0] + self.shape[1] * y[1],
            self.shape[0] * y[2] + self.shape[1] * y[3],
        )
    }
    /// Amplitude `√(η² + (η̇/ω)²)` (constant in the exact undamped solution).
    fn amplitude(&self, y: &[f64]) -> f64 {
        let (e, de) = self.project(y);
        e.hypot(de / self.omega)
    }
    /// Distance between two (coordinate, velocity) pairs, velocity scaled by 1/ω.
    fn distance(&self, a: (f64, f64), b: (f64, f64)) -> f64 {
        (a.0 - b.0).abs().max((a.1 - b.1).abs() / self.omega)
    }
    /// The exact modal coordinate and velocity at `t` from `y0` (underdamped).
    fn exact(&self, y0: &[f64], t: f64) -> (f64, f64) {
        assert!(self.zeta < 1.0);
        let (e0, de0) = self.project(y0);
        let sigma = self.zeta * self.omega;
        let wd = self.omega * (1.0 - self.zeta * self.zeta).sqrt();
        let (a, b) = (e0, (de0 + sigma * e0) / wd);
        let (s, c) = (wd * t).sin_cos();
        let decay = (-sigma * t).exp();
        (
            decay * (a * c + b * s),
            decay * ((b * wd - sigma * a) * c - (a * wd + sigma * b) * s),
        )
    }
}

#[test]
fn tr_bdf2_damps_the_stiff_mode_and_keeps_the_slow_one_accurate() {
    // Undamped: the exact stiff mode oscillates forever; an L-stable method with
    // h ω_fast ≫ 1 damps it (the method's R(hλ) → 0) instead of amplifying it.
    let mut sys = StiffChain {
        k_soft: 1.0,
        k_stiff: 1e8,
        beta: 0.0,
    };
    let [slow, fast] = sys.modes();
    // The stiff spring starts stretched by 1e-3: 50 J in the fast mode against 0.5 J in
    // the slow one.
    let y0 = [1.0, 1.001, 0.0, 0.0];
    let h = 0.01;
    let explicit_limit = 2.0 / fast.omega;
    println!(
        "stiff chain: slow ω = {:.6}, fast ω = {:.1}, h = {h} = {:.0} × 2/ω_fast",
        slow.omega,
        fast.omega,
        h / explicit_limit
    );
    assert!(h > 50.0 * explicit_limit);
    let t_end = 20.0;
    let fast0 = fast.amplitude(&y0);
    let slow0 = slow.amplitude(&y0);
    let sol = solve(
        &mut sys,
        Method::TrBdf2,
        0.0,
        &y0,
        t_end,
        &Options::with_tolerances(1e-10, 1e-12).fixed(h),
    )
    .unwrap();
    print_stats("TR-BDF2 stiff chain, fixed h = 0.01", &sol.stats);
    let mut max_fast: f64 = 0.0;
    let mut max_slow_err: f64 = 0.0;
    for i in 1..sol.len() {
        let y = sol.state(i);
        let a = fast.amplitude(y);
        assert!(
            a <= fast0,
            "fast amplitude {a:e} at t = {} above its initial {fast0:e}",
            sol.t[i]
        );
        if sol.t[i] >= 0.1 {
            max_fast = max_fast.max(a);
        }
        let err = slow.distance(slow.project(y), slow.exact(&y0, sol.t[i]));
        max_slow_err = max_slow_err.max(err);
    }
    let fast_end = fast.amplitude(&sol.y_final);
    println!(
        "  fast amplitude {fast0:.3e} → {fast_end:.3e} (max after t = 0.1: {max_fast:.3e}); \
         slow amplitude {slow0:.3e}, max slow-mode error {max_slow_err:.3e}"
    );
    // After ten steps the stiff mode is gone (|R(h λ)| ≪ 1 at |h λ| ≈ 141).
    assert!(
        max_fast < 1e-9 * fast0,
        "fast mode not damped: {max_fast:e}"
    );
    // The slow mode (ω h ≈ 0.007) is integrated at second order: phase error about
    // (ω h)² ω t / 12 · a few, 4e-5 relative here.
    assert!(
        max_slow_err < 2e-4 * slow0,
        "slow-mode error {max_slow_err:e}"
    );
    // An explicit method at the same step blows up.
    let rk4 = solve(
        &mut sys,
        Method::Rk4,
        0.0,
        &y0,
        t_end,
        &Options::default().fixed(h),
    );
    assert!(
        matches!(rk4, Err(IntegratorError::NonFiniteState { .. })),
        "RK4 at 70× its stability limit: {rk4:?}"
    );
}

#[test]
fn adaptive_tr_bdf2_steps_over_the_damped_stiff_mode() {
    // With a dashpot on the stiff spring (ζ_fast ≈ 0.71, ζ_slow ≈ 4e-5) the stiff mode
    // is a transient of a millisecond: the adaptive method resolves it, then takes steps
    // set by the slow mode, far beyond the explicit stability limit.
    let mut sys = StiffChain {
        k_soft: 1.0,
        k_stiff: 1e8,
        beta: 1e-4,
    };
    let [slow, fast] = sys.modes();
    println!(
        "damped stiff chain: ζ slow {:.2e}, ζ fast {:.3}",
        slow.zeta, fast.zeta
    );
    let y0 = [1.0, 1.001, 0.0, 0.0];
    let t_end = 20.0;
    let opts = Options {
        max_steps: 20_000,
        ..Options::with_tolerances(1e-6, 1e-8)
    };
    let sol = solve(&mut sys, Method::TrBdf2, 0.0, &y0, t_end, &opts).unwrap();
    print_stats("adaptive TR-BDF2 damped stiff chain, rtol 1e-6", &sol.stats);
    let slow_err = slow.distance(slow.project(&sol.y_final), slow.exact(&y0, t_end));
    let fast_err = fast.distance(fast.project(&sol.y_final), fast.exact(&y0, t_end));
    let mut max_slow_err: f64 = 0.0;
    for i in 0..sol.len() {
        let err = slow.distance(slow.project(sol.state(i)), slow.exact(&y0, sol.t[i]));
        max_slow_err = max_slow_err.max(err);
    }
    let explicit_steps = t_end / (2.0 / fast.omega);
    println!(
        "  slow-mode error at t_end {slow_err:.3e} (max {max_slow_err:.3e}), fast-mode error \
         {fast_err:.3e}; an explicit method would need over {explicit_steps:.0} steps"
    );
    assert!((sol.stats.steps as f64) < explicit_steps / 50.0);
    assert!(max_slow_err < 1e-3, "slow-mode error {max_slow_err:e}");
    assert!(fast_err < 1e-9, "fast-mode error {fast_err:e}");
}
