//! Replays the committed fuzzing corpora of `fuzz/corpus/model_json` and
//! `fuzz/corpus/states_json` through the fuzz targets' own bodies ([`mbs_core::fuzzing`])
//! on the stable toolchain, without libFuzzer: every file is run (the corpora are minimised
//! on edge coverage and replay in well under a second in the debug build). A panic, or an
//! input that breaks one of the harness's checks, fails the test with the file's name. A
//! missing corpus folder is a failure, not a skip.

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
fn model_json_corpus_replays_without_panics() {
    let accepted = replay("model_json", mbs_core::fuzzing::model_json);
    // The seeds include the README's and the golden file's models.
    assert!(accepted > 0, "no model of the corpus builds");
}

#[test]
fn states_json_corpus_replays_without_panics() {
    let model = mbs_core::fuzzing::states_model();
    let accepted = replay("states_json", |b| {
        mbs_core::fuzzing::states_json_on(&model, b)
    });
    assert!(accepted > 0, "no states file of the corpus evaluates");
}
