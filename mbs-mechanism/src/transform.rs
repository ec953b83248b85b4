//! Transformations of a description: a new [`Mechanism`] made from an old one, to ask what
//! a part's compliance or a felt's law changes (the diagnosis of a full action).
//!
//! - [`Mechanism::split_body`] cuts a body in two along a line and puts the distal part on
//!   a new revolute joint with a torsion spring: a flexible hammer shank (shank and head), a
//!   key that bends (front and back halves).
//! - [`Mechanism::mount_compliant`] puts the shapes of one side of a contact on a new light
//!   body on a sprung pivot: a back-check on its wire.
//! - [`Mechanism::swap_law`] and [`Mechanism::swap_friction`] change the normal law of a
//!   contact (or of a string's striker) and a contact's friction.
//!
//! Each checks its arguments first, an error naming the argument (`split_body.at`,
//! `mount_compliant.props.mass`), builds a new description (the old one is left as it
//! was) and validates it ([`Mechanism::validate`]).
//!
//! ```
//! use mbs_mechanism::{Flex, MassProps, Mechanism};
//! let arm = Mechanism::from_toml_str(r#"
//! name = "arm"
//! gravity = [0.0, -9.81]
//!
//! [[bodies]]
//! name = "arm"
//! mass = 0.1
//! com = [0.05, 0.0]
//! inertia = 1e-4
//! joint = { kind = "revolute", at = [0.0, 0.0] }
//!
//! [[markers]]
//! name = "tip"
//! at = { body = "arm", point = [0.1, 0.0] }
//! "#).unwrap();
//! // The outer half (40 g at 75 mm, a 50 mm rod) bends at 50 mm from the pivot.
//! let outer = MassProps { mass: 0.04, com: [0.075, 0.0], inertia: 0.04 * 0.05f64.powi(2) / 12.0 };
//! let hinge = Flex { stiffness: 50.0, damping: 0.0 };
//! let bent = arm.split_body("arm", [0.05, 0.0], [1.0, 0.0], "outer", outer, hinge).unwrap();
//! assert_eq!(bent.bodies[1].joint.parent, "arm");
//! assert_eq!(bent.torsion_springs[0].name, "outer flex");
//! // The tip is now on the outer part, in its frame (origin at the hinge).
//! assert_eq!(bent.markers[0].at.body, "outer");
//! assert_eq!(bent.markers[0].at.point, [0.05, 0.0]);
//! // Mass, centre of mass and inertia about the pivot are those of the rigid arm.
//! let whole = MassProps::of(&bent.bodies[0]).plus(&outer);
//! assert!((whole.inertia_about_origin() - 3.5e-4).abs() < 1e-15);
//! ```

use crate::description::*;
use crate::error::{MechanismError, Result};
use crate::validate::{friction, law, non_negative, point, positive};

/// Mass properties of a rigid part: mass, centre of mass and rotational inertia about the
/// centre of mass, in the frame of the body it belongs to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProps {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the body frame (m).
    pub com: [f64; 2],
    /// Rotational inertia about the centre of mass (kg·m²).
    pub inertia: f64,
}

impl MassProps {
    /// The mass properties of `body`, in its frame.
    pub fn of(body: &Body) -> Self {
        MassProps {
            mass: body.mass,
            com: body.com,
            inertia: body.inertia,
        }
    }

    /// Inertia about the frame's origin (the joint): `I + m |c|²`.
    pub fn inertia_about_origin(&self) -> f64 {
        self.inertia + mbs_core::Inertia::parallel_axis(self.mass, self.com)
    }

    /// The two parts as one rigid part: masses add, the centre of mass is their
    /// mass-weighted mean, inertias about the frame origin add (parallel axes).
    pub fn plus(&self, other: &MassProps) -> MassProps {
        let mass = self.mass + other.mass;
        let com = [
            (self.mass * self.com[0] + other.mass * other.com[0]) / mass,
            (self.mass * self.com[1] + other.mass * other.com[1]) / mass,
        ];
        let about_origin = self.inertia_about_origin() + other.inertia_about_origin();
        MassProps {
            mass,
            com,
            inertia: about_origin - mbs_core::Inertia::parallel_axis(mass, com),
        }
    }

