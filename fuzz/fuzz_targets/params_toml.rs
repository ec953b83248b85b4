//! Fuzz target `params_toml`: the body is `piano_action::fuzzing::params_toml`, shared with the corpus
//! replay in `piano-action/tests/fuzz_corpus.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    piano_action::fuzzing::params_toml(data);
});
