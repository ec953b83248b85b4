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

/// The polygons and polylines of a group, in world millimetres (y up).
fn outlines(group_text: &str) -> Vec<Vec<[f64; 2]>> {
    let mut out = Vec::new();
    let mut rest = group_text;
    while let Some(i) = rest.find(r#"points=""#) {
        let start = i + r#"points=""#.len();
        let end = start + rest[start..].find('"').expect("points closed");
        let pts = rest[start..end]
            .split_whitespace()
            .map(|xy| {
                let (x, y) = xy.split_once(',').expect("x,y");
                [x.parse::<f64>().unwrap(), -y.parse::<f64>().unwrap()]
            })
            .collect();
        out.push(pts);
        rest = &rest[end..];
    }
    out
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Whether segments ab and cd cross (touching counts).
fn segments_meet(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let (d1, d2) = (cross(c, d, a), cross(c, d, b));
    let (d3, d4) = (cross(a, b, c), cross(a, b, d));
    d1 * d2 <= 0.0 && d3 * d4 <= 0.0
}

/// Whether `p` is inside the polygon (even–odd rule).
fn inside(p: [f64; 2], poly: &[[f64; 2]]) -> bool {
    let mut odd = false;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        if (a[1] > p[1]) != (b[1] > p[1])
            && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0])
        {
            odd = !odd;
        }
    }
    odd
}

/// Whether a closed polygon and an outline (closed when `closed`) share any point.
fn shapes_meet(poly: &[[f64; 2]], other: &[[f64; 2]], closed: bool) -> bool {
    let n = other.len();
    let edges = if closed { n } else { n - 1 };
    for k in 0..edges {
        let (c, d) = (other[k], other[(k + 1) % n]);
        for j in 0..poly.len() {
            if segments_meet(poly[j], poly[(j + 1) % poly.len()], c, d) {
                return true;
            }
        }
    }
    other.iter().any(|&p| inside(p, poly)) || (closed && poly.iter().any(|&p| inside(p, other)))
}

/// The first place the drawn hammer and backcheck share a point, if any.
fn hammer_meets_backcheck(svg: &str) -> Option<String> {
    let hammer = outlines(group(svg, "body-hammer"));
    let check_group = group(svg, "key-backcheck");
    let polygons = outlines(&check_group.replace("<polyline", "<wire"));
    assert!(hammer.len() >= 4 && !polygons.is_empty());
    for (i, h) in hammer.iter().enumerate() {
        for (j, b) in polygons.iter().enumerate() {
            // The first outline of the backcheck group is its wire (a polyline).
            let closed = !(j == 0 && check_group.contains("<polyline"));
            if shapes_meet(h, b, closed) {
                return Some(format!("hammer outline {i} meets backcheck outline {j}"));
            }
        }
    }
    None
}

/// Bisection for the coordinate `name` in `[lo, hi]` where the contact's gap is `target`
/// (the gap must cross it once there).
fn solve_gap(
    action: &Action,
    x: &mut [f64],
    name: &str,
    contact: &str,
    lo: f64,
    hi: f64,
    target: f64,
) {
    let k = action.system.model().coordinate_id(name).unwrap();
    let gap = |x: &mut [f64], q: f64| {
        x[k] = q;
        action.gap(contact, 0.0, x).unwrap() - target
    };
    let (mut a, mut b) = (lo, hi);
    let ga = gap(x, a);
    assert!(
        ga * gap(x, b) < 0.0,
        "{contact}: no crossing of {target} in [{lo}, {hi}]"
    );
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        if (gap(x, m) > 0.0) == (ga > 0.0) {
            a = m;
        } else {
            b = m;
        }
    }
    x[k] = 0.5 * (a + b);
}

#[test]
fn the_backcheck_stands_clear_of_the_hammer_at_rest_and_until_the_tail_reaches_it() {
    let action = build(ModelKind::Double);
    let rest = action.layout_state().unwrap();
    let svg = action_svg(&action, 0.0, &rest, "rest").unwrap();
    // At rest the tail is far from the face (the model's gap), and no drawn part of the
    // backcheck (wire, block, leather) lies in the drawn hammer.
    let gap = action.gap("backcheck", 0.0, &rest).unwrap();
    assert!(gap > 5e-3, "tail {gap} m from the backcheck at rest");
    assert_eq!(hammer_meets_backcheck(&svg), None);

    // The key down on the front rail, the hammer falling from 23° above its rest (where it checks at about 15°) onto the
    // backcheck: 0.3 mm before the tail touches the face, the drawings do not touch
    // either ...
    let mut x = rest.clone();
    solve_gap(&action, &mut x, "key", "front_rail", 0.0, 0.1, 0.0);
    solve_gap(&action, &mut x, "hammer", "backcheck", 0.16, 0.4, 0.3e-3);
    let svg = action_svg(&action, 0.0, &x, "just before the check").unwrap();
    assert_eq!(hammer_meets_backcheck(&svg), None);
    // ... and when the tail presses 0.3 mm into the leather, they do: the catch face of
    // the drawn moulding is where the model's tail is.
    solve_gap(&action, &mut x, "hammer", "backcheck", 0.16, 0.4, -0.3e-3);
    let svg = action_svg(&action, 0.0, &x, "checked").unwrap();
    assert!(hammer_meets_backcheck(&svg).is_some());
}

