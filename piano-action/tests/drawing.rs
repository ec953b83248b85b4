//! The SVG drawing of the action: to scale, the bodies each model has, the contacts the
//! simulation uses and which of them are pressed, and errors rather than panics.

use mbs_core::DriveState;
use piano_action::drawing::{MARGIN_MM, SCALE_BAR_MM};
use piano_action::{Action, ActionParams, ModelKind, action_svg};

fn build(kind: ModelKind) -> Action {
    Action::build(&ActionParams::reference(), kind).expect("the reference action builds")
}

/// The numbers of an attribute of the first element that has it.
fn numbers(svg: &str, attr: &str) -> Vec<f64> {
    let key = format!(r#"{attr}=""#);
    let start = svg.find(&key).expect("attribute present") + key.len();
    let end = start + svg[start..].find('"').expect("attribute closed");
    svg[start..end]
        .trim_end_matches("mm")
        .split_whitespace()
        .map(|v| v.parse().expect("a number"))
        .collect()
}

/// The text of the group with this id (up to its first closing tag, enough for groups
/// without nested groups).
fn group<'a>(svg: &'a str, id: &str) -> &'a str {
    let key = format!(r#"<g id="{id}""#);
    let start = svg.find(&key).unwrap_or_else(|| panic!("no group {id}"));
    let end = start + svg[start..].find("</g>").expect("group closed");
    &svg[start..end]
}

/// The attribute `attr` of the first circle in `text`.
fn circle_attr(text: &str, attr: &str) -> f64 {
    let c = &text[text.find("<circle").expect("a circle")..];
    numbers(c, attr)[0]
}

fn hammer_index(action: &Action) -> usize {
    action
        .system
        .model()
        .coordinate_id("hammer")
        .expect("a hammer joint")
}

