//! # An independent check of the narrow phase against parry2d
//!
//! Our closed-form narrow phase (`mbs_contact::proximity`, and the profile minimum of the
//! [`Contact`] element) is compared with the `f64` build of parry2d (`parry2d-f64`, a
//! dev-dependency only) on random poses and sizes. Each case draws the geometry of two
//! bodies in their own frames and a world pose for each (angles anywhere, origins within
//! ±0.3 m); both libraries get the same local numbers and the same poses, and each places
//! the shapes itself.
//!
//! Compared, A then B and B then A:
//!
//! | pair | ours | parry2d |
//! | --- | --- | --- |
//! | circle–circle | `Circle`, `Circle` | `Ball`, `Ball` |
//! | segment–circle | `Segment`, `Circle` | `Segment`, `Ball` |
//! | line–circle | `Line`, `Circle` | `HalfSpace`, `Ball` |
//! | line–segment | `Line`, `Segment` | `HalfSpace`, `Segment` |
//! | segment–segment | `Segment`, `Segment` | `Segment`, `Segment` |
//! | profile–circle | a profile of 2–5 faces in a [`Contact`], `Circle` | `Polyline`, `Ball` |
//! | profile–segment | a profile of 2–5 faces in a [`Contact`], `Segment` | `Polyline`, `Segment` |
//!
//! - the **gap** against `query::distance` when parry finds the shapes apart, against the
//!   signed `dist` of `query::contact` when they overlap;
//! - the **normal** (from A toward B) against `normal1` of `query::contact` (queried with a
//!   1 m prediction, so it also answers when apart), except for two faces apart, where
//!   parry's contact goes through GJK iterations: there the reference is the direction
//!   between parry's (closed-form) closest points;
//! - the **nearest points** against `query::closest_points` when apart, against `point1`,
//!   `point2` of `query::contact` when overlapping.
//!
//! Tolerance: **1e-9** absolute, in metres for gaps and points and for the unit normal's
//! components, on piano-action sizes: radii 0.5–30 mm, faces 2–100 mm, profiles of 2–25 mm
//! faces, gaps from 90 % of a radius pressed in to 20 mm apart with a band of ±1 µm around
//! touching (two faces: 1 µm to 20 mm apart, since nearer than that the direction between
//! two vertices is not fixed to 1e-9 by coordinates rounded to ~3e-17 m).
//! [`worst_differences_per_pair`] sweeps 10 000 cases of every pair from a fixed seed and
//! prints the worst difference of each kind; run
//! `cargo test -p mbs-contact --test parry_check -- --nocapture` to see them. The
//! `proptest!` tests draw further cases and shrink a failure to a small one.
//!
//! The cases are the ones where both libraries answer the same question. Our faces are
//! one-sided: a segment is solid on its right, in the strip behind it at any depth; a line
//! is a half-plane; a profile's gap is the smallest over its faces. parry's segments and
//! polylines are thin and two-sided. So each case is drawn from a feature of A (a point
//! inside a face, or a vertex) and a direction in the normal cone of A's faces with their
//! strips there, and B is put in front of it along that direction, beyond the line across
//! it: the nearest points are unique and neither body is inside the other. The strips of a
//! profile's end faces can still cross beneath it and reach around; a draw that puts a
//! vertex or a circle's centre of one body in the strip behind a face of the other is drawn
//! again ([`Drawn::clear`]; the sweep prints how many). Overlap is compared where it has one
//! meaning: a circle pressed into a circle, a face or a profile with its centre still in
//! front, and a segment's vertex under a line (a half-space in parry, exact). Two crossing
//! faces are left out: our gap is the depth of the deepest vertex under the other face, a
//! vertex–face contact; parry's is the minimum translation separating two thin segments,
//! found by EPA iterations: different definitions.
//!
//! parry 0.31 answers `query::contact` with a half-space second as if the relative pose
//! were inverted ([`parry_needs_the_half_space_first`]), so a line second is asked first
//! and the answer flipped.
//!
//! Arcs are not compared: parry2d has no circular arc, and a ball stands only for a full
//! round. A polyline through an arc differs from it by its chordal error R(1 − cos(π/N)),
//! 37 nm for R = 30 mm at N = 2000 chords per turn; 1e-9 would take over 12 000 chords per
//! turn, and would then check the tessellation more than our arcs. The arcs are covered by
//! the hand-computed cases and the invariance properties in `tests/geometry.rs`.

use std::f64::consts::PI;
use std::fmt;

