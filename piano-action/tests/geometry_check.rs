//! Parameter files describing an impossible piano are refused with the field to change and
//! what is wrong in piano terms (issue 11, point 5); a badly regulated action still loads.

use piano_action::geometry_check::check;
use piano_action::params::DEFAULT_PARAMS_TOML;
use piano_action::regulation::{Targets, regulate};
use piano_action::{Action, ActionParams, ModelKind, PianoError};

/// `params` is refused with `field` named first, and the message contains every word of
/// `words`.
fn refused(params: &ActionParams, field: &str, words: &[&str]) {
    let problems = check(params);
    println!("{problems:#?}");
    let first = problems.first().expect("a problem is found");
    assert_eq!(first.field, field, "{problems:#?}");
    for w in words {
        assert!(first.message.contains(w), "no '{w}' in: {}", first.message);
    }
    match params.validate() {
        Err(PianoError::Input(e)) => {
            assert_eq!(e.field, field);
            assert!(e.message.contains(&first.message), "{}", e.message);
        }
        other => panic!("validate accepted it: {other:?}"),
    }
    // Nothing is built from it.
    assert!(Action::build(params, ModelKind::Double).is_err());
}

#[test]
fn the_reference_and_mis_regulated_actions_pass() {
    let reference = ActionParams::reference();
    assert_eq!(check(&reference), vec![]);
    // The screws and rails where action_layout.md §8 places them (tests/layout.rs).
    let mut layout = reference.clone();
    let r = &mut layout.regulation;
    r.let_off_button_y_mm = 68.40;
    r.drop_screw_y_mm = 102.28;
    r.rest_rail_top_y_mm = 72.9;
    r.front_rail_top_y_mm = -9.38;
    r.capstan_raise_mm = 0.0;
    r.backcheck_offset_mm = 0.0;
    assert_eq!(check(&layout), vec![]);
    // The badly regulated start of tests/regulation.rs: every screw off by a turn or so.
    let mut off = reference.clone();
    off.regulation.front_rail_top_y_mm -= 0.8;
    off.regulation.capstan_raise_mm -= 0.3;
    off.regulation.let_off_button_y_mm -= 0.4;
    off.regulation.drop_screw_y_mm += 0.2;
    off.regulation.backcheck_offset_mm -= 0.6;
    assert_eq!(check(&off), vec![]);
    // Each screw and rail 2 mm either way, alone and all together.
    type Screw = fn(&mut ActionParams, f64);
    let screws: [(&str, Screw); 6] = [
        ("front rail", |p, d| p.regulation.front_rail_top_y_mm += d),
        ("capstan", |p, d| p.regulation.capstan_raise_mm += d),
        ("let-off button", |p, d| {
            p.regulation.let_off_button_y_mm += d
        }),
        ("drop screw", |p, d| p.regulation.drop_screw_y_mm += d),
        ("backcheck", |p, d| p.regulation.backcheck_offset_mm += d),
        ("rest rail", |p, d| p.regulation.rest_rail_top_y_mm += d),
    ];
    for d in [-2.0, 2.0] {
        let mut all = reference.clone();
        for (name, turn) in screws {
            let mut one = reference.clone();
            turn(&mut one, d);
            turn(&mut all, d);
            assert_eq!(check(&one), vec![], "{name} {d:+} mm");
        }
        assert_eq!(check(&all), vec![], "all {d:+} mm");
    }
    // What other tests change: friction, tolerances.
    let mut stiff = reference.clone();
    stiff.hammer.pivot_friction_n_m += 0.75e-3;
    stiff.numerics.relative_tolerance = 1e-6;
    stiff.numerics.absolute_tolerance = 1e-9;
    assert_eq!(check(&stiff), vec![]);
    // They load and build.
    for p in [&layout, &off, &stiff] {
        ActionParams::from_toml_str(&p.to_toml_string().unwrap()).unwrap();
        for kind in ModelKind::ALL {
            Action::build(p, kind).unwrap();
        }
    }
}

