//! Prescribed key motions: monotonic key-front motions down to the full dip must strike
//! once; the hammer speed they give against the lever ratio; and the control, a let-off
//! regulated too close, which should make some of them double-strike or block.

use rayon::prelude::*;

use super::touches::{TOUCH_DURATION_S, Touch};
use super::{Band, Row};
use crate::action::ModelKind;
use crate::error::Result;
use crate::params::ActionParams;
use crate::regulation;
use crate::simulate::{Input, simulate};

/// A monotonic key-front motion down to the full dip and held.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Profile {
    /// Constant speed from the start (the corners rounded over 5 ms).
    Linear,
    /// Minimum jerk (quintic), peaking at the speed.
    MinimumJerk,
    /// Constant acceleration to the speed over `ramp_s`, then constant speed.
    Ramp { ramp_s: f64 },
}

/// The full dip the motions go to (mm): the nominal 10 mm (literature §2).
const MOTION_DIP_MM: f64 = 10.0;

/// Key-front speeds of the motions (m/s): A&J's "0.3-0.5 at mf, seldom above 1 at forte",
/// down to a soft 0.1.
const MOTION_SPEEDS: [f64; 4] = [0.1, 0.2, 0.5, 1.0];

/// Motion start (s): the key rests this long first.
const MOTION_START_S: f64 = 5e-3;

impl Profile {
    /// `(time_s, depth_mm)` points reaching `speed` (m/s) at its fastest, sampled every ms
    /// where curved; and when the dip is reached (s).
    fn points(self, speed: f64) -> (Vec<(f64, f64)>, f64) {
        let d = MOTION_DIP_MM;
        let v = speed * 1e3; // mm/s
        let t0 = MOTION_START_S;
        let sample = |t_end: f64, depth: &dyn Fn(f64) -> f64| {
            let n = (t_end / 1e-3).ceil() as usize;
            let mut p = vec![(0.0, 0.0)];
            p.extend((0..=n).map(|i| {
                let t = t_end * i as f64 / n as f64;
                (t0 + t, depth(t))
            }));
            (p, t0 + t_end)
        };
        match self {
            Profile::Linear => (vec![(0.0, 0.0), (t0, 0.0), (t0 + d / v, d)], t0 + d / v),
            Profile::MinimumJerk => {
                // s(u) = 10u³ − 15u⁴ + 6u⁵ peaks at 15/8 d/T.
                let t_end = 1.875 * d / v;
                sample(t_end, &|t| {
                    let u = t / t_end;
                    d * u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
                })
            }
            Profile::Ramp { ramp_s } => {
                let t_end = ramp_s + (d - 0.5 * v * ramp_s) / v;
                sample(t_end, &|t| {
                    if t < ramp_s {
                        0.5 * v * t * t / ramp_s
                    } else {
                        0.5 * v * ramp_s + v * (t - ramp_s)
                    }
                })
            }
        }
    }
}

/// What a motion run gave: its blows, whether the last one never left the string (the
/// hammer blocked against it), and the hammer speed at the first blow.
#[derive(Clone, Copy, Debug, PartialEq)]
struct MotionOutcome {
    strikes: usize,
    blocked: bool,
    first_speed_m_s: Option<f64>,
}

impl MotionOutcome {
    /// The blows of `run`; the first one's speed kept when `with_speed`.
    fn of(run: &crate::simulate::Run, with_speed: bool) -> Self {
        MotionOutcome {
            strikes: run.strikes.len(),
            blocked: run
                .strikes
                .last()
                .is_some_and(|s| s.contact_duration_s.is_none()),
            first_speed_m_s: run
                .strikes
                .first()
                .filter(|_| with_speed)
                .map(|s| s.hammer_velocity_m_s),
        }
    }

    /// Exactly one blow that left the string.
    fn single(&self) -> bool {
        self.strikes == 1 && !self.blocked
    }

    /// `2 strikes`, `1 strike, blocked`.
    fn describe(&self) -> String {
        format!(
            "{} strike{}{}",
            self.strikes,
            if self.strikes == 1 { "" } else { "s" },
            if self.blocked { ", blocked" } else { "" }
        )
    }
}

fn motion_strikes(
    params: &ActionParams,
    kind: ModelKind,
    profile: Profile,
    speed: f64,
) -> Result<MotionOutcome> {
    let (points, t_dip) = profile.points(speed);
    let run = simulate(params, kind, &Input::Motion { points }, t_dip + 0.15, 1e-3)?;
    Ok(MotionOutcome::of(&run, true))
}

/// The motion families: (id, description, profile and speed of each run).
/// A family of motions: id, description, and the profile and speed of each run.
type Family = (&'static str, &'static str, Vec<(Profile, f64)>);