use mbs_contact::laws::KelvinVoigt;
use mbs_contact::{Contact, ContactSide, Proximity, Shape, proximity};
use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement, System, Transform};
use parry2d_f64::math::{Pose, Vector};
use parry2d_f64::query::{self, ClosestPoints};
use parry2d_f64::shape::{self as pshape, Ball, HalfSpace, Polyline};
use proptest::prelude::*;
use proptest::strategy::ValueTree;
use proptest::test_runner::TestRunner;

/// The largest absolute difference accepted (m for gaps and points; unit normals).
const TOL: f64 = 1e-9;
/// A millimetre (m).
const MM: f64 = 1e-3;
/// parry's contact prediction: anything nearer than this answers (m).
const PREDICTION: f64 = 1.0;
/// Cases per pair in the seeded sweep.
const SWEEP: usize = 10_000;

// ---------------------------------------------------------------------------------------
// Small vector helpers.

fn add(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] + b[0], a[1] + b[1]]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn scale(k: f64, a: [f64; 2]) -> [f64; 2] {
    [k * a[0], k * a[1]]
}

fn norm(a: [f64; 2]) -> f64 {
    a[0].hypot(a[1])
}

/// The unit vector at `angle` (rad) from the x axis.
fn unit(angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c, s]
}

/// `v` turned by `angle` (rad) counter-clockwise.
fn turn(v: [f64; 2], angle: f64) -> [f64; 2] {
    let (s, c) = angle.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// `v` turned a quarter counter-clockwise: the outward normal of a face along `v`.
fn left(v: [f64; 2]) -> [f64; 2] {
    [-v[1], v[0]]
}

fn vector(p: [f64; 2]) -> Vector {
    Vector::new(p[0], p[1])
}

fn array(v: Vector) -> [f64; 2] {
    [v.x, v.y]
}

// ---------------------------------------------------------------------------------------
// Bodies: geometry in the body frame and a world pose, for both libraries.

/// Geometry in a body's own frame.
#[derive(Clone, Debug)]
enum Geom {
    Circle {
        center: [f64; 2],
        radius: f64,
    },
    /// Boundary of the half-plane on the side opposite `normal` (unit).
    Line {
        point: [f64; 2],
        normal: [f64; 2],
    },
    /// A face from `a` to `b`, solid on its right.
    Segment {
        a: [f64; 2],
        b: [f64; 2],
    },
    /// A profile: the faces `v[0]→v[1]`, `v[1]→v[2]`, …
    Profile(Vec<[f64; 2]>),
}

impl Geom {
    /// The same geometry with points mapped by `t` (a rigid motion).
    fn mapped(&self, t: &Transform) -> Geom {
        let p = |v: [f64; 2]| t.transform_point(v);
        match self {
            Geom::Circle { center, radius } => Geom::Circle {
                center: p(*center),
                radius: *radius,
            },
            Geom::Line { point, normal } => Geom::Line {
                point: p(*point),
                normal: t.rotate(*normal),
            },
            Geom::Segment { a, b } => Geom::Segment { a: p(*a), b: p(*b) },
            Geom::Profile(v) => Geom::Profile(v.iter().map(|&x| p(x)).collect()),
        }
    }
}

/// A body: its geometry in its frame, and its world pose `[angle, x, y]`.
#[derive(Clone, Debug)]
struct Body {
    geom: Geom,
    pose: [f64; 3],
}

impl Body {
    fn transform(&self) -> Transform {
        Transform::new(self.pose[0], self.pose[1], self.pose[2])
    }

    /// Our shapes, placed in the world.
    fn shapes(&self) -> Vec<Shape> {
        let local = match &self.geom {
            Geom::Circle { center, radius } => vec![Shape::circle(*center, *radius)],
            Geom::Line { point, normal } => vec![Shape::line(*point, *normal)],
            Geom::Segment { a, b } => vec![Shape::segment(*a, *b)],
            Geom::Profile(v) => v.windows(2).map(|f| Shape::segment(f[0], f[1])).collect(),
        };
        let t = self.transform();
        local.into_iter().map(|s| s.unwrap().placed(&t)).collect()
    }

    /// parry's shape and its world pose (the circle's and line's own origins placed by
    /// parry from the body pose).
    fn parry(&self) -> (Pose, Box<dyn pshape::Shape>) {
        let pose = Pose::new(Vector::new(self.pose[1], self.pose[2]), self.pose[0]);
        match &self.geom {
            Geom::Circle { center, radius } => (
                pose * Pose::translation(center[0], center[1]),
                Box::new(Ball::new(*radius)),
            ),
            Geom::Line { point, normal } => (
                pose * Pose::translation(point[0], point[1]),
                Box::new(HalfSpace::new(vector(*normal))),
            ),
            Geom::Segment { a, b } => {
                (pose, Box::new(pshape::Segment::new(vector(*a), vector(*b))))
            }
            Geom::Profile(v) => (
                pose,
                Box::new(Polyline::new(v.iter().map(|&p| vector(p)).collect(), None)),
            ),
        }
    }

    fn is_face(&self) -> bool {
        matches!(self.geom, Geom::Segment { .. } | Geom::Profile(_))
    }
}

/// A drawn case: A's geometry, B's geometry in A's frame, and the two world poses.
#[derive(Clone, Debug)]
struct Drawn {
    a: Geom,
    pose_a: [f64; 3],
    b_in_a: Geom,
    pose_b: [f64; 3],
}

fn pair(a: Geom, pose_a: [f64; 3], b_in_a: Geom, pose_b: [f64; 3]) -> Drawn {
    Drawn {
        a,
        pose_a,
        b_in_a,
        pose_b,
    }
}

impl Drawn {
    /// The two bodies, B expressed in its own frame for its pose, so that the relative
    /// placement (and so the gap) is the one drawn.
    fn bodies(self) -> (Body, Body) {
        let ta = Transform::new(self.pose_a[0], self.pose_a[1], self.pose_a[2]);
        let tb = Transform::new(self.pose_b[0], self.pose_b[1], self.pose_b[2]);
        let b = self.b_in_a.mapped(&tb.inverse().compose(&ta));
        (
            Body {
                geom: self.a,
                pose: self.pose_a,
            },
            Body {
                geom: b,
                pose: self.pose_b,
            },
        )
    }

    /// Whether neither body has a point (a vertex, a circle's centre) in the strip behind a
    /// face of the other: there our one-sided faces are solid at any depth, parry's thin.
    fn clear(&self) -> bool {
        clear_of_faces(&self.a, &self.b_in_a) && clear_of_faces(&self.b_in_a, &self.a)
    }
}

/// Whether no point of `points_of` lies behind a face of `faces_of` within its span.
fn clear_of_faces(faces_of: &Geom, points_of: &Geom) -> bool {
    let faces: Vec<[f64; 2]> = match faces_of {
        Geom::Segment { a, b } => vec![*a, *b],
        Geom::Profile(v) => v.clone(),
        _ => return true,
    };
    let points = match points_of {
        Geom::Circle { center, .. } => vec![*center],
        Geom::Segment { a, b } => vec![*a, *b],
        Geom::Profile(v) => v.clone(),
        Geom::Line { .. } => vec![],
    };
    faces.windows(2).all(|f| {
        let u = sub(f[1], f[0]);
        points.iter().all(|&p| {
            let d = sub(p, f[0]);
            let s = (d[0] * u[0] + d[1] * u[1]) / (u[0] * u[0] + u[1] * u[1]);
            let h = d[0] * -u[1] + d[1] * u[0];
            !((0.0..=1.0).contains(&s) && h < 0.0)
        })
    })
}

// ---------------------------------------------------------------------------------------
// Both answers, and how far apart they are.

/// The contact of a pair in our terms: gap, unit normal from A toward B, nearest points.
#[derive(Clone, Copy, Debug)]
struct Answer {
    gap: f64,
    normal: [f64; 2],
    point_a: [f64; 2],
    point_b: [f64; 2],
}

impl From<Proximity> for Answer {
    fn from(p: Proximity) -> Self {
        Answer {
            gap: p.gap,
            normal: p.normal,
            point_a: p.point_a,
            point_b: p.point_b,
        }
    }
}

/// Our answer: the narrow phase for two single shapes; for a profile, the [`Contact`]
/// element (the smallest gap over the pairs of shapes of its two sides).
fn ours(a: &Body, b: &Body) -> Answer {
    let (sa, sb) = (a.shapes(), b.shapes());
    if sa.len() == 1 && sb.len() == 1 {
        proximity(&sa[0], &sb[0]).unwrap().into()
    } else {
        through_contact(sa, sb).into()
    }
}

/// The proximity a [`Contact`] finds between world-placed shape lists: A on the ground,
/// B on a body at rest in the identity pose.
fn through_contact(a: Vec<Shape>, b: Vec<Shape>) -> Proximity {
    let mut builder = ModelBuilder::new();
    builder.add_link(
        "b",
        None,
        JointKind::Revolute,
        Placement::default(),
        BodySpec::new(1.0, [0.0, 0.0], 1e-3),
    );
    let model = builder.build().unwrap();
    let contact = Contact::new(
        &model,
        "profile",
        ContactSide::ground(a),
        ContactSide::on("b", b),
        KelvinVoigt::new(1e4, 0.0).unwrap(),
    )
    .unwrap();
    let mut system = System::new(model.clone());
    let e = system.add_element(contact.clone()).unwrap();
    let mut ws = system.workspace();
    let ctx = system
        .element_context(&mut ws, 0.0, &[0.0, 0.0], e)
        .unwrap();
    assert_eq!(
        ctx.body_pose(model.body_id("b").unwrap()),
        Transform::IDENTITY
    );
    contact.proximity(&ctx)
}

/// parry's answer, in our terms.
fn reference(a: &Body, b: &Body) -> Answer {
    // parry 0.31's `query::contact` with a half-space second hands the pose of the
    // half-space in the other shape's frame to its half-space kernel, which expects the
    // inverse (see `parry_needs_the_half_space_first`): ask with the half-space first.
    if matches!(b.geom, Geom::Line { .. }) {
        let r = reference(b, a);
        return Answer {
            gap: r.gap,
            normal: scale(-1.0, r.normal),
            point_a: r.point_b,
            point_b: r.point_a,
        };
    }
    let (pa, ga) = a.parry();
    let (pb, gb) = b.parry();
    let (ga, gb) = (ga.as_ref(), gb.as_ref());
    let c = query::contact(&pa, ga, &pb, gb, PREDICTION)
        .expect("pair supported by parry")
        .expect("within the prediction");
    if c.dist <= 0.0 {
        return Answer {
            gap: c.dist,
            normal: array(c.normal1),
            point_a: array(c.point1),
            point_b: array(c.point2),
        };
    }
    let gap = query::distance(&pa, ga, &pb, gb)
        .expect("pair supported by parry")
        .distance;
    let (p1, p2) = match query::closest_points(&pa, ga, &pb, gb, PREDICTION)
        .expect("pair supported by parry")
    {
        ClosestPoints::WithinMargin(p1, p2) => (array(p1), array(p2)),
        other => panic!("apart by {gap} but closest points {other:?}"),
    };
    // Two faces: parry's contact normal comes from GJK; the closest points are exact.
    let normal = if a.is_face() && b.is_face() {
        let d = sub(p2, p1);
        scale(1.0 / norm(d), d)
    } else {
        array(c.normal1)
    };
    Answer {
        gap,
        normal,
        point_a: p1,
        point_b: p2,
    }
}

/// Absolute differences between two answers.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Diff {
    gap: f64,
    normal: f64,
    points: f64,
}

