//! Event location: exact contact times of a bouncing ball, close events, directions, and
//! the record / stop / reset actions.

use mbs_integrators::{
    Crossing, EventAction, Method, OdeSystem, Options, SystemError, Termination, solve_with_events,
};

const G: f64 = 9.81;

/// A ball in free fall; the event is its height crossing zero downward.
struct Ball;

impl OdeSystem for Ball {
    fn len(&self) -> usize {
        2
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = y[1];
        dy[1] = -G;
        Ok(())
    }
    fn second_order_split(&self) -> Option<usize> {
        Some(1)
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
    fn event_name(&self, _k: usize) -> String {
        "impact".into()
    }
}

/// Analytic impact times of a ball dropped from `h0` with restitution `e`:
/// t₁ = √(2 h₀/g), then each flight lasts 2 eᵏ v₁ / g with v₁ = g t₁.
fn impact_times(h0: f64, e: f64, count: usize) -> Vec<f64> {
    let t1 = (2.0 * h0 / G).sqrt();
    let v1 = G * t1;
    let mut times = vec![t1];
    let mut v = v1;
    for _ in 1..count {
        v *= e;
        let last = *times.last().unwrap();
        times.push(last + 2.0 * v / G);
    }
    times
}

fn bounce(e: f64) -> impl FnMut(&mbs_integrators::Event, &mut [f64]) -> EventAction {
    move |_, y| {
        y[1] *= -e;
        y[0] = 0.0;
        EventAction::Reset
    }
}

#[test]
fn bouncing_ball_impacts_are_located_to_1e9_s() {
    let (h0, e) = (1.0, 0.8);
    let expect = impact_times(h0, e, 10);
    let t_end = expect[9] + 1e-3;
    for (method, opts) in [
        (
            Method::DormandPrince54,
            Options::with_tolerances(1e-10, 1e-12),
        ),
        (Method::TrBdf2, Options::with_tolerances(1e-8, 1e-10)),
        (Method::Ros34Pw2, Options::with_tolerances(1e-8, 1e-10)),
        (Method::Rk4, Options::default().fixed(1e-2)),
    ] {
        let sol = solve_with_events(
            &mut Ball,
            method,
            0.0,
            &[h0, 0.0],
            t_end,
            &opts,
            &mut bounce(e),
        )
        .unwrap();
        assert_eq!(
            sol.events.len(),
            10,
            "{method:?}: {} impacts",
            sol.events.len()
        );
        for (k, (ev, want)) in sol.events.iter().zip(&expect).enumerate() {
            assert_eq!(ev.name, "impact");
            let err = (ev.time - want).abs();
            assert!(
                err < 1e-9,
                "{method:?} impact {k}: {} vs {want} ({err:e} s)",
                ev.time
            );
            assert!(ev.state[0].abs() < 1e-8, "height at impact {}", ev.state[0]);
        }
    }
}

#[test]
fn rapid_bounces_are_all_found() {
    // With e = 0.5 the flights halve each time: after 14 bounces they last ~0.05 ms, far
    // less than the steps the solver would like to take.
    let (h0, e) = (0.5, 0.5);
    let expect = impact_times(h0, e, 14);
    let opts = Options::with_tolerances(1e-10, 1e-12);
    let t_end = expect[13] + 1e-6;
    let sol = solve_with_events(
        &mut Ball,
        Method::DormandPrince54,
        0.0,
        &[h0, 0.0],
        t_end,
        &opts,
        &mut bounce(e),
    )
    .unwrap();
    assert_eq!(sol.events.len(), 14);
    for (ev, want) in sol.events.iter().zip(&expect) {
        assert!((ev.time - want).abs() < 1e-9, "{} vs {want}", ev.time);
    }
}

/// ẏ = 1 with switching functions y − a_k, each in its own direction.
struct Clock {
    marks: Vec<(f64, Crossing)>,
}

impl OdeSystem for Clock {
    fn len(&self) -> usize {
        1
    }
    fn derivative(&mut self, _t: f64, _y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = 1.0;
        Ok(())
    }
    fn event_count(&self) -> usize {
        self.marks.len()
    }
    fn events(&mut self, _t: f64, y: &[f64], g: &mut [f64]) -> Result<(), SystemError> {
        for (gk, (a, dir)) in g.iter_mut().zip(&self.marks) {
            // Falling marks see a decreasing function.
            *gk = if *dir == Crossing::Falling {
                a - y[0]
            } else {
                y[0] - a
            };
        }
        Ok(())
    }
    fn event_direction(&self, k: usize) -> Crossing {
        self.marks[k].1
    }
    fn event_name(&self, k: usize) -> String {
        format!("mark {}", self.marks[k].0)
    }
}

#[test]
fn events_close_together_are_all_reported_in_time_order() {
    // Three functions crossing within 2e-7 s of each other, inside one big step.
    let marks = vec![
        (0.5000002, Crossing::Rising),
        (0.5, Crossing::Rising),
        (0.5000001, Crossing::Falling),
    ];
    let mut clock = Clock { marks };
    let opts = Options::default().fixed(0.25);
    let sol = solve_with_events(
        &mut clock,
        Method::Rk4,
        0.0,
        &[0.0],
        1.0,
        &opts,
        &mut |_, _| EventAction::Record,
    )
    .unwrap();
    let times: Vec<f64> = sol.events.iter().map(|e| e.time).collect();
    assert_eq!(sol.events.len(), 3, "{times:?}");
    assert_eq!(sol.events[0].index, 1);
    assert_eq!(sol.events[1].index, 2);
    assert_eq!(sol.events[2].index, 0);
    for (ev, want) in sol.events.iter().zip([0.5, 0.5000001, 0.5000002]) {
        assert!((ev.time - want).abs() < 1e-11, "{} vs {want}", ev.time);
    }
}

/// A switching function sin(ω t) driven by time only.
struct Wave {
    omega: f64,
    direction: Crossing,
}

impl OdeSystem for Wave {
    fn len(&self) -> usize {
        1
    }
    fn derivative(&mut self, _t: f64, _y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = 0.0;
        Ok(())
    }
    fn event_count(&self) -> usize {
        1
    }
    fn events(&mut self, t: f64, _y: &[f64], g: &mut [f64]) -> Result<(), SystemError> {
        g[0] = (self.omega * t).sin();
        Ok(())
    }
    fn event_direction(&self, _k: usize) -> Crossing {
        self.direction
    }
}

#[test]
fn directions_select_crossings_even_two_within_one_step() {
    // Zeros of sin(ω t) every π/ω = 0.1 s; steps of 0.35 s hold three of them, and the
    // four samples per step separate them.
    let omega = std::f64::consts::PI / 0.1;
    let opts = Options::default().fixed(0.35);
    for (direction, expect) in [
        (
            Crossing::Both,
            vec![0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9],
        ),
        (Crossing::Falling, vec![0.1, 0.3, 0.5, 0.7, 0.9]),
        (Crossing::Rising, vec![0.2, 0.4, 0.6, 0.8]),
    ] {
        let mut wave = Wave { omega, direction };
        let sol = solve_with_events(
            &mut wave,
            Method::Rk4,
            0.0,
            &[0.0],
            0.95,
            &opts,
            &mut |_, _| EventAction::Record,
        )
        .unwrap();
        let times: Vec<f64> = sol.events.iter().map(|e| e.time).collect();
        assert_eq!(times.len(), expect.len(), "{direction:?}: {times:?}");
        for (t, want) in times.iter().zip(&expect) {
            assert!((t - want).abs() < 1e-10, "{direction:?}: {t} vs {want}");
        }
        // Each event records the way it crossed: sin falls through zero at odd tenths and
        // rises at even ones; a plain ODE names no element.
        for e in &sol.events {
            let odd = ((e.time / 0.1).round() as i64) % 2 == 1;
            let want = if odd {
                Crossing::Falling
            } else {
                Crossing::Rising
            };
            assert_eq!(e.direction, want, "at {}", e.time);
            assert_eq!(e.source, None);
        }
    }
}

#[test]
fn stop_ends_the_solve_at_the_event_with_output_up_to_it() {
    let opts = Options::with_tolerances(1e-10, 1e-12).output_every(0.05);
    let sol = solve_with_events(
        &mut Ball,
        Method::DormandPrince54,
        0.0,
        &[1.0, 0.0],
        5.0,
        &opts,
        &mut |_, _| EventAction::Stop,
    )
    .unwrap();
    let t1 = (2.0 / G).sqrt();
    assert_eq!(sol.termination, Termination::Stopped);
    assert_eq!(sol.events.len(), 1);
    assert!((sol.t_final - t1).abs() < 1e-9);
    assert_eq!(sol.y_final, sol.events[0].state);
    // Grid points up to the impact, none after.
    assert!(sol.t.iter().all(|&t| t <= sol.t_final));
    assert_eq!(sol.len(), (t1 / 0.05).floor() as usize + 1);
    for (i, &t) in sol.t.iter().enumerate() {
        assert!((t - 0.05 * i as f64).abs() < 1e-12);
        let h = 1.0 - 0.5 * G * t * t;
        assert!((sol.state(i)[0] - h).abs() < 1e-9, "height at {t}");
    }
}

#[test]
fn grid_output_continues_across_resets() {
    let e = 0.8;
    let opts = Options::with_tolerances(1e-10, 1e-12).output_every(0.01);
    let t_end = 2.0;
    let sol = solve_with_events(
        &mut Ball,
        Method::DormandPrince54,
        0.0,
        &[1.0, 0.0],
        t_end,
        &opts,
        &mut bounce(e),
    )
    .unwrap();
    assert_eq!(sol.termination, Termination::Finished);
    assert_eq!(sol.len(), 201);
    let impacts = impact_times(1.0, e, 10);
    // Exact height between impacts: parabola from the last impact.
    for (i, &t) in sol.t.iter().enumerate() {
        assert!((t - 0.01 * i as f64).abs() < 1e-12);
        let k = impacts.iter().filter(|&&ti| ti <= t).count();
        let h = if k == 0 {
            1.0 - 0.5 * G * t * t
        } else {
            let v = G * impacts[0] * e.powi(k as i32);
            let s = t - impacts[k - 1];
            v * s - 0.5 * G * s * s
        };
        assert!(
            (sol.state(i)[0] - h).abs() < 1e-8,
            "t = {t}: {} vs {h}",
            sol.state(i)[0]
        );
    }
}

#[test]
fn same_input_gives_bit_identical_events_and_output() {
    let opts = Options::with_tolerances(1e-9, 1e-12).output_every(0.01);
    let run = || {
        solve_with_events(
            &mut Ball,
            Method::TrBdf2,
            0.0,
            &[1.0, 0.0],
            2.0,
            &opts,
            &mut bounce(0.7),
        )
        .unwrap()
    };
    let (a, b) = (run(), run());
    assert_eq!(a, b);
    let bits = |s: &mbs_integrators::Solution| s.y.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&a), bits(&b));
}
