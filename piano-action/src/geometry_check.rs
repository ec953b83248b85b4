//! Whether a parameter set describes an action that can work: the geometry and body data
//! checked the way a technician looks over an action before regulating it.
//!
//! [`ActionParams::validate`] refuses impossible numbers (not finite, a negative mass);
//! this module refuses impossible *pianos*: a string below the hammer, a let-off button the
//! jack toe can never reach, a capstan that cannot lift the wippen, a 2 kg hammer. Each
//! problem names the field to change and says what is wrong in piano terms.
//!
//! The checks are deliberately loose: a badly regulated action (every screw off by a turn
//! or more) must still load so that `piano regulate` can put it right. They judge the
//! layout pose (every joint at its rest angle, as the file places the parts), move the key
//! through a generous reach ([`DIP_MAX_MM`] plus [`DIP_REACH_EXTRA_MM`] at the key front)
//! with the kinematics linearised at rest, and report a contact pair only when it is
//! grossly inside itself at rest or cannot meet anywhere in that reach. False alarms are
//! worse than misses here: a miss shows up later in the regulation or the simulation.
//!
//! Frames and shapes follow [`crate::Action`]: world x from the key front toward the
//! strings, y up, angles counter-clockwise; the hammer's points are in its shank frame.
//!
//! ```
//! use piano_action::{ActionParams, geometry_check};
//!
//! let mut p = ActionParams::reference();
//! assert!(geometry_check::check(&p).is_empty());
//! p.regulation.string_y_mm = 40.0; // below the hammer
//! let problems = geometry_check::check(&p);
//! assert_eq!(problems[0].field, "regulation.string_y_mm");
//! ```

use std::fmt;

use crate::error::{PianoError, Result};
use crate::params::ActionParams;

mod shapes;

use shapes::{Face, Pose, Shapes, V, add, covers, cross, dot, ground, norm, scale, sub};

/// One thing wrong with a parameter set's geometry or body data.
#[derive(Clone, Debug, PartialEq)]
pub struct GeometryProblem {
    /// The field to change, as a path (`regulation.string_y_mm`).
    pub field: String,
    /// What is wrong, in piano terms, and what to change.
    pub message: String,
}

impl fmt::Display for GeometryProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "`{}`: {}", self.field, self.message)
    }
}

// ---------------------------------------------------------------------------------------
// Thresholds. Every one is loose on purpose; tags as in the parameter file: [V] read in a
// source, [S] secondhand, [M] judgement, [D] derived or design choice.

/// Deepest overlap (mm) two parts may have at rest: felt under the layout's contact laws
/// compresses 0.5–2 mm at forte loads (action_layout.md §6) \[D\]; a regulating screw turned
/// a little far stays inside.
pub const PENETRATION_MAX_MM: f64 = 3.0;
/// How far (mm) a contact point may lie past the end of the face that should meet it:
/// the 0.1 mm rounding of the layout's points, with room to spare \[D\].
pub const COVER_TOL_MM: f64 = 1.0;
/// Key dip (mm at the key front) the front-rail punching must allow at rest: regulated
/// 10 mm \[V Brekne\] (band 9.5–11), accepted 5–15 mm \[D\].
pub const DIP_MIN_MM: f64 = 5.0;
/// Upper end of the accepted key dip (mm) \[D\]; see [`DIP_MIN_MM`].
pub const DIP_MAX_MM: f64 = 15.0;
/// Extra key-front travel (mm) beyond the dip a hard blow can force: the punching
/// compresses a further 0.76–1.0 mm under a hard press \[V Bullock\], doubled \[D\].
pub const DIP_REACH_EXTRA_MM: f64 = 2.0;
/// Blow distance (mm, crown to string at rest) accepted: regulated 44–48 mm
/// \[V, literature.md §3\], accepted 20–80 so that a badly regulated action loads \[D\].
pub const BLOW_MM: (f64, f64) = (20.0, 80.0);
/// Largest hammer rotation (deg) from rest to the string: about 20° in the reference
/// layout and 42° under the other reading of Hirschkorn's frame (action_layout.md §7) \[D\].
pub const SWING_MAX_DEG: f64 = 60.0;
/// Largest gap (mm) between the key's back pad and the back-rail cloth at rest: the key
/// tail rests on the cloth \[V\]; 5 mm of air means the key rests elsewhere \[D\].
pub const BACK_RAIL_GAP_MAX_MM: f64 = 5.0;
/// Shank clearance (mm) over the rest-rail cushion when regulated: 1/8" \[V\].
pub const REST_RAIL_CLEARANCE_MM: f64 = 3.2;
/// Largest gap (mm) between the shank and the rest-rail cushion at rest: regulated 1/8"
/// \[V\]; 1/2" already spoils repetition \[V Foote\]; twice that \[D\].
pub const REST_RAIL_GAP_MAX_MM: f64 = 25.0;
/// The backcheck and the hammer tail "meet" when some key and hammer positions bring them
/// this close (mm): the scan's steps move the parts about 1 mm \[D\].
pub const BACKCHECK_MEET_MM: f64 = 2.0;
/// A regulating screw (capstan, backcheck) turned further than this (mm) is blamed before
/// the part it sits on \[D\].
pub const SCREW_RANGE_MM: f64 = 3.0;
/// Least lever arm (mm) of the knuckle about the hammer centre pin: the knuckle distance
/// is 15.5–17 mm \[V Ball, Stanwood\] \[D\].
pub const KNUCKLE_ARM_MIN_MM: f64 = 3.0;
/// Key ratio (capstan arm over key front arm) accepted: 0.49–0.58 \[V Love\], 0.45–0.58
/// in action_layout.md §3, 0.5 typical \[V Stanwood\] \[D\].
pub const KEY_RATIO: (f64, f64) = (0.3, 0.8);
/// Least distance (mm) between a pivot and a point that must lie on one side of it \[D\].
pub const SIDE_MARGIN_MM: f64 = 5.0;
/// How far (mm) a centre of mass may lie outside the box around its part's pivots and
/// contact points: wood and felt extend past them \[D\].
pub const COM_MARGIN_MM: f64 = 20.0;
/// A part's radius of gyration about its pivot may exceed the distance from the pivot to
/// its farthest listed point by this factor at most (physically it cannot exceed the
/// farthest material point; the listed points need not be the farthest) \[D\].
pub const GYRATION_MAX_FRACTION: f64 = 1.25;
/// Least radius of gyration about the centre of mass, as a fraction of the distance from
/// it to the part's farthest point: a slender rod has 0.58 (L/√12 over L/2), the reference
/// parts 0.46–0.58 \[D\].
pub const GYRATION_MIN_FRACTION: f64 = 0.05;
/// Tolerance on the length of a unit vector: the published jack axis is rounded to three
/// digits (length 1.0005) \[D\].
pub const UNIT_TOL: f64 = 0.02;
/// Largest angle (deg) between the jack axis and the line from the jack pin to its top \[D\].
pub const JACK_AXIS_MAX_DEG: f64 = 30.0;
/// Hammer shank angle at rest (deg): −19.86° in the reference layout, 0° in the other
/// reading of Hirschkorn's frame (action_layout.md §7) \[D\].
pub const HAMMER_REST_DEG: (f64, f64) = (-60.0, 45.0);
/// Backcheck face angle to the key (deg): 68–72° \[V Page\], accepted 30–150° \[D\].
pub const BACKCHECK_FACE_DEG: (f64, f64) = (30.0, 150.0);
/// Largest stop angle (rad, either sign) of the jack and repetition lever: more than 0.5
/// rad (29°) is likely degrees typed as radians \[D\].
pub const STOP_MAX_RAD: f64 = 0.5;