impl Diff {
    fn between(x: &Answer, y: &Answer) -> Diff {
        Diff {
            gap: nan_is_worst((x.gap - y.gap).abs()),
            normal: nan_is_worst(norm(sub(x.normal, y.normal))),
            points: nan_is_worst(
                norm(sub(x.point_a, y.point_a)).max(norm(sub(x.point_b, y.point_b))),
            ),
        }
    }

    fn largest(&self) -> f64 {
        self.gap.max(self.normal).max(self.points)
    }
}

/// A difference that is NaN (one side answered NaN) counts as infinitely wrong: `f64::max`
/// would otherwise drop it and let the case pass.
fn nan_is_worst(d: f64) -> f64 {
    if d.is_nan() { f64::INFINITY } else { d }
}

/// One case compared both ways round: the differences, and both answers A then B.
fn compare(a: &Body, b: &Body) -> (Diff, Answer, Answer) {
    let (o, r) = (ours(a, b), reference(a, b));
    let (o2, r2) = (ours(b, a), reference(b, a));
    let (d, d2) = (Diff::between(&o, &r), Diff::between(&o2, &r2));
    let diff = Diff {
        gap: d.gap.max(d2.gap),
        normal: d.normal.max(d2.normal),
        points: d.points.max(d2.points),
    };
    (diff, o, r)
}

