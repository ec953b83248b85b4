//! A full `piano diagnose` of the example pendulum dataset (two 4 s runs at 3000 fps, a
//! hidden viscous flange): data check, calibration, four candidates refitted and judged,
//! held-out fits. Target ≤ 10 s on a 2-core machine (issue 13). Run with
//! `cargo bench -p piano-action --bench diagnose`.

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use mbs_identify::Dataset;
use piano_action::ActionParams;
use piano_action::identify::diagnose::{DiagnoseOptions, diagnose};

fn diagnosis(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/data/pendulum_viscous");
    let Ok(dataset) = Dataset::load(&dir) else {
        eprintln!("the example dataset is missing: {}", dir.display());
        return;
    };
    let params = ActionParams::reference();
    let options = DiagnoseOptions::default();
    c.bench_function("diagnose_pendulum_2x4s_3000fps", |b| {
        b.iter(|| {
            diagnose(black_box(&params), &dataset, &options, &|_, _| {})
                .map(|d| d.decision)
                .unwrap_or_default()
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = diagnosis
}
criterion_main!(benches);