    /// What remains of this part without `part` (the inverse of [`MassProps::plus`]):
    /// `m = M − m_p`, `c = (M C − m_p c_p) / m`, inertia about the origin `J − J_p`. Its
    /// mass or inertia come out zero or negative when `part` does not fit inside.
    pub fn minus(&self, part: &MassProps) -> MassProps {
        let mass = self.mass - part.mass;
        let com = [
            (self.mass * self.com[0] - part.mass * part.com[0]) / mass,
            (self.mass * self.com[1] - part.mass * part.com[1]) / mass,
        ];
        let about_origin = self.inertia_about_origin() - part.inertia_about_origin();
        MassProps {
            mass,
            com,
            inertia: about_origin - mbs_core::Inertia::parallel_axis(mass, com),
        }
    }
}

/// The torsion spring on a joint a transformation makes: `τ = −k q − c q̇` (rest 0, no
/// preload), named `"<new body> flex"`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flex {
    /// Stiffness k (N·m/rad), ≥ 0.
    pub stiffness: f64,
    /// Damping c (N·m·s/rad), ≥ 0.
    pub damping: f64,
}

/// One side of a contact pair: its field `a` or `b`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The first side, `a`.
    A,
    /// The second side, `b`.
    B,
}

/// The name of the torsion spring that [`Mechanism::split_body`] and
/// [`Mechanism::mount_compliant`] put on the joint of `new_body`.
pub fn flex_spring_name(new_body: &str) -> String {
    format!("{new_body} flex")
}

/// The name of the contact that carries the distal shapes of `contact` when
/// [`Mechanism::split_body`] cuts one of its sides in two.
pub fn distal_contact_name(contact: &str, new_body: &str) -> String {
    format!("{contact} on {new_body}")
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn bad(function: &str, argument: &str, message: impl Into<String>) -> MechanismError {
    MechanismError::field(format!("{function}.{argument}"), message)
}

fn listed<'a>(names: impl Iterator<Item = &'a str>) -> String {
    let names: Vec<&str> = names.collect();
    if names.is_empty() {
        "none".into()
    } else {
        names.join(", ")
    }
}

impl ShapeSpec {
    /// The point that decides on which side of a cut the shape goes (see
    /// [`Mechanism::split_body`]): a circle's centre, a segment's midpoint, the middle of an
    /// arc's rim, the point half-way along a profile.
    pub fn reference_point(&self) -> [f64; 2] {
        match self {
            ShapeSpec::Circle { center, .. } => *center,
            ShapeSpec::Segment { a, b } => [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])],
            ShapeSpec::Arc {
                center,
                radius,
                start,
                sweep,
                ..
            } => {
                let (s, c) = (start + 0.5 * sweep).sin_cos();
                [center[0] + radius * c, center[1] + radius * s]
            }
            ShapeSpec::Profile { points } => {
                // Walk half the length along the faces.
                let length = |w: &[[f64; 2]]| sub(w[1], w[0])[0].hypot(sub(w[1], w[0])[1]);
                let mut left = 0.5 * points.windows(2).map(length).sum::<f64>();
                for w in points.windows(2) {
                    let l = length(w);
                    if left <= l && l > 0.0 {
                        let t = left / l;
                        return [
                            w[0][0] + t * (w[1][0] - w[0][0]),
                            w[0][1] + t * (w[1][1] - w[0][1]),
                        ];
                    }
                    left -= l;
                }
                points.last().copied().unwrap_or([0.0, 0.0])
            }
        }
    }

    /// The same shape with every point moved by `offset`.
    pub fn translated(&self, offset: [f64; 2]) -> ShapeSpec {
        let mv = |p: [f64; 2]| [p[0] + offset[0], p[1] + offset[1]];
        match self {
            ShapeSpec::Circle { center, radius } => ShapeSpec::Circle {
                center: mv(*center),
                radius: *radius,
            },
            ShapeSpec::Segment { a, b } => ShapeSpec::Segment {
                a: mv(*a),
                b: mv(*b),
            },
            ShapeSpec::Arc {
                center,
                radius,
                start,
                sweep,
                side,
            } => ShapeSpec::Arc {
                center: mv(*center),
                radius: *radius,
                start: *start,
                sweep: *sweep,
                side: *side,
            },
            ShapeSpec::Profile { points } => ShapeSpec::Profile {
                points: points.iter().map(|p| mv(*p)).collect(),
            },
        }
    }
}

/// The line of a split: the points `p` with `(p − at)·along > 0` are distal (`along` of
/// unit length).
#[derive(Clone, Copy, Debug)]
struct Cut {
    at: [f64; 2],
    along: [f64; 2],
}

