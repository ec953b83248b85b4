//! `cargo run --release --example glockenspiel`: a keyboard glockenspiel note — not a
//! piano — from its description (`examples/mechanisms/glockenspiel.toml`), played softly
//! (2 N on the key for 30 ms) and loudly (10 N), through `piano-action`'s public API: run
//! directories and one interactive report in `target/glockenspiel/`.

use std::path::Path;
use std::process::ExitCode;

use piano_action::ActionParams;
use piano_action::mechanism_run::write_mechanism_run_dir;
use piano_action::report::write_report;
use piano_action::scenario::{ForceSpec, Scenario, prepare_run_dir};

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mechanism = examples::glockenspiel()?;
    // The integrator's tolerances and event sampling of the piano's reference numerics.
    let params = ActionParams::reference();
    let root = Path::new("target/glockenspiel");
    let mut dirs = Vec::new();
    for (name, force_n) in [("soft", 2.0), ("loud", 10.0)] {
        let force = ForceSpec {
            force_n: Some(force_n),
            ramp_s: None,
            release_s: Some(0.03),
            points: None,
        };
        let scenario = Scenario::for_mechanism(
            "examples/mechanisms/glockenspiel.toml",
            mechanism.clone(),
            force,
            0.08,
            1e-4,
        )?;
        let run = scenario.run_mechanism(&params, &mut |_| {})?;
        let dir = root.join(name);
        prepare_run_dir(&dir, true)?;
        write_mechanism_run_dir(&dir, &scenario, &params.numerics, &run)?;
        println!("{name}: {force_n} N on the key for 30 ms");
        for m in &run.metrics {
            match m.value {
                Some(v) => println!("  {:<26} {v:.4} {}", m.name, m.unit),
                None => println!("  {:<26} (did not happen)", m.name),
            }
        }
        dirs.push(dir);
    }
    let report = root.join("report.html");
    write_report(&dirs, &report, true)?;
    println!("report: {}", report.display());
    Ok(())
}
