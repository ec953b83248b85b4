//! The grand actions as mechanism descriptions: `piano describe` writes a file that builds
//! and simulates bit for bit like the built-in model.

mod common;
use common::piano;

use mbs_core::time_function::Constant;
use mbs_mechanism::Mechanism;
use piano_action::describe::grand_mechanism;
use piano_action::identify::effects::EffectEntry;
use piano_action::{Action, ActionParams, ModelKind, Presser};

/// The state after 60 ms of a 10 N press, from the action built in code and from its
/// description read back from `text`.
fn press_both(
    params: &ActionParams,
    kind: ModelKind,
    presser: Option<Presser>,
    text: &str,
) -> (Vec<f64>, Vec<f64>, usize) {
    let run = |mut action: Action| {
        action.add_key_force(Constant(10.0)).unwrap();
        let x0 = action.layout_state().unwrap();
        let sol = action.integrate(&x0, 0.06, f64::INFINITY, None).unwrap();
        (sol.y, sol.events.len())
    };
    let (direct, events) = run(Action::build_with(params, kind, presser).unwrap());
    let mechanism = Mechanism::from_toml_str(text).unwrap();
    let (described, events_back) =
        run(Action::from_mechanism(params, kind, presser, &mechanism).unwrap());
    assert_eq!(events, events_back, "{kind:?}: the same events");
    (direct, described, events)
}

#[test]
fn every_grand_model_read_back_from_its_description_runs_bit_identically() {
    let params = ActionParams::reference();
    for kind in ModelKind::ALL {
        let m = grand_mechanism(&params, kind, None).unwrap();
        let text = m.to_toml_string().unwrap();
        assert_eq!(Mechanism::from_toml_str(&text).unwrap(), m, "{kind:?}");
        let json = m.to_json_string().unwrap();
        assert_eq!(Mechanism::from_json_str(&json).unwrap(), m, "{kind:?}");
        let (direct, described, events) = press_both(&params, kind, None, &text);
        assert!(events > 3, "{kind:?}: a press with events");
        assert!(
            direct
                .iter()
                .zip(&described)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{kind:?}: every state bit for bit"
        );
        assert_eq!(direct.len(), described.len());
    }
}

#[test]
fn a_described_action_keeps_its_presser_and_flange_effects() {
    let mut params = ActionParams::reference();
    params.effects = vec![EffectEntry {
        id: "pivot_viscous".into(),
        location: "hammer_flange".into(),
        params: [("c_n_m_s".to_string(), 4e-5)].into_iter().collect(),
    }];
    let finger = Presser {
        carried: true,
        ..Presser::weight(0.01, 0.0)
    };
    let m = grand_mechanism(&params, ModelKind::Double, Some(finger)).unwrap();
    assert!(m.bodies.iter().any(|b| b.name == "presser"));
    assert_eq!(m.loads.len(), 1, "the arm carries the finger");
    assert_eq!(m.extensions.len(), 1);
    let text = m.to_toml_string().unwrap();
    let (direct, described, _) = press_both(&params, ModelKind::Double, Some(finger), &text);
    assert!(
        direct
            .iter()
            .zip(&described)
            .all(|(a, b)| a.to_bits() == b.to_bits())
    );
    // An unknown effect in a hand-edited file names the extension.
    let bad = text.replace("name = \"pivot_viscous\"", "name = \"pivot_magic\"");
    let e = Action::from_mechanism(
        &params,
        ModelKind::Double,
        Some(finger),
        &Mechanism::from_toml_str(&bad).unwrap(),
    )
    .err()
    .expect("refused");
    assert!(e.to_string().contains("extensions[0]"), "{e}");
    assert!(e.to_string().contains("pivot_magic"), "{e}");
}

#[test]
fn piano_describe_writes_a_commented_description() {
    let (ok, text, err) = piano(&["describe", "--model", "single"]);
    assert!(ok, "{err}");
    assert!(text.starts_with("# Mechanism description: grand action, single model"));
    assert!(text.contains("# Contact pairs:"), "{text}");
    let m = Mechanism::from_toml_str(&text).unwrap();
    m.validate().unwrap();
    assert_eq!(
        m,
        grand_mechanism(&ActionParams::reference(), ModelKind::Single, None).unwrap()
    );
    assert!(m.contacts.iter().any(|c| c.name == "let_off_button"));
    assert!(!m.bodies.iter().any(|b| b.name == "repetition_lever"));

    let (ok, json, err) = piano(&["describe", "--json"]);
    assert!(ok, "{err}");
    let m = Mechanism::from_json_str(&json).unwrap();
    assert!(m.bodies.iter().any(|b| b.name == "repetition_lever"));

    // --out never replaces a file without --force.
    let dir = std::env::temp_dir().join(format!("piano-describe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("grand.toml");
    std::fs::write(&out, "mine").unwrap();
    let (ok, _, err) = piano(&["describe", "--out", out.to_str().unwrap()]);
    assert!(!ok && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "mine");
    let (ok, _, err) = piano(&["describe", "--out", out.to_str().unwrap(), "--force"]);
    assert!(ok, "{err}");
    assert!(Mechanism::load(&out).is_ok());
    std::fs::remove_dir_all(&dir).ok();
}
