//! The interactive report: one self-contained HTML file (no network, works from `file://`)
//! that replays one or more run directories in slow motion, with the mechanism drawn to
//! scale, the contact forces as arrows, the events on a timeline and linked plots.
//!
//! The data are read from the run directory's files alone (`run.json`, `poses.csv`,
//! `contacts.csv`, `series.csv`, `scene.json`, `events.json`, `summary.json`; a grand run
//! written before the replay files is rebuilt from its parameters), gathered in the typed
//! [`data::RunData`] and embedded as JSON. The page's script (`report/player.js`,
//! `view2d.js`, `view3d.js`, `plots.js`, `clock.js`, joined at build time) only draws: every
//! name, colour, plot and headline comes from the data, so it knows no mechanism.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use serde_json::{Value, json};

pub mod data;

use data::{Carry, ContactSeries, Measured, Plot, ReportData, RunData, Series};

use crate::action::ModelKind;
use crate::error::{InputKind, PianoError, Result};
use crate::params::ActionParams;
use crate::scenario::{
    ForceSpec, InputSpec, MassDropSpec, MotionSpec, PendulumSpec, Scenario, TouchSpec,
};
use crate::simulate::{Prepared, key_depth_mm, prepare};

const STYLE: &str = include_str!("report/report.css");
/// The `generator` of every report page: a file that lacks it is not overwritten.
pub const GENERATOR: &str = "piano report";
/// The page's script: the player, the 2D and 3D views, the plots and the clock, joined in
/// one function at build time (each file says what it holds; `player.js` has the data's
/// JSDoc typedef).
const SCRIPT: &str = concat!(
    "(function () {\n'use strict';\n\n",
    include_str!("report/player.js"),
    "\n",
    include_str!("report/view2d.js"),
    "\n",
    include_str!("report/view3d.js"),
    "\n",
    include_str!("report/plots.js"),
    "\n",
    include_str!("report/clock.js"),
    "})();\n"
);

/// A broken run directory: the error names it.
fn bad(dir: &Path, message: String) -> PianoError {
    PianoError::input(InputKind::RunDir, "", message).in_file(dir)
}

fn read(dir: &Path, name: &str) -> Result<String> {
    std::fs::read_to_string(dir.join(name))
        .map_err(|e| bad(dir, format!("cannot read {name}: {e}")))
}

pub(crate) fn read_json(dir: &Path, name: &str) -> Result<Value> {
    serde_json::from_str(&read(dir, name)?).map_err(|e| bad(dir, format!("{name}: {e}")))
}

/// Rounds `v` to `digits` decimals (keeps the embedded data small).
pub(crate) fn r(v: f64, digits: i32) -> f64 {
    let s = 10f64.powi(digits);
    let out = (v * s).round() / s;
    if out == 0.0 { 0.0 } else { out }
}

/// The rows of `trajectory.csv`: column names and values.
fn read_trajectory(dir: &Path) -> Result<(Vec<String>, Vec<Vec<f64>>)> {
    read_numeric_csv(dir, "trajectory.csv")
}

/// A CSV of finite numbers with a header line: header and rows.
pub(crate) fn read_numeric_csv(dir: &Path, name: &str) -> Result<(Vec<String>, Vec<Vec<f64>>)> {
    let text = read(dir, name)?;
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .ok_or_else(|| bad(dir, format!("{name} is empty")))?
        .split(',')
        .map(str::to_string)
        .collect();
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let row: std::result::Result<Vec<f64>, _> = line.split(',').map(str::parse).collect();
        let row = row.map_err(|e| bad(dir, format!("{name} line {}: {e}", i + 2)))?;
        if row.len() != header.len() || row.iter().any(|v| !v.is_finite()) {
            return Err(bad(
                dir,
                format!(
                    "{name} line {}: expected {} finite numbers",
                    i + 2,
                    header.len()
                ),
            ));
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err(bad(dir, format!("{name} has no rows")));
    }
    Ok((header, rows))
}

