//! An independent truth generator for key-drive datasets (`identification.md` §5.5, "Truths
//! that the library did not make").
//!
//! The library's own synthesiser (`identify::key_drive::synthesize`) adds its effects with
//! the same transformations its diagnosis fits, so a dataset it makes can only confirm the
//! library. This generator shares none of that: each case edits the grand's mechanism
//! description by hand (bodies, joints, springs, contacts of `mbs_mechanism`'s serde
//! structs), in a *form* the library does not hold (a key bending far behind the pivot or
//! at three places, a shank bending at mid-length or twice, a back-check sliding on a
//! prismatic spring, a felt with another exponent or law, friction with another law), or
//! adds what the library leaves out (a damper lever on the key's tail, a soft foot under
//! the mass, play in the hammer's flange pin, a stiff balance pin, a tracking target that
//! slips). Its camera (exposure averaging, clock offset, AR(1) noise, gross errors, lost
//! frames), its random numbers (splitmix64 + Box–Muller, one stream per purpose) and its
//! writers (CSV and JSON) are its own. From the library it uses the simulator
//! (`simulate_transformed`, `prepare_transformed`), the kinematics of the built system and
//! the parameter file's paths.
//!
//! Everything drawn for a dataset except the case's own strengths comes from streams keyed
//! by the seed alone, so two cases at one seed share the nuisance, the heights, the camera
//! and the noise: their difference is the case's effect. Gross errors (8–12 σ on one
//! coordinate) and lost frames are drawn per marker track: 0.3 % and 0.1 % of each
//! marker's frames.
//!
//! What dominates after the check (measured over seeds 0–19, 0.3 s): the checked hammer
//! of this model creeps slowly upward in the plain action (some 0.4 mm/s at the head in
//! the 0 mm drop) and, in 11 of 20 plain 5 mm drops, leaves the back-check for the
//! repetition lever (the head ends some 7 mm higher); several cases (both key flexes, the two-hinge shank, the soft mass pad) turn
//! the fitted 0 mm drop's hold into such an escape in 19–20 seeds of 20, so their
//! post-check gap is that flip (millimetres) more than the effect's own size.

#![allow(dead_code)]

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use piano_action::mechanism::{
    ArcSideSpec, Body, BodyPoint, CircleSpec, ContactFrictionSpec, ContactPair, ContactSideSpec,
    InputKind, Joint, JointType, LawSpec, Limits, Mechanism, OutlinePart, ShapeSpec, TorsionSpring,
};
use piano_action::params::{ActionParams, DEFAULT_PARAMS_TOML};
use piano_action::simulate::{Input, prepare_transformed, simulate_transformed};
use piano_action::{ModelKind, PianoError};
use serde::Serialize;

/// Frame rate of the camera (frames/s).
pub const FPS: f64 = 3000.0;
/// The mass released on the key (kg).
pub const MASS_KG: f64 = 1.0;
/// The tracking noise declared in `dataset.json` (m).
pub const DECLARED_SIGMA_M: f64 = 30e-6;
/// Declared release heights of the fitted and the held-out run (m).
pub const DECLARED_HEIGHTS_M: [f64; 2] = [0.0, 0.005];
/// The model the truth is simulated on.
const KIND: ModelKind = ModelKind::Double;
/// Output step of the simulation the camera samples (s).
const SIM_STEP_S: f64 = 2e-5;
/// Simulated time past the last frame, for the clock offset and the exposure (s).
const SIM_MARGIN_S: f64 = 1e-3;
/// The integrator's relative tolerance of the truth's simulations [D] (its absolute
/// tolerance a thousandth of it, in m and rad). A truth is the action's physics, not an
/// integrator's error: at the parameter file's 1e-3 / 1e-6 (`numerics`, chosen for the
/// hammer's speed at the string) the `keybed_felt_p3` seed-2 held-out drop's head was
/// 275 µm off a run at 1e-8 at 0.22 s, 7 noise floors, after the check where the hammer's
/// hold is a friction wedge (88 µm in the fitted drop); the refit on every run then pushed
/// the let-off button's, the lever knuckle's and the repetition lever's values to their
/// tolerance's edge to follow that error. At 1e-7, 0.6 µm; at the diagnosis's 1e-5, 14 µm.
pub const RELATIVE_TOLERANCE: f64 = 1e-7;
/// Points of the midpoint rule that averages the motion over an exposure.
const EXPOSURE_POINTS: usize = 8;
/// The tracked markers, in the order of the dataset.
pub const MARKERS: [&str; 4] = ["key_front", "key_back", "hammer_head", "hammer_shank"];
/// Index of `hammer_head` in [`MARKERS`].
pub const HEAD: usize = 2;

// ---------------------------------------------------------------------------------------
// Cases
// ---------------------------------------------------------------------------------------

/// What a diagnosis should conclude on a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Expected {
    /// The effect family of the library that holds the same physical effect.
    Family(&'static str),
    /// An effect the library does not hold: `unexplained` or `partly_explained`, never a
    /// name.
    Outside,
    /// Nothing hidden.
    Negative,
}

impl Expected {
    /// `key_flex`, `outside` or `negative`.
    pub fn label(&self) -> String {
        match self {
            Expected::Family(f) => (*f).to_string(),
            Expected::Outside => "outside".into(),
            Expected::Negative => "negative".into(),
        }
    }
}

/// A truth case.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Its id.
    pub id: &'static str,
    /// What it hides.
    pub about: &'static str,
    /// What a diagnosis should conclude.
    pub expected: Expected,
}

/// Every case, the library's families in other forms first, then the effects outside the
/// library, then the negative.
pub fn cases() -> Vec<Case> {
    use Expected::*;
    let case = |id, about, expected| Case {
        id,
        about,
        expected,
    };
    vec![
        case(
            "key_flex_far",
            "the key bends 60-80 mm behind the balance pivot: one torsion spring of \
             500-1500 N·m/rad, damping ratio 0.02-0.1",
            Family("key_flex"),
        ),
        case(
            "key_flex_beam",
            "the key's back arm bends at three hinges (about 30, 90, 150 mm behind the \
             pivot), each 1500-4000 N·m/rad: a beam's first mode, roughly",
            Family("key_flex"),
        ),
        case(
            "shank_flex_mid",
            "the hammer shank bends 35-45 mm from the flange pin (both hammer markers ride \
             the distal part), 2-6 N·m/rad, damping ratio 0.02-0.1",
            Family("shank_flex"),
        ),
        case(
            "shank_flex_two",
            "the hammer shank bends at two places (about 50 and 110 mm from the flange \
             pin), each 8-15 N·m/rad",
            Family("shank_flex"),
        ),
        case(
            "backcheck_slide",
            "the back-check head (6 g) slides on a prismatic spring along its face's \
             normal, 3e3-1e4 N/m, lightly damped",
            Family("backcheck_compliance"),
        ),
        case(
            "keybed_felt_p3",
            "the front-rail punching with exponent 2.7-3.2, its force at 1 mm 0.3-0.6 of \
             the file's, restitution 0.55-0.7",
            Family("keybed_felt"),
        ),
        case(
            "knuckle_felt_hc",
            "the jack-knuckle felt replaced by a Hunt-Crossley law (exponent 2.3-2.8, \
             loading matched at 0.2 mm, rate-dependent loss)",
            Family("felt_hysteresis"),
        ),
        case(
            "knuckle_friction_visc",
            "the jack-knuckle friction coefficient raised by 0.1-0.25 with a regularisation \
             speed of 0.02-0.05 m/s (viscous-like at low slip)",
            Family("knuckle_friction"),
        ),
        case(
            "damper",
            "a damper lever the model leaves out: pivoted on the ground behind the key, met \
             by the key's tail after about half the dip, 20-40 gf at the key front",
            Outside,
        ),
        case(
            "mass_pad",
            "the mass sits on a soft rubber foot: the mass-key contact 10-30 times softer, \
             restitution 0.2-0.4",
            Outside,
        ),
        case(
            "flange_play",
            "play of ±0.05-0.1 mm in the hammer's flange pin: the hammer on a 0.3 g carrier \
             sliding vertically and horizontally between stiff, damped stops",
            Outside,
        ),
        case(
            "key_pin_friction",
            "friction in the balance pin 4-8 times the file's (the wippen's flange 3 times)",
            Outside,
        ),
        case(
            "marker_slip",
            "the hammer-head target slips 0.2-0.4 mm along the shank at the first \
             back-check catch (camera stage; the action is untouched)",
            Outside,
        ),
        case("none", "the action with nuisance mismatches only", Negative),
    ]
}

/// The case `id`.
pub fn case(id: &str) -> Result<Case, String> {
    cases().into_iter().find(|c| c.id == id).ok_or_else(|| {
        format!(
            "no case '{id}' (cases: {})",
            cases().iter().map(|c| c.id).collect::<Vec<_>>().join(", ")
        )
    })
}

// ---------------------------------------------------------------------------------------
// Options, truth record
// ---------------------------------------------------------------------------------------

/// Which runs a dataset holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Heights {
    /// The fitted run (declared 0 mm) and the held-out run (declared 5 mm).
    Both,
    /// The fitted run only (a short CI dataset).
    FittedOnly,
}

/// What to generate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GenOptions {
    /// Length of each run (s).
    pub duration_s: f64,
    /// Which runs.
    pub heights: Heights,
    /// The integrator's relative tolerance ([`RELATIVE_TOLERANCE`]; the absolute one a
    /// thousandth of it).
    pub relative_tolerance: f64,
}

impl Default for GenOptions {
    fn default() -> Self {
        GenOptions {
            duration_s: 0.3,
            heights: Heights::Both,
            relative_tolerance: RELATIVE_TOLERANCE,
        }
    }
}