#[test]
fn the_capstan_stands_on_the_key_top() {
    // Raises the geometry check accepts (more than 3 mm pushes the capstan into the heel).
    for raise in [0.09, -1.0, 2.5] {
        let mut params = ActionParams::reference();
        params.regulation.capstan_raise_mm = raise;
        let action = Action::build(&params, ModelKind::Double).unwrap();
        let svg = action_svg(&action, 0.0, &action.layout_state().unwrap(), "rest").unwrap();
        let capstan = outlines(group(&svg, "key-capstan"));
        let ys: Vec<f64> = capstan.iter().flatten().map(|p| p[1]).collect();
        let lowest = ys.iter().copied().fold(f64::INFINITY, f64::min);
        let highest = ys.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let key_top = params.key.finger_mm[1];
        assert!(
            (lowest - key_top).abs() < 0.1,
            "raise {raise}: capstan from {lowest} mm, key top at {key_top} mm"
        );
        // Its top is the model's head: where the heel rests on it.
        let head_top = params.key.capstan_center_mm[1] + raise + params.key.capstan_radius_mm;
        assert!(
            (highest - head_top).abs() < 0.05,
            "raise {raise}: top {highest} vs {head_top}"
        );
    }
}

#[test]
fn the_rails_hang_on_the_action_bracket() {
    let action = build(ModelKind::Double);
    let svg = action_svg(&action, 0.0, &action.layout_state().unwrap(), "rest").unwrap();
    let bracket = outlines(group(&svg, "action-bracket"));
    assert_eq!(bracket.len(), 1);
    let bracket = &bracket[0];
    let p = &action.params;
    let (h, w, g) = (&p.hammer, &p.wippen, &p.regulation);
    // The bracket reaches each rail, or the flange on it: the point 1 mm outside the
    // rail's drawn block, on the bracket's side, is the bracket's.
    let (lx, ly) = (g.let_off_button_x_mm, g.let_off_button_y_mm);
    let rest_rail = 0.5 * (g.rest_rail_x_mm[0] + g.rest_rail_x_mm[1]);
    for (what, point) in [
        ("hammer-flange rail", [h.pivot_mm[0] - 28.0, h.pivot_mm[1]]),
        ("let-off rail", [0.5 * (lx[0] + lx[1]) - 11.0, ly + 21.0]),
        ("wippen flange", [w.pivot_mm[0] - 6.0, w.pivot_mm[1] - 2.0]),
        ("rest rail", [rest_rail, g.rest_rail_top_y_mm - 12.0]),
    ] {
        assert!(inside(point, bracket), "the {what} is not held: {point:?}");
    }
    // The bracket stands on the key frame, under the keys.
    let lowest = bracket.iter().map(|q| q[1]).fold(f64::INFINITY, f64::min);
    let frame = outlines(group(&svg, "fixed-parts"))[0]
        .iter()
        .map(|q| q[1])
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        (lowest - frame).abs() < 1e-6,
        "bracket foot {lowest}, key frame top {frame}"
    );
}

#[test]
fn a_finger_is_drawn_as_a_finger_and_a_weight_as_its_mass() {
    use piano_action::Presser;
    let params = ActionParams::reference();
    let mut finger = Presser::weight(0.03, 0.0);
    finger.carried = true;
    for (presser, name) in [
        (finger, "finger"),
        (Presser::weight(1.0, 20.0), "1 kg mass"),
    ] {
        let action = Action::build_with(&params, ModelKind::Double, Some(presser)).unwrap();
        let svg = action_svg(&action, 0.0, &action.layout_state().unwrap(), name).unwrap();
        let labels = group(&svg, "labels");
        assert!(labels.contains(&format!(">{name}<")), "no label {name}");
        assert!(!labels.contains("presser"), "{name} called presser");
        // Its lowest point is the model's pad: on the key top for the finger (which
        // starts on it), 20 mm above for the dropped mass.
        let lowest = outlines(group(&svg, "body-presser"))
            .iter()
            .flatten()
            .map(|q| q[1])
            .fold(f64::INFINITY, f64::min);
        let want = params.key.finger_mm[1] + if name == "finger" { 0.0 } else { 20.0 };
        assert!(
            (lowest - want).abs() < 0.05,
            "{name}: lowest {lowest}, pad at {want}"
        );
    }
}

#[test]
fn no_two_part_names_overlap() {
    use piano_action::drawing::label_box;
    for kind in ModelKind::ALL {
        let action = build(kind);
        let svg = action_svg(&action, 0.0, &action.layout_state().unwrap(), "labels").unwrap();
        let labels = group(&svg, "labels");
        let mut boxes = Vec::new();
        for t in labels.split("<text ").skip(1) {
            let x: f64 = numbers(t, "x")[0];
            let y: f64 = numbers(t, "y")[0];
            let align = t
                .split(r#"text-anchor=""#)
                .nth(1)
                .and_then(|s| s.split('"').next())
                .unwrap();
            let text = t
                .split('>')
                .nth(1)
                .and_then(|s| s.split('<').next())
                .unwrap();
            // The text stands on its point with its baseline 1 mm below (SVG y runs down).
            boxes.push((text.to_string(), label_box([x, -(y - 1.0)], text, align)));
        }
        assert!(boxes.len() >= 8, "{} labels", boxes.len());
        for (i, (ta, a)) in boxes.iter().enumerate() {
            for (tb, b) in &boxes[i + 1..] {
                let apart = a[2] <= b[0] || b[2] <= a[0] || a[3] <= b[1] || b[3] <= a[1];
                assert!(apart, "{}: '{ta}' {a:?} overlaps '{tb}' {b:?}", kind.name());
            }
        }
    }
}
