//! Contact geometry: circles, half-planes (infinite lines), segments and circular arcs, with
//! the closed-form narrow phase of every pair in `f64`.
//!
//! Conventions. A shape is given in its body's frame; [`Shape::placed`] puts it in the
//! world. Surfaces have an outside:
//!
//! - a [`Circle`] is a solid disk;
//! - a [`Line`] is the boundary of a half-plane, solid on the side opposite its `normal`;
//! - a [`Segment`] from `a` to `b` is a finite face, solid on its right (walking from `a` to
//!   `b`) and facing left, its outward normal `(−dy, dx)/L`;
//! - an [`Arc`] of centre `c` and radius `R` spanning the angles `start .. start + sweep`
//!   (counter-clockwise) is either [`ArcSide::Convex`] (the rim of a solid round, touched
//!   from outside, like a hammer head or a knuckle) or [`ArcSide::Concave`] (the inside of a
//!   round hollow, touched from inside).
//!
//! A pair gives a [`Proximity`]: the signed `gap` (positive when apart, negative when the
//! surfaces overlap), the unit `normal` pointing from A toward B (the direction in which B
//! must move to separate), and the nearest points on the two surfaces, with
//! `gap = (point_b − point_a) · normal`. Pairs of faces are vertex–face contacts: a vertex
//! of one against the face of the other; parallel overlapping faces touch at the middle of
//! their overlap.

use std::f64::consts::PI;

use mbs_core::Transform;

use crate::error::{ContactError, Result};

/// A solid disk.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Centre.
    pub center: [f64; 2],
    /// Radius (m), positive.
    pub radius: f64,
}

/// The boundary of a half-plane: solid on the side opposite `normal`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Line {
    /// A point of the line.
    pub point: [f64; 2],
    /// Unit outward normal.
    pub normal: [f64; 2],
}

/// A finite face from `a` to `b`, solid on its right, facing left.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Start.
    pub a: [f64; 2],
    /// End.
    pub b: [f64; 2],
    /// Unit direction from `a` to `b` (kept so placing a segment rotates it rather than
    /// taking a square root at every evaluation).
    u: [f64; 2],
    /// Length.
    len: f64,
}

/// Which side of an arc is the surface.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArcSide {
    /// The rim of a solid round, touched from outside.
    Convex,
    /// The inside of a round hollow, touched from inside.
    Concave,
}

/// A circular arc: centre, radius, span of angles `start .. start + sweep`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Arc {
    /// Centre.
    pub center: [f64; 2],
    /// Radius (m), positive.
    pub radius: f64,
    /// First angle of the span (rad, counter-clockwise from the frame's x axis).
    pub start: f64,
    /// Angular extent (rad), in (0, 2π].
    pub sweep: f64,
    /// Which side is the surface.
    pub side: ArcSide,
}

/// A contact shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A solid disk.
    Circle(Circle),
    /// A half-plane boundary.
    Line(Line),
    /// A finite face.
    Segment(Segment),
    /// A circular arc.
    Arc(Arc),
}

fn finite(shape: &str, v: &[f64]) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ContactError::DegenerateShape {
            shape: shape.into(),
            message: format!("numbers must be finite, got {v:?}"),
        })
    }
}

impl Shape {
    /// A circle; the radius must be positive.
    pub fn circle(center: [f64; 2], radius: f64) -> Result<Shape> {
        finite("circle", &[center[0], center[1], radius])?;
        if radius <= 0.0 {
            return Err(ContactError::DegenerateShape {
                shape: "circle".into(),
                message: format!("radius must be positive, got {radius}"),
            });
        }
        Ok(Shape::Circle(Circle { center, radius }))
    }

    /// A half-plane boundary through `point` with outward `normal` (normalised here; must
    /// be non-zero).
    pub fn line(point: [f64; 2], normal: [f64; 2]) -> Result<Shape> {
        finite("line", &[point[0], point[1], normal[0], normal[1]])?;
        let n = normal[0].hypot(normal[1]);
        if n <= 1e-12 {
            return Err(ContactError::DegenerateShape {
                shape: "line".into(),
                message: "normal must be non-zero".into(),
            });
        }
        Ok(Shape::Line(Line {
            point,
            normal: [normal[0] / n, normal[1] / n],
        }))
    }

    /// A face from `a` to `b` (solid on the right); its length must be positive.
    pub fn segment(a: [f64; 2], b: [f64; 2]) -> Result<Shape> {
        finite("segment", &[a[0], a[1], b[0], b[1]])?;
        if (b[0] - a[0]).hypot(b[1] - a[1]) <= 1e-12 {
            return Err(ContactError::DegenerateShape {
                shape: "segment".into(),
                message: format!("zero length: a = {a:?}, b = {b:?}"),
            });
        }
        let d = [b[0] - a[0], b[1] - a[1]];
        let len = d[0].hypot(d[1]);
        Ok(Shape::Segment(Segment {
            a,
            b,
            u: [d[0] / len, d[1] / len],
            len,
        }))
    }