// ---------------------------------------------------------------------------------------
// Random cases.

/// A world pose: any angle, origin within ±0.3 m.
fn pose() -> impl Strategy<Value = [f64; 3]> {
    (-PI..PI, -0.3..0.3f64, -0.3..0.3f64).prop_map(|(t, x, y)| [t, x, y])
}

/// A point within ±20 mm of a body's origin.
fn point() -> impl Strategy<Value = [f64; 2]> {
    (-20.0 * MM..20.0 * MM, -20.0 * MM..20.0 * MM).prop_map(|(x, y)| [x, y])
}

/// A radius, 0.5–30 mm.
fn radius() -> impl Strategy<Value = f64> {
    0.5 * MM..30.0 * MM
}

/// A signed gap: pressed in up to `deepest` (< 0, as a fraction of it), apart up to 20 mm,
/// or within ±1 µm of touching.
#[derive(Clone, Copy, Debug)]
enum GapDraw {
    Pressed(f64),
    Apart(f64),
    Touching(f64),
}

impl GapDraw {
    fn any() -> impl Strategy<Value = GapDraw> {
        prop_oneof![
            (0.0..1.0f64).prop_map(GapDraw::Pressed),
            (0.0..1.0f64).prop_map(GapDraw::Apart),
            (-1.0..1.0f64).prop_map(GapDraw::Touching),
        ]
    }