/// The truth behind a dataset (`truth.json`, never inside the dataset's folder).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TruthRecord {
    /// Which generator made it.
    pub generator: String,
    /// The case's id.
    pub case: String,
    /// What it hides.
    pub about: String,
    /// The expected outcome: a family's name, `outside` or `negative`.
    pub expected: String,
    /// The seed.
    pub seed: u64,
    /// The case's drawn strengths and geometry, by name (SI units unless the name says).
    pub effect: BTreeMap<String, f64>,
    /// What was edited in the description, in words with the numbers.
    pub edits: Vec<String>,
    /// Each mismatched parameter path and the factor it was multiplied by.
    pub nuisance: BTreeMap<String, f64>,
    /// The camera.
    pub camera: TruthCamera,
    /// Per run.
    pub runs: Vec<TruthRun>,
}

/// The camera behind a dataset.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TruthCamera {
    /// Frames per second.
    pub fps: f64,
    /// The exposure declared in `dataset.json` (s).
    pub declared_exposure_s: f64,
    /// The noise declared per marker (m).
    pub declared_sigma_m: f64,
    /// True AR(1) marginal SD of the tracking noise, per coordinate (m).
    pub sigma_m: f64,
    /// True AR(1) lag-one correlation.
    pub rho: f64,
}

/// The truth of one run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TruthRun {
    /// Its id.
    pub id: String,
    /// `fit` or `heldout`.
    pub role: String,
    /// The release height declared in `dataset.json` (m).
    pub declared_release_height_m: f64,
    /// The true release height (m).
    pub release_height_m: f64,
    /// The camera's clock offset τ (s).
    pub offset_s: f64,
    /// The true exposure (s).
    pub exposure_s: f64,
    /// The first back-check catch after the strike (s), if in the run.
    pub check_catch_s: Option<f64>,
    /// Frames with a gross error.
    pub outliers: Vec<TruthOutlier>,
    /// Frames lost.
    pub lost: Vec<TruthLost>,
}

/// A gross tracking error.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TruthOutlier {
    /// Frame index.
    pub frame: usize,
    /// Marker name.
    pub marker: String,
    /// `x` or `y`.
    pub axis: String,
    /// Signed size, in units of the true σ.
    pub sigmas: f64,
}

/// A lost frame of one marker (both coordinates empty).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TruthLost {
    /// Frame index.
    pub frame: usize,
    /// Marker name.
    pub marker: String,
}

// ---------------------------------------------------------------------------------------
// Random numbers: splitmix64, uniform from the top 53 bits, Box–Muller normals.
// ---------------------------------------------------------------------------------------

struct Rng {
    state: u64,
    spare: Option<f64>,
}

impl Rng {
    /// The stream `label` of `seed`: streams of different labels are unrelated.
    fn stream(seed: u64, label: &str) -> Rng {
        // FNV-1a of the label, mixed into the seed; splitmix's output scrambles the rest.
        let mut h: u64 = 0xcbf2_9ce4_8422_2325;
        for b in label.bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
        let mut rng = Rng {
            state: seed.wrapping_mul(0xd6e8_feb8_6659_fd93) ^ h,
            spare: None,
        };
        rng.next_u64();
        rng
    }

    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// ±1.
    fn sign(&mut self) -> f64 {
        if self.uniform() < 0.5 { -1.0 } else { 1.0 }
    }

    /// Standard normal (Box–Muller, both values used).
    fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let u1 = 1.0 - self.uniform(); // (0, 1]
        let u2 = self.uniform();
        let r = (-2.0 * u1.ln()).sqrt();
        let (s, c) = (std::f64::consts::TAU * u2).sin_cos();
        self.spare = Some(r * s);
        r * c
    }
}

// ---------------------------------------------------------------------------------------
// Mass properties of parts, in a body frame
// ---------------------------------------------------------------------------------------

/// A rigid part: mass (kg), centre of mass (m) and inertia about it (kg·m²) in a body's
/// frame.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Props {
    mass: f64,
    com: [f64; 2],
    inertia: f64,
}

impl Props {
    fn of(body: &Body) -> Props {
        Props {
            mass: body.mass,
            com: body.com,
            inertia: body.inertia,
        }
    }

    fn point(mass: f64, com: [f64; 2], inertia: f64) -> Props {
        Props { mass, com, inertia }
    }

    /// A uniform bar of `lambda` kg/m from x0 to x1 at height y, `thickness` tall.
    fn bar(lambda: f64, x0: f64, x1: f64, y: f64, thickness: f64) -> Props {
        let l = (x1 - x0).max(0.0);
        let mass = lambda * l;
        Props {
            mass,
            com: [0.5 * (x0 + x1), y],
            inertia: mass * (l * l + thickness * thickness) / 12.0,
        }
    }

    fn about_origin(&self) -> f64 {
        self.inertia + self.mass * (self.com[0] * self.com[0] + self.com[1] * self.com[1])
    }

    fn plus(&self, o: &Props) -> Props {
        if self.mass == 0.0 {
            return *o;
        }
        if o.mass == 0.0 {
            return *self;
        }
        let mass = self.mass + o.mass;
        let com = [
            (self.mass * self.com[0] + o.mass * o.com[0]) / mass,
            (self.mass * self.com[1] + o.mass * o.com[1]) / mass,
        ];
        let j = self.about_origin() + o.about_origin();
        Props {
            mass,
            com,
            inertia: j - mass * (com[0] * com[0] + com[1] * com[1]),
        }
    }

    fn minus(&self, o: &Props) -> Props {
        let mass = self.mass - o.mass;
        let com = [
            (self.mass * self.com[0] - o.mass * o.com[0]) / mass,
            (self.mass * self.com[1] - o.mass * o.com[1]) / mass,
        ];
        let j = self.about_origin() - o.about_origin();
        Props {
            mass,
            com,
            inertia: j - mass * (com[0] * com[0] + com[1] * com[1]),
        }
    }

    /// The same part in a frame whose origin is at `origin` (same orientation).
    fn seen_from(&self, origin: [f64; 2]) -> Props {
        Props {
            com: [self.com[0] - origin[0], self.com[1] - origin[1]],
            ..*self
        }
    }

    const ZERO: Props = Props {
        mass: 0.0,
        com: [0.0, 0.0],
        inertia: 0.0,
    };
}

/// The key as parts [D]: a basswood stick of 0.08 kg/m (23 mm tall, ~8 mm wide) from its
/// front end to its back end, the capstan (2 g), the back-check on its wire (6 g), and the
/// lead weights: what remains of the file's mass, centre of mass and inertia once the
/// others are taken away (so the parts add up to the file's key exactly). Key frame: the
/// balance pivot at the origin, the front toward −x.
struct KeyParts {
    wood_lambda: f64,
    capstan: Props,
    backcheck: Props,
    leads: Props,
}

/// The key's ends along its frame (m) [D]: the drawing's outline (`piano describe`).
const KEY_FRONT_END_M: f64 = -0.223;
const KEY_BACK_END_M: f64 = 0.236;
/// The key stick's mid-height and height (m) [D].
const KEY_WOOD_Y_M: f64 = 0.0115;
const KEY_TOP_Y_M: f64 = 0.023;
/// The reference key's mass (kg): parts scale with the key's mass under nuisance.
const KEY_MASS_REF_KG: f64 = 0.110;

impl KeyParts {
    fn of(key: &Body) -> Result<KeyParts, String> {
        let s = key.mass / KEY_MASS_REF_KG;
        let wood_lambda = 0.08 * s;
        let capstan = Props::point(2e-3 * s, [0.110, 0.0235], 1e-8 * s);
        let backcheck = Props::point(6e-3 * s, [0.2005, 0.065], 6e-7 * s);
        let wood = Props::bar(
            wood_lambda,
            KEY_FRONT_END_M,
            KEY_BACK_END_M,
            KEY_WOOD_Y_M,
            KEY_TOP_Y_M,
        );
        let known = wood.plus(&capstan).plus(&backcheck);
        let leads = Props::of(key).minus(&known);
        if !(leads.mass > 0.0 && leads.inertia > 0.0 && leads.com[0] < -0.02) {
            return Err(format!(
                "the key's parts do not fit its mass properties: leads {leads:?} (key \
                 {} kg, com {:?}, inertia {} kg·m²)",
                key.mass, key.com, key.inertia
            ));
        }
        Ok(KeyParts {
            wood_lambda,
            capstan,
            backcheck,
            leads,
        })
    }

    /// Everything of the key beyond x (toward its back end), in the key frame.
    fn beyond(&self, x: f64) -> Props {
        let mut p = Props::bar(
            self.wood_lambda,
            x,
            KEY_BACK_END_M,
            KEY_WOOD_Y_M,
            KEY_TOP_Y_M,
        );
        for part in [&self.capstan, &self.backcheck, &self.leads] {
            if part.com[0] > x {
                p = p.plus(part);
            }
        }
        p
    }
}

/// The hammer as parts [D]: the flange and knuckle block (1 g near the pin), a hornbeam
/// shank of 0.025 kg/m from the pin to the head (115 mm), and the head (moulding and
/// felt): what remains of the file's mass, centre of mass and inertia. Hammer frame: the
/// flange pin at the origin, x along the shank.
struct HammerParts {
    shank_lambda: f64,
    block: Props,
    head: Props,
}

const SHANK_END_M: f64 = 0.115;
const SHANK_Y_M: f64 = -0.0008;
const SHANK_THICKNESS_M: f64 = 0.0064;
const HAMMER_MASS_REF_KG: f64 = 0.01174;

impl HammerParts {
    fn of(hammer: &Body) -> Result<HammerParts, String> {
        let s = hammer.mass / HAMMER_MASS_REF_KG;
        let shank_lambda = 0.025 * s;
        let block = Props::point(1e-3 * s, [0.012, -0.005], 2e-8 * s);
        let shank = Props::bar(shank_lambda, 0.0, SHANK_END_M, SHANK_Y_M, SHANK_THICKNESS_M);
        let head = Props::of(hammer).minus(&block.plus(&shank));
        if !(head.mass > 0.0 && head.inertia > 1e-7 && head.com[0] > SHANK_END_M) {
            return Err(format!(
                "the hammer's parts do not fit its mass properties: head {head:?} (hammer \
                 {} kg, com {:?}, inertia {} kg·m²)",
                hammer.mass, hammer.com, hammer.inertia
            ));
        }
        Ok(HammerParts {
            shank_lambda,
            block,
            head,
        })
    }

