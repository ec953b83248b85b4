//! To-scale drawings of the action as SVG, the way a piano technician sees it from the side:
//! the key along the bottom on its key frame, the wippen over the key's back half, the jack
//! under the hammer knuckle, the repetition lever, the hammer with its shank toward the
//! string, and the fixed parts (rails, let-off button, drop screw, rest rail, string).
//!
//! Every outline is built from the parameters in their rest place and carried by its body's
//! world pose at `(t, x)`, as the system computes it (a prescribed coordinate takes its
//! drive's value). Over the outlines, thin lines show the contact shapes the simulation
//! actually uses, and a red dot marks each contact that is pressed (gap < 0). The drawing is
//! in millimetres, one SVG unit to the millimetre, with a 10 mm scale bar.
//!
//! ```
//! use piano_action::{Action, ActionParams, ModelKind, drawing::action_svg};
//! let action = Action::build(&ActionParams::reference(), ModelKind::Double)?;
//! let svg = action_svg(&action, 0.0, &action.layout_state()?, "double escapement at rest")?;
//! assert!(svg.starts_with("<svg") && svg.contains(r#"id="body-hammer""#));
//! # Ok::<(), piano_action::PianoError>(())
//! ```

use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::fmt::Write;

use mbs_contact::Shape;
use mbs_core::{CoreError, Data, Transform, frame_pose, update_poses};
use mbs_mechanism::{Built, Mechanism, OutlinePart};

use crate::action::{Action, ContactElement, PRESSER_PAD_RADIUS_MM, Presser};
use crate::error::Result;
use crate::params::ActionParams;

/// Blank space around the action's outline on every side of the drawing (mm).
pub const MARGIN_MM: f64 = 12.0;

/// Length of the scale bar (mm).
pub const SCALE_BAR_MM: f64 = 10.0;

// Drawing-only dimensions (mm): what the parameters do not fix, chosen to look like a real
// grand action. None of them affects the simulation.
/// Key front in front of the finger point.
const KEY_FRONT_LIP: f64 = 5.0;
/// Key tail behind the back-rail pad.
const KEY_TAIL: f64 = 10.0;
/// Length and thickness of the key covering (natural keytop).
const KEYTOP: [f64; 2] = [145.0, 2.0];
/// Height of the key-frame rails under their felt.
const RAIL_HEIGHT: f64 = 22.0;
/// Felt punchings and cloths on the rails.
const FELT: f64 = 2.0;
/// Half thickness of the wippen body.
const WIPPEN_HALF: f64 = 5.0;
/// Hammer shank diameter (Ellis: 6.1–6.6 mm knuckle stock).
const SHANK: f64 = 6.4;
/// Backcheck head thickness behind its face.
const BACKCHECK_THICK: f64 = 5.0;
/// Width of the hammer moulding along the shank, in front of its back line.
const HEAD_WIDTH: f64 = 12.0;
/// Space kept between the hammer felt and the backcheck under it at rest.
const HEAD_CLEARANCE: f64 = 1.0;
/// Space above the action for the title, and below it for the legend.
const TITLE_SPACE: f64 = 12.0;
const LEGEND_SPACE: f64 = 16.0;

/// Fill colours: muted, one per body.
const KEY_FILL: &str = "#dccaa4";
const KEYTOP_FILL: &str = "#f6f3ea";
const WIPPEN_FILL: &str = "#b9c9a4";
const JACK_FILL: &str = "#cfa7a2";
const LEVER_FILL: &str = "#a6b8cc";
const SHANK_FILL: &str = "#e0cfa8";
const MOLDING_FILL: &str = "#b89c74";
const HAMMER_FELT_FILL: &str = "#efe9da";
const BUCKSKIN_FILL: &str = "#a88d6c";
const RAIL_FILL: &str = "#c9c5bd";
const FELT_FILL: &str = "#8aa37a";
const CLOTH_FILL: &str = "#b46a6a";
const METAL_FILL: &str = "#9a9a9a";
const BRASS_FILL: &str = "#c8a85a";
const FINGER_FILL: &str = "#e7b99c";
const FINGER_NAIL_FILL: &str = "#f3e4dc";
const BRACKET_FILL: &str = "#eeece7";
/// The finger's last joint: its tilt from the key top toward the player, and half width.
const FINGER_TILT_DEG: f64 = 62.0;
const FINGER_HALF_WIDTH: f64 = 7.0;
const CONTACT_STROKE: &str = "#1f4e9c";
const ACTIVE_FILL: &str = "#d62020";

type P = [f64; 2];

fn add(a: P, b: P) -> P {
    [a[0] + b[0], a[1] + b[1]]
}

fn sub(a: P, b: P) -> P {
    [a[0] - b[0], a[1] - b[1]]
}

fn mul(a: P, s: f64) -> P {
    [a[0] * s, a[1] * s]
}

/// `a` normalised, or `fallback` when it has no length.
fn unit(a: P, fallback: P) -> P {
    let n = a[0].hypot(a[1]);
    if n > 1e-9 { mul(a, 1.0 / n) } else { fallback }
}

/// Points on the circle `(c, r)` from angle `a0` to `a1` (rad, either direction).
fn arc(c: P, r: f64, a0: f64, a1: f64) -> Vec<P> {
    let n = ((a1 - a0).abs() / (PI / 24.0)).ceil().max(2.0) as usize;
    (0..=n)
        .map(|i| {
            let a = a0 + (a1 - a0) * i as f64 / n as f64;
            [c[0] + r * a.cos(), c[1] + r * a.sin()]
        })
        .collect()
}

fn rect(x: [f64; 2], y: [f64; 2]) -> Vec<P> {
    vec![[x[0], y[0]], [x[1], y[0]], [x[1], y[1]], [x[0], y[1]]]
}

/// One filled outline.
#[derive(Clone, Debug)]
enum Outline {
    Polygon(Vec<P>),
    Circle(P, f64),
    /// A thick line (wire, screw shank): points and width.
    Wire(Vec<P>, f64),
}

/// A name written beside a part: the point it names (carried with the part), where the
/// text stands from it (mm, not turned), and which end of the text stands there.
#[derive(Clone, Debug)]
struct Label {
    anchor: P,
    offset: P,
    text: String,
    align: &'static str,
}

/// A drawn part: outlines in the rest layout (world mm), carried by one frame's motion
/// (`None`: fixed to the ground).
#[derive(Clone, Debug)]
struct Part {
    id: String,
    frame: Option<String>,
    pieces: Vec<(Outline, String)>,
    pivots: Vec<P>,
    labels: Vec<Label>,
    /// Seen through the action: a part in another plane (the action bracket stands between
    /// keys), drawn first, pale, with a dashed outline.
    behind: bool,
}

impl Part {
    fn new(id: &str, frame: Option<&str>) -> Self {
        Self {
            id: id.to_string(),
            frame: frame.map(str::to_string),
            pieces: Vec::new(),
            pivots: Vec::new(),
            labels: Vec::new(),
            behind: false,
        }
    }

    /// Names `anchor` with `text` written at `offset` from it (a leader line joins them when
    /// the offset is not zero); `align` is the SVG `text-anchor`.
    fn label(&mut self, anchor: P, offset: P, text: impl Into<String>, align: &'static str) {
        self.labels.push(Label {
            anchor,
            offset,
            text: text.into(),
            align,
        });
    }

    fn polygon(&mut self, pts: Vec<P>, fill: &str) {
        self.pieces.push((Outline::Polygon(pts), fill.to_string()));
    }

    fn circle(&mut self, c: P, r: f64, fill: &str) {
        self.pieces.push((Outline::Circle(c, r), fill.to_string()));
    }

    fn wire(&mut self, pts: Vec<P>, width: f64, fill: &str) {
        self.pieces
            .push((Outline::Wire(pts, width), fill.to_string()));
    }
}

