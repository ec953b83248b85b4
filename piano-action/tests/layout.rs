//! The reference parameters load, all three models assemble, and the layout at rest has
//! the clearances of action_layout.md §8 (gaps measured through the contact geometry).

use piano_action::{Action, ActionParams, ModelKind};

fn gaps_mm(action: &Action) -> Vec<(&str, f64)> {
    let x = action.layout_state().unwrap();
    action
        .contacts
        .keys()
        .map(|name| (name.as_str(), action.gap(name, 0.0, &x).unwrap() * 1e3))
        .collect()
}

#[test]
fn the_embedded_parameters_load_and_every_model_builds() {
    let p = ActionParams::reference();
    for kind in ModelKind::ALL {
        let a = Action::build(&p, kind).unwrap();
        let nv = a.system.model().nv();
        let expect = match kind {
            ModelKind::Simplified => 3,
            ModelKind::Single => 4,
            ModelKind::Double => 5,
        };
        assert_eq!(nv, expect, "{kind:?}");
        let contacts = a.contacts.len();
        assert_eq!(
            contacts,
            match kind {
                ModelKind::Simplified => 6,
                ModelKind::Single => 8,
                ModelKind::Double => 10,
            },
            "{kind:?}"
        );
    }
}

/// The reference parameters with the screws and rails back where action_layout.md §8
/// places them (the embedded file holds them as `piano regulate` left them).
fn layout_params() -> ActionParams {
    let mut p = ActionParams::reference();
    let r = &mut p.regulation;
    r.let_off_button_y_mm = 68.40;
    r.drop_screw_y_mm = 102.28;
    r.rest_rail_top_y_mm = 72.9;
    r.front_rail_top_y_mm = -9.38;
    r.capstan_raise_mm = 0.0;
    r.backcheck_offset_mm = 0.0;
    p
}

#[test]
fn the_layout_at_rest_has_the_documented_clearances() {
    let a = Action::build(&layout_params(), ModelKind::Double).unwrap();
    let gaps: std::collections::BTreeMap<_, _> = gaps_mm(&a).into_iter().collect();
    println!("{gaps:#?}");
    // Resting contacts touch, to the 0.1 mm rounding of the layout's published points:
    // capstan on heel, knuckle on jack and lever, key tail on the back rail.
    for name in ["capstan_heel", "jack_knuckle", "lever_knuckle", "back_rail"] {
        assert!(gaps[name].abs() < 0.1, "{name}: {} mm", gaps[name]);
    }
    // Key dip room at the front rail: 9.38 mm under the pad.
    assert!((gaps["front_rail"] - 9.38).abs() < 1e-6);
    // Jack toe 5.97 mm under the let-off button (layout §8.1).
    assert!(
        (gaps["let_off_button"] - 5.97).abs() < 0.05,
        "{}",
        gaps["let_off_button"]
    );
    // Rep lever tip under the drop screw: 102.28 − 96.7.
    assert!(
        (gaps["drop_screw"] - 5.58).abs() < 0.01,
        "{}",
        gaps["drop_screw"]
    );
    // Shank 1/8" (3 mm) over the rest-rail cushion.
    assert!(
        (gaps["rest_rail"] - 3.0).abs() < 0.1,
        "{}",
        gaps["rest_rail"]
    );
    // Blow: 47 mm from the strike point; the crown's highest point at the tilted rest pose
    // sits 0.6 mm above it.
    assert!(
        (gaps["hammer_string"] - 46.4).abs() < 0.2,
        "{}",
        gaps["hammer_string"]
    );
    // The tail is clear of the backcheck at rest.
    assert!(gaps["backcheck"] > 2.0, "{}", gaps["backcheck"]);
}