/// A short description of a scenario's input, for titles and legends.
pub(crate) fn describe(input: &InputSpec) -> String {
    match input {
        InputSpec::Force(ForceSpec {
            force_n: Some(f), ..
        }) => format!("force {f} N"),
        InputSpec::Force(ForceSpec { .. }) => "force table".into(),
        InputSpec::MassDrop(MassDropSpec { mass_kg, height_m }) => {
            format!("{mass_kg} kg dropped from {} mm", height_m * 1e3)
        }
        InputSpec::Pendulum(PendulumSpec { release_angle_deg }) => {
            format!("pendulum {release_angle_deg}°")
        }
        InputSpec::Motion(MotionSpec { .. }) => "key motion".into(),
        InputSpec::Touch(TouchSpec {
            peak_force_n: Some(f),
            ..
        }) => format!("pressed touch {f} N"),
        InputSpec::Touch(TouchSpec {
            finger_speed_m_s: Some(v),
            ..
        }) => format!("struck touch {v} m/s"),
        InputSpec::Touch(TouchSpec { .. }) => "touch".into(),
    }
}

/// Two onsets of the same contact closer than this are chatter, not a new event (s).
pub const CHATTER_S: f64 = 0.005;

/// The events of a run a reader should see, from the complete list of `events.json`
/// (objects with `name` and `time_s`, in time order), in time order. Left out:
/// - releases and lifts (`*_release`, `*_lift`): the end of what the onset started;
/// - chatter: the same event again within [`CHATTER_S`] of its last occurrence;
/// - a `let_off` before the jack has been reset (`jack_reset`) since the last one: the
///   escaped jack's toe touching its button again is not a new let-off;
/// - a `check_catch` with no string contact since the last one: the hammer bouncing on the
///   backcheck is not a new check.
///
/// `events.json` itself stays complete.
pub fn listed_events(events: &[Value]) -> Vec<Value> {
    let mut out: Vec<Value> = Vec::new();
    let (mut jack_out, mut struck_since_check, mut checked) = (false, false, false);
    let mut last_seen = std::collections::BTreeMap::new();
    for e in events {
        let (Some(name), Some(t)) = (e["name"].as_str(), e["time_s"].as_f64()) else {
            continue;
        };
        match name {
            "jack_reset" => jack_out = false,
            "string_contact_start" => struck_since_check = true,
            _ => {}
        }
        if name.ends_with("_release") || name.ends_with("_lift") {
            continue;
        }
        let before = last_seen.insert(name, t);
        if before.is_some_and(|before| t - before <= CHATTER_S) {
            continue;
        }
        match name {
            "let_off" if jack_out => continue,
            "let_off" => jack_out = true,
            "check_catch" if checked && !struck_since_check => continue,
            "check_catch" => (checked, struck_since_check) = (true, false),
            _ => {}
        }
        out.push(e.clone());
    }
    out
}

/// How a contact is named for a reader: its name with spaces, and the presser's pad by
/// what presses (a finger, or the dropped mass).
fn contact_label(name: &str, input: &InputSpec) -> String {
    match (name, input) {
        ("presser_key", InputSpec::MassDrop(_)) => "mass on key".into(),
        ("presser_key", _) => "finger on key".into(),
        _ => name.replace('_', " "),
    }
}

/// A run's name on the page: its folder's name.
pub(crate) fn run_name(dir: &Path) -> String {
    dir.file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| dir.display().to_string())
}

/// Plotted series as the page reads them.
pub(crate) fn to_series(series: Vec<(&str, &str, Vec<f64>)>) -> Vec<Series> {
    series
        .into_iter()
        .map(|(id, label, v)| Series::new(id, label, v))
        .collect()
}

/// The colours of the grand action's contacts on the page.
const GRAND_CONTACT_COLORS: [(&str, &str); 11] = [
    ("hammer_string", "#c0392b"),
    ("capstan_heel", "#2e8b57"),
    ("jack_knuckle", "#8e44ad"),
    ("lever_knuckle", "#2980b9"),
    ("front_rail", "#d35400"),
    ("back_rail", "#7f8c8d"),
    ("let_off_button", "#16a085"),
    ("drop_screw", "#34495e"),
    ("backcheck", "#b7950b"),
    ("rest_rail", "#95a5a6"),
    ("presser_key", "#555555"),
];

/// What the grand's event list leaves out, for the page's note (see [`listed_events`]).
const GRAND_MINOR_EVENTS: &str = "releases, chatter, the jack toe on its button again \
     before the jack is reset, a second catch without a new blow";

/// The grand's contact colours for `names` (grey for one not in the table).
fn grand_contact_colors<'a>(
    names: impl Iterator<Item = &'a str>,
) -> std::collections::BTreeMap<String, String> {
    names
        .map(|n| {
            let c = GRAND_CONTACT_COLORS
                .iter()
                .find(|(k, _)| *k == n)
                .map_or("#333333", |(_, c)| c);
            (n.to_string(), c.to_string())
        })
        .collect()
}

