//! RNEA, CRBA, ABA and CRBA + Cholesky on the 5-link planar chain of the Pinocchio
//! reference file and on the 13-body branching tree. Run with `cargo bench -p mbs-core`.
//!
//! The goal (issue 16): each algorithm ≥ 4× native Pinocchio on both models, measured side
//! by side by `benches/compare/run.sh` (its README has the latest tables: on a quiet machine
//! on 2026-11-26 the 5-link chain took 0.096 / 0.094 / 0.160 µs here against Pinocchio's
//! 0.53 / 0.21 / 1.07; the block CRBA of that afternoon takes it to about 0.065 µs built as
//! here, for generic x86-64, and 0.055 µs with `-C target-cpu=native`, as the comparison
//! builds it).

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mbs_core::benchmarks::{benchmark_state, branching_tree, branching_tree_system, planar_chain};
use mbs_core::{Data, Model, aba, crba, forward_dynamics_crba, rnea};

fn bench_model(c: &mut Criterion, name: &str, model: &Model) {
    let mut data = Data::new(model);
    let (q, v, a) = benchmark_state(model);
    let tau = rnea(model, &mut data, &q, &v, &a)
        .unwrap()
        .as_slice()
        .to_vec();
    let mut group = c.benchmark_group(name);
    group.bench_function("rnea", |b| {
        b.iter(|| {
            rnea(
                model,
                &mut data,
                black_box(&q),
                black_box(&v),
                black_box(&a),
            )
            .unwrap()[0]
        })
    });
    group.bench_function("crba", |b| {
        b.iter(|| crba(model, &mut data, black_box(&q)).unwrap()[(0, 0)])
    });
    group.bench_function("aba", |b| {
        b.iter(|| {
            aba(
                model,
                &mut data,
                black_box(&q),
                black_box(&v),
                black_box(&tau),
            )
            .unwrap()[0]
        })
    });
    group.bench_function("crba_cholesky", |b| {
        b.iter(|| {
            forward_dynamics_crba(
                model,
                &mut data,
                black_box(&q),
                black_box(&v),
                black_box(&tau),
                None,
            )
            .unwrap()[0]
        })
    });
    group.finish();
}

/// The path integrators take: `System::derivative` on the 13-body tree with one of every
/// force element and a prescribed coordinate (`benchmarks::branching_tree_system`).
fn bench_system(c: &mut Criterion) {
    let system = branching_tree_system().unwrap();
    let model = system.model().clone();
    let mut ws = system.workspace();
    let n = model.nv();
    let q: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin()).collect();
    let v: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).cos()).collect();
    let x = system.initial_state(0.0, &q, &v).unwrap();
    let mut xdot = vec![0.0; system.state_len()];
    c.bench_function("tree13/system_derivative_17_elements", |b| {
        b.iter(|| {
            system
                .derivative(&mut ws, black_box(0.2), black_box(&x), &mut xdot)
                .unwrap();
            xdot[n]
        })
    });
}

fn dynamics(c: &mut Criterion) {
    bench_model(c, "planar5", &planar_chain(5));
    bench_model(c, "tree13", &branching_tree());
    bench_system(c);
}

criterion_group!(benches, dynamics);
criterion_main!(benches);
