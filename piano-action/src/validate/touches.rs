//! Touches from soft to loud: sweeps of struck and pressed touches (the page's curves),
//! the touch that gives a row's hammer speed (bracketed by the sweep, then secant steps),
//! and the rows read off them: the velocity range, free flight after let-off, travel time
//! against Goebl's law, key bottom against string contact, the hammer–string contact and
//! rebound, the check.

use rayon::prelude::*;

use super::experiments::strike_radius;
use super::{Band, Row};
use crate::action::{Action, ModelKind};
use crate::error::Result;
use crate::params::ActionParams;
use crate::simulate::{Finger, Input, Run, TouchStyle, prepare, simulate};

/// How the finger plays the key in a touch experiment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Touch {
    /// The finger rests on the key, its force rising to a peak (level: the peak, N).
    Pressed,
    /// The finger arrives with a speed (level: the speed, m/s).
    Struck,
}

impl Touch {
    /// `"pressed"` or `"struck"`.
    pub fn name(self) -> &'static str {
        match self {
            Touch::Pressed => "pressed",
            Touch::Struck => "struck",
        }
    }

    /// The unit of the level.
    pub fn unit(self) -> &'static str {
        match self {
            Touch::Pressed => "N",
            Touch::Struck => "m/s",
        }
    }

    /// The keystroke input at `level`, with the default finger.
    pub fn input(self, level: f64) -> Input {
        let style = match self {
            Touch::Pressed => TouchStyle::Pressed {
                peak_force_n: level,
            },
            Touch::Struck => TouchStyle::Struck {
                finger_speed_m_s: level,
            },
        };
        Input::Touch {
            style,
            finger: Finger::default(),
        }
    }

    /// The softest and loudest levels the model is played with: pressed 0.65 to 50 N
    /// (just above the down weight; Kinoshita et al. 2007: staccato peaks up to 50 N at
    /// ff), struck 0.1 to 2 m/s (the finger speeds of `tests/touch.rs`).
    pub fn range(self) -> (f64, f64) {
        match self {
            Touch::Pressed => (0.65, 50.0),
            Touch::Struck => (0.1, 2.0),
        }
    }
}

/// One touch and what it gave (`None` where it did not happen).
#[derive(Clone, Debug, PartialEq)]
pub struct Blow {
    /// Pressed or struck.
    pub touch: Touch,
    /// Its level (N or m/s).
    pub level: f64,
    /// Hammer speed at the first string contact (m/s).
    pub hammer_speed_m_s: Option<f64>,
    /// Key start to the first string contact (s).
    pub travel_time_s: Option<f64>,
    /// Duration of the first string contact (s).
    pub contact_duration_s: Option<f64>,
    /// The hammer's rebound: its speed away from the string when the first contact ends
    /// over its speed at the start (e = −v_out / v_in).
    pub rebound: Option<f64>,
    /// Key bottom minus the first string contact (s).
    pub key_bottom_minus_contact_s: Option<f64>,
    /// Crown to string (mm) where the backcheck holds the hammer at the end of the run.
    pub check_mm: Option<f64>,
    /// Crown to string (mm) when the jack last stopped pushing the knuckle before the first
    /// string contact; 0 when it still pushes at contact.
    pub free_flight_mm: Option<f64>,
    /// Blows on the string.
    pub strikes: usize,
    /// Why the run failed, if it did.
    pub error: Option<String>,
}

/// The touches from soft to loud behind the rows, for the plots.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Curves {
    /// Struck touches over [`Touch::range`], log-spaced.
    pub struck: Vec<Blow>,
    /// Pressed touches over [`Touch::range`], log-spaced.
    pub pressed: Vec<Blow>,
    /// The touches matched to the hammer speeds of the rows.
    pub matched: Vec<Blow>,
}

/// Touches per sweep.
const SWEEP_LEVELS: usize = 16;

/// Simulated time of a touch (s): the softest blow reaches the string after some 0.2 s and
/// the backcheck must have caught a loud one.
pub(super) const TOUCH_DURATION_S: f64 = 0.3;

/// How much sooner a struck touch reaches the string than a pressed one of the same
/// intensity (s): "about 20 ms" (Goebl, Bresin & Galembo 2005, literature §3.2 \[S\]).
pub const STRUCK_LEAD_S: f64 = 0.020;