impl Cut {
    /// Signed distance of `p` from the line, positive on the distal side.
    fn side(&self, p: [f64; 2]) -> f64 {
        dot(sub(p, self.at), self.along)
    }

    fn is_distal(&self, p: [f64; 2]) -> bool {
        self.side(p) > 0.0
    }

    /// The part of the polygon `points` on one side (Sutherland–Hodgman against one
    /// half-plane), or none if nothing with an area is left there.
    fn clip(&self, points: &[[f64; 2]], distal: bool) -> Option<Vec<[f64; 2]>> {
        let inside = |p: [f64; 2]| self.is_distal(p) == distal;
        let mut out: Vec<[f64; 2]> = Vec::new();
        for (k, &p) in points.iter().enumerate() {
            let q = points[(k + 1) % points.len()];
            if inside(p) {
                out.push(p);
            }
            if inside(p) != inside(q) {
                // The sides differ, so the signed distances do too.
                let (sp, sq) = (self.side(p), self.side(q));
                let t = sp / (sp - sq);
                out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
            }
        }
        out.dedup();
        while out.len() > 1 && out.first() == out.last() {
            out.pop();
        }
        // Twice the signed area (shoelace).
        let area: f64 = (0..out.len())
            .map(|k| {
                let (p, q) = (out[k], out[(k + 1) % out.len()]);
                p[0] * q[1] - q[0] * p[1]
            })
            .sum();
        (out.len() >= 3 && area != 0.0).then_some(out)
    }
}

/// The outline cut by `cut`: (the proximal parts, the distal parts in the body frame).
/// Polygons are clipped; circles go whole by their centre.
fn split_outline(parts: &[OutlinePart], cut: &Cut) -> (Vec<OutlinePart>, Vec<OutlinePart>) {
    let (mut near, mut far) = (Vec::new(), Vec::new());
    for part in parts {
        match &part.circle {
            Some(c) if cut.is_distal(c.center) => far.push(part.clone()),
            Some(_) => near.push(part.clone()),
            None => {
                for (distal, out) in [(false, &mut near), (true, &mut far)] {
                    if let Some(points) = cut.clip(&part.points, distal) {
                        out.push(OutlinePart {
                            points,
                            ..part.clone()
                        });
                    }
                }
            }
        }
    }
    (near, far)
}

/// `part` moved by `offset`.
fn translated_part(part: &OutlinePart, offset: [f64; 2]) -> OutlinePart {
    let mv = |p: [f64; 2]| [p[0] + offset[0], p[1] + offset[1]];
    OutlinePart {
        points: part.points.iter().map(|p| mv(*p)).collect(),
        circle: part.circle.map(|c| CircleSpec {
            center: mv(c.center),
            radius: c.radius,
        }),
        ..part.clone()
    }
}

/// Moves `p` to `new_body` (in its frame, origin at `cut.at`) if it is on `body` beyond
/// the cut; whether it moved.
fn reattach(p: &mut BodyPoint, body: &str, new_body: &str, cut: &Cut) -> bool {
    if p.body == body && cut.is_distal(p.point) {
        p.body = new_body.to_string();
        p.point = sub(p.point, cut.at);
        true
    } else {
        false
    }
}

/// The shapes of `side` split by `cut`: (proximal, distal translated into the new frame).
fn split_shapes(shapes: &[ShapeSpec], cut: &Cut) -> (Vec<ShapeSpec>, Vec<ShapeSpec>) {
    let (far, near): (Vec<&ShapeSpec>, Vec<&ShapeSpec>) = shapes
        .iter()
        .partition(|s| cut.is_distal(s.reference_point()));
    let back = [-cut.at[0], -cut.at[1]];
    (
        near.into_iter().cloned().collect(),
        far.into_iter().map(|s| s.translated(back)).collect(),
    )
}

fn check_props(field: &str, p: &MassProps) -> Result<()> {
    positive(&format!("{field}.mass"), p.mass)?;
    point(&format!("{field}.com"), p.com)?;
    positive(&format!("{field}.inertia"), p.inertia)?;
    Ok(())
}

fn check_flex(function: &str, flex: &Flex) -> Result<()> {
    non_negative(&format!("{function}.flex.stiffness"), flex.stiffness)?;
    non_negative(&format!("{function}.flex.damping"), flex.damping)?;
    Ok(())
}

