//! Scenarios (what `piano simulate SCENARIO.toml` runs) and run directories (what it
//! writes: `run.json`, `trajectory.csv`, `events.json`, `summary.json`).

use std::fmt::Write as _;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::action::ModelKind;
use crate::error::{PianoError, Result};
use crate::params::ActionParams;
use crate::simulate::{Finger, Input, Prepared, Run, TouchStyle, simulate};

/// The input of a scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum InputSpec {
    /// A force on the key front: `force_n` (N) from t = 0, reached after `ramp_s` if given
    /// (a linear ramp), released at `release_s` if given; or a table
    /// `points = [[time_s, force_n], ...]`, piecewise linear.
    Force {
        /// Force (N).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        force_n: Option<f64>,
        /// Rise time of a ramp (s).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        ramp_s: Option<f64>,
        /// Release time (s).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        release_s: Option<f64>,
        /// `[time_s, force_n]` points, instead of `force_n`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        points: Option<Vec<[f64; 2]>>,
    },
    /// A mass released on the key front from `height_m` (0: placed on it).
    MassDrop {
        /// Mass (kg).
        mass_kg: f64,
        /// Drop height (m).
        height_m: f64,
    },
    /// The hammer alone on its flange released from `release_angle_deg` off hanging (the
    /// pendulum or swing test); `model` is not used.
    Pendulum {
        /// Release angle from the hanging position (degrees).
        release_angle_deg: f64,
    },
    /// A finger touch: `style = "pressed"` with `peak_force_n`, or `style = "struck"` with
    /// `finger_speed_m_s`; the finger's `finger_mass_g`, `rise_s` and `arm_damping_n_s_m`
    /// default to [`Finger::default`].
    Touch {
        /// `"pressed"` or `"struck"`.
        style: TouchStyleName,
        /// Peak force of a pressed touch (N).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        peak_force_n: Option<f64>,
        /// Arrival speed of a struck finger (m/s).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        finger_speed_m_s: Option<f64>,
        /// Effective finger mass (g).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        finger_mass_g: Option<f64>,
        /// Rise time of a pressed touch's force (s).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        rise_s: Option<f64>,
        /// Arm coupling of a struck touch (N·s/m).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        arm_damping_n_s_m: Option<f64>,
    },
    /// Prescribed key-front depth below rest, `points = [[time_s, depth_mm], ...]`,
    /// piecewise linear, or read from `csv = "FILE"` (two columns, time_s and depth_mm, an
    /// optional header line; the path relative to the scenario file).
    Motion {
        /// `[time_s, depth_mm]` points.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        points: Option<Vec<[f64; 2]>>,
        /// A CSV file of the points, instead of `points`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        csv: Option<String>,
    },
}

/// The two touches of Goebl, Bresin & Galembo (2005).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TouchStyleName {
    /// The finger rests on the key and pushes.
    Pressed,
    /// The finger arrives with a speed.
    Struck,
}

