//! The description's types: what a TOML or JSON mechanism file holds.
//!
//! Units are SI throughout (m, kg, kg·m², rad, N, N·m, s). Every body has its own frame, the
//! frame of the joint that carries it; the body's centre of mass, outline, contact shapes,
//! markers and attachment points are given in that frame. A joint's frame is placed in its
//! parent's frame (the world for a body on the ground) by a rotation `angle` and an offset
//! `at`. Unknown fields are refused so a misspelt field is never silently ignored.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

/// The name by which files refer to the fixed world.
pub const GROUND: &str = "ground";

/// A planar mechanism: bodies on a tree of joints, the force elements between them, where
/// it is driven, and what to measure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mechanism {
    /// Its name (`"grand double escapement"`).
    pub name: String,
    /// Free text: what it is, where its numbers come from.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub about: String,
    /// Gravity in world coordinates (m/s²).
    pub gravity: [f64; 2],
    /// Outlines of fixed parts (rails, buttons, the frame), for drawings only.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub ground: Vec<OutlinePart>,
    /// The moving bodies, each with the joint that carries it; coordinates are numbered in
    /// this order, and a body's parent comes before it.
    pub bodies: Vec<Body>,
    /// Torsion (or linear, on a slider) springs on joints.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torsion_springs: Vec<TorsionSpring>,
    /// Springs between two points.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub point_springs: Vec<PointSpring>,
    /// Cords that only pull (a bridle tape).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub cords: Vec<CordSpec>,
    /// Constant forces (a weight carried by something outside the mechanism).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub loads: Vec<LoadSpec>,
    /// Contact pairs: a shape on each side and a law.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contacts: Vec<ContactPair>,
    /// Strikers on modal strings (their internal states end the state vector).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub strings: Vec<StringPair>,
    /// Force elements provided by the program that reads the file (see
    /// [`crate::Extensions`]); each names its kind.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub extensions: Vec<Extension>,
    /// Where a finger, a force, a weight or a prescribed motion acts.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<Input>,
    /// Named points on bodies (what a camera tracks, what a metric measures).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub markers: Vec<Marker>,
    /// Named events: a contact's onset or release, a coordinate crossing a value.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<EventSpec>,
    /// Named measurements: a marker's speed at an event, a coordinate's extreme.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub metrics: Vec<Metric>,
}

/// A moving body and the joint that carries it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Body {
    /// Name of the body and of its joint (and coordinate).
    pub name: String,
    /// Where its numbers come from (tags \[V\] read, \[S\] secondhand, \[M\] recalled,
    /// \[D\] derived), or any remark.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// Mass (kg, > 0).
    pub mass: f64,
    /// Centre of mass in the body frame (m).
    pub com: [f64; 2],
    /// Rotational inertia about the centre of mass (kg·m², > 0).
    pub inertia: f64,
    /// The joint that carries it.
    pub joint: Joint,
    /// Its outline for drawings and the 3D view, in the body frame.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outline: Vec<OutlinePart>,
}

/// The kind of a joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointType {
    /// Rotation about z (coordinate in rad, positive counter-clockwise).
    Revolute,
    /// Translation along `axis` (coordinate in m).
    Prismatic,
    /// No relative motion: the body is merged into its parent (no coordinate).
    Fixed,
}

/// A joint: its kind, where it sits, its stops and its friction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Joint {
    /// Revolute, prismatic or fixed.
    pub kind: JointType,
    /// The parent body, or `"ground"` (the default).
    #[serde(default = "ground_name", skip_serializing_if = "is_ground")]
    pub parent: String,
    /// Origin of the joint (and body) frame in the parent's frame (m): the pivot.
    pub at: [f64; 2],
    /// Rotation of the frame relative to the parent's (rad).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub angle: f64,
    /// Sliding direction in the joint frame (prismatic only; unit length).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 2]>,
    /// Stops: stiff one-sided springs beyond the limits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits: Option<Limits>,
    /// Friction in the pivot (or slide).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<PivotFrictionSpec>,
}

fn ground_name() -> String {
    GROUND.to_string()
}

fn is_ground(s: &str) -> bool {
    s == GROUND
}

fn is_zero(v: &f64) -> bool {
    *v == 0.0
}

/// A joint's stops.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// Lower limit of the coordinate (rad or m); none = no stop below.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<f64>,
    /// Upper limit; none = no stop above.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<f64>,
    /// Stiffness of the stop (N·m/rad or N/m).
    pub stiffness: f64,
    /// Damping of the stop (N·m·s/rad or N·s/m).
    pub damping: f64,
}

