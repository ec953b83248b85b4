//! Keystrokes through `simulate`: piano events and strike metrics.

use piano_action::{ActionParams, Input, ModelKind, PianoError, simulate};

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
        let contact = strike.contact_duration_s.unwrap();
        assert!((0.5e-3..4e-3).contains(&contact), "contact {contact}");
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
    assert!(
        matches!(&e, PianoError::Params { field, .. } if field == "input.force_n"),
        "{e}"
    );
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
