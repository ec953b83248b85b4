//! Every pair of shapes against hand-computed cases, edge cases included, and properties
//! of the narrow phase (symmetry, rigid-motion invariance, gap consistency).

use std::f64::consts::PI;

use mbs_contact::{ArcSide, ContactError, Proximity, Shape, proximity};
use mbs_core::Transform;

const TOL: f64 = 1e-14;

fn close(p: &Proximity, gap: f64, normal: [f64; 2], pa: [f64; 2], pb: [f64; 2]) {
    let ok = |a: f64, b: f64| (a - b).abs() <= 1e-12;
    assert!(ok(p.gap, gap), "gap {} vs {gap}: {p:?}", p.gap);
    assert!(
        ok(p.normal[0], normal[0]) && ok(p.normal[1], normal[1]),
        "normal {p:?} vs {normal:?}"
    );
    assert!(
        ok(p.point_a[0], pa[0]) && ok(p.point_a[1], pa[1]),
        "point_a {p:?} vs {pa:?}"
    );
    assert!(
        ok(p.point_b[0], pb[0]) && ok(p.point_b[1], pb[1]),
        "point_b {p:?} vs {pb:?}"
    );
    // gap = (p_b − p_a) · n for every result.
    let g =
        (p.point_b[0] - p.point_a[0]) * p.normal[0] + (p.point_b[1] - p.point_a[1]) * p.normal[1];
    assert!(
        (g - p.gap).abs() < 1e-12,
        "inconsistent gap {g} vs {}",
        p.gap
    );
}

fn circle(c: [f64; 2], r: f64) -> Shape {
    Shape::circle(c, r).unwrap()
}

#[test]
fn circle_circle() {
    let p = proximity(&circle([0.0, 0.0], 1.0), &circle([3.0, 0.0], 0.5)).unwrap();
    close(&p, 1.5, [1.0, 0.0], [1.0, 0.0], [2.5, 0.0]);
    // Overlap along a diagonal.
    let p = proximity(&circle([0.0, 0.0], 1.0), &circle([0.6, 0.8], 0.5)).unwrap();
    close(&p, -0.5, [0.6, 0.8], [0.6, 0.8], [0.3, 0.4]);
    // Tangency.
    let p = proximity(&circle([0.0, 0.0], 1.0), &circle([0.0, 2.0], 1.0)).unwrap();
    assert!(p.gap.abs() < TOL);
    // Concentric: the direction is undefined; a fixed one is used and the gap is −(ra + rb).
    let p = proximity(&circle([1.0, 1.0], 1.0), &circle([1.0, 1.0], 0.5)).unwrap();
    close(&p, -1.5, [1.0, 0.0], [2.0, 1.0], [0.5, 1.0]);
}

#[test]
fn line_and_circle_both_ways() {
    let line = Shape::line([0.0, 0.0], [0.0, 2.0]).unwrap();
    let c = circle([2.0, 0.3], 0.5);
    let p = proximity(&line, &c).unwrap();
    close(&p, -0.2, [0.0, 1.0], [2.0, 0.0], [2.0, -0.2]);
    let q = proximity(&c, &line).unwrap();
    close(&q, -0.2, [0.0, -1.0], [2.0, -0.2], [2.0, 0.0]);
    // Deep below the line (centre inside the solid).
    let p = proximity(&line, &circle([0.0, -1.0], 0.5)).unwrap();
    close(&p, -1.5, [0.0, 1.0], [0.0, 0.0], [0.0, -1.5]);
}

#[test]
fn segment_and_circle_inside_and_beyond_the_ends() {
    // From (0,0) to (2,0): solid below, facing up.
    let seg = Shape::segment([0.0, 0.0], [2.0, 0.0]).unwrap();
    close(
        &proximity(&seg, &circle([1.0, 1.0], 0.5)).unwrap(),
        0.5,
        [0.0, 1.0],
        [1.0, 0.0],
        [1.0, 0.5],
    );
    // Tangent.
    assert!(proximity(&seg, &circle([0.3, 0.5], 0.5)).unwrap().gap.abs() < TOL);
    // Beyond the end b: the end is the contact, along the line from it to the centre.
    let p = proximity(&seg, &circle([3.0, 1.0], 0.5)).unwrap();
    let d = 2f64.sqrt();
    close(
        &p,
        d - 0.5,
        [1.0 / d, 1.0 / d],
        [2.0, 0.0],
        [3.0 - 0.5 / d, 1.0 - 0.5 / d],
    );
    // Continuity at the end: just inside and just outside give the same gap.
    let inside = proximity(&seg, &circle([2.0 - 1e-9, 0.7], 0.2))
        .unwrap()
        .gap;
    let outside = proximity(&seg, &circle([2.0 + 1e-9, 0.7], 0.2))
        .unwrap()
        .gap;
    assert!((inside - outside).abs() < 1e-9);
    // A reversed segment faces down.
    let down = Shape::segment([2.0, 0.0], [0.0, 0.0]).unwrap();
    let p = proximity(&down, &circle([1.0, -1.0], 0.5)).unwrap();
    close(&p, 0.5, [0.0, -1.0], [1.0, 0.0], [1.0, -0.5]);
}

