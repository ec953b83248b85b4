//! Any mechanism drawn from its description's outlines.

use super::*;

// ------------------------------------------------------------ any mechanism, from outlines

/// Fill colours of bodies that name none, in body order.
pub(super) const BODY_FILLS: [&str; 8] = [
    KEY_FILL,
    WIPPEN_FILL,
    JACK_FILL,
    LEVER_FILL,
    SHANK_FILL,
    MOLDING_FILL,
    BRASS_FILL,
    FELT_FILL,
];

/// The drawn frames of a mechanism: every body, in order.
pub(super) fn mechanism_frames(mechanism: &Mechanism) -> Vec<&str> {
    mechanism.bodies.iter().map(|b| b.name.as_str()).collect()
}

/// One outline part placed by `pose` (m) as a drawn piece (mm).
pub(super) fn outline_piece(part: &mut Part, o: &OutlinePart, pose: &Transform, fill: &str) {
    let fill = o.color.as_deref().unwrap_or(fill);
    if let Some(c) = o.circle {
        part.circle(
            mul(pose.transform_point(c.center), 1e3),
            c.radius * 1e3,
            fill,
        );
    } else {
        let pts = o
            .points
            .iter()
            .map(|&p| mul(pose.transform_point(p), 1e3))
            .collect();
        part.polygon(pts, fill);
    }
}

/// The parts of a mechanism drawn from its outlines, in their rest places (world mm): the
/// ground's outlines first (`fixed-parts`), then each body's (`body-<name>`) with a white
/// dot at a revolute joint's pivot and the body's name beside it.
pub(super) fn mechanism_parts(
    mechanism: &Mechanism,
    rest: &BTreeMap<String, Transform>,
) -> Vec<Part> {
    // Fixed parts behind the mechanism's plane (a bracket between keys) first, seen
    // through it (pale, dashed); then the others.
    let mut behind = Part::new("fixed-behind", None);
    behind.behind = true;
    let mut ground = Part::new("fixed-parts", None);
    for o in &mechanism.ground {
        let part = if o.z + 0.5 * o.thickness < 0.0 {
            &mut behind
        } else {
            &mut ground
        };
        outline_piece(part, o, &Transform::IDENTITY, RAIL_FILL);
    }
    let mut parts = vec![behind, ground];
    for (i, body) in mechanism.bodies.iter().enumerate() {
        let Some(pose) = rest.get(&body.name) else {
            continue;
        };
        let mut part = Part::new(&format!("body-{}", body.name), Some(&body.name));
        let fill = BODY_FILLS[i % BODY_FILLS.len()];
        for o in &body.outline {
            outline_piece(&mut part, o, pose, fill);
        }
        let origin = mul(pose.transform_point([0.0, 0.0]), 1e3);
        if body.joint.kind == mbs_mechanism::JointType::Revolute {
            part.pivots.push(origin);
        }
        let com = mul(pose.transform_point(body.com), 1e3);
        part.label(com, [0.0, 6.0], body.name.replace('_', " "), "middle");
        parts.push(part);
    }
    parts
}

/// Draws a mechanism built from its description (`built`) from the outlines, to scale, at
/// time `t` and state `x`: an SVG document in millimetres, with the contact shapes and the
/// pressed contacts marked as in [`action_svg`].
pub fn mechanism_svg(
    mechanism: &Mechanism,
    built: &Built,
    t: f64,
    x: &[f64],
    title: &str,
) -> Result<String> {
    if !t.is_finite() {
        return Err(CoreError::NonFiniteInput {
            what: "t",
            index: 0,
            value: t,
        }
        .into());
    }
    let frames = mechanism_frames(mechanism);
    let (rest, carry) = rest_and_carry_of(&built.system, &frames, t, x)?;
    let contacts = contact_views(
        &built.system,
        &built.contacts,
        &built.contact_handles,
        t,
        x,
        |n| n,
    )?;
    let parts = mechanism_parts(mechanism, &rest);
    let legend = format!("{}: contact shapes; white dots: pivots", mechanism.name);
    Ok(render(&parts, &carry, &contacts, &legend, title))
}

/// The drawing of a mechanism as data for the report (as [`scene`] for the grand action):
/// its outlines in their rest places, with each part's thickness and plane for the 3D
/// view.
pub fn mechanism_scene(mechanism: &Mechanism, built: &Built) -> Result<serde_json::Value> {
    let frames = mechanism_frames(mechanism);
    let x = built.layout_state()?;
    let (rest, _) = rest_and_carry_of(&built.system, &frames, 0.0, &x)?;
    let parts = mechanism_parts(mechanism, &rest);
    let mut parts_json = parts_json(&parts);
    // Thickness and plane (mm) of every part, from its outlines (the thickest, the mean
    // plane), for the 3D view.
    let (back, front): (Vec<OutlinePart>, Vec<OutlinePart>) = mechanism
        .ground
        .iter()
        .cloned()
        .partition(|o| o.z + 0.5 * o.thickness < 0.0);
    let outlines: Vec<&[OutlinePart]> = [back.as_slice(), front.as_slice()]
        .into_iter()
        .chain(mechanism.bodies.iter().map(|b| b.outline.as_slice()))
        .collect();
    for (json, outline) in parts_json.iter_mut().zip(outlines) {
        if let Some(obj) = json.as_object_mut()
            && !outline.is_empty()
        {
            let thick = outline.iter().map(|o| o.thickness).fold(0.0, f64::max);
            let z = outline.iter().map(|o| o.z).sum::<f64>() / outline.len() as f64;
            obj.insert("thickness".into(), serde_json::json!(round(thick * 1e3)));
            obj.insert("z".into(), serde_json::json!(round(z * 1e3)));
        }
    }
    Ok(serde_json::json!({
        "frames": frames,
        "parts": parts_json,
        "contacts": rest_contacts_json(&built.system, &built.contacts, &built.contact_handles)?,
    }))
}

/// For every body of a mechanism, the motion `[angle (rad), x (mm), y (mm)]` carrying its
/// parts from their rest places to where they are at `(t, x)`.
pub fn mechanism_carry(
    mechanism: &Mechanism,
    built: &Built,
    t: f64,
    x: &[f64],
) -> Result<Vec<(String, [f64; 3])>> {
    let frames = mechanism_frames(mechanism);
    let (_, carry) = rest_and_carry_of(&built.system, &frames, t, x)?;
    Ok(frames
        .into_iter()
        .filter_map(|f| {
            carry
                .get(f)
                .map(|c| (f.to_string(), [c.angle(), c.x * 1e3, c.y * 1e3]))
        })
        .collect())
}