/// The layout state with the hammer turned up until its crown presses `depth_m` into the
/// string (bisection on the model's own gap).
fn crown_in_string(action: &Action, depth_m: f64) -> Vec<f64> {
    let k = hammer_index(action);
    let mut x = action.layout_state().expect("layout");
    let gap = |x: &mut Vec<f64>, q: f64| {
        x[k] = q;
        action.gap("hammer_string", 0.0, x).expect("gap")
    };
    let (mut lo, mut hi) = (0.0, 0.8);
    assert!(gap(&mut x, lo) > 0.0 && gap(&mut x, hi) < -depth_m);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if gap(&mut x, mid) > -depth_m {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    x[k] = 0.5 * (lo + hi);
    x
}

#[test]
fn the_page_is_the_action_to_scale_in_millimetres() {
    let action = build(ModelKind::Double);
    let svg = action_svg(&action, 0.0, &action.layout_state().unwrap(), "to scale").unwrap();
    let view = numbers(&svg, "viewBox");
    let (width, height) = (numbers(&svg, "width")[0], numbers(&svg, "height")[0]);
    // One SVG unit is one millimetre on the page.
    assert!((width - view[2]).abs() < 0.01 && (height - view[3]).abs() < 0.01);
    // The action runs from the key front to the back of the key, rails and string.
    let p = &action.params;
    let front = p.key.finger_mm[0];
    let back = p.regulation.string_x_mm[1]
        .max(p.key.back_pad_mm[0])
        .max(p.regulation.back_rail_x_mm[1]);
    let expected = back - front + 2.0 * MARGIN_MM;
    assert!(
        (view[2] - expected).abs() < 8.0,
        "viewBox width {} mm, the action with margins {expected} mm",
        view[2]
    );
    // The scale bar is SCALE_BAR_MM units long.
    let bar = group(&svg, "scale-bar");
    let (x1, x2) = (numbers(bar, "x1")[0], numbers(bar, "x2")[0]);
    assert!((x2 - x1 - SCALE_BAR_MM).abs() < 1e-9);
}

#[test]
fn the_crown_is_drawn_at_its_size_and_on_the_string_when_it_strikes() {
    let action = build(ModelKind::Double);
    let x = crown_in_string(&action, 0.2e-3);
    let svg = action_svg(&action, 0.0, &x, "strike").unwrap();
    let p = &action.params;
    // The crown's contact circle: its radius in mm, its top 0.2 mm above the string (SVG y
    // runs down: y_svg = −y).
    let crown = group(&svg, "contact-hammer_string");
    let (cy, r) = (circle_attr(crown, "cy"), circle_attr(crown, "r"));
    assert!((r - p.hammer.crown_radius_mm).abs() < 0.01, "r = {r}");
    let top = -(cy - r);
    assert!(
        (top - (p.regulation.string_y_mm + 0.2)).abs() < 0.02,
        "crown top at {top} mm, string at {}",
        p.regulation.string_y_mm
    );
}

#[test]
fn only_pressed_contacts_are_marked() {
    let action = build(ModelKind::Double);
    let rest = action.layout_state().unwrap();
    let svg = action_svg(&action, 0.0, &rest, "rest").unwrap();
    for name in ["hammer_string", "let_off_button", "backcheck"] {
        assert!(
            !svg.contains(&format!(r#"id="active-{name}""#)),
            "{name} marked at rest"
        );
    }
    // Whatever is marked is pressed according to the model, and the other way round.
    for name in action.contacts.keys() {
        let pressed = action.gap(name, 0.0, &rest).unwrap() < 0.0;
        assert_eq!(
            svg.contains(&format!(r#"id="active-{name}""#)),
            pressed,
            "{name}"
        );
    }

    let x = crown_in_string(&action, 0.2e-3);
    let svg = action_svg(&action, 0.0, &x, "strike").unwrap();
    assert!(svg.contains(r#"id="active-hammer_string""#));
    // The dot sits where crown and string meet, and the legend names the contact.
    let dots = group(&svg, "active-contacts");
    let id = dots.find(r#"id="active-hammer_string""#).unwrap();
    let at = &dots[dots[..id].rfind("<circle").unwrap()..];
    let y = -circle_attr(at, "cy");
    assert!(
        (y - action.params.regulation.string_y_mm).abs() < 0.5,
        "dot at y = {y}"
    );
    let legend = group(&svg, "legend");
    assert!(legend.contains("hammer_string"));
}

#[test]
fn each_model_draws_the_bodies_it_has() {
    let id = |s: &str, body: &str| s.contains(&format!(r#"id="body-{body}""#));
    let draw = |kind| {
        let a = build(kind);
        action_svg(&a, 0.0, &a.layout_state().unwrap(), kind.name()).unwrap()
    };
    let simplified = draw(ModelKind::Simplified);
    let single = draw(ModelKind::Single);
    let double = draw(ModelKind::Double);
    for svg in [&simplified, &single, &double] {
        for body in ["key", "wippen", "hammer"] {
            assert!(id(svg, body), "no {body}");
        }
    }
    // The simplified jack is part of the wippen; no let-off button, backcheck or lever.
    assert!(!id(&simplified, "jack") && !id(&simplified, "repetition_lever"));
    assert!(!simplified.contains("let-off button") && !simplified.contains("key-backcheck"));
    assert!(id(&single, "jack") && !id(&single, "repetition_lever"));
    assert!(!single.contains("drop screw"));
    assert!(id(&double, "jack") && id(&double, "repetition_lever"));
    assert!(double.contains("drop screw"));
}

#[test]
fn every_contact_of_the_model_is_drawn() {
    let action = build(ModelKind::Double);
    let svg = action_svg(&action, 0.0, &action.layout_state().unwrap(), "contacts").unwrap();
    for name in action.contacts.keys() {
        let g = group(&svg, &format!("contact-{name}"));
        // Two sides, at least one shape each.
        let shapes = g.matches("<circle").count() + g.matches("<polyline").count();
        assert!(shapes >= 2, "{name}: {shapes} shapes");
    }
}

#[test]
fn a_prescribed_key_is_drawn_where_its_drive_puts_it() {
    let free = build(ModelKind::Double);
    let mut driven = build(ModelKind::Double);
    let q = 0.03;
    driven
        .system
        .prescribe("key", move |_t: f64| DriveState { q, v: 0.0, a: 0.0 })
        .unwrap();
    let rest = free.layout_state().unwrap();
    let mut pressed = rest.clone();
    pressed[free.system.model().coordinate_id("key").unwrap()] = q;
    // The driven action's state says the key is at rest: the drive wins.
    let a = action_svg(&driven, 0.0, &rest, "").unwrap();
    let b = action_svg(&free, 0.0, &pressed, "").unwrap();
    let c = action_svg(&free, 0.0, &rest, "").unwrap();
    assert_eq!(group(&a, "body-key"), group(&b, "body-key"));
    assert_ne!(group(&a, "body-key"), group(&c, "body-key"));
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let action = build(ModelKind::Double);
    let x = action.layout_state().unwrap();
    let mut nan = x.clone();
    nan[hammer_index(&action)] = f64::NAN;
    assert!(action_svg(&action, 0.0, &nan, "nan").is_err());
    assert!(action_svg(&action, 0.0, &x[..x.len() - 1], "short").is_err());
    assert!(action_svg(&action, f64::NAN, &x, "nan time").is_err());
    // A title is text, not markup.
    let svg = action_svg(&action, 0.0, &x, "<b> & \"c\"").unwrap();
    assert!(svg.contains("&lt;b&gt; &amp; &quot;c&quot;") && !svg.contains("<b>"));
}