#[test]
fn arcs_and_circles_convex_concave_ends_and_centre() {
    // Convex quarter arc, radius 1, from 0 to π/2.
    let arc = Shape::arc([0.0, 0.0], 1.0, 0.0, PI / 2.0, ArcSide::Convex).unwrap();
    let s = 0.5f64.sqrt();
    close(
        &proximity(&arc, &circle([2.0 * s, 2.0 * s], 0.5)).unwrap(),
        0.5,
        [s, s],
        [s, s],
        [1.5 * s, 1.5 * s],
    );
    // At the end point of the span, radially.
    close(
        &proximity(&arc, &circle([2.0, 0.0], 0.25)).unwrap(),
        0.75,
        [1.0, 0.0],
        [1.0, 0.0],
        [1.75, 0.0],
    );
    // Outside the span: the nearer end.
    let p = proximity(&arc, &circle([1.0, -1.0], 0.5)).unwrap();
    close(&p, 0.5, [0.0, -1.0], [1.0, 0.0], [1.0, -0.5]);
    // Continuity across the span boundary at angle 0.
    let r = 1.7;
    let just_in = proximity(&arc, &circle([r * 1e-9f64.cos(), r * 1e-9f64.sin()], 0.1))
        .unwrap()
        .gap;
    let just_out = proximity(
        &arc,
        &circle([r * (-1e-9f64).cos(), r * (-1e-9f64).sin()], 0.1),
    )
    .unwrap()
    .gap;
    assert!((just_in - just_out).abs() < 1e-8, "{just_in} vs {just_out}");
    // Concave hollow of radius 2: a ball inside touches from within.
    let hollow = Shape::arc([0.0, 0.0], 2.0, -PI / 2.0, PI, ArcSide::Concave).unwrap();
    close(
        &proximity(&hollow, &circle([0.5, 0.0], 0.5)).unwrap(),
        1.0,
        [-1.0, 0.0],
        [2.0, 0.0],
        [1.0, 0.0],
    );
    // Concentric: the middle of the span is used (angle 0 here): gap R − r.
    close(
        &proximity(&hollow, &circle([0.0, 0.0], 0.5)).unwrap(),
        1.5,
        [-1.0, 0.0],
        [2.0, 0.0],
        [0.5, 0.0],
    );
    // Reversed order flips the normal.
    let q = proximity(&circle([0.5, 0.0], 0.5), &hollow).unwrap();
    close(&q, 1.0, [1.0, 0.0], [1.0, 0.0], [2.0, 0.0]);
}

#[test]
fn faces_against_vertices_and_parallel_faces() {
    let floor = Shape::line([0.0, 0.0], [0.0, 1.0]).unwrap();
    // A tilted segment: its lower end touches.
    let seg = Shape::segment([0.0, 1.0], [2.0, 0.5]).unwrap();
    close(
        &proximity(&floor, &seg).unwrap(),
        0.5,
        [0.0, 1.0],
        [2.0, 0.0],
        [2.0, 0.5],
    );
    // Parallel to the line: contact at the middle.
    let flat = Shape::segment([0.0, 1.0], [2.0, 1.0]).unwrap();
    close(
        &proximity(&floor, &flat).unwrap(),
        1.0,
        [0.0, 1.0],
        [1.0, 0.0],
        [1.0, 1.0],
    );
    // Two parallel facing segments overlapping on x in [1, 2]: contact mid-overlap.
    let a = Shape::segment([0.0, 0.0], [2.0, 0.0]).unwrap(); // faces up
    let b = Shape::segment([3.0, 0.1], [1.0, 0.1]).unwrap(); // faces down
    close(
        &proximity(&a, &b).unwrap(),
        0.1,
        [0.0, 1.0],
        [1.5, 0.0],
        [1.5, 0.1],
    );
    // Crossing segments: the deepest vertex.
    let c = Shape::segment([2.0, 0.3], [0.5, -0.2]).unwrap();
    let p = proximity(&a, &c).unwrap();
    assert!((p.gap + 0.2).abs() < TOL, "{p:?}");
}

