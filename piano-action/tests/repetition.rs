//! Repeated notes under a prescribed key motion: press, hold, let the key rise, press again.

use piano_action::{ActionParams, Input, ModelKind, simulate};

/// Appends a smooth (minimum-jerk) key move from the last point to `depth_mm`, ending at
/// `t_end`, sampled every 5 ms: a finger accelerates the key gradually, it does not jump
/// to speed.
fn move_to(points: &mut Vec<(f64, f64)>, t_end: f64, depth_mm: f64) {
    let (t0, d0) = *points.last().unwrap();
    let n = ((t_end - t0) / 5e-3).ceil() as usize;
    for i in 1..=n {
        let u = i as f64 / n as f64;
        let s = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
        points.push((t0 + u * (t_end - t0), d0 + s * (depth_mm - d0)));
    }
}

/// Key-front depth: pressed to the bottom in 40 ms (forte), held, let up to `rise_to_mm` in
/// 100 ms, held 50 ms, pressed again in 40 ms and held.
fn repeat(kind: ModelKind, rise_to_mm: f64) -> piano_action::Run {
    let mut points = vec![(0.0, 0.0)];
    move_to(&mut points, 0.04, 10.5);
    points.push((0.2, 10.5));
    move_to(&mut points, 0.3, rise_to_mm);
    points.push((0.35, rise_to_mm));
    move_to(&mut points, 0.39, 10.5);
    simulate(
        &ActionParams::reference(),
        kind,
        &Input::Motion { points },
        0.55,
        1e-3,
    )
    .unwrap()
}

fn strike_times(run: &piano_action::Run) -> Vec<f64> {
    run.strikes.iter().map(|s| s.time_s).collect()
}

#[test]
fn half_release_repeats_on_the_double_escapement_only() {
    let double = repeat(ModelKind::Double, 5.3);
    let single = repeat(ModelKind::Single, 5.3);
    let (d, s) = (strike_times(&double), strike_times(&single));
    println!("double {:?}\nsingle {s:?}", double.strikes);
    // The repetition lever holds the hammer up while the key is half up, the jack slips
    // back under the knuckle and the second press strikes again.
    assert_eq!(d.len(), 2, "double: {d:?}");
    assert!(d[1] > 0.35, "second blow from the second press: {d:?}");
    assert!(double.strikes[1].hammer_velocity_m_s > 0.5);
    let resets = |run: &piano_action::Run| -> Vec<f64> {
        run.events
            .iter()
            .filter(|e| e.name == "jack_reset")
            .map(|e| e.time_s)
            .collect()
    };
    // The jack is back under the knuckle after the key has begun to rise (0.2 s) and before
    // the second press ends (0.39 s).
    let jr = resets(&double);
    assert!(
        jr.len() == 1 && jr[0] > 0.2 && jr[0] < 0.39 && jr[0] < d[1],
        "double jack resets {jr:?}"
    );
    // Without the lever the jack cannot get back under the knuckle from half-way.
    assert_eq!(s.len(), 1, "single: {s:?}");
    assert!(
        resets(&single).is_empty(),
        "single jack resets {:?}",
        resets(&single)
    );
}

#[test]
fn full_release_repeats_on_both_escapement_actions() {
    for kind in [ModelKind::Single, ModelKind::Double] {
        let run = repeat(kind, 0.0);
        let t = strike_times(&run);
        println!("{kind:?} {t:?}");
        assert_eq!(t.len(), 2, "{kind:?}: {t:?}");
        let reset = run.events.iter().find(|e| e.name == "jack_reset");
        assert!(
            reset.is_some_and(|e| e.time_s > 0.2 && e.time_s < t[1]),
            "{kind:?}: the jack resets between the blows: {:?}",
            run.events
        );
        assert!(t[1] > 0.35, "{kind:?}: {t:?}");
    }
}
