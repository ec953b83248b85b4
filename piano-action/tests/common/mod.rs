//! What the CLI tests share: running the `piano` command as a user does.

use std::process::Command;

/// Runs `piano ARGS`: whether it succeeded, its standard output and its standard error.
pub fn piano(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_piano"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
