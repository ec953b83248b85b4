//! Scenarios (what `piano simulate SCENARIO.toml` runs) and run directories (what it
//! writes: `run.json`, `trajectory.csv`, `events.json`, `summary.json`).

use std::fmt::Write as _;
use std::path::Path;

use serde::{Deserialize, Serialize};

use mbs_integrators::Solution;

use crate::action::ModelKind;
use crate::error::{InputKind, PianoError, Result};
use crate::params::ActionParams;
use crate::simulate::{Finger, Input, Prepared, Run, TouchStyle, simulate_observed};
use crate::toml_lines::from_toml;

/// The input of a scenario.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum InputSpec {
    /// `kind = "force"`: a force on the key front.
    Force(ForceSpec),
    /// `kind = "mass_drop"`: a mass released on the key front.
    MassDrop(MassDropSpec),
    /// `kind = "pendulum"`: the hammer alone swinging on its flange.
    Pendulum(PendulumSpec),
    /// `kind = "touch"`: a finger, pressed or struck.
    Touch(TouchSpec),
    /// `kind = "motion"`: a prescribed key-front depth.
    Motion(MotionSpec),
}

/// A force on the key front: `force_n` (N) from t = 0, reached after `ramp_s` if given
/// (a linear ramp), released at `release_s` if given; or a table
/// `points = [[time_s, force_n], ...]`, piecewise linear.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForceSpec {
    /// Force (N).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_n: Option<f64>,
    /// Rise time of a ramp (s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp_s: Option<f64>,
    /// Release time (s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub release_s: Option<f64>,
    /// `[time_s, force_n]` points, instead of `force_n`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<[f64; 2]>>,
}

/// A mass released on the key front from `height_m` (0: placed on it).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MassDropSpec {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Drop height (m).
    pub height_m: f64,
}

/// The hammer alone on its flange released from `release_angle_deg` off hanging (the
/// pendulum or swing test); `model` is not used.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PendulumSpec {
    /// Release angle from the hanging position (degrees).
    pub release_angle_deg: f64,
}

/// A finger touch: `style = "pressed"` with `peak_force_n`, or `style = "struck"` with
/// `finger_speed_m_s`; the finger's `finger_mass_g`, `rise_s` and `arm_damping_n_s_m`
/// default to [`Finger::default`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TouchSpec {
    /// `"pressed"` or `"struck"`.
    pub style: TouchStyleName,
    /// Peak force of a pressed touch (N).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub peak_force_n: Option<f64>,
    /// Arrival speed of a struck finger (m/s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub finger_speed_m_s: Option<f64>,
    /// Effective finger mass (g).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub finger_mass_g: Option<f64>,
    /// Rise time of a pressed touch's force (s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rise_s: Option<f64>,
    /// Arm coupling of a struck touch (N·s/m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_damping_n_s_m: Option<f64>,
}

/// Prescribed key-front depth below rest, `points = [[time_s, depth_mm], ...]`,
/// piecewise linear, or read from `csv = "FILE"` (two columns, time_s and depth_mm, an
/// optional header line; the path relative to the scenario file).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// `[time_s, depth_mm]` points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<[f64; 2]>>,
    /// A CSV file of the points, instead of `points`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub csv: Option<String>,
}