/// The key: stick with keytop and balance pivot (the capstan is [`capstan_part`], the
/// backcheck [`backcheck_part`], drawn over the hammer).
fn key_part(action: &Action) -> Part {
    let k = &action.params.key;
    let mut part = Part::new("body-key", Some("key"));
    let bottom = k.pivot_mm[1];
    let top = k.finger_mm[1];
    let front = k.finger_mm[0] - KEY_FRONT_LIP;
    let back = k.back_pad_mm[0] + k.back_pad_radius_mm + KEY_TAIL;
    part.polygon(rect([front, back], [bottom, top]), KEY_FILL);
    part.polygon(
        rect([front - 0.5, front + KEYTOP[0]], [top, top + KEYTOP[1]]),
        KEYTOP_FILL,
    );
    part.pivots.push(k.pivot_mm);
    let mid = 0.5 * (bottom + top) - 1.0;
    part.label([front + 60.0, mid], [0.0, 0.0], "key", "middle");
    part
}

/// The capstan, standing on the key top: the model's head (a circle) where the model puts
/// it, down to the key top on a post of the head's width when the head stands higher than
/// its radius; when the head's centre is below the key top only its cap shows (it never
/// reaches into the key).
fn capstan_part(action: &Action) -> Part {
    let (k, g) = (&action.params.key, &action.params.regulation);
    let mut part = Part::new("key-capstan", Some("key"));
    let top = k.finger_mm[1];
    let c = [
        k.capstan_center_mm[0],
        k.capstan_center_mm[1] + g.capstan_raise_mm,
    ];
    let r = k.capstan_radius_mm;
    if c[1] >= top {
        let mut outline = vec![[c[0] - r, top], [c[0] + r, top]];
        outline.extend(arc(c, r, 0.0, PI));
        part.polygon(outline, BRASS_FILL);
    } else if c[1] + r > top {
        // The cap of the head above the key top, closed by the chord on it.
        let a0 = ((top - c[1]) / r).asin();
        part.polygon(arc(c, r, a0, PI - a0), BRASS_FILL);
    }
    let mid = 0.5 * (k.pivot_mm[1] + top) - 1.0;
    part.label([c[0], mid], [0.0, 0.0], "capstan", "middle");
    part
}

/// The backcheck's face as the model places it, in the layout (world mm, key at rest):
/// its lower and upper ends, and its outward normal (toward the hammer tail at rest).
struct BackcheckFace {
    lo: P,
    hi: P,
    n: P,
}

/// Thickness of the backcheck's leather (mm), drawn behind its face.
const BACKCHECK_LEATHER: f64 = 1.5;

impl BackcheckFace {
    /// Built as [`Action::build`] builds the contact: the face through the catch point at
    /// its angle, turned so the tail at rest lies on its outward side, moved along that
    /// normal by the regulation's offset.
    fn of(params: &ActionParams) -> Self {
        let (k, g, h) = (&params.key, &params.regulation, &params.hammer);
        let a = k.backcheck_face_angle_deg.to_radians();
        let mut d = [a.cos(), a.sin()];
        let (s, c) = h.rest_angle_deg.to_radians().sin_cos();
        let tb = h.tail_body_mm;
        let tail = [
            h.pivot_mm[0] + c * tb[0] - s * tb[1],
            h.pivot_mm[1] + s * tb[0] + c * tb[1],
        ];
        let to_tail = sub(tail, k.backcheck_mm);
        if -d[1] * to_tail[0] + d[0] * to_tail[1] < 0.0 {
            d = mul(d, -1.0);
        }
        let n = [-d[1], d[0]];
        let mid = add(k.backcheck_mm, mul(n, g.backcheck_offset_mm));
        let hl = k.backcheck_half_length_mm;
        let (a, b) = (sub(mid, mul(d, hl)), add(mid, mul(d, hl)));
        let (lo, hi) = if a[1] <= b[1] { (a, b) } else { (b, a) };
        Self { lo, hi, n }
    }

    /// The head behind the face: leather, then the wooden block.
    fn head(&self) -> [Vec<P>; 2] {
        let (lo, hi, n) = (self.lo, self.hi, self.n);
        let back = mul(n, -BACKCHECK_THICK);
        let leather = vec![
            lo,
            hi,
            sub(hi, mul(n, BACKCHECK_LEATHER)),
            sub(lo, mul(n, BACKCHECK_LEATHER)),
        ];
        let block = vec![
            sub(lo, mul(n, BACKCHECK_LEATHER)),
            sub(hi, mul(n, BACKCHECK_LEATHER)),
            add(hi, back),
            add(lo, back),
        ];
        [leather, block]
    }

    /// Where the wire leaves the head: under its lower end, behind the face.
    fn wire_foot(&self) -> P {
        add(self.lo, mul(self.n, -0.6 * BACKCHECK_THICK))
    }
}

/// The backcheck on the key: the head with its leather face where the model puts the face,
/// on a wire standing up from the key top.
fn backcheck_part(action: &Action) -> Part {
    let k = &action.params.key;
    let mut part = Part::new("key-backcheck", Some("key"));
    let face = BackcheckFace::of(&action.params);
    // The wire runs up into the head (drawn over it) from the key top.
    let foot = face.wire_foot();
    part.wire(
        vec![[foot[0], foot[1] + 1.5], [foot[0], k.finger_mm[1]]],
        1.2,
        METAL_FILL,
    );
    let [leather, block] = face.head();
    part.polygon(block, MOLDING_FILL);
    part.polygon(leather, BUCKSKIN_FILL);
    let corner = add(face.lo, mul(face.n, -BACKCHECK_THICK));
    part.label(corner, [12.0, -3.0], "backcheck", "start");
    part
}

/// The wippen: body from the jack centre to its flange, heel down onto the capstan, and the
/// repetition-lever post when there is a lever. In the simplified model the jack is part
/// of it.
fn wippen_part(action: &Action, jack_fixed: bool, with_lever: bool) -> Part {
    let p = &action.params;
    let (w, j, r) = (&p.wippen, &p.jack, &p.repetition_lever);
    let mut part = Part::new("body-wippen", Some("wippen"));
    let (jp, wp) = (j.pivot_mm, w.pivot_mm);
    let u = unit(sub(wp, jp), [1.0, 0.0]);
    let n = if u[0] >= 0.0 {
        [-u[1], u[0]]
    } else {
        [u[1], -u[0]]
    };
    let len = (wp[0] - jp[0]).hypot(wp[1] - jp[1]);
    let along = |q: P| (q[0] - jp[0]) * u[0] + (q[1] - jp[1]) * u[1];
    let top = |s: f64| add(add(jp, mul(u, s)), mul(n, WIPPEN_HALF));
    let bot = |s: f64| sub(add(jp, mul(u, s)), mul(n, WIPPEN_HALF));
    let heel = w.heel_mm;
    let hl = w.heel_half_length_mm;
    let s_heel = along(heel);
    let mut outline = vec![top(-6.0)];
    if with_lever {
        let rp = r.pivot_mm;
        let s_rp = along(rp);
        outline.extend([
            top(s_rp - 9.0),
            [rp[0] - 4.0, rp[1] + 4.0],
            [rp[0] + 4.0, rp[1] + 4.0],
            top(s_rp + 9.0),
        ]);
    }
    outline.extend([
        top(len + 7.0),
        bot(len + 7.0),
        bot(s_heel + hl + 2.0),
        [heel[0] + hl, heel[1] + 6.0],
        [heel[0] + hl, heel[1]],
        [heel[0] - hl, heel[1]],
        [heel[0] - hl, heel[1] + 6.0],
        bot(s_heel - hl - 2.0),
        bot(-6.0),
    ]);
    part.polygon(outline, WIPPEN_FILL);
    // Heel cushion.
    part.polygon(
        rect([heel[0] - hl, heel[0] + hl], [heel[1], heel[1] + FELT]),
        FELT_FILL,
    );
    if jack_fixed {
        part.polygon(jack_outline(action), WIPPEN_FILL);
    }
    part.pivots.push(wp);
    if with_lever {
        part.pivots.push(r.pivot_mm);
    }
    part.label([heel[0], heel[1] + 14.0], [0.0, 0.0], "wippen", "middle");
    part
}