/// Mass ranges (g) of the parts, each a generous margin around what is known \[D\]:
/// key 90–130 g (action_layout.md §4 \[D\]); wippen 15 g \[M\], Stanwood's wippen weight 18 g
/// \[V\]; jack 4 g \[M\]; repetition lever 6 g \[M\]; hammer and shank 11.74 g \[S Hirschkorn\],
/// Stanwood strike weights 3.5–15 g \[V\] and a hammer's mass about 1.3 times its strike
/// weight \[D\].
pub const MASS_G: [(&str, f64, f64); 5] = [
    ("key", 40.0, 300.0),
    ("wippen", 3.0, 60.0),
    ("jack", 0.5, 15.0),
    ("repetition_lever", 0.5, 20.0),
    ("hammer", 2.0, 30.0),
];

// ---------------------------------------------------------------------------------------
// The checks.

/// Collects problems.
struct Report(Vec<GeometryProblem>);

impl Report {
    fn push(&mut self, field: &str, message: String) {
        self.0.push(GeometryProblem {
            field: field.to_string(),
            message,
        });
    }
}

/// Checks the geometry and body data of `params` and returns every problem found, the
/// most basic first (shapes, then bodies, then how the parts meet), each naming the field
/// to change. An empty list means the action can work; nothing is simulated.
///
/// What is checked (thresholds are the constants of this module):
/// - shapes: extents along x ordered and non-empty, radii and face lengths positive, the
///   jack axis a unit vector along the jack, angles in range;
/// - bodies: masses within a generous range for each part, radii of gyration neither
///   longer than the part nor implausibly small, inertias about a pivot at least the
///   parallel-axis term, centres of mass on their part;
/// - the lever chain: the balance pivot between the finger and the capstan, the pads on
///   their side of it, the heel in front of the wippen pin, the jack lifted by the wippen
///   and the knuckle behind the hammer pin so that the key lifts the hammer;
/// - the key dip the front-rail punching allows;
/// - the string above the crown at a plausible blow distance, within the hammer's swing
///   and over the strike point;
/// - every contact pair (front and back rail, capstan–heel, jack and lever on the
///   knuckle, let-off button–toe, drop screw–lever tip, backcheck–tail, rest rail–shank):
///   its face over the point that meets it, not deep inside it at rest, and able to meet
///   it within the key's reach.
pub fn check(params: &ActionParams) -> Vec<GeometryProblem> {
    let mut r = Report(Vec::new());
    let s = Shapes::new(params);
    shapes(params, &mut r);
    // The contact checks need well-formed shapes.
    let shapes_ok = r.0.is_empty();
    bodies(params, &mut r);
    if !shapes_ok {
        return r.0;
    }
    let reach = chain(params, &s, &mut r)
        .and_then(|c| Some(Reach::new(params, c, key_dip(params, &s, &mut r)?)));
    let swing = string(params, &s, &mut r);
    pairs(params, &s, reach, swing, &mut r);
    r.0
}

/// [`check`] as an error: `Ok` when no problem is found, otherwise a
/// parameter error ([`PianoError::params`]) naming the first problem's field, with every problem in the
/// message. [`ActionParams::validate`] calls it.
pub fn ensure_plausible(params: &ActionParams) -> Result<()> {
    let problems = check(params);
    let Some(first) = problems.first() else {
        return Ok(());
    };
    let mut message = first.message.clone();
    if problems.len() > 1 {
        let rest: Vec<String> = problems[1..].iter().map(|p| p.to_string()).collect();
        message.push_str(&format!("; also {}", rest.join("; ")));
    }
    Err(PianoError::params(first.field.clone(), message))
}

/// Extents, radii, face lengths, the jack axis and angles.
fn shapes(p: &ActionParams, r: &mut Report) {
    let g = &p.regulation;
    let extents = [
        (
            "regulation.front_rail_x_mm",
            "front-rail punching",
            g.front_rail_x_mm,
        ),
        (
            "regulation.back_rail_x_mm",
            "back-rail cloth",
            g.back_rail_x_mm,
        ),
        (
            "regulation.let_off_button_x_mm",
            "let-off button",
            g.let_off_button_x_mm,
        ),
        (
            "regulation.drop_screw_x_mm",
            "drop screw",
            g.drop_screw_x_mm,
        ),
        ("regulation.string_x_mm", "string", g.string_x_mm),
        (
            "regulation.rest_rail_x_mm",
            "rest-rail cushion",
            g.rest_rail_x_mm,
        ),
    ];
    for (field, what, [a, b]) in extents {
        if a >= b {
            r.push(
                field,
                format!(
                    "the {what} runs from x = {a} to x = {b} mm: the first value is its front \
                     end (toward the player) and must be the smaller, and the two must \
                     differ, otherwise the {what} has no length or faces the wrong way; \
                     write [{}, {}]",
                    a.min(b),
                    a.max(b).max(a.min(b) + 1.0)
                ),
            );
        }
    }
    let positive = [
        (
            "key.front_pad_radius_mm",
            p.key.front_pad_radius_mm,
            "rounding of the key's underside over the front-rail punching",
        ),
        (
            "key.back_pad_radius_mm",
            p.key.back_pad_radius_mm,
            "rounding of the key's underside over the back-rail cloth",
        ),
        (
            "key.backcheck_half_length_mm",
            p.key.backcheck_half_length_mm,
            "half height of the backcheck head",
        ),
        (
            "wippen.heel_half_length_mm",
            p.wippen.heel_half_length_mm,
            "half length of the wippen heel the capstan lifts",
        ),
        (
            "jack.toe_radius_mm",
            p.jack.toe_radius_mm,
            "rounding of the jack toe that meets the let-off button",
        ),
        (
            "repetition_lever.tip_radius_mm",
            p.repetition_lever.tip_radius_mm,
            "rounding of the repetition lever tip under the drop screw",
        ),
        (
            "hammer.tail_radius_mm",
            p.hammer.tail_radius_mm,
            "rounding of the hammer tail the backcheck catches",
        ),
    ];
    for (field, v, what) in positive {
        if v <= 0.0 {
            r.push(field, format!("the {what} must be positive, got {v} mm"));
        }
    }
    let edges = [
        (
            "jack.top_back_edge_mm",
            "jack.top_front_edge_mm",
            p.jack.top_back_edge_mm,
            p.jack.top_front_edge_mm,
            "jack top",
        ),
        (
            "repetition_lever.top_back_edge_mm",
            "repetition_lever.top_front_edge_mm",
            p.repetition_lever.top_back_edge_mm,
            p.repetition_lever.top_front_edge_mm,
            "repetition lever top",
        ),
    ];
    for (back_field, front_field, back, front, what) in edges {
        if back < 0.0 {
            r.push(
                back_field,
                format!(
                    "the {what} cannot end in front of the knuckle's contact point: its \
                     length behind it must be 0 or more, got {back} mm"
                ),
            );
        }
        if front < 0.0 {
            r.push(
                front_field,
                format!(
                    "the {what} cannot start behind the knuckle's contact point: its \
                     length in front of it must be 0 or more, got {front} mm"
                ),
            );
        }
        if back >= 0.0 && front >= 0.0 && back + front <= 0.0 {
            r.push(
                front_field,
                format!("the {what} has no length: give it a few mm in front of the knuckle"),
            );
        }
    }
    let j = &p.jack;
    let len = norm(j.axis);
    if (len - 1.0).abs() > UNIT_TOL {
        let n = if len > 0.0 {
            scale(j.axis, 1.0 / len)
        } else {
            [0.0, 1.0]
        };
        r.push(
            "jack.axis",
            format!(
                "the jack axis has length {len:.3}, not 1: it is the unit direction from the \
                 jack centre pin to its top, which also squares the jack top; write \
                 [{:.3}, {:.3}]",
                n[0], n[1]
            ),
        );
    } else {
        let along = sub(j.top_mm, j.pivot_mm);
        let l = norm(along);
        let angle = if l > 0.0 {
            (dot(j.axis, along) / (len * l))
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees()
        } else {
            180.0
        };
        if angle > JACK_AXIS_MAX_DEG {
            r.push(
                "jack.axis",
                format!(
                    "the jack axis points {angle:.0}° away from the line from the jack centre \
                     pin to its top (jack.top_mm): the jack top would be tilted that far off \
                     square to the jack; the axis runs from pin to top, here [{:.3}, {:.3}]",
                    along[0] / l.max(f64::MIN_POSITIVE),
                    along[1] / l.max(f64::MIN_POSITIVE)
                ),
            );
        }
    }
    let h = p.hammer.rest_angle_deg;
    if !(HAMMER_REST_DEG.0..=HAMMER_REST_DEG.1).contains(&h) {
        r.push(
            "hammer.rest_angle_deg",
            format!(
                "the hammer shank rests at {h}°: a grand's shank lies near horizontal at rest \
                 (about −20° head down in the reference layout; {}° to {}° accepted); is it \
                 in radians?",
                HAMMER_REST_DEG.0, HAMMER_REST_DEG.1
            ),
        );
    }
    let b = p.key.backcheck_face_angle_deg;
    if !(BACKCHECK_FACE_DEG.0..=BACKCHECK_FACE_DEG.1).contains(&b) {
        r.push(
            "key.backcheck_face_angle_deg",
            format!(
                "the backcheck face stands at {b}° to the key: technicians set it at 68–72° \
                 so the falling tail wedges against it ({}° to {}° accepted); is it in \
                 radians?",
                BACKCHECK_FACE_DEG.0, BACKCHECK_FACE_DEG.1
            ),
        );
    }
    let stops = [
        (
            "jack.stop_angle_rad",
            p.jack.stop_angle_rad,
            "jack stop (how far the jack may turn back past its rest angle)",
        ),
        (
            "jack.outer_stop_rad",
            p.jack.outer_stop_rad,
            "jack's outer stop (how far it may turn out from under the knuckle)",
        ),
        (
            "repetition_lever.upper_stop_rad",
            p.repetition_lever.upper_stop_rad,
            "repetition lever's upper stop",
        ),
    ];
    for (field, v, what) in stops {
        if v.abs() > STOP_MAX_RAD {
            r.push(
                field,
                format!(
                    "the {what} is {v} rad ({:.0}°): stops sit within a few degrees of rest \
                     (up to {STOP_MAX_RAD} rad accepted); is it in degrees?",
                    v.to_degrees()
                ),
            );
        }
    }
    if p.jack.outer_stop_rad <= p.jack.stop_angle_rad.max(0.0) + 0.02 {
        r.push(
            "jack.outer_stop_rad",
            format!(
                "the jack's outer stop ({} rad) must lie beyond its rest and its inner stop \
                 ({} rad) by at least 0.02 rad, or the jack cannot escape",
                p.jack.outer_stop_rad, p.jack.stop_angle_rad
            ),
        );
    }
}

