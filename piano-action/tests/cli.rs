//! The `piano` command as a user runs it.

use std::process::Command;

fn piano(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_piano"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn params_writes_the_default_file_and_params_loads_it_back() {
    let (ok, text, _) = piano(&["params"]);
    assert!(ok);
    let p = piano_action::ActionParams::from_toml_str(&text).unwrap();
    assert_eq!(p, piano_action::ActionParams::reference());
    // A broken copy is refused with the field named, and nothing runs.
    let dir = std::env::temp_dir().join(format!("piano-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text.replace("mass_g = 11.74", "mass_g = 0.0")).unwrap();
    let (ok, _, err) = piano(&["--params", bad.to_str().unwrap(), "touchweight"]);
    assert!(!ok);
    assert!(err.contains("hammer.mass_g"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn touchweight_json_reports_the_four_weights() {
    let (ok, out, err) = piano(&["touchweight", "--json"]);
    assert!(ok, "{err}");
    for field in [
        "down_weight_gf",
        "up_weight_gf",
        "balance_weight_gf",
        "friction_weight_gf",
    ] {
        assert!(out.contains(field), "{out}");
    }
    let (ok, _, err) = piano(&["touchweight", "--model", "upright"]);
    assert!(!ok && err.contains("unknown model 'upright'"), "{err}");
}
