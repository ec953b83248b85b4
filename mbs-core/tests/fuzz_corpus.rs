//! Replays the committed fuzzing corpora of `fuzz/corpus/model_json` and
//! `fuzz/corpus/states_json` through the fuzz targets' own bodies ([`mbs_core::fuzzing`])
//! on the stable toolchain, without libFuzzer: every file is run (the corpora are minimised
//! on edge coverage and replay in well under a second in the debug build). A panic, or an
//! input that breaks one of the harness's checks, fails the test with the file's name. A
//! missing corpus folder is a failure, not a skip.

/// Replays the corpus of `target` through `body` (see [`mbs_core::fuzzing::replay_corpus`]).
fn replay(target: &str, body: impl Fn(&[u8]) -> bool) -> usize {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus");
    mbs_core::fuzzing::replay_corpus(&root, target, body)
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