/// The jack as an L: the upright along its axis with the top under the knuckle, the toe
/// (tender) reaching forward under the let-off button.
fn jack_outline(action: &Action) -> Vec<P> {
    let j = &action.params.jack;
    let n = unit(j.axis, [0.0, 1.0]);
    let t = [n[1], -n[0]];
    let (top, jp) = (j.top_mm, j.pivot_mm);
    let front_top = sub(top, mul(t, j.top_front_edge_mm));
    let back_top = add(top, mul(t, j.top_back_edge_mm));
    let wb = j.top_back_edge_mm.max(2.5);
    let foot = 4.0;
    let tr = j.toe_radius_mm;
    let toe_c = [j.toe_mm[0], j.toe_mm[1] - tr];
    // Where the front edge comes down to just above the toe.
    let s = ((front_top[1] - (j.toe_mm[1] + 1.5)) / n[1].max(0.2)).max(0.0);
    let front_low = sub(front_top, mul(n, s));
    let mut outline = vec![
        front_top,
        back_top,
        add(jp, mul(t, wb)),
        sub(add(jp, mul(t, wb)), mul(n, foot)),
        [toe_c[0] + 1.0, toe_c[1] - tr - 0.8],
    ];
    outline.extend(arc(toe_c, tr + 0.8, 1.5 * PI, 0.5 * PI));
    outline.push(front_low);
    outline
}

fn jack_part(action: &Action) -> Part {
    let j = &action.params.jack;
    let mut part = Part::new("body-jack", Some("jack"));
    part.polygon(jack_outline(action), JACK_FILL);
    part.pivots.push(j.pivot_mm);
    part.label(j.toe_mm, [-5.0, -6.0], "jack", "end");
    part
}

/// The repetition lever: its top under the knuckle beside the jack top, its front tip under
/// the drop screw, pinned on the wippen's post.
fn lever_part(action: &Action) -> Part {
    let (r, j) = (&action.params.repetition_lever, &action.params.jack);
    let mut part = Part::new("body-repetition_lever", Some("repetition_lever"));
    let n = unit(j.axis, [0.0, 1.0]);
    let t = [n[1], -n[0]];
    let (rp, top) = (r.pivot_mm, r.top_mm);
    let f1 = sub(top, mul(t, r.top_front_edge_mm));
    let b1 = add(top, mul(t, r.top_back_edge_mm));
    let depth = 6.0;
    let tr = r.tip_radius_mm;
    let tip_c = [r.tip_mm[0], r.tip_mm[1] - tr];
    let mut outline = vec![
        r.tip_mm,
        f1,
        b1,
        [rp[0] + 6.0, rp[1] + 4.0],
        [rp[0] + 11.0, rp[1] + 2.0],
        [rp[0] + 11.0, rp[1] - 4.0],
        [rp[0], rp[1] - 5.0],
        [b1[0], b1[1] - depth],
        [f1[0], f1[1] - depth],
        [tip_c[0] + 1.5, tip_c[1] - 4.0],
    ];
    outline.extend(arc(tip_c, tr + 0.5, 1.25 * PI, 0.5 * PI));
    part.polygon(outline, LEVER_FILL);
    part.pivots.push(rp);
    let under = [0.5 * (b1[0] + rp[0]), 0.5 * (b1[1] + rp[1]) - depth];
    part.label(under, [0.0, -4.0], "repetition lever", "middle");
    part
}

/// The hammer in its shank frame: butt with the knuckle, shank, moulding with the tail,
/// felt with its crown; placed in the world by `rest` (its pose in the layout, for the
/// action).
///
/// The moulding is cut to the contact geometry: its back runs from the tail catch point
/// parallel to the backcheck face as it stands at rest, so the tail is the moulding's
/// lowest rear point, the catch face passes through it, and the backcheck (which stands
/// behind that line at rest) never lies inside the head. Where the backcheck reaches up
/// under the crown (`with_backcheck`: the model has one), the felt behind the moulding
/// stops above the backcheck's top.
fn hammer_part(params: &ActionParams, rest: &Transform, with_backcheck: bool) -> Part {
    let h = &params.hammer;
    let mut part = Part::new("body-hammer", Some("hammer"));
    let to_rest = |q: P| map(rest, q);
    let place = |pts: Vec<P>| pts.into_iter().map(to_rest).collect::<Vec<_>>();
    // The shape is cut against the backcheck where the layout puts them both.
    let to_body = {
        let inverse = hammer_layout_pose(params).inverse();
        move |q: P| map(&inverse, q)
    };
    let (k, kr) = (h.knuckle_body_mm, h.knuckle_radius_mm);
    let ys = [h.rest_body_mm[1], h.rest_body_mm[1] + SHANK];
    let cr = h.crown_radius_mm;
    let crown_c = [h.strike_body_mm[0], h.strike_body_mm[1] - cr];
    let tail = h.tail_body_mm;
    let tr = h.tail_radius_mm;

    // The backcheck at rest, in the shank frame: its face direction (pointing up the head)
    // and outward normal (toward the tail).
    let face = BackcheckFace::of(params);
    let lo = to_body(face.lo);
    let mut up = unit(sub(to_body(face.hi), lo), [0.0, 1.0]);
    if up[1] < 0.0 {
        up = mul(up, -1.0);
    }
    if up[1] < 0.2 {
        // A face lying along the shank cannot bound the head's back: stand it upright.
        up = [0.0, 1.0];
    }
    let normal = sub(to_body(add(face.lo, face.n)), lo);
    // The back of the moulding: the line through the back of the tail, parallel to the face.
    let tail_back = sub(tail, mul(normal, tr));
    let back_at = |y: f64| add(tail_back, mul(up, (y - tail_back[1]) / up[1]));
    let y_m = (ys[1] + 6.0).min(crown_c[1] - 2.0);
    let x_front = (crown_c[0] - cr - 2.0).min(back_at(y_m)[0] - HEAD_WIDTH);
    // The felt behind the moulding stays above the backcheck's highest point at rest.
    let backcheck_top = face
        .head()
        .iter()
        .flatten()
        .map(|&q| to_body(q)[1])
        .fold(f64::NEG_INFINITY, f64::max);
    let y_cut = if with_backcheck {
        (backcheck_top + HEAD_CLEARANCE).clamp(y_m, crown_c[1] + 0.9 * cr)
    } else {
        y_m
    };

    // Butt: the wood round the centre pin, carrying the knuckle.
    part.polygon(
        place(vec![
            [-7.0, ys[1] + 1.0],
            [k[0] + kr + 2.0, ys[1]],
            [k[0] + kr + 2.0, ys[0]],
            [k[0], k[1]],
            [-7.0, ys[0] - 2.0],
        ]),
        SHANK_FILL,
    );
    part.circle(to_rest(k), kr, BUCKSKIN_FILL);
    part.polygon(place(rect([0.0, x_front + 1.0], ys)), SHANK_FILL);
    // Moulding: front, back line down to the tail, round the tail, up to the shank.
    let mut molding = vec![[x_front, y_m], back_at(y_m), tail_back];
    let a0 = (-normal[1]).atan2(-normal[0]);
    molding.extend(arc(tail, tr, a0, a0 - PI));
    molding.push([x_front, ys[0]]);
    part.polygon(place(molding), MOLDING_FILL);
    // Felt: front flank, over the crown, down its back to the cut, under to the back line.
    let theta = ((y_cut - crown_c[1]) / cr).clamp(-1.0, 1.0).asin();
    let mut felt = vec![[x_front, y_m]];
    felt.extend(arc(crown_c, cr, PI, theta));
    let end = [crown_c[0] + cr * theta.cos(), crown_c[1] + cr * theta.sin()];
    let under = back_at(y_cut);
    if under[0] < end[0] {
        felt.push(under);
    }
    felt.push(back_at(y_m));
    part.polygon(place(felt), HAMMER_FELT_FILL);
    part.pivots.push(h.pivot_mm);
    part.label(
        to_rest([0.55 * x_front, ys[1]]),
        [0.0, 4.0],
        "hammer shank",
        "middle",
    );
    part.label(
        to_rest([crown_c[0] + cr, crown_c[1]]),
        [8.0, 0.0],
        "hammer",
        "start",
    );
    part
}

