//! The inspect tool's states file: bad states are refused with the field named, never
//! evaluated into `null` (regressions of issue 11).

use mbs_core::Model;
use mbs_core::inspect::{StatesFile, inspect};

const PENDULUM: &str = r#"{"gravity": [0.0, -9.81],
 "joints": [{"name": "link1", "parent": null, "kind": "revolute",
             "placement": {"angle": 0.0, "x": 0.0, "y": 0.0},
             "body": {"mass": 1.0, "com": [0.5, 0.0], "inertia": 0.0833}}]}"#;

fn state(q: &str, v: &str) -> String {
    format!(r#"{{"states": [{{"q": [{q}], "v": [{v}], "a": [0.0], "tau": [0.0]}}]}}"#)
}

#[test]
fn states_of_1e300_are_refused_not_printed_as_null() {
    let model = Model::from_json_str(PENDULUM).unwrap();
    // A velocity of 1e300 squares to infinity in the Coriolis terms.
    let states = StatesFile::from_json_str(&state("0.0", "1e300")).unwrap();
    let err = inspect(&model, &states).unwrap_err().to_string();
    assert!(
        err.starts_with("states file:") && err.contains("states[0]") && err.contains("not finite"),
        "{err}"
    );
    // A normal state still evaluates.
    let states = StatesFile::from_json_str(&state("0.3", "1.0")).unwrap();
    let report = inspect(&model, &states).unwrap();
    assert!(report.states[0].aba_qdd[0].is_finite());
}

#[test]
fn an_empty_states_list_is_refused() {
    let err = StatesFile::from_json_str(r#"{"states": []}"#)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("states file") && err.contains("empty"),
        "{err}"
    );
}

#[test]
fn states_file_errors_are_labelled_as_such_with_their_line() {
    let err = StatesFile::from_json_str("{\"states\": [\n {\"q\": [0.0], \"v\": [\"x\"]}]}")
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("states file:") && !err.contains("model description"),
        "{err}"
    );
    assert!(
        err.contains("line 2") && err.contains("states[0].v"),
        "{err}"
    );
    // Out of f64's range in the file: refused by the JSON reader, with its line.
    let err = StatesFile::from_json_str(&state("1e400", "0.0"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("line 1"), "{err}");
}

#[test]
fn body_name_of_a_foreign_id_is_none_not_a_panic() {
    let small = Model::from_json_str(PENDULUM).unwrap();
    let big = Model::from_json_str(&PENDULUM.replace(
        "}}]}",
        r#"}}, {"name": "link2", "parent": "link1", "kind": "revolute",
             "placement": {"angle": 0.0, "x": 1.0, "y": 0.0},
             "body": {"mass": 1.0, "com": [0.5, 0.0], "inertia": 0.0833}}]}"#,
    ))
    .unwrap();
    let foreign = big.body_id("link2").unwrap();
    assert_eq!(small.body_name(foreign), None);
    assert_eq!(small.parent(foreign), None);
    assert_eq!(big.body_name(foreign), Some("link2"));
    assert_eq!(big.parent(foreign), big.body_id("link1").ok());
    // Every lookup by body id answers None (or nothing) for a foreign id.
    assert!(small.joint_type(foreign).is_none());
    assert!(small.joint_placement(foreign).is_none());
    assert!(small.inertia(foreign).is_none());
    assert!(small.coordinate_of(foreign).is_none());
    assert_eq!(small.support(foreign).count(), 0);
    assert_eq!(big.support(foreign).count(), 2);
}