/// What remains of `body` without `part` (both in the body frame); an error at
/// `{field}.mass` or `{field}.inertia` if nothing with a positive mass and inertia would.
fn remainder(field: &str, body: &Body, part: &MassProps) -> Result<MassProps> {
    let whole = MassProps::of(body);
    let rest = whole.minus(part);
    if rest.mass <= 0.0 {
        return Err(MechanismError::field(
            format!("{field}.mass"),
            format!(
                "{} kg is not less than the mass of '{}' ({} kg): nothing would remain of it",
                part.mass, body.name, whole.mass
            ),
        ));
    }
    if rest.inertia <= 0.0 || rest.com.iter().any(|c| !c.is_finite()) {
        return Err(MechanismError::field(
            format!("{field}.inertia"),
            format!(
                "would leave '{}' {:.3e} kg·m² about its joint, less than its remaining \
                 {:.4} kg at [{:.4}, {:.4}] m needs ({:.3e}): its inertia about its centre of \
                 mass would be {:.3e} kg·m² (must be positive)",
                body.name,
                whole.inertia_about_origin() - part.inertia_about_origin(),
                rest.mass,
                rest.com[0],
                rest.com[1],
                mbs_core::Inertia::parallel_axis(rest.mass, rest.com),
                rest.inertia
            ),
        ));
    }
    Ok(rest)
}

fn revolute_on(parent: &str, at: [f64; 2]) -> Joint {
    Joint {
        kind: JointType::Revolute,
        parent: parent.to_string(),
        at,
        angle: 0.0,
        axis: None,
        limits: None,
        friction: None,
    }
}

impl Mechanism {
    fn body_index(&self, function: &str, body: &str) -> Result<usize> {
        if body == GROUND {
            return Err(bad(
                function,
                "body",
                "the ground is not a body: it has no mass to share",
            ));
        }
        self.bodies
            .iter()
            .position(|b| b.name == body)
            .ok_or_else(|| {
                bad(
                    function,
                    "body",
                    format!(
                        "no body '{body}' (bodies: {})",
                        listed(self.bodies.iter().map(|b| b.name.as_str()))
                    ),
                )
            })
    }

    /// Checks the name of a new body and of its spring; returns the spring's name.
    fn check_new_body(&self, function: &str, new_body: &str) -> Result<String> {
        if new_body.trim().is_empty() {
            return Err(bad(function, "new_body", "must not be empty"));
        }
        if new_body == GROUND {
            return Err(bad(
                function,
                "new_body",
                "'ground' is the fixed world; name the new body otherwise",
            ));
        }
        if self.bodies.iter().any(|b| b.name == new_body) {
            return Err(bad(
                function,
                "new_body",
                format!("'{new_body}' is already a body"),
            ));
        }
        let spring = flex_spring_name(new_body);
        let taken = self
            .torsion_springs
            .iter()
            .map(|s| &s.name)
            .chain(self.point_springs.iter().map(|s| &s.name))
            .chain(self.cords.iter().map(|c| &c.name))
            .chain(self.loads.iter().map(|l| &l.name))
            .any(|n| *n == spring);
        if taken {
            return Err(bad(
                function,
                "new_body",
                format!("its spring would be named '{spring}', which an element already is"),
            ));
        }
        Ok(spring)
    }

    fn contact_names(&self) -> String {
        listed(
            self.contacts
                .iter()
                .map(|c| c.name.as_str())
                .chain(self.strings.iter().map(|s| s.name.as_str())),
        )
    }

