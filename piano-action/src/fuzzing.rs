//! Fuzzing harness (not part of the API): the bodies of the `cargo fuzz` targets in `fuzz/`
//! and of the corpus replay in `tests/fuzz_corpus.rs`, kept here so the two cannot drift.
//!
//! Each function takes the raw bytes of one input (invalid UTF-8 is skipped), runs the
//! parser and a little of what follows a successful parse (never a simulation), and returns
//! whether the input was accepted. The library itself must never panic on such input;
//! these functions panic on purpose (with a message starting `fuzz oracle:`) when a result
//! breaks an invariant a caller relies on, so that the fuzzer reports it as a finding.

use crate::action::{Action, ModelKind};
use crate::error::PianoError;
use crate::params::ActionParams;
use crate::scenario::{Scenario, read_points_csv};

/// An error must say something.
fn check_message(what: &str, e: &PianoError) {
    assert!(
        !e.to_string().trim().is_empty(),
        "fuzz oracle: {what} returned an error with an empty message: {e:?}"
    );
}

/// Target `params_toml`: parses a parameter file, checks that it survives a round trip
/// through `to_toml_string`, assembles the three models from it and evaluates each one's
/// state derivative once at its layout state.
pub fn params_toml(bytes: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    let params = match ActionParams::from_toml_str(text) {
        Ok(p) => p,
        Err(e) => {
            check_message("ActionParams::from_toml_str", &e);
            return false;
        }
    };
    // What `piano params` writes, we read back unchanged.
    match params.to_toml_string() {
        Ok(written) => match ActionParams::from_toml_str(&written) {
            Ok(again) => assert!(
                again == params,
                "fuzz oracle: parameters changed in a TOML round trip:\n{written}"
            ),
            Err(e) => panic!("fuzz oracle: written parameters do not parse ({e}):\n{written}"),
        },
        Err(e) => panic!("fuzz oracle: valid parameters cannot be written: {e}"),
    }
    for kind in ModelKind::ALL {
        exercise_action(&params, kind);
    }
    true
}

/// Builds `kind` from `params` and evaluates its derivative at the layout state; errors
/// are acceptable (absurd but finite parameters), panics are not.
fn exercise_action(params: &ActionParams, kind: ModelKind) {
    let action = match Action::build(params, kind) {
        Ok(a) => a,
        Err(e) => {
            check_message("Action::build", &e);
            return;
        }
    };
    let x = match action.layout_state() {
        Ok(x) => x,
        Err(e) => {
            check_message("Action::layout_state", &e);
            return;
        }
    };
    let system = &action.system;
    let mut ws = system.workspace();
    let mut dx = vec![0.0; system.state_len()];
    if let Err(e) = system.derivative(&mut ws, 0.0, &x, &mut dx) {
        assert!(
            !matches!(e, mbs_core::CoreError::DimensionMismatch { .. }),
            "fuzz oracle: derivative at the layout state has a size error: {e}"
        );
        check_message("System::derivative", &PianoError::Core(e));
    }
}

/// Target `scenario_toml`: parses a scenario, then turns it into a simulation input and a
/// model kind (without simulating).
pub fn scenario_toml(bytes: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    let scenario = match Scenario::from_toml_str(text) {
        Ok(s) => s,
        Err(e) => {
            check_message("Scenario::from_toml_str", &e);
            return false;
        }
    };
    let input = scenario.input.to_input();
    let kind = scenario.model_kind();
    if let Err(e) = &input {
        check_message("InputSpec::to_input", e);
    }
    if let Err(e) = &kind {
        check_message("Scenario::model_kind", e);
    }
    input.is_ok() && kind.is_ok()
}

/// The file name the `motion_csv` target passes; every error must name it.
pub const MOTION_CSV_NAME: &str = "fuzz_motion.csv";

/// Target `motion_csv`: reads `[time, value]` points from CSV text.
pub fn motion_csv(bytes: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    match read_points_csv(text, MOTION_CSV_NAME) {
        Ok(points) => {
            assert!(
                !points.is_empty(),
                "fuzz oracle: read_points_csv accepted a file without points"
            );
            true
        }
        Err(e) => {
            check_message("read_points_csv", &e);
            assert!(
                e.to_string().contains(MOTION_CSV_NAME),
                "fuzz oracle: read_points_csv error does not name the file: {e}"
            );
            false
        }
    }
}

/// The file name the `measured_csv` target passes; every error must name it.
pub const MEASURED_CSV_NAME: &str = "fuzz_measured.csv";

/// The columns the `measured_csv` target accepts: the report's plotted series.
pub const MEASURED_COLUMNS: [&str; 6] = [
    "hammer_angle_deg",
    "hammer_speed_m_s",
    "key_depth_mm",
    "kinetic_mj",
    "gravity_mj",
    "key_drive_force_n",
];

/// Target `measured_csv`: reads a `measured.csv`. What it accepts holds only finite
/// numbers, times from 0 on and increasing in every series, and one series per column.
pub fn measured_csv(bytes: &[u8]) -> bool {
    let Ok(text) = std::str::from_utf8(bytes) else {
        return false;
    };
    let path = std::path::Path::new(MEASURED_CSV_NAME);
    match crate::measured::parse_measured(text, path, &MEASURED_COLUMNS) {
        Ok(series) => {
            for s in &series {
                assert!(
                    MEASURED_COLUMNS.contains(&s.id.as_str()) && s.t.len() == s.v.len(),
                    "fuzz oracle: measured series {} is malformed",
                    s.id
                );
                assert!(
                    s.t.iter().chain(&s.v).all(|x| x.is_finite())
                        && s.t.first().is_none_or(|&t| t >= 0.0)
                        && s.t.windows(2).all(|w| w[1] > w[0]),
                    "fuzz oracle: measured series {} has bad times or values",
                    s.id
                );
            }
            true
        }
        Err(e) => {
            check_message("parse_measured", &e);
            assert!(
                e.to_string().contains(MEASURED_CSV_NAME),
                "fuzz oracle: parse_measured error does not name the file: {e}"
            );
            false
        }
    }
}