impl InputSpec {
    /// The simulation input this spec describes; a missing or misplaced field is named.
    pub fn to_input(&self) -> Result<Input> {
        Ok(match self {
            InputSpec::Force {
                force_n,
                ramp_s,
                release_s,
                points,
            } => force_input(*force_n, *ramp_s, *release_s, points.as_deref())?,
            &InputSpec::MassDrop { mass_kg, height_m } => Input::MassDrop { mass_kg, height_m },
            InputSpec::Pendulum { .. } => {
                return Err(PianoError::Params {
                    field: "input.kind".into(),
                    message: "a pendulum scenario has no keystroke: run it with `swing` and \
                              `write_pendulum_dir`"
                        .into(),
                });
            }
            InputSpec::Motion { points, csv } => match (points, csv) {
                // Both: the points were read from the csv by `load`.
                (Some(points), _) => Input::Motion {
                    points: points.iter().map(|p| (p[0], p[1])).collect(),
                },
                (None, Some(file)) => {
                    return Err(PianoError::Params {
                        field: "input.csv".into(),
                        message: format!(
                            "'{file}' is read by Scenario::load, which knows where the \
                             scenario file is"
                        ),
                    });
                }
                _ => {
                    return Err(PianoError::Params {
                        field: "input.points".into(),
                        message: "give either points or csv".into(),
                    });
                }
            },
            &InputSpec::Touch {
                style,
                peak_force_n,
                finger_speed_m_s,
                finger_mass_g,
                rise_s,
                arm_damping_n_s_m,
            } => {
                let missing = |field: &str, style: &str| PianoError::Params {
                    field: format!("input.{field}"),
                    message: format!("a {style} touch needs {field}"),
                };
                let misplaced = |field: &str, style: &str| PianoError::Params {
                    field: format!("input.{field}"),
                    message: format!("does not apply to a {style} touch"),
                };
                let style = match style {
                    TouchStyleName::Pressed => {
                        if finger_speed_m_s.is_some() {
                            return Err(misplaced("finger_speed_m_s", "pressed"));
                        }
                        TouchStyle::Pressed {
                            peak_force_n: peak_force_n
                                .ok_or_else(|| missing("peak_force_n", "pressed"))?,
                        }
                    }
                    TouchStyleName::Struck => {
                        if peak_force_n.is_some() {
                            return Err(misplaced("peak_force_n", "struck"));
                        }
                        TouchStyle::Struck {
                            finger_speed_m_s: finger_speed_m_s
                                .ok_or_else(|| missing("finger_speed_m_s", "struck"))?,
                        }
                    }
                };
                let d = Finger::default();
                Input::Touch {
                    style,
                    finger: Finger {
                        mass_g: finger_mass_g.unwrap_or(d.mass_g),
                        rise_s: rise_s.unwrap_or(d.rise_s),
                        arm_damping_n_s_m: arm_damping_n_s_m.unwrap_or(d.arm_damping_n_s_m),
                        pad: d.pad,
                    },
                }
            }
        })
    }
}

/// The input of `kind = "force"`: a constant force, a ramp, a release, or a table.
fn force_input(
    force_n: Option<f64>,
    ramp_s: Option<f64>,
    release_s: Option<f64>,
    points: Option<&[[f64; 2]]>,
) -> Result<Input> {
    let field = |name: &str, message: &str| PianoError::Params {
        field: format!("input.{name}"),
        message: message.into(),
    };
    if let Some(points) = points {
        for (name, given) in [
            ("force_n", force_n.is_some()),
            ("ramp_s", ramp_s.is_some()),
            ("release_s", release_s.is_some()),
        ] {
            if given {
                return Err(field(name, "does not go with a points table"));
            }
        }
        return Ok(Input::ForceTable {
            points: points.iter().map(|p| (p[0], p[1])).collect(),
        });
    }
    let force_n = force_n.ok_or_else(|| field("force_n", "needs force_n or points"))?;
    let Some(ramp) = ramp_s else {
        return Ok(Input::Force { force_n, release_s });
    };
    if !(ramp.is_finite() && ramp > 0.0) {
        return Err(field("ramp_s", &format!("must be positive, got {ramp}")));
    }
    let mut table = vec![(0.0, 0.0), (ramp, force_n)];
    if let Some(t) = release_s {
        if !(t.is_finite() && t > ramp) {
            return Err(field(
                "release_s",
                &format!("must come after the ramp ({ramp} s), got {t}"),
            ));
        }
        table.extend([(t, force_n), (t + 1e-3, 0.0)]);
    }
    Ok(Input::ForceTable { points: table })
}

/// Reads `[time, value]` rows from CSV text (comma, semicolon, tab or space separated; a
/// first line that is not numbers is a header); errors name the file and the line.
pub fn read_points_csv(text: &str, file: &str) -> Result<Vec<[f64; 2]>> {
    let bad = |line: usize, message: String| PianoError::Params {
        field: "input.csv".into(),
        message: format!("{file} line {line}: {message}"),
    };
    let mut points = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let cells: Vec<&str> = line
            .split([',', ';', '\t', ' '])
            .filter(|c| !c.is_empty())
            .collect();
        let numbers: Vec<Option<f64>> = cells.iter().map(|c| c.parse().ok()).collect();
        match numbers.as_slice() {
            [Some(t), Some(v)] => points.push([*t, *v]),
            _ if points.is_empty() && numbers.iter().any(Option::is_none) && i == 0 => {}
            _ => {
                return Err(bad(
                    i + 1,
                    format!("expected two numbers (time, value), got '{line}'"),
                ));
            }
        }
    }
    if points.is_empty() {
        return Err(bad(0, "no data rows".into()));
    }
    Ok(points)
}

