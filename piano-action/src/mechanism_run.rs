//! Any mechanism description, simulated and written to a self-contained run directory.
//!
//! `piano simulate` runs a scenario with `mechanism = "FILE"` (a description, see
//! [`mbs_mechanism`]) in place of `model`: the mechanism settles at rest for `settle_s`,
//! then a force (`[input] kind = "force"`, a constant, a ramp, a release or a table) drives
//! its first force input. The run directory holds everything needed to replay it without
//! rebuilding or re-settling anything: `run.json` (the scenario, the expanded description,
//! the numerics and the initial state), `trajectory.csv` (and `internal_states.csv`),
//! `contacts.csv` (gap, force, point and normal of every contact), `poses.csv` (every
//! body's motion from its rest place), `series.csv` (coordinates, marker speeds, energies),
//! `events.json`, `summary.json` (the description's metrics) and SVG drawings from the
//! outlines at rest and at the first occurrence of each named event.

use std::fmt::Write as _;
use std::path::Path;

use mbs_core::time_function::PiecewiseLinear;
use mbs_integrators::Solution;
use mbs_mechanism::{
    Built, EventOccurrence, InputKind as MechInputKind, JointType, Mechanism, MetricValue,
};
use serde_json::{Value, json};

use crate::action::integrate_system;
use crate::describe::PianoExtensions;
use crate::error::{PianoError, Result};
use crate::params::NumericsParams;
use crate::simulate::Input;

/// How long a mechanism settles at rest before the input starts, unless the scenario says
/// (s) \[D\]: as the grand action, whose ringing dies away in 0.3 s.
pub const DEFAULT_SETTLE_S: f64 = 0.3;

/// A finished run of a mechanism description.
pub struct MechanismRun {
    /// The description it ran.
    pub mechanism: Mechanism,
    /// The system as it ran (with its input).
    pub built: Built,
    /// The state at t = 0 (settled).
    pub x0: Vec<f64>,
    /// The integrator's solution.
    pub solution: Solution,
    /// The description's named events, in time order.
    pub events: Vec<EventOccurrence>,
    /// Contact onsets and releases, in time order: `(contact, onset, time_s)`.
    pub contact_events: Vec<(String, bool, f64)>,
    /// The description's metrics.
    pub metrics: Vec<MetricValue>,
}

/// Per contact (by name), its numbers at every output time, or None: see
/// [`contact_series`].
pub type ContactSeries = Vec<(String, Option<Vec<[f64; 6]>>)>;

/// Every contact of a mechanism run on its output grid, as `contacts.csv` has them: per
/// contact (by name), per sample, the gap (mm), the normal force (N, zero when not
/// pressed), the contact point (mm) and the normal; None for a contact whose numbers the
/// description's build does not give.
pub fn contact_series(run: &MechanismRun) -> Result<ContactSeries> {
    let system = &run.built.system;
    let sol = &run.solution;
    let mut ws = system.workspace();
    let mut out = Vec::new();
    for (name, &e) in &run.built.contacts {
        let Some(c) = run.built.contact_handles.get(name) else {
            out.push((name.clone(), None));
            continue;
        };
        let mut rows = Vec::with_capacity(sol.len());
        for i in 0..sol.len() {
            let ctx = system.element_context(&mut ws, sol.t[i], sol.state(i), e)?;
            let o = c.output(&ctx);
            let f = if o.active {
                o.normal_force.max(0.0)
            } else {
                0.0
            };
            rows.push([
                o.gap * 1e3,
                f,
                o.point[0] * 1e3,
                o.point[1] * 1e3,
                o.normal[0],
                o.normal[1],
            ]);
        }
        out.push((name.clone(), Some(rows)));
    }
    Ok(out)
}

/// The summary of a mechanism run, as its `summary.json` has it (the mechanism's name, its
/// metrics, its named events and how many contact events), with `all_events` added: what
/// `events.json` holds (the named events and every contact onset and release, in time
/// order).
pub fn mechanism_summary(run: &MechanismRun) -> Value {
    let mut events: Vec<Value> = run
        .events
        .iter()
        .map(|e| json!({"name": e.name, "time_s": e.time_s, "named": true}))
        .collect();
    for (c, onset, t) in &run.contact_events {
        let what = if *onset { "onset" } else { "release" };
        events.push(json!({"name": format!("{c} {what}"), "time_s": t, "named": false}));
    }
    events.sort_by(|a, b| {
        a["time_s"]
            .as_f64()
            .unwrap_or(0.0)
            .total_cmp(&b["time_s"].as_f64().unwrap_or(0.0))
    });
    let metrics: Vec<Value> = run
        .metrics
        .iter()
        .map(|v| json!({"name": v.name, "value": v.value, "unit": v.unit}))
        .collect();
    json!({
        "mechanism": run.mechanism.name,
        "metrics": metrics,
        "events": run.events.iter().map(|e| json!({"name": e.name, "time_s": e.time_s})).collect::<Vec<_>>(),
        "contact_events": run.contact_events.len(),
        "all_events": events,
    })
}