/// One body's data for the plausibility checks.
struct Body<'a> {
    name: &'a str,
    what: &'a str,
    mass_g: f64,
    /// The pivot the inertia or the size is taken about.
    pivot: V,
    com: V,
    /// Inertia about the pivot (kg·m²).
    inertia_pivot: f64,
    /// Inertia about the centre of mass (kg·m²).
    inertia_com: f64,
    /// The inertia's field and whether it is given about the pivot.
    inertia_field: &'a str,
    about_pivot: bool,
    com_field: &'a str,
    /// Pivots and contact points of the part, with the radius of the round there.
    points: Vec<(V, f64)>,
}

/// Masses, radii of gyration and centres of mass.
fn bodies(p: &ActionParams, r: &mut Report) {
    let (k, w, j, l, h) = (&p.key, &p.wippen, &p.jack, &p.repetition_lever, &p.hammer);
    let s = Shapes::new(p);
    let from_pivot = |m_g: f64, com: V, pivot: V| {
        mbs_core::Inertia::parallel_axis(m_g * 1e-3, scale(sub(com, pivot), 1e-3))
    };
    let face_ends = |f: Face| [(f.a, 0.0), (f.b, 0.0)];
    let rest = Pose::default();
    let bodies = [
        Body {
            name: "key",
            what: "key",
            mass_g: k.mass_g,
            pivot: k.pivot_mm,
            com: k.com_mm,
            inertia_pivot: k.inertia_pivot_kg_m2,
            inertia_com: k.inertia_pivot_kg_m2 - from_pivot(k.mass_g, k.com_mm, k.pivot_mm),
            inertia_field: "key.inertia_pivot_kg_m2",
            about_pivot: true,
            com_field: "key.com_mm",
            points: [
                (k.pivot_mm, 0.0),
                (k.finger_mm, 0.0),
                (k.capstan_center_mm, k.capstan_radius_mm),
                (k.front_pad_mm, k.front_pad_radius_mm),
                (k.back_pad_mm, k.back_pad_radius_mm),
                (k.backcheck_mm, k.backcheck_half_length_mm),
            ]
            .to_vec(),
        },
        Body {
            name: "wippen",
            what: "wippen",
            mass_g: w.mass_g,
            pivot: w.pivot_mm,
            com: w.com_mm,
            inertia_pivot: w.inertia_com_kg_m2 + from_pivot(w.mass_g, w.com_mm, w.pivot_mm),
            inertia_com: w.inertia_com_kg_m2,
            inertia_field: "wippen.inertia_com_kg_m2",
            about_pivot: false,
            com_field: "wippen.com_mm",
            points: [
                (w.pivot_mm, 0.0),
                (w.heel_mm, w.heel_half_length_mm),
                (j.pivot_mm, 0.0),
                (l.pivot_mm, 0.0),
            ]
            .to_vec(),
        },
        Body {
            name: "jack",
            what: "jack",
            mass_g: j.mass_g,
            pivot: j.pivot_mm,
            com: j.com_mm,
            inertia_pivot: j.inertia_pivot_kg_m2,
            inertia_com: j.inertia_pivot_kg_m2 - from_pivot(j.mass_g, j.com_mm, j.pivot_mm),
            inertia_field: "jack.inertia_pivot_kg_m2",
            about_pivot: true,
            com_field: "jack.com_mm",
            points: [(j.pivot_mm, 0.0), (j.toe_mm, j.toe_radius_mm)]
                .into_iter()
                .chain(face_ends(s.jack_top(rest)))
                .collect(),
        },
        Body {
            name: "repetition_lever",
            what: "repetition lever",
            mass_g: l.mass_g,
            pivot: l.pivot_mm,
            com: l.com_mm,
            inertia_pivot: l.inertia_pivot_kg_m2,
            inertia_com: l.inertia_pivot_kg_m2 - from_pivot(l.mass_g, l.com_mm, l.pivot_mm),
            inertia_field: "repetition_lever.inertia_pivot_kg_m2",
            about_pivot: true,
            com_field: "repetition_lever.com_mm",
            points: [(l.pivot_mm, 0.0), (l.tip_mm, l.tip_radius_mm)]
                .into_iter()
                .chain(face_ends(s.lever_top(rest)))
                .collect(),
        },
        Body {
            name: "hammer",
            what: "hammer with its shank",
            mass_g: h.mass_g,
            // In the shank frame: the pin at the origin.
            pivot: [0.0, 0.0],
            com: h.com_body_mm,
            inertia_pivot: h.inertia_com_kg_m2 + from_pivot(h.mass_g, h.com_body_mm, [0.0; 2]),
            inertia_com: h.inertia_com_kg_m2,
            inertia_field: "hammer.inertia_com_kg_m2",
            about_pivot: false,
            com_field: "hammer.com_body_mm",
            points: vec![
                ([0.0, 0.0], 0.0),
                (h.knuckle_body_mm, h.knuckle_radius_mm),
                (h.strike_body_mm, 0.0),
                (h.tail_body_mm, h.tail_radius_mm),
                (h.rest_body_mm, 0.0),
            ],
        },
    ];
    for b in &bodies {
        body(b, r);
    }
}

