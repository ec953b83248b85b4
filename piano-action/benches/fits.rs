//! Fits per second on the shipped datasets (`examples/data/`): each diagnosis timed whole,
//! its criterion throughput counted in fits (so criterion prints fits/s), and the rates of
//! each stage (fits, residual evaluations and simulations per second) printed from a run.
//!
//! - `pendulum_viscous`: the whole swing-test diagnosis (two 4 s runs at 3000 fps).
//! - `key_drive_flex`: the key-drive diagnosis with the one effect hidden in the dataset
//!   (`key_flex`) as its library: the baseline's calibration, the held-out drop, the
//!   screening's 8 points, the refit and its held-out drop (about 30 s a run on 2 cores;
//!   the whole library's diagnosis prints the same table in its `report.md`).
//!
//! `cargo bench -p piano-action --bench fits` (about 6 minutes on 2 cores), or one of
//! them: `cargo bench -p piano-action --bench fits -- pendulum`.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{Criterion, SamplingMode, Throughput, criterion_group, criterion_main};
use mbs_identify::Dataset;
use mbs_identify::work::StageWork;
use piano_action::ActionParams;
use piano_action::identify::action_effects::action_effect_spec;
use piano_action::identify::diagnose::{DiagnoseOptions, diagnose};
use piano_action::identify::key_diagnose::{KeyDiagnoseOptions, diagnose_key_drive};
use piano_action::identify::report::throughput_lines;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../examples/data")
        .join(name)
}

/// Prints the stages' rates of a diagnosis, and returns its fits.
fn show(name: &str, throughput: &[StageWork]) -> u64 {
    eprintln!("{name}:");
    for line in throughput_lines(throughput) {
        eprintln!("  {line}");
    }
    throughput.last().map_or(0, |total| total.fits as u64)
}

fn pendulum(c: &mut Criterion) {
    let Ok(dataset) = Dataset::load(&data("pendulum_viscous")) else {
        eprintln!("the example dataset pendulum_viscous is missing");
        return;
    };
    let params = ActionParams::reference();
    let options = DiagnoseOptions::default();
    let run = || diagnose(black_box(&params), &dataset, &options, &|_, _| {});
    let Ok(first) = run() else {
        eprintln!("the pendulum diagnosis failed");
        return;
    };
    let fits = show("pendulum_viscous", &first.throughput);
    let mut group = c.benchmark_group("fits");
    group.throughput(Throughput::Elements(fits));
    group.sample_size(10);
    group.bench_function("pendulum_viscous", |b| {
        b.iter(|| run().map(|d| d.decision).unwrap_or_default())
    });
    group.finish();
}

fn key_drive(c: &mut Criterion) {
    let Ok(dataset) = Dataset::load(&data("key_drive_flex")) else {
        eprintln!("the example dataset key_drive_flex is missing");
        return;
    };
    let params = ActionParams::reference();
    let options = KeyDiagnoseOptions {
        library: action_effect_spec("key_flex").into_iter().collect(),
        ..KeyDiagnoseOptions::default()
    };
    let run = || diagnose_key_drive(black_box(&params), &dataset, &options, &|_, _| {});
    let Ok(first) = run() else {
        eprintln!("the key-drive diagnosis failed");
        return;
    };
    let fits = show("key_drive_flex (library: key_flex)", &first.throughput);
    let mut group = c.benchmark_group("fits");
    group.throughput(Throughput::Elements(fits));
    group.sample_size(10);
    group.sampling_mode(SamplingMode::Flat);
    group.warm_up_time(Duration::from_millis(1));
    group.bench_function("key_drive_flex_key_flex", |b| {
        b.iter(|| run().map(|d| d.decision).unwrap_or_default())
    });
    group.finish();
}

criterion_group!(benches, pendulum, key_drive);
criterion_main!(benches);
