//! Small programs a newcomer runs first; see the `[[example]]` entries of this crate:
//!
//! ```text
//! cargo run --release --example double_pendulum
//! cargo run --release --example glockenspiel
//! ```
//!
//! And mechanisms that are not the grand action, written as descriptions
//! (`examples/mechanisms/`): a keyboard glockenspiel note, [`glockenspiel`].

use piano_action::mechanism::{Mechanism, MechanismError};

/// The keyboard glockenspiel note of `examples/mechanisms/glockenspiel.toml`: a key throws
/// a felt hammer against a steel bar that rings at 1046.5 Hz (sources in the file).
pub const GLOCKENSPIEL_TOML: &str = include_str!("../mechanisms/glockenspiel.toml");

/// [`GLOCKENSPIEL_TOML`], read and checked.
pub fn glockenspiel() -> Result<Mechanism, MechanismError> {
    let m = Mechanism::from_toml_str(GLOCKENSPIEL_TOML).map_err(|e| {
        e.in_file(
            "examples/mechanisms/glockenspiel.toml",
            Some(GLOCKENSPIEL_TOML),
        )
    })?;
    m.validate().map_err(|e| {
        e.in_file(
            "examples/mechanisms/glockenspiel.toml",
            Some(GLOCKENSPIEL_TOML),
        )
    })?;
    Ok(m)
}

/// Plays `mechanism` once per `(name, force_n)` keystroke (a force on its first force input
/// from t = 0, released at `release_s`, `duration_s` long, output every `output_step_s`),
/// writes each run directory under `root`, prints the named events and metrics, and writes
/// one report of them all, `root/report.html`. `file` is what the run directories record as
/// the description's file.
pub fn play_and_report(
    mechanism: &Mechanism,
    file: &str,
    root: &std::path::Path,
    keystrokes: &[(&str, f64)],
    release_s: f64,
    duration_s: f64,
    output_step_s: f64,
) -> Result<std::path::PathBuf, Box<dyn std::error::Error>> {
    use piano_action::scenario::{ForceSpec, Scenario, prepare_run_dir};
    // The integrator's tolerances and event sampling of the piano's reference numerics.
    let params = piano_action::ActionParams::reference();
    let mut dirs = Vec::new();
    for &(name, force_n) in keystrokes {
        let force = ForceSpec {
            force_n: Some(force_n),
            ramp_s: None,
            release_s: Some(release_s),
            points: None,
        };
        let scenario =
            Scenario::for_mechanism(file, mechanism.clone(), force, duration_s, output_step_s)?;
        let run = scenario.run_mechanism(&params, &mut |_| {})?;
        let dir = root.join(name);
        prepare_run_dir(&dir, true)?;
        piano_action::mechanism_run::write_mechanism_run_dir(
            &dir,
            &scenario,
            &params.numerics,
            &run,
        )?;
        println!(
            "{name}: {force_n} N on the key until {:.0} ms",
            release_s * 1e3
        );
        for e in &run.events {
            println!("  {:<26} {:8.2} ms", e.name, e.time_s * 1e3);
        }
        for m in &run.metrics {
            match m.value {
                Some(v) => println!("  {:<26} {v:.4} {}", m.name, m.unit),
                None => println!("  {:<26} (did not happen)", m.name),
            }
        }
        dirs.push(dir);
    }
    let report = root.join("report.html");
    piano_action::report::write_report(&dirs, &report, true)?;
    println!("report: {}", report.display());
    Ok(report)
}
