//! The Python package's tests (`piano-py/tests/test_*.py`, pytest), run by `cargo test`.
//!
//! They need a Python environment with the package installed (`pip install
//! "./piano-py[test]"`, as `.ci/run` does into `target/pyenv`): `PIANO_PYTHON` names its
//! interpreter, else `target/pyenv/bin/python` is used. Without one this test says
//! `SKIPPED` with how to make one, and fails instead under `PIANO_PYTHON_TESTS=required` or
//! `CI`. The package is tested as installed; when it is older than the Rust sources it is
//! built from, this test says so (SKIPPED, or FAILED where required) rather than test old
//! code: install it again.

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

#[path = "../../piano-action/tests/harness/mod.rs"]
mod harness;
use harness::Outcome;

const NAME: &str = "the_python_package_passes_its_tests";

fn main() -> ExitCode {
    harness::main(
        NAME,
        "python",
        "python3 -m venv target/pyenv && target/pyenv/bin/pip install \"./piano-py[test]\"; \
         set PIANO_PYTHON_TESTS=required to make this a failure",
        run,
    )
}

fn run() -> Outcome {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap_or(Path::new(".."))
        .to_path_buf();
    let python = std::env::var_os("PIANO_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target/pyenv/bin/python"));
    let probe = Command::new(&python)
        .args(["-c", "import piano_action, pytest, distributed, numpy"])
        .output();
    let missing = match probe {
        Err(e) => Some(format!("no Python at {} ({e})", python.display())),
        Ok(out) if !out.status.success() => Some(format!(
            "{} cannot import piano_action, pytest, distributed and numpy: {}",
            python.display(),
            String::from_utf8_lossy(&out.stderr)
                .lines()
                .last()
                .unwrap_or("")
        )),
        Ok(_) => None,
    };
    if let Some(why) = missing {
        return if harness::required("PIANO_PYTHON_TESTS") {
            Outcome::Failed(format!(
                "{why}, and the Python tests are required here (PIANO_PYTHON_TESTS=required \
                 or CI is set)"
            ))
        } else {
            Outcome::Skipped(why)
        };
    }
    if let Some(why) = stale(&python, &root) {
        return if harness::required("PIANO_PYTHON_TESTS") {
            Outcome::Failed(format!("{why}, and the Python tests are required here"))
        } else {
            Outcome::Skipped(why)
        };
    }
    // The command line the tests compare with is built by the tests (`cargo build`, a no-op
    // when `cargo test` has just built it).
    let out = Command::new(&python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg(root.join("piano-py/tests"))
        .current_dir(&root)
        .output();
    match out {
        Err(e) => Outcome::Failed(format!("cannot run pytest: {e}")),
        Ok(out) => {
            let text = format!(
                "{}{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
            if out.status.success() {
                println!(
                    "    pytest ({}): {}",
                    python.display(),
                    text.lines().last().unwrap_or("").trim()
                );
                Outcome::Passed
            } else {
                Outcome::Failed(format!("pytest failed:\n{text}"))
            }
        }
    }
}

/// Why the installed package is older than the Rust code it is built from (None when it is
/// not): its tests would test the old code.
fn stale(python: &Path, root: &Path) -> Option<String> {
    let out = Command::new(python)
        .args(["-c", "import piano_action._core as c; print(c.__file__)"])
        .output()
        .ok()?;
    let built = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    let built_at = std::fs::metadata(&built).ok()?.modified().ok()?;
    let newest = newest_source(root)?;
    (newest.1 > built_at).then(|| {
        format!(
            "the installed piano_action ({}) is older than {}; install it again: \
             {} -m pip install \"./piano-py[test]\"",
            built.display(),
            newest.0.display(),
            python.display()
        )
    })
}

/// The most recently changed Rust source or manifest of the crates the package is built
/// from.
fn newest_source(root: &Path) -> Option<(PathBuf, std::time::SystemTime)> {
    let mut newest: Option<(PathBuf, std::time::SystemTime)> = None;
    let mut stack: Vec<PathBuf> = [
        "piano-py/src",
        "piano-py/Cargo.toml",
        "piano-action/src",
        "mbs-core/src",
        "mbs-contact/src",
        "mbs-integrators/src",
        "mbs-identify/src",
        "mbs-mechanism/src",
    ]
    .iter()
    .map(|p| root.join(p))
    .collect();
    while let Some(path) = stack.pop() {
        let Ok(meta) = std::fs::metadata(&path) else {
            continue;
        };
        if meta.is_dir() {
            if let Ok(entries) = std::fs::read_dir(&path) {
                stack.extend(entries.flatten().map(|e| e.path()));
            }
            continue;
        }
        let source = path
            .extension()
            .is_some_and(|e| e == "rs" || e == "toml" || e == "csv");
        if let (true, Ok(at)) = (source, meta.modified())
            && newest.as_ref().is_none_or(|(_, t)| at > *t)
        {
            newest = Some((path, at));
        }
    }
    newest
}