/// Goebl's travel-time law for `touch` (literature §3.2): 89 ms · (MHV / (m/s))^−0.57 for
/// a pressed touch (Goebl 2001's function, constants recalled \[M\], unverified), and
/// [`STRUCK_LEAD_S`] less for a struck one (Goebl et al. 2005 fit the touches separately
/// \[S\]).
pub fn goebl_travel_time_s(hammer_speed_m_s: f64, touch: Touch) -> f64 {
    let pressed = 0.089 * hammer_speed_m_s.powf(-0.57);
    match touch {
        Touch::Pressed => pressed,
        Touch::Struck => pressed - STRUCK_LEAD_S,
    }
}

/// Dynamic levels as hammer speeds at the string (m/s) \[D\], from literature §3.1 ("≈ 1 m/s
/// (p) … 5–6 m/s (ff)") and §7.5 (pp 0.3–1, ff 4–7): pp 0.5, p 1, mf 2.5, f 4, ff 5.5.
pub const DYNAMICS: [(&str, f64); 5] = [
    ("pp", 0.5),
    ("p", 1.0),
    ("mf", 2.5),
    ("f", 4.0),
    ("ff", 5.5),
];

fn dynamic(name: &str) -> f64 {
    DYNAMICS
        .iter()
        .find(|d| d.0 == name)
        .map_or(f64::NAN, |d| d.1)
}

/// Hammer-speed contact durations and rebounds of the reference experiment
/// (string_reference.md §4.1: C4, Chaigne–Askenfelt felt, waveguide string): (v_in m/s,
/// contact ms, e).
pub const CONTACT_REFERENCE: [(f64, f64, f64); 4] = [
    (0.5, 2.538, 0.747),
    (1.0, 2.283, 0.698),
    (2.0, 2.092, 0.660),
    (4.0, 1.948, 0.636),
];

/// Askenfelt & Jansson and Goebl: key bottom minus string contact (ms) at the dynamic
/// levels of [`DYNAMICS`] (literature §3.1, §3.2, §7.6; \[S\]): (level, ms).
pub const KEY_BOTTOM_REFERENCE: [(&str, f64); 5] = [
    ("pp", 35.0),
    ("p", 12.0),
    ("mf", 0.0),
    ("f", -3.0),
    ("ff", -4.0),
];

/// Hammer speeds (m/s) at which free flight is measured.
const FREE_FLIGHT_SPEEDS: [f64; 3] = [2.0, 3.5, 5.0];

/// Runs one touch and reads what it gave.
pub fn blow(params: &ActionParams, kind: ModelKind, touch: Touch, level: f64) -> Blow {
    let mut out = Blow {
        touch,
        level,
        hammer_speed_m_s: None,
        travel_time_s: None,
        contact_duration_s: None,
        rebound: None,
        key_bottom_minus_contact_s: None,
        check_mm: None,
        free_flight_mm: None,
        strikes: 0,
        error: None,
    };
    if let Err(e) = read_blow(params, kind, &mut out) {
        out.error = Some(e.to_string());
    }
    out
}

fn read_blow(params: &ActionParams, kind: ModelKind, out: &mut Blow) -> Result<()> {
    let input = out.touch.input(out.level);
    let run = simulate(params, kind, &input, TOUCH_DURATION_S, 1e-3)?;
    let action = prepare(params, kind, &input)?.action;
    out.strikes = run.strikes.len();
    let Some(strike) = run.strikes.first().copied() else {
        return Ok(());
    };
    out.hammer_speed_m_s = Some(strike.hammer_velocity_m_s);
    out.travel_time_s = run.travel_time_s;
    out.contact_duration_s = strike.contact_duration_s;
    out.key_bottom_minus_contact_s = run.key_bottom_time_s.map(|t| t - strike.time_s);
    out.rebound = rebound(params, &action, &run);
    out.free_flight_mm = free_flight_mm(&action, &run)?;
    // The hammer held by the backcheck at the end, the key still down.
    let sol = &run.solution;
    if kind != ModelKind::Simplified
        && run.check_time_s.is_some()
        && action.gap("backcheck", sol.t_final, &sol.y_final)? < 0.0
    {
        out.check_mm = Some(crown_to_string_mm(&action, sol.t_final, &sol.y_final)?);
    }
    Ok(())
}