/// The `[input]` table of a scenario file as the spec of its `kind`; an error names the
/// field inside it (`input.points[1][1]`).
fn input_from_table(mut table: toml::Table) -> Result<InputSpec> {
    const KINDS: &str = "force, mass_drop, pendulum, touch or motion";
    let kind = match table.remove("kind") {
        Some(toml::Value::String(k)) => k,
        Some(other) => {
            return Err(PianoError::scenario(
                "input.kind",
                format!("must be a string ({KINDS}), got {other}"),
            ));
        }
        None => {
            return Err(PianoError::scenario(
                "input.kind",
                format!("missing ({KINDS})"),
            ));
        }
    };
    fn read<T: serde::de::DeserializeOwned>(table: toml::Table) -> Result<T> {
        serde_path_to_error::deserialize(toml::Value::Table(table)).map_err(|e| {
            let message = e.inner().message().trim().to_string();
            let mut field = match e.path().to_string() {
                p if p == "." => "input".to_string(),
                p => format!("input.{p}"),
            };
            // An unknown field is reported at its table: name the field itself.
            if let Some(name) = message
                .strip_prefix("unknown field `")
                .and_then(|rest| rest.split('`').next())
                && !field.ends_with(&format!(".{name}"))
            {
                field = format!("{field}.{name}");
            }
            PianoError::scenario(field, message)
        })
    }
    Ok(match kind.as_str() {
        "force" => InputSpec::Force(read(table)?),
        "mass_drop" => InputSpec::MassDrop(read(table)?),
        "pendulum" => InputSpec::Pendulum(read(table)?),
        "touch" => InputSpec::Touch(read(table)?),
        "motion" => InputSpec::Motion(read(table)?),
        other => {
            return Err(PianoError::scenario(
                "input.kind",
                format!("unknown kind '{other}' ({KINDS})"),
            ));
        }
    })
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
            InputSpec::Force(ForceSpec {
                force_n,
                ramp_s,
                release_s,
                points,
            }) => force_input(*force_n, *ramp_s, *release_s, points.as_deref())?,
            &InputSpec::MassDrop(MassDropSpec { mass_kg, height_m }) => {
                Input::MassDrop { mass_kg, height_m }
            }
            InputSpec::Pendulum(PendulumSpec { .. }) => {
                return Err(PianoError::scenario(
                    "input.kind",
                    "a pendulum scenario has no keystroke: run it with `swing` and \
                              `write_pendulum_dir`",
                ));
            }
            InputSpec::Motion(MotionSpec { points, csv }) => match (points, csv) {
                // Both: the points were read from the csv by `load`.
                (Some(points), _) => Input::Motion {
                    points: points.iter().map(|p| (p[0], p[1])).collect(),
                },
                (None, Some(file)) => {
                    return Err(PianoError::scenario(
                        "input.csv",
                        format!(
                            "'{file}' is read by Scenario::load, which knows where the \
                             scenario file is"
                        ),
                    ));
                }
                _ => {
                    return Err(PianoError::scenario(
                        "input.points",
                        "give either points or csv",
                    ));
                }
            },
            &InputSpec::Touch(TouchSpec {
                style,
                peak_force_n,
                finger_speed_m_s,
                finger_mass_g,
                rise_s,
                arm_damping_n_s_m,
            }) => {
                let missing = |field: &str, style: &str| {
                    PianoError::scenario(
                        format!("input.{field}"),
                        format!("a {style} touch needs {field}"),
                    )
                };
                let misplaced = |field: &str, style: &str| {
                    PianoError::scenario(
                        format!("input.{field}"),
                        format!("does not apply to a {style} touch"),
                    )
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
    let field = |name: &str, message: &str| PianoError::scenario(format!("input.{name}"), message);
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
    read_points_csv_lines(text, Path::new(file)).map(|(points, _)| points)
}

/// Reads `[time, value]` rows like [`read_points_csv`], with the line of each row. Times
/// must be finite, from 0 on and increasing, values finite; a row with more or fewer than
/// two cells is refused.
pub fn read_points_csv_lines(text: &str, file: &Path) -> Result<(Vec<[f64; 2]>, Vec<usize>)> {
    let bad = |line: usize, message: String| {
        PianoError::input(InputKind::PointsCsv, "", message)
            .in_file(file)
            .at_line((line > 0).then_some(line))
    };
    let mut points: Vec<[f64; 2]> = Vec::new();
    let mut lines = Vec::new();
    let mut first = true;
    // A spreadsheet's UTF-8 byte-order mark is not part of the first cell.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
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
        // A header names its columns: no cell of it is a number (a first row with one bad
        // cell is a typo in the data, not a header).
        let header = std::mem::take(&mut first) && numbers.iter().all(Option::is_none);
        match numbers.as_slice() {
            _ if header => {}
            [Some(t), Some(v)] => {
                let (t, v) = (*t, *v);
                if !(t.is_finite() && v.is_finite()) {
                    return Err(bad(i + 1, format!("not finite: '{line}'")));
                }
                if t < 0.0 {
                    return Err(bad(
                        i + 1,
                        format!("time {t} s is negative (times count from the run's start)"),
                    ));
                }
                if let Some(prev) = points.last()
                    && t <= prev[0]
                {
                    return Err(bad(
                        i + 1,
                        format!("times must increase: {t} s comes after {} s", prev[0]),
                    ));
                }
                points.push([t, v]);
                lines.push(i + 1);
            }
            [first, _] => {
                let cell = if first.is_none() { cells[0] } else { cells[1] };
                return Err(bad(
                    i + 1,
                    format!("'{cell}' is not a number (expected time, value): '{line}'"),
                ));
            }
            _ => {
                return Err(bad(
                    i + 1,
                    format!(
                        "expected two numbers (time, value), got {} cell{}: '{line}'",
                        cells.len(),
                        if cells.len() == 1 { "" } else { "s" }
                    ),
                ));
            }
        }
    }
    if points.is_empty() {
        return Err(bad(0, "no data rows".into()));
    }
    Ok((points, lines))
}

/// A scenario file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// `"simplified"`, `"single"` or `"double"`; empty when `mechanism` is given.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub model: String,
    /// A mechanism description (TOML or JSON, relative to the scenario's folder) to run in
    /// place of a grand `model` (see [`crate::mechanism_run`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mechanism: Option<String>,
    /// How long a mechanism settles at rest before the input starts (s; mechanism
    /// scenarios only, [`crate::mechanism_run::DEFAULT_SETTLE_S`] by default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub settle_s: Option<f64>,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Output grid spacing (s); 1 ms by default.
    #[serde(default = "default_output_step")]
    pub output_step_s: f64,
    /// What drives the key.
    pub input: InputSpec,
    /// The description `mechanism` names, as [`Scenario::load`] read it.
    #[serde(skip)]
    pub loaded_mechanism: Option<mbs_mechanism::Mechanism>,
}

