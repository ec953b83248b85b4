//! Nanoseconds per contact evaluation, for each pair type: the narrow phase on shapes
//! placed by body poses (as `Contact` does at every derivative evaluation). Run with
//! `cargo bench -p mbs-contact`.

use std::f64::consts::PI;
use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mbs_contact::{ArcSide, Shape, proximity};
use mbs_core::Transform;

fn pairs() -> Vec<(&'static str, Shape, Shape)> {
    let circle = Shape::circle([0.01, 0.0], 0.015).unwrap();
    let circle2 = Shape::circle([0.0, 0.03], 0.01).unwrap();
    let line = Shape::line([0.0, 0.0], [0.0, 1.0]).unwrap();
    let seg = Shape::segment([-0.02, 0.0], [0.02, 0.0]).unwrap();
    let seg2 = Shape::segment([0.03, 0.01], [-0.01, 0.012]).unwrap();
    let arc = Shape::arc([0.0, 0.02], 0.015, PI, PI, ArcSide::Convex).unwrap();
    let arc2 = Shape::arc([0.01, -0.02], 0.012, 0.0, PI, ArcSide::Convex).unwrap();
    let hollow = Shape::arc([0.0, 0.0], 0.05, -PI / 2.0, PI, ArcSide::Concave).unwrap();
    vec![
        ("circle-circle", circle, circle2),
        ("line-circle", line, circle),
        ("segment-circle", seg, circle),
        ("arc-circle", arc, circle2),
        ("concave_arc-circle", hollow, circle),
        ("line-segment", line, seg2),
        ("segment-segment", seg, seg2),
        ("line-arc", line, arc),
        ("segment-arc", seg, arc),
        ("arc-arc", arc, arc2),
    ]
}

fn contact(c: &mut Criterion) {
    let pose_a = Transform::new(0.1, 0.002, -0.001);
    let pose_b = Transform::new(-0.05, 0.001, 0.003);
    let mut group = c.benchmark_group("narrow_phase");
    for (name, a, b) in pairs() {
        group.bench_function(name, |bench| {
            bench.iter(|| {
                let wa = black_box(&a).placed(black_box(&pose_a));
                let wb = black_box(&b).placed(black_box(&pose_b));
                proximity(&wa, &wb).map(|p| p.gap).unwrap_or(0.0)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, contact);
criterion_main!(benches);