/// The grand runs' plots: the hammer, the key, the contact forces, the energies and the
/// hand's force under a key motion.
fn grand_plots() -> Vec<Plot> {
    vec![
        Plot::of("hammer-angle", "Hammer angle (°)", "hammer_angle_deg"),
        Plot::of(
            "hammer-speed",
            "Hammer speed at the strike point (m/s)",
            "hammer_speed_m_s",
        ),
        Plot::of(
            "key-depth",
            "Key-front depth below rest (mm)",
            "key_depth_mm",
        ),
        Plot::contact_forces(),
        Plot::energy("from rest"),
        Plot::of(
            "hand-force",
            "Hand force at the key front (N)",
            "key_drive_force_n",
        ),
    ]
}

/// A grand run's headline: the first strike's speed and time.
fn grand_headline(summary: &Value) -> String {
    match summary["strikes"].get(0) {
        Some(first) => format!(
            "{:.2} m/s at {:.2} ms",
            first["hammer_velocity_m_s"].as_f64().unwrap_or(f64::NAN),
            first["time_s"].as_f64().unwrap_or(f64::NAN) * 1e3
        ),
        None => "no strike".into(),
    }
}

/// The grand's drawing with each part's thickness across the plane (a scene written
/// before the thickness was part of it gets it here).
fn with_grand_thickness(mut scene: Value) -> Value {
    if let Some(parts) = scene["parts"].as_array_mut() {
        for part in parts {
            if part.get("thickness").is_none() {
                let id = part["id"].as_str().unwrap_or_default();
                let h = crate::drawing::grand_thickness_mm(id);
                part["thickness"] = json!(h);
            }
        }
    }
    scene
}

/// A grand run's data from its parts.
#[allow(clippy::too_many_arguments)]
fn grand_run(
    dir: &Path,
    scenario: &Scenario,
    kind: ModelKind,
    scene: Value,
    t: Vec<f64>,
    carry: std::collections::BTreeMap<String, Carry>,
    contacts: std::collections::BTreeMap<String, ContactSeries>,
    series: Vec<Series>,
    zoom: Value,
) -> Result<RunData> {
    let contact_labels = contacts
        .keys()
        .map(|c| (c.clone(), contact_label(c, &scenario.input)))
        .collect();
    let contact_colors = grand_contact_colors(contacts.keys().map(String::as_str));
    let measured = read_measured(dir, &series)?;
    let events = read_json(dir, "events.json")?;
    let summary = read_json(dir, "summary.json")?;
    Ok(RunData {
        name: run_name(dir),
        title: format!("{} action, {}", kind.name(), describe(&scenario.input)),
        model: kind.name().into(),
        headline: grand_headline(&summary),
        scene: with_grand_thickness(scene),
        t,
        carry,
        contacts,
        contact_labels,
        contact_colors,
        series,
        plots: grand_plots(),
        listed_events: Value::from(listed_events(events.as_array().map_or(&[], Vec::as_slice))),
        events,
        minor_events: GRAND_MINOR_EVENTS.into(),
        summary,
        zoom,
        measured,
    })
}

