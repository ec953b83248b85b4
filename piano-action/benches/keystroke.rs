//! A loud keystroke on the double-escapement action: 0.2 s simulated (target ≤ 10 ms wall
//! on a 2-core machine). Run with `cargo bench -p piano-action`; the work counts are
//! printed once before timing. The action's rest is settled once (about 4 ms) and
//! remembered, as in a sweep; each timed keystroke starts from it.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use piano_action::{ActionParams, Input, ModelKind, simulate};

fn keystroke(c: &mut Criterion) {
    let params = ActionParams::reference();
    let input = Input::Force {
        force_n: 30.0,
        release_s: None,
    };
    if let Ok(run) = simulate(&params, ModelKind::Double, &input, 0.2, 1e-3) {
        eprintln!("loud keystroke, 0.2 s: {:?}", run.solution.stats);
    }
    c.bench_function("double_loud_keystroke_0.2s", |b| {
        b.iter(|| {
            simulate(black_box(&params), ModelKind::Double, &input, 0.2, 1e-3)
                .map(|r| r.strikes.len())
                .unwrap_or(0)
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = keystroke
}
criterion_main!(benches);
