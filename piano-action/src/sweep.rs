//! Sweeps: one keystroke per touch level, run in parallel (rayon), one row each.

use std::fmt::Write as _;

use rayon::prelude::*;

use crate::action::ModelKind;
use crate::error::{PianoError, Result};
use crate::params::ActionParams;
use crate::simulate::{Finger, Input, Run, TouchStyle, simulate};

/// What a sweep varies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepKind {
    /// A constant force on the key front (N).
    Force,
    /// The peak force of a pressed touch (N).
    Pressed,
    /// The arrival speed of a struck finger (m/s).
    Struck,
}

impl SweepKind {
    /// The name used on the command line and in the CSV.
    pub fn name(self) -> &'static str {
        match self {
            SweepKind::Force => "force",
            SweepKind::Pressed => "pressed",
            SweepKind::Struck => "struck",
        }
    }

    /// The unit of the swept value.
    pub fn unit(self) -> &'static str {
        match self {
            SweepKind::Force | SweepKind::Pressed => "N",
            SweepKind::Struck => "m/s",
        }
    }

    /// The input for one value.
    pub fn input(self, value: f64) -> Input {
        match self {
            SweepKind::Force => Input::Force {
                force_n: value,
                release_s: None,
            },
            SweepKind::Pressed => Input::Touch {
                style: TouchStyle::Pressed {
                    peak_force_n: value,
                },
                finger: Finger::default(),
            },
            SweepKind::Struck => Input::Touch {
                style: TouchStyle::Struck {
                    finger_speed_m_s: value,
                },
                finger: Finger::default(),
            },
        }
    }
}

/// `n` values from `from` to `to`, evenly spaced on a log scale (both must be positive) or
/// a linear one.
pub fn levels(from: f64, to: f64, n: usize, log: bool) -> Result<Vec<f64>> {
    if n == 0 || n > MAX_RUNS {
        return Err(PianoError::option(
            "--runs",
            format!("must be 1 to {MAX_RUNS}, got {n}"),
        ));
    }
    for (flag, v) in [("--from", from), ("--to", to)] {
        if !v.is_finite() {
            return Err(PianoError::option(flag, format!("must be finite, got {v}")));
        }
        if log && v <= 0.0 {
            return Err(PianoError::option(
                flag,
                format!("a log sweep needs positive levels, got {v} (or pass --linear)"),
            ));
        }
    }
    Ok((0..n)
        .map(|i| {
            let u = if n == 1 {
                0.0
            } else {
                i as f64 / (n - 1) as f64
            };
            if i == 0 {
                from
            } else if i == n - 1 {
                // The ends are the levels asked for, not their round-off.
                to
            } else if log {
                (from.ln() + u * (to.ln() - from.ln())).exp()
            } else {
                from + u * (to - from)
            }
        })
        .collect())
}

/// The most runs one sweep takes [D]: 100 000 keystrokes are some ten minutes on two cores.
pub const MAX_RUNS: usize = 100_000;

/// Checks every level of a sweep before any runs: the input it makes must be valid (a
/// finger speed, a force in range); the error names `--from` or `--to`.
pub fn check_levels(kind: SweepKind, values: &[f64]) -> Result<()> {
    for (i, &v) in values.iter().enumerate() {
        if let Err(e) = kind.input(v).validate() {
            let flag = if i == 0 { "--from" } else { "--to" };
            let why = e.as_input().map_or(e.to_string(), |b| b.message.clone());
            return Err(PianoError::option(
                flag,
                format!("the {} level {v}: {why}", kind.name()),
            ));
        }
    }
    Ok(())
}

/// One run of a sweep.
#[derive(Clone, Debug)]
pub struct SweepRow {
    /// The swept value.
    pub value: f64,
    /// The run, or why it failed (a failed run does not stop the others).
    pub run: std::result::Result<Run, String>,
}

/// Runs `kind` at every value of `values` in parallel on all cores, `duration_s` each,
/// calling `progress` after each run. Rows come back in the order of `values`.
pub fn sweep(
    params: &ActionParams,
    model: ModelKind,
    kind: SweepKind,
    values: &[f64],
    duration_s: f64,
    progress: &(dyn Fn() + Sync),
) -> Vec<SweepRow> {
    values
        .par_iter()
        .map(|&value| {
            let run = simulate(params, model, &kind.input(value), duration_s, 1e-3)
                .map_err(|e| e.to_string());
            progress();
            SweepRow { value, run }
        })
        .collect()
}

