//! The experiments behind the validation rows, each as the literature describes it, run on
//! the model through the public keystroke API ([`simulate()`](crate::simulate()): events,
//! strikes and the solution), so that they work whatever the string model is: the
//! regulation, the touchweight, the lever ratio, the slow press, repetition, the 1 kg drop
//! and the swing test here; the touches from soft to loud in [`super::touches`]; the
//! prescribed key motions in `motions.rs`. Independent experiments run in parallel (rayon).

use rayon::prelude::*;

use super::motions::{control_rows, motion_rows};
use super::touches::touch_experiments;
use super::{Band, Row, Validation};
use crate::action::{Action, ModelKind};
use crate::error::Result;
use crate::params::ActionParams;
use crate::regulation::{self, Regulation};
use crate::simulate::{Input, Run, key_depth_mm, prepare, simulate};

/// The strike point's distance from the flange pin (m).
pub(super) fn strike_radius(params: &ActionParams) -> f64 {
    let s = params.hammer.strike_body_mm;
    s[0].hypot(s[1]) * 1e-3
}

/// Runs the validation of `kind` built from `params`: every experiment the model can
/// reproduce, in parallel. Errors only on parameters that cannot build the action; a failed
/// experiment gives rows without a value, their note saying why.
pub fn validate(params: &ActionParams, kind: ModelKind) -> Result<Validation> {
    Action::build(params, kind)?;
    let escapement = kind != ModelKind::Simplified;
    type Group<'a> = (&'static str, Box<dyn Fn() -> Vec<Row> + Send + Sync + 'a>);
    let mut groups: Vec<Group> = vec![
        ("regulation", Box::new(|| regulation_rows(params, kind))),
        ("touchweight", Box::new(|| touchweight_rows(params, kind))),
        ("ratio", Box::new(|| ratio_rows(params, kind))),
        ("slow_press", Box::new(|| slow_press_rows(params, kind))),
        ("pendulum", Box::new(|| pendulum_rows(params))),
    ];
    if escapement {
        groups.push(("motion", Box::new(|| motion_rows(params, kind))));
        groups.push(("control", Box::new(|| control_rows(params, kind))));
        groups.push(("repetition", Box::new(|| repetition_rows(params, kind))));
        groups.push(("mass_drop", Box::new(|| mass_drop_rows(params, kind))));
    }
    let (grouped, touches) = rayon::join(
        || {
            groups
                .par_iter()
                .map(|(name, g)| (*name, g()))
                .collect::<Vec<_>>()
        },
        || escapement.then(|| touch_experiments(params, kind)),
    );
    let mut grouped = grouped;
    let mut take = |name: &str| {
        grouped
            .iter_mut()
            .find(|g| g.0 == name)
            .map(|g| std::mem::take(&mut g.1))
            .unwrap_or_default()
    };
    let (velocity, touch_rows, curves) = touches.unwrap_or_default();
    let mut rows = take("regulation");
    rows.extend(take("touchweight"));
    rows.extend(velocity);
    rows.extend(take("ratio"));
    rows.extend(touch_rows);
    for name in [
        "motion",
        "control",
        "slow_press",
        "repetition",
        "mass_drop",
        "pendulum",
    ] {
        rows.extend(take(name));
    }
    Ok(Validation {
        model: kind,
        rows,
        curves,
        known_listed: false,
    })
}

/// Notes the error of a failed experiment on its rows that have no value.
pub(super) fn failed<T>(mut rows: Vec<Row>, outcome: &Result<T>) -> Vec<Row> {
    if let Err(e) = outcome {
        for r in rows.iter_mut().filter(|r| r.model_value.is_none()) {
            r.note = Some(format!("the experiment failed: {e}"));
        }
    }
    rows
}