/// The crown's distance (mm) to the string line at rest, what a technician measures
/// (the string may still ring after a blow).
fn crown_to_string_mm(action: &Action, t: f64, x: &[f64]) -> Result<f64> {
    Ok(action.string_rest_gap(t, x)? * 1e3)
}

/// e = −v_out / v_in of the first strike: the hammer's speed at the end of the contact
/// (the state of the contact's closing event, or the first output point after it) over its
/// speed at the start.
fn rebound(params: &ActionParams, action: &Action, run: &Run) -> Option<f64> {
    let s = run.strikes.first()?;
    let end = s.time_s + s.contact_duration_s?;
    let model = action.system.model();
    let (nv, hammer) = (model.nv(), model.coordinate_id("hammer").ok()?);
    let sol = &run.solution;
    let state = sol
        .events
        .iter()
        .filter(|e| e.name.contains("hammer_string"))
        .min_by(|a, b| (a.time - end).abs().total_cmp(&(b.time - end).abs()))
        .filter(|e| (e.time - end).abs() < 1e-9)
        .map(|e| e.state.as_slice())
        .or_else(|| {
            let i = sol.t.partition_point(|&t| t <= end);
            (i < sol.len()).then(|| sol.state(i))
        })?;
    let v_out = state[nv + hammer] * strike_radius(params);
    Some(-v_out / s.hammer_velocity_m_s)
}

/// Crown-to-string distance (mm) at the moment the jack stopped pushing the knuckle for
/// the last time before the first string contact (the `jack_knuckle` contact opening);
/// 0 when the jack is still under the knuckle at the string.
fn free_flight_mm(action: &Action, run: &Run) -> Result<Option<f64>> {
    let Some(strike) = run.strikes.first() else {
        return Ok(None);
    };
    let mut released: Option<f64> = None;
    let knuckle = action.contacts.get("jack_knuckle").copied();
    for e in
        run.solution.events.iter().filter(|e| {
            e.time < strike.time_s && e.source.is_some_and(|s| Some(s.element) == knuckle)
        })
    {
        // The contact's switching function is its gap: rising through zero, it opens.
        released = if e.direction == mbs_integrators::Crossing::Rising {
            Some(crown_to_string_mm(action, e.time, &e.state)?)
        } else {
            None
        };
    }
    Ok(Some(released.unwrap_or(0.0)))
}

/// `n` levels from `lo` to `hi`, evenly spaced on a log scale.
fn log_levels(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / (n - 1) as f64).exp())
        .collect()
}

/// The touch of `touch` that gives the hammer `target` m/s at the string within 1 %:
/// bracketed by the sweep, then secant steps on the logarithms (regula falsi, Illinois).
/// `Err` says why there is none.
fn matched(
    params: &ActionParams,
    kind: ModelKind,
    touch: Touch,
    target: f64,
    sweep: &[Blow],
) -> std::result::Result<Blow, String> {
    let points: Vec<(f64, f64)> = sweep
        .iter()
        .filter_map(|b| b.hammer_speed_m_s.map(|v| (b.level, v)))
        .collect();
    let bracket = points
        .windows(2)
        .find(|w| (w[0].1 - target) * (w[1].1 - target) <= 0.0)
        .map(|w| (w[0], w[1]));
    let Some((mut a, mut b)) = bracket else {
        let (lo, hi) = points.iter().fold((f64::INFINITY, 0.0_f64), |(lo, hi), p| {
            (lo.min(p.1), hi.max(p.1))
        });
        return Err(format!(
            "no {} touch from {} to {} {} gives {target} m/s (they give {lo:.2} to {hi:.2} m/s)",
            touch.name(),
            touch.range().0,
            touch.range().1,
            touch.unit()
        ));
    };
    let f = |p: (f64, f64)| p.1.ln() - target.ln();
    let (mut fa, mut fb) = (f(a), f(b));
    let mut best: Option<Blow> = None;
    let mut side = 0;
    for _ in 0..12 {
        let next = if (fb - fa).abs() > 1e-12 {
            (a.0.ln() - fa * (b.0.ln() - a.0.ln()) / (fb - fa)).exp()
        } else {
            (a.0 * b.0).sqrt()
        };
        let run = blow(params, kind, touch, next);
        let Some(v) = run.hammer_speed_m_s else {
            return Err(format!(
                "the {} touch at {next:.3} {} did not strike{}",
                touch.name(),
                touch.unit(),
                run.error.map_or(String::new(), |e| format!(": {e}"))
            ));
        };
        let fv = v.ln() - target.ln();
        if (v / target - 1.0).abs() < 0.01 {
            return Ok(run);
        }
        if best
            .as_ref()
            .and_then(|b| b.hammer_speed_m_s)
            .is_none_or(|bv| (v / target - 1.0).abs() < (bv / target - 1.0).abs())
        {
            best = Some(run);
        }
        // Keep the root bracketed; halve the stale end's value when one end sticks.
        if fv * fa > 0.0 {
            (a, fa) = ((next, v), fv);
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        } else {
            (b, fb) = ((next, v), fv);
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        }
    }
    best.filter(|b| {
        b.hammer_speed_m_s
            .is_some_and(|v| (v / target - 1.0).abs() < 0.03)
    })
    .ok_or_else(|| {
        format!(
            "no {} touch found giving {target} m/s within 3 %",
            touch.name()
        )
    })
}