/// The checks of one body.
fn body(b: &Body, r: &mut Report) {
    let Some(&(_, lo, hi)) = MASS_G.iter().find(|(n, _, _)| *n == b.name) else {
        return;
    };
    let mass_field = format!("{}.mass_g", b.name);
    // The hammer's points are in its shank frame.
    let frame = if b.name == "hammer" {
        " (shank frame: x along the shank from the centre pin)"
    } else {
        ""
    };
    // Centre of mass: inside the box around the part's points.
    let (mut x0, mut y0, mut x1, mut y1) = (f64::MAX, f64::MAX, f64::MIN, f64::MIN);
    for &(q, _) in &b.points {
        x0 = x0.min(q[0]);
        y0 = y0.min(q[1]);
        x1 = x1.max(q[0]);
        y1 = y1.max(q[1]);
    }
    let m = COM_MARGIN_MM;
    let com_on_part =
        b.com[0] >= x0 - m && b.com[0] <= x1 + m && b.com[1] >= y0 - m && b.com[1] <= y1 + m;
    if !com_on_part {
        r.push(
            b.com_field,
            format!(
                "the centre of mass of the {} ({:.1}, {:.1}) mm{frame} lies off the part: its \
                 pivots and contact points span x {x0:.0} to {x1:.0} and y {y0:.0} to {y1:.0} \
                 mm ({m} mm margin accepted)",
                b.what, b.com[0], b.com[1]
            ),
        );
    }
    if !(lo..=hi).contains(&b.mass_g) {
        r.push(
            &mass_field,
            format!(
                "the {} weighs {} g: in a grand action it weighs {lo}–{hi} g (a generous \
                 margin around the literature); check the value and its unit (grams)",
                b.what, b.mass_g
            ),
        );
    }
    // The inertia checks divide by the mass and use the centre of mass: judge them only
    // when both are plausible.
    if !(lo..=hi).contains(&b.mass_g) || !com_on_part {
        return;
    }
    let mass = b.mass_g * 1e-3;
    let size_pivot = b
        .points
        .iter()
        .map(|&(q, rad)| norm(sub(q, b.pivot)) + rad)
        .fold(0.0, f64::max);
    let size_com = b
        .points
        .iter()
        .map(|&(q, rad)| norm(sub(q, b.com)) + rad)
        .fold(0.0, f64::max);
    let reference = if b.about_pivot {
        "its pivot"
    } else {
        "its centre of mass"
    };
    let given = if b.about_pivot {
        b.inertia_pivot
    } else {
        b.inertia_com
    };
    if b.about_pivot && b.inertia_com <= 0.0 {
        r.push(
            b.inertia_field,
            format!(
                "the inertia of the {} about its pivot ({given:.3e} kg·m²) is not more than its \
                 mass times the squared distance from the pivot to its centre of mass \
                 ({:.3e} kg·m²): no rigid part has that (parallel-axis theorem); the value \
                 is about the pivot, not the centre of mass",
                b.what,
                given - b.inertia_com
            ),
        );
        return;
    }
    // Radius of gyration about the pivot: k = sqrt(I_pivot / m) (mm).
    let k_pivot = (b.inertia_pivot / mass).sqrt() * 1e3;
    if k_pivot > GYRATION_MAX_FRACTION * size_pivot {
        r.push(
            b.inertia_field,
            format!(
                "the inertia of the {} ({given:.3e} kg·m² about {reference}) gives a radius of \
                 gyration of {k_pivot:.0} mm about its pivot, longer than the part itself \
                 ({size_pivot:.0} mm from the pivot to its farthest point): check the value \
                 and its unit (kg·m²)",
                b.what
            ),
        );
        return;
    }
    let k_com = (b.inertia_com.max(0.0) / mass).sqrt() * 1e3;
    if k_com < GYRATION_MIN_FRACTION * size_com {
        r.push(
            b.inertia_field,
            format!(
                "the inertia of the {} ({given:.3e} kg·m² about {reference}) gives a radius of \
                 gyration of only {k_com:.1} mm about its centre of mass, for a part \
                 reaching {size_com:.0} mm from it: its mass could not be spread along the \
                 part (a slender rod's is 0.58 of its half length); check the value and its \
                 unit (kg·m²)",
                b.what
            ),
        );
    }
}

/// The lever chain's ratios, linearised at rest.
#[derive(Clone, Copy, Debug)]
struct Chain {
    /// Wippen rotation per key rotation (negative: the wippen rises).
    wippen_per_key: f64,
}

