//! Honest failure: every way a solve can go wrong is an error that says when and why,
//! never a silent wrong answer or a hang.

use mbs_integrators::{IntegratorError, Method, OdeSystem, Options, SystemError, solve};

/// ẏ = y², y(0) = 1: y = 1/(1 − t) blows up at t = 1.
struct BlowUp;

impl OdeSystem for BlowUp {
    fn len(&self) -> usize {
        1
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = y[0] * y[0];
        Ok(())
    }
}

#[test]
fn a_finite_time_blow_up_stops_with_the_time_it_happened() {
    for method in [Method::DormandPrince54, Method::TrBdf2] {
        let e = solve(&mut BlowUp, method, 0.0, &[1.0], 2.0, &Options::default()).unwrap_err();
        let t = match e {
            IntegratorError::StepSizeTooSmall { t, .. } => t,
            IntegratorError::NonFiniteState { t, .. } => t,
            IntegratorError::NewtonFailure { t, .. } => t,
            ref other => panic!("{method:?}: unexpected {other:?}"),
        };
        assert!(
            (0.99..=1.001).contains(&t),
            "{method:?} failed at t = {t}: {e}"
        );
        assert!(e.to_string().contains("at t = "), "{e}");
    }
    // A fixed-step method walks into the overflow and says so.
    let e = solve(
        &mut BlowUp,
        Method::Rk4,
        0.0,
        &[1.0],
        2.0,
        &Options::default().fixed(0.01),
    )
    .unwrap_err();
    assert!(
        matches!(e, IntegratorError::NonFiniteState { t, .. } if t > 0.9 && t <= 2.0),
        "{e:?}"
    );
}

/// A system that fails, or returns NaN, after a given time.
struct Breaks {
    at: f64,
    nan: bool,
}

impl OdeSystem for Breaks {
    fn len(&self) -> usize {
        2
    }
    fn derivative(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        if t > self.at && !self.nan {
            return Err(SystemError::new("felt law out of range"));
        }
        dy[0] = y[1];
        dy[1] = if t > self.at { f64::NAN } else { -y[0] };
        Ok(())
    }
}

#[test]
fn system_errors_and_nan_are_reported_with_their_time() {
    for method in [Method::Rk4, Method::DormandPrince54, Method::TrBdf2] {
        let opts = if method == Method::Rk4 {
            Options::default().fixed(0.01)
        } else {
            Options::default()
        };
        let e = solve(
            &mut Breaks {
                at: 0.5,
                nan: false,
            },
            method,
            0.0,
            &[1.0, 0.0],
            1.0,
            &opts,
        )
        .unwrap_err();
        match &e {
            IntegratorError::System { t, source } => {
                assert!(*t > 0.5 && *t < 0.6, "{method:?}: {e}");
                assert!(source.0.contains("felt law"));
            }
            other => panic!("{method:?}: {other:?}"),
        }
        let e = solve(
            &mut Breaks { at: 0.5, nan: true },
            method,
            0.0,
            &[1.0, 0.0],
            1.0,
            &opts,
        )
        .unwrap_err();
        match e {
            IntegratorError::NonFiniteState { t, .. }
            | IntegratorError::StepSizeTooSmall { t, .. } => {
                assert!((0.49..0.6).contains(&t), "{method:?} at {t}")
            }
            IntegratorError::NewtonFailure { t, .. } => assert!((0.49..0.6).contains(&t)),
            other => panic!("{method:?}: {other:?}"),
        }
    }
}

/// ẏ = 1 + y², y(0) = 1 (y = tan(t + π/4)). With h = 1 the trapezoidal stage
/// `z = ψ + c (1 + z²)` (c = h d ≈ 0.29, ψ ≈ 1.59) has no real root: Newton cannot converge.
struct Riccati;

impl OdeSystem for Riccati {
    fn len(&self) -> usize {
        1
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = 1.0 + y[0] * y[0];
        Ok(())
    }
}

#[test]
fn newton_failure_at_a_fixed_step_is_an_error() {
    let e = solve(
        &mut Riccati,
        Method::TrBdf2,
        0.0,
        &[1.0],
        1.0,
        &Options::default().fixed(1.0),
    )
    .unwrap_err();
    assert!(
        matches!(e, IntegratorError::NewtonFailure { t, .. } if t == 0.0),
        "{e:?}"
    );
    assert!(e.to_string().contains("Newton"), "{e}");
}