    /// An arc; radius positive, sweep in (0, 2π].
    pub fn arc(
        center: [f64; 2],
        radius: f64,
        start: f64,
        sweep: f64,
        side: ArcSide,
    ) -> Result<Shape> {
        finite("arc", &[center[0], center[1], radius, start, sweep])?;
        if radius <= 0.0 || sweep <= 0.0 || sweep > 2.0 * PI + 1e-12 {
            return Err(ContactError::DegenerateShape {
                shape: "arc".into(),
                message: format!(
                    "needs radius > 0 and sweep in (0, 2π], got radius {radius}, sweep {sweep}"
                ),
            });
        }
        Ok(Shape::Arc(Arc {
            center,
            radius,
            start,
            sweep: sweep.min(2.0 * PI),
            side,
        }))
    }

    /// The same shape expressed in the parent frame of `pose` (e.g. the world, with the
    /// body's world pose).
    pub fn placed(&self, pose: &Transform) -> Shape {
        match *self {
            Shape::Circle(c) => Shape::Circle(Circle {
                center: pose.transform_point(c.center),
                radius: c.radius,
            }),
            Shape::Line(l) => Shape::Line(Line {
                point: pose.transform_point(l.point),
                normal: pose.rotate(l.normal),
            }),
            Shape::Segment(s) => Shape::Segment(Segment {
                a: pose.transform_point(s.a),
                b: pose.transform_point(s.b),
                u: pose.rotate(s.u),
                len: s.len,
            }),
            Shape::Arc(a) => Shape::Arc(Arc {
                center: pose.transform_point(a.center),
                start: a.start + pose.angle(),
                ..a
            }),
        }
    }
}

/// The nearest points of two shapes and the signed gap between them (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Proximity {
    /// Signed distance (m): positive apart, negative overlapping.
    pub gap: f64,
    /// Unit normal from A toward B.
    pub normal: [f64; 2],
    /// Nearest point on A's surface.
    pub point_a: [f64; 2],
    /// Nearest point on B's surface.
    pub point_b: [f64; 2],
}

impl Proximity {
    /// The same contact seen from the other side.
    pub fn flipped(&self) -> Proximity {
        Proximity {
            gap: self.gap,
            normal: [-self.normal[0], -self.normal[1]],
            point_a: self.point_b,
            point_b: self.point_a,
        }
    }

