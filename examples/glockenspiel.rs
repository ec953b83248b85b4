//! `cargo run --release --example glockenspiel`: a keyboard glockenspiel note — not a
//! piano — from its description (`examples/mechanisms/glockenspiel.toml`), played softly
//! (2 N on the key for 30 ms) and loudly (10 N), through `piano-action`'s public API: run
//! directories and one interactive report in `target/glockenspiel/`.

use std::path::Path;
use std::process::ExitCode;

fn main() -> ExitCode {
    let played = examples::glockenspiel()
        .map_err(Box::<dyn std::error::Error>::from)
        .and_then(|m| {
            examples::play_and_report(
                &m,
                "examples/mechanisms/glockenspiel.toml",
                Path::new("target/glockenspiel"),
                &[("soft", 2.0), ("loud", 10.0)],
                0.03,
                0.08,
                1e-4,
            )
        });
    match played {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