    /// The description with `body` cut in two by the line through `at` perpendicular to
    /// `along` (both in the body frame; `along` need not be of unit length): what lies on
    /// the side `along` points to, `(p − at)·along > 0`, goes to `new_body`, a body on a
    /// revolute joint at `at` on `body`, its frame parallel to `body`'s (a point `p` of
    /// `body` is `p − at` in it), held by a torsion spring `"<new_body> flex"` of `flex`
    /// (rest 0).
    ///
    /// `distal` gives the mass properties of the part that goes (in the body frame; its
    /// centre of mass must lie beyond the cut); `body` keeps the remainder, computed so that
    /// the total mass, centre of mass and inertia about `body`'s joint are those of the
    /// rigid body (parallel axes; see [`MassProps::minus`]). A remainder without a positive
    /// mass or inertia is refused (`split_body.distal.mass`, `split_body.distal.inertia`).
    ///
    /// What moves, each by one point (a point on the cut line stays):
    /// - contact shapes whole, by their [`ShapeSpec::reference_point`]; a side whose shapes
    ///   fall on both sides of the cut is split into two contacts with the same law and
    ///   friction: the original (its name, its events) keeps the proximal shapes, a new
    ///   contact [`distal_contact_name`] (`"<contact> on <new_body>"`), listed right after
    ///   it, takes the distal ones. Each then touches at its own nearest point, as two
    ///   bodies do; a shape that straddles the cut goes whole (split it in the description
    ///   first if it must bend);
    /// - a string's striker whole; a cut through a striker's shapes is refused
    ///   (`split_body.at`): one string has one striker;
    /// - markers, the ends of point springs and cords, loads and force inputs, by their
    ///   point; motion inputs stay (they prescribe `body`'s coordinate);
    /// - child bodies whose joint sits beyond the cut, their `at` re-expressed in the new
    ///   frame (their `angle` is unchanged: the frames are parallel);
    /// - outline polygons are clipped into their two parts, circles go by their centre.
    ///
    /// `body`'s joint (its stops, friction, springs), extensions, events and metrics stay.
    /// The new body is listed right after `body`, so the coordinates after it shift by one.
    /// A cut with nothing of `body` beyond it is refused (`split_body.at`).
    pub fn split_body(
        &self,
        body: &str,
        at: [f64; 2],
        along: [f64; 2],
        new_body: &str,
        distal: MassProps,
        flex: Flex,
    ) -> Result<Mechanism> {
        const F: &str = "split_body";
        self.validate()?;
        let index = self.body_index(F, body)?;
        let spring = self.check_new_body(F, new_body)?;
        point(&format!("{F}.at"), at)?;
        point(&format!("{F}.along"), along)?;
        let n = along[0].hypot(along[1]);
        if n == 0.0 || !n.is_finite() {
            return Err(bad(F, "along", "must be a direction, got the zero vector"));
        }
        let cut = Cut {
            at,
            along: [along[0] / n, along[1] / n],
        };
        check_props(&format!("{F}.distal"), &distal)?;
        if !cut.is_distal(distal.com) {
            return Err(bad(
                F,
                "distal.com",
                format!(
                    "[{}, {}] is not beyond the cut (the line through [{}, {}] across \
                     [{}, {}]): the distal part's centre of mass lies on the side `along` \
                     points to",
                    distal.com[0], distal.com[1], at[0], at[1], along[0], along[1]
                ),
            ));
        }
        check_flex(F, &flex)?;
        let rest = remainder(&format!("{F}.distal"), &self.bodies[index], &distal)?;

        let mut m = self.clone();
        let mut moved = 0;
        let back = [-at[0], -at[1]];
        let (near, far) = split_outline(&self.bodies[index].outline, &cut);
        moved += far.len();
        for b in &mut m.bodies {
            if b.joint.parent == body && cut.is_distal(b.joint.at) {
                b.joint.parent = new_body.to_string();
                b.joint.at = sub(b.joint.at, at);
                moved += 1;
            }
        }
        let mut attach =
            |p: &mut BodyPoint| moved += usize::from(reattach(p, body, new_body, &cut));
        for s in &mut m.point_springs {
            attach(&mut s.a);
            attach(&mut s.b);
        }
        for c in &mut m.cords {
            attach(&mut c.a);
            attach(&mut c.b);
        }
        for l in &mut m.loads {
            attach(&mut l.at);
        }
        for i in &mut m.inputs {
            if i.kind == InputKind::Force {
                attach(&mut i.at);
            }
        }
        for mk in &mut m.markers {
            attach(&mut mk.at);
        }

        let mut contacts = Vec::with_capacity(m.contacts.len() + 1);
        for mut c in std::mem::take(&mut m.contacts) {
            let mut distal_part = None;
            for which in [Side::A, Side::B] {
                let side = match which {
                    Side::A => &mut c.a,
                    Side::B => &mut c.b,
                };
                if side.body != body {
                    continue;
                }
                let (near, far) = split_shapes(&side.shapes, &cut);
                if far.is_empty() {
                    continue;
                }
                moved += far.len();
                if near.is_empty() {
                    side.body = new_body.to_string();
                    side.shapes = far;
                } else {
                    side.shapes = near;
                    distal_part = Some((which, far));
                }
            }
            let split = distal_part.map(|(which, far)| {
                let moved_side = ContactSideSpec {
                    body: new_body.to_string(),
                    shapes: far,
                };
                let (a, b) = match which {
                    Side::A => (moved_side, c.b.clone()),
                    Side::B => (c.a.clone(), moved_side),
                };
                ContactPair {
                    name: distal_contact_name(&c.name, new_body),
                    note: format!("the part of '{}' beyond the cut of split_body", c.name),
                    a,
                    b,
                    ..c.clone()
                }
            });
            contacts.push(c);
            if let Some(extra) = split {
                let taken = self.contacts.iter().any(|o| o.name == extra.name)
                    || self.strings.iter().any(|o| o.name == extra.name);
                if taken {
                    return Err(bad(
                        F,
                        "new_body",
                        format!(
                            "the cut splits a contact whose distal part would be named '{}', \
                             which is taken",
                            extra.name
                        ),
                    ));
                }
                contacts.push(extra);
            }
        }
        m.contacts = contacts;
        for (i, s) in m.strings.iter_mut().enumerate() {
            if s.striker.body != body {
                continue;
            }
            let (near, far) = split_shapes(&s.striker.shapes, &cut);
            match (near.is_empty(), far.is_empty()) {
                (_, true) => {}
                (true, false) => {
                    moved += far.len();
                    s.striker.body = new_body.to_string();
                    s.striker.shapes = far;
                }
                (false, false) => {
                    return Err(bad(
                        F,
                        "at",
                        format!(
                            "the cut runs through the striker of string '{}' \
                             (strings[{i}].striker): a string has one striker, on one body",
                            s.name
                        ),
                    ));
                }
            }
        }
        if moved == 0 {
            return Err(bad(
                F,
                "at",
                format!(
                    "nothing of '{body}' lies beyond the cut through [{}, {}] across [{}, {}] \
                     (no contact shape, striker, marker, attachment point, force input, child \
                     joint or outline): the new body would carry nothing",
                    at[0], at[1], along[0], along[1]
                ),
            ));
        }

        let original = &mut m.bodies[index];
        original.mass = rest.mass;
        original.com = rest.com;
        original.inertia = rest.inertia;
        original.outline = near;
        let split_note = format!(
            "split at [{}, {}] m: the part beyond is '{new_body}', these mass properties the \
             remainder",
            at[0], at[1]
        );
        original.note = if original.note.is_empty() {
            split_note
        } else {
            format!("{}; {split_note}", original.note)
        };
        m.bodies.insert(
            index + 1,
            Body {
                name: new_body.to_string(),
                note: format!(
                    "the part of '{body}' beyond the cut at [{}, {}] m",
                    at[0], at[1]
                ),
                mass: distal.mass,
                com: sub(distal.com, at),
                inertia: distal.inertia,
                joint: revolute_on(body, at),
                outline: far.iter().map(|p| translated_part(p, back)).collect(),
            },
        );
        m.torsion_springs.push(TorsionSpring {
            name: spring,
            note: format!("the joint between '{body}' and '{new_body}' (split_body)"),
            joint: new_body.to_string(),
            stiffness: flex.stiffness,
            rest: 0.0,
            preload: 0.0,
            damping: flex.damping,
        });
        m.validate()?;
        Ok(m)
    }

