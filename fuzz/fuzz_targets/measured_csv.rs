//! Fuzz target `measured_csv`: the body is `piano_action::fuzzing::measured_csv`, shared
//! with the corpus replay in `piano-action/tests/fuzz_corpus.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    piano_action::fuzzing::measured_csv(data);
});
