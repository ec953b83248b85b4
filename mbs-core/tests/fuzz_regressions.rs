//! Regression tests for what fuzzing found (see `fuzz/README.md`): each test is named
//! after the bug and holds the minimised input.

use mbs_core::inspect::{StatesFile, inspect};
use mbs_core::{CoreError, Model};

const DOUBLE_PENDULUM: &str = r#"{"gravity": [0.0, -9.81], "joints": [
  {"name": "upper", "parent": null, "kind": "revolute",
   "placement": {"angle": 0.0, "x": 0.0, "y": 0.0},
   "body": {"mass": 1.0, "com": [0.5, 0.0], "inertia": 0.08333333333333333}},
  {"name": "lower", "parent": "upper", "kind": "revolute",
   "placement": {"angle": 0.0, "x": 1.0, "y": 0.0},
   "body": {"mass": 1.0, "com": [0.5, 0.0], "inertia": 0.08333333333333333}}]}"#;

fn inspect_err(model: &Model, states: &str) -> String {
    let states = StatesFile::from_json_str(states).expect("the states file parses");
    match inspect(model, &states) {
        Ok(report) => panic!("expected an error, got {report:?}"),
        Err(e) => e.to_string(),
    }
}

/// `inspect` returned `inf`/`NaN` in the report (written as `null` by serde_json) for
/// finite but huge states: v = 1e300 squares to infinity in the velocity products.
#[test]
fn inspect_huge_velocity_gave_non_finite_report() {
    let model = Model::from_json_str(DOUBLE_PENDULUM).unwrap();
    let err = inspect_err(
        &model,
        r#"{"states": [{"q": [0, 0], "v": [0, 0], "a": [0, 0], "tau": [0, 0]},
                       {"q": [0, 0], "v": [1e300, 0], "a": [0, 0], "tau": [0, 0]}]}"#,
    );
    assert!(
        err.contains("states[1]") && err.contains("rnea_tau is not finite"),
        "{err}"
    );
}

/// The same through `tau` alone: ABA's accelerations overflow.
#[test]
fn inspect_huge_tau_gave_non_finite_report() {
    let model = Model::from_json_str(DOUBLE_PENDULUM).unwrap();
    let err = inspect_err(
        &model,
        r#"{"states": [{"q": [0, 0], "v": [0, 0], "a": [0, 0], "tau": [1e308, -1e308]}]}"#,
    );
    assert!(
        err.contains("states[0]") && err.contains("aba_qdd is not finite"),
        "{err}"
    );
}

/// NaN cannot be written in JSON, but a states file built in code can hold it: it is
/// named, not propagated.
#[test]
fn inspect_nan_state_is_named() {
    let model = Model::from_json_str(DOUBLE_PENDULUM).unwrap();
    let mut states = StatesFile::from_json_str(
        r#"{"states": [{"q": [0, 0], "v": [0, 0], "a": [0, 0], "tau": [0, 0]}]}"#,
    )
    .unwrap();
    states.states[0].v[1] = f64::NAN;
    let err = inspect(&model, &states).unwrap_err();
    assert!(
        matches!(&err, CoreError::States(message)
            if message.contains("states[0]") && message.contains("v[1] is not finite")),
        "{err}"
    );
}

/// serde_json's default float parser may be off by one unit in the last place (`21e300`
/// read as 2.1000000000000002e301), so a description written by `to_json_string` and read
/// back was a different model. The workspace now enables serde_json's `float_roundtrip`:
/// numbers are read exactly as Rust's `str::parse` reads them.
#[test]
fn model_json_numbers_were_parsed_inexactly_so_round_trip_changed() {
    use mbs_core::ModelDescription;
    for text in [
        "21e300",
        "0.1",
        "2.2250738585072011e-308",
        "9007199254740993",
        "1.7976931348623157e308",
        "4.9e-324",
        "123456789.123456789e-5",
    ] {
        let json = format!(r#"{{"gravity": [0.0, {text}], "joints": []}}"#);
        let d = ModelDescription::from_json_str(&json).unwrap();
        let exact: f64 = text.parse().unwrap();
        assert_eq!(d.gravity[1].to_bits(), exact.to_bits(), "{text}");
        let again = ModelDescription::from_json_str(&d.to_json_string()).unwrap();
        assert_eq!(again, d, "{text}");
    }
}
