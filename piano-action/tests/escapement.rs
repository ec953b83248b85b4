//! The escapement under real touches (issue 12): the jack leaves the knuckle before the
//! string, so the hammer flies free for the last 0.5-2 mm (Gillespie et al. 2011 measured
//! 1-1.5 mm); a monotonic key motion strikes once, whatever its speed profile; a let-off
//! regulated too close to the string can strike twice.

use piano_action::simulate::{KEY_START_MM, prepare};
use piano_action::{ActionParams, Finger, Input, ModelKind, Run, TouchStyle, simulate};

/// Key dip the motions travel (mm): the regulated dip under a hand's weight.
const DIP_MM: f64 = 9.6;

/// Hammer crown below the string (mm) when the jack last pushed the knuckle before the
/// first string contact: the free flight.
fn free_flight_mm(params: &ActionParams, input: &Input) -> (f64, f64) {
    let run = simulate(params, ModelKind::Double, input, 0.15, 2e-5).expect("runs");
    let strike = run.strikes.first().expect("the hammer strikes");
    let action = prepare(params, ModelKind::Double, input)
        .expect("builds")
        .action;
    let sol = &run.solution;
    let mut flight = f64::NAN;
    for i in 0..sol.len() {
        let (t, x) = (sol.t[i], sol.state(i));
        if t >= strike.time_s {
            break;
        }
        let push = action
            .contact_output("jack_knuckle", t, x)
            .expect("contact");
        if push.normal_force > 0.0 {
            flight = action.gap("hammer_string", t, x).expect("gap") * 1e3;
        }
    }
    (flight, strike.hammer_velocity_m_s)
}

fn struck(speed: f64) -> Input {
    Input::Touch {
        style: TouchStyle::Struck {
            finger_speed_m_s: speed,
        },
        finger: Finger::default(),
    }
}

#[test]
fn the_hammer_flies_free_before_the_string_from_mezzoforte_to_fortissimo() {
    let params = ActionParams::reference();
    let mut speeds = Vec::new();
    for finger in [0.6, 1.2, 2.0] {
        let (flight, v) = free_flight_mm(&params, &struck(finger));
        eprintln!("struck {finger} m/s: hammer {v:.2} m/s, free flight {flight:.2} mm");
        assert!(
            (0.5..=2.0).contains(&flight),
            "struck {finger} m/s: free flight {flight:.2} mm, outside 0.5-2 mm"
        );
        speeds.push(v);
    }
    // mezzoforte to fortissimo: about 2.5 to 5.5 m/s at the string.
    assert!(speeds[0] < 3.0 && speeds[2] > 5.0, "{speeds:?}");
}

/// Key-front depth (mm) reaching `speed` (m/s) at a constant acceleration over `ramp_s`,
/// then constant to the dip, held.
fn constant_speed(speed: f64, ramp_s: f64) -> Vec<(f64, f64)> {
    let mut points = vec![(0.0, 0.0)];
    let n = 12;
    for i in 1..=n {
        let t = ramp_s * i as f64 / n as f64;
        points.push((t, 0.5 * speed / ramp_s * t * t * 1e3));
    }
    let reached = 0.5 * speed * ramp_s * 1e3;
    assert!(reached < DIP_MM);
    let end = ramp_s + (DIP_MM - reached) / (speed * 1e3);
    points.push((end, DIP_MM));
    points.push((end + 0.2, DIP_MM));
    points
}

/// Minimum-jerk key motion to the dip with peak speed `speed` (m/s), then held.
fn minimum_jerk(speed: f64) -> Vec<(f64, f64)> {
    let duration = 1.875 * DIP_MM * 1e-3 / speed;
    let n = 24;
    let mut points: Vec<(f64, f64)> = (0..=n)
        .map(|i| {
            let s = i as f64 / n as f64;
            (
                duration * s,
                DIP_MM * (10.0 * s.powi(3) - 15.0 * s.powi(4) + 6.0 * s.powi(5)),
            )
        })
        .collect();
    points.push((duration + 0.2, DIP_MM));
    points
}

/// Linear to the dip at `speed` (the corners rounded by the drive over 5 ms), then held.
fn linear(speed: f64) -> Vec<(f64, f64)> {
    let end = DIP_MM * 1e-3 / speed;
    vec![(0.0, 0.0), (end, DIP_MM), (end + 0.2, DIP_MM)]
}

