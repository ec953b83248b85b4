//! A slow press, 10 mm in 2 s at the key front, held: the escapement actions let off and
//! never touch the string; the simplified one pushes the hammer to the string and holds it.

use piano_action::{Action, ActionParams, Input, ModelKind, simulate};

fn slow_press(kind: ModelKind) -> (Action, piano_action::Run) {
    let params = ActionParams::reference();
    let run = simulate(
        &params,
        kind,
        &Input::Motion {
            points: vec![(0.0, 0.0), (2.0, 10.0)],
        },
        2.5,
        2e-3,
    )
    .unwrap();
    // Gaps read off the states (the key coordinate in them follows the drive).
    let action = Action::build(&params, kind).unwrap();
    (action, run)
}

fn names(run: &piano_action::Run) -> Vec<&str> {
    run.events.iter().map(|e| e.name).collect()
}

#[test]
fn single_and_double_actions_escape_in_a_slow_press_and_never_touch_the_string() {
    for kind in [ModelKind::Single, ModelKind::Double] {
        let (action, run) = slow_press(kind);
        let ev = names(&run);
        println!("{kind:?}: {ev:?}");
        assert!(
            run.strikes.is_empty(),
            "{kind:?} touched the string: {ev:?}"
        );
        assert!(
            run.let_off_time_s.is_some(),
            "{kind:?}: toe never met the button"
        );
        let sol = &run.solution;
        let gaps: Vec<f64> = (0..sol.len())
            .map(|i| action.gap("hammer_string", sol.t[i], sol.state(i)).unwrap() * 1e3)
            .collect();
        let closest = gaps.iter().copied().fold(f64::INFINITY, f64::min);
        let end = *gaps.last().unwrap();
        // Let-off about 2 mm from the string, then the hammer falls away: onto the
        // repetition lever (double, ~1 mm drop) or much further (single, no lever).
        assert!(
            (1.0..3.0).contains(&closest),
            "{kind:?}: closest {closest} mm"
        );
        assert!(end > closest + 0.5, "{kind:?}: ends at {end} mm");
        // The jack has turned out from under the knuckle (its top escapes after about
        // 0.05 rad) and stays out while the key is held.
        let jack = action.system.model().coordinate_id("jack").unwrap();
        assert!(
            sol.y_final[jack] > 0.05,
            "{kind:?}: jack at {} rad",
            sol.y_final[jack]
        );
        // The hand's force is reported, pressing down, of the order of the touchweight.
        let f = run.key_drive_force_n[run.key_drive_force_n.len() / 2];
        assert!(
            (0.2..2.0).contains(&f),
            "{kind:?}: key force {f} N mid-press"
        );
    }
}

#[test]
fn the_simplified_action_pushes_the_hammer_to_the_string_and_holds_it_there() {
    let (action, run) = slow_press(ModelKind::Simplified);
    let ev = names(&run);
    println!("{ev:?}");
    // The crown arrives slowly (it may settle with a bounce or two of the stiff string
    // contact) and stays: the run ends in contact.
    assert!(!run.strikes.is_empty(), "{ev:?}");
    let last = run.strikes.last().unwrap();
    assert!(last.contact_duration_s.is_none(), "{ev:?}");
    let sol = &run.solution;
    assert!(
        action
            .gap("hammer_string", sol.t_final, &sol.y_final)
            .unwrap()
            < 0.0
    );
    // A quasi-static arrival, not a blow.
    assert!(
        run.strikes.iter().all(|s| s.hammer_velocity_m_s < 0.1),
        "{:?}",
        run.strikes
    );
}