fn default_output_step() -> f64 {
    1e-3
}

impl Scenario {
    /// Parses a scenario and checks its values; errors name the field and its line.
    pub fn from_toml_str(text: &str) -> Result<Self> {
        // Read in two stages: `input` is a table tagged by `kind`, and a tagged value loses
        // the path of what is wrong inside it; read as the kind's own type it keeps it.
        #[derive(Deserialize)]
        #[serde(deny_unknown_fields)]
        struct File {
            #[serde(default)]
            model: String,
            mechanism: Option<String>,
            settle_s: Option<f64>,
            duration_s: f64,
            #[serde(default = "default_output_step")]
            output_step_s: f64,
            input: toml::Table,
        }
        let file: File = from_toml(text, InputKind::Scenario)?;
        let scenario = Scenario {
            model: file.model,
            mechanism: file.mechanism,
            settle_s: file.settle_s,
            duration_s: file.duration_s,
            output_step_s: file.output_step_s,
            input: input_from_table(file.input).map_err(|e| e.locate_in_toml(text))?,
            loaded_mechanism: None,
        };
        scenario.check().map_err(|e| e.locate_in_toml(text))?;
        Ok(scenario)
    }

    /// Checks what can be checked before running: the model, the duration and output step,
    /// and the input's values (a motion's `csv` is checked when [`Scenario::load`] reads it).
    pub fn check(&self) -> Result<()> {
        if self.mechanism.is_some() {
            return self.check_mechanism_scenario();
        }
        if self.settle_s.is_some() {
            return Err(PianoError::scenario(
                "settle_s",
                "belongs to a mechanism scenario (a grand model settles on its own)",
            ));
        }
        // The pendulum uses the hammer alone, but the model must still be one of ours.
        self.model_kind()?;
        if let InputSpec::Pendulum(PendulumSpec { release_angle_deg }) = self.input {
            crate::pendulum::check_release_angle(release_angle_deg)?;
        }
        crate::simulate::check_duration(self.duration_s, self.output_step_s)?;
        match &self.input {
            InputSpec::Pendulum(PendulumSpec { .. }) => Ok(()),
            InputSpec::Motion(MotionSpec {
                points: None,
                csv: Some(_),
            }) => Ok(()),
            InputSpec::Motion(MotionSpec {
                points: Some(_),
                csv: Some(_),
            }) => Err(PianoError::scenario(
                "input.csv",
                "give either points or csv, not both",
            )),
            spec => spec.to_input()?.validate(),
        }
    }