#[test]
fn bad_options_and_initial_conditions_are_named() {
    let mut sys = BlowUp;
    let cases: Vec<(Options, Method, &str)> = vec![
        (
            Options {
                rtol: -1.0,
                ..Options::default()
            },
            Method::DormandPrince54,
            "rtol",
        ),
        (
            Options {
                atol: f64::NAN,
                ..Options::default()
            },
            Method::DormandPrince54,
            "atol",
        ),
        (Options::default(), Method::Rk4, "fixed_step"),
        (
            Options::default().fixed(0.0),
            Method::DormandPrince54,
            "fixed_step",
        ),
        (
            Options {
                max_step: 0.0,
                ..Options::default()
            },
            Method::TrBdf2,
            "max_step",
        ),
        (
            Options::default().output_every(-1.0),
            Method::TrBdf2,
            "output_step",
        ),
        (
            Options {
                event_samples: 0,
                ..Options::default()
            },
            Method::TrBdf2,
            "event_samples",
        ),
    ];
    for (opts, method, field) in cases {
        let e = solve(&mut sys, method, 0.0, &[0.5], 0.1, &opts).unwrap_err();
        assert!(
            matches!(&e, IntegratorError::InvalidOption { option, .. } if *option == field),
            "{field}: {e:?}"
        );
    }
    let e = solve(
        &mut sys,
        Method::DormandPrince54,
        0.0,
        &[0.5, 1.0],
        0.1,
        &Options::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("length 2"), "{e}");
    let e = solve(
        &mut sys,
        Method::DormandPrince54,
        0.0,
        &[f64::NAN],
        0.1,
        &Options::default(),
    )
    .unwrap_err();
    assert!(e.to_string().contains("y0[0]"), "{e}");
    let e = solve(
        &mut sys,
        Method::DormandPrince54,
        1.0,
        &[0.5],
        0.0,
        &Options::default(),
    )
    .unwrap_err();
    assert!(
        matches!(e, IntegratorError::InvalidInitialCondition(_)),
        "{e:?}"
    );
    // Symplectic Euler needs q̇ = v.
    let e = solve(
        &mut sys,
        Method::SemiImplicitEuler,
        0.0,
        &[0.5],
        0.1,
        &Options::default().fixed(0.01),
    )
    .unwrap_err();
    assert!(e.to_string().contains("second-order"), "{e}");
}

#[test]
fn the_step_budget_is_an_error_not_a_hang() {
    let opts = Options {
        max_steps: 50,
        ..Options::with_tolerances(1e-12, 1e-14)
    };
    let e = solve(
        &mut BlowUp,
        Method::DormandPrince54,
        0.0,
        &[1.0],
        0.9,
        &opts,
    )
    .unwrap_err();
    assert!(
        matches!(e, IntegratorError::TooManySteps { max_steps: 50, t } if t < 0.9),
        "{e:?}"
    );
    // A minimum step above what the tolerance needs is reported too.
    let opts = Options {
        min_step: Some(0.05),
        initial_step: Some(0.1),
        ..Options::with_tolerances(1e-12, 1e-14)
    };
    let e = solve(
        &mut BlowUp,
        Method::DormandPrince54,
        0.0,
        &[1.0],
        0.9,
        &opts,
    )
    .unwrap_err();
    assert!(
        matches!(e, IntegratorError::StepSizeTooSmall { h_min, .. } if h_min == 0.05),
        "{e:?}"
    );
}

/// ẏ = −2 t y², y(0) = 1: y = 1 / (1 + t²). Its Jacobian −4 t y vanishes at t = 0.
struct VanishingJacobian;

impl OdeSystem for VanishingJacobian {
    fn len(&self) -> usize {
        1
    }
    fn derivative(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = -2.0 * t * y[0] * y[0];
        Ok(())
    }
}

/// Regression (integrator test review): a fixed-step TR-BDF2 failed Newton on this easy
/// problem because the Jacobian at the step start is zero; it now retries with the
/// Jacobian at the stage point.
#[test]
fn fixed_step_newton_recovers_when_the_start_jacobian_is_useless() {
    for rtol in [1e-6, 1e-10] {
        let opts = Options::with_tolerances(rtol, 1e-2 * rtol).fixed(0.5);
        let sol = solve(
            &mut VanishingJacobian,
            Method::TrBdf2,
            0.0,
            &[1.0],
            2.0,
            &opts,
        )
        .unwrap();
        // Second order at h = 0.5: a few per cent.
        assert!((sol.y_final[0] - 0.2).abs() < 0.02, "{}", sol.y_final[0]);
        assert_eq!(sol.stats.steps, 4);
    }
}

/// Regression (integrator test review): fixed steps used to leave a sliver step of ~1e-12 s
/// at the end as round-off accumulated in t.
#[test]
fn fixed_steps_do_not_leave_a_sliver_at_the_end() {
    let opts = Options::default().fixed(0.1);
    let sol = solve(
        &mut VanishingJacobian,
        Method::Rk4,
        0.0,
        &[1.0],
        100.0,
        &opts,
    )
    .unwrap();
    assert_eq!(sol.stats.steps, 1000);
    assert_eq!(sol.t_final, 100.0);
}

/// ẏ = −y, solved with fixed small steps: thousands of steps to an interrupt check.
struct Decay;

impl OdeSystem for Decay {
    fn len(&self) -> usize {
        1
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = -y[0];
        Ok(())
    }
}

static CHECKS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

/// Says "stop" at its third call.
fn stop_at_third() -> bool {
    CHECKS.fetch_add(1, std::sync::atomic::Ordering::SeqCst) >= 2
}

#[test]
fn an_interrupt_check_stops_a_solve_and_is_removed_afterwards() {
    let opts = Options {
        fixed_step: Some(1e-4),
        ..Options::default()
    };
    let run = || solve(&mut Decay, Method::Rk4, 0.0, &[1.0], 1.0, &opts);
    let e = mbs_integrators::with_interrupt_check(stop_at_third, run).unwrap_err();
    let IntegratorError::Interrupted { t } = e else {
        panic!("unexpected {e:?}");
    };
    // Three checks, a few hundred steps apart: stopped early, not at the end.
    assert!(t > 0.0 && t < 0.5, "stopped at t = {t}");
    assert_eq!(CHECKS.load(std::sync::atomic::Ordering::SeqCst), 3);
    assert!(e.to_string().contains("interrupted"), "{e}");
    // Outside it, nothing is checked: the same solve runs to the end.
    let sol = run().unwrap();
    assert_eq!(sol.t.last().copied(), Some(1.0));
    assert_eq!(CHECKS.load(std::sync::atomic::Ordering::SeqCst), 3);
}