    /// Apart only, 1 µm to 20 mm: nearer, the direction between two vertices is no longer
    /// fixed to 1e-9 by coordinates rounded to ~3e-17 m.
    fn apart() -> impl Strategy<Value = GapDraw> {
        (0.0..1.0f64).prop_map(GapDraw::Apart)
    }

    fn value(self, deepest: f64) -> f64 {
        match self {
            GapDraw::Pressed(x) => x * deepest,
            GapDraw::Apart(x) => 1e-6 + x * (20.0 * MM - 1e-6),
            GapDraw::Touching(x) => x * 1e-6,
        }
    }
}

/// A convex chain of `faces` faces facing up, walked left to right: every face within ±60°
/// of the x axis, turning clockwise by 5–40° at a vertex and by at most 120° in all (one
/// face: a segment). Our faces are solid in the strip behind them, square to the face and
/// at any depth. Near the chain these strips fill the region behind it between the rays
/// from its end vertices straight back from the end faces; a point put in front of a
/// feature of the chain, along a direction in that region's normal cone there, is outside
/// it and has that feature's point as its nearest point of the chain. Farther back, the
/// strips of the end faces can cross beneath the chain and reach around it: draws that
/// land there are rejected by [`Drawn::clear`].
#[derive(Clone, Debug)]
struct Chain {
    vertices: Vec<[f64; 2]>,
}

impl Chain {
    fn strategy(faces: std::ops::RangeInclusive<usize>) -> impl Strategy<Value = Chain> {
        faces
            .prop_flat_map(|n| {
                (
                    point(),
                    0.0..60.0f64,
                    prop::collection::vec((5.0..40.0f64, 2.0 * MM..25.0 * MM), n),
                )
            })
            .prop_map(|(start, first, faces)| {
                // Clockwise turns between faces, scaled down if the last face would point
                // more than 60° below the x axis.
                let total: f64 = faces.iter().skip(1).map(|f| f.0).sum();
                let k = if first - total < -60.0 {
                    (first + 60.0) / total
                } else {
                    1.0
                };
                let mut vertices = vec![start];
                let mut angle = first;
                for (i, &(t, len)) in faces.iter().enumerate() {
                    if i > 0 {
                        angle -= k * t;
                    }
                    let last = *vertices.last().unwrap();
                    vertices.push(add(last, scale(len, unit(angle.to_radians()))));
                }
                Chain { vertices }
            })
    }

    fn faces(&self) -> usize {
        self.vertices.len() - 1
    }

    /// Outward normal of face `i`.
    fn normal(&self, i: usize) -> [f64; 2] {
        let d = sub(self.vertices[i + 1], self.vertices[i]);
        left(scale(1.0 / norm(d), d))
    }

    /// A point of the chain and an outward direction in its normal cone, from a feature
    /// index (even: a vertex, odd: inside a face) and two numbers in [0, 1]: where along
    /// the face, and where within a vertex's cone (kept `margin` of the cone's width away
    /// from its edges).
    fn feature(&self, k: usize, along: f64, within: f64, margin: f64) -> ([f64; 2], [f64; 2]) {
        let n = self.faces();
        let k = k % (2 * n + 1);
        if k % 2 == 1 {
            let i = k / 2;
            let (a, b) = (self.vertices[i], self.vertices[i + 1]);
            let t = 0.05 + 0.9 * along;
            return (add(a, scale(t, sub(b, a))), self.normal(i));
        }
        let j = k / 2;
        let angle = |v: [f64; 2]| v[1].atan2(v[0]);
        // The cone runs counter-clockwise from `lo` to `hi`.
        let (lo, hi) = if j == 0 {
            let a = angle(self.normal(0));
            (a, a + 0.5 * PI)
        } else if j == n {
            let a = angle(self.normal(n - 1));
            (a - 0.5 * PI, a)
        } else {
            (angle(self.normal(j)), angle(self.normal(j - 1)))
        };
        let s = margin + (1.0 - 2.0 * margin) * within;
        (self.vertices[j], unit(lo + s * (hi - lo)))
    }

