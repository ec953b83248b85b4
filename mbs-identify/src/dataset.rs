//! Tracked-marker datasets (schema version 1).
//!
//! `dataset.json`: `schema_version` (1), `experiment`, `description`, `fps`, `exposure_s`,
//! `markers` (`{"name", "body", "local_m": [x, y], "sigma_m"}`: a point fixed on a body, in
//! that body's frame), optionally `drive` (the marker whose measured motion drives the
//! model, e.g. `"key_front"` in a `key_drive` experiment; the others are compared) and
//! `runs` (`{"id", "file", "role": "fit" | "heldout", "conditions": {...}}`). Each run's CSV: `time_s`, then `<marker>_x_m` and `<marker>_y_m` for every
//! marker (world frame, m); an empty cell or `NaN` is a lost frame.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// The dataset schema this crate reads.
pub const SCHEMA_VERSION: u64 = 1;

/// What is wrong with a dataset: the file, the line (1-based, when it is about one) and
/// the field (a JSON path such as `markers[1].sigma_m`, or a CSV column).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{}{}{}: {message}", file.display(), line.map_or(String::new(), |l| format!(", line {l}")), if field.is_empty() { String::new() } else { format!(", field `{field}`") })]
pub struct DatasetError {
    /// The file.
    pub file: PathBuf,
    /// The line, when the error is about one.
    pub line: Option<usize>,
    /// The field or column, when the error is about one (empty otherwise).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl DatasetError {
    fn new(file: &Path, field: impl Into<String>, message: impl Into<String>) -> Self {
        DatasetError {
            file: file.to_path_buf(),
            line: None,
            field: field.into(),
            message: message.into(),
        }
    }

    fn at(mut self, line: usize) -> Self {
        self.line = Some(line);
        self
    }
}

/// How a run is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Role {
    /// Fitted.
    Fit,
    /// Kept out of the fit, to test the result.
    Heldout,
}

/// A tracked point fixed on a body.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct MarkerSpec {
    /// Its name: the CSV columns are `<name>_x_m` and `<name>_y_m`.
    pub name: String,
    /// The body it is fixed on (a body of the experiment's model).
    pub body: String,
    /// Its place in the body's frame (m).
    pub local_m: [f64; 2],
    /// The tracking noise, one standard deviation per coordinate (m).
    pub sigma_m: f64,
}

/// One recorded run.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RunSpec {
    /// Its name, unique in the dataset.
    pub id: String,
    /// Its CSV, relative to the dataset directory.
    pub file: String,
    /// Fitted or held out.
    pub role: Role,
    /// The experiment's conditions (`{"release_angle_deg": -35}` for a pendulum).
    #[serde(default)]
    pub conditions: serde_json::Map<String, serde_json::Value>,
}

/// A dataset: its directory and what `dataset.json` says.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Dataset {
    /// The directory it was read from.
    #[serde(skip)]
    pub dir: PathBuf,
    /// Always [`SCHEMA_VERSION`].
    pub schema_version: u64,
    /// Which experiment (`"pendulum"`).
    pub experiment: String,
    /// Free text.
    #[serde(default)]
    pub description: String,
    /// Frames per second.
    pub fps: f64,
    /// Exposure of a frame (s): a frame at `t` averages the motion over
    /// `[t + τ, t + τ + exposure_s]`, τ the camera's unknown sync offset.
    pub exposure_s: f64,
    /// The tracked markers.
    pub markers: Vec<MarkerSpec>,
    /// The marker whose measured motion drives the model (the others are compared), for
    /// an experiment driven by a measured motion (`key_drive`); none for a free motion (a
    /// pendulum).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive: Option<String>,
    /// The runs.
    pub runs: Vec<RunSpec>,
}

/// The frames of one run: times and, per marker, the world position (m) or `None` for a
/// lost frame.
#[derive(Clone, Debug, PartialEq)]
pub struct RunData {
    /// Frame times (s), strictly increasing.
    pub time_s: Vec<f64>,
    /// Per marker (in the order of [`Dataset::markers`]), per frame.
    pub positions: Vec<Vec<Option<[f64; 2]>>>,
}

impl RunData {
    /// Frames where marker `m` was seen.
    pub fn seen(&self, m: usize) -> usize {
        self.positions
            .get(m)
            .map_or(0, |p| p.iter().filter(|x| x.is_some()).count())
    }
}