    /// The checks of a scenario with `mechanism`: no `model`, a force input, a sensible
    /// settling time.
    fn check_mechanism_scenario(&self) -> Result<()> {
        if !self.model.is_empty() {
            return Err(PianoError::scenario(
                "model",
                "give either `model` (a grand action) or `mechanism` (a description file), \
                 not both",
            ));
        }
        if let Some(s) = self.settle_s
            && !(s.is_finite() && (0.0..=crate::simulate::MAX_DURATION_S).contains(&s))
        {
            return Err(PianoError::scenario(
                "settle_s",
                format!("must be 0-{} s, got {s}", crate::simulate::MAX_DURATION_S),
            ));
        }
        crate::simulate::check_duration(self.duration_s, self.output_step_s)?;
        match &self.input {
            InputSpec::Force(_) => self.input.to_input()?.validate(),
            _ => Err(PianoError::scenario(
                "input.kind",
                "a mechanism description is driven by a force (kind = \"force\"); mass \
                 drops, touches, key motions and the swing test belong to the grand models",
            )),
        }
    }

    /// Reads and parses the scenario file at `path`, and reads a motion's `csv` (relative to
    /// the scenario's folder) into its points. Errors name the file, the line and the field.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| PianoError::io(path, "read the scenario", e))?;
        Self::from_toml_str_in(&text, path.parent().unwrap_or(Path::new(".")), Some(path))
    }

    /// Parses a scenario as [`Scenario::load`] does a file's text: the files it names (a
    /// mechanism description, a motion's `csv`) are read relative to the folder `base`;
    /// errors name `file` when given.
    pub fn from_toml_str_in(text: &str, base: &Path, file: Option<&Path>) -> Result<Self> {
        let named = |e: PianoError| match file {
            Some(path) => e.in_file(path),
            None => e,
        };
        let mut scenario = Self::from_toml_str(text).map_err(named)?;
        if let Some(name) = &scenario.mechanism {
            let full = base.join(name);
            if !full.is_file() {
                return Err(named(PianoError::scenario(
                    "mechanism",
                    format!("cannot read the mechanism description {}", full.display()),
                ))
                .locate_in_toml(text));
            }
            scenario.loaded_mechanism = Some(mbs_mechanism::Mechanism::load(&full)?);
        }
        if let InputSpec::Motion(MotionSpec {
            points,
            csv: Some(name),
        }) = &mut scenario.input
        {
            let full = base.join(&*name);
            let csv_text = std::fs::read_to_string(&full).map_err(|e| {
                named(PianoError::scenario(
                    "input.csv",
                    format!("cannot read the key motion {}: {e}", full.display()),
                ))
                .locate_in_toml(text)
            })?;
            let (rows, lines) = read_points_csv_lines(&csv_text, &full)?;
            *points = Some(rows);
            // The points are now in the scenario (and its run.json); the file name stays as
            // a record of where they came from. A bad value is shown at its CSV line.
            scenario.input.to_input()?.validate().map_err(|e| {
                let row = e
                    .field()
                    .strip_prefix("input.points[")
                    .and_then(|r| r.split(']').next())
                    .and_then(|r| r.parse::<usize>().ok());
                match (row, e) {
                    (Some(row), PianoError::Input(mut bad)) => {
                        bad.kind = InputKind::PointsCsv;
                        bad.file = Some(full.clone());
                        bad.line = lines.get(row).copied();
                        bad.field = String::new();
                        PianoError::Input(bad)
                    }
                    (_, e) => named(e),
                }
            })?;
        }
        Ok(scenario)
    }

    /// A scenario running `mechanism` (recorded as read from the file `file`) driven by a
    /// force, checked: what a program that builds its own description runs.
    pub fn for_mechanism(
        file: &str,
        mechanism: mbs_mechanism::Mechanism,
        force: ForceSpec,
        duration_s: f64,
        output_step_s: f64,
    ) -> Result<Self> {
        mechanism.validate()?;
        let scenario = Scenario {
            model: String::new(),
            mechanism: Some(file.to_string()),
            settle_s: None,
            duration_s,
            output_step_s,
            input: InputSpec::Force(force),
            loaded_mechanism: Some(mechanism),
        };
        scenario.check()?;
        Ok(scenario)
    }

    /// Runs a scenario with a mechanism description (see [`crate::mechanism_run`]).
    pub fn run_mechanism(
        &self,
        params: &ActionParams,
        progress: &mut dyn FnMut(f64),
    ) -> Result<crate::mechanism_run::MechanismRun> {
        let mechanism = self.loaded_mechanism.as_ref().ok_or_else(|| {
            PianoError::scenario(
                "mechanism",
                "this scenario has no mechanism description loaded (Scenario::load reads it)",
            )
        })?;
        crate::mechanism_run::simulate_mechanism(
            mechanism,
            &self.input.to_input()?,
            &params.numerics,
            self.settle_s
                .unwrap_or(crate::mechanism_run::DEFAULT_SETTLE_S),
            self.duration_s,
            self.output_step_s,
            progress,
        )
    }

    /// The model kind named by `model`.
    pub fn model_kind(&self) -> Result<ModelKind> {
        if self.model.is_empty() && self.mechanism.is_some() {
            return Err(PianoError::scenario(
                "model",
                "this scenario runs a mechanism description, not a grand model",
            ));
        }
        ModelKind::ALL
            .into_iter()
            .find(|k| k.name() == self.model)
            .ok_or_else(|| {
                PianoError::scenario(
                    "model",
                    format!(
                        "unknown model '{}' (simplified, single or double)",
                        self.model
                    ),
                )
            })
    }

    /// Runs the scenario.
    pub fn run(&self, params: &ActionParams) -> Result<Run> {
        self.run_observed(params, &mut |_| {})
    }

    /// Runs the scenario, calling `progress` with the simulated time after every step.
    pub fn run_observed(
        &self,
        params: &ActionParams,
        progress: &mut dyn FnMut(f64),
    ) -> Result<Run> {
        let input = self.input.to_input()?;
        simulate_observed(
            params,
            self.model_kind()?,
            &input,
            self.duration_s,
            self.output_step_s,
            progress,
        )
    }
}