/// A scenario file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// `"simplified"`, `"single"` or `"double"`.
    pub model: String,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Output grid spacing (s); 1 ms by default.
    #[serde(default = "default_output_step")]
    pub output_step_s: f64,
    /// What drives the key.
    pub input: InputSpec,
}

fn default_output_step() -> f64 {
    1e-3
}

impl Scenario {
    /// Parses a scenario; errors name the field.
    pub fn from_toml_str(text: &str) -> Result<Self> {
        let de = toml::Deserializer::parse(text).map_err(|e| PianoError::Params {
            field: String::new(),
            message: e.to_string(),
        })?;
        serde_path_to_error::deserialize(de).map_err(|e| PianoError::Params {
            field: e.path().to_string(),
            message: e.inner().to_string(),
        })
    }

    /// Reads and parses the scenario file at `path`, and reads a motion's `csv` (relative to
    /// the scenario's folder) into its points. Errors name the file and the field.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path).map_err(|e| PianoError::Params {
            field: String::new(),
            message: format!("cannot read {}: {e}", path.display()),
        })?;
        let mut scenario = Self::from_toml_str(&text).map_err(|e| match e {
            PianoError::Params { field, message } => PianoError::Params {
                field,
                message: format!("{message} (in {})", path.display()),
            },
            other => other,
        })?;
        if let InputSpec::Motion {
            points,
            csv: Some(file),
        } = &mut scenario.input
        {
            if points.is_some() {
                return Err(PianoError::Params {
                    field: "input.csv".into(),
                    message: "give either points or csv, not both".into(),
                });
            }
            let full = path.parent().unwrap_or(Path::new(".")).join(&*file);
            let text = std::fs::read_to_string(&full).map_err(|e| PianoError::Params {
                field: "input.csv".into(),
                message: format!("cannot read {}: {e}", full.display()),
            })?;
            *points = Some(read_points_csv(&text, &full.display().to_string())?);
            // The points are now in the scenario (and its run.json); the file name stays as
            // a record of where they came from.
        }
        Ok(scenario)
    }

    /// The model kind named by `model`.
    pub fn model_kind(&self) -> Result<ModelKind> {
        ModelKind::ALL
            .into_iter()
            .find(|k| k.name() == self.model)
            .ok_or_else(|| PianoError::Params {
                field: "model".into(),
                message: format!(
                    "unknown model '{}' (simplified, single or double)",
                    self.model
                ),
            })
    }

    /// Runs the scenario.
    pub fn run(&self, params: &ActionParams) -> Result<Run> {
        let input = self.input.to_input()?;
        simulate(
            params,
            self.model_kind()?,
            &input,
            self.duration_s,
            self.output_step_s,
        )
    }
}

/// Writes `text` to `dir/name`; the error names the file.
fn write_file(dir: &Path, name: &str, text: &str) -> Result<()> {
    std::fs::write(dir.join(name), text).map_err(|e| PianoError::Params {
        field: String::new(),
        message: format!("cannot write {}: {e}", dir.join(name).display()),
    })
}

/// Writes `value` as pretty JSON to `dir/name`.
fn write_json(dir: &Path, name: &str, value: &serde_json::Value) -> Result<()> {
    let text = serde_json::to_string_pretty(value).map_err(|e| PianoError::Params {
        field: String::new(),
        message: format!("cannot encode {name}: {e}"),
    })?;
    write_file(dir, name, &text)
}

/// Creates the run directory and writes `run.json` (scenario, parameters, version).
fn start_run_dir(dir: &Path, scenario: &Scenario, params: &ActionParams) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| PianoError::Params {
        field: String::new(),
        message: format!("cannot create {}: {e}", dir.display()),
    })?;
    let run_json = serde_json::json!({
        "scenario": serde_json::to_value(scenario).unwrap_or_default(),
        "params": serde_json::to_value(params).unwrap_or_default(),
        "version": env!("CARGO_PKG_VERSION"),
    });
    write_json(dir, "run.json", &run_json)
}

fn num(x: Option<f64>) -> serde_json::Value {
    x.map_or(serde_json::Value::Null, serde_json::Value::from)
}