/// The key, wippen, jack and hammer each on the right side of their pivots, so that
/// pressing the key lifts the hammer. Returns the ratios when the chain is sound.
fn chain(p: &ActionParams, s: &Shapes, r: &mut Report) -> Option<Chain> {
    let before = r.0.len();
    let (k, w) = (&p.key, &p.wippen);
    let kx = k.pivot_mm[0];
    let m = SIDE_MARGIN_MM;
    if k.finger_mm[0] > kx - m {
        r.push(
            "key.finger_mm",
            format!(
                "the key front (x = {} mm, where the finger presses) is not in front of the \
                 balance pivot (x = {kx} mm): the finger must press toward the player's end \
                 (smaller x) so that the key's back end rises",
                k.finger_mm[0]
            ),
        );
    }
    // The wippen hangs from the action's rail above the key, its heel on the capstan.
    let key_top = k.finger_mm[1];
    if w.pivot_mm[1] < key_top + m {
        r.push(
            "wippen.pivot_mm",
            format!(
                "the wippen's flange pin (y = {} mm) is not above the key, whose top is at y = \
                 {key_top} mm: the wippen hangs from the action rail over the key, its heel \
                 resting on the capstan; raise wippen.pivot_mm",
                w.pivot_mm[1]
            ),
        );
    }
    let (capstan, _) = s.capstan(Pose::default());
    let finger_arm = kx - k.finger_mm[0];
    if capstan[0] < kx + m {
        r.push(
            "key.capstan_center_mm",
            format!(
                "the capstan (x = {} mm) is not behind the balance pivot (x = {kx} mm): \
                 pressing the key would lower it instead of lifting the wippen; the capstan \
                 sits on the key's back half (key ratio 0.45–0.58)",
                capstan[0]
            ),
        );
    } else if finger_arm > m {
        let ratio = (capstan[0] - kx) / finger_arm;
        if !(KEY_RATIO.0..=KEY_RATIO.1).contains(&ratio) {
            r.push(
                "key.capstan_center_mm",
                format!(
                    "the key ratio (capstan arm {:.0} mm over key front arm {finger_arm:.0} mm, \
                     both from the balance pivot) is {ratio:.2}: grand keys have 0.45–0.58 \
                     ({}–{} accepted), so the capstan, the balance pivot (key.pivot_mm) or the \
                     key front (key.finger_mm) is misplaced",
                    capstan[0] - kx,
                    KEY_RATIO.0,
                    KEY_RATIO.1
                ),
            );
        }
    }
    if k.front_pad_mm[0] > kx - m {
        r.push(
            "key.front_pad_mm",
            format!(
                "the key's front pad (x = {} mm) is not in front of the balance pivot \
                 (x = {kx} mm): the key front could never come down onto the front-rail \
                 punching",
                k.front_pad_mm[0]
            ),
        );
    }
    if k.back_pad_mm[0] < kx + m {
        r.push(
            "key.back_pad_mm",
            format!(
                "the key's back pad (x = {} mm) is not behind the balance pivot (x = {kx} \
                 mm): the key's tail could not rest on the back-rail cloth",
                k.back_pad_mm[0]
            ),
        );
    }
    if k.backcheck_mm[0] < kx + m {
        r.push(
            "key.backcheck_mm",
            format!(
                "the backcheck (x = {} mm) is not behind the balance pivot (x = {kx} mm): \
                 it stands on the key's tail, rising with it to catch the hammer",
                k.backcheck_mm[0]
            ),
        );
    }
    let wx = w.pivot_mm[0];
    if w.heel_mm[0] > wx - m {
        r.push(
            "wippen.heel_mm",
            format!(
                "the wippen heel (x = {} mm) is not in front of the wippen flange pin \
                 (x = {wx} mm): a grand wippen is pinned at the rear and lifted by the \
                 capstan in front of its pin",
                w.heel_mm[0]
            ),
        );
    }
    // The jack top's contact point: the knuckle centre projected on the top line.
    let rest = Pose::default();
    let (knuckle, _) = s.knuckle(rest);
    let j = &p.jack;
    let contact = add(j.top_mm, scale(s.t, dot(sub(knuckle, j.top_mm), s.t)));
    // Rise of the contact along the jack axis per radian of wippen rise:
    // v = ω × (P − W), ω = −1 (the wippen turns clockwise as it rises).
    let jack_rise = -cross(sub(contact, w.pivot_mm), s.n);
    if jack_rise < m {
        r.push(
            "jack.pivot_mm",
            format!(
                "the jack (top at x = {:.1} mm) is not in front of the wippen flange pin \
                 (x = {wx} mm): raising the wippen would not lift the jack into the knuckle",
                contact[0]
            ),
        );
    }
    // Torque arm of the jack's push on the knuckle about the hammer pin: (c − H) × n.
    let arm = cross(sub(knuckle, p.hammer.pivot_mm), s.n);
    if arm < KNUCKLE_ARM_MIN_MM {
        r.push(
            "hammer.knuckle_body_mm",
            format!(
                "the knuckle does not hang behind the hammer centre pin, toward the strings: \
                 the jack pushing it up would turn the hammer head with a lever arm of only \
                 {arm:.1} mm (the knuckle distance is 15.5–17 mm), or down if negative"
            ),
        );
    }
    if r.0.len() > before {
        return None;
    }
    // The capstan lifts the heel vertically: ω_w (C − W)_x = ω_k (C − K)_x.
    Some(Chain {
        wippen_per_key: (capstan[0] - kx) / (capstan[0] - wx),
    })
}

/// The key dip the front-rail punching allows (the lever chain being sound); returns the
/// key's reach (rad): the deepest plausible dip, or the allowed one if deeper, plus what a
/// hard blow forces.
fn key_dip(p: &ActionParams, s: &Shapes, r: &mut Report) -> Option<f64> {
    let (k, g) = (&p.key, &p.regulation);
    let finger_arm = k.pivot_mm[0] - k.finger_mm[0];
    let pad_arm = k.pivot_mm[0] - k.front_pad_mm[0];
    let rest = Pose::default();
    let (pad, pad_r) = s.front_pad(rest);
    let field = "regulation.front_rail_x_mm";
    if !covers(g.front_rail_x_mm, pad[0]) {
        r.push(
            field,
            format!(
                "the front-rail punching spans x = {} to {} mm, not under the key's front \
                 pad (x = {:.1} mm): the key front would go down past it with nothing to \
                 stop it; make it cover x = {:.1}",
                g.front_rail_x_mm[0], g.front_rail_x_mm[1], pad[0], pad[0]
            ),
        );
        return None;
    }
    // Room under the pad, scaled to the key front by the lever arms.
    let room = pad[1] - pad_r - g.front_rail_top_y_mm;
    let dip = room * finger_arm / pad_arm;
    let field = "regulation.front_rail_top_y_mm";
    let to_10 = |d: f64| (d - 10.0) * pad_arm / finger_arm;
    if room <= 0.0 {
        r.push(
            field,
            format!(
                "the front-rail punching (top y = {} mm) is not below the key's front pad \
                 (bottom y = {:.2} mm): the key front cannot go down at all; lower the \
                 punching by about {:.1} mm for a 10 mm key dip",
                g.front_rail_top_y_mm,
                pad[1] - pad_r,
                -to_10(dip)
            ),
        );
    } else if dip < DIP_MIN_MM {
        r.push(
            field,
            format!(
                "the front-rail punching leaves the key front only {dip:.1} mm to go down: a \
                 grand's key dip is about 10 mm ({DIP_MIN_MM}–{DIP_MAX_MM} accepted); lower \
                 the punching by about {:.1} mm",
                -to_10(dip)
            ),
        );
    } else if dip > DIP_MAX_MM {
        r.push(
            field,
            format!(
                "the front-rail punching lets the key front go down {dip:.1} mm: a grand's \
                 key dip is about 10 mm ({DIP_MIN_MM}–{DIP_MAX_MM} accepted); raise the \
                 punching by about {:.1} mm",
                to_10(dip)
            ),
        );
    }
    // The reach: dip ≈ finger arm × key angle.
    Some((dip.max(DIP_MAX_MM) + DIP_REACH_EXTRA_MM) / finger_arm)
}