/// Friction in a pivot: regularised Coulomb, optionally with viscous and Stribeck parts.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PivotFrictionSpec {
    /// Coulomb torque (N·m, or N on a slider), ≥ 0.
    pub coulomb: f64,
    /// Regularisation speed of the `tanh` (rad/s or m/s), > 0.
    pub regularization: f64,
    /// Viscous coefficient (N·m·s/rad), ≥ 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub viscous: f64,
    /// Breakaway torque above the Coulomb level, and its speed scale.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stribeck: Option<StribeckSpec>,
}

/// The Stribeck peak of pivot friction.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StribeckSpec {
    /// Breakaway (static) torque, ≥ the Coulomb torque.
    pub static_torque: f64,
    /// Stribeck speed (rad/s), > 0.
    pub velocity: f64,
}

/// One part of an outline: a closed polygon or a circle, extruded to `thickness` around the
/// plane `z` for the 3D view.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutlinePart {
    /// What the part is (`"shank"`, `"front rail"`), shown in drawings.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub name: String,
    /// Corners of a closed polygon (m), in order; at least three.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<[f64; 2]>,
    /// A circle instead of a polygon.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub circle: Option<CircleSpec>,
    /// Thickness across the plane (m), > 0.
    pub thickness: f64,
    /// Offset of its mid-plane from the mechanism's plane (m).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub z: f64,
    /// Colour for drawings (`"#8b5a2b"`); a default by body otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<String>,
}

/// A circle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CircleSpec {
    /// Centre (m).
    pub center: [f64; 2],
    /// Radius (m), > 0.
    pub radius: f64,
}

/// A joint torsion spring (a linear spring on a slider):
/// `τ = preload − k (q − rest) − c q̇`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TorsionSpring {
    /// Its name.
    pub name: String,
    /// Where its numbers come from (tags \[V\] read, \[S\] secondhand, \[M\] recalled,
    /// \[D\] derived), or any remark.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// The body whose joint it acts on.
    pub joint: String,
    /// Stiffness (N·m/rad), ≥ 0.
    pub stiffness: f64,
    /// Rest value of the coordinate (rad).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub rest: f64,
    /// Torque at the rest value, signed along the coordinate (N·m).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub preload: f64,
    /// Damping (N·m·s/rad), ≥ 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub damping: f64,
}

/// A point on a body (or on the ground, in world coordinates).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyPoint {
    /// The body, or `"ground"`.
    pub body: String,
    /// The point in the body frame (m).
    pub point: [f64; 2],
}

/// A spring between two points: tension `T = preload + k (l − rest_length) + c l̇`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PointSpring {
    /// Its name.
    pub name: String,
    /// Where its numbers come from (tags \[V\] read, \[S\] secondhand, \[M\] recalled,
    /// \[D\] derived), or any remark.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// One end.
    pub a: BodyPoint,
    /// The other end.
    pub b: BodyPoint,
    /// Stiffness (N/m), ≥ 0.
    pub stiffness: f64,
    /// Rest length (m), ≥ 0.
    pub rest_length: f64,
    /// Tension at rest length (N).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub preload: f64,
    /// Damping (N·s/m), ≥ 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub damping: f64,
}

/// A cord that only pulls: tension `k (l − length) + c l̇` when longer than `length`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CordSpec {
    /// Its name.
    pub name: String,
    /// Where its numbers come from (tags \[V\] read, \[S\] secondhand, \[M\] recalled,
    /// \[D\] derived), or any remark.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// One end.
    pub a: BodyPoint,
    /// The other end.
    pub b: BodyPoint,
    /// Slack length (m), > 0.
    pub length: f64,
    /// Stiffness when taut (N/m), ≥ 0.
    pub stiffness: f64,
    /// Damping when taut (N·s/m), ≥ 0.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub damping: f64,
}

/// A constant force at a body point, its direction fixed in the world.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Its name.
    pub name: String,
    /// Where its numbers come from (tags \[V\] read, \[S\] secondhand, \[M\] recalled,
    /// \[D\] derived), or any remark.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// Where it acts.
    pub at: BodyPoint,
    /// Its direction in the world (unit length).
    pub direction: [f64; 2],
    /// Its magnitude (N).
    pub magnitude: f64,
}