/// Writes the run directory `dir` (created if needed): `run.json` (scenario and
/// parameters), `trajectory.csv` (time, coordinates, velocities on the output grid),
/// `contacts.csv` (gaps and normal forces on the same grid), `events.json`,
/// `summary.json` (strikes, key start, travel, let-off, key-bottom and check times,
/// events) and the drawings `drawing_rest.svg`, `drawing_let_off.svg`,
/// `drawing_string_contact.svg` and `drawing_check.svg` (those that happen).
pub fn write_run_dir(
    dir: &Path,
    scenario: &Scenario,
    params: &ActionParams,
    run: &Run,
) -> Result<()> {
    start_run_dir(dir, scenario, params)?;

    // The action as the run had it (with a presser, if any), for the names, the contacts
    // and the drawings.
    let prepared = crate::simulate::prepare(params, run.kind, &scenario.input.to_input()?)?;
    let names = prepared.action.system.model().coordinate_names().to_vec();
    let sol = &run.solution;
    let nv = names.len();
    let mut csv = String::from("time_s");
    for n in &names {
        let _ = write!(csv, ",{n}_q");
    }
    for n in names {
        let _ = write!(csv, ",{n}_v");
    }
    let with_force = run.key_drive_force_n.len() == sol.len();
    if with_force {
        csv.push_str(",key_drive_force_n");
    }
    csv.push('\n');
    for i in 0..sol.len() {
        let _ = write!(csv, "{}", sol.t[i]);
        for v in &sol.state(i)[..2 * nv] {
            let _ = write!(csv, ",{v}");
        }
        if with_force {
            let _ = write!(csv, ",{}", run.key_drive_force_n[i]);
        }
        csv.push('\n');
    }
    write_file(dir, "trajectory.csv", &csv)?;
    write_contacts_and_drawings(dir, &prepared, run)?;

    let events: Vec<serde_json::Value> = run
        .events
        .iter()
        .map(|e| serde_json::json!({"name": e.name, "time_s": e.time_s}))
        .collect();
    write_json(dir, "events.json", &serde_json::Value::from(events.clone()))?;
    let strikes: Vec<serde_json::Value> = run
        .strikes
        .iter()
        .map(|s| {
            serde_json::json!({
                "time_s": s.time_s,
                "hammer_velocity_m_s": s.hammer_velocity_m_s,
                "contact_duration_s": num(s.contact_duration_s),
            })
        })
        .collect();
    let summary = serde_json::json!({
        "model": run.kind.name(),
        "strikes": strikes,
        "key_start_time_s": num(run.key_start_time_s),
        "travel_time_s": num(run.travel_time_s),
        "let_off_time_s": num(run.let_off_time_s),
        "key_bottom_time_s": num(run.key_bottom_time_s),
        "key_bottom_minus_string_contact_s": num(
            run.key_bottom_time_s
                .zip(run.strikes.first())
                .map(|(k, s)| k - s.time_s)
        ),
        "check_time_s": num(run.check_time_s),
        "events": events,
    });
    write_json(dir, "summary.json", &summary)?;
    Ok(())
}

/// Writes `contacts.csv` (every contact's gap and normal force on the output grid) and the
/// drawings of the action at rest, at let-off, at string contact and at the check (those
/// that happen), with the pressed contacts marked.
fn write_contacts_and_drawings(dir: &Path, prepared: &Prepared, run: &Run) -> Result<()> {
    let action = &prepared.action;
    let sol = &run.solution;
    let names: Vec<&str> = action.contacts.keys().copied().collect();
    let mut csv = String::from("time_s");
    for n in &names {
        let _ = write!(csv, ",{n}_gap_mm,{n}_force_n");
    }
    csv.push('\n');
    for i in 0..sol.len() {
        let (t, x) = (sol.t[i], sol.state(i));
        let _ = write!(csv, "{t}");
        for n in &names {
            let out = action.contact_output(n, t, x)?;
            let _ = write!(csv, ",{},{}", out.gap * 1e3, out.normal_force);
        }
        csv.push('\n');
    }
    write_file(dir, "contacts.csv", &csv)?;

    // The state at an event is the integrator's, just past the crossing.
    let at = |time: Option<f64>| {
        time.and_then(|t| {
            sol.events
                .iter()
                .find(|e| e.time == t)
                .map(|e| (t, e.state.clone()))
        })
    };
    let model = run.kind.name();
    let shots = [
        ("rest", Some((0.0, prepared.x0.clone())), "at rest"),
        (
            "let_off",
            at(run.let_off_time_s),
            "let-off (jack toe on the button)",
        ),
        (
            "string_contact",
            at(run.strikes.first().map(|s| s.time_s)),
            "string contact",
        ),
        (
            "check",
            at(run.check_time_s),
            "check (tail on the backcheck)",
        ),
    ];
    for (file, state, what) in shots {
        if let Some((t, x)) = state {
            let title = format!("{model} action, {what}, t = {:.1} ms", t * 1e3);
            let svg = crate::drawing::action_svg(action, t, &x, &title)?;
            write_file(dir, &format!("drawing_{file}.svg"), &svg)?;
        }
    }
    Ok(())
}

