//! The Python package's tests (`piano-py/tests/test_*.py`, pytest), run by `cargo test`.
//!
//! They need a Python environment with the package installed (`pip install
//! "./piano-py[test]"`, as `.ci/run` does into `target/pyenv`): `PIANO_PYTHON` names its
//! interpreter, else `target/pyenv/bin/python` is used. Without one this test says
//! `SKIPPED` with how to make one, and fails instead under `PIANO_PYTHON_TESTS=required` or
//! `CI`. The package is tested as installed: after changing Rust code, install it again.

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
    // The command line the tests compare with: the one `cargo test --workspace` built
    // beside this test (`target/<profile>/piano`), else the tests build it.
    let mut pytest = Command::new(&python);
    pytest
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg(root.join("piano-py/tests"))
        .current_dir(&root);
    let beside = std::env::current_exe()
        .ok()
        .and_then(|exe| Some(exe.parent()?.parent()?.join("piano")));
    if let Some(bin) = beside.filter(|b| b.is_file()) {
        pytest.env("PIANO_BIN", bin);
    }
    let out = pytest.output();
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