    /// Everything of the hammer beyond x along the shank, in the hammer frame.
    fn beyond(&self, x: f64) -> Props {
        let mut p = Props::bar(
            self.shank_lambda,
            x,
            SHANK_END_M,
            SHANK_Y_M,
            SHANK_THICKNESS_M,
        );
        for part in [&self.block, &self.head] {
            if part.com[0] > x {
                p = p.plus(part);
            }
        }
        p
    }
}

// ---------------------------------------------------------------------------------------
// Hand edits of the description
// ---------------------------------------------------------------------------------------

/// A cut of a body: points `p` of `body` with `(p − at)·along > 0` go to `new_body`, whose
/// frame has its origin at `at` and the orientation of `body`'s.
#[derive(Clone, Debug, PartialEq)]
struct Cut {
    body: String,
    at: [f64; 2],
    along: [f64; 2],
    new_body: String,
}

impl Cut {
    fn side(&self, p: [f64; 2]) -> f64 {
        (p[0] - self.at[0]) * self.along[0] + (p[1] - self.at[1]) * self.along[1]
    }

    fn distal(&self, p: [f64; 2]) -> bool {
        self.side(p) > 0.0
    }

    fn moved(&self, p: [f64; 2]) -> [f64; 2] {
        [p[0] - self.at[0], p[1] - self.at[1]]
    }
}

/// The extreme signed distances from the cut of a shape's points (a circle's rim, an arc's
/// centre and rim: conservative).
fn shape_span(cut: &Cut, s: &ShapeSpec) -> (f64, f64) {
    let pts: Vec<([f64; 2], f64)> = match s {
        ShapeSpec::Circle { center, radius } => vec![(*center, *radius)],
        ShapeSpec::Segment { a, b } => vec![(*a, 0.0), (*b, 0.0)],
        ShapeSpec::Arc { center, radius, .. } => vec![(*center, *radius)],
        ShapeSpec::Profile { points } => points.iter().map(|p| (*p, 0.0)).collect(),
    };
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for (p, r) in pts {
        let d = cut.side(p);
        lo = lo.min(d - r);
        hi = hi.max(d + r);
    }
    (lo, hi)
}

fn shape_moved(s: &ShapeSpec, by: [f64; 2]) -> ShapeSpec {
    let mv = |p: &[f64; 2]| [p[0] - by[0], p[1] - by[1]];
    match s {
        ShapeSpec::Circle { center, radius } => ShapeSpec::Circle {
            center: mv(center),
            radius: *radius,
        },
        ShapeSpec::Segment { a, b } => ShapeSpec::Segment { a: mv(a), b: mv(b) },
        ShapeSpec::Arc {
            center,
            radius,
            start,
            sweep,
            side,
        } => ShapeSpec::Arc {
            center: mv(center),
            radius: *radius,
            start: *start,
            sweep: *sweep,
            side: match side {
                ArcSideSpec::Convex => ArcSideSpec::Convex,
                ArcSideSpec::Concave => ArcSideSpec::Concave,
            },
        },
        ShapeSpec::Profile { points } => ShapeSpec::Profile {
            points: points.iter().map(mv).collect(),
        },
    }
}

/// Moves the shapes of one contact side (or striker) of `cut.body` beyond the cut onto the
/// new body. Every shape of a side must lie wholly on one side of the cut, and a side goes
/// whole (none of the grand's sides has shapes on both sides of these cuts).
fn move_side(cut: &Cut, side: &mut ContactSideSpec, what: &str) -> Result<bool, String> {
    if side.body != cut.body {
        return Ok(false);
    }
    let mut far = 0;
    for s in &side.shapes {
        let (lo, hi) = shape_span(cut, s);
        if lo < 0.0 && hi > 0.0 {
            return Err(format!(
                "{what}: a shape of '{}' straddles the cut at {:?}",
                cut.body, cut.at
            ));
        }
        if lo >= 0.0 {
            far += 1;
        }
    }
    if far == 0 {
        return Ok(false);
    }
    if far != side.shapes.len() {
        return Err(format!(
            "{what}: its shapes on '{}' lie on both sides of the cut at {:?}",
            cut.body, cut.at
        ));
    }
    side.body = cut.new_body.clone();
    side.shapes = side.shapes.iter().map(|s| shape_moved(s, cut.at)).collect();
    Ok(true)
}

/// Sutherland–Hodgman clip of a polygon to one side of the cut.
fn clip(cut: &Cut, points: &[[f64; 2]], distal: bool) -> Option<Vec<[f64; 2]>> {
    let inside = |p: [f64; 2]| cut.distal(p) == distal;
    let mut out = Vec::new();
    for (i, &p) in points.iter().enumerate() {
        let q = points[(i + 1) % points.len()];
        if inside(p) {
            out.push(p);
        }
        if inside(p) != inside(q) {
            let (sp, sq) = (cut.side(p), cut.side(q));
            let t = sp / (sp - sq);
            out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
        }
    }
    (out.len() >= 3).then_some(out)
}

fn reattach(cut: &Cut, p: &mut BodyPoint) {
    if p.body == cut.body && cut.distal(p.point) {
        p.body = cut.new_body.clone();
        p.point = cut.moved(p.point);
    }
}

/// `m` with `cut.body` cut in two: the part beyond the cut (mass properties `distal`, in
/// `cut.body`'s frame) on a revolute hinge at `cut.at` held by a torsion spring of
/// stiffness `k` and damping `c`. The body keeps the remainder (the whole's mass, centre of
/// mass and inertia about its joint are kept). Contact sides, strikers, markers, force
/// inputs, spring and cord ends, loads, child joints and outline parts beyond the cut go
/// to the new body in its frame. The new body is listed right after the cut one.
fn split(
    m: &Mechanism,
    cut: &Cut,
    distal: Props,
    k: f64,
    c: f64,
    log: &mut Vec<String>,
) -> Result<Mechanism, String> {
    let index = m
        .bodies
        .iter()
        .position(|b| b.name == cut.body)
        .ok_or_else(|| format!("split: no body '{}'", cut.body))?;
    if m.bodies.iter().any(|b| b.name == cut.new_body) {
        return Err(format!("split: '{}' is already a body", cut.new_body));
    }
    if !cut.distal(distal.com) {
        return Err(format!(
            "split of '{}': the distal part's centre of mass {:?} is not beyond the cut",
            cut.body, distal.com
        ));
    }
    let whole = Props::of(&m.bodies[index]);
    let rest = whole.minus(&distal);
    if !(rest.mass > 0.0 && rest.inertia > 0.0) {
        return Err(format!(
            "split of '{}' at {:?}: the remainder {rest:?} has no positive mass or inertia",
            cut.body, cut.at
        ));
    }
    let mut out = m.clone();
    for c in &mut out.contacts {
        let what = format!("contact '{}'", c.name);
        move_side(cut, &mut c.a, &what)?;
        move_side(cut, &mut c.b, &what)?;
    }
    for s in &mut out.strings {
        move_side(cut, &mut s.striker, &format!("string '{}'", s.name))?;
    }
    for mk in &mut out.markers {
        reattach(cut, &mut mk.at);
    }
    for i in &mut out.inputs {
        if i.kind == InputKind::Force {
            reattach(cut, &mut i.at);
        }
    }
    for s in &mut out.point_springs {
        reattach(cut, &mut s.a);
        reattach(cut, &mut s.b);
    }
    for s in &mut out.cords {
        reattach(cut, &mut s.a);
        reattach(cut, &mut s.b);
    }
    for l in &mut out.loads {
        reattach(cut, &mut l.at);
    }
    for b in &mut out.bodies {
        if b.joint.parent == cut.body && cut.distal(b.joint.at) {
            b.joint.parent = cut.new_body.clone();
            b.joint.at = cut.moved(b.joint.at);
        }
    }
    let (mut near, mut far) = (Vec::new(), Vec::new());
    for part in &m.bodies[index].outline {
        match &part.circle {
            Some(circle) => {
                if cut.distal(circle.center) {
                    far.push(OutlinePart {
                        circle: Some(CircleSpec {
                            center: cut.moved(circle.center),
                            radius: circle.radius,
                        }),
                        ..part.clone()
                    });
                } else {
                    near.push(part.clone());
                }
            }
            None => {
                if let Some(points) = clip(cut, &part.points, false) {
                    near.push(OutlinePart {
                        points,
                        ..part.clone()
                    });
                }
                if let Some(points) = clip(cut, &part.points, true) {
                    far.push(OutlinePart {
                        points: points.iter().map(|p| cut.moved(*p)).collect(),
                        ..part.clone()
                    });
                }
            }
        }
    }
    let body = &mut out.bodies[index];
    body.mass = rest.mass;
    body.com = rest.com;
    body.inertia = rest.inertia;
    body.outline = near;
    let moved = distal.seen_from(cut.at);
    out.bodies.insert(
        index + 1,
        Body {
            name: cut.new_body.clone(),
            note: format!(
                "independent truth: the part of '{}' beyond [{}, {}] m",
                cut.body, cut.at[0], cut.at[1]
            ),
            mass: moved.mass,
            com: moved.com,
            inertia: moved.inertia,
            joint: Joint {
                kind: JointType::Revolute,
                parent: cut.body.clone(),
                at: cut.at,
                angle: 0.0,
                axis: None,
                limits: None,
                friction: None,
            },
            outline: far,
        },
    );
    out.torsion_springs.push(TorsionSpring {
        name: format!("{} hinge", cut.new_body),
        note: "independent truth".into(),
        joint: cut.new_body.clone(),
        stiffness: k,
        rest: 0.0,
        preload: 0.0,
        damping: c,
    });
    log.push(format!(
        "split '{}' at [{:.4}, {:.4}] m across [{}, {}]: new body '{}' on a revolute hinge \
         ({:.2} g, com [{:.4}, {:.4}] m in its frame, inertia {:.3e} kg·m²), torsion spring \
         k = {:.4} N·m/rad, c = {:.3e} N·m·s/rad; '{}' keeps {:.2} g, com [{:.4}, {:.4}] m, \
         inertia {:.3e} kg·m²",
        cut.body,
        cut.at[0],
        cut.at[1],
        cut.along[0],
        cut.along[1],
        cut.new_body,
        moved.mass * 1e3,
        moved.com[0],
        moved.com[1],
        moved.inertia,
        k,
        c,
        cut.body,
        rest.mass * 1e3,
        rest.com[0],
        rest.com[1],
        rest.inertia
    ));
    Ok(out)
}