#[test]
fn bad_parameter_files_name_the_field() {
    let text =
        piano_action::params::DEFAULT_PARAMS_TOML.replace("mass_g = 11.74", "mass_g = -11.74");
    let e = ActionParams::from_toml_str(&text).unwrap_err();
    assert!(e.to_string().contains("hammer.mass_g"), "{e}");
    let text =
        piano_action::params::DEFAULT_PARAMS_TOML.replace("mass_g = 11.74", "mass_g = \"heavy\"");
    let e = ActionParams::from_toml_str(&text).unwrap_err();
    assert!(e.field() == "hammer.mass_g", "{e}");
    let text = piano_action::params::DEFAULT_PARAMS_TOML.replace("crown_radius_mm", "crown_radius");
    let e = ActionParams::from_toml_str(&text).unwrap_err();
    assert!(e.to_string().contains("crown_radius"), "{e}");
    let text = piano_action::params::DEFAULT_PARAMS_TOML
        .replace("string_y_mm = 149.2", "string_y_mm = nan");
    let e = ActionParams::from_toml_str(&text).unwrap_err();
    assert!(e.to_string().contains("regulation.string_y_mm"), "{e}");
    // The parameters round-trip through their TOML form.
    let p = ActionParams::reference();
    assert_eq!(
        ActionParams::from_toml_str(&p.to_toml_string().unwrap()).unwrap(),
        p
    );
}

#[test]
fn the_string_section_is_checked_and_the_old_restitution_refused() {
    let default = piano_action::params::DEFAULT_PARAMS_TOML;
    let p = ActionParams::reference();
    // The C4 unison of Chaigne & Askenfelt, three strings, 48 modes.
    let string = p.string.build().unwrap();
    assert_eq!((string.strings(), string.modes()), (3, 48));
    assert!((string.unison_impedance() - 6.18).abs() < 0.01);
    // A file written before the string was modelled gives the hammer-string contact a
    // restitution: refused, named, on its line, saying why.
    let old = default.replace(
        "p = 2.5                               # [S] Chaigne & Askenfelt C4\n",
        "p = 2.5\ne = 0.6\n",
    );
    assert_ne!(old, default);
    let e = ActionParams::from_toml_str(&old).unwrap_err();
    assert_eq!(e.field(), "contacts.hammer_string.e", "{e}");
    let line = old.lines().position(|l| l == "e = 0.6").unwrap() + 1;
    assert!(e.to_string().contains(&format!("line {line}")), "{e}");
    assert!(e.to_string().contains("rebound"), "{e}");
    // Friction along the string is not modelled.
    let text = default.replace(
        "mu = 0.0                              # [M] friction along the string",
        "mu = 0.2                              # [M] friction along the string",
    );
    assert_ne!(text, default);
    let e = ActionParams::from_toml_str(&text).unwrap_err();
    assert_eq!(e.field(), "contacts.hammer_string.mu", "{e}");
    // The string's own fields, named as in the file.
    for (from, to, field) in [
        (
            "tension_per_string_n = 670.0",
            "tension_per_string_n = 750.0",
            "string.tension_per_string_n",
        ),
        (
            "striking_ratio = 0.12",
            "striking_ratio = 1.2",
            "string.striking_ratio",
        ),
        ("modes = 48", "modes = 0", "string.modes"),
        ("strings = 3", "strings = 0", "string.strings"),
        (
            "loss_b1_per_s = 0.5",
            "loss_b1_per_s = -0.5",
            "string.loss_b1_per_s",
        ),
        ("length_m = 0.62", "length_m = nan", "string.length_m"),
    ] {
        let text = default.replace(from, to);
        assert_ne!(text, default, "{from}");
        let e = ActionParams::from_toml_str(&text).unwrap_err();
        assert_eq!(e.field(), field, "{e}");
        assert!(e.to_string().contains("line"), "{e}");
    }
    let without: Vec<&str> = default
        .lines()
        .filter(|l| !l.starts_with("modes = "))
        .collect();
    let e = ActionParams::from_toml_str(&without.join("\n")).unwrap_err();
    assert!(e.to_string().contains("modes"), "{e}");
}
