//! Finger touches: pressed (the finger rests on the key and pushes) and struck (the finger
//! arrives with a speed), through a fingertip pad on the key top.

use piano_action::{ActionParams, Finger, Input, ModelKind, Run, TouchStyle, simulate};

fn touch(style: TouchStyle, duration_s: f64) -> Run {
    simulate(
        &ActionParams::reference(),
        ModelKind::Double,
        &Input::Touch {
            style,
            finger: Finger::default(),
        },
        duration_s,
        1e-3,
    )
    .unwrap()
}

fn pressed(peak_force_n: f64) -> Run {
    let duration = if peak_force_n < 1.5 { 0.3 } else { 0.12 };
    touch(TouchStyle::Pressed { peak_force_n }, duration)
}

fn struck(finger_speed_m_s: f64) -> Run {
    let duration = if finger_speed_m_s < 0.25 { 0.25 } else { 0.1 };
    touch(TouchStyle::Struck { finger_speed_m_s }, duration)
}

/// Hammer speed at the first string contact and the travel time (key start to string).
fn blow(run: &Run) -> (f64, f64) {
    let s = run.strikes.first().expect("the hammer reaches the string");
    (
        s.hammer_velocity_m_s,
        run.travel_time_s.expect("a travel time"),
    )
}

#[test]
fn hammer_speed_grows_with_the_touch_and_spans_the_dynamic_range() {
    let mut all = Vec::new();
    for (what, runs) in [
        ("pressed", [0.8, 2.0, 8.0, 50.0].map(pressed)),
        ("struck", [0.1, 0.3, 1.0, 2.0].map(struck)),
    ] {
        let blows: Vec<(f64, f64)> = runs.iter().map(blow).collect();
        eprintln!("{what}: (hammer m/s, travel s) {blows:?}");
        for w in blows.windows(2) {
            assert!(w[1].0 > w[0].0, "{what}: hammer speed must grow: {blows:?}");
            assert!(
                w[1].1 < w[0].1,
                "{what}: travel time must shrink: {blows:?}"
            );
        }
        for (run, b) in runs.iter().zip(&blows) {
            assert_eq!(run.strikes.len(), 1, "{what}: one blow");
            // Below about 1 m/s the rebound is too weak to reach the backcheck: the
            // repetition lever takes the hammer.
            if b.0 > 1.0 {
                assert!(run.check_time_s.is_some(), "{what}: the backcheck catches");
            }
        }
        // Askenfelt & Jansson: the key bottoms after the string contact at p (some 12 ms)
        // and before it at f (some 3 ms).
        let lead = |run: &Run| run.key_bottom_time_s.unwrap() - run.strikes[0].time_s;
        let (soft, loud) = (lead(&runs[0]), lead(&runs[3]));
        eprintln!("{what}: key bottom - string contact {soft:.4} s (soft), {loud:.4} s (loud)");
        assert!(
            soft > 0.0 && soft < 0.04,
            "{what}: soft key bottom - HS {soft} s"
        );
        assert!(
            loud < 0.0 && loud > -0.01,
            "{what}: loud key bottom - HS {loud} s"
        );
        all.extend(blows);
    }
    let lo = all.iter().map(|b| b.0).fold(f64::INFINITY, f64::min);
    let hi = all.iter().map(|b| b.0).fold(0.0, f64::max);
    // Literature: about 0.4-1 m/s (pp) to 5-6 m/s (ff) at the string.
    assert!(lo < 0.65, "softest touch gives {lo} m/s");
    assert!(hi > 5.5 && hi < 8.0, "loudest touch gives {hi} m/s");
    // Travel times (Askenfelt & Jansson; Goebl et al.): some 100-200 ms at pp, 20-50 ms at ff.
    let slowest = all.iter().map(|b| b.1).fold(0.0, f64::max);
    let fastest = all.iter().map(|b| b.1).fold(f64::INFINITY, f64::min);
    assert!((0.1..0.3).contains(&slowest), "pp travel time {slowest} s");
    assert!(
        (0.01..0.03).contains(&fastest),
        "ff travel time {fastest} s"
    );
}