/// Key dip, blow, let-off, drop, check and aftertouch as a technician measures them
/// ([`regulation::measure`]).
fn regulation_rows(params: &ActionParams, kind: ModelKind) -> Vec<Row> {
    let r = regulation::measure(params, kind);
    let get = |f: fn(&Regulation) -> Option<f64>| r.as_ref().ok().and_then(f);
    let mut rows = vec![
        Row::new(
            "regulation.key_dip",
            "key dip (5 N on the key front)",
            get(|r| Some(r.key_dip_mm)),
            Band::Range(9.5, 11.0),
            "mm",
            "lit. §2, §7.3 (PTG, MMD) [V]",
        ),
        Row::new(
            "regulation.blow",
            "blow distance (crown to string at rest)",
            get(|r| Some(r.blow_distance_mm)),
            Band::Range(44.5, 48.0),
            "mm",
            "lit. §2 (PTG, azpianoservice) [V]",
        ),
    ];
    if kind != ModelKind::Simplified {
        rows.push(
            Row::new(
                "regulation.let_off",
                "let-off (closest approach, slow press)",
                get(|r| r.let_off_mm),
                Band::Range(1.0, 2.5),
                "mm",
                "lit. §2, §7.3 (PTG) [V]",
            )
            .note("missing: the jack did not escape before the hammer reached the string"),
        );
        if kind == ModelKind::Double {
            rows.push(Row::new(
                "regulation.drop",
                "drop below let-off (onto the lever)",
                get(|r| r.drop_mm),
                Band::Range(1.0, 2.0),
                "mm",
                "lit. §2 (MMD) [V], mm [M]",
            ));
        }
        rows.push(
            Row::new(
                "regulation.check",
                "check (crown to string, struck f, key held)",
                get(|r| r.check_mm),
                Band::Range(12.0, 16.0),
                "mm",
                "lit. §2 (Gillespie 2011) [V]",
            )
            .note("missing: the hammer was not caught by the backcheck"),
        );
        rows.push(Row::new(
            "regulation.aftertouch",
            "aftertouch (key travel after let-off)",
            get(|r| r.aftertouch_mm),
            Band::Range(0.5, 1.5),
            "mm",
            "lit. §2, §7.3 (PTG .040-.060\") [V]",
        ));
    }
    // A note explains a missing value only.
    for row in &mut rows {
        if row.model_value.is_some() {
            row.note = None;
        }
    }
    failed(rows, &r)
}

/// Static touchweight, and what 0.75 mN·m more hammer-flange friction (3 gf at 1") does
/// to it (Monroe's table, literature §2).
fn touchweight_rows(params: &ActionParams, kind: ModelKind) -> Vec<Row> {
    let mut stiff = params.clone();
    stiff.hammer.pivot_friction_n_m += 0.75e-3;
    let (base, more) = rayon::join(
        || crate::touchweight::measure(params, kind),
        || crate::touchweight::measure(&stiff, kind),
    );
    let b = base.as_ref().ok();
    let both = b.zip(more.as_ref().ok());
    let source = "lit. §7.1, §2 (CAUT) [V]";
    let rows = vec![
        Row::new(
            "touchweight.down",
            "down weight DW",
            b.map(|w| w.down_weight_gf),
            Band::Range(45.0, 60.0),
            "gf",
            source,
        )
        .decimals(1),
        Row::new(
            "touchweight.up",
            "up weight UW",
            b.map(|w| w.up_weight_gf),
            Band::Range(20.0, 35.0),
            "gf",
            source,
        )
        .decimals(1),
        Row::new(
            "touchweight.balance",
            "balance weight (DW+UW)/2",
            b.map(|w| w.balance_weight_gf),
            Band::Range(38.0, 45.0),
            "gf",
            source,
        )
        .decimals(1),
        Row::new(
            "touchweight.friction",
            "friction weight (DW-UW)/2",
            b.map(|w| w.friction_weight_gf),
            Band::Range(8.0, 15.0),
            "gf",
            source,
        )
        .decimals(1),
        Row::new(
            "touchweight.flange_friction_dw",
            "DW change, +3 gf hammer-flange friction",
            both.map(|(a, b)| b.down_weight_gf - a.down_weight_gf),
            Band::Range(2.0, 5.0),
            "gf",
            "lit. §2 (Monroe, CAUT 2010) [V]",
        )
        .decimals(1)
        .note("+0.75 mN m at the hammer flange; Monroe: about +1 gf DW per gf of friction"),
        Row::new(
            "touchweight.flange_friction_uw",
            "UW change, +3 gf hammer-flange friction",
            both.map(|(a, b)| b.up_weight_gf - a.up_weight_gf),
            Band::Range(-3.0, 0.0),
            "gf",
            "lit. §2 (Monroe, CAUT 2010) [V]",
        )
        .decimals(1)
        .note("+0.75 mN m at the hammer flange; Monroe: UW falls about half as much"),
    ];
    let rows = failed(rows, &base);
    failed(rows, &more)
}