    /// The unit tangent: the normal turned a quarter counter-clockwise.
    pub fn tangent(&self) -> [f64; 2] {
        [-self.normal[1], self.normal[0]]
    }
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

/// Euclidean length; plain `sqrt` (lengths in a mechanism are far from overflow, and
/// `hypot` costs several times more).
fn norm(a: [f64; 2]) -> f64 {
    (a[0] * a[0] + a[1] * a[1]).sqrt()
}

fn dot(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

fn axpy(a: [f64; 2], k: f64, d: [f64; 2]) -> [f64; 2] {
    [a[0] + k * d[0], a[1] + k * d[1]]
}

/// Two rounded points: centres `pa`, `pb` with radii `ra`, `rb` (0 for a sharp vertex). When
/// the centres coincide the direction is undefined; `fallback` is used.
fn round_round(pa: [f64; 2], ra: f64, pb: [f64; 2], rb: f64, fallback: [f64; 2]) -> Proximity {
    let d = sub(pb, pa);
    let dist = norm(d);
    let n = if dist > 1e-15 {
        [d[0] / dist, d[1] / dist]
    } else {
        fallback
    };
    Proximity {
        gap: dist - ra - rb,
        normal: n,
        point_a: axpy(pa, ra, n),
        point_b: axpy(pb, -rb, n),
    }
}

/// A face (point `p0`, outward unit normal `n`, optional span along the face from `p0` of
/// length `len` in direction `u`) against a rounded point (`c`, `r`). Outside the span the
/// nearer end of the face is the contact.
fn face_round(
    p0: [f64; 2],
    n: [f64; 2],
    span: Option<([f64; 2], f64)>,
    c: [f64; 2],
    r: f64,
) -> Proximity {
    if let Some((u, len)) = span {
        let s = dot(sub(c, p0), u);
        if s < 0.0 {
            return round_round(p0, 0.0, c, r, n);
        }
        if s > len {
            return round_round(axpy(p0, len, u), 0.0, c, r, n);
        }
    }
    let h = dot(sub(c, p0), n);
    Proximity {
        gap: h - r,
        normal: n,
        point_a: axpy(c, -h, n),
        point_b: axpy(c, -r, n),
    }
}

/// Unit direction and length of a segment.
fn seg_frame(s: &Segment) -> ([f64; 2], f64, [f64; 2]) {
    let u = s.u;
    // Outward normal: the direction turned a quarter counter-clockwise (faces left).
    (u, s.len, [-u[1], u[0]])
}

/// Whether angle `phi` lies in the arc's span.
fn in_span(a: &Arc, phi: f64) -> bool {
    if a.sweep >= 2.0 * PI {
        return true;
    }
    let rel = (phi - a.start).rem_euclid(2.0 * PI);
    rel <= a.sweep
}

fn arc_ends(a: &Arc) -> [[f64; 2]; 2] {
    let (s0, c0) = a.start.sin_cos();
    let (s1, c1) = (a.start + a.sweep).sin_cos();
    [
        [a.center[0] + a.radius * c0, a.center[1] + a.radius * s0],
        [a.center[0] + a.radius * c1, a.center[1] + a.radius * s1],
    ]
}

fn arc_mid_direction(a: &Arc) -> [f64; 2] {
    let (s, c) = (a.start + 0.5 * a.sweep).sin_cos();
    [c, s]
}

/// An arc (A) against a rounded point (`p`, `r`).
fn arc_round(a: &Arc, p: [f64; 2], r: f64) -> Proximity {
    let d = sub(p, a.center);
    let dist = norm(d);
    // Concentric: every direction is as good; take the middle of the span.
    let u = if dist > 1e-15 {
        [d[0] / dist, d[1] / dist]
    } else {
        arc_mid_direction(a)
    };
    let phi = u[1].atan2(u[0]);
    if in_span(a, phi) {
        let surface = axpy(a.center, a.radius, u);
        return match a.side {
            ArcSide::Convex => Proximity {
                gap: dist - a.radius - r,
                normal: u,
                point_a: surface,
                point_b: axpy(p, -r, u),
            },
            ArcSide::Concave => Proximity {
                gap: a.radius - dist - r,
                normal: [-u[0], -u[1]],
                point_a: surface,
                point_b: axpy(p, r, u),
            },
        };
    }
    let mut c = Candidates::new();
    for e in arc_ends(a) {
        c.push(round_round(e, 0.0, p, r, u));
    }
    c.nearest()
}

/// Up to eight candidate contacts on the stack (no allocation in the narrow phase).
#[derive(Clone, Copy)]
struct Candidates {
    items: [Proximity; 8],
    len: usize,
}

impl Candidates {
    fn new() -> Self {
        let zero = Proximity {
            gap: f64::INFINITY,
            normal: [1.0, 0.0],
            point_a: [0.0, 0.0],
            point_b: [0.0, 0.0],
        };
        Self {
            items: [zero; 8],
            len: 0,
        }
    }

    fn push(&mut self, p: Proximity) {
        if self.len < self.items.len() {
            self.items[self.len] = p;
            self.len += 1;
        }
    }

    /// A face (point `p0`, outward normal `n`, optional span) against sharp vertices.
    fn face_vertices(
        &mut self,
        p0: [f64; 2],
        n: [f64; 2],
        span: Option<([f64; 2], f64)>,
        vertices: &[[f64; 2]],
    ) {
        for &v in vertices {
            self.push(face_round(p0, n, span, v, 0.0));
        }
    }

    /// The candidate with the smallest gap; near-ties with the same normal (parallel
    /// faces) touch at the middle of the tied points.
    fn nearest(&self) -> Proximity {
        let all = &self.items[..self.len.max(1)];
        let mut best = all[0];
        for c in &all[1..] {
            if c.gap < best.gap {
                best = *c;
            }
        }
        let tol = 1e-12 + 1e-9 * best.gap.abs();
        let (mut pa, mut pb, mut count) = ([0.0, 0.0], [0.0, 0.0], 0.0);
        for c in all {
            if (c.gap - best.gap).abs() <= tol && dot(c.normal, best.normal) > 1.0 - 1e-9 {
                pa = axpy(pa, 1.0, c.point_a);
                pb = axpy(pb, 1.0, c.point_b);
                count += 1.0;
            }
        }
        if count > 1.0 {
            best.point_a = [pa[0] / count, pa[1] / count];
            best.point_b = [pb[0] / count, pb[1] / count];
        }
        best
    }
}

/// The point of a convex arc farthest along `-n` (its support point toward a face of
/// outward normal `n`), if the span contains it.
fn arc_support(a: &Arc, n: [f64; 2]) -> Option<[f64; 2]> {
    if a.side != ArcSide::Convex {
        return None;
    }
    let phi = (-n[1]).atan2(-n[0]);
    in_span(a, phi).then(|| axpy(a.center, -a.radius, n))
}

/// The proximity of two placed shapes (both in the same frame), A then B.
pub fn proximity(a: &Shape, b: &Shape) -> Result<Proximity> {
    use Shape::*;
    Ok(match (a, b) {
        (Circle(ca), Circle(cb)) => {
            round_round(ca.center, ca.radius, cb.center, cb.radius, [1.0, 0.0])
        }
        (Line(l), Circle(c)) => face_round(l.point, l.normal, None, c.center, c.radius),
        (Segment(s), Circle(c)) => {
            let (u, len, n) = seg_frame(s);
            face_round(s.a, n, Some((u, len)), c.center, c.radius)
        }
        (Arc(ar), Circle(c)) => arc_round(ar, c.center, c.radius),
        (Line(l), Segment(s)) => {
            let mut c = Candidates::new();
            c.face_vertices(l.point, l.normal, None, &[s.a, s.b]);
            c.nearest()
        }
        (Line(l), Arc(ar)) => {
            let mut c = Candidates::new();
            c.face_vertices(l.point, l.normal, None, &arc_ends(ar));
            if let Some(p) = arc_support(ar, l.normal) {
                c.push(face_round(l.point, l.normal, None, p, 0.0));
            }
            c.nearest()
        }
        (Segment(sa), Segment(sb)) => {
            let (ua, la, na) = seg_frame(sa);
            let (ub, lb, nb) = seg_frame(sb);
            let mut c = Candidates::new();
            c.face_vertices(sa.a, na, Some((ua, la)), &[sb.a, sb.b]);
            for v in [sa.a, sa.b] {
                c.push(face_round(sb.a, nb, Some((ub, lb)), v, 0.0).flipped());
            }
            c.nearest()
        }
        (Segment(s), Arc(ar)) => {
            let (u, len, n) = seg_frame(s);
            let mut c = Candidates::new();
            c.face_vertices(s.a, n, Some((u, len)), &arc_ends(ar));
            if let Some(p) = arc_support(ar, n) {
                c.push(face_round(s.a, n, Some((u, len)), p, 0.0));
            }
            for v in [s.a, s.b] {
                c.push(arc_round(ar, v, 0.0).flipped());
            }
            c.nearest()
        }
        (Arc(x), Arc(y)) => arc_arc(x, y)?,
        (Line(_), Line(_)) => {
            return Err(ContactError::DegenerateShape {
                shape: "line–line".into(),
                message: "two half-planes have no nearest points; use segments".into(),
            });
        }
        // The remaining orders are the pairs above seen from the other side.
        (Circle(_), _) | (Segment(_), Line(_)) | (Arc(_), Line(_)) | (Arc(_), Segment(_)) => {
            proximity(b, a)?.flipped()
        }
    })
}

/// Arc against arc: the line of centres when both spans face each other, else the ends.
fn arc_arc(x: &Arc, y: &Arc) -> Result<Proximity> {
    if x.side == ArcSide::Concave && y.side == ArcSide::Concave {
        return Err(ContactError::DegenerateShape {
            shape: "arc–arc".into(),
            message: "two concave arcs cannot touch from their surface sides".into(),
        });
    }
    let mut c = Candidates::new();
    for e in arc_ends(y) {
        c.push(arc_round(x, e, 0.0));
    }
    for e in arc_ends(x) {
        c.push(arc_round(y, e, 0.0).flipped());
    }
    let d = sub(y.center, x.center);
    let dist = norm(d);
    if dist > 1e-15 {
        let u = [d[0] / dist, d[1] / dist];
        let up = u[1].atan2(u[0]);
        let down = (-u[1]).atan2(-u[0]);
        match (x.side, y.side) {
            (ArcSide::Convex, ArcSide::Convex) if in_span(x, up) && in_span(y, down) => {
                c.push(round_round(x.center, x.radius, y.center, y.radius, u));
            }
            // A convex round inside a concave hollow: nearest where the hollow is farthest.
            (ArcSide::Convex, ArcSide::Concave) if in_span(x, down) && in_span(y, down) => {
                let pa = axpy(x.center, -x.radius, u);
                let pb = axpy(y.center, -y.radius, u);
                // The hollow separates by moving toward the side of contact (−u).
                c.push(Proximity {
                    gap: y.radius - dist - x.radius,
                    normal: [-u[0], -u[1]],
                    point_a: pa,
                    point_b: pb,
                });
            }
            (ArcSide::Concave, ArcSide::Convex) if in_span(x, up) && in_span(y, up) => {
                let pa = axpy(x.center, x.radius, u);
                let pb = axpy(y.center, y.radius, u);
                c.push(Proximity {
                    gap: x.radius - dist - y.radius,
                    normal: [-u[0], -u[1]],
                    point_a: pa,
                    point_b: pb,
                });
            }
            _ => {}
        }
    }
    Ok(c.nearest())
}