/// The struck finger speed that gives the hammer `target` m/s at the string (secant on the
/// logarithms, within 1 %).
fn struck_matching(target: f64) -> (f64, f64) {
    let (mut a, mut b) = (0.3_f64, 0.6_f64);
    let (mut va, mut vb) = (blow(&struck(a)).0, blow(&struck(b)).0);
    for _ in 0..8 {
        let slope = (vb.ln() - va.ln()) / (b.ln() - a.ln());
        let next = (b.ln() + (target.ln() - vb.ln()) / slope)
            .exp()
            .clamp(0.08, 3.0);
        let run = struck(next);
        let (v, tt) = blow(&run);
        if (v / target - 1.0).abs() < 0.01 {
            return (v, tt);
        }
        (a, va, b, vb) = (b, vb, next, v);
    }
    panic!("no struck touch matches {target} m/s");
}

#[test]
fn a_struck_touch_reaches_the_string_sooner_than_a_pressed_one_of_equal_speed() {
    // Goebl, Bresin & Galembo (2005): some 20 ms less travel time at equal hammer speed.
    for force in [2.0, 8.0] {
        let (v_pressed, tt_pressed) = blow(&pressed(force));
        let (v_struck, tt_struck) = struck_matching(v_pressed);
        eprintln!(
            "{v_pressed:.3} m/s: pressed ({force} N) {:.1} ms, struck ({v_struck:.3} m/s) {:.1} ms",
            tt_pressed * 1e3,
            tt_struck * 1e3
        );
        assert!(
            tt_struck < 0.9 * tt_pressed,
            "at {v_pressed} m/s struck takes {tt_struck} s, pressed {tt_pressed} s"
        );
    }
}

#[test]
fn a_struck_touch_starts_the_key_when_the_finger_lands() {
    // The pad starts 0.5 mm above the key and the arm carries the finger at 0.5 m/s, so it
    // lands after exactly 1 ms (the action starts settled at rest); the key front is 0.1 mm
    // down once the pulp has taken up the key's down weight, a few milliseconds later.
    let run = struck(0.5);
    let landed = run.events.iter().find(|e| e.name == "finger_key").unwrap();
    assert!(
        (landed.time_s - 1e-3).abs() < 1e-6,
        "finger lands at {}",
        landed.time_s
    );
    let t = run.key_start_time_s.unwrap();
    assert!((1.0e-3..6.0e-3).contains(&t), "key start at {t} s");
    // A pressed touch starts the key once the rising force has beaten the key's down weight
    // (0.5 N of 2 N rising over 30 ms: after 7.5 ms) and set the key going.
    let t = pressed(2.0).key_start_time_s.unwrap();
    assert!((7.5e-3..20e-3).contains(&t), "key start at {t} s");
    let names: Vec<&str> = run.events.iter().map(|e| e.name).collect();
    assert_eq!(names[..2], ["finger_key", "key_start"], "{names:?}");
}

#[test]
fn bad_touches_are_named() {
    for (style, field) in [
        (
            TouchStyle::Pressed { peak_force_n: -1.0 },
            "input.peak_force_n",
        ),
        (
            TouchStyle::Struck {
                finger_speed_m_s: f64::NAN,
            },
            "input.finger_speed_m_s",
        ),
    ] {
        let err = simulate(
            &ActionParams::reference(),
            ModelKind::Double,
            &Input::Touch {
                style,
                finger: Finger::default(),
            },
            0.1,
            1e-3,
        )
        .unwrap_err();
        assert!(err.to_string().contains(field), "{err}");
    }
    let finger = Finger {
        mass_g: 0.0,
        ..Finger::default()
    };
    let err = simulate(
        &ActionParams::reference(),
        ModelKind::Double,
        &Input::Touch {
            style: TouchStyle::Pressed { peak_force_n: 2.0 },
            finger,
        },
        0.1,
        1e-3,
    )
    .unwrap_err();
    assert!(err.to_string().contains("finger_mass_g"), "{err}");
}
