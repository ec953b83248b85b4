//! Evaluates a model at a list of states and prints the results as JSON, to cross-check
//! against another engine (Pinocchio, MuJoCo, RBDL...).
//!
//! ```text
//! cargo run --release -p mbs-core --example inspect -- MODEL.json STATES.json
//! ```
//!
//! MODEL.json is the core's model description; STATES.json is
//! `{"states": [{"q": [...], "v": [...], "a": [...], "tau": [...]}]}`. The output is
//! `{"states": [{"mass_matrix": [[...]], "rnea_tau": [...], "nonlinear_effects": [...],
//! "gravity_torque": [...], "aba_qdd": [...]}]}` with `rnea_tau = RNEA(q, v, a)` and
//! `aba_qdd = ABA(q, v, tau)`.

use std::process::ExitCode;

use mbs_core::Model;
use mbs_core::inspect::{StatesFile, inspect};

fn run(model_path: &str, states_path: &str) -> Result<String, String> {
    let read = |p: &str| std::fs::read_to_string(p).map_err(|e| format!("cannot read {p}: {e}"));
    let model =
        Model::from_json_str(&read(model_path)?).map_err(|e| format!("{model_path}: {e}"))?;
    let states = StatesFile::from_json_str(&read(states_path)?)
        .map_err(|e| format!("{states_path}: {e}"))?;
    let report = inspect(&model, &states).map_err(|e| format!("{states_path}: {e}"))?;
    serde_json::to_string_pretty(&report).map_err(|e| format!("cannot write JSON: {e}"))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() != 2 {
        eprintln!("usage: inspect MODEL.json STATES.json");
        return ExitCode::from(2);
    }
    match run(&args[0], &args[1]) {
        Ok(json) => {
            // A closed pipe (e.g. `| head`) is not an error worth a panic.
            use std::io::Write;
            let _ = writeln!(std::io::stdout(), "{json}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
