//! `cargo run --release --example upright`: the upright piano action of `examples/upright`
//! (written through `piano-action`'s public API from `upright_layout.md`), played softly
//! (5 N on the key) and loudly (30 N), released at 60 ms: run directories, the description
//! as TOML and one interactive report in `target/upright/`.

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
    let mechanism = upright_action::upright_mechanism()?;
    let params = ActionParams::reference();
    let root = Path::new("target/upright");
    std::fs::create_dir_all(root)?;
    mechanism.save(&root.join("upright.toml"))?;
    let mut dirs = Vec::new();
    for (name, force_n) in [("soft", 5.0), ("loud", 30.0)] {
        let force = ForceSpec {
            force_n: Some(force_n),
            ramp_s: None,
            release_s: Some(0.06),
            points: None,
        };
        let scenario =
            Scenario::for_mechanism("upright.toml", mechanism.clone(), force, 0.15, 2e-4)?;
        let run = scenario.run_mechanism(&params, &mut |_| {})?;
        let dir = root.join(name);
        prepare_run_dir(&dir, true)?;
        write_mechanism_run_dir(&dir, &scenario, &params.numerics, &run)?;
        println!("{name}: {force_n} N on the key front until 60 ms");
        for e in &run.events {
            println!("  {:<14} {:7.2} ms", e.name, e.time_s * 1e3);
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
    write_report(&dirs, &report, true)?;
    println!("report: {}", report.display());
    Ok(())
}