/// Damping of a hinge of stiffness `k` carrying inertia `inertia` at damping ratio `zeta`.
fn damping(zeta: f64, k: f64, inertia: f64) -> f64 {
    2.0 * zeta * (k * inertia).sqrt()
}

fn body<'m>(m: &'m Mechanism, name: &str) -> Result<&'m Body, String> {
    m.bodies
        .iter()
        .find(|b| b.name == name)
        .ok_or_else(|| format!("the description has no body '{name}'"))
}

fn contact_mut<'m>(m: &'m mut Mechanism, name: &str) -> Result<&'m mut ContactPair, String> {
    m.contacts
        .iter_mut()
        .find(|c| c.name == name)
        .ok_or_else(|| format!("the description has no contact '{name}'"))
}

/// The felt law of a contact: (k, p, e, smoothing).
fn felt_of(m: &Mechanism, name: &str) -> Result<(f64, f64, f64, f64), String> {
    let c = m
        .contacts
        .iter()
        .find(|c| c.name == name)
        .ok_or_else(|| format!("the description has no contact '{name}'"))?;
    match c.law {
        LawSpec::Felt {
            k, p, e, smoothing, ..
        } => Ok((k, p, e, smoothing)),
        ref other => Err(format!("contact '{name}' has law {other:?}, not a felt")),
    }
}

/// Where a new root body goes: before the presser (its coordinate must stay last, where
/// `prepare_transformed` puts its starting height), else last.
fn root_insert_index(m: &Mechanism) -> usize {
    m.bodies
        .iter()
        .position(|b| b.name == "presser")
        .unwrap_or(m.bodies.len())
}

// ---------------------------------------------------------------------------------------
// The effects, drawn and applied
// ---------------------------------------------------------------------------------------

/// A case's effect with its drawn values.
#[derive(Clone, Debug, PartialEq)]
enum Effect {
    None,
    KeyFlexFar {
        cut_m: f64,
        k: f64,
        zeta: f64,
    },
    KeyFlexBeam {
        cuts_m: [f64; 3],
        k: [f64; 3],
        zeta: f64,
    },
    ShankFlexMid {
        cut_m: f64,
        k: f64,
        zeta: f64,
    },
    ShankFlexTwo {
        cuts_m: [f64; 2],
        k: [f64; 2],
        zeta: f64,
    },
    BackcheckSlide {
        k: f64,
        zeta: f64,
        mass_kg: f64,
    },
    KeybedFeltP3 {
        p: f64,
        force_ratio_1mm: f64,
        e: f64,
    },
    KnuckleFeltHc {
        p: f64,
        alpha: f64,
    },
    KnuckleFrictionVisc {
        dmu: f64,
        regularization: f64,
    },
    Damper {
        front_load_gf: f64,
        engage_fraction: f64,
    },
    MassPad {
        k_ratio: f64,
        e: f64,
    },
    FlangePlay {
        play_m: f64,
    },
    KeyPinFriction {
        key_factor: f64,
    },
    MarkerSlip {
        slip_m: f64,
    },
}

/// Where the key's tail meets the damper lever, along the key (m) [D].
const DAMPER_CONTACT_X_M: f64 = 0.229;
/// The damper lever: length from its pivot to its felt and to its centre of mass (m) [D].
const DAMPER_ARM_M: f64 = 0.10;
const DAMPER_COM_ARM_M: f64 = 0.05;
/// The key's nominal dip at the finger point (mm) [D]: the file's action, settled under
/// the 1 kg (23.3 → 13.3 mm in a plain run).
const KEY_DIP_MM: f64 = 10.0;
/// The hammer carrier of `flange_play` (kg, both slides) and its stops [D]: stiff, damped.
const CARRIER_MASS_KG: f64 = 0.3e-3;
const CARRIER_STOP_N_M: f64 = 1e6;
const CARRIER_STOP_N_S_M: f64 = 50.0;
/// The knuckle law's loading is matched at this compression (m).
const KNUCKLE_MATCH_M: f64 = 0.2e-3;

impl Effect {
    /// The effect of case `id`, its strengths drawn from the case's own stream of `seed`.
    fn draw(id: &str, seed: u64) -> Result<Effect, String> {
        let mut r = Rng::stream(seed, &format!("effect:{id}"));
        Ok(match id {
            "none" => Effect::None,
            "key_flex_far" => Effect::KeyFlexFar {
                cut_m: r.range(0.060, 0.080),
                k: r.range(500.0, 1500.0),
                zeta: r.range(0.02, 0.1),
            },
            "key_flex_beam" => Effect::KeyFlexBeam {
                cuts_m: [
                    r.range(0.025, 0.035),
                    r.range(0.085, 0.095),
                    r.range(0.145, 0.155),
                ],
                k: [
                    r.range(1500.0, 4000.0),
                    r.range(1500.0, 4000.0),
                    r.range(1500.0, 4000.0),
                ],
                zeta: r.range(0.02, 0.1),
            },
            "shank_flex_mid" => Effect::ShankFlexMid {
                cut_m: r.range(0.035, 0.045),
                k: r.range(2.0, 6.0),
                zeta: r.range(0.02, 0.1),
            },
            "shank_flex_two" => Effect::ShankFlexTwo {
                cuts_m: [r.range(0.045, 0.055), r.range(0.105, 0.113)],
                k: [r.range(8.0, 15.0), r.range(8.0, 15.0)],
                zeta: r.range(0.02, 0.1),
            },
            "backcheck_slide" => Effect::BackcheckSlide {
                k: r.range(3e3, 1e4),
                zeta: r.range(0.02, 0.1),
                mass_kg: r.range(0.0055, 0.0065),
            },
            "keybed_felt_p3" => Effect::KeybedFeltP3 {
                p: r.range(2.7, 3.2),
                force_ratio_1mm: r.range(0.3, 0.6),
                e: r.range(0.55, 0.7),
            },
            "knuckle_felt_hc" => Effect::KnuckleFeltHc {
                p: r.range(2.3, 2.8),
                alpha: r.range(0.5, 2.0),
            },
            "knuckle_friction_visc" => Effect::KnuckleFrictionVisc {
                dmu: r.range(0.1, 0.25),
                regularization: r.range(0.02, 0.05),
            },
            "damper" => Effect::Damper {
                front_load_gf: r.range(20.0, 40.0),
                engage_fraction: r.range(0.45, 0.55),
            },
            "mass_pad" => Effect::MassPad {
                k_ratio: 1.0 / r.range(10.0, 30.0),
                e: r.range(0.2, 0.4),
            },
            "flange_play" => Effect::FlangePlay {
                play_m: r.range(0.05e-3, 0.1e-3),
            },
            "key_pin_friction" => Effect::KeyPinFriction {
                key_factor: r.range(4.0, 8.0),
            },
            "marker_slip" => Effect::MarkerSlip {
                slip_m: r.sign() * r.range(0.2e-3, 0.4e-3),
            },
            other => return Err(format!("no effect is drawn for case '{other}'")),
        })
    }

    /// Its drawn values by name.
    fn values(&self) -> BTreeMap<String, f64> {
        let mut v = BTreeMap::new();
        let mut put = |k: &str, x: f64| {
            v.insert(k.to_string(), x);
        };
        match *self {
            Effect::None => {}
            Effect::KeyFlexFar { cut_m, k, zeta } | Effect::ShankFlexMid { cut_m, k, zeta } => {
                put("cut_m", cut_m);
                put("k_n_m_per_rad", k);
                put("zeta", zeta);
            }
            Effect::KeyFlexBeam { cuts_m, k, zeta } => {
                for i in 0..3 {
                    put(&format!("cut{}_m", i + 1), cuts_m[i]);
                    put(&format!("k{}_n_m_per_rad", i + 1), k[i]);
                }
                put("zeta", zeta);
            }
            Effect::ShankFlexTwo { cuts_m, k, zeta } => {
                for i in 0..2 {
                    put(&format!("cut{}_m", i + 1), cuts_m[i]);
                    put(&format!("k{}_n_m_per_rad", i + 1), k[i]);
                }
                put("zeta", zeta);
            }
            Effect::BackcheckSlide { k, zeta, mass_kg } => {
                put("k_n_per_m", k);
                put("zeta", zeta);
                put("mass_kg", mass_kg);
            }
            Effect::KeybedFeltP3 {
                p,
                force_ratio_1mm,
                e,
            } => {
                put("p", p);
                put("force_ratio_at_1mm", force_ratio_1mm);
                put("e", e);
            }
            Effect::KnuckleFeltHc { p, alpha } => {
                put("p", p);
                put("alpha_s_per_m", alpha);
                put("matched_at_m", KNUCKLE_MATCH_M);
            }
            Effect::KnuckleFrictionVisc {
                dmu,
                regularization,
            } => {
                put("dmu", dmu);
                put("regularization_m_s", regularization);
            }
            Effect::Damper {
                front_load_gf,
                engage_fraction,
            } => {
                put("front_load_gf", front_load_gf);
                put("engage_fraction_of_dip", engage_fraction);
            }
            Effect::MassPad { k_ratio, e } => {
                put("k_ratio", k_ratio);
                put("e", e);
            }
            Effect::FlangePlay { play_m } => put("play_m", play_m),
            Effect::KeyPinFriction { key_factor } => {
                put("key_friction_factor", key_factor);
                put("wippen_friction_factor", 3.0);
            }
            Effect::MarkerSlip { slip_m } => put("slip_along_shank_m", slip_m),
        }
        v
    }