/// The presser on the key front, in its own frame (origin at its pad's centre): a
/// fingertip coming down from the player's side, or a weight (a steel cylinder as tall as
/// it is wide, to scale for its mass) on its pad.
fn presser_part(presser: Option<&Presser>, rest: &Transform) -> Part {
    let mut part = Part::new("body-presser", Some("presser"));
    let place = |pts: Vec<P>| pts.into_iter().map(|q| map(rest, q)).collect::<Vec<_>>();
    let r = PRESSER_PAD_RADIUS_MM;
    match presser {
        Some(p) if !p.carried => {
            // Steel, 7.85 g/cm³: a cylinder of diameter d and height d holds π d³ / 4.
            let volume_mm3 = p.mass_kg / 7.85e-6;
            let d = (4.0 * volume_mm3 / PI).cbrt();
            let mut pad = vec![[-r, r]];
            pad.extend(arc([0.0, 0.0], r, PI, 2.0 * PI));
            pad.push([r, r]);
            part.polygon(place(rect([-0.5 * d, 0.5 * d], [r, r + d])), METAL_FILL);
            part.polygon(place(pad), FELT_FILL);
            let name = format!("{} kg mass", trim_number(p.mass_kg));
            part.label(map(rest, [0.0, r + 0.5 * d]), [0.0, 0.0], name, "middle");
        }
        _ => {
            // The last joint of a finger: its pad (the model's round pad) on the key, the
            // finger rising toward the player, the nail on its back.
            let axis = [
                -(FINGER_TILT_DEG.to_radians().cos()),
                FINGER_TILT_DEG.to_radians().sin(),
            ];
            let side = [axis[1], -axis[0]];
            let len = 45.0;
            let half = FINGER_HALF_WIDTH;
            let a = axis[1].atan2(axis[0]);
            // Round tip of radius r, widening to the finger's width 12 mm up.
            let mut outline = arc([0.0, 0.0], r, a + 0.5 * PI, a + 1.5 * PI);
            outline.push(add(mul(axis, 12.0), mul(side, half)));
            outline.push(add(mul(axis, len), mul(side, half)));
            outline.push(sub(mul(axis, len), mul(side, half)));
            outline.push(sub(mul(axis, 12.0), mul(side, half)));
            part.polygon(place(outline), FINGER_FILL);
            // The nail on the finger's back (the side away from the player).
            let nail = vec![
                add(mul(axis, 2.0), mul(side, r)),
                add(mul(axis, 14.0), mul(side, half)),
                add(mul(axis, 14.0), mul(side, half - 1.2)),
                add(mul(axis, 3.0), mul(side, r - 1.2)),
            ];
            part.polygon(place(nail), FINGER_NAIL_FILL);
            part.label(
                map(rest, mul(axis, 30.0)),
                mul(side, -(half + 3.0)),
                "finger",
                "end",
            );
        }
    }
    part
}