/// The string: above the crown by a plausible blow distance, within the hammer's swing,
/// over the strike point. Returns the hammer's rotation from rest to the string (rad) when
/// all is well.
fn string(p: &ActionParams, s: &Shapes, r: &mut Report) -> Option<f64> {
    let g = &p.regulation;
    let field = "regulation.string_y_mm";
    let (crown, radius) = s.crown(Pose::default());
    let top = crown[1] + radius;
    let blow = g.string_y_mm - top;
    let suggest = top + 46.0;
    if blow <= 0.0 {
        r.push(
            field,
            format!(
                "the string (y = {} mm) is below the hammer crown at rest (y = {top:.1} mm): \
                 the hammer would start inside the string; raise regulation.string_y_mm \
                 above the crown, to about {suggest:.1} mm for a 46 mm blow distance",
                g.string_y_mm
            ),
        );
        return None;
    }
    if blow < BLOW_MM.0 || blow > BLOW_MM.1 {
        let (only, fix) = if blow < BLOW_MM.0 {
            ("only ", "raise")
        } else {
            ("", "lower")
        };
        r.push(
            field,
            format!(
                "the string (y = {} mm) is {only}{blow:.1} mm above the hammer crown at rest: \
                 a grand's blow distance is 44–48 mm when regulated ({}–{} accepted); {fix} \
                 regulation.string_y_mm to about {suggest:.1} mm",
                g.string_y_mm, BLOW_MM.0, BLOW_MM.1
            ),
        );
        return None;
    }
    // Turn the hammer up in quarter degrees until the crown meets the string.
    let string = ground(g.string_y_mm, g.string_x_mm, false);
    let steps = (SWING_MAX_DEG * 4.0) as usize;
    let mut nearest = f64::MAX;
    for i in 0..=steps {
        let angle = (i as f64 * 0.25).to_radians();
        let (c, rad) = s.crown(Pose {
            hammer: angle,
            ..Pose::default()
        });
        let gap = string.gap(c, rad);
        nearest = nearest.min(gap);
        if gap <= 0.0 {
            if !covers(g.string_x_mm, c[0]) {
                r.push(
                    "regulation.string_x_mm",
                    format!(
                        "the hammer meets the string at x = {:.1} mm, outside the string's \
                         extent (x = {} to {} mm): it would strike the string's end or miss \
                         it; make regulation.string_x_mm cover x = {:.1}",
                        c[0], g.string_x_mm[0], g.string_x_mm[1], c[0]
                    ),
                );
                return None;
            }
            return Some(angle);
        }
    }
    r.push(
        field,
        format!(
            "the hammer cannot reach the string: turned {SWING_MAX_DEG}° up from rest, its \
             crown still misses it by {nearest:.1} mm; lower regulation.string_y_mm, or \
             check regulation.string_x_mm and hammer.strike_body_mm"
        ),
    );
    None
}

/// How far the key can move the parts, when the lever chain is sound.
#[derive(Clone, Copy, Debug)]
struct Reach {
    /// Key-front travel (mm).
    dip_mm: f64,
    /// Key angle (rad).
    key: f64,
    /// The key at its reach, everything else at rest.
    key_down: Pose,
    /// The key at its reach with the wippen lifted by it.
    wippen_up: Pose,
}

impl Reach {
    fn new(p: &ActionParams, chain: Chain, key: f64) -> Reach {
        Reach {
            dip_mm: key * (p.key.pivot_mm[0] - p.key.finger_mm[0]),
            key,
            key_down: Pose {
                key,
                ..Pose::default()
            },
            wippen_up: Pose {
                key,
                wippen: chain.wippen_per_key * key,
                hammer: 0.0,
            },
        }
    }
}

/// "rises only 3.2 mm", or that it does not come closer.
fn rises(rise: f64) -> String {
    if rise > 0.05 {
        format!("rises only {rise:.1} mm")
    } else {
        "does not rise toward it".to_string()
    }
}

/// A contact pair, at rest and through the key's reach.
struct Pair<'a> {
    /// The field to change for this pair.
    field: &'a str,
    /// Gap at rest (mm).
    rest: f64,
    /// Gap with the key at its reach (mm), when the chain gives the reach: to the face's
    /// line, since the generous reach may carry a part past the end of a face that covers
    /// it at rest (the extents are checked at rest).
    reach: Option<f64>,
    /// What an overlap means: "the X is d mm into the Y at rest: <consequence>; <fix>".
    inside: String,
    /// What an unreachable gap means, given the gap and how much the reach closes it.
    apart: &'a dyn Fn(f64, f64) -> String,
}

/// Reports a pair deep inside itself at rest, or apart and not brought together by the
/// reach.
fn judge(pair: Pair, r: &mut Report) {
    if pair.rest < -PENETRATION_MAX_MM {
        r.push(pair.field, pair.inside);
    } else if let Some(reach) = pair.reach
        && pair.rest > 0.0
        && reach > 0.0
    {
        r.push(pair.field, (pair.apart)(pair.rest, pair.rest - reach));
    }
}

/// Whether each contact pair is over its partner, not deep inside it at rest, and able to
/// meet it within the key's reach.
fn pairs(p: &ActionParams, s: &Shapes, reach: Option<Reach>, swing: Option<f64>, r: &mut Report) {
    back_rail(p, s, r);
    capstan_heel(p, s, reach, r);
    knuckle_rests(p, s, reach, r);
    screws(p, s, reach, r);
    backcheck(p, s, reach, swing, r);
    rest_rail(p, s, r);
}

/// The key's tail rests on the back-rail cloth.
fn back_rail(p: &ActionParams, s: &Shapes, r: &mut Report) {
    let g = &p.regulation;
    let (pad, pad_r) = s.back_pad(Pose::default());
    if !covers(g.back_rail_x_mm, pad[0]) {
        r.push(
            "regulation.back_rail_x_mm",
            format!(
                "the back-rail cloth spans x = {} to {} mm, not under the key's back pad \
                 (x = {:.1} mm): the key's tail would have nothing to rest on",
                g.back_rail_x_mm[0], g.back_rail_x_mm[1], pad[0]
            ),
        );
        return;
    }
    let gap = ground(g.back_rail_top_y_mm, g.back_rail_x_mm, true).gap(pad, pad_r);
    let field = "regulation.back_rail_top_y_mm";
    let bottom = pad[1] - pad_r;
    if gap < -PENETRATION_MAX_MM {
        r.push(
            field,
            format!(
                "the back-rail cloth is {:.1} mm up into the key's back pad at rest: it would \
                 hold the key's tail up and its front down; lower \
                 regulation.back_rail_top_y_mm to touch the pad (y = {bottom:.1} mm)",
                -gap
            ),
        );
    } else if gap > BACK_RAIL_GAP_MAX_MM {
        r.push(
            field,
            format!(
                "the back-rail cloth is {gap:.1} mm below the key's back pad: at rest the key \
                 would tip back that far before its tail lands, lifting the key front and \
                 dropping the capstan away from the wippen; raise \
                 regulation.back_rail_top_y_mm to touch the pad (y = {bottom:.1} mm)"
            ),
        );
    }
}

/// The capstan under the wippen heel, lifting it within the key's reach.
fn capstan_heel(p: &ActionParams, s: &Shapes, reach: Option<Reach>, r: &mut Report) {
    let (w, g) = (&p.wippen, &p.regulation);
    let rest = Pose::default();
    let (capstan, capstan_r) = s.capstan(rest);
    let heel = [
        w.heel_mm[0] - w.heel_half_length_mm,
        w.heel_mm[0] + w.heel_half_length_mm,
    ];
    if !covers(heel, capstan[0]) {
        r.push(
            "key.capstan_center_mm",
            format!(
                "the capstan (x = {:.1} mm) is not under the wippen heel (x = {:.1} to {:.1} \
                 mm): it would lift nothing; move key.capstan_center_mm or wippen.heel_mm so \
                 that the heel lies over the capstan",
                capstan[0], heel[0], heel[1]
            ),
        );
        return;
    }
    let dip = reach.map_or(0.0, |q| q.dip_mm);
    judge(
        Pair {
            field: if g.capstan_raise_mm.abs() > SCREW_RANGE_MM {
                "regulation.capstan_raise_mm"
            } else {
                "key.capstan_center_mm"
            },
            rest: s.heel(rest).gap(capstan, capstan_r),
            reach: reach.map(|q| {
                let (c, cr) = s.capstan(q.key_down);
                s.heel(rest).line_gap(c, cr)
            }),
            inside: format!(
                "the capstan is {:.1} mm up inside the wippen heel at rest: the wippen, and \
                 with it the hammer, would be forced up toward the string; lower the capstan \
                 (regulation.capstan_raise_mm or key.capstan_center_mm)",
                -s.heel(rest).gap(capstan, capstan_r)
            ),
            apart: &|gap, rise| {
                format!(
                    "the capstan is {gap:.1} mm below the wippen heel at rest and {} through \
                     the deepest key dip ({dip:.0} mm): the key would never lift the wippen, \
                     and the hammer would not move; raise the capstan by about {gap:.1} mm \
                     (regulation.capstan_raise_mm or key.capstan_center_mm)",
                    rises(rise)
                )
            },
        },
        r,
    );
}