/// The report data of one run directory (see the module docs).
pub fn run_data(dir: &Path) -> Result<RunData> {
    let run = read_json(dir, "run.json")?;
    if run["scenario"].get("mechanism").is_some() {
        return crate::mechanism_run::report_data(dir, &run);
    }
    let scenario: Scenario = serde_json::from_value(run["scenario"].clone())
        .map_err(|e| bad(dir, format!("run.json scenario: {e}")))?;
    let params: ActionParams = serde_json::from_value(run["params"].clone())
        .map_err(|e| bad(dir, format!("run.json params: {e}")))?;
    params
        .validate()
        .map_err(|e| e.in_file(&dir.join("run.json")))?;
    if let InputSpec::Pendulum(PendulumSpec { release_angle_deg }) = scenario.input {
        return pendulum_data(dir, &params, release_angle_deg);
    }
    let kind: ModelKind = scenario.model_kind()?;
    if dir.join(SCENE_JSON).exists() {
        return grand_data_from_files(dir, &scenario, kind);
    }
    // A run directory written before the replay files: rebuild the action and settle it.
    let Prepared {
        action,
        x0,
        rest_depth_mm,
    } = prepare(&params, kind, &scenario.input.to_input()?)?;
    let model = action.system.model();
    let nv = model.nv();
    let names = model.coordinate_names().to_vec();
    let (header, rows) = read_trajectory(dir)?;
    for (i, n) in names.iter().enumerate() {
        let (q, v) = (format!("{n}_q"), format!("{n}_v"));
        if header.get(1 + i) != Some(&q) || header.get(1 + nv + i) != Some(&v) {
            return Err(bad(
                dir,
                format!(
                    "trajectory.csv columns do not match the {} model",
                    kind.name()
                ),
            ));
        }
    }
    // The internal states (the string's modes), when the model has any: without them
    // the string would be drawn at rest and its force recomputed as zero.
    let internal = x0.len() - 2 * nv;
    let internal_rows = if internal > 0 {
        let (h, r) = read_numeric_csv(dir, crate::scenario::INTERNAL_STATES_CSV)?;
        if h.len() != 1 + internal || r.len() != rows.len() {
            return Err(bad(
                dir,
                format!(
                    "{} has {} columns and {} rows; the {} model needs {} and trajectory.csv has {}",
                    crate::scenario::INTERNAL_STATES_CSV,
                    h.len(),
                    r.len(),
                    kind.name(),
                    1 + internal,
                    rows.len()
                ),
            ));
        }
        r
    } else {
        Vec::new()
    };
    let drive_col = header.iter().position(|h| h == "key_drive_force_n");
    let key = model.coordinate_id("key")?;
    let hammer = model.coordinate_id("hammer")?;
    let strike_radius_m = {
        let s = params.hammer.strike_body_mm;
        s[0].hypot(s[1]) * 1e-3
    };

    let frames = crate::drawing::scene(&action)?;
    let frame_names: Vec<&str> = frames["frames"]
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_str).collect())
        .unwrap_or_default();
    let contact_names: Vec<&str> = action.contacts.keys().map(String::as_str).collect();

    let n = rows.len();
    let mut t = Vec::with_capacity(n);
    let mut carry: Vec<[Vec<f64>; 3]> = vec![Default::default(); frame_names.len()];
    let mut forces: Vec<[Vec<f64>; 5]> = vec![Default::default(); contact_names.len()];
    let mut series: Vec<(&str, &str, Vec<f64>)> = vec![
        ("hammer_angle_deg", "hammer angle (°)", Vec::new()),
        (
            "hammer_speed_m_s",
            "hammer speed at the strike point (m/s)",
            Vec::new(),
        ),
        (
            "key_depth_mm",
            "key-front depth below rest (mm)",
            Vec::new(),
        ),
        ("kinetic_mj", "kinetic energy (mJ)", Vec::new()),
        (
            "gravity_mj",
            "gravitational energy from rest (mJ)",
            Vec::new(),
        ),
    ];
    if drive_col.is_some() {
        series.push((
            "key_drive_force_n",
            "hand force at the key front (N)",
            Vec::new(),
        ));
    }
    let mut ws = action.system.workspace();
    let mut potential0 = None;
    let mut x = x0.clone();
    for (i, row) in rows.iter().enumerate() {
        let time = row[0];
        x[..2 * nv].copy_from_slice(&row[1..1 + 2 * nv]);
        if let Some(states) = internal_rows.get(i) {
            x[2 * nv..].copy_from_slice(&states[1..]);
        }
        t.push(r(time, 6));
        let c = crate::drawing::carry(&action, time, &x)?;
        for (slot, (_, m)) in carry.iter_mut().zip(&c) {
            slot[0].push(r(m[0], 6));
            slot[1].push(r(m[1], 3));
            slot[2].push(r(m[2], 3));
        }
        for (slot, name) in forces.iter_mut().zip(&contact_names) {
            let o = action.contact_output(name, time, &x)?;
            let on = o.active && o.normal_force > 0.0;
            let f = if on { o.normal_force } else { 0.0 };
            slot[0].push(r(f, 3));
            // Arrows show the force on a contact's second body, the part acted on; the
            // finger's pad is that body in the model, but the arrow named "finger on key"
            // is the force on the key.
            let sign = if *name == "presser_key" { -1.0 } else { 1.0 };
            for (k, v) in [
                o.point[0] * 1e3,
                o.point[1] * 1e3,
                sign * o.normal[0],
                sign * o.normal[1],
            ]
            .into_iter()
            .enumerate()
            {
                slot[1 + k].push(if on {
                    r(v, if k < 2 { 2 } else { 3 })
                } else {
                    0.0
                });
            }
        }
        let e = action.system.energy(&mut ws, time, &x)?;
        // The elastic energy is left out: under a touch it holds the arm's work (a preload),
        // which would swamp the action's own.
        let p0 = *potential0.get_or_insert(e.gravity);
        let values = [
            x[hammer].to_degrees(),
            x[nv + hammer] * strike_radius_m,
            key_depth_mm(&params, x[key]) - rest_depth_mm,
            e.kinetic * 1e3,
            (e.gravity - p0) * 1e3,
        ];
        for (s, v) in series.iter_mut().zip(values) {
            s.2.push(r(v, 4));
        }
        if let (Some(col), Some(s)) = (drive_col, series.get_mut(5)) {
            s.2.push(r(row[col], 3));
        }
    }

    let zoom = zoom_presets(&action, &x0)?;
    let carry = frame_names
        .iter()
        .zip(carry)
        .map(|(f, [a, x, y])| (f.to_string(), Carry { a, x, y }))
        .collect();
    let contacts = contact_names
        .iter()
        .zip(forces)
        .map(|(c, [f, px, py, nx, ny])| (c.to_string(), ContactSeries { f, px, py, nx, ny }))
        .collect();
    grand_run(
        dir,
        &scenario,
        kind,
        frames,
        t,
        carry,
        contacts,
        to_series(series),
        zoom,
    )
}