/// `v` as short text: no trailing zeros ("1", "0.5", "2.25").
fn trim_number(v: f64) -> String {
    let s = format!("{v:.3}");
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The action bracket, seen through the action (it stands between keys, in another
/// plane): a post on the key frame in front of the action carrying the hammer-flange rail
/// and the let-off rail, and an arm back to the wippen flange with a strut up to the rest
/// rail.
fn bracket_part(action: &Action, frame_top: f64) -> Part {
    let p = &action.params;
    let (g, w, h) = (&p.regulation, &p.wippen, &p.hammer);
    let mut part = Part::new("action-bracket", None);
    part.behind = true;
    let (hp, wp) = (h.pivot_mm, w.pivot_mm);
    let post = [hp[0] - 44.0, hp[0] - 30.0];
    let flange_rail = [hp[1] - 8.0, hp[1] + 9.0];
    let arm = [wp[1] - 9.0, wp[1] + 5.0];
    let mut outline = vec![
        [post[0], frame_top],
        [post[0], flange_rail[1]],
        [hp[0] - 7.0, flange_rail[1]],
        [hp[0] - 7.0, flange_rail[0]],
        [post[1], flange_rail[0]],
    ];
    if action.contacts.contains_key("let_off_button") {
        let (x, y) = (g.let_off_button_x_mm, g.let_off_button_y_mm);
        let front = 0.5 * (x[0] + x[1]) - 10.0;
        outline.extend([
            [post[1], y + 26.0],
            [front, y + 26.0],
            [front, y + 16.0],
            [post[1], y + 16.0],
        ]);
    }
    outline.push([post[1], arm[1]]);
    let (rx, ry) = (g.rest_rail_x_mm, g.rest_rail_top_y_mm - 11.0);
    if ry > arm[1] && rx[0] + 4.0 > post[1] && rx[1] - 4.0 < wp[0] - 5.0 {
        outline.extend([
            [rx[0] + 4.0, arm[1]],
            [rx[0] + 4.0, ry],
            [rx[1] - 4.0, ry],
            [rx[1] - 4.0, arm[1]],
        ]);
    }
    outline.extend([
        [wp[0] + 5.0, arm[1]],
        [wp[0] + 5.0, arm[0]],
        [post[1], arm[0]],
        [post[1], frame_top],
    ]);
    part.polygon(outline, BRACKET_FILL);
    part.label(
        [post[0], 0.5 * (arm[1] + flange_rail[0])],
        [-3.0, 0.0],
        "action bracket (behind)",
        "end",
    );
    part
}

/// Height of the key frame's top, under the rails (mm).
fn key_frame_top(action: &Action) -> f64 {
    let (k, g) = (&action.params.key, &action.params.regulation);
    g.front_rail_top_y_mm
        .min(g.back_rail_top_y_mm)
        .min(k.pivot_mm[1])
        - RAIL_HEIGHT
}

/// The key frame with its rails, the let-off button and its rail, the drop screw, the
/// wippen and hammer flanges, the rest rail and the string.
fn fixed_part(action: &Action) -> Part {
    let p = &action.params;
    let (k, g, w, h) = (&p.key, &p.regulation, &p.wippen, &p.hammer);
    let mut part = Part::new("fixed-parts", None);
    let low = key_frame_top(action);
    let fx = g.front_rail_x_mm;
    let bx = g.back_rail_x_mm;
    let kp = k.pivot_mm;
    // Key frame and its three rails, with punchings and cloth.
    part.polygon(rect([fx[0] - 6.0, bx[1]], [low - 4.0, low]), RAIL_FILL);
    part.polygon(
        rect(
            [fx[0] - 4.0, fx[1] + 4.0],
            [low, g.front_rail_top_y_mm - FELT],
        ),
        RAIL_FILL,
    );
    part.polygon(
        rect(fx, [g.front_rail_top_y_mm - FELT, g.front_rail_top_y_mm]),
        CLOTH_FILL,
    );
    part.polygon(
        rect([kp[0] - 12.0, kp[0] + 12.0], [low, kp[1] - FELT]),
        RAIL_FILL,
    );
    part.polygon(
        rect([kp[0] - 5.0, kp[0] + 5.0], [kp[1] - FELT, kp[1]]),
        CLOTH_FILL,
    );
    part.polygon(
        rect([kp[0] - 0.8, kp[0] + 0.8], [kp[1] - FELT, kp[1] + 12.0]),
        METAL_FILL,
    );
    part.polygon(
        rect(bx, [low, g.back_rail_top_y_mm - FELT - 1.0]),
        RAIL_FILL,
    );
    part.polygon(
        rect(
            bx,
            [g.back_rail_top_y_mm - FELT - 1.0, g.back_rail_top_y_mm],
        ),
        FELT_FILL,
    );
    let under = low - 9.0;
    part.label(
        [0.5 * (fx[0] + fx[1]), under],
        [0.0, 0.0],
        "front rail",
        "middle",
    );
    part.label([kp[0], under], [0.0, 0.0], "balance rail", "middle");
    part.label(
        [0.5 * (bx[0] + bx[1]), under],
        [0.0, 0.0],
        "back rail",
        "middle",
    );
    // Let-off button hanging from its rail on a screw.
    if action.contacts.contains_key("let_off_button") {
        let (x, y) = (g.let_off_button_x_mm, g.let_off_button_y_mm);
        let c = 0.5 * (x[0] + x[1]);
        part.polygon(rect([c - 10.0, c + 4.0], [y + 16.0, y + 26.0]), RAIL_FILL);
        part.polygon(rect([c - 1.0, c + 1.0], [y + 5.5, y + 16.0]), METAL_FILL);
        part.polygon(rect(x, [y + FELT, y + 5.5]), MOLDING_FILL);
        part.polygon(rect(x, [y, y + FELT]), CLOTH_FILL);
        part.label([x[0], y + 2.0], [-3.0, 0.0], "let-off button", "end");
    }
    // Hammer flange and its rail; the drop screw goes down through the flange.
    let hp = h.pivot_mm;
    add_hammer_flange(&mut part, hp, "flange rail");
    if action.contacts.contains_key("drop_screw") {
        let (x, y) = (g.drop_screw_x_mm, g.drop_screw_y_mm);
        let c = 0.5 * (x[0] + x[1]);
        part.polygon(rect([c - 1.2, c + 1.2], [y, hp[1] - 3.0]), METAL_FILL);
        part.label([c - 1.2, y + 1.0], [-3.0, 0.0], "drop screw", "end");
    }
    // Wippen flange.
    let wp = w.pivot_mm;
    part.polygon(
        rect([wp[0] - 5.0, wp[0] + 5.0], [wp[1] - 9.0, wp[1] + 5.0]),
        RAIL_FILL,
    );
    // Hammer rest rail with its cushion.
    let rx = g.rest_rail_x_mm;
    let ry = g.rest_rail_top_y_mm;
    part.polygon(rect(rx, [ry - 3.0 - 8.0, ry - 3.0]), RAIL_FILL);
    part.polygon(rect(rx, [ry - 3.0, ry]), FELT_FILL);
    part.label(
        [0.5 * (rx[0] + rx[1]), ry - 9.0],
        [0.0, 0.0],
        "rest rail",
        "middle",
    );
    // The string, seen from the side: a horizontal wire at its height.
    let (sx, sy) = (g.string_x_mm, g.string_y_mm);
    part.wire(vec![[sx[0], sy + 0.5], [sx[1], sy + 0.5]], 1.0, "#555555");
    part.label(
        [0.5 * (sx[0] + sx[1]), sy + 3.0],
        [0.0, 0.0],
        "string",
        "middle",
    );
    part
}

/// Font size of the part names (mm).
pub const LABEL_FONT_MM: f64 = 3.0;

/// The box a label takes on the page (world mm, y up: `[x0, y0, x1, y1]`) when written at
/// `at` with `align` (the SVG `text-anchor`), as [`Svg::text`] writes it: a generous
/// estimate of sans-serif text, 0.6 em per character.
pub fn label_box(at: [f64; 2], text: &str, align: &str) -> [f64; 4] {
    let w = 0.6 * LABEL_FONT_MM * text.chars().count() as f64;
    let x0 = match align {
        "middle" => at[0] - 0.5 * w,
        "end" => at[0] - w,
        _ => at[0],
    };
    [
        x0,
        at[1] - 0.6 * LABEL_FONT_MM,
        x0 + w,
        at[1] + 0.5 * LABEL_FONT_MM,
    ]
}

fn overlaps(a: &[f64; 4], b: &[f64; 4]) -> bool {
    a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]
}

/// Where to write a label wanted at `at`: there if its box is free, else the nearest free
/// place straight above or below (in steps of a line); its box joins `placed`.
fn place_label(at: P, text: &str, align: &str, placed: &mut Vec<[f64; 4]>) -> P {
    let step = 1.2 * LABEL_FONT_MM;
    let candidates = (0..40).map(|k| {
        let k = k as f64;
        let dy = if k == 0.0 {
            0.0
        } else {
            let ring = ((k + 1.0) / 2.0).floor();
            if k % 2.0 == 1.0 {
                ring * step
            } else {
                -ring * step
            }
        };
        [at[0], at[1] + dy]
    });
    let mut chosen = at;
    for q in candidates {
        let b = label_box(q, text, align);
        if !placed.iter().any(|p| overlaps(p, &b)) {
            chosen = q;
            break;
        }
    }
    placed.push(label_box(chosen, text, align));
    chosen
}

/// The hammer flange on its rail, the hammer's centre pin at `hp`; the rail named `name`.
fn add_hammer_flange(part: &mut Part, hp: P, name: &str) {
    part.polygon(
        rect([hp[0] - 27.0, hp[0] - 7.0], [hp[1] - 8.0, hp[1] + 9.0]),
        RAIL_FILL,
    );
    part.polygon(
        vec![
            [hp[0] - 7.0, hp[1] + 8.0],
            [hp[0] + 5.0, hp[1] + 6.0],
            [hp[0] + 5.0, hp[1] - 5.0],
            [hp[0] - 7.0, hp[1] - 7.0],
        ],
        RAIL_FILL,
    );
    part.label([hp[0] - 17.0, hp[1] - 1.0], [0.0, 0.0], name, "middle");
}

/// The parts of the swing test: the hammer flange clamped on its rail, and the hammer with
/// its shank at `shank_angle_rad` in the world.
fn pendulum_parts(params: &ActionParams, shank_angle_rad: f64) -> Vec<Part> {
    // The flange is a fork round the butt: seen through the hammer, dashed, with the clamp
    // that holds it above, out of the swing's way.
    let hp = params.hammer.pivot_mm;
    let mut flange = Part::new("fixed-parts", None);
    flange.behind = true;
    flange.polygon(
        vec![
            [hp[0] - 7.0, hp[1] + 10.0],
            [hp[0] + 7.0, hp[1] + 10.0],
            [hp[0] + 5.0, hp[1] - 5.0],
            [hp[0] - 5.0, hp[1] - 5.0],
        ],
        RAIL_FILL,
    );
    flange.polygon(
        rect([hp[0] - 20.0, hp[0] + 20.0], [hp[1] + 10.0, hp[1] + 22.0]),
        METAL_FILL,
    );
    flange.label(
        [hp[0] + 20.0, hp[1] + 16.0],
        [4.0, 0.0],
        "flange, clamped",
        "start",
    );
    vec![
        flange,
        hammer_part(params, &hammer_pose(params, shank_angle_rad), false),
    ]
}

/// The hammer's pose (metres) with its shank at `shank_angle_rad` about its flange pin.
fn hammer_pose(params: &ActionParams, shank_angle_rad: f64) -> Transform {
    let h = &params.hammer;
    Transform::new(shank_angle_rad, h.pivot_mm[0] * 1e-3, h.pivot_mm[1] * 1e-3)
}

/// The hammer's pose in the layout: the shank at its rest angle.
fn hammer_layout_pose(params: &ActionParams) -> Transform {
    hammer_pose(params, params.hammer.rest_angle_deg.to_radians())
}

/// The swing test drawn to scale: the hammer on its clamped flange with its shank at
/// `shank_angle_rad` in the world (radians, counter-clockwise from the x axis; hanging is
/// [`crate::pendulum::Swing::hanging_shank_angle_rad`]), titled `title`. The hammer is the
/// one [`action_svg`] draws (group `body-hammer`); the flange is `fixed-parts`.
///
/// Errors: a non-finite angle.
pub fn pendulum_svg(params: &ActionParams, shank_angle_rad: f64, title: &str) -> Result<String> {
    if !shank_angle_rad.is_finite() {
        return Err(CoreError::NonFiniteInput {
            what: "shank angle",
            index: 0,
            value: shank_angle_rad,
        }
        .into());
    }
    Ok(render(
        &pendulum_parts(params, shank_angle_rad),
        &BTreeMap::new(),
        &[],
        "the hammer swinging on its flange; white dot: its centre pin",
        title,
    ))
}

/// The swing test as data for a viewer that moves it (see [`scene`]): the clamped flange
/// and the hammer (frame `"hammer"`) hanging, its shank at `hanging_shank_angle_rad`; no
/// contacts.
pub fn pendulum_scene(params: &ActionParams, hanging_shank_angle_rad: f64) -> serde_json::Value {
    serde_json::json!({
        "frames": ["hammer"],
        "parts": parts_json(&pendulum_parts(params, hanging_shank_angle_rad)),
        "contacts": [],
    })
}

/// The motion `[angle (rad), x (mm), y (mm)]` carrying the swing test's hammer from its
/// place in [`pendulum_scene`] (hanging) to `angle_from_hanging_rad` from there: a turn
/// about the flange pin.
pub fn pendulum_carry(params: &ActionParams, angle_from_hanging_rad: f64) -> [f64; 3] {
    let p = params.hammer.pivot_mm;
    let (s, c) = angle_from_hanging_rad.sin_cos();
    // x' = R (x − p) + p, so the translation is p − R p.
    [
        angle_from_hanging_rad,
        p[0] - (c * p[0] - s * p[1]),
        p[1] - (s * p[0] + c * p[1]),
    ]
}

/// Bounding box of the drawn points (mm).
#[derive(Clone, Copy, Debug)]
struct Bounds {
    min: P,
    max: P,
}

impl Bounds {
    fn new() -> Self {
        Self {
            min: [f64::INFINITY; 2],
            max: [f64::NEG_INFINITY; 2],
        }
    }

    fn add(&mut self, q: P, pad: f64) {
        for ((lo, hi), v) in self.min.iter_mut().zip(&mut self.max).zip(q) {
            *lo = lo.min(v - pad);
            *hi = hi.max(v + pad);
        }
    }
}

/// Writes SVG elements with the y axis flipped (world mm, y up → SVG, y down).
struct Svg {
    body: String,
    bounds: Bounds,
}

impl Svg {
    fn pt(q: P) -> String {
        format!("{:.2},{:.2}", q[0], -q[1])
    }

    fn polygon(&mut self, pts: &[P], attrs: &str) {
        for &q in pts {
            self.bounds.add(q, 0.0);
        }
        let s: Vec<String> = pts.iter().map(|&q| Self::pt(q)).collect();
        let _ = writeln!(self.body, r#"<polygon points="{}" {attrs}/>"#, s.join(" "));
    }

    fn polyline(&mut self, pts: &[P], attrs: &str) {
        for &q in pts {
            self.bounds.add(q, 0.0);
        }
        let s: Vec<String> = pts.iter().map(|&q| Self::pt(q)).collect();
        let _ = writeln!(
            self.body,
            r#"<polyline points="{}" fill="none" {attrs}/>"#,
            s.join(" ")
        );
    }

    fn circle(&mut self, c: P, r: f64, attrs: &str) {
        self.bounds.add(c, r);
        let _ = writeln!(
            self.body,
            r#"<circle cx="{:.2}" cy="{:.2}" r="{:.2}" {attrs}/>"#,
            c[0], -c[1], r
        );
    }

    /// Text standing on `at` (its baseline 1 mm below, so it is centred on the point).
    fn text(&mut self, at: P, text: &str, align: &str) {
        let _ = writeln!(
            self.body,
            r#"<text x="{:.2}" y="{:.2}" text-anchor="{align}">{}</text>"#,
            at[0],
            -at[1] + 1.0,
            escape(text)
        );
    }

    fn open(&mut self, attrs: &str) {
        let _ = writeln!(self.body, "<g {attrs}>");
    }

    fn close(&mut self) {
        self.body.push_str("</g>\n");
    }
}

/// Escapes text for SVG.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Maps a point (mm) by a pose in metres.
fn map(x: &Transform, q: P) -> P {
    mul(x.transform_point(mul(q, 1e-3)), 1e3)
}

/// Draws a contact shape placed in the world (m), thin.
fn draw_shape(svg: &mut Svg, s: &Shape) {
    let attrs = format!(r#"stroke="{CONTACT_STROKE}" stroke-width="0.25""#);
    match s {
        Shape::Circle(c) => svg.circle(
            mul(c.center, 1e3),
            c.radius * 1e3,
            &format!(r#"fill="none" {attrs}"#),
        ),
        Shape::Segment(g) => svg.polyline(&[mul(g.a, 1e3), mul(g.b, 1e3)], &attrs),
        Shape::Line(l) => {
            let t = [-l.normal[1], l.normal[0]];
            let p = mul(l.point, 1e3);
            svg.polyline(&[sub(p, mul(t, 20.0)), add(p, mul(t, 20.0))], &attrs);
        }
        Shape::Arc(a) => svg.polyline(
            &arc(
                mul(a.center, 1e3),
                a.radius * 1e3,
                a.start,
                a.start + a.sweep,
            ),
            &attrs,
        ),
    }
}

/// What the drawing needs of one contact at `(t, x)`: its shapes in the world (m), whether
/// it is pressed and where.
struct ContactView<'a> {
    name: &'a str,
    /// The name in the legend: the presser's pad is the finger's or the mass's.
    label: &'a str,
    shapes: Vec<Shape>,
    active: bool,
    point: Option<P>,
}

/// Draws `action` to scale at time `t` and state `x` (a full state of `action.system`, as
/// [`Action::layout_state`] or a solution row gives), titled `title`: an SVG document in
/// millimetres.
///
/// Each body is an outline built from the parameters and placed by its world pose at
/// `(t, x)` (the drive's value for a prescribed coordinate); bodies the model lacks are not
/// drawn (the simplified model's jack is drawn as part of the wippen). Groups carry ids:
/// `body-key`, `key-capstan`, `key-backcheck`, `body-wippen`, `body-jack`,
/// `body-repetition_lever`, `body-hammer`, `body-presser` (a finger or a mass),
/// `fixed-parts`, `action-bracket` (drawn first, dashed: it stands between keys),
/// `contact-<name>` for each contact's shapes (thin blue), `active-<name>` for the red dot
/// on each pressed contact (gap < 0), which the legend also lists, and `labels` (part
/// names, placed so that no two overlap).
///
/// Errors: a non-finite `t`, a state of the wrong length or with a non-finite entry.
pub fn action_svg(action: &Action, t: f64, x: &[f64], title: &str) -> Result<String> {
    if !t.is_finite() {
        return Err(CoreError::NonFiniteInput {
            what: "t",
            index: 0,
            value: t,
        }
        .into());
    }
    let (rest, carry) = rest_and_carry(action, t, x)?;
    let contacts = contact_views(&action.system, &action.contacts, t, x, |name| {
        match (name, action.presser) {
            ("presser_key", Some(p)) if p.carried => "finger_key",
            ("presser_key", Some(_)) => "mass_key",
            _ => name,
        }
    })?;

    let parts = build_parts(action, &rest);
    let legend = format!(
        "contact shapes of the {} model; white dots: pivots",
        action.kind.name()
    );
    Ok(render(&parts, &carry, &contacts, &legend, title))
}

/// What the drawings need of every contact of `system` (`contacts`: element index by name)
/// at `(t, x)`, named in the legend by `label`.
fn contact_views<'a>(
    system: &mbs_core::System,
    contacts: &'a BTreeMap<String, usize>,
    t: f64,
    x: &[f64],
    label: impl Fn(&'a str) -> &'a str,
) -> Result<Vec<ContactView<'a>>> {
    let mut ws = system.workspace();
    let mut views = Vec::new();
    for (name, &e) in contacts {
        let name = name.as_str();
        let ctx = system.element_context(&mut ws, t, x, e)?;
        let Some(element) = system.elements().nth(e) else {
            continue;
        };
        let mut gap = [0.0];
        if element.switch_count() > 0 {
            element.switching_functions(&ctx, &mut gap);
        }
        let (shapes, point) = match ContactElement::of(element) {
            Some(c) => {
                let shapes = c
                    .sides()
                    .iter()
                    .flat_map(|(body, shapes)| {
                        let pose = ctx.body_pose(*body);
                        shapes.iter().map(move |s| s.placed(&pose))
                    })
                    .collect();
                (shapes, Some(mul(c.output(&ctx).point, 1e3)))
            }
            None => (Vec::new(), None),
        };
        views.push(ContactView {
            name,
            label: label(name),
            shapes,
            active: gap[0] < 0.0,
            point,
        });
    }
    Ok(views)
}

/// The SVG document of `parts`, each carried from its rest place by its frame's motion in
/// `carry` (fixed parts and frames not in it stay), with the contacts' shapes and pressed
/// dots over them, the part names, and `title` and `legend` (the line under the pressed
/// contacts).
fn render(
    parts: &[Part],
    carry: &BTreeMap<String, Transform>,
    contacts: &[ContactView],
    legend: &str,
    title: &str,
) -> String {
    let mut svg = Svg {
        body: String::new(),
        bounds: Bounds::new(),
    };
    let outline = r##"stroke="#333333" stroke-width="0.3" stroke-linejoin="round""##;
    // Rest layout → now, for a part.
    let carried = |part: &Part| {
        part.frame
            .as_ref()
            .and_then(|f| carry.get(f).copied())
            .unwrap_or(Transform::IDENTITY)
    };
    let hidden = r##"stroke="#8c8c8c" stroke-width="0.3" stroke-dasharray="1.5 1""##;
    for part in parts {
        let x_part = carried(part);
        let outline = if part.behind { hidden } else { outline };
        svg.open(&format!(r#"id="{}""#, part.id));
        for (piece, fill) in &part.pieces {
            match piece {
                Outline::Polygon(pts) => {
                    let pts: Vec<P> = pts.iter().map(|&q| map(&x_part, q)).collect();
                    svg.polygon(&pts, &format!(r#"fill="{fill}" {outline}"#));
                }
                Outline::Circle(c, r) => {
                    svg.circle(map(&x_part, *c), *r, &format!(r#"fill="{fill}" {outline}"#))
                }
                Outline::Wire(pts, width) => {
                    let pts: Vec<P> = pts.iter().map(|&q| map(&x_part, q)).collect();
                    svg.polyline(
                        &pts,
                        &format!(r#"stroke="{fill}" stroke-width="{width:.2}""#),
                    );
                }
            }
        }
        for &pv in &part.pivots {
            svg.circle(
                map(&x_part, pv),
                1.0,
                r##"fill="#ffffff" stroke="#000000" stroke-width="0.3""##,
            );
        }
        svg.close();
    }
    svg.open(r#"id="contact-shapes""#);
    for c in contacts {
        svg.open(&format!(r#"id="contact-{}""#, c.name));
        for s in &c.shapes {
            draw_shape(&mut svg, s);
        }
        svg.close();
    }
    svg.close();
    svg.open(r#"id="active-contacts""#);
    for c in contacts.iter().filter(|c| c.active) {
        if let Some(q) = c.point {
            svg.circle(
                q,
                1.4,
                &format!(
                    r#"id="active-{}" fill="{ACTIVE_FILL}" stroke="none""#,
                    c.name
                ),
            );
        }
    }
    svg.close();
    svg.open(&format!(
        r##"id="labels" font-size="{LABEL_FONT_MM}" fill="#222222""##
    ));
    let mut placed: Vec<[f64; 4]> = Vec::new();
    for part in parts {
        let x_part = carried(part);
        for l in &part.labels {
            let a = map(&x_part, l.anchor);
            let at = place_label(add(a, l.offset), &l.text, l.align, &mut placed);
            if at != a {
                svg.polyline(&[a, at], r##"stroke="#555555" stroke-width="0.15""##);
            }
            svg.text(at, &l.text, l.align);
        }
    }
    svg.close();

    frame_document(svg, contacts, legend, title)
}

/// Wraps the drawing in its document: white page fitted around the action with a margin,
/// title above, legend and scale bar below.
fn frame_document(svg: Svg, contacts: &[ContactView], legend: &str, title: &str) -> String {
    let b = svg.bounds;
    // Wide enough for the title and the legend beside the scale bar (text at 0.6 em a
    // character).
    let active: Vec<&str> = contacts
        .iter()
        .filter(|c| c.active)
        .map(|c| c.label)
        .collect();
    let list = if active.is_empty() {
        "none".to_string()
    } else {
        active.join(", ")
    };
    let pressed = format!("contacts pressed: {list}");
    let text_w = |text: &str, size: f64| 0.6 * size * text.chars().count() as f64;
    let right = (b.max[0])
        .max(b.min[0] + text_w(title, 6.0))
        .max(b.min[0] + 4.5 + text_w(legend, 3.5).max(text_w(&pressed, 3.5)) + 6.0 + SCALE_BAR_MM);
    let (x0, x1) = (b.min[0] - MARGIN_MM, right + MARGIN_MM);
    // SVG y runs down: the top of the page is above the action's highest point.
    let top = -b.max[1] - MARGIN_MM - TITLE_SPACE;
    let bottom = -b.min[1] + MARGIN_MM + LEGEND_SPACE;
    let (w, h) = (x1 - x0, bottom - top);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.2}mm" height="{h:.2}mm" viewBox="{x0:.2} {top:.2} {w:.2} {h:.2}" font-family="sans-serif">"#
    );
    let _ = writeln!(
        out,
        r##"<rect x="{x0:.2}" y="{top:.2}" width="{w:.2}" height="{h:.2}" fill="#ffffff"/>"##
    );
    let _ = writeln!(
        out,
        r##"<text id="title" x="{:.2}" y="{:.2}" font-size="6" fill="#111111">{}</text>"##,
        b.min[0],
        -b.max[1] - TITLE_SPACE + 2.0,
        escape(title)
    );
    out.push_str(&svg.body);

    // Legend: pressed contacts, and what the thin lines are.
    let y0 = -b.min[1] + MARGIN_MM;
    let _ = writeln!(out, r##"<g id="legend" font-size="3.5" fill="#222222">"##);
    // Without contacts (the swing test) only the legend line stands.
    if !contacts.is_empty() {
        let _ = writeln!(
            out,
            r#"<circle cx="{:.2}" cy="{:.2}" r="1.4" fill="{ACTIVE_FILL}"/>"#,
            b.min[0] + 1.4,
            y0 - 1.2
        );
        let _ = writeln!(
            out,
            r#"<text x="{:.2}" y="{:.2}">{}</text>"#,
            b.min[0] + 4.5,
            y0,
            escape(&pressed)
        );
        let _ = writeln!(
            out,
            r#"<line x1="{:.2}" y1="{:.2}" x2="{:.2}" y2="{:.2}" stroke="{CONTACT_STROKE}" stroke-width="0.25"/>"#,
            b.min[0],
            y0 + 4.8,
            b.min[0] + 3.0,
            y0 + 4.8
        );
    }
    let _ = writeln!(
        out,
        r#"<text x="{:.2}" y="{:.2}">{}</text>"#,
        b.min[0] + 4.5,
        y0 + 6.0,
        escape(legend)
    );
    out.push_str("</g>\n");

    // Scale bar at the bottom right.
    let (sx1, sy) = (right, y0 + 4.0);
    let sx0 = sx1 - SCALE_BAR_MM;
    let _ = writeln!(
        out,
        r##"<g id="scale-bar" stroke="#000000" stroke-width="0.4"><line x1="{sx0:.2}" y1="{sy:.2}" x2="{sx1:.2}" y2="{sy:.2}"/><line x1="{sx0:.2}" y1="{:.2}" x2="{sx0:.2}" y2="{:.2}"/><line x1="{sx1:.2}" y1="{:.2}" x2="{sx1:.2}" y2="{:.2}"/><text x="{:.2}" y="{:.2}" font-size="3.5" stroke="none" fill="#000000" text-anchor="middle">{SCALE_BAR_MM} mm</text></g>"##,
        sy - 1.2,
        sy + 1.2,
        sy - 1.2,
        sy + 1.2,
        0.5 * (sx0 + sx1),
        sy - 2.0
    );
    out.push_str("</svg>\n");
    out
}

/// The frames a drawing carries, in drawing order.
fn drawn_frames(action: &Action) -> Vec<&'static str> {
    let model = action.system.model();
    let mut names = vec!["key", "wippen", "jack", "hammer"];
    for extra in ["repetition_lever", "presser"] {
        if model.body_id(extra).is_ok() {
            names.push(extra);
        }
    }
    names
}

/// Rest poses (q = 0, the layout) of every drawn frame, and the motion carrying each from
/// its rest place to where it is at `(t, x)` (`X_now ∘ X_rest⁻¹`; a prescribed coordinate
/// takes its drive's value).
#[allow(clippy::type_complexity)]
fn rest_and_carry(
    action: &Action,
    t: f64,
    x: &[f64],
) -> Result<(BTreeMap<String, Transform>, BTreeMap<String, Transform>)> {
    rest_and_carry_of(&action.system, &drawn_frames(action), t, x)
}

/// [`rest_and_carry`] for the named frames of any system.
#[allow(clippy::type_complexity)]
fn rest_and_carry_of(
    system: &mbs_core::System,
    frames: &[&str],
    t: f64,
    x: &[f64],
) -> Result<(BTreeMap<String, Transform>, BTreeMap<String, Transform>)> {
    let model = system.model();
    let mut rest_data = Data::new(model);
    update_poses(model, &mut rest_data, &vec![0.0; model.nv()])?;
    let mut ws = system.workspace();
    let mut carry = BTreeMap::new();
    let mut rest = BTreeMap::new();
    let ctx = system.kinematics(&mut ws, t, x)?;
    for &name in frames {
        let id = model.frame_id(name)?;
        let x0 = frame_pose(model, &rest_data, id);
        let x1 = frame_pose(model, ctx.data, id);
        rest.insert(name.to_string(), x0);
        carry.insert(name.to_string(), x1.compose(&x0.inverse()));
    }
    Ok((rest, carry))
}

/// The parts of `action`, back to front, in their rest places.
fn build_parts(action: &Action, rest: &BTreeMap<String, Transform>) -> Vec<Part> {
    let model = action.system.model();
    let is_body = |name: &str| model.body_id(name).is_ok();
    let jack_moves = is_body("jack");
    let with_lever = is_body("repetition_lever");
    let mut parts = vec![
        bracket_part(action, key_frame_top(action)),
        fixed_part(action),
        key_part(action),
        capstan_part(action),
    ];
    parts.push(wippen_part(action, !jack_moves, with_lever));
    if with_lever {
        parts.push(lever_part(action));
    }
    if jack_moves {
        parts.push(jack_part(action));
    }
    if let Some(x0) = rest.get("hammer") {
        let with_backcheck = action.contacts.contains_key("backcheck");
        parts.push(hammer_part(&action.params, x0, with_backcheck));
    }
    if action.contacts.contains_key("backcheck") {
        parts.push(backcheck_part(action));
    }
    if let Some(x0) = rest.get("presser") {
        parts.push(presser_part(action.presser.as_ref(), x0));
    }
    parts
}

fn round(v: f64) -> f64 {
    (v * 1e3).round() / 1e3
}

fn json_points(pts: &[P]) -> serde_json::Value {
    pts.iter()
        .map(|q| serde_json::json!([round(q[0]), round(q[1])]))
        .collect()
}

/// Parts as data: outlines in their rest places, frame, pivots and labels.
fn parts_json(parts: &[Part]) -> Vec<serde_json::Value> {
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
        "contacts": rest_contacts_json(&action.system, &action.contacts)?,
    }))
}

/// Every contact's shapes in their rest places (mm), by side with the frame that carries it.
fn rest_contacts_json(
    system: &mbs_core::System,
    contacts_by_name: &BTreeMap<String, usize>,
) -> Result<Vec<serde_json::Value>> {
    let model = system.model();
    let mut contacts = Vec::new();
    let mut rest_data = Data::new(model);
    update_poses(model, &mut rest_data, &vec![0.0; model.nv()])?;
    for (name, &e) in contacts_by_name {
        let Some(c) = system.elements().nth(e).and_then(ContactElement::of) else {
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

// ------------------------------------------------------------ any mechanism, from outlines

/// Fill colours of bodies that name none, in body order.
const BODY_FILLS: [&str; 8] = [
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
fn mechanism_frames(mechanism: &Mechanism) -> Vec<&str> {
    mechanism.bodies.iter().map(|b| b.name.as_str()).collect()
}

/// One outline part placed by `pose` (m) as a drawn piece (mm).
fn outline_piece(part: &mut Part, o: &OutlinePart, pose: &Transform, fill: &str) {
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
fn mechanism_parts(mechanism: &Mechanism, rest: &BTreeMap<String, Transform>) -> Vec<Part> {
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
    let contacts = contact_views(&built.system, &built.contacts, t, x, |n| n)?;
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
        "contacts": rest_contacts_json(&built.system, &built.contacts)?,
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

/// Thickness of the grand action's drawn parts across the plane (mm) \[M\]: the key 22 mm
/// wide, the wippen and hammer 14 mm, the jack 8 mm; the fixed rails span the keys.
const GRAND_THICKNESS_MM: [(&str, f64); 10] = [
    ("fixed-parts", 36.0),
    ("body-key", 22.0),
    ("body-wippen", 14.0),
    ("body-jack", 8.0),
    ("body-repetition_lever", 10.0),
    ("body-hammer", 14.0),
    ("key-backcheck", 14.0),
    ("body-presser", 14.0),
    ("key-capstan", 8.0),
    ("action-bracket", 10.0),
];

/// The grand action's drawing as description outlines: the ground's (world, m) and each
/// body's (its frame, m), with their colours and thicknesses, so that a description
/// written by `piano describe` draws like the built-in model.
#[allow(clippy::type_complexity)]
pub fn grand_outlines(
    action: &Action,
) -> Result<(Vec<OutlinePart>, BTreeMap<String, Vec<OutlinePart>>)> {
    let x = action.layout_state()?;
    let (rest, _) = rest_and_carry(action, 0.0, &x)?;
    let mut ground = Vec::new();
    let mut bodies: BTreeMap<String, Vec<OutlinePart>> = BTreeMap::new();
    for part in build_parts(action, &rest) {
        let thickness = GRAND_THICKNESS_MM
            .iter()
            .find(|(id, _)| *id == part.id)
            .map_or(10.0, |(_, t)| *t)
            * 1e-3;
        // World mm at rest → the frame's coordinates in m.
        let inverse = part
            .frame
            .as_ref()
            .and_then(|f| rest.get(f))
            .map_or(Transform::IDENTITY, |x0| x0.inverse());
        let local = |q: P| inverse.transform_point(mul(q, 1e-3));
        let z = if part.behind { -0.04 } else { 0.0 };
        let mut out = Vec::new();
        for (piece, fill) in &part.pieces {
            let mut o = OutlinePart {
                name: part.id.clone(),
                points: Vec::new(),
                circle: None,
                thickness,
                z,
                color: Some(fill.clone()),
            };
            match piece {
                Outline::Polygon(pts) => {
                    o.points = pts.iter().map(|&q| local(q)).collect();
                    out.push(o);
                }
                Outline::Circle(c, r) => {
                    o.circle = Some(mbs_mechanism::CircleSpec {
                        center: local(*c),
                        radius: r * 1e-3,
                    });
                    out.push(o);
                }
                Outline::Wire(pts, width) => {
                    // Each stretch of wire as a thin quadrilateral.
                    for w in pts.windows(2) {
                        let d = unit(sub(w[1], w[0]), [1.0, 0.0]);
                        let n = mul([-d[1], d[0]], 0.5 * width);
                        let mut q = o.clone();
                        q.points = [add(w[0], n), add(w[1], n), sub(w[1], n), sub(w[0], n)]
                            .into_iter()
                            .map(local)
                            .collect();
                        q.thickness = (width * 1e-3).max(1.5e-3);
                        out.push(q);
                    }
                }
            }
        }
        out.retain(|o| o.circle.is_some() || o.points.len() >= 3);
        match &part.frame {
            None => ground.extend(out),
            Some(f) => bodies.entry(f.clone()).or_default().extend(out),
        }
    }
    Ok((ground, bodies))
}
