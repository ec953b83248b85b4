//! Every numeric parameter by a stable path with its unit and source tag (issue 13,
//! "Parameters by name"): listing, get, set, and the errors of an unknown path or a value
//! a parameter cannot take.

mod common;
use common::piano;

use piano_action::params::DEFAULT_PARAMS_TOML;
use piano_action::{ActionParams, PianoError};

#[test]
fn every_numeric_parameter_has_a_path_a_unit_and_a_source_tag() {
    let params = ActionParams::reference();
    let list = params.parameter_list(DEFAULT_PARAMS_TOML).unwrap();
    assert!(list.len() > 150, "{} parameters", list.len());
    // The file's rule: every constant carries its source.
    let untagged: Vec<&str> = list
        .iter()
        .filter(|p| p.tags.is_empty())
        .map(|p| p.path.as_str())
        .collect();
    assert!(untagged.is_empty(), "no source tag: {untagged:?}");
    let find = |path: &str| list.iter().find(|p| p.path == path).unwrap();
    for (path, unit) in [
        ("hammer.pivot_friction_n_m", "N m"),
        ("hammer.inertia_com_kg_m2", "kg m^2"),
        ("hammer.mass_g", "g"),
        ("contacts.hammer_string.k", "N/m^p"),
        ("contacts.hammer_string.p", "1"),
        ("jack.toe_mm[1]", "mm"),
        ("jack.outer_stop_rad", "rad"),
        ("string.fundamental_hz", "Hz"),
        ("string.loss_b1_per_s", "1/s"),
        ("repetition_lever.spring_stiffness_n_m_per_rad", "N m/rad"),
    ] {
        assert_eq!(find(path).unit, unit, "{path}");
    }
    assert_eq!(find("jack.toe_mm[1]").value, params.jack.toe_mm[1]);
    assert!(find("contacts.hammer_string.k").tags.contains("[S]"));
    assert!(
        find("regulation.let_off_button_y_mm")
            .tags
            .contains("[regulated]")
    );
    // In the file's order: the key's table comes first.
    assert!(list[0].path.starts_with("key."), "{}", list[0].path);
    // Every path reads back its own value, and setting it to that value changes nothing.
    let mut same = params.clone();
    for p in &list {
        assert_eq!(params.parameter(&p.path).unwrap(), p.value, "{}", p.path);
        same.set_parameter(&p.path, p.value).unwrap();
    }
    assert_eq!(same, params);
}

#[test]
fn setting_a_parameter_changes_the_model_and_bad_values_change_nothing() {
    let mut params = ActionParams::reference();
    params
        .set_parameter("hammer.pivot_friction_n_m", 2.5e-3)
        .unwrap();
    assert_eq!(params.hammer.pivot_friction_n_m, 2.5e-3);
    assert_eq!(
        params.parameter("hammer.pivot_friction_n_m").unwrap(),
        2.5e-3
    );
    params.set_parameter("jack.toe_mm[0]", 63.0).unwrap();
    assert_eq!(params.jack.toe_mm[0], 63.0);
    params.set_parameter("string.modes", 40.0).unwrap();
    assert_eq!(params.parameter("string.modes").unwrap(), 40.0);

    let before = params.clone();
    // A value the file would refuse: the error names the path, nothing changes.
    let e = params.set_parameter("hammer.mass_g", -1.0).unwrap_err();
    assert!(e.to_string().contains("hammer.mass_g"), "{e}");
    let e = params.set_parameter("string.modes", 2.5).unwrap_err();
    assert!(e.to_string().contains("whole number"), "{e}");
    let e = params.set_parameter("hammer.mass_g", f64::NAN).unwrap_err();
    assert!(e.to_string().contains("finite"), "{e}");
    assert_eq!(params, before);

    // An unknown path is its own error, with the closest path when one is close.
    match params.set_parameter("hammer.pivot_fricton_n_m", 1e-3) {
        Err(PianoError::UnknownParameter { path, suggestion }) => {
            assert_eq!(path, "hammer.pivot_fricton_n_m");
            assert_eq!(suggestion.as_deref(), Some("hammer.pivot_friction_n_m"));
        }
        other => panic!("{other:?}"),
    }
    match params.parameter("no.such.thing") {
        Err(PianoError::UnknownParameter { suggestion, .. }) => assert!(suggestion.is_none()),
        other => panic!("{other:?}"),
    }
    // A table is not a parameter.
    assert!(matches!(
        params.parameter("hammer"),
        Err(PianoError::UnknownParameter { .. })
    ));
    assert_eq!(params, before);
}

#[test]
fn piano_params_list_prints_every_path_and_reads_the_tags_of_your_file() {
    let (ok, stdout, err) = piano(&["params", "--list"]);
    assert!(ok, "{err}");
    let n = ActionParams::reference()
        .parameter_list(DEFAULT_PARAMS_TOML)
        .unwrap()
        .len();
    assert!(stdout.contains(&format!("{n} parameters")), "{stdout}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("hammer.pivot_friction_n_m "))
        .expect("listed");
    assert!(line.contains("N m"), "{line}");

    let (ok, stdout, err) = piano(&["params", "--list", "--json"]);
    assert!(ok, "{err}");
    let rows: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), n);
    let k = rows
        .iter()
        .find(|r| r["path"] == "contacts.hammer_string.k")
        .unwrap();
    assert_eq!(k["unit"], "N/m^p");
    assert_eq!(k["value"].as_f64().unwrap(), 1.35e10);

    // Your own file: its values and its tags.
    let dir = std::env::temp_dir().join(format!("piano-list-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("mine.toml");
    let text = DEFAULT_PARAMS_TOML.replace(
        "mass_g = 110.0                        #",
        "mass_g = 112.0                        # [V] weighed on my scale;",
    );
    assert_ne!(text, DEFAULT_PARAMS_TOML);
    std::fs::write(&file, text).unwrap();
    let (ok, stdout, err) = piano(&["--params", file.to_str().unwrap(), "params", "--list"]);
    assert!(ok, "{err}");
    let line = stdout
        .lines()
        .find(|l| l.starts_with("key.mass_g "))
        .unwrap();
    assert!(line.contains("112") && line.contains("[V]"), "{line}");
    // --json needs --list; the plain `params` still refuses --params.
    let (ok, _, err) = piano(&["params", "--json"]);
    assert!(!ok && err.contains("--list"), "{err}");
    let (ok, _, err) = piano(&["--params", file.to_str().unwrap(), "params"]);
    assert!(!ok && err.contains("--params"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
