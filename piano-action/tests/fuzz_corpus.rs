//! Replays the committed fuzzing corpora of `fuzz/corpus/params_toml`,
//! `fuzz/corpus/scenario_toml`, `fuzz/corpus/motion_csv` and `fuzz/corpus/measured_csv`
//! through the fuzz targets' own
//! bodies ([`piano_action::fuzzing`]) on the stable toolchain, without libFuzzer: every
//! file is run (the corpora are minimised on edge coverage: the three replay in well under
//! a second in the debug build). A panic, or an input that breaks one of the harness's
//! checks, fails the test with the file's name. A missing corpus folder is a failure, not a
//! skip.

/// Replays the corpus of `target` through `body` (see [`mbs_core::fuzzing::replay_corpus`]).
fn replay(target: &str, body: impl Fn(&[u8]) -> bool) -> usize {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../fuzz/corpus");
    mbs_core::fuzzing::replay_corpus(&root, target, body)
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