/// The touch experiments: sweeps of struck and pressed touches, the touches matched to the
/// rows' hammer speeds, and the rows they give: the velocity range; free flight, travel
/// time, key bottom, contact and check; the curves.
pub(super) fn touch_experiments(
    params: &ActionParams,
    kind: ModelKind,
) -> (Vec<Row>, Vec<Row>, Curves) {
    let sweep = |touch: Touch| -> Vec<Blow> {
        let (lo, hi) = touch.range();
        log_levels(lo, hi, SWEEP_LEVELS)
            .par_iter()
            .map(|&level| blow(params, kind, touch, level))
            .collect()
    };
    let (struck, pressed) = rayon::join(|| sweep(Touch::Struck), || sweep(Touch::Pressed));
    // Every hammer speed a row needs: the dynamic levels for both touches, and for struck
    // ones the contact reference and free flight speeds.
    let pressed_targets: Vec<f64> = DYNAMICS.iter().map(|d| d.1).collect();
    let mut struck_targets = pressed_targets.clone();
    struck_targets.extend(CONTACT_REFERENCE.iter().map(|c| c.0));
    struck_targets.extend(FREE_FLIGHT_SPEEDS);
    struck_targets.sort_by(f64::total_cmp);
    struck_targets.dedup();
    let jobs: Vec<(Touch, f64)> = struck_targets
        .iter()
        .map(|&v| (Touch::Struck, v))
        .chain(pressed_targets.iter().map(|&v| (Touch::Pressed, v)))
        .collect();
    let found: Vec<Matched> = jobs
        .par_iter()
        .map(|&(touch, v)| {
            let sweep = if touch == Touch::Struck {
                &struck
            } else {
                &pressed
            };
            ((touch, v), matched(params, kind, touch, v, sweep))
        })
        .collect();
    let at = |touch: Touch, v: f64| -> std::result::Result<&Blow, String> {
        found
            .iter()
            .find(|(k, _)| k.0 == touch && k.1 == v)
            .map_or_else(
                || Err("not run".to_string()),
                |(_, r)| r.as_ref().map_err(Clone::clone),
            )
    };
    // Velocity range: the softest and loudest touches.
    let mut velocity = Vec::new();
    for (touch, sweep) in [(Touch::Pressed, &pressed), (Touch::Struck, &struck)] {
        for (end, dynamic, band) in [
            (sweep.first(), "pp", Band::Range(0.3, 1.0)),
            (sweep.last(), "ff", Band::Range(4.0, 7.0)),
        ] {
            let level = end.map_or(f64::NAN, |b| b.level);
            let mut row = Row::new(
                format!("velocity.{dynamic}.{}", touch.name()),
                format!(
                    "hammer speed, {} {} {} ({dynamic})",
                    touch.name(),
                    super::num(level),
                    touch.unit()
                ),
                end.and_then(|b| b.hammer_speed_m_s),
                band,
                "m/s",
                "lit. §7.5, §3.1 [M]",
            );
            if row.model_value.is_none() {
                row.note = Some(
                    end.and_then(|b| b.error.clone())
                        .unwrap_or_else(|| "the hammer did not reach the string".to_string()),
                );
            }
            velocity.push(row);
        }
    }
    let mut rows = Vec::new();

    // Free flight from let-off to the string.
    for v in FREE_FLIGHT_SPEEDS {
        let b = at(Touch::Struck, v);
        rows.push(with_match(
            Row::new(
                format!("free_flight.{}", super::num(v)),
                format!("free flight after let-off, struck {} m/s", super::num(v)),
                b.as_ref().ok().and_then(|b| b.free_flight_mm),
                Band::Range(0.5, 2.0),
                "mm",
                "lit. §2 (Gillespie 2011) [V]",
            )
            .literature("0.5..2 (measured 1-1.5)"),
            &b,
        ));
    }

    // Travel time: struck touches against Goebl's law; pressed minus struck.
    for (touch, sweep) in [(Touch::Struck, &struck), (Touch::Pressed, &pressed)] {
        rows.push(goebl_row(touch, sweep, &found));
    }
    for (name, v) in [("p", dynamic("p")), ("f", dynamic("f"))] {
        let (p, s) = (at(Touch::Pressed, v), at(Touch::Struck, v));
        let both = p.as_ref().ok().zip(s.as_ref().ok());
        let value = both.and_then(|(p, s)| Some((p.travel_time_s? - s.travel_time_s?) * 1e3));
        let mut row = Row::new(
            format!("travel_time.pressed_minus_struck.{name}"),
            format!(
                "travel time pressed - struck, {} m/s ({name})",
                super::num(v)
            ),
            value,
            Band::Range(10.0, 30.0),
            "ms",
            "lit. §3.2 (Goebl 2005) [S]",
        )
        .literature("about 20 (10..30)")
        .decimals(1);
        if let Err(e) = p.as_ref().and(s.as_ref()) {
            row.note = Some(e.clone());
        }
        rows.push(row);
    }

    // Key bottom minus string contact.
    for (name, band) in [
        ("pp", Band::Range(10.0, 35.0)),
        ("mf", Band::Range(-2.0, 2.0)),
        ("ff", Band::Range(-5.0, -3.0)),
    ] {
        let v = dynamic(name);
        for touch in [Touch::Struck, Touch::Pressed] {
            let b = at(touch, v);
            let literature = match name {
                "mf" => "about 0 (-2..2)".to_string(),
                _ => band.describe(),
            };
            rows.push(with_match(
                Row::new(
                    format!("key_bottom.{name}.{}", touch.name()),
                    format!(
                        "key bottom - string contact, {} {} m/s",
                        touch.name(),
                        super::num(v)
                    ),
                    b.as_ref()
                        .ok()
                        .and_then(|b| b.key_bottom_minus_contact_s)
                        .map(|s| s * 1e3),
                    band,
                    "ms",
                    "lit. §3.1, §7.6 (A&J; Goebl) [S]",
                )
                .literature(literature)
                .decimals(1),
                &b,
            ));
        }
    }

    // Hammer-string contact: duration and rebound against the reference experiment.
    let mut durations = Vec::new();
    for (v, ms, _) in CONTACT_REFERENCE {
        let b = at(Touch::Struck, v);
        let d = b
            .as_ref()
            .ok()
            .and_then(|b| b.contact_duration_s)
            .map(|s| s * 1e3);
        durations.push(d);
        rows.push(with_match(
            Row::new(
                format!("contact.duration.{}", super::num(v)),
                format!("string contact duration, {} m/s", super::num(v)),
                d,
                Band::Relative {
                    reference: ms,
                    tolerance: 0.25,
                },
                "ms",
                "str. ref. §4.1 (C4, C&A felt) [D]",
            ),
            &b,
        ));
    }
    let shortening = durations
        .first()
        .copied()
        .flatten()
        .zip(durations.last().copied().flatten())
        .map(|(soft, loud)| loud / soft);
    rows.push(
        Row::new(
            "contact.shortening",
            "contact at 4 m/s / contact at 0.5 m/s",
            shortening,
            Band::Range(0.5, 1.0),
            "-",
            "str. ref. §4.1; lit. §3.1 [D]/[S]",
        )
        .literature("0.5..1 (ref. 0.77)")
        .note("shorter when louder: reference 2.54 -> 1.95 ms (0.77); A&J about 4 -> 2 ms (0.5)"),
    );
    for (v, _, e) in CONTACT_REFERENCE {
        let b = at(Touch::Struck, v);
        rows.push(with_match(
            Row::new(
                format!("contact.rebound.{}", super::num(v)),
                format!("hammer rebound e = -v_out/v_in, {} m/s", super::num(v)),
                b.as_ref().ok().and_then(|b| b.rebound),
                Band::Relative {
                    reference: e,
                    tolerance: 0.25,
                },
                "-",
                "str. ref. §4.1 (C4, C&A felt) [D]",
            ),
            &b,
        ));
    }

    // Check distance from mf to ff.
    for name in ["mf", "f", "ff"] {
        let v = dynamic(name);
        let b = at(Touch::Struck, v);
        let mut row = with_match(
            Row::new(
                format!("check.{name}"),
                format!("check, struck {} m/s ({name}), key held", super::num(v)),
                b.as_ref().ok().and_then(|b| b.check_mm),
                Band::Range(12.0, 16.0),
                "mm",
                "lit. §2 (Gillespie 2011) [V]",
            ),
            &b,
        );
        if b.is_ok() && row.model_value.is_none() {
            row.note = Some("the backcheck does not hold the hammer at the end".into());
        }
        rows.push(row);
    }

    let matched_blows = found.into_iter().filter_map(|(_, r)| r.ok()).collect();
    (
        velocity,
        rows,
        Curves {
            struck,
            pressed,
            matched: matched_blows,
        },
    )
}

