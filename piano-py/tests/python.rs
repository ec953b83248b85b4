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
    // The command line the tests compare with: the one `cargo test --workspace` has just
    // built beside this test, when it is newer than every source it is built from; else
    // the tests build it (`cargo build -p piano-action`, whose features differ from the
    // workspace's: a second build of the dependencies, minutes on a clean clone).
    let mut pytest = Command::new(&python);
    pytest
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg(root.join("piano-py/tests"))
        .current_dir(&root);
    if std::env::var_os("PIANO_BIN").is_none() {
        match built_piano(&root) {
            Ok(bin) => {
                println!("    piano: {} (built by this cargo test)", bin.display());
                pytest.env("PIANO_BIN", bin);
            }
            Err(why) => println!("    piano: the tests build it ({why})"),
        }
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

/// The `piano` binary this test's build made (`target/debug/piano` beside
/// `target/debug/deps/python-*`), if it is newer than every source of the crates it is
/// built from; else why not.
fn built_piano(root: &Path) -> Result<PathBuf, String> {
    let exe = std::env::current_exe().map_err(|e| format!("no path to this test: {e}"))?;
    let bin = exe
        .parent()
        .and_then(Path::parent)
        .map(|dir| dir.join(format!("piano{}", std::env::consts::EXE_SUFFIX)))
        .ok_or_else(|| format!("no directory above {}", exe.display()))?;
    let built_at = std::fs::metadata(&bin)
        .and_then(|m| m.modified())
        .map_err(|_| format!("no {}", bin.display()))?;
    match newest_source(root, PIANO_SOURCES) {
        Some((path, at)) if at > built_at => Err(format!(
            "{} is older than {}",
            bin.display(),
            path.display()
        )),
        Some(_) => Ok(bin),
        None => Err("no sources found".to_string()),
    }
}

/// The sources of the `piano` command line, with the manifests and the lock file (a
/// binary built before a dependency changed is as old as one built before a source did).
const PIANO_SOURCES: &[&str] = &[
    "Cargo.toml",
    "Cargo.lock",
    "piano-action/Cargo.toml",
    "piano-action/src",
    "piano-action/validation",
    "mbs-core/Cargo.toml",
    "mbs-core/src",
    "mbs-contact/Cargo.toml",
    "mbs-contact/src",
    "mbs-integrators/Cargo.toml",
    "mbs-integrators/src",
    "mbs-identify/Cargo.toml",
    "mbs-identify/src",
    "mbs-mechanism/Cargo.toml",
    "mbs-mechanism/src",
];

/// The sources of the Python package.
const PACKAGE_SOURCES: &[&str] = &[
    "piano-py/src",
    "piano-py/Cargo.toml",
    "piano-action/src",
    "piano-action/validation",
    "mbs-core/src",
    "mbs-contact/src",
    "mbs-integrators/src",
    "mbs-identify/src",
    "mbs-mechanism/src",
];

/// Why the installed package is older than the Rust code it is built from (None when it is
/// not): its tests would test the old code.
fn stale(python: &Path, root: &Path) -> Option<String> {
    let out = Command::new(python)
        .args(["-c", "import piano_action._core as c; print(c.__file__)"])
        .output()
        .ok()?;
    let built = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
    let built_at = std::fs::metadata(&built).ok()?.modified().ok()?;
    let newest = newest_source(root, PACKAGE_SOURCES)?;
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

/// The most recently changed Rust source, manifest or embedded table under `paths`.
fn newest_source(root: &Path, paths: &[&str]) -> Option<(PathBuf, std::time::SystemTime)> {
    let mut newest: Option<(PathBuf, std::time::SystemTime)> = None;
    let mut stack: Vec<PathBuf> = paths.iter().map(|p| root.join(p)).collect();
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
        let source = path.extension().is_some_and(|e| {
            ["rs", "toml", "lock", "csv", "js", "css"]
                .iter()
                .any(|x| e == *x)
        });
        if let (true, Ok(at)) = (source, meta.modified())
            && newest.as_ref().is_none_or(|(_, t)| at > *t)
        {
            newest = Some((path, at));
        }
    }
    newest
}
