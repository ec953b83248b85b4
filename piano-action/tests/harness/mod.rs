//! A test binary with its own `main` (`harness = false`), for tests that need something
//! outside cargo (a browser, a Python environment): what it prints is not captured, so when
//! that something is missing it says `SKIPPED` on the terminal of `cargo test`, with how to
//! get it; and it fails instead when the environment asks for it (`<VAR>=required`, or `CI`
//! set, as on CI services). Shared by `piano-action/tests/browser.rs` and
//! `piano-py/tests/python.rs`.

use std::process::ExitCode;

/// What a test came to.
pub enum Outcome {
    /// It ran and passed.
    Passed,
    /// It could not run here, and why.
    Skipped(String),
    /// It ran and failed, or could not run where it is required.
    Failed(String),
}

/// Runs the test `name` (`kind` names it on the terminal) if the command line selects it,
/// prints its outcome as libtest would, with `hint` under a skip, and gives the exit code.
pub fn main(name: &str, kind: &str, hint: &str, run: fn() -> Outcome) -> ExitCode {
    if !selected(name, std::env::args().skip(1).collect()) {
        return ExitCode::SUCCESS;
    }
    println!("\nrunning 1 test ({kind})");
    let outcome = run();
    let (word, code) = match &outcome {
        Outcome::Passed => ("ok", ExitCode::SUCCESS),
        Outcome::Skipped(_) => ("SKIPPED", ExitCode::SUCCESS),
        Outcome::Failed(_) => ("FAILED", ExitCode::FAILURE),
    };
    println!("test {name} ... {word}");
    match outcome {
        Outcome::Passed => {}
        Outcome::Skipped(why) => println!("    SKIPPED: {why}\n    ({hint})"),
        Outcome::Failed(why) => println!("\n{why}"),
    }
    println!();
    code
}

/// Whether a missing tool is a failure here: `var` is `required`, or `CI` is set.
pub fn required(var: &str) -> bool {
    std::env::var(var).is_ok_and(|v| v == "required")
        || std::env::var_os("CI").is_some_and(|v| !v.is_empty() && v != "false")
}

/// Whether the command line (as `cargo test` passes it on to every test binary) selects
/// the test `name`: the libtest options that matter here are honoured (`FILTER`, `--exact`,
/// `--skip PATTERN`, `--ignored`, `--list`), the others are ignored.
fn selected(name: &str, args: Vec<String>) -> bool {
    let (mut filters, mut skips) = (Vec::new(), Vec::new());
    let (mut exact, mut ignored_only) = (false, false);
    let mut args = args.into_iter();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--list" => {
                println!("{name}: test");
                return false;
            }
            "--exact" => exact = true,
            "--ignored" => ignored_only = true,
            "--skip" => skips.extend(args.next()),
            "--test-threads" | "--format" | "--color" | "--logfile" | "-Z" | "--shuffle-seed" => {
                args.next();
            }
            _ if a.starts_with('-') => {}
            _ => filters.push(a),
        }
    }
    let matches = |f: &String| {
        if exact {
            name == f
        } else {
            name.contains(f.as_str())
        }
    };
    !ignored_only
        && (filters.is_empty() || filters.iter().any(matches))
        && !skips.iter().any(|s| name.contains(s.as_str()))
}