    fn geom(&self) -> Geom {
        if self.faces() == 1 {
            Geom::Segment {
                a: self.vertices[0],
                b: self.vertices[1],
            }
        } else {
            Geom::Profile(self.vertices.clone())
        }
    }
}

/// Where B touches A: a feature of A's chain and a direction in its cone.
#[derive(Clone, Copy, Debug)]
struct Feature {
    index: usize,
    along: f64,
    within: f64,
}

fn feature() -> impl Strategy<Value = Feature> {
    (0usize..11, 0.0..1.0f64, 0.0..1.0f64).prop_map(|(index, along, within)| Feature {
        index,
        along,
        within,
    })
}

/// A segment B in front of a point `p` of A seen along `dir` (from A toward B, in A's
/// normal cone), `gap` beyond it, facing A: either B's vertex is the nearest point (B
/// leaving at 5–85° from `dir`, either end first), or B's face is (B across `dir`, the
/// point at 10–90 % of its length).
#[derive(Clone, Copy, Debug)]
struct FacingSegment {
    length: f64,
    vertex_first: bool,
    leave: f64,
    b_end: bool,
    across_at: f64,
}

fn facing_segment() -> impl Strategy<Value = FacingSegment> {
    (
        2.0 * MM..100.0 * MM,
        any::<bool>(),
        5.0..85.0f64,
        any::<bool>(),
        0.1..0.9f64,
    )
        .prop_map(
            |(length, vertex_first, leave, b_end, across_at)| FacingSegment {
                length,
                vertex_first,
                leave,
                b_end,
                across_at,
            },
        )
}

impl FacingSegment {
    /// B with its nearest point at `p + gap dir`. `vertex_only`: when A's feature is a
    /// face, B's face cannot be the nearest (it would lie parallel to A's face).
    fn geom(&self, p: [f64; 2], dir: [f64; 2], gap: f64, vertex_only: bool) -> Geom {
        let q = add(p, scale(gap, dir));
        if self.vertex_first || vertex_only {
            // B's vertex at q, the rest of B beyond the line across `dir` there. B faces A
            // when it starts at q and leaves turned counter-clockwise from `dir`, or ends
            // at q coming from a point turned clockwise from it.
            let leave = self.leave.to_radians();
            if self.b_end {
                let w = turn(dir, -leave);
                Geom::Segment {
                    a: add(q, scale(self.length, w)),
                    b: q,
                }
            } else {
                let w = turn(dir, leave);
                Geom::Segment {
                    a: q,
                    b: add(q, scale(self.length, w)),
                }
            }
        } else {
            // B's face across `dir`, outward normal −dir: direction left(dir).
            let u = left(dir);
            let a = sub(q, scale(self.across_at * self.length, u));
            Geom::Segment {
                a,
                b: add(a, scale(self.length, u)),
            }
        }
    }
}

/// The pairs compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Pair {
    CircleCircle,
    SegmentCircle,
    LineCircle,
    LineSegment,
    SegmentSegment,
    ProfileCircle,
    ProfileSegment,
}

impl Pair {
    const ALL: [Pair; 7] = [
        Pair::CircleCircle,
        Pair::SegmentCircle,
        Pair::LineCircle,
        Pair::LineSegment,
        Pair::SegmentSegment,
        Pair::ProfileCircle,
        Pair::ProfileSegment,
    ];

    /// Random cases of this pair: A, B with their poses. Draws that put a point of one
    /// body behind a face of the other are drawn again (see [`Drawn::clear`]).
    fn cases(self) -> BoxedStrategy<(Body, Body)> {
        self.drawn()
            .prop_filter("a point behind a face", Drawn::clear)
            .prop_map(Drawn::bodies)
            .boxed()
    }

