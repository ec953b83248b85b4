//! The drawing as data for the report: parts in their rest places with the frames that carry
//! them, contact shapes at rest, and the frames' motion at a state.

use super::*;

pub(super) fn round(v: f64) -> f64 {
    (v * 1e3).round() / 1e3
}

pub(super) fn json_points(pts: &[P]) -> serde_json::Value {
    pts.iter()
        .map(|q| serde_json::json!([round(q[0]), round(q[1])]))
        .collect()
}

/// Parts as data: outlines in their rest places, frame, pivots and labels.
pub(super) fn parts_json(parts: &[Part]) -> Vec<serde_json::Value> {
    parts
        .iter()
        .map(|part| {
            let pieces: Vec<serde_json::Value> = part
                .pieces
                .iter()
                .map(|(piece, fill)| match piece {
                    Outline::Polygon(pts) => {
                        serde_json::json!({"kind": "polygon", "pts": json_points(pts), "fill": fill})
                    }
                    Outline::Circle(c, r) => serde_json::json!({
                        "kind": "circle", "c": [round(c[0]), round(c[1])], "r": round(*r), "fill": fill
                    }),
                    Outline::Wire(pts, w) => serde_json::json!({
                        "kind": "wire", "pts": json_points(pts), "width": round(*w), "fill": fill
                    }),
                })
                .collect();
            let labels: Vec<serde_json::Value> = part
                .labels
                .iter()
                .map(|l| {
                    serde_json::json!({
                        "anchor": [round(l.anchor[0]), round(l.anchor[1])],
                        "offset": l.offset, "text": l.text, "align": l.align
                    })
                })
                .collect();
            serde_json::json!({
                "id": part.id,
                "frame": part.frame,
                "behind": part.behind,
                "pieces": pieces,
                "pivots": json_points(&part.pivots),
                "labels": labels,
            })
        })
        .collect()
}

/// The drawing as data, for a viewer that moves it (the report): every part's outlines in
/// its rest place (mm, world, y up) with the frame that carries it (`null`: fixed), pivots
/// and labels; and every contact's shapes in their rest places, each with the frame of its
/// side. Move a part by its frame's [`carry`] transform.
pub fn scene(action: &Action) -> Result<serde_json::Value> {
    let (rest, _) = {
        let x = action.layout_state()?;
        rest_and_carry(action, 0.0, &x)?
    };
    let parts = parts_json(&build_parts(action, &rest));
    Ok(serde_json::json!({
        "frames": drawn_frames(action),
        "parts": parts,
        "contacts": rest_contacts_json(&action.system, &action.contacts, &action.contact_handles)?,
    }))
}

/// Every contact's shapes in their rest places (mm), by side with the frame that carries it.
pub(super) fn rest_contacts_json(
    system: &mbs_core::System,
    contacts_by_name: &BTreeMap<String, usize>,
    handles: &BTreeMap<String, ContactHandle>,
) -> Result<Vec<serde_json::Value>> {
    let model = system.model();
    let mut contacts = Vec::new();
    let mut rest_data = Data::new(model);
    update_poses(model, &mut rest_data, &vec![0.0; model.nv()])?;
    for name in contacts_by_name.keys() {
        let Some(c) = handles.get(name) else {
            continue;
        };
        let mut sides = Vec::new();
        for (body, shapes) in c.sides() {
            let frame = if body == mbs_core::BodyId::GROUND {
                None
            } else {
                model.body_name(body).map(str::to_string)
            };
            let pose = rest_data.body_pose(body);
            let placed: Vec<serde_json::Value> = shapes
                .iter()
                .map(|s| match s.placed(&pose) {
                    Shape::Circle(c) => serde_json::json!({
                        "kind": "circle",
                        "c": [round(c.center[0] * 1e3), round(c.center[1] * 1e3)],
                        "r": round(c.radius * 1e3)
                    }),
                    Shape::Segment(g) => serde_json::json!({
                        "kind": "segment", "pts": json_points(&[mul(g.a, 1e3), mul(g.b, 1e3)])
                    }),
                    Shape::Line(l) => serde_json::json!({
                        "kind": "line", "point": json_points(&[mul(l.point, 1e3)]), "normal": l.normal
                    }),
                    Shape::Arc(a) => serde_json::json!({
                        "kind": "arc",
                        "c": [round(a.center[0] * 1e3), round(a.center[1] * 1e3)],
                        "r": round(a.radius * 1e3), "start": a.start, "sweep": a.sweep
                    }),
                })
                .collect();
            sides.push(serde_json::json!({"frame": frame, "shapes": placed}));
        }
        contacts.push(serde_json::json!({"name": name, "sides": sides}));
    }
    Ok(contacts)
}

/// For every drawn frame, the motion `[angle (rad), x (mm), y (mm)]` carrying its parts from
/// their rest places to where they are at `(t, x)` (see [`scene`]).
pub fn carry(action: &Action, t: f64, x: &[f64]) -> Result<Vec<(&'static str, [f64; 3])>> {
    let (_, carry) = rest_and_carry(action, t, x)?;
    Ok(drawn_frames(action)
        .into_iter()
        .filter_map(|f| carry.get(f).map(|c| (f, [c.angle(), c.x * 1e3, c.y * 1e3])))
        .collect())
}