    /// The cuts it makes, in order (the markers beyond them ride the new bodies).
    fn cuts(&self) -> Vec<Cut> {
        let cut = |body: &str, x: f64, new_body: &str| Cut {
            body: body.into(),
            at: [x, 0.0],
            along: [1.0, 0.0],
            new_body: new_body.into(),
        };
        match *self {
            Effect::KeyFlexFar { cut_m, .. } => vec![cut("key", cut_m, "key_tail")],
            Effect::KeyFlexBeam { cuts_m: c, .. } => vec![
                cut("key", c[0], "key_seg1"),
                cut("key_seg1", c[1] - c[0], "key_seg2"),
                cut("key_seg2", c[2] - c[1], "key_seg3"),
            ],
            Effect::ShankFlexMid { cut_m, .. } => vec![cut("hammer", cut_m, "hammer_outer")],
            Effect::ShankFlexTwo { cuts_m: c, .. } => vec![
                cut("hammer", c[0], "hammer_mid"),
                cut("hammer_mid", c[1] - c[0], "hammer_tip"),
            ],
            _ => Vec::new(),
        }
    }

    /// `m` (the grand's description, with or without the presser) with the effect added,
    /// and what was done.
    fn apply(&self, m: &Mechanism) -> Result<(Mechanism, Vec<String>), String> {
        let mut log = Vec::new();
        let out = match *self {
            Effect::None | Effect::MarkerSlip { .. } => m.clone(),
            Effect::KeyFlexFar { k, zeta, .. } => {
                let parts = KeyParts::of(body(m, "key")?)?;
                let cut = &self.cuts()[0];
                let distal = parts.beyond(cut.at[0]);
                let j = distal.seen_from(cut.at).about_origin();
                split(m, cut, distal, k, damping(zeta, k, j), &mut log)?
            }
            Effect::KeyFlexBeam { k, zeta, .. } => {
                let parts = KeyParts::of(body(m, "key")?)?;
                let mut out = m.clone();
                let mut origin = 0.0;
                for (i, cut) in self.cuts().iter().enumerate() {
                    // The cut in the key frame, then the part beyond it in the frame of the
                    // body being cut (its origin at the previous cut).
                    let x = origin + cut.at[0];
                    let distal = parts.beyond(x).seen_from([origin, 0.0]);
                    let j = distal.seen_from(cut.at).about_origin();
                    out = split(&out, cut, distal, k[i], damping(zeta, k[i], j), &mut log)?;
                    origin = x;
                }
                out
            }
            Effect::ShankFlexMid { k, zeta, .. } => {
                let parts = HammerParts::of(body(m, "hammer")?)?;
                let cut = &self.cuts()[0];
                let distal = parts.beyond(cut.at[0]);
                let j = distal.seen_from(cut.at).about_origin();
                split(m, cut, distal, k, damping(zeta, k, j), &mut log)?
            }
            Effect::ShankFlexTwo { k, zeta, .. } => {
                let parts = HammerParts::of(body(m, "hammer")?)?;
                let mut out = m.clone();
                let mut origin = 0.0;
                for (i, cut) in self.cuts().iter().enumerate() {
                    let x = origin + cut.at[0];
                    let distal = parts.beyond(x).seen_from([origin, 0.0]);
                    let j = distal.seen_from(cut.at).about_origin();
                    out = split(&out, cut, distal, k[i], damping(zeta, k[i], j), &mut log)?;
                    origin = x;
                }
                out
            }
            Effect::BackcheckSlide { k, zeta, mass_kg } => {
                backcheck_slide(m, k, zeta, mass_kg, &mut log)?
            }
            Effect::KeybedFeltP3 {
                p,
                force_ratio_1mm,
                e,
            } => {
                let (k0, p0, e0, smoothing) = felt_of(m, "front_rail")?;
                let d: f64 = 1e-3;
                let k1 = force_ratio_1mm * k0 * d.powf(p0) / d.powf(p);
                let mut out = m.clone();
                contact_mut(&mut out, "front_rail")?.law = LawSpec::Felt {
                    k: k1,
                    p,
                    e,
                    smoothing,
                    alpha: 0.0,
                };
                log.push(format!(
                    "contact 'front_rail': Felt k = {k0:.4e}, p = {p0}, e = {e0} → Felt k = \
                     {k1:.4e} N/m^p, p = {p:.3}, e = {e:.3} (force at 1 mm × {force_ratio_1mm:.3})"
                ));
                out
            }
            Effect::KnuckleFeltHc { p, alpha } => {
                let (k0, p0, e0, _) = felt_of(m, "jack_knuckle")?;
                // The felt loads along k(1 + a)δ^p, a from its restitution; the new law's
                // elastic part goes through the same loading force at KNUCKLE_MATCH_M.
                let a = (1.0 - e0 * e0) / (1.0 + e0 * e0);
                let d = KNUCKLE_MATCH_M;
                let k1 = k0 * (1.0 + a) * d.powf(p0) / d.powf(p);
                let mut out = m.clone();
                contact_mut(&mut out, "jack_knuckle")?.law =
                    LawSpec::HuntCrossley { k: k1, p, alpha };
                log.push(format!(
                    "contact 'jack_knuckle': Felt k = {k0:.4e}, p = {p0}, e = {e0} → \
                     HuntCrossley k = {k1:.4e} N/m^p, p = {p:.3}, alpha = {alpha:.3} s/m \
                     (mbs_contact applies F = k δ^p (1 + 1.5 α δ'); loading force matched \
                     at {:.2} mm)",
                    d * 1e3
                ));
                out
            }
            Effect::KnuckleFrictionVisc {
                dmu,
                regularization,
            } => {
                let mut out = m.clone();
                let c = contact_mut(&mut out, "jack_knuckle")?;
                let mu0 = match c.friction {
                    Some(ContactFrictionSpec::Coulomb { mu, .. }) => mu,
                    None => 0.0,
                    ref other => {
                        return Err(format!(
                            "contact 'jack_knuckle' has friction {other:?}, not a coefficient"
                        ));
                    }
                };
                c.friction = Some(ContactFrictionSpec::Coulomb {
                    mu: mu0 + dmu,
                    regularization,
                });
                log.push(format!(
                    "contact 'jack_knuckle': Coulomb mu = {mu0:.4} → {:.4}, regularisation \
                     speed {regularization:.4} m/s",
                    mu0 + dmu
                ));
                out
            }
            Effect::Damper {
                front_load_gf,
                engage_fraction,
            } => damper(m, front_load_gf, engage_fraction, &mut log)?,
            Effect::MassPad { k_ratio, e } => {
                let mut out = m.clone();
                if m.bodies.iter().any(|b| b.name == "presser") {
                    let (k0, p0, e0, smoothing) = felt_of(m, "presser_key")?;
                    contact_mut(&mut out, "presser_key")?.law = LawSpec::Felt {
                        k: k0 * k_ratio,
                        p: p0,
                        e,
                        smoothing,
                        alpha: 0.0,
                    };
                    log.push(format!(
                        "contact 'presser_key': Felt k = {k0:.4e}, p = {p0}, e = {e0} → Felt \
                         k = {:.4e} N/m^p (× {k_ratio:.4}), p = {p0}, e = {e:.3}",
                        k0 * k_ratio
                    ));
                }
                out
            }
            Effect::FlangePlay { play_m } => flange_play(m, play_m, &mut log)?,
            Effect::KeyPinFriction { key_factor } => {
                let mut out = m.clone();
                for (name, factor) in [("key", key_factor), ("wippen", 3.0)] {
                    let b = out
                        .bodies
                        .iter_mut()
                        .find(|b| b.name == name)
                        .ok_or_else(|| format!("the description has no body '{name}'"))?;
                    let f = b
                        .joint
                        .friction
                        .as_mut()
                        .ok_or_else(|| format!("the joint of '{name}' has no friction"))?;
                    log.push(format!(
                        "joint '{name}': Coulomb torque {:.4e} → {:.4e} N·m (× {factor:.3})",
                        f.coulomb,
                        f.coulomb * factor
                    ));
                    f.coulomb *= factor;
                }
                out
            }
        };
        Ok((out, log))
    }
}