/// The coordinates of `mechanism` settled at rest for `settle_s` from its layout (the
/// layout itself for 0). The last few results are remembered (a sweep settles the same
/// mechanism once).
pub fn settle(mechanism: &Mechanism, numerics: &NumericsParams, settle_s: f64) -> Result<Vec<f64>> {
    type Cache = Vec<(Mechanism, NumericsParams, f64, Vec<f64>)>;
    static CACHE: std::sync::Mutex<Cache> = std::sync::Mutex::new(Vec::new());
    let lookup = |cache: &Cache| {
        cache
            .iter()
            .find(|(m, n, s, _)| m == mechanism && n == numerics && *s == settle_s)
            .map(|(_, _, _, q)| q.clone())
    };
    if let Some(q) = CACHE.lock().ok().and_then(|c| lookup(&c)) {
        return Ok(q);
    }
    let q = settle_uncached(mechanism, numerics, settle_s)?;
    if let Ok(mut cache) = CACHE.lock() {
        if cache.len() >= 4 {
            cache.remove(0);
        }
        cache.push((mechanism.clone(), numerics.clone(), settle_s, q.clone()));
    }
    Ok(q)
}

fn settle_uncached(
    mechanism: &Mechanism,
    numerics: &NumericsParams,
    settle_s: f64,
) -> Result<Vec<f64>> {
    let built = mechanism.build_with(&PianoExtensions)?;
    let x = built.layout_state()?;
    let nv = built.system.model().nv();
    if settle_s <= 0.0 {
        return Ok(x[..nv].to_vec());
    }
    let settled = integrate_system(
        &built.system,
        numerics,
        &x,
        settle_s,
        2e-3,
        Some(settle_s),
        &mut |_| {},
    )?;
    let last = settled.len().saturating_sub(1);
    Ok(settled.state(last)[..nv].to_vec())
}

/// The force input a scenario's force drives: the description's first.
fn force_input(mechanism: &Mechanism) -> Result<&str> {
    mechanism
        .inputs
        .iter()
        .find(|i| i.kind == MechInputKind::Force)
        .map(|i| i.name.as_str())
        .ok_or_else(|| {
            PianoError::scenario(
                "input",
                format!(
                    "the mechanism '{}' has no force input to drive: add an `[[inputs]]` \
                     table with kind = \"force\"",
                    mechanism.name
                ),
            )
        })
}

/// Simulates `mechanism`, settled for `settle_s`, driven by `input` (a force or a force
/// table on its first force input) for `duration_s`, with output every `output_step_s`.
pub fn simulate_mechanism(
    mechanism: &Mechanism,
    input: &Input,
    numerics: &NumericsParams,
    settle_s: f64,
    duration_s: f64,
    output_step_s: f64,
    progress: &mut dyn FnMut(f64),
) -> Result<MechanismRun> {
    crate::simulate::check_duration(duration_s, output_step_s)?;
    if !(settle_s.is_finite() && (0.0..=crate::simulate::MAX_DURATION_S).contains(&settle_s)) {
        return Err(PianoError::scenario(
            "settle_s",
            format!(
                "must be 0-{} s, got {settle_s}",
                crate::simulate::MAX_DURATION_S
            ),
        ));
    }
    input.validate()?;
    let table = match input {
        Input::Force { force_n, release_s } => match release_s {
            None => vec![(0.0, *force_n)],
            Some(t) => vec![(0.0, *force_n), (*t, *force_n), (t + 1e-3, 0.0)],
        },
        Input::ForceTable { points } => points.clone(),
        _ => {
            return Err(PianoError::scenario(
                "input.kind",
                "a mechanism description is driven by a force (kind = \"force\", with \
                 force_n, ramp_s, release_s or points); mass drops, touches, key motions and \
                 the swing test belong to the grand models",
            ));
        }
    };
    let q0 = settle(mechanism, numerics, settle_s)?;
    let mut built = mechanism.build_with(&PianoExtensions)?;
    let name = force_input(mechanism)?.to_string();
    built.drive_force(mechanism, &name, PiecewiseLinear::new(table)?)?;
    let nv = built.system.model().nv();
    let x0 = built.system.initial_state(0.0, &q0, &vec![0.0; nv])?;
    let solution = integrate_system(
        &built.system,
        numerics,
        &x0,
        duration_s,
        1e-3,
        Some(output_step_s),
        progress,
    )?;
    let events = mechanism.events_in(&built, &solution)?;
    let metrics = mechanism.metrics_in(&built, &solution)?;
    let mut contact_events = Vec::new();
    for ev in &solution.events {
        let Some(mbs_integrators::EventSource { element, local: 0 }) = ev.source else {
            continue;
        };
        if let Some((name, _)) = built.contacts.iter().find(|(_, e)| **e == element) {
            let onset = ev.direction == mbs_integrators::Crossing::Falling;
            contact_events.push((name.clone(), onset, ev.time));
        }
    }
    Ok(MechanismRun {
        mechanism: mechanism.clone(),
        built,
        x0,
        solution,
        events,
        contact_events,
        metrics,
    })
}

