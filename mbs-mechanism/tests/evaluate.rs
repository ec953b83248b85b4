//! Named events and metrics read from a solution: a rod falls from horizontal onto a felt
//! stop; energy conservation gives the tip speed where it passes a given angle.

use mbs_integrators::{Method, MultibodyOde, Options, solve};
use mbs_mechanism::Mechanism;

const ROD: &str = r#"
name = "falling rod"
gravity = [0.0, -9.81]

[[bodies]]
name = "rod"
mass = 0.1
com = [0.05, 0.0]
inertia = 8.333333333333334e-5  # m L² / 12 with L = 0.1 m
joint = { kind = "revolute", at = [0.0, 0.0] }

[[contacts]]
name = "stop"
a = { body = "ground", shapes = [{ segment = { a = [0.05, -0.08], b = [0.12, -0.08] } }] }
b = { body = "rod", shapes = [{ circle = { center = [0.1, 0.0], radius = 0.002 } }] }
law = { material = "action_felt" }

[[markers]]
name = "tip"
at = { body = "rod", point = [0.1, 0.0] }

[[events]]
name = "thirty degrees down"
coordinate = "rod"
value = -0.5235987755982988
direction = "falling"

[[events]]
name = "lands"
contact = "stop"
on = "onset"

[[events]]
name = "leaves"
contact = "stop"
on = "release"

[[metrics]]
name = "tip speed at thirty degrees"
quantity = "speed"
marker = "tip"
at = "thirty degrees down"
unit = "m/s"

[[metrics]]
name = "landing time"
quantity = "time"
at = "lands"
unit = "s"

[[metrics]]
name = "tip height at landing"
quantity = "y"
marker = "tip"
at = "lands"
unit = "m"
"#;

#[test]
fn events_and_metrics_follow_the_physics() {
    let m = Mechanism::from_toml_str(ROD).unwrap();
    let built = m.build().unwrap();
    let x0 = built.layout_state().unwrap();
    let opts = Options {
        max_step: 1e-3,
        ..Options::with_tolerances(1e-9, 1e-12)
    };
    let sol = solve(
        &mut MultibodyOde::new(&built.system),
        Method::TrBdf2,
        0.0,
        &x0,
        0.3,
        &opts,
    )
    .unwrap();
    let events = m.events_in(&built, &sol).unwrap();
    let names: Vec<&str> = events.iter().map(|e| e.name.as_str()).collect();
    assert_eq!(names[..2], ["thirty degrees down", "lands"], "{names:?}");
    assert!(
        names.contains(&"leaves"),
        "the rod bounces off the felt: {names:?}"
    );
    // The integrator's events name the element that raised them and the way it crossed:
    // the stop's gap falls through zero as the rod lands and rises as it leaves.
    let stop = built.contacts["stop"];
    let stop_events: Vec<_> = sol
        .events
        .iter()
        .filter(|e| e.source.map(|s| s.element) == Some(stop))
        .collect();
    assert!(stop_events.len() >= 2);
    assert_eq!(stop_events[0].direction, mbs_integrators::Crossing::Falling);
    assert_eq!(stop_events[1].direction, mbs_integrators::Crossing::Rising);
    assert_eq!(stop_events[0].time, events[1].time_s);
    let watch = built.watches["thirty degrees down"];
    assert!(
        sol.events
            .iter()
            .any(|e| e.source.map(|s| s.element) == Some(watch)
                && e.direction == mbs_integrators::Crossing::Falling)
    );
    let metrics = m.metrics_in(&built, &sol).unwrap();
    // Energy: I_O ω² / 2 = m g (L/2) sin 30°, tip speed L ω.
    let (mass, l, g) = (0.1f64, 0.1f64, 9.81f64);
    let i_o = mass * l * l / 3.0;
    let omega = (2.0 * mass * g * 0.5 * l * 0.5 / i_o).sqrt();
    let speed = metrics[0].value.expect("passed thirty degrees");
    assert!(
        (speed - l * omega).abs() < 1e-5 * l * omega,
        "tip speed {speed} m/s, energy says {}",
        l * omega
    );
    assert_eq!(metrics[0].unit, "m/s");
    // It lands when the tip's pad reaches the stop: the tip 2 mm above the face.
    let landing = metrics[1].value.expect("lands");
    assert_eq!(landing, events[1].time_s);
    let y = metrics[2].value.unwrap();
    assert!((y - (-0.078)).abs() < 1e-5, "tip at {y} m when it lands");
}

#[test]
fn a_metric_whose_event_never_happens_has_no_value() {
    let text = ROD.replace("value = -0.5235987755982988", "value = -1.5");
    let m = Mechanism::from_toml_str(&text).unwrap();
    let built = m.build().unwrap();
    let x0 = built.layout_state().unwrap();
    let sol = solve(
        &mut MultibodyOde::new(&built.system),
        Method::TrBdf2,
        0.0,
        &x0,
        0.2,
        &Options::with_tolerances(1e-7, 1e-10),
    )
    .unwrap();
    let metrics = m.metrics_in(&built, &sol).unwrap();
    assert_eq!(metrics[0].value, None, "the rod never reaches -1.5 rad");
    assert!(metrics[1].value.is_some());
}