    fn drawn(self) -> BoxedStrategy<Drawn> {
        match self {
            Pair::CircleCircle => (
                pose(),
                pose(),
                point(),
                radius(),
                radius(),
                -PI..PI,
                GapDraw::any(),
            )
                .prop_map(|(pa, pb, c, ra, rb, phi, g)| {
                    // Down to 90 % of the radii pressed in: centres never closer than
                    // 0.1 (ra + rb), where the direction between them is well defined.
                    let d = ra + rb + g.value(-0.9 * (ra + rb));
                    let a = Geom::Circle {
                        center: c,
                        radius: ra,
                    };
                    let b = Geom::Circle {
                        center: add(c, scale(d, unit(phi))),
                        radius: rb,
                    };
                    pair(a, pa, b, pb)
                })
                .boxed(),
            Pair::SegmentCircle | Pair::ProfileCircle => {
                let faces = if self == Pair::SegmentCircle {
                    1..=1
                } else {
                    2..=5
                };
                (
                    pose(),
                    pose(),
                    Chain::strategy(faces),
                    feature(),
                    radius(),
                    GapDraw::any(),
                )
                    .prop_map(|(pa, pb, chain, f, r, g)| {
                        // The centre outside the solid, its nearest point of A at `p`.
                        let (p, dir) = chain.feature(f.index, f.along, f.within, 0.0);
                        let d = r + g.value(-0.9 * r);
                        let b = Geom::Circle {
                            center: add(p, scale(d, dir)),
                            radius: r,
                        };
                        pair(chain.geom(), pa, b, pb)
                    })
                    .boxed()
            }
            Pair::LineCircle => (
                pose(),
                pose(),
                point(),
                -PI..PI,
                -50.0 * MM..50.0 * MM,
                radius(),
                GapDraw::any(),
            )
                .prop_map(|(pa, pb, p, theta, along, r, g)| {
                    let n = unit(theta);
                    // A half-plane: the centre may be deep inside.
                    let foot = add(p, scale(along, left(n)));
                    let d = r + g.value(-1.5 * r);
                    let a = Geom::Line {
                        point: p,
                        normal: n,
                    };
                    let b = Geom::Circle {
                        center: add(foot, scale(d, n)),
                        radius: r,
                    };
                    pair(a, pa, b, pb)
                })
                .boxed(),
            Pair::LineSegment => (
                pose(),
                pose(),
                point(),
                -PI..PI,
                -50.0 * MM..50.0 * MM,
                GapDraw::any(),
                2.0 * MM..100.0 * MM,
                -PI..PI,
            )
                .prop_map(|(pa, pb, p, theta, along, g, len, psi)| {
                    let n = unit(theta);
                    // B's first vertex at the drawn height (down to 5 mm deep), any
                    // direction: the deeper vertex is the contact.
                    let start = add(add(p, scale(along, left(n))), scale(g.value(-5.0 * MM), n));
                    let a = Geom::Line {
                        point: p,
                        normal: n,
                    };
                    let b = Geom::Segment {
                        a: start,
                        b: add(start, scale(len, unit(theta + psi))),
                    };
                    pair(a, pa, b, pb)
                })
                .boxed(),
            Pair::SegmentSegment | Pair::ProfileSegment => {
                let faces = if self == Pair::SegmentSegment {
                    1..=1
                } else {
                    2..=5
                };
                (
                    pose(),
                    pose(),
                    Chain::strategy(faces),
                    feature(),
                    facing_segment(),
                    GapDraw::apart(),
                )
                    .prop_map(|(pa, pb, chain, f, s, g)| {
                        // Kept 5 % of a vertex cone off its edges, so that B's face is
                        // never parallel to A's.
                        let (p, dir) = chain.feature(f.index, f.along, f.within, 0.05);
                        let on_face = f.index % (2 * chain.faces() + 1) % 2 == 1;
                        let b = s.geom(p, dir, g.value(0.0), on_face);
                        pair(chain.geom(), pa, b, pb)
                    })
                    .boxed()
            }
        }
    }
}

impl fmt::Display for Pair {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self {
            Pair::CircleCircle => "circle–circle",
            Pair::SegmentCircle => "segment–circle",
            Pair::LineCircle => "line–circle",
            Pair::LineSegment => "line–segment",
            Pair::SegmentSegment => "segment–segment",
            Pair::ProfileCircle => "profile–circle",
            Pair::ProfileSegment => "profile–segment",
        };
        f.pad(name)
    }
}

/// Fails a case whose answers differ by more than [`TOL`].
fn check(pair: Pair, a: &Body, b: &Body) -> std::result::Result<(), TestCaseError> {
    let (d, o, r) = compare(a, b);
    prop_assert!(
        d.largest() <= TOL,
        "{pair}: {d:?}\nours   {o:?}\nparry  {r:?}\nA {a:?}\nB {b:?}"
    );
    Ok(())
}

