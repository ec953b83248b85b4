//! The upright action from its layout: its regulation at rest and in motion against the
//! layout's figures, its functional sequence under a keystroke, and hammer speed against
//! key force.

use piano_action::ActionParams;
use piano_action::mechanism_run::{MechanismRun, simulate_mechanism};
use piano_action::simulate::Input;
use upright_action::{crown_to_string_mm, upright_mechanism};

fn press(force_n: f64, duration_s: f64) -> MechanismRun {
    let m = upright_mechanism().expect("the description is valid");
    simulate_mechanism(
        &m,
        &Input::Force {
            force_n,
            release_s: None,
        },
        &ActionParams::reference().numerics,
        0.3,
        duration_s,
        1e-3,
        &mut |_| {},
    )
    .expect("it runs")
}

fn first(run: &MechanismRun, name: &str) -> Option<f64> {
    run.events.iter().find(|e| e.name == name).map(|e| e.time_s)
}

/// The crown-to-string distance (mm) at the integrator's record of the first `event`.
fn distance_at(run: &MechanismRun, event: &str) -> f64 {
    let e = run.events.iter().find(|e| e.name == event).expect(event);
    let record = &run.solution.events[e.record];
    crown_to_string_mm(&run.mechanism, &run.built, record.time, &record.state).unwrap()
}

#[test]
fn regulation_blow_let_off_and_check_match_the_layout() {
    let run = press(10.0, 0.12);
    // Blow: 46.0 mm from the layout's rest (§4.4) [D]; settled on the rail and the felts,
    // within 1 mm.
    let blow = crown_to_string_mm(&run.mechanism, &run.built, 0.0, &run.x0).unwrap();
    assert!((blow - 46.0).abs() < 1.0, "blow {blow:.2} mm");
    // Let-off: the jack leaves the notch about 3 mm from the string (layout: 3.1 mm
    // regulated, 1/8" [V]); in motion the hammer travels on while the top slides off the
    // lip, so 1-5 mm.
    let escape = distance_at(&run, "escape");
    assert!(
        (1.0..5.0).contains(&escape),
        "escape at {escape:.2} mm from the string"
    );
    // Check: caught 15 mm from the string with the key held (layout §3: 15-19 mm [V]; the
    // layout's 15.0 mm is rigid, at exactly 10 mm dip). In motion, at first touch with the
    // felts compressed, 11-19 mm (12.2 mm measured).
    let check = distance_at(&run, "check");
    eprintln!("upright at 10 N: blow {blow:.2} mm, escape {escape:.2} mm, check {check:.2} mm");
    assert!(
        (11.0..19.0).contains(&check),
        "checked at {check:.2} mm from the string"
    );
}

#[test]
fn a_keystroke_lifts_lets_off_before_the_string_strikes_and_checks() {
    let run = press(10.0, 0.12);
    let let_off = first(&run, "let_off").expect("the toe meets the button");
    let escape = first(&run, "escape").expect("the jack leaves the notch");
    let strike = first(&run, "strike").expect("the hammer strikes");
    let check = first(&run, "check").expect("the catcher is caught");
    assert!(
        let_off < escape && escape < strike && strike < check,
        "{let_off} {escape} {strike} {check}"
    );
    // In free flight at the strike: the jack top touches neither the seat nor the wall.
    let seat = run.built.contacts["jack_seat"];
    let wall = run.built.contacts["jack_wall"];
    let touching = run.solution.events.iter().filter(|e| {
        e.time > escape
            && e.time < strike
            && e.source
                .is_some_and(|s| s.element == seat || s.element == wall)
    });
    assert_eq!(
        touching.count(),
        0,
        "the jack stays clear of the butt until the strike"
    );
    // The string throws the hammer back and the back-check holds it: at the end the crown
    // rests well away from the string.
    let end = crown_to_string_mm(
        &run.mechanism,
        &run.built,
        run.solution.t_final,
        &run.solution.y_final,
    )
    .unwrap();
    assert!(end > 10.0, "the crown ends {end:.1} mm from the string");
}

#[test]
fn a_harder_key_force_throws_the_hammer_faster() {
    let speeds: Vec<f64> = [4.0, 10.0, 25.0]
        .into_iter()
        .map(|f| press(f, 0.1).metrics[0].value.expect("each strikes"))
        .collect();
    eprintln!("upright crown speed at 4, 10, 25 N: {speeds:?} m/s");
    assert!(
        speeds[0] < speeds[1] && speeds[1] < speeds[2],
        "{speeds:?} m/s"
    );
    // pp to ff on a real piano: about 0.5-7 m/s at the crown (literature.md §3).
    assert!(speeds[0] > 0.5 && speeds[2] < 8.0, "{speeds:?} m/s");
}

/// `examples/mechanisms/upright.toml` is this description as a file (what the browser test
/// and `piano simulate` read): it must stay what the code writes.
#[test]
fn the_description_file_is_what_the_code_writes() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms/upright.toml");
    let file = piano_action::mechanism::Mechanism::load(&path).expect("the file reads");
    assert_eq!(
        file,
        upright_mechanism().unwrap(),
        "regenerate it: cargo run --release --example upright && cp target/upright/upright.toml examples/mechanisms/"
    );
}
