//! `cargo run --release --example upright`: the upright piano action of `examples/upright`
//! (written through `piano-action`'s public API from `docs/reference/upright_layout.md`),
//! played softly (5 N on the key) and loudly (30 N), released at 60 ms: run directories,
//! the description as TOML and one interactive report in `target/upright/`. Then its
//! repetition against the grand's double escapement (`upright_action::repetition`): the
//! key rise each needs before the jack is back under the hammer, and the fastest
//! repetition of 10 N presses.

use std::path::Path;
use std::process::ExitCode;

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mechanism = upright_action::upright_mechanism()?;
    let root = Path::new("target/upright");
    std::fs::create_dir_all(root)?;
    mechanism.save(&root.join("upright.toml"))?;
    examples::play_and_report(
        &mechanism,
        "upright.toml",
        root,
        &[("soft", 5.0), ("loud", 30.0)],
        0.06,
        0.15,
        2e-4,
    )?;

    use upright_action::repetition::{Action, fastest_repetition_hz, key_rise_to_repeat};
    println!("\nrepetition, upright against the grand double escapement:");
    for speed in [20.0, 100.0] {
        for action in [Action::Grand, Action::Upright] {
            let r = key_rise_to_repeat(action, speed)?;
            let rise = r
                .rise_mm
                .map_or("not back under the hammer".into(), |m| format!("{m:.2} mm"));
            println!(
                "  key let up at {speed:>3} mm/s, {action:?}: jack back after a rise of {rise} \
                 (pressed {:.2} mm)",
                r.depth_mm
            );
        }
    }
    let rates: Vec<f64> = (4..=24).map(f64::from).collect();
    for rest_n in [0.2, 0.0] {
        for action in [Action::Grand, Action::Upright] {
            let fastest = fastest_repetition_hz(action, 10.0, rest_n, &rates, 5)?
                .map_or("under 4".into(), |f| format!("{f}"));
            let finger = if rest_n > 0.0 {
                format!("finger resting {rest_n} N between")
            } else {
                "finger off the key between".into()
            };
            println!(
                "  10 N presses, {finger}, {action:?}: fastest repetition {fastest} per second"
            );
        }
    }
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
