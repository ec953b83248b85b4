//! Solves on a given mesh (`Options::mesh`): a solve on its own step ends takes exactly
//! them and is as accurate, finite differences between solves on one mesh follow the exact
//! sensitivity of a ball on a felt where adaptive solves' step choices get in the way, a
//! step Newton cannot solve is taken in quarters, the step ends stay a mesh across
//! restarts, and bad meshes are refused by name.

use std::sync::Arc;

use mbs_integrators::{
    Crossing, EventAction, IntegratorError, Method, OdeSystem, Options, Solution, SystemError,
    Termination, solve, solve_with_events,
};

/// `x'' + 2ζω x' + ω² x = 0` from `x = 1, x' = 0`, underdamped.
struct Oscillator {
    omega: f64,
    zeta: f64,
}

impl Oscillator {
    /// The exact displacement at `t`.
    fn exact(omega: f64, zeta: f64, t: f64) -> f64 {
        let wd = omega * (1.0 - zeta * zeta).sqrt();
        let s = zeta * omega;
        (-s * t).exp() * ((wd * t).cos() + s / wd * (wd * t).sin())
    }
}

impl OdeSystem for Oscillator {
    fn len(&self) -> usize {
        2
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = y[1];
        dy[1] = -2.0 * self.zeta * self.omega * y[1] - self.omega * self.omega * y[0];
        Ok(())
    }
}

const OMEGA: f64 = 20.0;
const ZETA: f64 = 0.05;
const T_END: f64 = 2.0;
const RTOL: f64 = 1e-4;

fn oscillator(omega: f64, opts: &Options) -> Solution {
    let mut sys = Oscillator { omega, zeta: ZETA };
    solve(&mut sys, Method::TrBdf2, 0.0, &[1.0, 0.0], T_END, opts).expect("oscillator")
}

fn adaptive() -> Options {
    Options {
        record_steps: true,
        ..Options::with_tolerances(RTOL, RTOL * 1e-3).output_every(0.01)
    }
}

fn on(mesh: &[f64]) -> Options {
    Options {
        mesh: Some(Arc::from(mesh)),
        ..adaptive()
    }
}

/// A ball dropped from 10 mm on a felt: `x'' = −g + k max(0, −x)^1.5 max(0, 1 − 0.5 x')`
/// (Hunt & Crossley's damping).
struct Felt {
    k: f64,
}

impl OdeSystem for Felt {
    fn len(&self) -> usize {
        2
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        let pen = (-y[0]).max(0.0);
        dy[0] = y[1];
        dy[1] = -9.81 + self.k * pen.powf(1.5) * (1.0 - 0.5 * y[1]).max(0.0);
        Ok(())
    }
}

fn felt(k: f64, opts: &Options) -> Solution {
    solve(
        &mut Felt { k },
        Method::TrBdf2,
        0.0,
        &[0.01, 0.0],
        0.5,
        opts,
    )
    .expect("felt")
}

/// The largest distance from the exact motion over the output.
fn worst_error(sol: &Solution, omega: f64) -> f64 {
    (0..sol.len())
        .map(|i| (sol.state(i)[0] - Oscillator::exact(omega, ZETA, sol.t[i])).abs())
        .fold(0.0, f64::max)
}

#[test]
fn a_solve_on_its_own_step_ends_takes_exactly_them_and_is_as_accurate() {
    let free = oscillator(OMEGA, &adaptive());
    assert!(
        free.stats.rejected > 0,
        "the adaptive solve rejected no step"
    );
    let meshed = oscillator(OMEGA, &on(&free.step_ends));
    assert_eq!(meshed.stats.steps, free.step_ends.len());
    assert_eq!(meshed.stats.rejected, 0);
    for (a, b) in meshed.step_ends.iter().zip(&free.step_ends) {
        assert!(
            (a - b).abs() <= 1e-12,
            "step end {a} on the mesh, {b} adaptive"
        );
    }
    let (e_free, e_meshed) = (worst_error(&free, OMEGA), worst_error(&meshed, OMEGA));
    println!("worst error: adaptive {e_free:.3e}, on its mesh {e_meshed:.3e}");
    assert!(
        e_meshed <= 1.5 * e_free,
        "on its own mesh {e_meshed:e}, adaptive {e_free:e}"
    );
}

#[test]
fn finite_differences_on_one_mesh_follow_the_exact_sensitivity() {
    // d x / d k over the output, by central differences of solves 1e6 times tighter.
    let k = 1e6;
    let grid = 1e-3;
    let tight = Options::with_tolerances(1e-10, 1e-13).output_every(grid);
    let d = 1e-4 * k;
    let (a, b) = (felt(k - d, &tight), felt(k + d, &tight));
    let exact: Vec<f64> = (0..a.len().min(b.len()))
        .map(|i| (b.state(i)[0] - a.state(i)[0]) / (2.0 * d))
        .collect();
    let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let opts = Options {
        record_steps: true,
        ..Options::with_tolerances(1e-4, 1e-7).output_every(grid)
    };
    let base = felt(k, &opts);
    assert!(base.stats.rejected > 20, "{:?}", base.stats);
    let mesh = Options {
        mesh: Some(base.step_ends.clone().into()),
        ..opts.clone()
    };
    let on_mesh = felt(k, &mesh);
    // The worst error of a forward difference with step `rel` of k, over its largest value.
    let column = |rel: f64, meshed: bool| -> f64 {
        let h = rel * k;
        let (from, to) = if meshed {
            (&on_mesh, felt(k + h, &mesh))
        } else {
            (&base, felt(k + h, &opts))
        };
        (0..exact.len().min(from.len()).min(to.len()))
            .map(|i| ((to.state(i)[0] - from.state(i)[0]) / h - exact[i]).abs())
            .fold(0.0, f64::max)
            / scale
    };
    let (m3, m4) = (column(1e-3, true), column(1e-4, true));
    let (a3, a4) = (column(1e-3, false), column(1e-4, false));
    println!("steps 1e-3 of k: adaptive {a3:.3e}, on one mesh {m3:.3e}");
    println!("steps 1e-4 of k: adaptive {a4:.3e}, on one mesh {m4:.3e}");
    // On one mesh the error is the discretisation's, whatever the step; adaptive solves'
    // step choices differ between the two runs by more than the step's effect.
    assert!(m3 < 0.3 && m4 < 0.3, "on one mesh: {m3:e}, {m4:e}");
    assert!(
        (m3 / m4 - 1.0).abs() < 0.5,
        "on one mesh: {m3:e} against {m4:e}"
    );
    assert!(a4 > 3.0 * m4, "adaptive {a4:e}, on one mesh {m4:e}");
}