fn strikes(params: &ActionParams, points: Vec<(f64, f64)>) -> Run {
    let end = points.last().map(|p| p.0).unwrap_or(0.0);
    simulate(
        params,
        ModelKind::Double,
        &Input::Motion { points },
        end + 0.05,
        1e-4,
    )
    .expect("runs")
}

#[test]
fn a_monotonic_key_motion_strikes_once_whatever_its_profile() {
    let params = ActionParams::reference();
    let mut cases: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for speed in [0.1, 0.25, 0.5, 1.0] {
        for ramp_ms in [5.0, 15.0, 30.0] {
            if 0.5 * speed * ramp_ms < DIP_MM - 1.0 {
                cases.push((
                    format!("{speed} m/s reached in {ramp_ms} ms"),
                    constant_speed(speed, ramp_ms * 1e-3),
                ));
            }
        }
        cases.push((
            format!("minimum jerk, peak {speed} m/s"),
            minimum_jerk(speed),
        ));
        cases.push((format!("linear {speed} m/s"), linear(speed)));
    }
    for (name, points) in cases {
        let run = strikes(&params, points);
        assert!(run.key_start_time_s.is_some() && KEY_START_MM > 0.0);
        let times: Vec<f64> = run.strikes.iter().map(|s| s.time_s * 1e3).collect();
        eprintln!("{name}: strikes at {times:.1?} ms");
        assert_eq!(times.len(), 1, "{name}: strikes at {times:.1?} ms");
    }
}

#[test]
fn a_let_off_regulated_too_close_to_the_string_strikes_twice() {
    // The button raised 0.3 mm: the jack escapes about 1.7 mm later in the hammer's rise,
    // under 0.5 mm from the string, and a slow motion bounces the hammer back onto
    // the string (a "double strike", what technicians regulate let-off against).
    let mut params = ActionParams::reference();
    let close = piano_action::regulation::measure(&params, ModelKind::Double).expect("measures");
    params.regulation.let_off_button_y_mm += 0.3;
    let closer = piano_action::regulation::measure(&params, ModelKind::Double).expect("measures");
    let (before, after) = (
        close.let_off_mm.expect("lets off"),
        closer.let_off_mm.expect("lets off"),
    );
    eprintln!("let-off {before:.2} mm -> {after:.2} mm");
    assert!(after < 0.6 * before, "{before} -> {after}");
    // A slow touch (0.1 m/s, reached in 5 ms): the hammer leaves the jack only at the
    // string, falls back onto a jack that has not yet slipped clear and is thrown again.
    let run = strikes(&params, constant_speed(0.1, 5e-3));
    for s in &run.strikes {
        eprintln!("{s:?}");
    }
    assert!(
        run.strikes.len() >= 2,
        "{} strike(s) with let-off at {after:.2} mm",
        run.strikes.len()
    );
    // The regulated action strikes once under the same motion.
    let once = strikes(&ActionParams::reference(), constant_speed(0.1, 5e-3));
    assert_eq!(once.strikes.len(), 1);
}

#[test]
fn the_key_bottoms_after_the_string_contact_at_piano_and_before_it_at_forte() {
    // Askenfelt & Jansson, Goebl et al. (literature §3.1-3.2 [S]): the key reaches the
    // key bed well after the hammer meets the string in soft playing and a few ms before
    // it in loud playing. Struck touches of about 1 m/s (p) and 4 m/s (f) at the string.
    let params = ActionParams::reference();
    let mut lags = Vec::new();
    for finger_speed_m_s in [0.215, 1.15] {
        let input = Input::Touch {
            style: TouchStyle::Struck { finger_speed_m_s },
            finger: Finger::default(),
        };
        let run = simulate(&params, ModelKind::Double, &input, 0.3, 1e-3).expect("runs");
        let strike = run.strikes[0];
        let lag_ms = (run.key_bottom_time_s.expect("bottoms") - strike.time_s) * 1e3;
        eprintln!(
            "finger {finger_speed_m_s} m/s: hammer {:.2} m/s, key bottom - string contact {lag_ms:.1} ms",
            strike.hammer_velocity_m_s
        );
        lags.push((strike.hammer_velocity_m_s, lag_ms));
    }
    let ((v_p, p), (v_f, f)) = (lags[0], lags[1]);
    assert!(
        (0.7..1.4).contains(&v_p) && (3.0..5.0).contains(&v_f),
        "{v_p} {v_f}"
    );
    assert!(p > 1.0, "p: key bottom {p} ms after the string contact");
    assert!(f < -0.5, "f: key bottom {f} ms after the string contact");
}