/// The run-directory file with the drawing's scene and the zoom presets (written by
/// `piano simulate`, so the report replays a run without rebuilding the action).
pub const SCENE_JSON: &str = "scene.json";

/// The grand series of the report and `series.csv`: id and label.
const GRAND_SERIES: [(&str, &str); 6] = [
    ("hammer_angle_deg", "hammer angle (°)"),
    ("hammer_speed_m_s", "hammer speed at the strike point (m/s)"),
    ("key_depth_mm", "key-front depth below rest (mm)"),
    ("kinetic_mj", "kinetic energy (mJ)"),
    ("gravity_mj", "gravitational energy from rest (mJ)"),
    ("key_drive_force_n", "hand force at the key front (N)"),
];

/// Writes what the report of a grand run reads besides `trajectory.csv` and `contacts.csv`
/// (which must be written): `poses.csv` (every drawn frame's motion from its rest place),
/// `series.csv` (hammer angle and speed, key depth, energies, the hand's force under a key
/// motion) and [`SCENE_JSON`] (the drawing's parts and contact shapes at rest, the zoom
/// presets). The report then needs neither the parameters' action nor a settle.
pub(crate) fn write_replay_files(
    dir: &Path,
    prepared: &Prepared,
    run: &crate::simulate::Run,
) -> Result<()> {
    use std::fmt::Write as _;
    let action = &prepared.action;
    let params = &action.params;
    let sol = &run.solution;
    let model = action.system.model();
    let nv = model.nv();
    let key = model.coordinate_id("key")?;
    let hammer = model.coordinate_id("hammer")?;
    let strike_radius_m = {
        let s = params.hammer.strike_body_mm;
        s[0].hypot(s[1]) * 1e-3
    };
    let with_drive = run.key_drive_force_n.len() == sol.len();
    let mut poses = String::from("time_s");
    for (f, _) in crate::drawing::carry(action, 0.0, &prepared.x0)? {
        let _ = write!(poses, ",{f}_angle_rad,{f}_x_mm,{f}_y_mm");
    }
    poses.push('\n');
    let mut series = String::from("time_s");
    for (id, _) in GRAND_SERIES.iter().take(if with_drive { 6 } else { 5 }) {
        let _ = write!(series, ",{id}");
    }
    series.push('\n');
    let mut ws = action.system.workspace();
    let mut potential0 = None;
    for i in 0..sol.len() {
        let (time, x) = (sol.t[i], sol.state(i));
        let _ = write!(poses, "{time}");
        for (_, c) in crate::drawing::carry(action, time, x)? {
            let _ = write!(poses, ",{},{},{}", c[0], c[1], c[2]);
        }
        poses.push('\n');
        let e = action.system.energy(&mut ws, time, x)?;
        // The elastic energy is left out: under a touch it holds the arm's work (a preload),
        // which would swamp the action's own.
        let p0 = *potential0.get_or_insert(e.gravity);
        let _ = write!(
            series,
            "{time},{},{},{},{},{}",
            x[hammer].to_degrees(),
            x[nv + hammer] * strike_radius_m,
            key_depth_mm(params, x[key]) - prepared.rest_depth_mm,
            e.kinetic * 1e3,
            (e.gravity - p0) * 1e3
        );
        if with_drive {
            let _ = write!(series, ",{}", run.key_drive_force_n[i]);
        }
        series.push('\n');
    }
    let write = |name: &str, text: &str| {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| PianoError::io(&path, "write", e))
    };
    write("poses.csv", &poses)?;
    write("series.csv", &series)?;
    let scene = json!({
        "scene": crate::drawing::scene(action)?,
        "zoom": zoom_presets(action, &prepared.x0)?,
    });
    let text = serde_json::to_string(&scene)
        .map_err(|e| PianoError::file(&dir.join(SCENE_JSON), format!("cannot encode: {e}")))?;
    write(SCENE_JSON, &text)
}