    /// The description with the shapes of side `side` of contact `contact` on a new body
    /// `new_body`, on a revolute joint at `pivot` (in the frame of the side's body, the
    /// host; world coordinates for the ground), its frame parallel to the host's, held by a
    /// torsion spring `"<new_body> flex"` of `flex` (rest 0): a back-check on its wire.
    ///
    /// `props` gives the new body's mass properties in the host frame. A moving host keeps
    /// the remainder, as in [`Mechanism::split_body`], so the total mass, centre of mass
    /// and inertia about the host's joint are unchanged (a part the host's numbers already
    /// count, like a back-check on a key); a remainder without a positive mass or inertia
    /// is refused (`mount_compliant.props.mass`, `.props.inertia`). On the ground nothing is
    /// taken away. Only that side's shapes move: other contacts, markers and points of the
    /// host stay. The new body is listed right after its host (last for the ground).
    /// Contacts only: a string's striker moves with [`Mechanism::split_body`].
    pub fn mount_compliant(
        &self,
        contact: &str,
        side: Side,
        new_body: &str,
        pivot: [f64; 2],
        props: MassProps,
        flex: Flex,
    ) -> Result<Mechanism> {
        const F: &str = "mount_compliant";
        self.validate()?;
        let Some(ci) = self.contacts.iter().position(|c| c.name == contact) else {
            let message = if self.strings.iter().any(|s| s.name == contact) {
                format!("'{contact}' is a string: mount a striker's body with split_body")
            } else {
                format!(
                    "no contact '{contact}' (contacts: {})",
                    listed(self.contacts.iter().map(|c| c.name.as_str()))
                )
            };
            return Err(bad(F, "contact", message));
        };
        let spring = self.check_new_body(F, new_body)?;
        point(&format!("{F}.pivot"), pivot)?;
        check_props(&format!("{F}.props"), &props)?;
        check_flex(F, &flex)?;

        let mut m = self.clone();
        let c = &mut m.contacts[ci];
        let mounted = match side {
            Side::A => &mut c.a,
            Side::B => &mut c.b,
        };
        let host = std::mem::replace(&mut mounted.body, new_body.to_string());
        let back = [-pivot[0], -pivot[1]];
        mounted.shapes = mounted.shapes.iter().map(|s| s.translated(back)).collect();
        let position = if host == GROUND {
            m.bodies.len()
        } else {
            let hi = self.body_index(F, &host)?;
            let rest = remainder(&format!("{F}.props"), &self.bodies[hi], &props)?;
            let h = &mut m.bodies[hi];
            h.mass = rest.mass;
            h.com = rest.com;
            h.inertia = rest.inertia;
            hi + 1
        };
        m.bodies.insert(
            position,
            Body {
                name: new_body.to_string(),
                note: format!(
                    "carries side {} of contact '{contact}', on a sprung pivot on '{host}' \
                     (mount_compliant)",
                    match side {
                        Side::A => "a",
                        Side::B => "b",
                    }
                ),
                mass: props.mass,
                com: sub(props.com, pivot),
                inertia: props.inertia,
                joint: revolute_on(&host, pivot),
                outline: Vec::new(),
            },
        );
        m.torsion_springs.push(TorsionSpring {
            name: spring,
            note: format!("the mount of '{new_body}' on '{host}' (mount_compliant)"),
            joint: new_body.to_string(),
            stiffness: flex.stiffness,
            rest: 0.0,
            preload: 0.0,
            damping: flex.damping,
        });
        m.validate()?;
        Ok(m)
    }