/// Writes `text` to `dir/name`; the error names the file.
fn write_file(dir: &Path, name: &str, text: &str) -> Result<()> {
    let path = dir.join(name);
    std::fs::write(&path, text).map_err(|e| PianoError::io(&path, "write", e))
}

/// Writes `value` as pretty JSON to `dir/name`.
fn write_json(dir: &Path, name: &str, value: &serde_json::Value) -> Result<()> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| PianoError::file(&dir.join(name), format!("cannot encode as JSON: {e}")))?;
    write_file(dir, name, &text)
}

/// The run-directory file with the force elements' internal states (time, then one column
/// per state, `state_<index in the state vector>`), written when the model has any.
pub const INTERNAL_STATES_CSV: &str = "internal_states.csv";

/// Whether `name` is a file that `piano` writes into a run directory (by `simulate`,
/// `report` or `plot`).
pub fn is_run_output(name: &str) -> bool {
    matches!(
        name,
        "run.json"
            | "trajectory.csv"
            | INTERNAL_STATES_CSV
            | "contacts.csv"
            | "poses.csv"
            | "series.csv"
            | "scene.json"
            | "events.json"
            | "summary.json"
            | "report.html"
            | "figure.svg"
            | "figure.png"
    ) || (name.starts_with("drawing_") && name.ends_with(".svg"))
}

