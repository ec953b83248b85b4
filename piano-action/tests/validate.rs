//! The validation against the literature (issue 12): every row of `piano validate` for the
//! reference action is in its band or listed, with its reason, in
//! `piano-action/validation/known_deviations.toml`; and nothing listed there is back in
//! band. A change to the physics that moves a row across its band edge fails here, naming
//! the rows, so the list stays the truth.

mod common;
use common::piano;

use piano_action::validate::{KNOWN_DEVIATIONS_TOML, parse_known_deviations, validate};
use piano_action::{ActionParams, ModelKind};

/// The known-deviations file as it is on disk (the binary embeds the same file).
fn known_text() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/validation/known_deviations.toml"
    ))
    .unwrap()
}

#[test]
fn every_out_of_band_row_is_a_known_deviation_and_no_known_deviation_is_stale() {
    let known = parse_known_deviations(&known_text()).unwrap();
    let start = std::time::Instant::now();
    let mut v = validate(&ActionParams::reference(), ModelKind::Double).unwrap();
    let took = start.elapsed().as_secs_f64();
    v.apply_known(&known);
    println!("{}", v.table());
    eprintln!("the validation ran in {took:.1} s");

    let unlisted: Vec<String> = v
        .unlisted(&known)
        .iter()
        .map(|r| {
            format!(
                "{} = {} (literature {} {}){}",
                r.id,
                r.value_text(),
                r.literature,
                r.unit,
                r.note
                    .as_deref()
                    .map_or(String::new(), |n| format!(": {n}"))
            )
        })
        .collect();
    let stale = v.stale(&known);
    assert!(
        unlisted.is_empty() && stale.is_empty(),
        "\nout of band but not in validation/known_deviations.toml (fix the physics or list \
         them with a reason):\n  {}\nlisted but in band now (remove them from the file):\n  {}\n",
        unlisted.join("\n  "),
        stale.join("\n  ")
    );
}

#[test]
fn the_rows_are_well_formed() {
    let v = validate(&ActionParams::reference(), ModelKind::Double).unwrap();
    let mut ids: Vec<&str> = v.rows.iter().map(|r| r.id.as_str()).collect();
    let n = ids.len();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), n, "row ids must be unique");
    for r in &v.rows {
        // Every band has a source with its tag.
        assert!(
            ["[V]", "[S]", "[M]", "[D]"]
                .iter()
                .any(|t| r.source.contains(t)),
            "{}: source '{}' has no tag",
            r.id,
            r.source
        );
        assert_eq!(r.in_band, r.band.contains(r.model_value), "{}", r.id);
        if r.model_value.is_none() {
            assert!(r.note.is_some(), "{}: no value and no reason", r.id);
        }
    }
    // The experiments the issue names are all there.
    for prefix in [
        "regulation.",
        "touchweight.",
        "velocity.",
        "ratio.",
        "free_flight.",
        "travel_time.",
        "key_bottom.",
        "contact.duration.",
        "contact.rebound.",
        "check.",
        "motion.",
        "slow_press.",
        "repetition.",
        "mass_drop.",
        "pendulum.",
    ] {
        assert!(
            v.rows.iter().any(|r| r.id.starts_with(prefix)),
            "no {prefix} row"
        );
    }
    // The page's curves: both touches from soft to loud, each struck touch striking.
    assert!(v.curves.struck.len() >= 10 && v.curves.pressed.len() >= 10);
    assert!(
        v.curves
            .struck
            .iter()
            .all(|b| b.error.is_none() && b.hammer_speed_m_s.is_some())
    );
}

#[test]
fn the_simplified_action_gets_only_the_rows_it_can_reproduce() {
    let v = validate(&ActionParams::reference(), ModelKind::Simplified).unwrap();
    let ids: Vec<&str> = v.rows.iter().map(|r| r.id.as_str()).collect();
    // No escapement: no let-off, no blows to time, no repetition.
    for absent in [
        "regulation.let_off",
        "free_flight.2",
        "repetition.half_release",
    ] {
        assert!(!ids.contains(&absent), "{ids:?}");
    }
    let held = v
        .rows
        .iter()
        .find(|r| r.id == "slow_press.held_on_string")
        .unwrap();
    assert!(held.in_band, "{held:?}");
}

#[test]
fn the_embedded_known_deviations_are_the_file() {
    assert_eq!(KNOWN_DEVIATIONS_TOML, known_text());
}

#[test]
fn piano_validate_refuses_bad_options_before_running() {
    let (ok, _, err) = piano(&["validate", "--model", "upright"]);
    assert!(!ok && err.contains("unknown model 'upright'"), "{err}");
    let dir = std::env::temp_dir().join(format!("piano-validate-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // --out naming a file, and a folder holding someone else's validation.md.
    let file = dir.join("notes.txt");
    std::fs::write(&file, "mine").unwrap();
    let (ok, _, err) = piano(&["validate", "--out", file.to_str().unwrap()]);
    assert!(!ok && err.contains("is a file"), "{err}");
    std::fs::write(dir.join("validation.md"), "mine").unwrap();
    let (ok, _, err) = piano(&["validate", "--out", dir.to_str().unwrap(), "--force"]);
    assert!(
        !ok && err.contains("not written by piano validate"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(dir.join("validation.md")).unwrap(),
        "mine"
    );
    // A broken parameter file is named with its field.
    let params = dir.join("bad.toml");
    let (_, text, _) = piano(&["params"]);
    std::fs::write(&params, text.replace("mass_g = 11.74", "mass_g = -1.0")).unwrap();
    let (ok, _, err) = piano(&["--params", params.to_str().unwrap(), "validate"]);
    assert!(!ok && err.contains("hammer.mass_g"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn piano_validate_prints_json_and_writes_its_pages() {
    let dir = std::env::temp_dir().join(format!("piano-validate-out-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let (ok, out, err) = piano(&["validate", "--json", "--out", dir.to_str().unwrap()]);
    assert!(ok, "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(json["model"], "double");
    let rows = json["rows"].as_array().unwrap();
    assert!(rows.len() > 40);
    for r in rows {
        for key in [
            "id",
            "quantity",
            "literature",
            "unit",
            "source",
            "in_band",
            "known_deviation",
            "model_value",
        ] {
            assert!(r.get(key).is_some(), "{key} missing in {r}");
        }
        assert!(r["model_value"].is_number() || r["model_value"].is_null());
        // Out of band means listed, for the reference action.
        assert!(
            r["in_band"] == true || r["known_deviation"].is_string(),
            "{r}"
        );
    }
    let html = std::fs::read_to_string(dir.join("validation.html")).unwrap();
    assert!(html.contains("<svg") && html.contains("Travel time"));
    let md = std::fs::read_to_string(dir.join("validation.md")).unwrap();
    assert!(md.contains("| `regulation.key_dip` |"), "{md}");
    // Written once, refused the second time unless forced.
    let (ok, _, err) = piano(&["validate", "--out", dir.to_str().unwrap()]);
    assert!(!ok && err.contains("--force"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
