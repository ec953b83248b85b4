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
    // Measured as a technician regulates: let-off on a slow press, the check with the key
    // held down after the blow.
    let slow = press(0.8, 0.3);
    // Blow: 46.0 mm from the layout's rest (§4.4) [D]; settled on the rail and the felts,
    // within 1 mm.
    let blow = crown_to_string_mm(&slow.mechanism, &slow.built, 0.0, &slow.x0).unwrap();
    assert!((blow - 46.0).abs() < 1.0, "blow {blow:.2} mm");
    // Let-off: the jack leaves the notch about 3 mm from the string (1/8" [V]; layout
    // 3.1 mm [D]): 2-5 mm on a slow press.
    let let_off = distance_at(&slow, "escape");
    assert!(
        (2.0..5.0).contains(&let_off),
        "slow press: escape at {let_off:.2} mm from the string"
    );
    // Check: the hammer held 15-19 mm from the string with the key down (layout §3 [V]),
    // here at the end of the slow press.
    let check = crown_to_string_mm(
        &slow.mechanism,
        &slow.built,
        slow.solution.t_final,
        &slow.solution.y_final,
    )
    .unwrap();
    // In motion (10 N) the top slides off the lip while the hammer flies on: let-off nearer
    // the string, 1-5 mm.
    let hard = press(10.0, 0.12);
    let escape = distance_at(&hard, "escape");
    eprintln!(
        "upright: blow {blow:.2} mm, let-off {let_off:.2} mm (slow) and {escape:.2} mm (10 N), \
         check {check:.2} mm (key held)"
    );
    assert!(
        (13.0..19.0).contains(&check),
        "held at {check:.2} mm from the string"
    );
    assert!(
        (1.0..5.0).contains(&escape),
        "10 N: escape at {escape:.2} mm from the string"
    );
}

#[test]
fn a_keystroke_lifts_lets_off_before_the_string_strikes_and_checks() {
    let run = press(10.0, 0.12);
    let let_off = first(&run, "let_off").expect("the toe meets the button");
    let escape = first(&run, "escape").expect("the jack leaves the notch");
    let strike = first(&run, "strike").expect("the hammer strikes");
    // The back-check can brush the catcher as a hard press takes up the lost motion; the
    // check is the first touch after the strike.
    let check = run
        .events
        .iter()
        .find(|e| e.name == "check" && e.time_s > strike)
        .map(|e| e.time_s)
        .expect("the catcher is caught");
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
    let code = upright_mechanism().unwrap();
    if file != code {
        // Name the first line that differs rather than print two whole descriptions.
        let (a, b) = (
            file.to_toml_string().unwrap(),
            code.to_toml_string().unwrap(),
        );
        let first = a
            .lines()
            .zip(b.lines())
            .enumerate()
            .find(|(_, (x, y))| x != y)
            .map(|(i, (x, y))| format!("line {}: file `{x}`, code `{y}`", i + 1))
            .unwrap_or_else(|| "the files differ in length".into());
        panic!(
            "examples/mechanisms/upright.toml is not what the code writes ({first}); \
             regenerate it: cargo run --release --example upright && cp \
             target/upright/upright.toml examples/mechanisms/"
        );
    }
}