/// A contact shape in its body's frame (m, rad).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ShapeSpec {
    /// A disc.
    Circle {
        /// Centre.
        center: [f64; 2],
        /// Radius, > 0.
        radius: f64,
    },
    /// A flat face from `a` to `b`; its outward side is on the left of `a → b` (the normal
    /// is the direction turned a quarter counter-clockwise).
    Segment {
        /// Start.
        a: [f64; 2],
        /// End.
        b: [f64; 2],
    },
    /// A circular arc from angle `start` sweeping counter-clockwise by `sweep`.
    Arc {
        /// Centre.
        center: [f64; 2],
        /// Radius, > 0.
        radius: f64,
        /// Start angle (rad).
        start: f64,
        /// Sweep (rad), in (0, 2π].
        sweep: f64,
        /// Which side is the surface: `"convex"` (the rim of a solid round, touched from
        /// outside) or `"concave"` (a round hollow, touched from inside).
        side: ArcSideSpec,
    },
    /// A polyline of flat faces through `points`, each facing left of its direction.
    Profile {
        /// The corners, at least two.
        points: Vec<[f64; 2]>,
    },
}

/// Which side of an arc is the surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ArcSideSpec {
    /// The rim of a solid round, touched from outside.
    Convex,
    /// The inside of a round hollow, touched from inside.
    Concave,
}

/// One side of a contact pair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSideSpec {
    /// The body, or `"ground"`.
    pub body: String,
    /// Its shapes, in the body frame.
    pub shapes: Vec<ShapeSpec>,
}

/// The normal law of a contact: a material preset by name, or a law with its parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum LawSpec {
    /// A preset of `mbs_contact::materials` by name: `hammer_felt`, `hammer_felt_stulov`,
    /// `action_felt`, `cloth`, `buckskin`, `wood`, `metal`.
    Material(String),
    /// Rate-independent hysteretic felt `F = k δᵖ (1 ± h)`, given by its restitution `e`;
    /// `smoothing` is the speed (m/s) over which the loading/unloading switch is smoothed.
    /// A loss that also grows with the rate adds a Hunt–Crossley term, `alpha`:
    /// `F = k δᵖ (1 ± h + (3/2) α δ̇)` (`mbs_contact::laws::HystereticFelt`).
    Felt {
        /// Stiffness (N/mᵖ).
        k: f64,
        /// Exponent.
        p: f64,
        /// Restitution, in (0, 1].
        e: f64,
        /// Smoothing speed (m/s), > 0.
        smoothing: f64,
        /// Hunt–Crossley damping factor (s/m), ≥ 0; 0 (the default, not written) for a
        /// rate-independent felt.
        #[serde(default, skip_serializing_if = "is_zero")]
        alpha: f64,
    },
    /// Elastic power law `F = k δᵖ`.
    Hertz {
        /// Stiffness (N/mᵖ).
        k: f64,
        /// Exponent.
        p: f64,
    },
    /// Linear spring and dashpot.
    KelvinVoigt {
        /// Stiffness (N/m).
        k: f64,
        /// Damping (N·s/m).
        c: f64,
    },
    /// Power law with Hunt–Crossley damping `F = k δᵖ (1 + (3/2) α δ̇)` (Hunt & Crossley's
    /// material constant α; `mbs_contact::laws::HuntCrossley`).
    HuntCrossley {
        /// Stiffness (N/mᵖ).
        k: f64,
        /// Exponent.
        p: f64,
        /// Damping (s/m).
        alpha: f64,
    },
    /// Stulov's hereditary felt, from its static stiffness.
    Stulov {
        /// Static stiffness (N/mᵖ).
        q0: f64,
        /// Exponent.
        p: f64,
        /// Hereditary amplitude ε, in [0, 1).
        epsilon: f64,
        /// Relaxation time (s).
        tau0: f64,
    },
}

/// Friction at a contact.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ContactFrictionSpec {
    /// Regularised Coulomb friction `μ`, with regularisation speed (m/s).
    Coulomb {
        /// Friction coefficient, ≥ 0.
        mu: f64,
        /// Regularisation speed (m/s), > 0.
        regularization: f64,
    },
    /// The friction of a material preset (kinetic and static coefficients, Stribeck).
    Material {
        /// The preset's name.
        name: String,
        /// Regularisation speed (m/s), > 0.
        regularization: f64,
    },
}

/// A contact pair.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactPair {
    /// Its name (`"capstan_heel"`).
    pub name: String,
    /// Where its numbers come from (tags \[V\] read, \[S\] secondhand, \[M\] recalled,
    /// \[D\] derived), or any remark.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// The first side.
    pub a: ContactSideSpec,
    /// The second side.
    pub b: ContactSideSpec,
    /// The normal law.
    pub law: LawSpec,
    /// Friction, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<ContactFrictionSpec>,
}