/// The line (1-based) of byte `offset` in `text`.
fn line_at(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// The line of field `path` in the JSON `text` (`fps`, `markers[1].sigma_m`): the line of
/// the `(i + 1)`-th `"key"` after the array's own key for an element's field, of the first
/// `"key"` otherwise (the files are small and their keys plain).
fn line_of_field(text: &str, path: &str) -> Option<usize> {
    let (array, rest) = match path.split_once('[') {
        Some((array, rest)) => (Some(array), rest),
        None => (None, path),
    };
    let key = path.rsplit(['.', ']']).next().filter(|k| !k.is_empty())?;
    let quoted = |k: &str| format!("\"{k}\"");
    let Some(array) = array else {
        return text.find(&quoted(key)).map(|i| line_at(text, i));
    };
    let index: usize = rest.split(']').next()?.parse().ok()?;
    let start = text.find(&quoted(array))?;
    let mut at = start;
    for _ in 0..=index {
        at += text[at..].find(&quoted(key))? + 1;
    }
    Some(line_at(text, at - 1))
}

impl Dataset {
    /// Reads and checks `dir/dataset.json` (the runs' files must exist; they are read by
    /// [`Dataset::read_run`]).
    pub fn load(dir: &Path) -> Result<Dataset, DatasetError> {
        let file = dir.join("dataset.json");
        let text = std::fs::read_to_string(&file)
            .map_err(|e| DatasetError::new(&file, "", format!("cannot read: {e}")))?;
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text).to_string();
        let mut dataset = parse_dataset(&text, &file)?;
        dataset.dir = dir.to_path_buf();
        dataset.check(&file, &text)?;
        Ok(dataset)
    }

    fn check(&self, file: &Path, text: &str) -> Result<(), DatasetError> {
        let err = |field: &str, message: String| {
            let e = DatasetError::new(file, field, message);
            match line_of_field(text, field) {
                Some(l) => e.at(l),
                None => e,
            }
        };
        if self.schema_version != SCHEMA_VERSION {
            return Err(err(
                "schema_version",
                format!(
                    "this version reads schema {SCHEMA_VERSION}, the file is schema {}",
                    self.schema_version
                ),
            ));
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(err("fps", format!("must be positive, got {}", self.fps)));
        }
        if !(self.exposure_s.is_finite() && self.exposure_s >= 0.0)
            || self.exposure_s > 1.0 / self.fps
        {
            return Err(err(
                "exposure_s",
                format!(
                    "must lie in [0, 1/fps = {:.3e}] s, got {}",
                    1.0 / self.fps,
                    self.exposure_s
                ),
            ));
        }
        if self.markers.is_empty() {
            return Err(err("markers", "lists no marker".into()));
        }
        let mut names = BTreeSet::new();
        for (i, m) in self.markers.iter().enumerate() {
            let field = |f: &str| format!("markers[{i}].{f}");
            let valid_name = !m.name.is_empty()
                && m.name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-');
            if !valid_name {
                return Err(err(
                    &field("name"),
                    format!("'{}': use letters, digits, _ or -", m.name),
                ));
            }
            if !names.insert(m.name.as_str()) {
                return Err(err(&field("name"), format!("'{}' is listed twice", m.name)));
            }
            if m.local_m.iter().any(|v| !v.is_finite()) {
                return Err(err(&field("local_m"), "must be finite".into()));
            }
            if !(m.sigma_m.is_finite() && m.sigma_m > 0.0) {
                return Err(err(
                    &field("sigma_m"),
                    format!("must be positive, got {}", m.sigma_m),
                ));
            }
        }
        if let Some(drive) = &self.drive
            && !self.markers.iter().any(|m| &m.name == drive)
        {
            return Err(err(
                "drive",
                format!(
                    "'{drive}' is not one of the markers ({})",
                    self.markers
                        .iter()
                        .map(|m| m.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ));
        }
        if self.runs.is_empty() {
            return Err(err("runs", "lists no run".into()));
        }
        let mut ids = BTreeSet::new();
        for (i, r) in self.runs.iter().enumerate() {
            if !ids.insert(r.id.as_str()) {
                return Err(err(
                    &format!("runs[{i}].id"),
                    format!("'{}' is listed twice", r.id),
                ));
            }
            let path = self.dir.join(&r.file);
            if !path.is_file() {
                return Err(err(
                    &format!("runs[{i}].file"),
                    format!("{} does not exist", path.display()),
                ));
            }
        }
        Ok(())
    }

    /// Checks that every marker's body is one of `bodies` (the experiment's model).
    pub fn check_bodies(&self, bodies: &[&str]) -> Result<(), DatasetError> {
        let file = self.dir.join("dataset.json");
        for (i, m) in self.markers.iter().enumerate() {
            if !bodies.contains(&m.body.as_str()) {
                return Err(DatasetError::new(
                    &file,
                    format!("markers[{i}].body"),
                    format!(
                        "no body '{}' in the {} model (its bodies: {})",
                        m.body,
                        self.experiment,
                        bodies.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Writes the dataset into `dir` (created if missing): `dataset.json` and, for each run
    /// with its frames in `runs` (same order as [`Dataset::runs`]), its CSV, lost frames as
    /// empty cells. Files already in `dir` are replaced: the caller decides whether that is
    /// allowed.
    pub fn write(&self, dir: &Path, runs: &[RunData]) -> std::io::Result<()> {
        use std::fmt::Write as _;
        if runs.len() != self.runs.len() {
            return Err(std::io::Error::other(format!(
                "{} runs of frames for {} runs listed",
                runs.len(),
                self.runs.len()
            )));
        }
        std::fs::create_dir_all(dir)?;
        let json = serde_json::to_string_pretty(self).map_err(std::io::Error::other)?;
        std::fs::write(dir.join("dataset.json"), json + "\n")?;
        for (spec, data) in self.runs.iter().zip(runs) {
            let mut csv = String::from("time_s");
            for m in &self.markers {
                let _ = write!(csv, ",{0}_x_m,{0}_y_m", m.name);
            }
            csv.push('\n');
            for (k, t) in data.time_s.iter().enumerate() {
                let _ = write!(csv, "{t:.7}");
                for track in &data.positions {
                    match track.get(k).copied().flatten() {
                        Some([x, y]) => {
                            let _ = write!(csv, ",{x:.7},{y:.7}");
                        }
                        None => csv.push_str(",,"),
                    }
                }
                csv.push('\n');
            }
            std::fs::write(dir.join(&spec.file), csv)?;
        }
        Ok(())
    }

    /// Reads the frames of `run`. Errors name the file, the line and the column: a missing
    /// marker column, a cell that is not a number, time not increasing, every frame lost.
    pub fn read_run(&self, run: &RunSpec) -> Result<RunData, DatasetError> {
        let file = self.dir.join(&run.file);
        let text = std::fs::read_to_string(&file)
            .map_err(|e| DatasetError::new(&file, "", format!("cannot read: {e}")))?;
        // A spreadsheet's "CSV UTF-8" starts with a byte-order mark.
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let (_, header) = lines
            .next()
            .ok_or_else(|| DatasetError::new(&file, "", "is empty"))?;
        let header: Vec<&str> = header.split(',').map(str::trim).collect();
        let column = |name: &str| {
            header.iter().position(|h| *h == name).ok_or_else(|| {
                DatasetError::new(&file, name, "column missing from the header").at(1)
            })
        };
        let time_col = column("time_s")?;
        let mut cols = Vec::with_capacity(self.markers.len());
        for m in &self.markers {
            cols.push((
                column(&format!("{}_x_m", m.name))?,
                column(&format!("{}_y_m", m.name))?,
            ));
        }
        let mut out = RunData {
            time_s: Vec::new(),
            positions: vec![Vec::new(); self.markers.len()],
        };
        for (i, line) in lines {
            let line_no = i + 1;
            let cells: Vec<&str> = line.split(',').map(str::trim).collect();
            if cells.len() != header.len() {
                return Err(DatasetError::new(
                    &file,
                    "",
                    format!(
                        "{} cells where the header has {}",
                        cells.len(),
                        header.len()
                    ),
                )
                .at(line_no));
            }
            let number = |col: usize| -> Result<Option<f64>, DatasetError> {
                let cell = cells[col];
                if cell.is_empty() || cell.eq_ignore_ascii_case("nan") {
                    return Ok(None);
                }
                match cell.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(Some(v)),
                    _ => Err(DatasetError::new(
                        &file,
                        header[col],
                        format!("'{cell}' is not a number"),
                    )
                    .at(line_no)),
                }
            };
            let t = number(time_col)?.ok_or_else(|| {
                DatasetError::new(&file, "time_s", "a frame needs its time").at(line_no)
            })?;
            if let Some(&prev) = out.time_s.last()
                && t <= prev
            {
                return Err(DatasetError::new(
                    &file,
                    "time_s",
                    format!("{t} s does not follow {prev} s: time must increase"),
                )
                .at(line_no));
            }
            out.time_s.push(t);
            for (m, &(cx, cy)) in cols.iter().enumerate() {
                let p = match (number(cx)?, number(cy)?) {
                    (Some(x), Some(y)) => Some([x, y]),
                    _ => None,
                };
                out.positions[m].push(p);
            }
        }
        if out.time_s.is_empty() {
            return Err(DatasetError::new(&file, "", "has no frames"));
        }
        for (m, marker) in self.markers.iter().enumerate() {
            if out.seen(m) == 0 {
                return Err(DatasetError::new(
                    &file,
                    format!("{}_x_m", marker.name),
                    format!("marker '{}' is lost in every frame", marker.name),
                ));
            }
        }
        Ok(out)
    }
}

/// Deserializes `dataset.json`, naming the field path and line of a value that does not
/// fit.
fn parse_dataset(text: &str, file: &Path) -> Result<Dataset, DatasetError> {
    let mut de = serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let field = match e.path().to_string() {
            p if p == "." || p == "?" => String::new(),
            p => p,
        };
        let inner = e.inner();
        let message = inner.to_string();
        // serde_json's message ends in "at line L column C": the line goes in its place.
        let message = message
            .rsplit_once(" at line ")
            .map_or(message.as_str(), |(m, _)| m)
            .to_string();
        DatasetError {
            file: file.to_path_buf(),
            line: (inner.line() > 0).then_some(inner.line()),
            field,
            message,
        }
    })
}
