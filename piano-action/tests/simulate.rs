//! Keystrokes through `simulate`: piano events and strike metrics.

use piano_action::{ActionParams, Input, ModelKind, simulate};

#[test]
fn hammer_velocity_grows_with_key_force_and_events_come_in_order() {
    let params = ActionParams::reference();
    let mut last_v = 0.0;
    for force_n in [2.0, 8.0, 32.0] {
        let run = simulate(
            &params,
            ModelKind::Double,
            &Input::Force {
                force_n,
                release_s: None,
            },
            0.15,
            1e-3,
        )
        .unwrap();
        let strike = run.strikes[0];
        assert!(
            strike.hammer_velocity_m_s > last_v,
            "{force_n} N: {} m/s",
            strike.hammer_velocity_m_s
        );
        last_v = strike.hammer_velocity_m_s;
        // The modal C4 string sets contact and rebound: 1.9-2.6 ms, and the hammer leaves
        // at 0.6-0.8 of its strike speed (string_reference.md §4.1: 2.54 ms and 0.75 at
        // 0.5 m/s to 1.88 ms and 0.63 at 6 m/s).
        let contact = strike.contact_duration_s.unwrap();
        assert!((1.8e-3..2.7e-3).contains(&contact), "contact {contact}");
        let e = strike.rebound_velocity_m_s.unwrap() / strike.hammer_velocity_m_s;
        assert!((0.55..0.8).contains(&e), "{force_n} N: rebound ratio {e}");
        // Let-off before the strike, the check after it.
        let let_off = run.let_off_time_s.unwrap();
        let check = run.check_time_s.unwrap();
        assert!(
            let_off < strike.time_s && strike.time_s < check,
            "{let_off} {} {check}",
            strike.time_s
        );
        assert!(run.key_bottom_time_s.is_some());
        // The event list is in time order and holds the string contact start and end.
        assert!(run.events.windows(2).all(|w| w[0].time_s <= w[1].time_s));
        assert!(run.events.iter().any(|e| e.name == "string_contact_end"));
    }
    // From a soft press to a loud one the hammer speed spans roughly 1.5 to 6.5 m/s.
    assert!(last_v > 5.0);
}

#[test]
fn bad_inputs_are_named() {
    let params = ActionParams::reference();
    let e = simulate(
        &params,
        ModelKind::Double,
        &Input::Force {
            force_n: f64::NAN,
            release_s: None,
        },
        0.1,
        1e-3,
    )
    .unwrap_err();
    assert!(e.field() == "input.force_n", "{e}");
    let e = simulate(
        &params,
        ModelKind::Double,
        &Input::Force {
            force_n: 5.0,
            release_s: Some(-1.0),
        },
        0.1,
        1e-3,
    )
    .unwrap_err();
    assert!(e.to_string().contains("release_s"), "{e}");
    let e = simulate(
        &params,
        ModelKind::Double,
        &Input::Force {
            force_n: 5.0,
            release_s: None,
        },
        0.0,
        1e-3,
    )
    .unwrap_err();
    assert!(e.to_string().contains("duration_s"), "{e}");
}

#[test]
fn a_ramped_force_is_a_table_and_strikes_later_and_softer_than_a_step() {
    use piano_action::scenario::Scenario;
    let head = "model = \"double\"\nduration_s = 0.15\n[input]\nkind = \"force\"\n";
    let ramp = Scenario::from_toml_str(&format!("{head}force_n = 8.0\nramp_s = 0.04\n")).unwrap();
    assert_eq!(
        ramp.input.to_input().unwrap(),
        Input::ForceTable {
            points: vec![(0.0, 0.0), (0.04, 8.0)]
        }
    );
    let step = Scenario::from_toml_str(&format!("{head}force_n = 8.0\n")).unwrap();
    let table =
        Scenario::from_toml_str(&format!("{head}points = [[0.0, 0.0], [0.04, 8.0]]\n")).unwrap();
    let params = ActionParams::reference();
    let (ramp, step, table) = (
        ramp.run(&params).unwrap(),
        step.run(&params).unwrap(),
        table.run(&params).unwrap(),
    );
    assert_eq!(ramp.strikes, table.strikes, "the same table");
    let (r, s) = (ramp.strikes[0], step.strikes[0]);
    assert!(r.time_s > s.time_s + 0.005, "ramp {r:?} step {s:?}");
    assert!(
        r.hammer_velocity_m_s < s.hammer_velocity_m_s,
        "ramp {r:?} step {s:?}"
    );
    // Misplaced and missing fields are named.
    for (body, field) in [
        ("points = [[0.0, 1.0]]\nforce_n = 2.0\n", "input.force_n"),
        ("ramp_s = 0.01\n", "input.force_n"),
        (
            "force_n = 2.0\nramp_s = 0.05\nrelease_s = 0.01\n",
            "input.release_s",
        ),
        ("points = [[0.1, 1.0], [0.05, 2.0]]\n", "input.points"),
    ] {
        let e = Scenario::from_toml_str(&format!("{head}{body}"))
            .and_then(|s| s.run(&params))
            .unwrap_err();
        assert!(e.to_string().contains(field), "{body}: {e}");
    }
}