/// The back-check head on a prismatic slide along its face's normal, held by a linear
/// spring (a `torsion_springs` entry acts on any joint coordinate: on a slider it is a
/// linear spring, N/m).
fn backcheck_slide(
    m: &Mechanism,
    k: f64,
    zeta: f64,
    mass_kg: f64,
    log: &mut Vec<String>,
) -> Result<Mechanism, String> {
    let mut out = m.clone();
    let pair = contact_mut(&mut out, "backcheck")?;
    let side = if pair.a.body == "key" {
        &mut pair.a
    } else if pair.b.body == "key" {
        &mut pair.b
    } else {
        return Err("contact 'backcheck' has no side on the key".into());
    };
    let [ShapeSpec::Segment { a, b }] = side.shapes.as_slice() else {
        return Err(format!(
            "contact 'backcheck': expected one segment on the key, got {:?}",
            side.shapes
        ));
    };
    let (a, b) = (*a, *b);
    let centre = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
    let l = (b[0] - a[0]).hypot(b[1] - a[1]);
    // The face's outward normal: its direction turned a quarter counter-clockwise.
    let n = [-(b[1] - a[1]) / l, (b[0] - a[0]) / l];
    side.body = "backcheck_head".into();
    side.shapes = vec![ShapeSpec::Segment {
        a: [a[0] - centre[0], a[1] - centre[1]],
        b: [b[0] - centre[0], b[1] - centre[1]],
    }];
    // The head's centre of mass 5 mm behind its face [D].
    let head = Props::point(
        mass_kg,
        [centre[0] - 0.005 * n[0], centre[1] - 0.005 * n[1]],
        6e-7,
    );
    let ki = out
        .bodies
        .iter()
        .position(|b| b.name == "key")
        .ok_or("the description has no body 'key'")?;
    let rest = Props::of(&out.bodies[ki]).minus(&head);
    if !(rest.mass > 0.0 && rest.inertia > 0.0) {
        return Err(format!("backcheck_slide: the key's remainder {rest:?}"));
    }
    let key = &mut out.bodies[ki];
    key.mass = rest.mass;
    key.com = rest.com;
    key.inertia = rest.inertia;
    let local = head.seen_from(centre);
    out.bodies.insert(
        ki + 1,
        Body {
            name: "backcheck_head".into(),
            note: "independent truth: the back-check head on a prismatic slide".into(),
            mass: local.mass,
            com: local.com,
            inertia: local.inertia,
            joint: Joint {
                kind: JointType::Prismatic,
                parent: "key".into(),
                at: centre,
                angle: 0.0,
                axis: Some(n),
                limits: None,
                friction: None,
            },
            outline: Vec::new(),
        },
    );
    let c = damping(zeta, k, mass_kg);
    out.torsion_springs.push(TorsionSpring {
        name: "backcheck_head slide".into(),
        note: "independent truth: a linear spring on the slider".into(),
        joint: "backcheck_head".into(),
        stiffness: k,
        rest: 0.0,
        preload: 0.0,
        damping: c,
    });
    log.push(format!(
        "contact 'backcheck': the key's face moved to a new body 'backcheck_head' ({:.2} g) \
         on a prismatic joint on 'key' at [{:.4}, {:.4}] m, axis [{:.4}, {:.4}] (the face's \
         normal), linear spring k = {k:.1} N/m, c = {c:.4} N·s/m; the key keeps {:.2} g",
        mass_kg * 1e3,
        centre[0],
        centre[1],
        n[0],
        n[1],
        rest.mass * 1e3
    ));
    Ok(out)
}

/// A damper lever pivoted on the ground behind the key, its felt over the key's tail with
/// a gap closed after `engage_fraction` of the dip, weighted to put `front_load_gf` on the
/// key front once lifted.
fn damper(
    m: &Mechanism,
    front_load_gf: f64,
    engage_fraction: f64,
    log: &mut Vec<String>,
) -> Result<Mechanism, String> {
    let key = body(m, "key")?;
    if key.joint.parent != "ground" || key.joint.angle != 0.0 {
        return Err("damper: the key must turn on the ground, its frame world-aligned".into());
    }
    let finger_x = m
        .inputs
        .iter()
        .find(|i| i.name == "finger")
        .map(|i| i.at.point[0].abs())
        .ok_or("damper: the description has no input 'finger'")?;
    let (_, _, _, smoothing) = felt_of(m, "front_rail")?;
    let pivot = key.joint.at;
    let x_c = DAMPER_CONTACT_X_M;
    let gap = engage_fraction * KEY_DIP_MM * 1e-3 * x_c / finger_x;
    let pad_r = 0.002;
    // World positions (the key frame at rest is the world moved to the balance pivot).
    let pad = [pivot[0] + x_c, pivot[1] + KEY_TOP_Y_M + gap + pad_r];
    let lever_pivot = [pad[0] + DAMPER_ARM_M, pad[1] + 0.004];
    let g = 9.81;
    let pad_force = front_load_gf * 1e-3 * g * finger_x / x_c;
    let mass = pad_force * DAMPER_ARM_M / (g * DAMPER_COM_ARM_M);
    let inertia = mass * (0.15f64.powi(2) + 0.01f64.powi(2)) / 12.0;
    let mut out = m.clone();
    out.bodies.insert(
        root_insert_index(m),
        Body {
            name: "damper".into(),
            note: "independent truth: the damper lever the model leaves out".into(),
            mass,
            com: [-DAMPER_COM_ARM_M, 0.0],
            inertia,
            joint: Joint {
                kind: JointType::Revolute,
                parent: "ground".into(),
                at: lever_pivot,
                angle: 0.0,
                axis: None,
                // Resting on its stop (the damper on the strings) until the key lifts it.
                limits: Some(Limits {
                    lower: None,
                    upper: Some(0.0),
                    stiffness: 200.0,
                    damping: 0.05,
                }),
                friction: None,
            },
            outline: Vec::new(),
        },
    );
    out.contacts.push(ContactPair {
        name: "damper_lift".into(),
        note: "independent truth: the key's tail lifting the damper lever".into(),
        a: ContactSideSpec {
            body: "key".into(),
            shapes: vec![ShapeSpec::Segment {
                a: [0.222, KEY_TOP_Y_M],
                b: [KEY_BACK_END_M, KEY_TOP_Y_M],
            }],
        },
        b: ContactSideSpec {
            body: "damper".into(),
            shapes: vec![ShapeSpec::Circle {
                center: [-DAMPER_ARM_M, -0.004],
                radius: pad_r,
            }],
        },
        law: LawSpec::Felt {
            k: 1e7,
            p: 2.0,
            e: 0.3,
            smoothing,
            alpha: 0.0,
        },
        friction: None,
    });
    log.push(format!(
        "new body 'damper' ({:.1} g, inertia {inertia:.3e} kg·m², com {DAMPER_COM_ARM_M} m \
         toward the key) on a revolute joint on the ground at [{:.4}, {:.4}] m, resting on a \
         stop (upper limit 0, 200 N·m/rad, 0.05 N·m·s/rad); contact 'damper_lift': key top \
         [0.222..{KEY_BACK_END_M}] m × felt pad r = 2 mm at {DAMPER_ARM_M} m from the pivot, \
         gap {:.2} mm at rest ({engage_fraction:.3} of a {KEY_DIP_MM} mm dip), Felt k = 1e7, \
         p = 2, e = 0.3; {:.3} N on the key's tail = {front_load_gf:.1} gf at the key front",
        mass * 1e3,
        lever_pivot[0],
        lever_pivot[1],
        gap * 1e3,
        pad_force
    ));
    Ok(out)
}

/// The hammer on a light carrier in the flange pin's clearance: a vertical slide (the
/// carrier the brief asks for) and, on it, a horizontal one, each between stops at ±play
/// (a square clearance around the pin), 0.3 g in all. The vertical slide alone never
/// changes sides in this action (the pin's vertical load keeps one sign through the whole
/// run: the carrier rests on its upper stop), so it would only move the pin by the play;
/// the horizontal load turns over between the rise (the jack pushes the knuckle toward +x)
/// and the check (the back-check pushes the tail toward −x), which the play shows.
fn flange_play(m: &Mechanism, play_m: f64, log: &mut Vec<String>) -> Result<Mechanism, String> {
    let hi = m
        .bodies
        .iter()
        .position(|b| b.name == "hammer")
        .ok_or("the description has no body 'hammer'")?;
    let mut out = m.clone();
    let hammer = &mut out.bodies[hi];
    if hammer.joint.parent != "ground" {
        return Err("flange_play: the hammer must turn on the ground".into());
    }
    let at = hammer.joint.at;
    hammer.joint.parent = "hammer_pin_x".into();
    hammer.joint.at = [0.0, 0.0];
    let slide = |name: &str, parent: &str, at: [f64; 2], axis: [f64; 2]| Body {
        name: name.into(),
        note: "independent truth: the flange pin's play".into(),
        mass: 0.5 * CARRIER_MASS_KG,
        com: [0.0, 0.0],
        inertia: 1e-9,
        joint: Joint {
            kind: JointType::Prismatic,
            parent: parent.into(),
            at,
            angle: 0.0,
            axis: Some(axis),
            limits: Some(Limits {
                lower: Some(-play_m),
                upper: Some(play_m),
                stiffness: CARRIER_STOP_N_M,
                damping: CARRIER_STOP_N_S_M,
            }),
            friction: None,
        },
        outline: Vec::new(),
    };
    out.bodies.insert(
        hi,
        slide("hammer_pin_x", "hammer_pin_y", [0.0, 0.0], [1.0, 0.0]),
    );
    out.bodies
        .insert(hi, slide("hammer_pin_y", "ground", at, [0.0, 1.0]));
    log.push(format!(
        "new bodies 'hammer_pin_y' ({} g, a vertical prismatic joint on the ground at the \
         flange pin [{:.4}, {:.4}] m) and on it 'hammer_pin_x' ({} g, horizontal), each \
         between stops at ±{:.4} mm ({CARRIER_STOP_N_M:.0e} N/m, {CARRIER_STOP_N_S_M} N·s/m); \
         the hammer's revolute joint moved onto 'hammer_pin_x' at [0, 0]",
        0.5 * CARRIER_MASS_KG * 1e3,
        at[0],
        at[1],
        0.5 * CARRIER_MASS_KG * 1e3,
        play_m * 1e3
    ));
    Ok(out)
}

/// `m` (a grand's description) with the effect of case `case_id` at `seed` added by hand,
/// and what was done (for a drawing or a look at the edited description).
pub fn edited(case_id: &str, seed: u64, m: &Mechanism) -> Result<(Mechanism, Vec<String>), String> {
    case(case_id)?;
    Effect::draw(case_id, seed)?.apply(m)
}

/// The body and local point (m) that a marker declared on `body` at `local` (the
/// parameter file's frames) rides on after `cuts`.
fn marker_place(cuts: &[Cut], body: &str, local: [f64; 2]) -> (String, [f64; 2]) {
    let (mut b, mut p) = (body.to_string(), local);
    for c in cuts {
        if c.body == b && c.distal(p) {
            b = c.new_body.clone();
            p = c.moved(p);
        }
    }
    (b, p)
}

// ---------------------------------------------------------------------------------------
// Markers, nuisance, camera, simulation
// ---------------------------------------------------------------------------------------

/// A dataset marker: name, body, point in the parameter file's body frame (m).
#[derive(Clone, Debug, PartialEq)]
pub struct MarkerDef {
    /// Name.
    pub name: &'static str,
    /// Body.
    pub body: &'static str,
    /// Point in that body's frame of the parameter file (m).
    pub local_m: [f64; 2],
}

