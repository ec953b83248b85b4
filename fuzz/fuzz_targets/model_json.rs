//! Fuzz target `model_json`: the body is `mbs_core::fuzzing::model_json`, shared with the corpus replay
//! in `mbs-core/tests/fuzz_corpus.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    mbs_core::fuzzing::model_json(data);
});