fn write(dir: &Path, name: &str, text: &str) -> Result<()> {
    let path = dir.join(name);
    std::fs::write(&path, text).map_err(|e| PianoError::io(&path, "write", e))
}

fn write_json(dir: &Path, name: &str, value: &Value) -> Result<()> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| PianoError::file(&dir.join(name), format!("cannot encode as JSON: {e}")))?;
    write(dir, name, &text)
}

/// A file name for an event's drawing: letters, digits and underscores.
fn file_stem(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect()
}

/// Writes the run directory of a mechanism run (see the module docs); `scenario` is what
/// `run.json` records. The folder must be ready ([`crate::scenario::prepare_run_dir`]).
pub fn write_mechanism_run_dir(
    dir: &Path,
    scenario: &crate::scenario::Scenario,
    numerics: &NumericsParams,
    run: &MechanismRun,
) -> Result<()> {
    let m = &run.mechanism;
    let system = &run.built.system;
    let model = system.model();
    let sol = &run.solution;
    write_json(
        dir,
        "run.json",
        &json!({
            "scenario": serde_json::to_value(scenario).unwrap_or_default(),
            "mechanism": serde_json::to_value(m).unwrap_or_default(),
            "numerics": serde_json::to_value(numerics).unwrap_or_default(),
            "initial_state": run.x0,
            "version": env!("CARGO_PKG_VERSION"),
        }),
    )?;
    crate::scenario::write_trajectory(
        dir,
        model.coordinate_names(),
        system.state_len(),
        sol,
        None,
    )?;

    // Contacts: gap, force, point and normal (the force on the second side) per sample.
    let mut csv = String::from("time_s");
    for n in run.built.contacts.keys() {
        let _ = write!(
            csv,
            ",{n}_gap_mm,{n}_force_n,{n}_px_mm,{n}_py_mm,{n}_nx,{n}_ny"
        );
    }
    csv.push('\n');
    let series = contact_series(run)?;
    let mut ws = system.workspace();
    for i in 0..sol.len() {
        let _ = write!(csv, "{}", sol.t[i]);
        for (_, rows) in &series {
            match rows {
                Some(rows) => {
                    let [gap, force, px, py, nx, ny] = rows[i];
                    let _ = write!(csv, ",{gap},{force},{px},{py},{nx},{ny}");
                }
                None => csv.push_str(",,,,,,"),
            }
        }
        csv.push('\n');
    }
    write(dir, "contacts.csv", &csv)?;

    // Poses: every body carried from its rest place, so the report needs no model.
    let frames: Vec<&str> = m.bodies.iter().map(|b| b.name.as_str()).collect();
    let mut csv = String::from("time_s");
    for f in &frames {
        let _ = write!(csv, ",{f}_angle_rad,{f}_x_mm,{f}_y_mm");
    }
    csv.push('\n');
    for i in 0..sol.len() {
        let (t, x) = (sol.t[i], sol.state(i));
        let _ = write!(csv, "{t}");
        for (_, c) in crate::drawing::mechanism_carry(m, &run.built, t, x)? {
            let _ = write!(csv, ",{},{},{}", c[0], c[1], c[2]);
        }
        csv.push('\n');
    }
    write(dir, "poses.csv", &csv)?;

    // Series: coordinates (° or mm), marker speeds (m/s), energies (mJ).
    let mut header = vec!["time_s".to_string()];
    for b in &m.bodies {
        match b.joint.kind {
            JointType::Revolute => header.push(format!("{}_angle_deg", b.name)),
            JointType::Prismatic => header.push(format!("{}_position_mm", b.name)),
            JointType::Fixed => {}
        }
    }
    for mk in &m.markers {
        header.push(format!("{}_speed_m_s", mk.name));
    }
    header.push("kinetic_mj".into());
    header.push("gravity_mj".into());
    let markers: Vec<(mbs_core::BodyId, [f64; 2])> = m
        .markers
        .iter()
        .map(|mk| {
            if mk.at.body == mbs_mechanism::GROUND {
                Ok((mbs_core::BodyId::GROUND, mk.at.point))
            } else {
                let frame = model.frame_id(&mk.at.body)?;
                Ok(mbs_core::frame_point(model, frame, mk.at.point))
            }
        })
        .collect::<std::result::Result<_, mbs_core::CoreError>>()?;
    let mut csv = header.join(",");
    csv.push('\n');
    let mut gravity0 = None;
    for i in 0..sol.len() {
        let (t, x) = (sol.t[i], sol.state(i));
        let _ = write!(csv, "{t}");
        let ctx = system.kinematics(&mut ws, t, x)?;
        for b in &m.bodies {
            let Ok(k) = model.coordinate_id(&b.name) else {
                continue;
            };
            let v = match b.joint.kind {
                JointType::Revolute => ctx.q[k].to_degrees(),
                _ => ctx.q[k] * 1e3,
            };
            let _ = write!(csv, ",{v}");
        }
        for &(body, point) in &markers {
            let v = ctx.point_velocity(body, point);
            let _ = write!(csv, ",{}", v[0].hypot(v[1]));
        }
        let e = system.energy(&mut ws, t, x)?;
        let g0 = *gravity0.get_or_insert(e.gravity);
        let _ = writeln!(csv, ",{},{}", e.kinetic * 1e3, (e.gravity - g0) * 1e3);
    }
    write(dir, "series.csv", &csv)?;

    let summary = mechanism_summary(run);
    write_json(dir, "events.json", &summary["all_events"])?;
    let mut summary = summary;
    if let Some(map) = summary.as_object_mut() {
        map.remove("all_events");
    }
    write_json(dir, "summary.json", &summary)?;

    // Drawings: at rest and at the first occurrence of each named event.
    let svg = crate::drawing::mechanism_svg(
        m,
        &run.built,
        0.0,
        &run.x0,
        &format!("{}, at rest", m.name),
    )?;
    write(dir, "drawing_rest.svg", &svg)?;
    let mut drawn = std::collections::BTreeSet::new();
    for e in &run.events {
        if !drawn.insert(e.name.clone()) {
            continue;
        }
        if let Some(record) = sol.events.get(e.record) {
            let title = format!("{}, {}, t = {:.1} ms", m.name, e.name, e.time_s * 1e3);
            let svg =
                crate::drawing::mechanism_svg(m, &run.built, record.time, &record.state, &title)?;
            write(dir, &format!("drawing_{}.svg", file_stem(&e.name)), &svg)?;
        }
    }
    Ok(())
}

