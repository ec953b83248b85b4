//! The 1 kg experiment: a mass released on the key front strikes and is checked.

use piano_action::{ActionParams, Input, ModelKind, simulate};

#[test]
fn a_one_kilogram_mass_released_on_the_key_strikes_and_the_hammer_is_checked() {
    let params = ActionParams::reference();
    for height_m in [0.0, 0.02] {
        let run = simulate(
            &params,
            ModelKind::Double,
            &Input::MassDrop {
                mass_kg: 1.0,
                height_m,
            },
            0.4,
            1e-3,
        )
        .unwrap();
        let ev: Vec<&str> = run.events.iter().map(|e| e.name).collect();
        println!("{height_m} m: {:?}\n  {ev:?}", run.strikes);
        assert!(!run.strikes.is_empty(), "{ev:?}");
        let strike = run.strikes[0];
        // Placed on the key, the mass's weight (9.8 N) drives it but must be accelerated
        // with it (four times the action's own inertia at the key front): softer than a
        // constant 8 N (3.3 m/s). Dropped 2 cm, it hits the key: a loud blow.
        assert!(
            (1.0..7.0).contains(&strike.hammer_velocity_m_s),
            "{height_m} m: {} m/s",
            strike.hammer_velocity_m_s
        );
        // Caught by the backcheck after the blow (before the heavy key, bouncing on the
        // punching, sets the double action off again).
        let check = run.check_time_s.expect("the hammer is checked");
        assert!(check > strike.time_s);
        assert!(
            run.strikes.get(1).is_none_or(|s| s.time_s > check),
            "{ev:?}"
        );
        assert!(run.key_bottom_time_s.is_some());
    }
    // Dropped from higher, the key is hit harder and the hammer goes faster.
    let fast = |h: f64| {
        simulate(
            &params,
            ModelKind::Double,
            &Input::MassDrop {
                mass_kg: 1.0,
                height_m: h,
            },
            0.3,
            1e-3,
        )
        .unwrap()
        .strikes[0]
            .hammer_velocity_m_s
    };
    assert!(fast(0.05) > fast(0.0));
    let e = simulate(
        &params,
        ModelKind::Double,
        &Input::MassDrop {
            mass_kg: -1.0,
            height_m: 0.0,
        },
        0.3,
        1e-3,
    )
    .unwrap_err();
    assert!(e.field() == "input.mass_kg", "{e}");
}