/// Writes the run directory of a pendulum scenario: `run.json`, `trajectory.csv` (time,
/// the hammer's angle from hanging `hammer_q` in rad and its rate `hammer_v` in rad/s),
/// `events.json` (the turning points), `summary.json` (no strikes; the turning points, the
/// period and what the hammer's inertia and centre of mass predict for small swings) and
/// the drawings `drawing_release.svg` and `drawing_turn.svg` (the hammer on its flange at
/// the release and at the first turning point). There are no contacts, so no
/// `contacts.csv`.
pub fn write_pendulum_dir(
    dir: &Path,
    scenario: &Scenario,
    params: &ActionParams,
    swing: &crate::pendulum::Swing,
) -> Result<()> {
    start_run_dir(dir, scenario, params)?;
    let mut csv = String::from("time_s,hammer_q,hammer_v\n");
    for ((t, q), v) in swing.t.iter().zip(&swing.angle_rad).zip(&swing.rate_rad_s) {
        let _ = writeln!(csv, "{t},{q},{v}");
    }
    write_file(dir, "trajectory.csv", &csv)?;
    let shots = [
        ("release", swing.angle_rad.first().map(|&q| (0.0, q))),
        ("turn", swing.turns.first().map(|t| (t.time_s, t.angle_rad))),
    ];
    for (file, at) in shots {
        if let Some((t, q)) = at {
            let title = format!(
                "hammer swing, {file} at t = {:.1} ms, {:.1}° from hanging",
                t * 1e3,
                q.to_degrees()
            );
            let svg =
                crate::drawing::pendulum_svg(params, swing.hanging_shank_angle_rad + q, &title)?;
            write_file(dir, &format!("drawing_{file}.svg"), &svg)?;
        }
    }
    let events: Vec<serde_json::Value> = swing
        .turns
        .iter()
        .map(|t| serde_json::json!({"name": "turn", "time_s": t.time_s}))
        .collect();
    write_json(dir, "events.json", &serde_json::Value::from(events.clone()))?;
    let turns: Vec<serde_json::Value> = swing
        .turns
        .iter()
        .map(|t| serde_json::json!({"time_s": t.time_s, "angle_deg": t.angle_rad.to_degrees()}))
        .collect();
    // Two turns per period.
    let period = (swing.turns.len() >= 2).then(|| {
        let (first, last) = (
            swing.turns[0].time_s,
            swing.turns[swing.turns.len() - 1].time_s,
        );
        2.0 * (last - first) / (swing.turns.len() - 1) as f64
    });
    let m = params.hammer.mass_g * 1e-3;
    let small = 2.0
        * std::f64::consts::PI
        * (swing.inertia_pin_kg_m2 / (m * 9.81 * swing.com_distance_m)).sqrt();
    let summary = serde_json::json!({
        "model": "pendulum",
        "strikes": [],
        "let_off_time_s": null,
        "key_bottom_time_s": null,
        "check_time_s": null,
        "events": events,
        "pendulum": {
            "turns": turns,
            "period_s": num(period),
            "small_amplitude_period_s": small,
            "com_distance_m": swing.com_distance_m,
            "inertia_pin_kg_m2": swing.inertia_pin_kg_m2,
        },
    });
    write_json(dir, "summary.json", &summary)?;
    Ok(())
}