/// Colours of a description's contacts in the report, in name order.
const CONTACT_PALETTE: [&str; 10] = [
    "#c0392b", "#2e8b57", "#8e44ad", "#2980b9", "#d35400", "#16a085", "#b7950b", "#34495e",
    "#7f8c8d", "#555555",
];

/// The report data of a mechanism run directory, read from its files alone (the
/// description in `run.json` gives the drawing; nothing is simulated again).
pub fn report_data(dir: &Path, run_json: &Value) -> Result<crate::report::data::RunData> {
    use crate::report::data::{Carry, ContactSeries, Plot, RunData, precision};
    use crate::report::{r, read_json, read_numeric_csv, run_name, to_series};
    let bad = |message: String| PianoError::file(dir, message);
    let mechanism: Mechanism = serde_json::from_value(run_json["mechanism"].clone())
        .map_err(|e| bad(format!("run.json mechanism: {e}")))?;
    mechanism.validate()?;
    let scenario: crate::scenario::Scenario = serde_json::from_value(run_json["scenario"].clone())
        .map_err(|e| bad(format!("run.json scenario: {e}")))?;
    let built = mechanism.build_with(&PianoExtensions)?;
    let scene = crate::drawing::mechanism_scene(&mechanism, &built)?;

    let (header, rows) = read_numeric_csv(dir, "poses.csv")?;
    let t: Vec<f64> = rows.iter().map(|row| r(row[0], 6)).collect();
    let mut carry = std::collections::BTreeMap::new();
    for b in &mechanism.bodies {
        let col = header
            .iter()
            .position(|h| *h == format!("{}_angle_rad", b.name))
            .ok_or_else(|| bad(format!("poses.csv has no columns for body '{}'", b.name)))?;
        let take = |k: usize, digits: i32| -> Vec<f64> {
            rows.iter().map(|row| r(row[col + k], digits)).collect()
        };
        carry.insert(
            b.name.clone(),
            Carry {
                a: take(0, 6),
                x: take(1, 3),
                y: take(2, 3),
            },
        );
    }

    let (header, rows) = read_numeric_csv(dir, "contacts.csv")?;
    if rows.len() != t.len() {
        return Err(bad(format!(
            "contacts.csv has {} rows and poses.csv {}",
            rows.len(),
            t.len()
        )));
    }
    let mut contacts = std::collections::BTreeMap::new();
    let mut colors = std::collections::BTreeMap::new();
    let mut labels = std::collections::BTreeMap::new();
    for (k, name) in built.contacts.keys().enumerate() {
        let col = header
            .iter()
            .position(|h| *h == format!("{name}_force_n"))
            .ok_or_else(|| bad(format!("contacts.csv has no columns for contact '{name}'")))?;
        let take = |k: usize, digits: i32| -> Vec<f64> {
            rows.iter().map(|row| r(row[col + k], digits)).collect()
        };
        contacts.insert(
            name.clone(),
            ContactSeries {
                f: take(0, 3),
                px: take(1, 2),
                py: take(2, 2),
                nx: take(3, 3),
                ny: take(4, 3),
            },
        );
        colors.insert(
            name.clone(),
            CONTACT_PALETTE[k % CONTACT_PALETTE.len()].to_string(),
        );
        labels.insert(name.clone(), name.replace('_', " "));
    }

    let (header, rows) = read_numeric_csv(dir, "series.csv")?;
    let label = |id: &str| -> String {
        for (suffix, unit) in [
            ("_angle_deg", "angle (°)"),
            ("_position_mm", "position (mm)"),
            ("_speed_m_s", "speed (m/s)"),
        ] {
            if let Some(name) = id.strip_suffix(suffix) {
                return format!("{} {unit}", name.replace('_', " "));
            }
        }
        match id {
            "kinetic_mj" => "kinetic energy (mJ)".into(),
            "gravity_mj" => "gravitational energy from rest (mJ)".into(),
            other => other.replace('_', " "),
        }
    };
    let labels_owned: Vec<String> = header.iter().map(|h| label(h)).collect();
    let series: Vec<(&str, &str, Vec<f64>)> = header
        .iter()
        .zip(&labels_owned)
        .enumerate()
        .skip(1)
        .map(|(k, (id, lab))| {
            (
                id.as_str(),
                lab.as_str(),
                rows.iter().map(|row| r(row[k], 4)).collect(),
            )
        })
        .collect();

    let events = read_json(dir, "events.json")?;
    let listed: Vec<Value> = events
        .as_array()
        .map(|a| {
            a.iter()
                .filter(|e| e["named"].as_bool().unwrap_or(false))
                .cloned()
                .collect()
        })
        .unwrap_or_default();
    let summary = read_json(dir, "summary.json")?;
    // The metrics, as the run's headline.
    let headline = match summary["metrics"].as_array() {
        Some(m) if !m.is_empty() => m
            .iter()
            .map(|m| {
                let value = m["value"].as_f64().map_or("–".into(), |v| {
                    format!("{} {}", precision(v, 4), m["unit"].as_str().unwrap_or(""))
                });
                format!("{} {value}", m["name"].as_str().unwrap_or(""))
            })
            .collect::<Vec<_>>()
            .join(", "),
        _ => "no metrics".into(),
    };
    let series = to_series(series);
    let mut plots = vec![Plot::contact_forces()];
    if series.iter().any(|s| s.id == "kinetic_mj") {
        plots.push(Plot::energy("from rest"));
    }
    Ok(RunData {
        name: run_name(dir),
        title: format!(
            "{}, {}",
            mechanism.name,
            crate::report::describe(&scenario.input)
        ),
        model: mechanism.name.clone(),
        headline,
        scene,
        t,
        carry,
        contacts,
        contact_labels: labels,
        contact_colors: colors,
        series,
        plots,
        listed_events: if listed.is_empty() {
            events.clone()
        } else {
            Value::from(listed)
        },
        events,
        minor_events: "releases and the unnamed contacts' onsets".into(),
        summary,
        zoom: json!({}),
        measured: None,
    })
}
