//! Replays the committed fuzzing corpora of `fuzz/corpus/params_toml`,
//! `fuzz/corpus/scenario_toml`, `fuzz/corpus/motion_csv` and `fuzz/corpus/measured_csv`
//! through the fuzz targets' own
//! bodies ([`piano_action::fuzzing`]) on the stable toolchain, without libFuzzer: every
//! file is run (the corpora are minimised on edge coverage: the three replay in well under
//! a second in the debug build). A panic, or an input that breaks one of the harness's
//! checks, fails the test with the file's name. A missing corpus folder is a failure, not a
//! skip.

use std::path::{Path, PathBuf};

/// The files of `fuzz/corpus/<target>`, sorted; panics if the folder is missing or empty.
fn corpus(target: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../fuzz/corpus")
        .join(target);
    let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| {
        panic!(
            "fuzz corpus {} is missing ({e}): it is committed with the repository",
            dir.display()
        )
    });
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.expect("readable corpus entry").path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "fuzz corpus {} is empty", dir.display());
    files
}

/// Runs `body` on every file of the corpus, naming the file of a panic; returns how many
/// inputs were accepted.
fn replay(target: &str, body: impl Fn(&[u8]) -> bool) -> usize {
    let files = corpus(target);
    let mut accepted = 0;
    for path in &files {
        let bytes = std::fs::read(path).expect("readable corpus file");
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| body(&bytes)));
        match outcome {
            Ok(ok) => accepted += usize::from(ok),
            Err(_) => panic!("{target}: input {} panicked (see above)", path.display()),
        }
    }
    println!("{target}: {} inputs, {accepted} accepted", files.len());
    accepted
}

#[test]
fn params_toml_corpus_replays_without_panics() {
    let accepted = replay("params_toml", piano_action::fuzzing::params_toml);
    // The seeds include the embedded default parameter file.
    assert!(accepted > 0, "no parameter file of the corpus is accepted");
}

#[test]
fn scenario_toml_corpus_replays_without_panics() {
    let accepted = replay("scenario_toml", piano_action::fuzzing::scenario_toml);
    // The seeds include the shipped scenarios.
    assert!(accepted > 0, "no scenario of the corpus is accepted");
}

#[test]
fn motion_csv_corpus_replays_without_panics() {
    let accepted = replay("motion_csv", piano_action::fuzzing::motion_csv);
    assert!(accepted > 0, "no motion file of the corpus is accepted");
}

#[test]
fn measured_csv_corpus_replays_without_panics() {
    let accepted = replay("measured_csv", piano_action::fuzzing::measured_csv);
    assert!(accepted > 0, "no measured file of the corpus is accepted");
}