/// Where millimetres matter: the contacts that set the regulation, at rest.
fn zoom_presets(action: &crate::Action, x0: &[f64]) -> Result<Value> {
    let mut zoom = serde_json::Map::new();
    for (label, contact, half) in [
        ("let-off", "let_off_button", 18.0),
        ("jack and knuckle", "jack_knuckle", 18.0),
        ("string", "hammer_string", 25.0),
        ("backcheck", "backcheck", 25.0),
        ("capstan", "capstan_heel", 18.0),
    ] {
        if action.contacts.contains_key(contact) {
            // The first side's surface point (the string, the button, the jack top, the
            // backcheck face, the capstan), not the middle of a wide gap.
            let o = action.contact_output(contact, 0.0, x0)?;
            let p = [
                o.point[0] - 0.5 * o.gap * o.normal[0],
                o.point[1] - 0.5 * o.gap * o.normal[1],
            ];
            zoom.insert(
                label.into(),
                json!({"center": [r(p[0] * 1e3, 2), r(p[1] * 1e3, 2)], "half_width": half}),
            );
        }
    }
    Ok(Value::Object(zoom))
}

/// The report data of a grand run from its files alone (see [`write_replay_files`]).
fn grand_data_from_files(dir: &Path, scenario: &Scenario, kind: ModelKind) -> Result<RunData> {
    let scene_file = read_json(dir, SCENE_JSON)?;
    let frames = scene_file["scene"].clone();
    let frame_names: Vec<String> = frames["frames"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(Value::as_str)
                .map(str::to_string)
                .collect()
        })
        .unwrap_or_default();
    let (header, rows) = read_numeric_csv(dir, "poses.csv")?;
    // The trajectory is the run's record: read and check it even though the replay files
    // hold what the page shows.
    let (_, trajectory) = read_trajectory(dir)?;
    if trajectory.len() != rows.len() {
        return Err(bad(
            dir,
            format!(
                "trajectory.csv has {} rows and poses.csv {}",
                trajectory.len(),
                rows.len()
            ),
        ));
    }
    let t: Vec<f64> = rows.iter().map(|row| r(row[0], 6)).collect();
    let column = |header: &[String], name: &str, file: &str| {
        header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| bad(dir, format!("{file} has no column {name}")))
    };
    let mut carry = std::collections::BTreeMap::new();
    for f in &frame_names {
        let col = column(&header, &format!("{f}_angle_rad"), "poses.csv")?;
        let take = |k: usize, digits: i32| -> Vec<f64> {
            rows.iter().map(|row| r(row[col + k], digits)).collect()
        };
        carry.insert(
            f.clone(),
            Carry {
                a: take(0, 6),
                x: take(1, 3),
                y: take(2, 3),
            },
        );
    }
    let (header, crow) = read_numeric_csv(dir, "contacts.csv")?;
    if crow.len() != rows.len() {
        return Err(bad(
            dir,
            format!(
                "contacts.csv has {} rows and poses.csv {}",
                crow.len(),
                rows.len()
            ),
        ));
    }
    let contact_names: Vec<String> = header
        .iter()
        .filter_map(|h| h.strip_suffix("_active"))
        .map(str::to_string)
        .collect();
    let mut forces = std::collections::BTreeMap::new();
    for name in &contact_names {
        let col = column(&header, &format!("{name}_force_n"), "contacts.csv")?;
        let active = column(&header, &format!("{name}_active"), "contacts.csv")?;
        // Arrows show the force on a contact's second body, the part acted on; the finger's
        // pad is that body in the model, but the arrow named "finger on key" is the force
        // on the key.
        let sign = if name == "presser_key" { -1.0 } else { 1.0 };
        let mut slot: [Vec<f64>; 5] = Default::default();
        for row in &crow {
            let on = row[active] > 0.5 && row[col] > 0.0;
            slot[0].push(r(if on { row[col] } else { 0.0 }, 3));
            for k in 0..4 {
                let v = row[col + 1 + k] * if k < 2 { 1.0 } else { sign };
                slot[1 + k].push(if on {
                    r(v, if k < 2 { 2 } else { 3 })
                } else {
                    0.0
                });
            }
        }
        let [f, px, py, nx, ny] = slot;
        forces.insert(name.clone(), ContactSeries { f, px, py, nx, ny });
    }
    let (header, srow) = read_numeric_csv(dir, "series.csv")?;
    let mut series: Vec<(&str, &str, Vec<f64>)> = Vec::new();
    for (id, label) in GRAND_SERIES {
        if let Some(col) = header.iter().position(|h| h == id) {
            let digits = if id == "key_drive_force_n" { 3 } else { 4 };
            series.push((
                id,
                label,
                srow.iter().map(|row| r(row[col], digits)).collect(),
            ));
        }
    }
    grand_run(
        dir,
        scenario,
        kind,
        frames,
        t,
        carry,
        forces,
        to_series(series),
        scene_file["zoom"].clone(),
    )
}