#[test]
fn arcs_against_faces_and_arcs() {
    let floor = Shape::line([0.0, 0.0], [0.0, 1.0]).unwrap();
    // Lower half of a round of radius 0.5 centred at height 1: its bottom touches.
    let lower = Shape::arc([0.0, 1.0], 0.5, PI, PI, ArcSide::Convex).unwrap();
    close(
        &proximity(&floor, &lower).unwrap(),
        0.5,
        [0.0, 1.0],
        [0.0, 0.0],
        [0.0, 0.5],
    );
    // Upper half: only its ends can reach the floor (both at height 1: mid-point).
    let upper = Shape::arc([0.0, 1.0], 0.5, 0.0, PI, ArcSide::Convex).unwrap();
    let p = proximity(&floor, &upper).unwrap();
    assert!((p.gap - 1.0).abs() < TOL);
    // A segment against a convex round above it, and the reverse order.
    let seg = Shape::segment([-1.0, 0.0], [1.0, 0.0]).unwrap();
    let round = Shape::arc([0.3, 0.7], 0.5, 0.0, 2.0 * PI, ArcSide::Convex).unwrap();
    close(
        &proximity(&seg, &round).unwrap(),
        0.2,
        [0.0, 1.0],
        [0.3, 0.0],
        [0.3, 0.2],
    );
    close(
        &proximity(&round, &seg).unwrap(),
        0.2,
        [0.0, -1.0],
        [0.3, 0.2],
        [0.3, 0.0],
    );
    // Two convex arcs facing each other behave like circles.
    let x = Shape::arc([0.0, 0.0], 1.0, -PI / 2.0, PI, ArcSide::Convex).unwrap();
    let y = Shape::arc([3.0, 0.0], 1.0, PI / 2.0, PI, ArcSide::Convex).unwrap();
    close(
        &proximity(&x, &y).unwrap(),
        1.0,
        [1.0, 0.0],
        [1.0, 0.0],
        [2.0, 0.0],
    );
    // Turned away (x's span on the left): the ends meet instead.
    let x_away = Shape::arc([0.0, 0.0], 1.0, PI / 2.0, PI, ArcSide::Convex).unwrap();
    let p = proximity(&x_away, &y).unwrap();
    assert!((p.gap - (10f64.sqrt() - 1.0)).abs() < 1e-12, "{p:?}");
    // A round inside a hollow: nearest where the wall is closest.
    let ball = Shape::arc([0.2, 0.0], 0.5, 0.0, 2.0 * PI, ArcSide::Convex).unwrap();
    let hollow = Shape::arc([0.0, 0.0], 1.0, 0.0, 2.0 * PI, ArcSide::Concave).unwrap();
    close(
        &proximity(&ball, &hollow).unwrap(),
        0.3,
        [1.0, 0.0],
        [0.7, 0.0],
        [1.0, 0.0],
    );
    close(
        &proximity(&hollow, &ball).unwrap(),
        0.3,
        [-1.0, 0.0],
        [1.0, 0.0],
        [0.7, 0.0],
    );
}

#[test]
fn degenerate_shapes_and_pairs_are_rejected() {
    let bad = [
        Shape::circle([0.0, 0.0], 0.0),
        Shape::circle([f64::NAN, 0.0], 1.0),
        Shape::segment([1.0, 1.0], [1.0, 1.0]),
        Shape::line([0.0, 0.0], [0.0, 0.0]),
        Shape::arc([0.0, 0.0], 1.0, 0.0, 0.0, ArcSide::Convex),
        Shape::arc([0.0, 0.0], -1.0, 0.0, 1.0, ArcSide::Convex),
        Shape::arc([0.0, 0.0], 1.0, 0.0, 7.0, ArcSide::Convex),
    ];
    for b in bad {
        assert!(
            matches!(b, Err(ContactError::DegenerateShape { .. })),
            "{b:?}"
        );
    }
    let l = Shape::line([0.0, 0.0], [0.0, 1.0]).unwrap();
    assert!(proximity(&l, &l).is_err());
    let h = Shape::arc([0.0, 0.0], 1.0, 0.0, 1.0, ArcSide::Concave).unwrap();
    assert!(proximity(&h, &h).is_err());
}

#[test]
fn narrow_phase_is_symmetric_and_invariant_under_rigid_motion() {
    let shapes = [
        circle([0.1, 0.2], 0.3),
        Shape::segment([-0.5, -0.1], [0.7, 0.2]).unwrap(),
        Shape::arc([0.2, -0.1], 0.6, 0.3, 2.0, ArcSide::Convex).unwrap(),
        Shape::line([0.0, -0.4], [0.2, 1.0]).unwrap(),
    ];
    let motions = [
        Transform::new(0.7, 0.3, -0.2),
        Transform::new(-2.1, -1.0, 0.5),
    ];
    let offsets = [
        Transform::new(0.4, 1.3, 0.9),
        Transform::new(2.0, -0.6, 1.4),
    ];
    for a in &shapes {
        for b in &shapes {
            if matches!((a, b), (Shape::Line(_), Shape::Line(_))) {
                continue;
            }
            for off in &offsets {
                let b_off = b.placed(off);
                let p = proximity(a, &b_off).unwrap();
                let q = proximity(&b_off, a).unwrap();
                assert!((p.gap - q.gap).abs() < 1e-12, "{a:?} {b:?}");
                for m in &motions {
                    let r = proximity(&a.placed(m), &b_off.placed(m)).unwrap();
                    assert!(
                        (r.gap - p.gap).abs() < 1e-12,
                        "{a:?} {b:?}: {} vs {}",
                        r.gap,
                        p.gap
                    );
                    let n = m.rotate(p.normal);
                    assert!((r.normal[0] - n[0]).abs() < 1e-9 && (r.normal[1] - n[1]).abs() < 1e-9);
                }
            }
        }
    }
}