/// The four markers of the parameter file `params`.
pub fn markers(params: &ActionParams) -> Vec<MarkerDef> {
    let k = &params.key;
    let s = params.hammer.strike_body_mm;
    let finger = piano_action::key::KeyGeometry::of(k).finger_m();
    vec![
        MarkerDef {
            name: MARKERS[0],
            body: "key",
            local_m: finger,
        },
        MarkerDef {
            name: MARKERS[1],
            body: "key",
            local_m: [
                (k.back_pad_mm[0] - k.pivot_mm[0]) * 1e-3,
                (k.back_pad_mm[1] - k.pivot_mm[1]) * 1e-3,
            ],
        },
        MarkerDef {
            name: MARKERS[2],
            body: "hammer",
            local_m: [s[0] * 1e-3, s[1] * 1e-3],
        },
        MarkerDef {
            name: MARKERS[3],
            body: "hammer",
            local_m: [s[0] * 0.5e-3, s[1] * 0.5e-3],
        },
    ]
}

/// The file's parameters with the nuisance mismatches of `seed`: every `*.mass_g` ±3 %,
/// every `contacts.*.k` ±15 % but the hammer–string's, every `*pivot_friction_n_m` and
/// `contacts.*.mu` ±20 %; `string.*` and `numerics.*` untouched.
pub fn nuisance(
    file: &ActionParams,
    seed: u64,
) -> Result<(ActionParams, BTreeMap<String, f64>), String> {
    let mut r = Rng::stream(seed, "nuisance");
    let mut out = file.clone();
    let mut drawn = BTreeMap::new();
    let list = file
        .parameter_list(DEFAULT_PARAMS_TOML)
        .map_err(|e| format!("the parameter list: {e}"))?;
    for info in list {
        let p = info.path.as_str();
        if p.starts_with("string.") || p.starts_with("numerics.") {
            continue;
        }
        let spread = if p.ends_with(".mass_g") {
            0.03
        } else if p.starts_with("contacts.") && p.ends_with(".k") && p != "contacts.hammer_string.k"
        {
            0.15
        } else if p.ends_with("pivot_friction_n_m")
            || (p.starts_with("contacts.") && p.ends_with(".mu"))
        {
            0.20
        } else {
            continue;
        };
        let factor = 1.0 + r.range(-spread, spread);
        out.set_parameter(p, info.value * factor)
            .map_err(|e| format!("nuisance on {p}: {e}"))?;
        drawn.insert(info.path.clone(), factor);
    }
    out.validate()
        .map_err(|e| format!("the mismatched parameters: {e}"))?;
    Ok((out, drawn))
}

/// The camera of a dataset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraDraw {
    /// Declared exposure (s).
    pub declared_exposure_s: f64,
    /// The held-out run's true exposure (s): 5 % off the declared one.
    pub heldout_exposure_s: f64,
    /// AR(1) marginal SD (m).
    pub sigma_m: f64,
    /// AR(1) lag-one correlation.
    pub rho: f64,
}

fn draw_camera(seed: u64) -> CameraDraw {
    let mut r = Rng::stream(seed, "camera");
    let declared = r.range(0.5, 1.0) / FPS;
    let sigma_m = r.range(25e-6, 40e-6);
    let rho = r.range(0.6, 0.85);
    let up = r.sign() > 0.0;
    // 5 % off; a longer exposure than a frame cannot be, so then 5 % short.
    let heldout = if up && declared * 1.05 <= 1.0 / FPS {
        declared * 1.05
    } else {
        declared * 0.95
    };
    CameraDraw {
        declared_exposure_s: declared,
        heldout_exposure_s: heldout,
        sigma_m,
        rho,
    }
}

/// The id of run `i` (0 fitted, 1 held out).
fn run_label(i: usize) -> &'static str {
    if i == 0 { "fit" } else { "heldout" }
}

/// A run's clean record: the marker tracks as simulated and as the camera frames them,
/// before any tracking noise.
#[derive(Clone, Debug, PartialEq)]
pub struct CleanRun {
    /// Its id (`drop_0mm`, `drop_5mm`).
    pub id: String,
    /// `fit` or `heldout`.
    pub role: &'static str,
    /// Declared and true release heights (m).
    pub declared_height_m: f64,
    /// True release height (m).
    pub height_m: f64,
    /// Camera clock offset (s).
    pub offset_s: f64,
    /// True exposure (s).
    pub exposure_s: f64,
    /// The simulation's output times (s).
    pub sim_t: Vec<f64>,
    /// Per marker, the world position of the physical point on the simulation's grid (m);
    /// a slipping target's slip is not in it.
    pub sim_tracks: Vec<Vec<[f64; 2]>>,
    /// Frame times (s).
    pub frame_t: Vec<f64>,
    /// Per marker, per frame: what the camera records without tracking noise (m).
    pub frames: Vec<Vec<[f64; 2]>>,
    /// The first back-check catch after the strike (s).
    pub check_catch_s: Option<f64>,
}

/// Everything of a dataset before the tracking noise.
#[derive(Clone, Debug)]
pub struct Clean {
    /// The case.
    pub case: Case,
    /// The truth's parameters (the file with the nuisance).
    pub params: ActionParams,
    /// The nuisance factors.
    pub nuisance: BTreeMap<String, f64>,
    /// The camera.
    pub camera: CameraDraw,
    /// The case's drawn values.
    pub effect_values: BTreeMap<String, f64>,
    /// The edits made to the description (with the presser of the first run).
    pub edits: Vec<String>,
    /// The runs.
    pub runs: Vec<CleanRun>,
    effect: Effect,
}

fn piano_err(what: &str) -> impl Fn(PianoError) -> String + '_ {
    move |e| format!("{what}: {e}")
}

/// Linear interpolation of a track at `s` (held before the first and after the last
/// sample).
fn interp(t: &[f64], track: &[[f64; 2]], s: f64) -> [f64; 2] {
    let i = t.partition_point(|&x| x <= s);
    if i == 0 {
        return track[0];
    }
    if i >= t.len() {
        return track[track.len() - 1];
    }
    let u = (s - t[i - 1]) / (t[i] - t[i - 1]);
    let (a, b) = (track[i - 1], track[i]);
    [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])]
}

/// What a frame stamped `t` records of `position(time)`: its mean over the exposure
/// `[t + τ, t + τ + exposure]`, by the midpoint rule.
fn expose(t: f64, offset: f64, exposure: f64, position: impl Fn(f64) -> [f64; 2]) -> [f64; 2] {
    let mut sum = [0.0; 2];
    for i in 0..EXPOSURE_POINTS {
        let s = t + offset + exposure * (i as f64 + 0.5) / EXPOSURE_POINTS as f64;
        let p = position(s);
        sum[0] += p[0];
        sum[1] += p[1];
    }
    let n = EXPOSURE_POINTS as f64;
    [sum[0] / n, sum[1] / n]
}

/// A simulated run's output times, per point its world track, and the first check catch.
type Simulated = (Vec<f64>, Vec<Vec<[f64; 2]>>, Option<f64>);

/// Simulates the case's action (`params`, the effect added by hand) for a mass released
/// from `height_m`, and records the world positions of `points` (body, local point in the
/// parameter file's frames) on the simulation's grid; also the first check catch.
fn simulate_points(
    params: &ActionParams,
    effect: &Effect,
    height_m: f64,
    duration_s: f64,
    points: &[(&str, [f64; 2])],
) -> Result<Simulated, String> {
    let input = Input::MassDrop {
        mass_kg: MASS_KG,
        height_m,
    };
    let transform = |m: &Mechanism| -> piano_action::Result<Mechanism> {
        effect
            .apply(m)
            .map(|(m, _)| m)
            .map_err(PianoError::Simulation)
    };
    let run = simulate_transformed(
        params,
        KIND,
        &input,
        duration_s + SIM_MARGIN_S,
        SIM_STEP_S,
        Some(&transform),
        &mut |_| {},
    )
    .map_err(piano_err("simulation"))?;
    let prepared = prepare_transformed(params, KIND, &input, Some(&transform))
        .map_err(piano_err("the action's system"))?;
    let system = &prepared.action.system;
    let model = system.model();
    let cuts = effect.cuts();
    let mut placed = Vec::new();
    for (body, local) in points {
        let (b, p) = marker_place(&cuts, body, *local);
        let frame = model
            .frame_id(&b)
            .map_err(|e| format!("marker on '{b}': {e}"))?;
        placed.push(mbs_core::frame_point(model, frame, p));
    }
    let sol = &run.solution;
    if sol.t.is_empty() {
        return Err("the simulation gave no output".into());
    }
    let mut ws = system.workspace();
    let mut tracks = vec![Vec::with_capacity(sol.len()); points.len()];
    for i in 0..sol.len() {
        let ctx = system
            .kinematics(&mut ws, sol.t[i], sol.state(i))
            .map_err(|e| format!("kinematics at t = {} s: {e}", sol.t[i]))?;
        for (track, &(b, p)) in tracks.iter_mut().zip(&placed) {
            track.push(ctx.point_position(b, p));
        }
    }
    Ok((sol.t.clone(), tracks, run.check_time_s))
}

/// A run's id from its declared height.
fn run_id(declared_m: f64) -> String {
    format!("drop_{}mm", (declared_m * 1e3).round() as i64)
}