fn motion_families() -> Vec<Family> {
    let every = |p: Profile| MOTION_SPEEDS.iter().map(|&v| (p, v)).collect::<Vec<_>>();
    // Ramps of 5, 15 and 30 ms, where the constant speed is reached within half the dip.
    let ramps = [5e-3, 15e-3, 30e-3]
        .iter()
        .flat_map(|&ramp_s| {
            MOTION_SPEEDS
                .iter()
                .filter(move |&&v| 0.5 * v * 1e3 * ramp_s <= 0.5 * MOTION_DIP_MM)
                .map(move |&v| (Profile::Ramp { ramp_s }, v))
        })
        .collect();
    vec![
        ("linear", "linear motions", every(Profile::Linear)),
        (
            "minimum_jerk",
            "minimum-jerk motions",
            every(Profile::MinimumJerk),
        ),
        ("ramp", "ramps of 5-30 ms", ramps),
    ]
}

/// Describes a motion run: `linear 0.5 m/s`, `ramp 15 ms 0.2 m/s`.
fn motion_name(profile: Profile, speed: f64) -> String {
    match profile {
        Profile::Linear => format!("linear {speed} m/s"),
        Profile::MinimumJerk => format!("min-jerk {speed} m/s"),
        Profile::Ramp { ramp_s } => format!("ramp {:.0} ms {speed} m/s", ramp_s * 1e3),
    }
}

/// Key-front speeds (m/s) at which the hammer speed of a linear key motion is compared
/// with the lever ratio.
const RATIO_MOTION_SPEEDS: [f64; 3] = [0.1, 0.5, 1.0];

/// Prescribed monotonic key motions to the full dip and held, 0.1 to 1 m/s at the key
/// front: each must strike exactly once (no double strike, no blocking); and the hammer
/// speed at the string of the linear ones over the key-front speed, against the lever
/// ratio (literature §3.4: a rigid action turns 1 m/s at the key front into about 5.8 m/s).
pub(super) fn motion_rows(params: &ActionParams, kind: ModelKind) -> Vec<Row> {
    let families = motion_families();
    let runs: Vec<(Profile, f64)> = families.iter().flat_map(|f| f.2.clone()).collect();
    let outcomes: Vec<Result<MotionOutcome>> = runs
        .par_iter()
        .map(|&(p, v)| motion_strikes(params, kind, p, v))
        .collect();
    let outcome = |p: Profile, v: f64| {
        runs.iter()
            .zip(&outcomes)
            .find(|(r, _)| r.0 == p && r.1 == v)
            .map(|(_, o)| o)
    };
    let mut rows: Vec<Row> = RATIO_MOTION_SPEEDS
        .iter()
        .map(|&v| {
            let o = outcome(Profile::Linear, v);
            let row = Row::new(
                format!("motion.speed_ratio.{}", super::num(v)),
                format!("hammer / key speed, key moved at {v} m/s"),
                o.and_then(|o| o.as_ref().ok())
                    .and_then(|o| o.first_speed_m_s)
                    .map(|h| h / v),
                Band::Range(5.0, 6.0),
                "-",
                "lit. §3.4 [D], §7.2, §7.5 [V]",
            );
            match o {
                Some(Err(e)) => row.note(format!("the experiment failed: {e}")),
                Some(Ok(o)) => row.note(format!(
                    "linear key-front motion to the dip: {}, hammer {:.2} m/s",
                    o.describe(),
                    o.first_speed_m_s.unwrap_or(f64::NAN)
                )),
                None => row,
            }
        })
        .collect();
    for (id, what, family) in families {
        let mut bad = Vec::new();
        let mut error = None;
        for &(p, v) in &family {
            match outcome(p, v) {
                Some(Ok(o)) if o.single() => {}
                Some(Ok(o)) => bad.push(format!("{}: {}", motion_name(p, v), o.describe())),
                Some(Err(e)) => error = Some(format!("{}: {e}", motion_name(p, v))),
                None => {}
            }
        }
        let row = Row::new(
            format!("motion.{id}"),
            format!("{what}, 0.1-1 m/s: not 1 strike"),
            error.is_none().then_some(bad.len() as f64),
            Band::Exactly(0.0),
            "runs",
            "DESIGN sequence; lit. §7.10 [V]",
        )
        .literature("0 (one strike each)")
        .decimals(0);
        rows.push(match (error, bad.is_empty()) {
            (Some(e), _) => row.note(format!("the experiment failed: {e}")),
            (None, true) => row.note(format!("{} runs, one strike each", family.len())),
            (None, false) => row.note(format!("of {} runs: {}", family.len(), bad.join("; "))),
        });
    }
    rows
}

/// The let-off (mm) the control regulates to: "too close" (literature §2: 1.5-2.5 mm).
const CLOSE_LET_OFF_MM: f64 = 0.3;