/// The CSV columns of [`csv`].
pub const CSV_HEADER: &str = "touch,value,unit,hammer_velocity_m_s,string_contact_s,\
contact_duration_s,key_start_s,travel_time_s,let_off_s,key_bottom_s,\
key_bottom_minus_string_contact_s,check_s,strikes,rebound_velocity_m_s,error";

/// The rows as CSV (header [`CSV_HEADER`]): times in seconds, empty where a thing did not
/// happen; `error` says why a run failed.
pub fn csv(kind: SweepKind, rows: &[SweepRow]) -> String {
    let opt = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x}"));
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for row in rows {
        let _ = write!(out, "{},{},{},", kind.name(), row.value, kind.unit());
        match &row.run {
            Ok(run) => {
                let s = run.strikes.first();
                let _ = writeln!(
                    out,
                    "{},{},{},{},{},{},{},{},{},{},{},",
                    opt(s.map(|s| s.hammer_velocity_m_s)),
                    opt(s.map(|s| s.time_s)),
                    opt(s.and_then(|s| s.contact_duration_s)),
                    opt(run.key_start_time_s),
                    opt(run.travel_time_s),
                    opt(run.let_off_time_s),
                    opt(run.key_bottom_time_s),
                    opt(run.key_bottom_time_s.zip(s).map(|(k, s)| k - s.time_s)),
                    opt(run.check_time_s),
                    run.strikes.len(),
                    opt(s.and_then(|s| s.rebound_velocity_m_s)),
                );
            }
            Err(e) => {
                let clean: String = e
                    .chars()
                    .map(|c| if c == ',' || c == '\n' { ';' } else { c })
                    .collect();
                let _ = writeln!(out, ",,,,,,,,,0,,{clean}");
            }
        }
    }
    out
}

/// One run of a sweep of a mechanism description.
#[derive(Clone, Debug)]
pub struct MechanismSweepRow {
    /// The swept force (N).
    pub value: f64,
    /// The description's metrics and the first time of each named event, or why the run
    /// failed.
    pub run: std::result::Result<(Vec<mbs_mechanism::MetricValue>, Vec<Option<f64>>), String>,
}

/// Runs `mechanism` driven by a constant force at every value of `values` (N) on its first
/// force input, in parallel, `duration_s` each, settled once ([`crate::mechanism_run`]).
pub fn sweep_mechanism(
    mechanism: &mbs_mechanism::Mechanism,
    params: &ActionParams,
    values: &[f64],
    duration_s: f64,
    progress: &(dyn Fn() + Sync),
) -> Vec<MechanismSweepRow> {
    values
        .par_iter()
        .map(|&value| {
            let run = crate::mechanism_run::simulate_mechanism(
                mechanism,
                &SweepKind::Force.input(value),
                &params.numerics,
                crate::mechanism_run::DEFAULT_SETTLE_S,
                duration_s,
                1e-3,
                &mut |_| {},
            )
            .map(|run| {
                let first = mechanism
                    .events
                    .iter()
                    .map(|e| {
                        run.events
                            .iter()
                            .find(|o| o.name == e.name)
                            .map(|o| o.time_s)
                    })
                    .collect();
                (run.metrics, first)
            })
            .map_err(|e| e.to_string());
            progress();
            MechanismSweepRow { value, run }
        })
        .collect()
}

/// The rows of a mechanism sweep as CSV: `touch,value,unit`, then every metric (its unit
/// in the header) and the first time of every named event (`<event>_s`), then `error`;
/// empty where a thing did not happen.
pub fn mechanism_csv(mechanism: &mbs_mechanism::Mechanism, rows: &[MechanismSweepRow]) -> String {
    let opt = |x: Option<f64>| x.map_or(String::new(), |x| format!("{x}"));
    let clean = |s: &str| -> String {
        s.chars()
            .map(|c| if c == ',' || c == '\n' { ';' } else { c })
            .collect()
    };
    let mut out = String::from("touch,value,unit");
    for m in &mechanism.metrics {
        let _ = write!(out, ",{} ({})", clean(&m.name), clean(&m.unit));
    }
    for e in &mechanism.events {
        let _ = write!(out, ",{}_s", clean(&e.name));
    }
    out.push_str(",error\n");
    for row in rows {
        let _ = write!(out, "force,{},N", row.value);
        match &row.run {
            Ok((metrics, first)) => {
                for m in metrics {
                    let _ = write!(out, ",{}", opt(m.value));
                }
                for t in first {
                    let _ = write!(out, ",{}", opt(*t));
                }
                out.push_str(",\n");
            }
            Err(e) => {
                for _ in 0..mechanism.metrics.len() + mechanism.events.len() {
                    out.push(',');
                }
                let _ = writeln!(out, ",{}", clean(e));
            }
        }
    }
    out
}
