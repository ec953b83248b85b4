//! Sweeps over touch levels, in parallel.

use piano_action::sweep::{CSV_HEADER, SweepKind, csv, levels, sweep};
use piano_action::{ActionParams, ModelKind, simulate};

#[test]
fn levels_are_spaced_as_asked_and_bad_bounds_are_named() {
    let log = levels(0.1, 10.0, 5, true).unwrap();
    for (got, want) in log
        .iter()
        .zip([0.1, 0.316_227_766, 1.0, 3.162_277_66, 10.0])
    {
        assert!((got / want - 1.0).abs() < 1e-8, "{log:?}");
    }
    assert_eq!(levels(1.0, 3.0, 3, false).unwrap(), vec![1.0, 2.0, 3.0]);
    assert_eq!(levels(2.0, 5.0, 1, true).unwrap(), vec![2.0]);
    // Each bad bound names its option.
    for (from, to, n, log, option) in [
        (0.0, 1.0, 3, true, "option --from"),
        (1.0, f64::NAN, 3, false, "option --to"),
        (1.0, 2.0, 0, false, "option --runs"),
    ] {
        let err = levels(from, to, n, log).unwrap_err();
        assert!(err.to_string().starts_with(option), "{err}");
    }
}

#[test]
fn a_parallel_sweep_matches_single_runs_in_order_and_reports_failures() {
    let params = ActionParams::reference();
    let values = [0.15, 0.3, 0.6, 1.2];
    let done = std::sync::atomic::AtomicUsize::new(0);
    let rows = sweep(
        &params,
        ModelKind::Double,
        SweepKind::Struck,
        &values,
        0.2,
        &|| {
            done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        },
    );
    assert_eq!(done.into_inner(), 4, "progress is called once per run");
    let speeds: Vec<f64> = rows
        .iter()
        .map(|r| r.run.as_ref().unwrap().strikes[0].hammer_velocity_m_s)
        .collect();
    assert_eq!(rows.iter().map(|r| r.value).collect::<Vec<_>>(), values);
    assert!(speeds.windows(2).all(|w| w[1] > w[0]), "{speeds:?}");
    // The same run alone on this thread gives the same numbers, bit for bit.
    let alone = simulate(
        &params,
        ModelKind::Double,
        &SweepKind::Struck.input(0.6),
        0.2,
        1e-3,
    )
    .unwrap();
    assert_eq!(alone.strikes, rows[2].run.as_ref().unwrap().strikes);
    // A bad level fails its own row, named, and the others still run.
    let rows = sweep(
        &params,
        ModelKind::Double,
        SweepKind::Force,
        &[-1.0, 20.0],
        0.06,
        &|| {},
    );
    let text = csv(SweepKind::Force, &rows);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3, "{text}");
    assert_eq!(lines[0], CSV_HEADER);
    assert!(
        lines[1].starts_with("force,-1,N,") && lines[1].contains("input.force_n"),
        "{}",
        lines[1]
    );
    let fields: Vec<&str> = lines[2].split(',').collect();
    assert_eq!(fields.len(), CSV_HEADER.split(',').count());
    let v: f64 = fields[3].parse().unwrap();
    assert!((4.0..8.0).contains(&v), "20 N gives {v} m/s");
    // The rebound off the string, then no error.
    let rebound: f64 = fields[13].parse().unwrap();
    assert!(
        (0.5 * v..0.8 * v).contains(&rebound),
        "rebound {rebound} m/s"
    );
    assert_eq!(fields[14], "", "no error");
}