/// Hammer over key-front speed before let-off under a constant press (as
/// `tests/ratio.rs`): mean speeds from a quarter of the way to let-off until just before it,
/// once the felts have taken up their load (instantaneous speeds ring).
fn ratio_rows(params: &ActionParams, kind: ModelKind) -> Vec<Row> {
    const FORCES: [f64; 3] = [1.0, 2.0, 4.0];
    let ratios: Vec<Result<Option<f64>>> = FORCES
        .par_iter()
        .map(|&force_n| {
            let run = simulate(
                params,
                kind,
                &Input::Force {
                    force_n,
                    release_s: None,
                },
                0.3,
                2e-4,
            )?;
            let Some(end) = run
                .let_off_time_s
                .or_else(|| run.strikes.first().map(|s| s.time_s))
            else {
                return Ok(None);
            };
            let action = Action::build(params, kind)?;
            let model = action.system.model();
            let (key, hammer) = (model.coordinate_id("key")?, model.coordinate_id("hammer")?);
            let k = &params.key;
            let finger_radius = crate::key::KeyGeometry::of(k).radius_mm() * 1e-3;
            let radius = strike_radius(params);
            let sol = &run.solution;
            let at = |frac: f64| {
                let i = sol
                    .t
                    .partition_point(|&t| t < frac * end)
                    .min(sol.len() - 1);
                let x = sol.state(i);
                (x[key] * finger_radius, x[hammer] * radius)
            };
            let ((k0, h0), (k1, h1)) = (at(0.25), at(0.95));
            Ok(Some((h1 - h0) / (k1 - k0)))
        })
        .collect();
    FORCES
        .iter()
        .zip(ratios)
        .map(|(f, r)| {
            let row = Row::new(
                format!("ratio.{f:.0}N"),
                format!("hammer / key-front speed, {f:.0} N press"),
                r.as_ref().ok().copied().flatten(),
                Band::Range(5.0, 6.0),
                "-",
                "lit. §7.2, §7.5 (SWR 5.5-6) [V]",
            );
            let row = match &r {
                Ok(None) => row.note("no let-off and no strike: no window to measure in"),
                _ => row,
            };
            failed(vec![row], &r).remove(0)
        })
        .collect()
}