/// A touch matched to a hammer speed: (touch, target m/s), and the blow or why none.
type Matched = ((Touch, f64), std::result::Result<Blow, String>);

/// The worst relative deviation (%) from Goebl's travel-time law of the touches of `touch`
/// (sweep and matched) that give 1 to 5 m/s.
fn goebl_row(touch: Touch, sweep: &[Blow], found: &[Matched]) -> Row {
    let in_range: Vec<&Blow> = sweep
        .iter()
        .chain(
            found
                .iter()
                .filter(|(k, _)| k.0 == touch)
                .filter_map(|(_, r)| r.as_ref().ok()),
        )
        .filter(|b| b.hammer_speed_m_s.is_some_and(|v| (1.0..=5.0).contains(&v)))
        .collect();
    let worst = in_range
        .iter()
        .filter_map(|b| {
            let (v, tt) = (b.hammer_speed_m_s?, b.travel_time_s?);
            Some((v, tt, 100.0 * (tt / goebl_travel_time_s(v, touch) - 1.0)))
        })
        .max_by(|a, b| a.2.abs().total_cmp(&b.2.abs()));
    let row = Row::new(
        format!("travel_time.{}_vs_goebl", touch.name()),
        format!("travel time, {} 1-5 m/s, worst", touch.name()),
        worst.map(|w| w.2),
        Band::Range(-25.0, 25.0),
        "%",
        match touch {
            Touch::Pressed => "lit. §3.2 (Goebl 2001) [M]",
            Touch::Struck => "lit. §3.2 (Goebl 2001 [M], 2005 [S])",
        },
    )
    .literature(match touch {
        Touch::Pressed => "89 ms v^-0.57 +-25 %",
        Touch::Struck => "89 ms v^-0.57 - 20 ms +-25 %",
    })
    .decimals(0);
    row.note(match worst {
        Some((v, tt, _)) => format!(
            "constants recalled, unverified; worst of {} {} touches: {:.0} ms at {v:.2} m/s, law {:.0} ms",
            in_range.len(),
            touch.name(),
            tt * 1e3,
            goebl_travel_time_s(v, touch) * 1e3
        ),
        None => format!("no {} touch gave 1-5 m/s", touch.name()),
    })
}

/// Notes on `row` which touch gave its hammer speed, or why none did.
fn with_match(row: Row, b: &std::result::Result<&Blow, String>) -> Row {
    match b {
        Ok(b) => {
            let mut text = format!(
                "{} {:.3} {} gave {:.2} m/s",
                b.touch.name(),
                b.level,
                b.touch.unit(),
                b.hammer_speed_m_s.unwrap_or(f64::NAN)
            );
            if let Some(e) = &b.error {
                text.push_str(&format!("; {e}"));
            }
            row.note(text)
        }
        Err(e) => row.note(e.clone()),
    }
}