    /// The description with the normal law of contact (or string) `contact` replaced by
    /// `law`. A string's striker takes an elastic law (not Stulov's hereditary felt).
    pub fn swap_law(&self, contact: &str, law_spec: LawSpec) -> Result<Mechanism> {
        const F: &str = "swap_law";
        self.validate()?;
        law(&format!("{F}.law"), &law_spec)?;
        let mut m = self.clone();
        if let Some(c) = m.contacts.iter_mut().find(|c| c.name == contact) {
            c.law = law_spec;
        } else if let Some(s) = m.strings.iter_mut().find(|s| s.name == contact) {
            if let LawSpec::Stulov { .. } = law_spec {
                return Err(bad(
                    F,
                    "law",
                    "a striker on a string takes an elastic law (the string gives the loss)",
                ));
            }
            s.law = law_spec;
        } else {
            return Err(bad(
                F,
                "contact",
                format!(
                    "no contact or string '{contact}' (known: {})",
                    self.contact_names()
                ),
            ));
        }
        m.validate()?;
        Ok(m)
    }

    /// The description with the friction of contact `contact` replaced by `friction_spec`
    /// (`None`: frictionless). Strings have no friction.
    pub fn swap_friction(
        &self,
        contact: &str,
        friction_spec: Option<ContactFrictionSpec>,
    ) -> Result<Mechanism> {
        const F: &str = "swap_friction";
        self.validate()?;
        if let Some(f) = &friction_spec {
            friction(&format!("{F}.friction"), f)?;
        }
        let mut m = self.clone();
        let Some(c) = m.contacts.iter_mut().find(|c| c.name == contact) else {
            let message = if self.strings.iter().any(|s| s.name == contact) {
                format!("'{contact}' is a string: a striker on a string has no friction")
            } else {
                format!(
                    "no contact '{contact}' (contacts: {})",
                    listed(self.contacts.iter().map(|c| c.name.as_str()))
                )
            };
            return Err(bad(F, "contact", message));
        };
        c.friction = friction_spec;
        m.validate()?;
        Ok(m)
    }
}