/// The report data of a pendulum run directory: the hammer hanging on its flange and
/// swinging by the angle in `trajectory.csv`, the angle, the strike point's speed and the
/// energies against time, the turning points as events. No key, no contacts.
fn pendulum_data(dir: &Path, params: &ActionParams, release_angle_deg: f64) -> Result<RunData> {
    let (header, rows) = read_trajectory(dir)?;
    if header != ["time_s", "hammer_q", "hammer_v"] {
        return Err(bad(
            dir,
            "trajectory.csv of a pendulum run has the columns time_s, hammer_q, hammer_v".into(),
        ));
    }
    let h = &params.hammer;
    let hanging = crate::pendulum::hanging_shank_angle_rad(params);
    let mass = h.mass_g * 1e-3;
    let com = h.com_body_mm[0].hypot(h.com_body_mm[1]) * 1e-3;
    let inertia_pin = h.inertia_com_kg_m2 + mass * com * com;
    let strike_radius_m = h.strike_body_mm[0].hypot(h.strike_body_mm[1]) * 1e-3;
    let (mut t, mut carry) = (Vec::new(), [Vec::new(), Vec::new(), Vec::new()]);
    let mut series: Vec<(&str, &str, Vec<f64>)> = vec![
        (
            "hammer_angle_deg",
            "hammer angle from hanging (°)",
            Vec::new(),
        ),
        (
            "hammer_speed_m_s",
            "hammer speed at the strike point (m/s)",
            Vec::new(),
        ),
        ("kinetic_mj", "kinetic energy (mJ)", Vec::new()),
        (
            "gravity_mj",
            "gravitational energy from the release (mJ)",
            Vec::new(),
        ),
    ];
    let q0 = rows[0][1];
    for row in &rows {
        let (time, q, w) = (row[0], row[1], row[2]);
        t.push(r(time, 6));
        for (slot, v) in carry
            .iter_mut()
            .zip(crate::drawing::pendulum_carry(params, q))
        {
            slot.push(r(v, 6));
        }
        // The centre of mass is d cos q below the pin.
        let values = [
            q.to_degrees(),
            w * strike_radius_m,
            0.5 * inertia_pin * w * w * 1e3,
            mass * crate::params::GRAVITY_M_S2 * com * (q0.cos() - q.cos()) * 1e3,
        ];
        for (s, v) in series.iter_mut().zip(values) {
            s.2.push(r(v, 4));
        }
    }
    let series = to_series(series);
    let events = read_json(dir, "events.json")?;
    let measured = read_measured(dir, &series)?;
    let summary = read_json(dir, "summary.json")?;
    let [a, x, y] = carry;
    let p = &summary["pendulum"];
    let headline = format!(
        "{} turning points, period {} (small swings: {:.3} s)",
        p["turns"].as_array().map_or(0, Vec::len),
        p["period_s"]
            .as_f64()
            .map_or("–".into(), |t| format!("{t:.3} s")),
        p["small_amplitude_period_s"].as_f64().unwrap_or(f64::NAN)
    );
    Ok(RunData {
        name: run_name(dir),
        title: format!("hammer swing, released {release_angle_deg}° from hanging"),
        model: "pendulum".into(),
        headline,
        scene: with_grand_thickness(crate::drawing::pendulum_scene(params, hanging)),
        t,
        carry: [("hammer".to_string(), Carry { a, x, y })].into(),
        contacts: Default::default(),
        contact_labels: Default::default(),
        contact_colors: Default::default(),
        series,
        plots: vec![
            Plot::of(
                "hammer-angle",
                "Hammer angle from hanging (°)",
                "hammer_angle_deg",
            ),
            Plot::of(
                "hammer-speed",
                "Hammer speed at the strike point (m/s)",
                "hammer_speed_m_s",
            ),
            Plot::energy("from the release"),
        ],
        listed_events: Value::from(listed_events(events.as_array().map_or(&[], Vec::as_slice))),
        events,
        minor_events: "releases and chatter".into(),
        summary,
        zoom: json!({}),
        measured,
    })
}

