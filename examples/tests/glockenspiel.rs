//! The keyboard glockenspiel note, a mechanism that is not a piano, run from its
//! description through piano-action's public API: the hammer is thrown (in free flight at
//! the strike), the bar rings at the frequency its numbers give, and a harder press throws
//! the hammer faster.

use piano_action::ActionParams;
use piano_action::mechanism_run::{MechanismRun, simulate_mechanism};
use piano_action::simulate::Input;

fn play(force_n: f64, output_step_s: f64) -> MechanismRun {
    play_with(force_n, output_step_s, ActionParams::reference().numerics)
}

fn play_with(
    force_n: f64,
    output_step_s: f64,
    numerics: piano_action::params::NumericsParams,
) -> MechanismRun {
    let m = examples::glockenspiel().expect("the description reads");
    simulate_mechanism(
        &m,
        &Input::Force {
            force_n,
            release_s: Some(0.03),
        },
        &numerics,
        0.3,
        0.05,
        output_step_s,
        &mut |_| {},
    )
    .expect("it runs")
}

fn first(run: &MechanismRun, name: &str) -> Option<f64> {
    run.events.iter().find(|e| e.name == name).map(|e| e.time_s)
}

#[test]
fn the_hammer_flies_free_to_the_bar_and_falls_back() {
    let run = play(6.0, 1e-4);
    let flight = first(&run, "free_flight").expect("the hammer leaves the key");
    let strike = first(&run, "strike").expect("it strikes the bar");
    let rebound = first(&run, "rebound").expect("it rebounds");
    assert!(
        flight < strike && strike < rebound,
        "{flight} {strike} {rebound}"
    );
    // Nothing touches the hammer's butt between leaving the key and the strike.
    let touched = run
        .contact_events
        .iter()
        .any(|(c, onset, t)| c == "key_butt" && *onset && (flight..strike).contains(t));
    assert!(
        !touched,
        "free flight from {flight} s to the strike at {strike} s"
    );
    // A felt head on steel stays on for about a millisecond (0.3–3 ms).
    let contact = rebound - strike;
    assert!((3e-4..3e-3).contains(&contact), "contact {contact} s");
    // It comes back down onto the key.
    assert!(
        run.contact_events
            .iter()
            .any(|(c, onset, t)| c == "key_butt" && *onset && *t > rebound),
        "lands on the key again"
    );
}

#[test]
fn the_bar_rings_at_the_frequency_of_its_mode() {
    // The bar rings with a 20 µm amplitude: the grand action's tolerances (relative 1e-3,
    // absolute 1e-6, sized for millimetre motions) let TR-BDF2 take steps whose phase error
    // shortens the period by 0.5 %; tight tolerances resolve it, so the test checks the
    // model, not the integrator's dispersion.
    let mut numerics = ActionParams::reference().numerics;
    numerics.relative_tolerance = 1e-7;
    numerics.absolute_tolerance = 1e-11;
    let run = play_with(6.0, 2e-5, numerics);
    let rebound = first(&run, "rebound").expect("rebound");
    let model = run.built.system.model();
    let bar = model.coordinate_id("bar").unwrap();
    let sol = &run.solution;
    // Upward zero crossings of the bar's motion about its rest after the hammer has left.
    let rest = run.x0[bar];
    let mut ups = Vec::new();
    for i in 1..sol.len() {
        let (t0, t1) = (sol.t[i - 1], sol.t[i]);
        let (a, b) = (sol.state(i - 1)[bar] - rest, sol.state(i)[bar] - rest);
        if t0 > rebound && a < 0.0 && b >= 0.0 {
            ups.push(t0 + (t1 - t0) * (-a) / (b - a));
        }
    }
    assert!(ups.len() > 10, "{} cycles", ups.len());
    let period = (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64;
    // f = sqrt(k / m) / 2π with the file's k = 6.92e6 N/m, m = 0.160 kg; its damping
    // (c = 0.74 N·s/m, ζ = 3.5e-4) shifts it by ζ²/2, nothing.
    let expect = (6.92e6f64 / 0.16).sqrt() / (2.0 * std::f64::consts::PI);
    let f = 1.0 / period;
    assert!(
        (f - expect).abs() < 2e-3 * expect,
        "rings at {f:.1} Hz, its mode says {expect:.1} Hz"
    );
    assert!((expect - 1046.5).abs() < 2.0, "the file's numbers give C6");
}

#[test]
fn a_harder_press_throws_the_hammer_faster() {
    let speeds: Vec<f64> = [2.0, 5.0, 10.0]
        .into_iter()
        .map(|f| {
            play(f, 1e-3).metrics[0]
                .value
                .expect("every press strikes the bar")
        })
        .collect();
    assert!(
        speeds[0] < speeds[1] && speeds[1] < speeds[2],
        "head speeds {speeds:?} m/s"
    );
    // Soft to loud: about 1 to 3 m/s, a mallet's range.
    assert!(speeds[0] > 0.5 && speeds[2] < 5.0, "{speeds:?}");
}