/// The jack top and the repetition lever top under the knuckle, lifting it within the
/// key's reach.
fn knuckle_rests(p: &ActionParams, s: &Shapes, reach: Option<Reach>, r: &mut Report) {
    let (j, l) = (&p.jack, &p.repetition_lever);
    let rest = Pose::default();
    let (knuckle, knuckle_r) = s.knuckle(rest);
    let dip = reach.map_or(0.0, |q| q.dip_mm);
    let jack = Top {
        field: "jack.top_mm",
        what: "jack",
        top: j.top_mm,
        front: j.top_front_edge_mm,
        back: j.top_back_edge_mm,
        face: s.jack_top(rest),
        lifted: reach.map(|q| s.jack_top(q.wippen_up)),
        never: "the jack would never lift the hammer",
    };
    let lever = Top {
        field: "repetition_lever.top_mm",
        what: "repetition lever",
        top: l.top_mm,
        front: l.top_front_edge_mm,
        back: l.top_back_edge_mm,
        face: s.lever_top(rest),
        lifted: reach.map(|q| s.lever_top(q.wippen_up)),
        never: "the lever would never hold the hammer up after let-off (no drop, no \
                repetition)",
    };
    for t in [jack, lever] {
        let (field, what) = (t.field, t.what);
        let along = dot(sub(knuckle, t.top), s.t);
        if along > t.back + COVER_TOL_MM || along < -t.front - COVER_TOL_MM {
            let side = if along > t.back {
                "behind"
            } else {
                "in front of"
            };
            let note = if what == "jack" && along > t.back {
                "; the jack would already be out from under the knuckle"
            } else {
                ""
            };
            r.push(
                field,
                format!(
                    "the knuckle rests {:.1} mm {side} the {what} top's contact point, off its \
                     top (which runs {} mm in front of and {} mm behind that point){note}: \
                     move {field} under the knuckle",
                    along.abs(),
                    t.front,
                    t.back
                ),
            );
            continue;
        }
        let gap = t.face.gap(knuckle, knuckle_r);
        judge(
            Pair {
                field,
                rest: gap,
                reach: t.lifted.map(|f| f.line_gap(knuckle, knuckle_r)),
                inside: format!(
                    "the knuckle sits {:.1} mm inside the {what} top at rest: the {what} would \
                     be jammed into it; lower {field} to touch the knuckle's underside (or \
                     check hammer.knuckle_body_mm)",
                    -gap
                ),
                apart: &|gap, rise| {
                    format!(
                        "the {what} top is {gap:.1} mm below the knuckle at rest and {} \
                         through the deepest key dip ({dip:.0} mm): {}; raise {field} to \
                         touch the knuckle",
                        rises(rise),
                        t.never
                    )
                },
            },
            r,
        );
    }
}

/// A top face under the knuckle.
struct Top<'a> {
    field: &'a str,
    what: &'a str,
    /// The contact point at rest.
    top: V,
    /// Length of the face in front of and behind it (mm).
    front: f64,
    back: f64,
    face: Face,
    /// The face with the wippen lifted by the key's reach.
    lifted: Option<Face>,
    /// What an unreachable knuckle means.
    never: &'a str,
}

/// A fixed screw over a part that the wippen lifts to it.
struct Screw<'a> {
    field: &'a str,
    x_field: &'a str,
    what: &'a str,
    part: &'a str,
    y: f64,
    x: [f64; 2],
    /// The part's round at rest and lifted by the key's reach.
    round: (V, f64),
    lifted: Option<(V, f64)>,
    inside: &'a str,
    never: &'a str,
    hint: &'a str,
}

/// The let-off button over the jack toe and the drop screw over the repetition lever tip.
fn screws(p: &ActionParams, s: &Shapes, reach: Option<Reach>, r: &mut Report) {
    let g = &p.regulation;
    let rest = Pose::default();
    let dip = reach.map_or(0.0, |q| q.dip_mm);
    let button = Screw {
        field: "regulation.let_off_button_y_mm",
        x_field: "regulation.let_off_button_x_mm",
        what: "let-off button",
        part: "jack toe",
        y: g.let_off_button_y_mm,
        x: g.let_off_button_x_mm,
        round: s.toe(rest),
        lifted: reach.map(|q| s.toe(q.wippen_up)),
        inside: "the jack would be tripped from under the knuckle before the key moves, and \
                 no blow is possible",
        never: "the jack would never escape, and the hammer would block against the string",
        hint: "a regulated button sits about 6 mm above the toe at rest",
    };
    let drop = Screw {
        field: "regulation.drop_screw_y_mm",
        x_field: "regulation.drop_screw_x_mm",
        what: "drop screw",
        part: "repetition lever tip",
        y: g.drop_screw_y_mm,
        x: g.drop_screw_x_mm,
        round: s.tip(rest),
        lifted: reach.map(|q| s.tip(q.wippen_up)),
        inside: "it would push the repetition lever down off the knuckle",
        never: "the repetition lever would never be stopped and would throw the hammer back \
                to the string after let-off (no drop)",
        hint: "a regulated drop screw sits about 5.5 mm above the tip at rest",
    };
    for sc in [button, drop] {
        let (field, what, part, y) = (sc.field, sc.what, sc.part, sc.y);
        let (c, cr) = sc.round;
        if !covers(sc.x, c[0]) {
            r.push(
                sc.x_field,
                format!(
                    "the {what} spans x = {} to {} mm, not over the {part} (x = {:.1} mm): the \
                     {part} would pass beside it; make {} cover x = {:.1}",
                    sc.x[0], sc.x[1], c[0], sc.x_field, c[0]
                ),
            );
            continue;
        }
        let face = ground(y, sc.x, false);
        let gap = face.gap(c, cr);
        judge(
            Pair {
                field,
                rest: gap,
                reach: sc.lifted.map(|(c, cr)| face.line_gap(c, cr)),
                inside: format!(
                    "the {what} (y = {y} mm) is {:.1} mm down into the {part} at rest: {}; \
                     raise {field} ({})",
                    -gap, sc.inside, sc.hint
                ),
                apart: &|gap, rise| {
                    format!(
                        "the {what} (y = {y} mm) is {gap:.1} mm above the {part}, which {} \
                         through the deepest key dip ({dip:.0} mm): {}; lower {field} ({})",
                        rises(rise),
                        sc.never,
                        sc.hint
                    )
                },
            },
            r,
        );
    }
}