#[test]
fn a_string_below_the_hammer_is_refused() {
    // Issue 11, point 5: it used to load, strike nothing and weigh 11 076 gf.
    let text = DEFAULT_PARAMS_TOML.replace("string_y_mm = 149.2", "string_y_mm = 40.0");
    assert_ne!(text, DEFAULT_PARAMS_TOML);
    let e = ActionParams::from_toml_str(&text).unwrap_err();
    let PianoError::Input(bad) = &e else {
        panic!("{e}");
    };
    let (field, message) = (&bad.field, &bad.message);
    assert_eq!(field, "regulation.string_y_mm");
    assert!(
        message.contains("below the hammer crown") && message.contains("raise"),
        "{message}"
    );
    // Alone: nothing else in the file is blamed.
    let mut p = ActionParams::reference();
    p.regulation.string_y_mm = 40.0;
    assert_eq!(check(&p).len(), 1, "{:#?}", check(&p));
    refused(
        &p,
        "regulation.string_y_mm",
        &["string", "below the hammer crown"],
    );
    // `regulate` says so instead of failing inside the integrator.
    let e = regulate(&p, ModelKind::Double, &Targets::default()).unwrap_err();
    assert!(e.to_string().contains("regulation.string_y_mm"), "{e}");
    // A string a few mm over the crown, or out of the hammer's reach, is as wrong.
    p.regulation.string_y_mm = 110.0;
    refused(&p, "regulation.string_y_mm", &["blow distance", "raise"]);
    p.regulation.string_y_mm = 300.0;
    refused(&p, "regulation.string_y_mm", &["blow distance", "lower"]);
}

