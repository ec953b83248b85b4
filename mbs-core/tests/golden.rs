//! Golden data: the 5-link planar chain of `tests/data/planar5_reference.json`
//! (Featherstone's `planar(5)`), with mass matrix, RNEA, nonlinear effects, gravity torques
//! and ABA computed by Pinocchio 4.1.0 and cross-checked with MuJoCo 4.0.0. Reproduced to
//! 1e-12.

use mbs_core::{
    Data, Model, ModelDescription, aba, crba, forward_dynamics_crba, gravity_torque,
    nonlinear_effects, rnea,
};
use serde_json::Value;

fn reference() -> Value {
    serde_json::from_str(include_str!("data/planar5_reference.json")).expect("reference JSON")
}

fn vec_of(v: &Value) -> Vec<f64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect()
}

fn assert_close(what: &str, got: &[f64], want: &[f64], tol: f64) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(
            (g - w).abs() <= tol,
            "{what}[{k}]: got {g:.17e}, want {w:.17e}, diff {:.3e}",
            (g - w).abs()
        );
    }
}

#[test]
fn planar5_reproduces_pinocchio_to_1e12() {
    let r = reference();
    let desc: ModelDescription = serde_json::from_value(r["model"].clone()).expect("model");
    let model: Model = desc.build().expect("valid model");
    assert_eq!(model.nv(), 5);
    let mut data = Data::new(&model);
    let states = r["states"]["states"].as_array().expect("states");
    let expect = r["expect"]["states"].as_array().expect("expect");
    assert!(!states.is_empty());
    for (s, e) in states.iter().zip(expect) {
        let (q, v, a, tau) = (
            vec_of(&s["q"]),
            vec_of(&s["v"]),
            vec_of(&s["a"]),
            vec_of(&s["tau"]),
        );
        let m = crba(&model, &mut data, &q).unwrap().clone();
        for (i, row) in e["mass_matrix"].as_array().unwrap().iter().enumerate() {
            let row = vec_of(row);
            let got: Vec<f64> = (0..5).map(|j| m[(i, j)]).collect();
            assert_close(&format!("M row {i}"), &got, &row, 1e-12);
        }
        let t = rnea(&model, &mut data, &q, &v, &a).unwrap().clone();
        assert_close("rnea_tau", t.as_slice(), &vec_of(&e["rnea_tau"]), 1e-12);
        let n = nonlinear_effects(&model, &mut data, &q, &v)
            .unwrap()
            .clone();
        assert_close(
            "nonlinear_effects",
            n.as_slice(),
            &vec_of(&e["nonlinear_effects"]),
            1e-12,
        );
        let g = gravity_torque(&model, &mut data, &q).unwrap().clone();
        assert_close(
            "gravity_torque",
            g.as_slice(),
            &vec_of(&e["gravity_torque"]),
            1e-12,
        );
        let qdd = aba(&model, &mut data, &q, &v, &tau).unwrap().clone();
        assert_close("aba_qdd", qdd.as_slice(), &vec_of(&e["aba_qdd"]), 1e-12);
        let qdd2 = forward_dynamics_crba(&model, &mut data, &q, &v, &tau, None).unwrap();
        assert_close(
            "crba+cholesky qdd",
            qdd2.as_slice(),
            &vec_of(&e["aba_qdd"]),
            1e-12,
        );
    }
}

#[test]
fn inspect_reproduces_the_reference_expect_block() {
    use mbs_core::inspect::{ReportFile, StatesFile, inspect};
    let r = reference();
    let model = Model::from_json_str(&r["model"].to_string()).unwrap();
    let states = StatesFile::from_json_str(&r["states"].to_string()).unwrap();
    let expect: ReportFile = serde_json::from_value(r["expect"].clone()).unwrap();
    let got = inspect(&model, &states).unwrap();
    assert_eq!(got.states.len(), expect.states.len());
    for (g, e) in got.states.iter().zip(&expect.states) {
        for (gr, er) in g.mass_matrix.iter().zip(&e.mass_matrix) {
            assert_close("mass_matrix", gr, er, 1e-12);
        }
        assert_close("rnea_tau", &g.rnea_tau, &e.rnea_tau, 1e-12);
        assert_close(
            "nonlinear_effects",
            &g.nonlinear_effects,
            &e.nonlinear_effects,
            1e-12,
        );
        assert_close(
            "gravity_torque",
            &g.gravity_torque,
            &e.gravity_torque,
            1e-12,
        );
        assert_close("aba_qdd", &g.aba_qdd, &e.aba_qdd, 1e-12);
    }
    // A state of the wrong size is named.
    let bad =
        StatesFile::from_json_str(r#"{"states": [{"q": [0], "v": [0], "a": [0], "tau": [0]}]}"#)
            .unwrap();
    let err = inspect(&model, &bad).unwrap_err().to_string();
    assert!(
        err.contains("states[0]") && err.contains("q: expected length 5"),
        "{err}"
    );
    let err =
        StatesFile::from_json_str(r#"{"states": [{"q": [0], "v": [0], "a": [0]}]}"#).unwrap_err();
    assert!(err.to_string().contains("tau"), "{err}");
}