/// The backcheck clear of the hammer tail at rest, and meeting it somewhere between the
/// hammer at rest and at the string (`swing`, rad) with the key anywhere in its reach.
fn backcheck(
    p: &ActionParams,
    s: &Shapes,
    reach: Option<Reach>,
    swing: Option<f64>,
    r: &mut Report,
) {
    let field = if p.regulation.backcheck_offset_mm.abs() > SCREW_RANGE_MM {
        "regulation.backcheck_offset_mm"
    } else {
        "key.backcheck_mm"
    };
    let rest = Pose::default();
    let (tail, tail_r) = s.tail(rest);
    let gap = s.backcheck(rest).gap(tail, tail_r);
    if gap < -PENETRATION_MAX_MM {
        r.push(
            field,
            format!(
                "the backcheck is {:.1} mm into the hammer tail at rest: it would hold the \
                 hammer before it could rise; move the backcheck away from the tail \
                 (key.backcheck_mm, or regulation.backcheck_offset_mm)",
                -gap
            ),
        );
        return;
    }
    let Some(reach) = reach else {
        return;
    };
    // Without a sound string, scan the whole swing the string check allows. Steps of
    // about 1 mm at the backcheck and at the tail; the face is one-sided, so a tail far
    // behind it has a large negative gap and does not touch it: the nearest |gap| counts.
    let swing = swing.unwrap_or(SWING_MAX_DEG.to_radians());
    let (nk, nh) = (16, ((swing.to_degrees() * 2.0).ceil() as usize).max(1));
    let mut nearest = f64::MAX;
    for a in 0..=nk {
        let key = reach.key * a as f64 / nk as f64;
        let face = s.backcheck(Pose { key, ..rest });
        for b in 0..=nh {
            let hammer = swing * b as f64 / nh as f64;
            let (c, cr) = s.tail(Pose { hammer, ..rest });
            nearest = nearest.min(face.gap(c, cr).abs());
        }
    }
    if nearest > BACKCHECK_MEET_MM {
        r.push(
            field,
            format!(
                "the backcheck never comes within {nearest:.1} mm of the hammer tail, with the \
                 key anywhere in its dip ({:.0} mm) and the hammer anywhere between rest and \
                 the string: the falling hammer would not be checked and would bounce back to \
                 the string; move key.backcheck_mm toward the tail's path (or check \
                 hammer.tail_body_mm and regulation.backcheck_offset_mm)",
                reach.dip_mm
            ),
        );
    }
}

/// The rest-rail cushion under the shank.
fn rest_rail(p: &ActionParams, s: &Shapes, r: &mut Report) {
    let g = &p.regulation;
    let (shank, shank_r) = s.shank(Pose::default());
    if !covers(g.rest_rail_x_mm, shank[0]) {
        r.push(
            "regulation.rest_rail_x_mm",
            format!(
                "the rest-rail cushion spans x = {} to {} mm, not under the shank (x = {:.1} \
                 mm): the hammer would have nothing to rest on; make it cover x = {:.1}",
                g.rest_rail_x_mm[0], g.rest_rail_x_mm[1], shank[0], shank[0]
            ),
        );
        return;
    }
    let gap = ground(g.rest_rail_top_y_mm, g.rest_rail_x_mm, true).gap(shank, shank_r);
    let field = "regulation.rest_rail_top_y_mm";
    let regulated = shank[1] - shank_r - REST_RAIL_CLEARANCE_MM;
    if gap < -PENETRATION_MAX_MM {
        r.push(
            field,
            format!(
                "the rest-rail cushion is {:.1} mm above the shank's underside at rest: it \
                 would hold the hammer up off the jack; lower regulation.rest_rail_top_y_mm \
                 to about {regulated:.1} mm (1/8 inch under the shank)",
                -gap
            ),
        );
    } else if gap > REST_RAIL_GAP_MAX_MM {
        r.push(
            field,
            format!(
                "the rest-rail cushion is {gap:.1} mm below the shank at rest: the hammer \
                 would never land on it (regulated 1/8 inch; 1/2 inch already spoils \
                 repetition); raise regulation.rest_rail_top_y_mm to about {regulated:.1} mm"
            ),
        );
    }
}

#[cfg(test)]
mod drift {
    //! The checker keeps its own plane copy of the contact shapes: these tests hold it to
    //! the shapes `Action::build` makes, so the two cannot drift apart unseen.
    use super::*;
    use crate::{Action, ModelKind};

    /// The checker's gap of each contact at `pose` (mm).
    fn checker_gaps(p: &ActionParams, pose: Pose) -> Vec<(&'static str, f64)> {
        let s = Shapes::new(p);
        let g = &p.regulation;
        let on_ground = |y, x, up, (c, r): (V, f64)| ground(y, x, up).gap(c, r);
        vec![
            (
                "front_rail",
                on_ground(
                    g.front_rail_top_y_mm,
                    g.front_rail_x_mm,
                    true,
                    s.front_pad(pose),
                ),
            ),
            (
                "back_rail",
                on_ground(
                    g.back_rail_top_y_mm,
                    g.back_rail_x_mm,
                    true,
                    s.back_pad(pose),
                ),
            ),
            ("capstan_heel", {
                let (c, r) = s.capstan(pose);
                s.heel(pose).gap(c, r)
            }),
            ("jack_knuckle", {
                let (c, r) = s.knuckle(pose);
                s.jack_top(pose).gap(c, r)
            }),
            ("lever_knuckle", {
                let (c, r) = s.knuckle(pose);
                s.lever_top(pose).gap(c, r)
            }),
            (
                "let_off_button",
                on_ground(
                    g.let_off_button_y_mm,
                    g.let_off_button_x_mm,
                    false,
                    s.toe(pose),
                ),
            ),
            (
                "drop_screw",
                on_ground(g.drop_screw_y_mm, g.drop_screw_x_mm, false, s.tip(pose)),
            ),
            ("backcheck", {
                let (c, r) = s.tail(pose);
                s.backcheck(pose).gap(c, r)
            }),
            (
                "rest_rail",
                on_ground(g.rest_rail_top_y_mm, g.rest_rail_x_mm, true, s.shank(pose)),
            ),
            (
                "hammer_string",
                on_ground(g.string_y_mm, g.string_x_mm, false, s.crown(pose)),
            ),
        ]
    }

    fn compare(p: &ActionParams, pose: Pose) {
        let action = Action::build(p, ModelKind::Double).unwrap();
        let model = action.system.model().clone();
        let mut x = action.layout_state().unwrap();
        for (name, q) in [
            ("key", pose.key),
            ("wippen", pose.wippen),
            ("hammer", pose.hammer),
        ] {
            x[model.coordinate_id(name).unwrap()] = q;
        }
        for (name, ours) in checker_gaps(p, pose) {
            let built = action.gap(name, 0.0, &x).unwrap() * 1e3;
            // 1 µm: the checker's thresholds are millimetres; it normalises the file's jack
            // axis (length 1.0005), which moves the turned jack top by some 0.03 µm.
            assert!(
                (ours - built).abs() < 1e-3,
                "{name} at {pose:?}: checker {ours} mm, action {built} mm"
            );
        }
    }

    #[test]
    fn the_checker_sees_the_gaps_the_built_action_has() {
        let reference = ActionParams::reference();
        for pose in [
            Pose::default(),
            Pose {
                key: -0.02,
                wippen: 0.03,
                hammer: 0.2,
            },
        ] {
            compare(&reference, pose);
            let mut p = reference.clone();
            p.regulation.capstan_raise_mm = 1.5;
            p.regulation.backcheck_offset_mm = -1.0;
            p.regulation.string_y_mm += 3.0;
            compare(&p, pose);
        }
    }
}