#[test]
fn the_cli_refuses_a_string_below_the_hammer_naming_the_file_and_field() {
    let dir = std::env::temp_dir().join(format!("piano-geometry-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        DEFAULT_PARAMS_TOML.replace("string_y_mm = 149.2", "string_y_mm = 40.0"),
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_piano"))
        .args(["--params", bad.to_str().unwrap(), "touchweight"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    std::fs::remove_dir_all(&dir).ok();
    assert!(!out.status.success(), "exit 0; stdout: {}", {
        String::from_utf8_lossy(&out.stdout)
    });
    assert!(err.contains("bad.toml"), "{err}");
    assert!(err.contains("regulation.string_y_mm"), "{err}");
    assert!(err.contains("below the hammer crown"), "{err}");
    // Nothing was measured.
    assert!(out.stdout.is_empty());
}

#[test]
fn a_let_off_button_out_of_reach_of_the_toe_is_refused() {
    let mut p = ActionParams::reference();
    p.regulation.let_off_button_y_mm = 100.0;
    refused(
        &p,
        "regulation.let_off_button_y_mm",
        &["jack toe", "never escape", "lower"],
    );
    // Below the toe at rest: the jack is tripped before the key moves.
    p.regulation.let_off_button_y_mm = 40.0;
    refused(
        &p,
        "regulation.let_off_button_y_mm",
        &["into the jack toe", "tripped", "raise"],
    );
    // Beside the toe.
    let mut p = ActionParams::reference();
    p.regulation.let_off_button_x_mm = [20.0, 40.0];
    refused(
        &p,
        "regulation.let_off_button_x_mm",
        &["jack toe", "beside"],
    );
}

#[test]
fn a_capstan_far_below_the_heel_is_refused() {
    let mut p = ActionParams::reference();
    p.key.capstan_center_mm[1] = 5.0;
    refused(
        &p,
        "key.capstan_center_mm",
        &["below the wippen heel", "never lift the wippen", "raise"],
    );
    // The same done with the capstan screw names the screw.
    let mut p = ActionParams::reference();
    p.regulation.capstan_raise_mm = -15.0;
    refused(
        &p,
        "regulation.capstan_raise_mm",
        &["below the wippen heel", "never lift the wippen"],
    );
    // Screwed deep into the heel.
    p.regulation.capstan_raise_mm = 5.0;
    refused(
        &p,
        "regulation.capstan_raise_mm",
        &["inside the wippen heel"],
    );
}

#[test]
fn a_two_kilogram_hammer_is_refused() {
    let mut p = ActionParams::reference();
    p.hammer.mass_g = 2000.0;
    assert_eq!(check(&p).len(), 1, "{:#?}", check(&p));
    refused(&p, "hammer.mass_g", &["2000 g", "grams"]);
    // Masses in kg, inertias in the wrong unit or about the wrong point.
    let mut p = ActionParams::reference();
    p.key.mass_g = 0.110;
    refused(&p, "key.mass_g", &["key weighs 0.11 g"]);
    let mut p = ActionParams::reference();
    p.hammer.inertia_com_kg_m2 = 1e-3;
    refused(
        &p,
        "hammer.inertia_com_kg_m2",
        &["radius of gyration", "longer"],
    );
    let mut p = ActionParams::reference();
    p.key.inertia_pivot_kg_m2 = 1e-5;
    refused(&p, "key.inertia_pivot_kg_m2", &["parallel-axis"]);
    let mut p = ActionParams::reference();
    p.hammer.com_body_mm = [176.0, 92.5]; // the world point, not the shank frame
    refused(&p, "hammer.com_body_mm", &["centre of mass", "shank frame"]);
}

#[test]
fn a_negative_or_zero_extent_is_refused() {
    let mut p = ActionParams::reference();
    p.regulation.let_off_button_x_mm = [70.0, 58.0];
    refused(
        &p,
        "regulation.let_off_button_x_mm",
        &["let-off button", "[58, 70]"],
    );
    let mut p = ActionParams::reference();
    p.regulation.string_x_mm = [200.0, 200.0];
    refused(&p, "regulation.string_x_mm", &["string", "no length"]);
    let mut p = ActionParams::reference();
    p.jack.toe_radius_mm = 0.0;
    refused(&p, "jack.toe_radius_mm", &["jack toe", "positive"]);
    let mut p = ActionParams::reference();
    p.wippen.heel_half_length_mm = -10.0;
    refused(&p, "wippen.heel_half_length_mm", &["heel", "positive"]);
}

#[test]
fn other_impossible_layouts_name_their_field() {
    type Edit = fn(&mut ActionParams);
    let cases: [(Edit, &str, &str); 12] = [
        (
            |p| p.regulation.front_rail_top_y_mm = 2.0,
            "regulation.front_rail_top_y_mm",
            "cannot go down",
        ),
        (
            |p| p.regulation.drop_screw_y_mm = 130.0,
            "regulation.drop_screw_y_mm",
            "no drop",
        ),
        (
            |p| p.key.backcheck_mm = [202.1, 30.0],
            "key.backcheck_mm",
            "not be checked",
        ),
        (
            |p| p.regulation.rest_rail_top_y_mm = 90.0,
            "regulation.rest_rail_top_y_mm",
            "off the jack",
        ),
        (
            |p| p.regulation.back_rail_top_y_mm = -10.0,
            "regulation.back_rail_top_y_mm",
            "tip back",
        ),
        (|p| p.jack.axis = [0.0, 2.0], "jack.axis", "not 1"),
        (|p| p.jack.axis = [0.941, -0.340], "jack.axis", "off square"),
        (
            |p| p.jack.top_mm = [84.4, 120.0],
            "jack.top_mm",
            "out from under the knuckle",
        ),
        (
            |p| p.key.capstan_center_mm[0] = -60.0,
            "key.capstan_center_mm",
            "balance pivot",
        ),
        (
            |p| p.key.pivot_mm[0] = 50.0,
            "key.capstan_center_mm",
            "key ratio",
        ),
        (
            |p| p.regulation.backcheck_offset_mm = -20.0,
            "regulation.backcheck_offset_mm",
            "not be checked",
        ),
        (
            |p| p.hammer.rest_angle_deg = -95.0,
            "hammer.rest_angle_deg",
            "near horizontal",
        ),
    ];
    for (edit, field, words) in cases {
        let mut p = ActionParams::reference();
        edit(&mut p);
        refused(&p, field, &[words]);
    }
}

#[test]
fn a_wippen_pinned_inside_the_key_is_refused() {
    // Found in review: the wippen drawn through the key stick, striking four times.
    let mut p = ActionParams::reference();
    p.wippen.pivot_mm = [187.0, 10.0];
    let problems = check(&p);
    assert!(
        problems
            .iter()
            .any(|q| q.field == "wippen.pivot_mm" && q.message.contains("not above the key")),
        "{problems:#?}"
    );
    assert!(p.validate().is_err());
}