/// `y' = −k √y`, not finite below zero: `√y = 1 − k t / 2`.
struct Root(f64);

impl OdeSystem for Root {
    fn len(&self) -> usize {
        1
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = -self.0 * y[0].sqrt();
        Ok(())
    }
}

#[test]
fn a_step_newton_cannot_solve_is_taken_in_quarters_towards_the_same_end() {
    // One step to t = 1, where y = 0.0025: Newton's iterates fall below zero.
    let k = 1.9;
    let opts = Options {
        mesh: Some(Arc::from(&[1.0][..])),
        record_steps: true,
        ..Options::with_tolerances(1e-6, 1e-9)
    };
    let sol = solve(&mut Root(k), Method::TrBdf2, 0.0, &[1.0], 1.0, &opts)
        .expect("solved in shorter steps");
    println!("{:?}", sol.stats);
    assert!(sol.stats.rejected_newton > 0, "no step was shortened");
    assert_eq!(sol.termination, Termination::Finished);
    assert_eq!(sol.step_ends.last(), Some(&1.0));
    let exact = (1.0 - k / 2.0) * (1.0 - k / 2.0);
    assert!(
        (sol.y_final[0] - exact).abs() < 1e-3 * exact,
        "y(1) = {} for {exact}",
        sol.y_final[0]
    );
}

/// A ball falling onto a floor that returns it with restitution 0.8.
struct Ball;

impl OdeSystem for Ball {
    fn len(&self) -> usize {
        2
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = y[1];
        dy[1] = -9.81;
        Ok(())
    }
    fn event_count(&self) -> usize {
        1
    }
    fn events(&mut self, _t: f64, y: &[f64], g: &mut [f64]) -> Result<(), SystemError> {
        g[0] = y[0];
        Ok(())
    }
    fn event_direction(&self, _k: usize) -> Crossing {
        Crossing::Falling
    }
}

#[test]
fn step_ends_are_a_mesh_across_restarts_and_a_solve_follows_it() {
    let mut bounce = |_: &mbs_integrators::Event, y: &mut [f64]| {
        y[0] = 0.0;
        y[1] *= -0.8;
        EventAction::Reset
    };
    let opts = Options {
        record_steps: true,
        ..Options::with_tolerances(1e-6, 1e-9)
    };
    let free = solve_with_events(
        &mut Ball,
        Method::TrBdf2,
        0.0,
        &[1.0, 0.0],
        2.0,
        &opts,
        &mut bounce,
    )
    .expect("ball");
    assert!(free.events.len() >= 3);
    assert!(free.step_ends.windows(2).all(|w| w[0] < w[1]));
    for e in &free.events {
        assert!(
            free.step_ends.contains(&e.time),
            "no step ends at {}",
            e.time
        );
    }
    let meshed = solve_with_events(
        &mut Ball,
        Method::TrBdf2,
        0.0,
        &[1.0, 0.0],
        2.0,
        &Options {
            mesh: Some(free.step_ends.clone().into()),
            ..opts
        },
        &mut bounce,
    )
    .expect("ball on its mesh");
    assert_eq!(meshed.events.len(), free.events.len());
    for (a, b) in meshed.events.iter().zip(&free.events) {
        assert!(
            (a.time - b.time).abs() < 1e-9,
            "impact {} against {}",
            a.time,
            b.time
        );
    }
}

#[test]
fn a_bad_mesh_is_refused_by_name() {
    let cases: [(Method, Vec<f64>, Option<f64>); 5] = [
        (Method::TrBdf2, vec![0.1, 0.1, 0.2], None),
        (Method::TrBdf2, vec![0.1, 0.5], None),
        (Method::TrBdf2, vec![0.1, f64::NAN], None),
        (Method::TrBdf2, vec![0.1, 0.2], Some(0.01)),
        (Method::DormandPrince54, vec![0.1, 0.2], None),
    ];
    for (method, mesh, fixed) in cases {
        let opts = Options {
            mesh: Some(mesh.clone().into()),
            fixed_step: fixed,
            ..Options::default()
        };
        let mut sys = Oscillator {
            omega: 1.0,
            zeta: 0.0,
        };
        match solve(&mut sys, method, 0.0, &[1.0, 0.0], 1.0, &opts) {
            Err(IntegratorError::InvalidOption { option, message }) => {
                assert_eq!(option, "mesh", "{message}");
                println!("{method:?} {mesh:?} {fixed:?}: {message}");
            }
            other => panic!("{method:?} {mesh:?} {fixed:?} accepted: {other:?}"),
        }
    }
}
