//! Repetition, upright against grand (issue 14; layout §8.1–§8.2): the key rise each action
//! needs before the jack is back under the hammer, and the fastest repetition at a fixed
//! force. Both actions run from their descriptions through the same code.

use upright_action::repetition::{Action, fastest_repetition_hz, key_rise_to_repeat};

/// Slowly let up (20 mm/s at the front), the grand's repetition lever holds the hammer up
/// and its jack is back under the knuckle after a small part of the dip; the upright's
/// hammer falls back to its rail first, and its jack gets back into the notch only when
/// the key is all the way up, within the lost motion (layout §8.1: "requires letting the
/// key all the way up" [V]). Let up fast (100 mm/s) the upright's key wins the race with
/// its falling hammer and the jack resets early, as Bremmer and Wyatt describe [V], though
/// still later than the grand's.
#[test]
fn the_upright_needs_the_key_all_the_way_up_to_repeat_unless_it_rises_fast() {
    let rise = |action, speed| {
        let r = key_rise_to_repeat(action, speed).expect("it runs");
        let rise = r.rise_mm.expect("the jack gets back under the hammer");
        (rise, rise / r.depth_mm, r.depth_mm)
    };
    let (grand_slow, grand_slow_part, grand_depth) = rise(Action::Grand, 20.0);
    let (upright_slow, upright_slow_part, upright_depth) = rise(Action::Upright, 20.0);
    let (grand_fast, _, _) = rise(Action::Grand, 100.0);
    let (upright_fast, upright_fast_part, _) = rise(Action::Upright, 100.0);
    eprintln!(
        "key rise to repeat (of the pressed depth): at 20 mm/s grand {grand_slow:.2} of \
         {grand_depth:.2} mm, upright {upright_slow:.2} of {upright_depth:.2} mm; at 100 mm/s \
         grand {grand_fast:.2} mm, upright {upright_fast:.2} mm"
    );
    // The grand: well under half the dip (half release repeats, tests/repetition.rs).
    assert!(grand_slow_part < 0.4, "grand {grand_slow:.2} mm");
    // The upright, slowly: the last 5 % of the way (0.5 mm lost motion at the jack top is
    // about 3 % of the key travel).
    assert!(upright_slow_part > 0.95, "upright {upright_slow:.2} mm");
    // Fast: an early reset, above the rail, but still more than the grand needs.
    assert!(
        upright_fast_part < 0.75 && upright_fast > grand_fast,
        "upright {upright_fast:.2} mm, grand {grand_fast:.2} mm at 100 mm/s"
    );
}

/// Repeated 10 N presses, the finger resting on the key with 0.2 N (20 gf) between them:
/// the grand repeats about twice as fast as the upright (trade literature: about 14 and 7
/// notes per second, layout §8.2 [V]). The upright's key rises slowly under so light an
/// up-weight (layout §7: UW 15–18 gf), its hammer falls back to the rail first, and the
/// jack must wait for the key to come all the way up.
#[test]
fn at_a_fixed_force_the_grand_repeats_faster_than_the_upright() {
    let rates: Vec<f64> = (4..=18).map(f64::from).collect();
    let fastest = |action| {
        fastest_repetition_hz(action, 10.0, 0.2, &rates, 5)
            .expect("it runs")
            .expect("the slowest rate repeats")
    };
    let (grand, upright) = (fastest(Action::Grand), fastest(Action::Upright));
    eprintln!(
        "fastest repetition at 10 N, finger resting 0.2 N: grand {grand} Hz, upright {upright} Hz"
    );
    assert!(
        upright <= 0.75 * grand,
        "upright {upright} Hz, grand {grand} Hz"
    );
    // Within the trade literature's range for each (7 and 14 per second), to a factor 1.5.
    assert!(
        (7.0 / 1.5..=7.0 * 1.5).contains(&upright),
        "upright {upright} Hz"
    );
    assert!(
        (14.0 / 1.5..=14.0 * 1.5).contains(&grand),
        "grand {grand} Hz"
    );
}