/// A slow press (10 mm over 2 s, held): the escapement actions let off and never touch
/// the string; the simplified action pushes the hammer to the string and holds it there.
fn slow_press_rows(params: &ActionParams, kind: ModelKind) -> Vec<Row> {
    let run = simulate(
        params,
        kind,
        &Input::Motion {
            points: vec![(0.0, 0.0), (2.0, 10.0)],
        },
        2.5,
        2e-3,
    );
    let ok = run.as_ref().ok();
    let source = "DESIGN sequence 3-4 [D]";
    let rows = if kind == ModelKind::Simplified {
        vec![
            Row::new(
                "slow_press.held_on_string",
                "slow press: hammer held on the string (1 = yes)",
                ok.map(|r| {
                    let held = r
                        .strikes
                        .last()
                        .is_some_and(|s| s.contact_duration_s.is_none());
                    if held { 1.0 } else { 0.0 }
                }),
                Band::Exactly(1.0),
                "-",
                source,
            )
            .decimals(0),
        ]
    } else {
        vec![
            Row::new(
                "slow_press.let_off",
                "slow press (10 mm in 2 s): let-off events",
                ok.map(|r| r.events.iter().filter(|e| e.name == "let_off").count() as f64),
                Band::AtLeast(1.0),
                "count",
                source,
            )
            .decimals(0),
            Row::new(
                "slow_press.strikes",
                "slow press: string contacts",
                ok.map(|r| r.strikes.len() as f64),
                Band::Exactly(0.0),
                "count",
                source,
            )
            .decimals(0),
        ]
    };
    failed(rows, &run)
}

/// Appends a minimum-jerk key move from the last point to `depth_mm` ending at `t_end`,
/// sampled every 5 ms.
fn move_to(points: &mut Vec<(f64, f64)>, t_end: f64, depth_mm: f64) {
    let Some(&(t0, d0)) = points.last() else {
        return;
    };
    let n = ((t_end - t0) / 5e-3).ceil() as usize;
    for i in 1..=n {
        let u = i as f64 / n as f64;
        let s = u * u * u * (10.0 - 15.0 * u + 6.0 * u * u);
        points.push((t0 + u * (t_end - t0), d0 + s * (depth_mm - d0)));
    }
}

/// Repeated notes (as `tests/repetition.rs`): pressed to the bottom in 40 ms, held, let up
/// to half (5.3 mm) or fully in 100 ms, held 50 ms, pressed again in 40 ms. Half release
/// repeats on the double escapement only; full release on both.
fn repetition_rows(params: &ActionParams, kind: ModelKind) -> Vec<Row> {
    let repeat = |rise_to_mm: f64| {
        let mut points = vec![(0.0, 0.0)];
        move_to(&mut points, 0.04, 10.5);
        points.push((0.2, 10.5));
        move_to(&mut points, 0.3, rise_to_mm);
        points.push((0.35, rise_to_mm));
        move_to(&mut points, 0.39, 10.5);
        simulate(params, kind, &Input::Motion { points }, 0.55, 1e-3)
    };
    let (half, full) = rayon::join(|| repeat(5.3), || repeat(0.0));
    let blows = |r: &Result<Run>| r.as_ref().ok().map(|r| r.strikes.len() as f64);
    let source = "lit. §7.8; DESIGN sequence 6 [D]";
    let half_row = Row::new(
        "repetition.half_release",
        "press, half release (5.3 mm), press: blows",
        blows(&half),
        Band::Exactly(if kind == ModelKind::Double { 2.0 } else { 1.0 }),
        "count",
        source,
    )
    .literature(if kind == ModelKind::Double {
        "2 (repeats)"
    } else {
        "1 (needs full return)"
    })
    .decimals(0);
    let full_row = Row::new(
        "repetition.full_release",
        "press, full release, press: blows",
        blows(&full),
        Band::Exactly(2.0),
        "count",
        source,
    )
    .decimals(0);
    let rows = failed(vec![half_row], &half);
    let mut rows = rows;
    rows.extend(failed(vec![full_row], &full));
    rows
}

