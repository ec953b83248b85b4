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
use mbs_mechanism::{Built, ContactHandle, Mechanism, OutlinePart};

use crate::action::{Action, PRESSER_PAD_RADIUS_MM, Presser};
use crate::error::Result;
use crate::params::ActionParams;

mod grand;
mod outlines;
mod scene;
mod svg;

pub(crate) use grand::grand_thickness_mm;
use grand::*;
pub use grand::{grand_outlines, pendulum_carry, pendulum_scene, pendulum_svg};
pub use outlines::{mechanism_carry, mechanism_scene, mechanism_svg};
use scene::*;
pub use scene::{carry, scene};
use svg::*;
pub use svg::{LABEL_FONT_MM, action_svg, label_box};

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