/// The clean records of case `case_id` at `seed`: nuisance, camera, heights and the
/// case's effect drawn, each run simulated and framed without tracking noise.
pub fn clean(case_id: &str, seed: u64, options: &GenOptions) -> Result<Clean, String> {
    let case = case(case_id)?;
    if !(options.duration_s.is_finite() && (0.05..=2.0).contains(&options.duration_s)) {
        return Err(format!("duration {} s: 0.05 to 2 s", options.duration_s));
    }
    let file = ActionParams::reference();
    if !(options.relative_tolerance.is_finite()
        && (1e-12..=1e-3).contains(&options.relative_tolerance))
    {
        return Err(format!(
            "relative tolerance {}: 1e-12 to 1e-3",
            options.relative_tolerance
        ));
    }
    let (mut params, nuisance) = nuisance(&file, seed)?;
    params.numerics.relative_tolerance = options.relative_tolerance;
    params.numerics.absolute_tolerance = options.relative_tolerance * 1e-3;
    let camera = draw_camera(seed);
    let effect = Effect::draw(case_id, seed)?;
    let defs = markers(&file);
    let n_runs = match options.heights {
        Heights::Both => 2,
        Heights::FittedOnly => 1,
    };
    let frames = (options.duration_s * FPS).round() as usize;
    let frame_t: Vec<f64> = (0..frames).map(|k| k as f64 / FPS).collect();
    let mut runs = Vec::new();
    let mut edits = Vec::new();
    for (i, &declared) in DECLARED_HEIGHTS_M.iter().enumerate().take(n_runs) {
        let mut r = Rng::stream(seed, &format!("run:{}", run_label(i)));
        let height = if i == 0 {
            r.range(0.0, 0.3e-3)
        } else {
            declared + r.range(-0.3e-3, 0.3e-3)
        };
        let offset = r.range(-0.25e-3, 0.25e-3);
        let exposure = if i == 0 {
            camera.declared_exposure_s
        } else {
            camera.heldout_exposure_s
        };
        if i == 0 {
            let presser = piano_action::Presser::weight(MASS_KG, height * 1e3);
            let grand = piano_action::describe::grand_mechanism(&params, KIND, Some(presser))
                .map_err(piano_err("the grand's description"))?;
            edits = effect.apply(&grand)?.1;
        }
        let mut points: Vec<(&str, [f64; 2])> = defs.iter().map(|d| (d.body, d.local_m)).collect();
        let slip = match effect {
            Effect::MarkerSlip { slip_m } => Some(slip_m),
            _ => None,
        };
        if let Some(s) = slip {
            let h = &defs[HEAD];
            points.push((h.body, [h.local_m[0] + s, h.local_m[1]]));
        }
        let (sim_t, mut tracks, check) =
            simulate_points(&params, &effect, height, options.duration_s, &points)?;
        let slipped = if slip.is_some() { tracks.pop() } else { None };
        let mut framed = Vec::new();
        for (m, track) in tracks.iter().enumerate() {
            let f: Vec<[f64; 2]> = frame_t
                .iter()
                .map(|&t| {
                    expose(t, offset, exposure, |s| match (&slipped, check) {
                        (Some(sl), Some(tc)) if m == HEAD && s >= tc => interp(&sim_t, sl, s),
                        _ => interp(&sim_t, track, s),
                    })
                })
                .collect();
            framed.push(f);
        }
        runs.push(CleanRun {
            id: run_id(declared),
            role: run_label(i),
            declared_height_m: declared,
            height_m: height,
            offset_s: offset,
            exposure_s: exposure,
            sim_t,
            sim_tracks: tracks,
            frame_t: frame_t.clone(),
            frames: framed,
            check_catch_s: check,
        });
    }
    Ok(Clean {
        case,
        params,
        nuisance,
        camera,
        effect_values: effect.values(),
        edits,
        runs,
        effect,
    })
}

// ---------------------------------------------------------------------------------------
// Tracking noise and writing
// ---------------------------------------------------------------------------------------

/// A run's tracked frames: per marker, per frame, a position or `None` (lost); and what
/// went wrong.
type Tracked = (
    Vec<Vec<Option<[f64; 2]>>>,
    Vec<TruthOutlier>,
    Vec<TruthLost>,
);

/// The camera's tracker on a run's clean frames: AR(1) noise per coordinate, 0.3 % of
/// (frame, marker) pairs with a gross error of 8–12 σ on one coordinate, 0.1 % lost.
fn track(seed: u64, run: usize, camera: &CameraDraw, clean: &[Vec<[f64; 2]>]) -> Tracked {
    let mut r = Rng::stream(seed, &format!("noise:{}", run_label(run)));
    let (sigma, rho) = (camera.sigma_m, camera.rho);
    let innovation = sigma * (1.0 - rho * rho).sqrt();
    let mut out: Vec<Vec<Option<[f64; 2]>>> = Vec::new();
    for frames in clean {
        let mut e = [sigma * r.normal(), sigma * r.normal()];
        let mut noisy = Vec::with_capacity(frames.len());
        for (k, p) in frames.iter().enumerate() {
            if k > 0 {
                e = [
                    rho * e[0] + innovation * r.normal(),
                    rho * e[1] + innovation * r.normal(),
                ];
            }
            noisy.push(Some([p[0] + e[0], p[1] + e[1]]));
        }
        out.push(noisy);
    }
    let frames = clean.first().map_or(0, Vec::len);
    let (mut outliers, mut lost) = (Vec::new(), Vec::new());
    for k in 0..frames {
        for (m, track) in out.iter_mut().enumerate() {
            if r.uniform() < 0.003 {
                let axis = usize::from(r.uniform() >= 0.5);
                let sigmas = r.sign() * r.range(8.0, 12.0);
                if let Some(p) = track[k].as_mut() {
                    p[axis] += sigmas * sigma;
                }
                outliers.push(TruthOutlier {
                    frame: k,
                    marker: MARKERS[m].into(),
                    axis: ["x", "y"][axis].into(),
                    sigmas,
                });
            }
            if r.uniform() < 0.001 {
                track[k] = None;
                lost.push(TruthLost {
                    frame: k,
                    marker: MARKERS[m].into(),
                });
            }
        }
    }
    (out, outliers, lost)
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("cannot write {}: {e}", path.display()))
}

/// Generates the dataset of case `case_id` at `seed` into `dir` (`dataset.json` and one
/// CSV per run; created if missing, its files of the same names replaced) and its truth
/// into `truth_path` (which must not lie inside `dir`); returns the truth.
pub fn generate(
    case_id: &str,
    seed: u64,
    dir: &Path,
    truth_path: &Path,
    options: &GenOptions,
) -> Result<TruthRecord, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let canon_dir = dir
        .canonicalize()
        .map_err(|e| format!("cannot resolve {}: {e}", dir.display()))?;
    let truth_parent = match truth_path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    std::fs::create_dir_all(&truth_parent)
        .map_err(|e| format!("cannot create {}: {e}", truth_parent.display()))?;
    let canon_truth = truth_parent
        .canonicalize()
        .map_err(|e| format!("cannot resolve {}: {e}", truth_parent.display()))?;
    if canon_truth.starts_with(&canon_dir) {
        return Err(format!(
            "the truth {} lies inside the dataset's folder {}: keep it out",
            truth_path.display(),
            dir.display()
        ));
    }

    let clean = clean(case_id, seed, options)?;
    let file = ActionParams::reference();
    let defs = markers(&file);
    let mut run_specs = Vec::new();
    let mut truth_runs = Vec::new();
    for (i, run) in clean.runs.iter().enumerate() {
        let (tracked, outliers, lost) = track(seed, i, &clean.camera, &run.frames);
        let mut csv = String::from("time_s");
        for m in MARKERS {
            let _ = write!(csv, ",{m}_x_m,{m}_y_m");
        }
        csv.push('\n');
        for (k, t) in run.frame_t.iter().enumerate() {
            let _ = write!(csv, "{t:.9}");
            for m in &tracked {
                match m[k] {
                    Some([x, y]) => {
                        let _ = write!(csv, ",{x:.9},{y:.9}");
                    }
                    None => csv.push_str(",,"),
                }
            }
            csv.push('\n');
        }
        let file_name = format!("{}.csv", run.id);
        write(&dir.join(&file_name), &csv)?;
        run_specs.push(serde_json::json!({
            "id": run.id,
            "file": file_name,
            "role": run.role,
            "conditions": {
                "mass_kg": MASS_KG,
                "release_height_m": run.declared_height_m,
            },
        }));
        truth_runs.push(TruthRun {
            id: run.id.clone(),
            role: run.role.into(),
            declared_release_height_m: run.declared_height_m,
            release_height_m: run.height_m,
            offset_s: run.offset_s,
            exposure_s: run.exposure_s,
            check_catch_s: run.check_catch_s,
            outliers,
            lost,
        });
    }
    let dataset = serde_json::json!({
        "schema_version": 1,
        "experiment": "key_drive",
        "description": format!(
            "independent synthetic key drive (tests/truths), {MASS_KG} kg released on the \
             key, seed {seed}; what is hidden in it is in its truth file"
        ),
        "fps": FPS,
        "exposure_s": clean.camera.declared_exposure_s,
        "markers": defs.iter().map(|d| serde_json::json!({
            "name": d.name,
            "body": d.body,
            "local_m": d.local_m,
            "sigma_m": DECLARED_SIGMA_M,
        })).collect::<Vec<_>>(),
        "drive": MARKERS[0],
        "runs": run_specs,
    });
    let text = serde_json::to_string_pretty(&dataset).map_err(|e| format!("dataset.json: {e}"))?;
    write(&dir.join("dataset.json"), &(text + "\n"))?;

    let record = TruthRecord {
        generator: "piano-action/tests/truths (independent of the library's synthesiser)".into(),
        case: clean.case.id.into(),
        about: clean.case.about.into(),
        expected: clean.case.expected.label(),
        seed,
        effect: clean.effect_values.clone(),
        edits: clean.edits.clone(),
        nuisance: clean.nuisance.clone(),
        camera: TruthCamera {
            fps: FPS,
            declared_exposure_s: clean.camera.declared_exposure_s,
            declared_sigma_m: DECLARED_SIGMA_M,
            sigma_m: clean.camera.sigma_m,
            rho: clean.camera.rho,
        },
        runs: truth_runs,
    };
    let text = serde_json::to_string_pretty(&record).map_err(|e| format!("truth: {e}"))?;
    write(truth_path, &(text + "\n"))?;
    Ok(record)
}