/// The measured data of a run, if its directory has `measured.csv` (see
/// [`crate::measured`]), by series id.
pub(crate) fn read_measured(
    dir: &Path,
    series: &[Series],
) -> Result<Option<std::collections::BTreeMap<String, Measured>>> {
    let path = dir.join("measured.csv");
    if !path.exists() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path).map_err(|e| PianoError::io(&path, "read", e))?;
    let known: Vec<&str> = series.iter().map(|s| s.id.as_str()).collect();
    let measured = crate::measured::parse_measured(&text, &path, &known)?;
    Ok(Some(
        measured
            .into_iter()
            .map(|s| {
                let t: Vec<f64> = s.t.iter().map(|&t| r(t, 6)).collect();
                let v: Vec<f64> = s.v.iter().map(|&v| r(v, 4)).collect();
                (s.id, Measured { t, v })
            })
            .collect(),
    ))
}

/// Embeds `value` as JSON inside a `<script>` element: `</` is escaped so no string in the
/// data can close the element.
fn embed(value: &impl serde::Serialize) -> Result<String> {
    let text = serde_json::to_string(value)
        .map_err(|e| PianoError::Simulation(format!("cannot encode the report's data: {e}")))?;
    Ok(text.replace("</", "<\\/"))
}

fn escape_html(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The report page of the runs in `dirs` (at least one), as one self-contained HTML string.
pub fn report_html(dirs: &[PathBuf]) -> Result<String> {
    if dirs.is_empty() {
        return Err(PianoError::option(
            "RUN_DIR",
            "give at least one run directory",
        ));
    }
    let runs: Vec<RunData> = dirs.iter().map(|d| run_data(d)).collect::<Result<_>>()?;
    let swings = runs.iter().filter(|r| r.model == "pendulum").count();
    if swings > 0 && swings < runs.len() {
        return Err(PianoError::option(
            "RUN_DIR",
            "a hammer swing (pendulum run) and keystrokes have different plots; give them \
             separate reports",
        ));
    }
    let title = runs
        .iter()
        .map(|r| r.title.as_str())
        .collect::<Vec<_>>()
        .join(" · ");
    let data = ReportData {
        version: env!("CARGO_PKG_VERSION").into(),
        runs,
    };
    let mut html = String::new();
    let _ = write!(
        html,
        r#"<!DOCTYPE html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<meta name="generator" content="{GENERATOR}">
<title>{}</title>
<style>
{STYLE}
</style>
</head>
<body>
<script type="application/json" id="report-data">{}</script>
<script>
{SCRIPT}
</script>
</body>
</html>
"#,
        escape_html(&format!("Piano action report: {title}")),
        embed(&data)?
    );
    Ok(html)
}

/// Writes the report of `dirs` to `out`. An existing `out` is refused, unless `replace`
/// is set and it is itself a report (its `generator` is [`GENERATOR`]): anything else is
/// left alone, with an error.
pub fn write_report(dirs: &[PathBuf], out: &Path, replace: bool) -> Result<()> {
    if out.exists() {
        let ours = std::fs::read_to_string(out)
            .map(|t| t.contains(&format!(r#"<meta name="generator" content="{GENERATOR}">"#)))
            .unwrap_or(false);
        if !ours {
            return Err(PianoError::file(
                out,
                "exists and is not a piano report; choose another --out",
            ));
        }
        if !replace {
            return Err(PianoError::file(
                out,
                "exists; choose another --out, or pass --force to replace it",
            ));
        }
    }
    let html = report_html(dirs)?;
    std::fs::write(out, html).map_err(|e| PianoError::io(out, "write", e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn embedded_json_cannot_close_its_script_element() {
        let v = json!({"name": "</script><script>alert(1)</script>"});
        let text = embed(&v).unwrap();
        assert!(!text.contains("</"), "{text}");
        let back: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, v);
    }
}
