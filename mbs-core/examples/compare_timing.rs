//! Our side of the side-by-side timing against native Pinocchio
//! (`benches/compare/run.sh`, which builds and runs both and prints the table).
//!
//! ```text
//! cargo run --release -p mbs-core --example compare_timing
//! ```
//!
//! Evaluates `benchmarks::planar_chain(5)` and `benchmarks::branching_tree()` at the state of
//! `benches/dynamics.rs`, prints the values (the script checks them against Pinocchio's to
//! prove the models are the same), then times RNEA, CRBA and ABA exactly as
//! `benches/compare/pinocchio_bench.cpp` times Pinocchio: the batch size doubles until one
//! batch lasts 10 ms (the warm-up), then 30 batches give the median, min and max time per
//! call. One record per line:
//!
//! ```text
//! value <model> <quantity> <x0> <x1> ...        (17 significant digits, matrices row-major)
//! time  <model> <algorithm> <median_us> <min_us> <max_us> <calls_per_batch>
//! ```

use std::hint::black_box;
use std::io::Write;
use std::time::{Duration, Instant};

use mbs_core::benchmarks::{benchmark_state, branching_tree, planar_chain, spread};
use mbs_core::{Data, Model, aba, crba, rnea};

/// Batches timed per (model, algorithm).
const BATCHES: usize = 30;
/// The batch size doubles until one batch lasts this long.
const TARGET_BATCH: Duration = Duration::from_millis(10);

/// Median, min and max time per call over the batches (µs), and the batch size.
struct Timing {
    median_us: f64,
    min_us: f64,
    max_us: f64,
    calls: u64,
}

fn time_batch(call: &mut impl FnMut() -> f64, n: u64) -> Duration {
    let start = Instant::now();
    for _ in 0..n {
        black_box(call());
    }
    start.elapsed()
}

fn time_per_call(mut call: impl FnMut() -> f64) -> Timing {
    let mut n = 1;
    while time_batch(&mut call, n) < TARGET_BATCH {
        n *= 2;
    }
    let mut per_call_us: Vec<f64> = (0..BATCHES)
        .map(|_| time_batch(&mut call, n).as_secs_f64() / n as f64 * 1e6)
        .collect();
    per_call_us.sort_by(f64::total_cmp);
    Timing {
        median_us: 0.5 * (per_call_us[BATCHES / 2 - 1] + per_call_us[BATCHES / 2]),
        min_us: per_call_us[0],
        max_us: per_call_us[BATCHES - 1],
        calls: n,
    }
}

/// The benchmarks' state (`mbs_core::benchmarks::benchmark_state`: the reference file's for
/// the chain, a deterministic spread for the tree), and the torque at which ABA's result is compared:
/// independent of either engine's RNEA, so a model mismatch shows.
struct State {
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau_check: Vec<f64>,
}

fn state(model: &Model) -> State {
    let n = model.nv();
    let (q, v, a) = benchmark_state(model);
    State {
        q,
        v,
        a,
        tau_check: spread(n, 4.1),
    }
}

fn print_values(out: &mut impl Write, model: &str, quantity: &str, x: &[f64]) {
    let numbers: Vec<String> = x.iter().map(|v| format!("{v:.16e}")).collect();
    writeln!(out, "value {model} {quantity} {}", numbers.join(" ")).expect("stdout");
}

fn print_timing(out: &mut impl Write, model: &str, algorithm: &str, t: &Timing) {
    writeln!(
        out,
        "time {model} {algorithm} {:.5} {:.5} {:.5} {}",
        t.median_us, t.min_us, t.max_us, t.calls
    )
    .expect("stdout");
    out.flush().expect("stdout");
}

fn run(out: &mut impl Write, name: &str, model: &Model) -> mbs_core::Result<()> {
    let mut data = Data::new(model);
    let State { q, v, a, tau_check } = state(model);

    print_values(out, name, "q", &q);
    print_values(out, name, "v", &v);
    print_values(out, name, "a", &a);
    print_values(out, name, "tau_check", &tau_check);
    let tau = rnea(model, &mut data, &q, &v, &a)?.as_slice().to_vec();
    print_values(out, name, "rnea_tau", &tau);
    // nalgebra is column-major and M symmetric: transpose anyway so the layout is row-major.
    let mass = crba(model, &mut data, &q)?.transpose();
    print_values(out, name, "mass_matrix", mass.as_slice());
    let qdd = aba(model, &mut data, &q, &v, &tau_check)?
        .as_slice()
        .to_vec();
    print_values(out, name, "aba_qdd", &qdd);

    let rnea_time = time_per_call(|| {
        rnea(
            model,
            &mut data,
            black_box(&q),
            black_box(&v),
            black_box(&a),
        )
        .unwrap()[0]
    });
    print_timing(out, name, "rnea", &rnea_time);
    let crba_time = time_per_call(|| crba(model, &mut data, black_box(&q)).unwrap()[(0, 0)]);
    print_timing(out, name, "crba", &crba_time);
    // ABA at RNEA's torque, as benches/dynamics.rs times it.
    let aba_time = time_per_call(|| {
        aba(
            model,
            &mut data,
            black_box(&q),
            black_box(&v),
            black_box(&tau),
        )
        .unwrap()[0]
    });
    print_timing(out, name, "aba", &aba_time);
    Ok(())
}

fn main() -> mbs_core::Result<()> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "# mbs-core, planar spatial algebra").expect("stdout");
    run(&mut out, "planar5", &planar_chain(5))?;
    run(&mut out, "tree13", &branching_tree())?;
    Ok(())
}
