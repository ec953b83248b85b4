//! `cargo run --release --example upright`: the upright piano action of `examples/upright`
//! (written through `piano-action`'s public API from `docs/reference/upright_layout.md`),
//! played softly (5 N on the key) and loudly (30 N), released at 60 ms: run directories,
//! the description as TOML and one interactive report in `target/upright/`.

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
