//! Fuzzing harness (not part of the API): the bodies of the `cargo fuzz` targets in `fuzz/`
//! and of the corpus replay in `tests/fuzz_corpus.rs`, kept here so the two cannot drift.
//!
//! Each function takes the raw bytes of one input (invalid UTF-8 is skipped), runs the
//! parsers and a little of what follows a successful parse, and returns whether the input
//! was accepted. The library itself must never panic on such input; these functions panic
//! on purpose (with a message starting `fuzz oracle:`) when a result breaks an invariant a
//! caller relies on, so that the fuzzer reports it as a finding.

use crate::builder::{BodySpec, JointKind, ModelBuilder, Placement};
use crate::description::ModelDescription;
use crate::error::CoreError;
use crate::inspect::{StatesFile, inspect};
use crate::model::Model;
use crate::{Data, aba, crba, forward_dynamics_crba, gravity_torque, nonlinear_effects, rnea};

/// An error must say something.
fn check_message(what: &str, e: &CoreError) {
    assert!(
        !e.to_string().trim().is_empty(),
        "fuzz oracle: {what} returned an error with an empty message: {e:?}"
    );
}

/// Errors that mean the caller passed a wrong-sized argument: never expected when the
/// arguments are sized from the model itself.
fn is_size_error(e: &CoreError) -> bool {
    matches!(
        e,
        CoreError::DimensionMismatch { .. }
            | CoreError::WorkspaceMismatch { .. }
            | CoreError::ShapeMismatch { .. }
    )
}

/// Target `model_json`: parses a model description, checks that it survives a round trip
/// through its own JSON, builds it and evaluates RNEA, CRBA, ABA, the nonlinear effects,
/// the gravity torques and CRBA forward dynamics at the zero state.
pub fn model_json(bytes: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    let description = match ModelDescription::from_json_str(text) {
        Ok(d) => d,
        Err(e) => {
            check_message("ModelDescription::from_json_str", &e);
            return false;
        }
    };
    // What we write, we read back unchanged.
    let written = description.to_json_string();
    match ModelDescription::from_json_str(&written) {
        Ok(again) => assert!(
            again == description,
            "fuzz oracle: model description changed in a JSON round trip:\n{written}"
        ),
        Err(e) => panic!("fuzz oracle: written model description does not parse ({e}):\n{written}"),
    }
    let model = match Model::from_json_str(text) {
        Ok(m) => m,
        Err(e) => {
            check_message("Model::from_json_str", &e);
            return false;
        }
    };
    exercise_model(&model);
    true
}

/// Evaluates the algorithms at the zero state of `model`; only non-size errors (such as a
/// mass matrix that is not positive definite for extreme inputs) are acceptable.
fn exercise_model(model: &Model) {
    let n = model.nv();
    assert!(n > 0, "fuzz oracle: a built model has no coordinate");
    let mut data = Data::new(model);
    let zero = vec![0.0; n];
    let results = [
        ("rnea", rnea(model, &mut data, &zero, &zero, &zero).err()),
        ("crba", crba(model, &mut data, &zero).err()),
        ("aba", aba(model, &mut data, &zero, &zero, &zero).err()),
        (
            "nonlinear_effects",
            nonlinear_effects(model, &mut data, &zero, &zero).err(),
        ),
        (
            "gravity_torque",
            gravity_torque(model, &mut data, &zero).err(),
        ),
        (
            "forward_dynamics_crba",
            forward_dynamics_crba(model, &mut data, &zero, &zero, &zero, None).err(),
        ),
    ];
    for (what, err) in results {
        if let Some(e) = err {
            assert!(
                !is_size_error(&e),
                "fuzz oracle: {what} at the zero state of a valid model: {e}"
            );
            check_message(what, &e);
        }
    }
}

/// The fixed model the `states_json` target evaluates states on: three coordinates (two
/// revolute, one prismatic on a skew axis) and a body merged by a fixed joint.
pub fn states_model() -> Model {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81])
        .add_link(
            "upper",
            None,
            JointKind::Revolute,
            Placement::default(),
            BodySpec::rod(1.0, 1.0),
        )
        .add_link(
            "lower",
            Some("upper"),
            JointKind::Revolute,
            Placement::new(0.1, 1.0, 0.0),
            BodySpec::rod(0.5, 0.8),
        )
        .add_link(
            "slider",
            Some("lower"),
            JointKind::Prismatic { axis: [1.0, 0.5] },
            Placement::new(-0.3, 0.8, 0.05),
            BodySpec::new(0.2, [0.01, 0.02], 1e-3),
        )
        .add_link(
            "weight",
            Some("slider"),
            JointKind::Fixed,
            Placement::offset(0.05, 0.0),
            BodySpec::new(0.1, [0.0, 0.0], 1e-4),
        );
    match b.build() {
        Ok(m) => m,
        // A fixed, tested model: failing to build it is a defect of this file.
        Err(e) => unreachable!("the fuzzing model does not build: {e}"),
    }
}

/// Target `states_json`: parses an inspect states file and evaluates it on
/// [`states_model`]. A report must hold only finite numbers: states that overflow must be
/// refused with an error naming the state.
pub fn states_json(bytes: &[u8]) -> bool {
    states_json_on(&states_model(), bytes)
}

/// [`states_json`] on a given model (the replay builds the model once).
pub fn states_json_on(model: &Model, bytes: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    let states = match StatesFile::from_json_str(text) {
        Ok(s) => s,
        Err(e) => {
            check_message("StatesFile::from_json_str", &e);
            return false;
        }
    };
    match inspect(model, &states) {
        Ok(report) => {
            assert_eq!(
                report.states.len(),
                states.states.len(),
                "fuzz oracle: inspect reported a different number of states"
            );
            for (k, s) in report.states.iter().enumerate() {
                let all = s
                    .mass_matrix
                    .iter()
                    .flatten()
                    .chain(&s.rnea_tau)
                    .chain(&s.nonlinear_effects)
                    .chain(&s.gravity_torque)
                    .chain(&s.aba_qdd);
                for x in all {
                    assert!(
                        x.is_finite(),
                        "fuzz oracle: inspect returned a non-finite number ({x}) for state {k}"
                    );
                }
            }
            true
        }
        Err(e) => {
            check_message("inspect", &e);
            false
        }
    }
}

/// Runs `body` on every file of the corpus folder `corpus_root/target` in name order (the
/// replay in `cargo test` of what the fuzzer found), naming the file of a panic; returns
/// how many inputs were accepted. Panics if the folder is missing or empty: the corpora
/// are committed, and a replay that finds nothing must not pass quietly.
pub fn replay_corpus(
    corpus_root: &std::path::Path,
    target: &str,
    body: impl Fn(&[u8]) -> bool,
) -> usize {
    let dir = corpus_root.join(target);
    let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| {
        panic!(
            "fuzz corpus {} is missing ({e}): it is committed with the repository",
            dir.display()
        )
    });
    let mut files: Vec<std::path::PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    assert!(!files.is_empty(), "fuzz corpus {} is empty", dir.display());
    let mut accepted = 0;
    for path in &files {
        let bytes = std::fs::read(path)
            .unwrap_or_else(|e| panic!("cannot read corpus file {}: {e}", path.display()));
        let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| body(&bytes)));
        match outcome {
            Ok(ok) => accepted += usize::from(ok),
            Err(_) => panic!("{target}: input {} panicked (see above)", path.display()),
        }
    }
    println!("{target}: {} inputs, {accepted} accepted", files.len());
    accepted
}