/// The files of an earlier run in `dir` (empty when `dir` does not exist).
fn run_outputs_in(dir: &Path) -> Result<Vec<std::path::PathBuf>> {
    if !dir.exists() {
        return Ok(Vec::new());
    }
    if !dir.is_dir() {
        return Err(PianoError::file(
            dir,
            "is a file, not a folder: choose another --out",
        ));
    }
    let entries = std::fs::read_dir(dir).map_err(|e| PianoError::io(dir, "list the folder", e))?;
    let mut found = Vec::new();
    for entry in entries.flatten() {
        if entry.file_name().to_str().is_some_and(is_run_output) {
            found.push(entry.path());
        }
    }
    found.sort();
    Ok(found)
}

/// Whether `dir` holds a `run.json` written by `piano` (a run directory).
fn holds_piano_run(dir: &Path) -> bool {
    std::fs::read_to_string(dir.join("run.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .is_some_and(|v| v.get("scenario").is_some() && v.get("version").is_some())
}

/// Checks that a run may be written to `dir` without touching anything it should not: a
/// missing or empty folder is fine, and so is one holding only files of yours; a run
/// directory of an earlier run only when `replace` is set; a folder holding files named
/// like a run's but no piano `run.json` never (they are not ours to replace).
pub fn check_run_dir(dir: &Path, replace: bool) -> Result<()> {
    let old = run_outputs_in(dir)?;
    if old.is_empty() {
        return Ok(());
    }
    let names: Vec<String> = old
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    if !holds_piano_run(dir) {
        return Err(PianoError::file(
            dir,
            format!(
                "holds files named like a run's ({}) but is not a run directory (no run.json \
                 written by piano): choose another --out",
                names.join(", ")
            ),
        ));
    }
    if !replace {
        return Err(PianoError::file(
            dir,
            format!(
                "holds an earlier run ({}); choose another --out, or pass --force to replace \
                 it",
                names.join(", ")
            ),
        ));
    }
    Ok(())
}

/// Makes `dir` ready for a new run (see [`check_run_dir`]): created if missing; with
/// `replace`, the files of an earlier run (and only those: `measured.csv` and anything else
/// of yours stays) are removed first, so old and new files are never mixed.
pub fn prepare_run_dir(dir: &Path, replace: bool) -> Result<()> {
    check_run_dir(dir, replace)?;
    for path in run_outputs_in(dir)? {
        std::fs::remove_file(&path).map_err(|e| PianoError::io(&path, "remove", e))?;
    }
    std::fs::create_dir_all(dir).map_err(|e| PianoError::io(dir, "create the folder", e))
}

/// Creates the run directory and writes `run.json` (scenario, parameters, version); a
/// folder holding an earlier run is refused (see [`prepare_run_dir`]).
fn start_run_dir(dir: &Path, scenario: &Scenario, params: &ActionParams) -> Result<()> {
    start_run_dir_with(dir, scenario, params, serde_json::json!({}))
}

/// [`start_run_dir`] with more fields in `run.json` (an object's fields).
fn start_run_dir_with(
    dir: &Path,
    scenario: &Scenario,
    params: &ActionParams,
    more: serde_json::Value,
) -> Result<()> {
    prepare_run_dir(dir, false)?;
    let mut run_json = serde_json::json!({
        "scenario": serde_json::to_value(scenario).unwrap_or_default(),
        "params": serde_json::to_value(params).unwrap_or_default(),
        "version": env!("CARGO_PKG_VERSION"),
    });
    if let (Some(obj), Some(more)) = (run_json.as_object_mut(), more.as_object()) {
        obj.extend(more.clone());
    }
    write_json(dir, "run.json", &run_json)
}

fn num(x: Option<f64>) -> serde_json::Value {
    x.map_or(serde_json::Value::Null, serde_json::Value::from)
}

/// Writes the run directory `dir` (created if needed): `run.json` (scenario, parameters,
/// the expanded description and the initial state), `trajectory.csv` (time, coordinates,
/// velocities on the output grid), `contacts.csv` (gaps, normal forces, points, normals and
/// whether pressed, on the same grid), `poses.csv`, `series.csv` and `scene.json` (what the
/// report replays without rebuilding the action), `events.json`,
/// `summary.json` (strikes, key start, travel, let-off, key-bottom and check times,
/// events) and the drawings `drawing_rest.svg`, `drawing_let_off.svg`,
/// `drawing_string_contact.svg` and `drawing_check.svg` (those that happen).
pub fn write_run_dir(
    dir: &Path,
    scenario: &Scenario,
    params: &ActionParams,
    run: &Run,
) -> Result<()> {
    // The action as the run had it (with a presser, if any), for the names, the contacts
    // and the drawings; run.json keeps its expanded description and the initial state.
    let prepared = crate::simulate::prepare(params, run.kind, &scenario.input.to_input()?)?;
    start_run_dir_with(
        dir,
        scenario,
        params,
        serde_json::json!({
            "mechanism": serde_json::to_value(&prepared.action.mechanism).unwrap_or_default(),
            "initial_state": prepared.x0,
        }),
    )?;
    let sol = &run.solution;
    let extra = (run.key_drive_force_n.len() == sol.len())
        .then_some(("key_drive_force_n", run.key_drive_force_n.as_slice()));
    write_trajectory(
        dir,
        prepared.action.system.model().coordinate_names(),
        prepared.action.system.state_len(),
        sol,
        extra,
    )?;
    write_contacts_and_drawings(dir, &prepared, run)?;

    let events: Vec<serde_json::Value> = run
        .events
        .iter()
        .map(|e| serde_json::json!({"name": e.name, "time_s": e.time_s}))
        .collect();
    write_json(dir, "events.json", &serde_json::Value::from(events))?;
    let summary = run_summary(run);
    write_json(dir, "summary.json", &summary)?;
    Ok(())
}

/// The summary of a grand run, as `summary.json` has it: the model, the strikes (time,
/// hammer speed, contact duration, rebound speed, pulses), the key-start, travel, let-off,
/// key-bottom and check times, the key bottom less the string contact, and the events.
pub fn run_summary(run: &Run) -> serde_json::Value {
    let events: Vec<serde_json::Value> = run
        .events
        .iter()
        .map(|e| serde_json::json!({"name": e.name, "time_s": e.time_s}))
        .collect();
    let strikes: Vec<serde_json::Value> = run
        .strikes
        .iter()
        .map(|s| {
            serde_json::json!({
                "time_s": s.time_s,
                "hammer_velocity_m_s": s.hammer_velocity_m_s,
                "contact_duration_s": num(s.contact_duration_s),
                "rebound_velocity_m_s": num(s.rebound_velocity_m_s),
                "pulses": s.pulses,
            })
        })
        .collect();
    serde_json::json!({
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
    })
}

/// The summary of a swing test, as its `summary.json` has it: the turning points, the
/// period measured and the small-amplitude one, the centre of mass's distance from the pin
/// and the inertia about it (`events` lists the turns).
pub fn pendulum_summary(
    params: &ActionParams,
    swing: &crate::pendulum::Swing,
) -> serde_json::Value {
    let events: Vec<serde_json::Value> = swing
        .turns
        .iter()
        .map(|t| serde_json::json!({"name": "turn", "time_s": t.time_s}))
        .collect();
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
        * (swing.inertia_pin_kg_m2 / (m * crate::params::GRAVITY_M_S2 * swing.com_distance_m))
            .sqrt();
    serde_json::json!({
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
    })
}

/// Writes `trajectory.csv` (time, then `<name>_q` and `<name>_v` for every coordinate in
/// `names`, then the `extra` column if given) and, when the state holds more than the
/// coordinates and velocities (`state_len`), [`INTERNAL_STATES_CSV`] with the force
/// elements' internal states (the string's modal amplitudes) on the same grid.
pub fn write_trajectory(
    dir: &Path,
    names: &[String],
    state_len: usize,
    sol: &Solution,
    extra: Option<(&str, &[f64])>,
) -> Result<()> {
    let nv = names.len();
    let mut csv = String::from("time_s");
    for n in names {
        let _ = write!(csv, ",{n}_q");
    }
    for n in names {
        let _ = write!(csv, ",{n}_v");
    }
    if let Some((name, _)) = extra {
        let _ = write!(csv, ",{name}");
    }
    csv.push('\n');
    for i in 0..sol.len() {
        let _ = write!(csv, "{}", sol.t[i]);
        for v in &sol.state(i)[..2 * nv] {
            let _ = write!(csv, ",{v}");
        }
        if let Some((_, values)) = extra {
            let _ = write!(csv, ",{}", values[i]);
        }
        csv.push('\n');
    }
    write_file(dir, "trajectory.csv", &csv)?;
    let internal = state_len.saturating_sub(2 * nv);
    if internal > 0 {
        let mut csv = String::from("time_s");
        for k in 0..internal {
            let _ = write!(csv, ",state_{}", 2 * nv + k);
        }
        csv.push('\n');
        for i in 0..sol.len() {
            let _ = write!(csv, "{}", sol.t[i]);
            for v in &sol.state(i)[2 * nv..] {
                let _ = write!(csv, ",{v}");
            }
            csv.push('\n');
        }
        write_file(dir, INTERNAL_STATES_CSV, &csv)?;
    }
    Ok(())
}

/// A contact's numbers as `contacts.csv` of a grand run has them, in its column order: the
/// gap (mm), the normal force (N), the contact point (mm) and the normal.
pub fn contact_columns(o: &mbs_contact::ContactOutput) -> [f64; 6] {
    [
        o.gap * 1e3,
        o.normal_force,
        o.point[0] * 1e3,
        o.point[1] * 1e3,
        o.normal[0],
        o.normal[1],
    ]
}

/// Writes `contacts.csv` (every contact's gap and normal force on the output grid) and the
/// drawings of the action at rest, at let-off, at string contact and at the check (those
/// that happen), with the pressed contacts marked.
fn write_contacts_and_drawings(dir: &Path, prepared: &Prepared, run: &Run) -> Result<()> {
    let action = &prepared.action;
    let sol = &run.solution;
    let names: Vec<&str> = action.contacts.keys().map(String::as_str).collect();
    let mut csv = String::from("time_s");
    for n in &names {
        let _ = write!(
            csv,
            ",{n}_gap_mm,{n}_force_n,{n}_px_mm,{n}_py_mm,{n}_nx,{n}_ny,{n}_active"
        );
    }
    csv.push('\n');
    for i in 0..sol.len() {
        let (t, x) = (sol.t[i], sol.state(i));
        let _ = write!(csv, "{t}");
        for n in &names {
            let o = action.contact_output(n, t, x)?;
            let [gap, force, px, py, nx, ny] = contact_columns(&o);
            let _ = write!(
                csv,
                ",{gap},{force},{px},{py},{nx},{ny},{}",
                u8::from(o.active)
            );
        }
        csv.push('\n');
    }
    write_file(dir, "contacts.csv", &csv)?;
    crate::report::write_replay_files(dir, prepared, run)?;

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
    let summary = pendulum_summary(params, swing);
    write_json(dir, "events.json", &summary["events"])?;
    write_json(dir, "summary.json", &summary)?;
    Ok(())
}