/// The let-off button raised until the let-off is about [`CLOSE_LET_OFF_MM`] (secant
/// steps from about −7 mm of let-off per mm of button, `regulation.rs`; raising the button
/// makes the jack escape later, nearer the string): the parameters, the raise (mm) and the
/// let-off reached (`None`: the hammer reaches the string before the jack escapes).
fn close_let_off(
    params: &ActionParams,
    kind: ModelKind,
) -> Result<(ActionParams, f64, Option<f64>)> {
    let measure = |raise: f64| -> Result<(ActionParams, Option<f64>)> {
        let mut p = params.clone();
        p.regulation.let_off_button_y_mm += raise;
        let let_off = regulation::measure(&p, kind)?.let_off_mm;
        Ok((p, let_off))
    };
    let (mut p, base) = measure(0.0)?;
    let Some(mut value) = base else {
        return Ok((p, 0.0, None));
    };
    let (mut raise, mut slope) = (0.0, -7.0);
    for _ in 0..3 {
        if (value - CLOSE_LET_OFF_MM).abs() < 0.05 {
            break;
        }
        let step = ((CLOSE_LET_OFF_MM - value) / slope).clamp(-0.5, 0.5);
        let (q, got) = measure(raise + step)?;
        let Some(got) = got else {
            return Ok((q, raise + step, None));
        };
        if (got - value).abs() > 1e-6 {
            slope = (got - value) / step;
        }
        (p, raise, value) = (q, raise + step, got);
    }
    Ok((p, raise, Some(value)))
}

/// The control of the motion rows: the let-off regulated too close (about 0.3 mm) should
/// make some keystrokes that strike once at the regulated let-off double-strike or block,
/// as technicians report (upright_layout §8.4: too little let-off or aftertouch blocks or
/// "bobbles"; a soft button felt blocks). Runs: the linear and minimum-jerk motions, struck
/// touches of 0.1 to 0.5 m/s and the slow press. A row, not information: it tells whether
/// the single-strike rows could fail at all, and the model should show this behaviour.
pub(super) fn control_rows(params: &ActionParams, kind: ModelKind) -> Vec<Row> {
    #[derive(Clone, Copy)]
    enum Stroke {
        Motion(Profile, f64),
        Struck(f64),
        SlowPress,
    }
    let name = |s: Stroke| match s {
        Stroke::Motion(p, v) => motion_name(p, v),
        Stroke::Struck(v) => format!("struck {v} m/s"),
        Stroke::SlowPress => "slow press".into(),
    };
    let mut strokes: Vec<Stroke> = [Profile::Linear, Profile::MinimumJerk]
        .iter()
        .flat_map(|&p| MOTION_SPEEDS.iter().map(move |&v| Stroke::Motion(p, v)))
        .collect();
    strokes.extend([0.1, 0.2, 0.3, 0.5].map(Stroke::Struck));
    strokes.push(Stroke::SlowPress);
    let play = |p: &ActionParams, s: Stroke| -> Result<MotionOutcome> {
        let run = match s {
            Stroke::Motion(profile, v) => return motion_strikes(p, kind, profile, v),
            Stroke::Struck(v) => {
                simulate(p, kind, &Touch::Struck.input(v), TOUCH_DURATION_S, 1e-3)?
            }
            Stroke::SlowPress => simulate(
                p,
                kind,
                &Input::Motion {
                    points: vec![(0.0, 0.0), (2.0, 10.0)],
                },
                2.5,
                2e-3,
            )?,
        };
        Ok(MotionOutcome::of(&run, false))
    };
    let (close, outcomes) = rayon::join(
        || close_let_off(params, kind),
        || {
            strokes
                .par_iter()
                .map(|&s| play(params, s))
                .collect::<Vec<_>>()
        },
    );
    let row = |value: Option<f64>, note: String| {
        vec![
            Row::new(
                "motion.control_close_let_off",
                "control: let-off ~0.3 mm, new double strikes",
                value,
                Band::AtLeast(1.0),
                "runs",
                "upright layout §8.4 (Sykes) [V]",
            )
            .literature(">= 1")
            .decimals(0)
            .note(note),
        ]
    };
    let (close, raise, let_off) = match close {
        Ok(c) => c,
        Err(e) => return row(None, format!("the experiment failed: {e}")),
    };
    let closer: Vec<Result<MotionOutcome>> = strokes.par_iter().map(|&s| play(&close, s)).collect();
    // The strokes that strike once at the regulated let-off, and what they do now.
    let mut fine = 0;
    let mut worse = Vec::new();
    for ((s, before), after) in strokes.iter().zip(&outcomes).zip(&closer) {
        match (before, after) {
            (Ok(b), Ok(a)) if b.single() || matches!(s, Stroke::SlowPress) && b.strikes == 0 => {
                fine += 1;
                let normal = if matches!(s, Stroke::SlowPress) {
                    a.strikes == 0
                } else {
                    a.single()
                };
                if !normal {
                    worse.push(format!("{}: {}", name(*s), a.describe()));
                }
            }
            (Err(e), _) | (_, Err(e)) => {
                return row(None, format!("the experiment failed: {}: {e}", name(*s)));
            }
            _ => {}
        }
    }
    let let_off_text = let_off.map_or(
        "the hammer reaches the string before the jack escapes".into(),
        |l| format!("let-off {l:.2} mm"),
    );
    row(
        Some(worse.len() as f64),
        format!(
            "let-off button raised {raise:.3} mm ({let_off_text}); of the {fine} of {} strokes \
         that strike once at the regulated let-off (linear and minimum-jerk motions, struck \
         0.1-0.5 m/s, slow press with no strike): {}",
            strokes.len(),
            if worse.is_empty() {
                "none double-strikes or blocks".to_string()
            } else {
                worse.join("; ")
            }
        ),
    )
}