/// The 1 kg experiment: a 1 kg mass placed on the key front and released strikes once,
/// the backcheck catches the hammer; how deep the key goes.
fn mass_drop_rows(params: &ActionParams, kind: ModelKind) -> Vec<Row> {
    let input = Input::MassDrop {
        mass_kg: 1.0,
        height_m: 0.0,
    };
    let outcome = simulate(params, kind, &input, 0.4, 2e-4).and_then(|run| {
        let prepared = prepare(params, kind, &input)?;
        let key = prepared.action.system.model().coordinate_id("key")?;
        let sol = &run.solution;
        let deepest = (0..sol.len())
            .map(|i| key_depth_mm(params, sol.state(i)[key]) - prepared.rest_depth_mm)
            .fold(f64::NEG_INFINITY, f64::max);
        Ok((run, deepest))
    });
    let ok = outcome.as_ref().ok();
    let before_check = ok.map(|(run, _)| {
        run.strikes
            .iter()
            .filter(|s| run.check_time_s.is_none_or(|c| s.time_s < c))
            .count() as f64
    });
    let source = "tests/mass_drop.rs; lit. §7.8 [D]";
    let rows = vec![
        Row::new(
            "mass_drop.strikes_before_check",
            "1 kg on the key: blows before the check",
            before_check,
            Band::Exactly(1.0),
            "count",
            source,
        )
        .decimals(0),
        Row::new(
            "mass_drop.checked",
            "1 kg on the key: hammer checked (1 = yes)",
            ok.map(|(run, _)| if run.check_time_s.is_some() { 1.0 } else { 0.0 }),
            Band::Exactly(1.0),
            "-",
            source,
        )
        .decimals(0),
        Row::new(
            "mass_drop.key_max_depth",
            "1 kg on the key: deepest key-front travel",
            ok.map(|(_, d)| *d),
            Band::Range(9.5, 12.0),
            "mm",
            "lit. §2; layout §6 (Bullock) [V]",
        )
        .literature("9.5..12"),
    ];
    failed(rows, &outcome)
}

/// The swing test (literature §5): the hammer released from horizontal swings on its
/// flange; the period and the Coulomb decrement per half swing over the small swings
/// (below 45°), where the linear theory holds.
fn pendulum_rows(params: &ActionParams) -> Vec<Row> {
    let swing = crate::pendulum::swing(params, 90.0, 6.0);
    let measured = swing.as_ref().ok().map(|s| {
        // Turning points with the release: (time, amplitude).
        let mut turns = vec![(0.0, std::f64::consts::FRAC_PI_2)];
        turns.extend(s.turns.iter().map(|t| (t.time_s, t.angle_rad.abs())));
        // Half swings that moved (the hammer sticks at the end) and stayed small.
        let small: Vec<(f64, f64)> = turns
            .windows(2)
            .filter(|w| w[1].1 < w[0].1 - 1e-3 && w[1].1 > 2f64.to_radians())
            .filter(|w| w[0].1 < 45f64.to_radians())
            .map(|w| (w[1].0 - w[0].0, (w[0].1 - w[1].1).to_degrees()))
            .collect();
        let n = small.len() as f64;
        let period = (n > 0.0).then(|| 2.0 * small.iter().map(|h| h.0).sum::<f64>() / n);
        let decrement = (n > 0.0).then(|| small.iter().map(|h| h.1).sum::<f64>() / n);
        (period, decrement, small.len())
    });
    let note = |row: Row| match measured {
        Some((_, _, n)) => row.note(format!(
            "released from horizontal; mean of {n} half swings below 45 deg"
        )),
        None => row,
    };
    let rows = vec![
        note(
            Row::new(
                "pendulum.period",
                "swing period, hammer on its flange",
                measured.and_then(|m| m.0),
                Band::Relative {
                    reference: 0.715,
                    tolerance: 0.05,
                },
                "s",
                "lit. §5 (Hirschkorn hammer) [D]",
            )
            .decimals(3),
        ),
        note(
            Row::new(
                "pendulum.decrement",
                "amplitude lost per half swing",
                measured.and_then(|m| m.1),
                Band::Relative {
                    reference: 9.7,
                    tolerance: 0.2,
                },
                "deg",
                "lit. §5 (Hirschkorn T_f) [D]",
            )
            .decimals(1),
        ),
    ];
    failed(rows, &swing)
}