/// A striker on a modal string lying along a fixed line.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StringPair {
    /// Its name (`"hammer_string"`).
    pub name: String,
    /// Where its numbers come from (tags \[V\] read, \[S\] secondhand, \[M\] recalled,
    /// \[D\] derived), or any remark.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// The string at rest: a ground segment in world coordinates whose outward side faces
    /// the striker.
    pub line: [[f64; 2]; 2],
    /// The striker's body and shapes.
    pub striker: ContactSideSpec,
    /// The striker's felt (elastic laws: the string's motion gives the rebound).
    pub law: LawSpec,
    /// The string.
    pub string: StringModes,
}

/// A string's physical description (see `mbs_contact::StringSpec`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StringModes {
    /// Speaking length (m).
    pub length_m: f64,
    /// Fundamental of the ideal string (Hz).
    pub fundamental_hz: f64,
    /// Mass of one string's speaking length (kg), or derived from the tension.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass_kg: Option<f64>,
    /// Tension of one string (N), or derived from the mass.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tension_n: Option<f64>,
    /// Inharmonicity `B` (≥ 0).
    pub inharmonicity: f64,
    /// Striking point over length, in (0, 1).
    pub striking_ratio: f64,
    /// Strings in the unison (≥ 1).
    pub strings: usize,
    /// Frequency-independent loss (1/s).
    pub loss_b1: f64,
    /// Frequency-dependent loss (s).
    pub loss_b3: f64,
    /// Number of modes, or from the default highest frequency.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub modes: Option<usize>,
    /// Whether the cut modes' static compliance is kept as a series spring.
    pub residual_compliance: bool,
}

/// A force element that the reading program provides (see [`crate::Extensions`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Extension {
    /// The kind, as the program knows it (`"flange_effect"`).
    pub kind: String,
    /// Its name or id.
    pub name: String,
    /// The body it acts on.
    pub body: String,
    /// Its parameters by name.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub params: BTreeMap<String, f64>,
}

/// What an input does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InputKind {
    /// A force along `direction` at the point (a finger, a weight, a push), its magnitude
    /// a function of time given by the scenario.
    Force,
    /// The body's coordinate is prescribed (a measured key motion).
    Motion,
}

/// Where the mechanism is driven.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Input {
    /// Its name (`"finger"`).
    pub name: String,
    /// Where its numbers come from (tags \[V\] read, \[S\] secondhand, \[M\] recalled,
    /// \[D\] derived), or any remark.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// Force or prescribed motion.
    pub kind: InputKind,
    /// Where a force acts, or the body whose coordinate a motion prescribes (its point is
    /// where the motion is measured).
    pub at: BodyPoint,
    /// World direction of a positive force or of a positive measured displacement.
    pub direction: [f64; 2],
}

/// A named point on a body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Marker {
    /// Its name (`"hammer_crown"`).
    pub name: String,
    /// Where its numbers come from (tags \[V\] read, \[S\] secondhand, \[M\] recalled,
    /// \[D\] derived), or any remark.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// The body and the point in its frame.
    pub at: BodyPoint,
}

/// Which way a crossing goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CrossingSpec {
    /// Upward.
    Rising,
    /// Downward.
    Falling,
    /// Either.
    Both,
}

/// A named event.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EventSpec {
    /// Its name (`"strike"`).
    pub name: String,
    /// A contact (or string) whose onset or release this is.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub contact: Option<String>,
    /// `"onset"` or `"release"` for a contact event.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub on: Option<ContactPhase>,
    /// A body whose coordinate crosses `value`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coordinate: Option<String>,
    /// The value the coordinate crosses (rad or m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<f64>,
    /// The direction of the coordinate's crossing (default both).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<CrossingSpec>,
}

/// Onset or release of a contact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ContactPhase {
    /// The shapes touch.
    Onset,
    /// They part.
    Release,
}

/// What a metric measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// A marker's speed (m/s).
    Speed,
    /// A marker's world x (m).
    X,
    /// A marker's world y (m).
    Y,
    /// A marker's world x velocity (m/s).
    VelocityX,
    /// A marker's world y velocity (m/s).
    VelocityY,
    /// The time of the event (s).
    Time,
}

/// A named measurement at an event.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Metric {
    /// Its name (`"hammer_speed"`).
    pub name: String,
    /// What it measures.
    pub quantity: Quantity,
    /// The marker it measures (not needed for `time`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub marker: Option<String>,
    /// The event at whose first occurrence it is read.
    pub at: String,
    /// Unit for display (`"m/s"`).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub unit: String,
}