#[test]
fn a_key_motion_can_come_from_a_csv_file_beside_the_scenario() {
    use piano_action::scenario::Scenario;
    let dir = std::env::temp_dir().join(format!("piano-motion-csv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("key.csv"),
        "time_s,depth_mm\n0.0,0.0\n0.03,10.0\n# held\n0.08,10.0\n",
    )
    .unwrap();
    let path = dir.join("motion.toml");
    std::fs::write(
        &path,
        "model = \"double\"\nduration_s = 0.08\n[input]\nkind = \"motion\"\ncsv = \"key.csv\"\n",
    )
    .unwrap();
    let from_csv = Scenario::load(&path).unwrap();
    let inline = Scenario::from_toml_str(
        "model = \"double\"\nduration_s = 0.08\n[input]\nkind = \"motion\"\npoints = [[0.0, 0.0], [0.03, 10.0], [0.08, 10.0]]\n",
    )
    .unwrap();
    let params = ActionParams::reference();
    let (a, b) = (from_csv.run(&params).unwrap(), inline.run(&params).unwrap());
    assert!(!a.strikes.is_empty());
    assert_eq!(a.strikes, b.strikes);
    // A bad row names the file and the line; a missing file names it.
    std::fs::write(dir.join("key.csv"), "0.0,0.0\n0.03,ten\n").unwrap();
    let e = Scenario::load(&path).unwrap_err().to_string();
    assert!(
        e.contains("key.csv, line 2") && e.contains("'ten' is not a number"),
        "{e}"
    );
    // Rows with an extra cell, times out of order or negative, and depths out of range are
    // refused at their CSV line.
    for (rows, line, what) in [
        ("0.0,0.0\n0.03,10.0,1\n", 2, "3 cells"),
        (
            "time_s,depth_mm\n0.0,0.0\n0.03,10.0\n0.02,10.0\n",
            4,
            "must increase",
        ),
        ("-0.01,0.0\n0.03,10.0\n", 1, "negative"),
        ("0.0,0.0\n\n0.03,10.0\n0.05,35.0\n", 4, "outside -20..20 mm"),
    ] {
        std::fs::write(dir.join("key.csv"), rows).unwrap();
        let e = Scenario::load(&path).unwrap_err().to_string();
        assert!(
            e.contains(&format!("key.csv, line {line}:")) && e.contains(what),
            "{rows}: {e}"
        );
    }
    std::fs::remove_file(dir.join("key.csv")).unwrap();
    let e = Scenario::load(&path).unwrap_err().to_string();
    assert!(e.contains("input.csv") && e.contains("key.csv"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn blended_linear_refuses_an_empty_or_unordered_table_instead_of_panicking() {
    use mbs_core::Drive;
    use piano_action::simulate::BlendedLinear;
    assert!(BlendedLinear::new(&[], 5e-3).is_err());
    assert!(BlendedLinear::new(&[(0.0, 0.0), (0.0, 1.0)], 5e-3).is_err());
    assert!(BlendedLinear::new(&[(0.0, f64::NAN)], 5e-3).is_err());
    assert!(BlendedLinear::new(&[(0.0, 0.0)], -1.0).is_err());
    // One point: a constant.
    let one = BlendedLinear::new(&[(0.1, 2.0)], 5e-3).unwrap();
    assert_eq!(one.eval(0.0).q, 2.0);
    assert_eq!(one.eval(1.0).v, 0.0);
}

#[test]
fn a_run_reports_its_progress_step_by_step_up_to_its_duration() {
    // What drives `piano simulate`'s progress bar for long runs.
    let params = ActionParams::reference();
    let mut seen: Vec<f64> = Vec::new();
    let run = piano_action::simulate::simulate_observed(
        &params,
        ModelKind::Double,
        &Input::Force {
            force_n: 10.0,
            release_s: None,
        },
        0.05,
        1e-3,
        &mut |t| seen.push(t),
    )
    .unwrap();
    assert!(seen.len() > 10, "{} progress calls", seen.len());
    assert!(seen.windows(2).all(|w| w[1] > w[0]), "times increase");
    assert!((seen[seen.len() - 1] - 0.05).abs() < 1e-12);
    assert!(!run.strikes.is_empty());
}

/// An integration that cannot start keeps the integrator's error as its cause (a typed
/// source, not a string).
#[test]
fn a_failed_integration_keeps_the_integrators_error() {
    let action = piano_action::Action::build(
        &piano_action::ActionParams::reference(),
        piano_action::ModelKind::Double,
    )
    .unwrap();
    let mut x0 = action.layout_state().unwrap();
    x0[0] = f64::NAN;
    let e = action.integrate(&x0, 0.01, 1e-3, None).unwrap_err();
    assert!(
        matches!(e, piano_action::PianoError::Integrator(_)),
        "{e:?}"
    );
    assert!(e.to_string().starts_with("simulation failed: "), "{e}");
    let cause = std::error::Error::source(&e).expect("the integrator's error is kept");
    assert!(
        cause
            .downcast_ref::<mbs_integrators::IntegratorError>()
            .is_some()
    );
}