proptest! {
    #[test]
    fn circle_circle_agrees_with_parry((a, b) in Pair::CircleCircle.cases()) {
        check(Pair::CircleCircle, &a, &b)?;
    }

    #[test]
    fn segment_circle_agrees_with_parry((a, b) in Pair::SegmentCircle.cases()) {
        check(Pair::SegmentCircle, &a, &b)?;
    }

    #[test]
    fn line_circle_agrees_with_parry((a, b) in Pair::LineCircle.cases()) {
        check(Pair::LineCircle, &a, &b)?;
    }

    #[test]
    fn line_segment_agrees_with_parry((a, b) in Pair::LineSegment.cases()) {
        check(Pair::LineSegment, &a, &b)?;
    }

    #[test]
    fn segment_segment_agrees_with_parry((a, b) in Pair::SegmentSegment.cases()) {
        check(Pair::SegmentSegment, &a, &b)?;
    }

    #[test]
    fn profile_circle_agrees_with_parry((a, b) in Pair::ProfileCircle.cases()) {
        check(Pair::ProfileCircle, &a, &b)?;
    }

    #[test]
    fn profile_segment_agrees_with_parry((a, b) in Pair::ProfileSegment.cases()) {
        check(Pair::ProfileSegment, &a, &b)?;
    }
}

/// parry 0.31 answers `query::contact` with a half-space second as if the relative pose
/// were inverted (here: the ball put below the floor instead of above it); [`reference`]
/// asks with the half-space first. Should this fail, parry has been fixed and that
/// workaround can go.
#[test]
fn parry_needs_the_half_space_first() {
    let ball = Ball::new(1.0);
    let floor = HalfSpace::new(Vector::Y);
    let (at_ball, at_floor) = (Pose::translation(0.0, 3.0), Pose::identity());
    let first = query::contact(&at_floor, &floor, &at_ball, &ball, 10.0)
        .unwrap()
        .unwrap();
    assert!((first.dist - 2.0).abs() < 1e-15, "{first:?}");
    let second = query::contact(&at_ball, &ball, &at_floor, &floor, 10.0)
        .unwrap()
        .unwrap();
    // The right answer is 2 again; parry puts the ball's centre at (0, −3): −4.
    assert!(
        (second.dist + 4.0).abs() < 1e-15,
        "parry now handles a half-space second ({second:?}): drop the flip in `reference`"
    );
    // Its distance query does invert the pose.
    let d = query::distance(&at_ball, &ball, &at_floor, &floor).unwrap();
    assert!((d.distance - 2.0).abs() < 1e-15, "{d:?}");
}

/// The worst difference of one kind over a sweep, and the case it came from.
#[derive(Default)]
struct Worst {
    value: f64,
    case: Option<(Body, Body)>,
}

impl Worst {
    fn record(&mut self, value: f64, a: &Body, b: &Body) {
        if value > self.value || self.case.is_none() {
            self.value = value;
            self.case = Some((a.clone(), b.clone()));
        }
    }
}

/// A seeded sweep of [`SWEEP`] cases per pair: prints the worst gap, normal and point
/// differences of each pair, and fails if any exceeds [`TOL`].
#[test]
fn worst_differences_per_pair() {
    let mut failures = Vec::new();
    eprintln!("parry2d-f64 check, {SWEEP} seeded cases per pair, both orders, tolerance {TOL:e}");
    for pair in Pair::ALL {
        // The same seed for every pair, and every run.
        let mut runner = TestRunner::deterministic();
        let strategy = pair.drawn();
        let (mut gap, mut normal, mut points) =
            (Worst::default(), Worst::default(), Worst::default());
        let (mut apart, mut pressed, mut skipped) = (0, 0, 0);
        while apart + pressed < SWEEP {
            let drawn = strategy.new_tree(&mut runner).unwrap().current();
            if !drawn.clear() {
                skipped += 1;
                continue;
            }
            let (a, b) = drawn.bodies();
            let (d, o, _) = compare(&a, &b);
            if o.gap > 0.0 {
                apart += 1;
            } else {
                pressed += 1;
            }
            gap.record(d.gap, &a, &b);
            normal.record(d.normal, &a, &b);
            points.record(d.points, &a, &b);
        }
        eprintln!(
            "{pair:<16} ({apart:>5} apart, {pressed:>5} pressed, {skipped:>3} skipped): \
             worst gap difference {:.2e} m, worst normal difference {:.2e}, \
             worst point difference {:.2e} m",
            gap.value, normal.value, points.value
        );
        for (what, w) in [("gap", gap), ("normal", normal), ("point", points)] {
            if w.value > TOL {
                let (a, b) = w.case.unwrap();
                failures.push(format!(
                    "{pair}: {what} difference {:e}\nA {a:?}\nB {b:?}",
                    w.value
                ));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "differences above {TOL:e}:\n{}",
        failures.join("\n")
    );
}
