//! What `piano synth` and `piano diagnose` do on disk: where they write, what they refuse
//! to overwrite, and the corrected parameter file.

use std::path::{Path, PathBuf};

use mbs_identify::Dataset;

use super::diagnose::{DiagnoseOptions, Diagnosis, Progress, diagnose};
use super::effects::{PENDULUM_EFFECTS, library_ids};
use super::synth::{SynthOptions, synthesize};
use crate::error::{PianoError, Result};
use crate::params::ActionParams;

/// Writes a synthetic dataset into `out` and its truth to `truth` (a `.json` file outside
/// the dataset). Refuses to replace an existing dataset or truth file without `force`.
pub fn synth_to_disk(
    params: &ActionParams,
    options: &SynthOptions,
    out: &Path,
    truth: &Path,
    force: bool,
) -> Result<()> {
    check_synth_paths(out, truth, force)?;
    let (dataset, runs, truth_record) = synthesize(params, options)?;
    write_synth(out, truth, &dataset, &runs, &truth_record)
}

/// Writes a synthetic key-drive dataset (issue 15) into `out` and its truth to `truth`,
/// refusing as [`synth_to_disk`] does.
pub fn synth_key_drive_to_disk(
    params: &ActionParams,
    options: &super::key_drive::KeyDriveOptions,
    out: &Path,
    truth: &Path,
    force: bool,
) -> Result<()> {
    check_synth_paths(out, truth, force)?;
    let (dataset, runs, truth_record) = super::key_drive::synthesize(params, options)?;
    write_synth(out, truth, &dataset, &runs, &truth_record)
}

/// What `piano synth` is asked for: the experiment and its options, as the command line
/// takes them.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthRequest {
    /// `pendulum` (the swing test) or `key_drive` (a mass released on the key).
    pub experiment: String,
    /// The hidden effect, `ID[:name=value,...]`; None for none.
    pub effect: Option<String>,
    /// The seed: the same seed gives the same dataset.
    pub seed: u64,
    /// Pendulum: release angles (° above horizontal); the first run is fitted.
    pub releases_deg: Vec<f64>,
    /// Key drive: release heights of the mass above the key (mm); the first is fitted.
    pub heights_mm: Vec<f64>,
    /// Key drive: the markers tracked (empty: all).
    pub markers: Option<Vec<String>>,
    /// Key drive: the mass (kg).
    pub mass_kg: f64,
    /// Length of each run (s); None: 4 for a pendulum, 0.3 for a key drive.
    pub duration_s: Option<f64>,
}

impl Default for SynthRequest {
    fn default() -> Self {
        SynthRequest {
            experiment: "pendulum".into(),
            effect: None,
            seed: 0,
            releases_deg: vec![0.0, -35.0],
            heights_mm: vec![0.0, 5.0],
            markers: None,
            mass_kg: 1.0,
            duration_s: None,
        }
    }
}

/// What [`synth_request_to_disk`] wrote.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthDone {
    /// Runs written.
    pub runs: usize,
    /// Length of each (s).
    pub duration_s: f64,
    /// The camera's frame rate.
    pub fps: f64,
}

/// `piano synth`: writes the dataset asked for into `out` and its truth to `truth`,
/// refusing to replace either without `force`; options that do not apply to the experiment
/// are refused, naming the option.
pub fn synth_request_to_disk(
    params: &ActionParams,
    request: &SynthRequest,
    out: &Path,
    truth: &Path,
    force: bool,
) -> Result<SynthDone> {
    match request.experiment.as_str() {
        "pendulum" => {
            if request.markers.is_some() {
                return Err(PianoError::option(
                    "--markers",
                    "the key drive's; a pendulum dataset tracks the hammer's head and shank",
                ));
            }
            let options = SynthOptions {
                effect: request
                    .effect
                    .as_deref()
                    .map(super::synth::parse_effect)
                    .transpose()?,
                seed: request.seed,
                releases_deg: request.releases_deg.clone(),
                duration_s: request.duration_s.unwrap_or(4.0),
                ..SynthOptions::default()
            };
            synth_to_disk(params, &options, out, truth, force)?;
            Ok(SynthDone {
                runs: options.releases_deg.len(),
                duration_s: options.duration_s,
                fps: options.camera.fps,
            })
        }
        super::key_drive::EXPERIMENT => {
            let effect = request
                .effect
                .as_deref()
                .map(super::action_effects::ActionEffect::parse)
                .transpose()?;
            let options = super::key_drive::KeyDriveOptions {
                seed: request.seed,
                mass_kg: request.mass_kg,
                release_heights_m: request.heights_mm.iter().map(|h| h * 1e-3).collect(),
                duration_s: request.duration_s.unwrap_or(0.3),
                effect,
                markers: request.markers.clone().unwrap_or_default(),
                ..Default::default()
            };
            synth_key_drive_to_disk(params, &options, out, truth, force)?;
            Ok(SynthDone {
                runs: options.release_heights_m.len(),
                duration_s: options.duration_s,
                fps: options.camera.fps,
            })
        }
        other => Err(PianoError::option(
            "--experiment",
            format!("'{other}': 'pendulum' or 'key_drive'"),
        )),
    }
}

/// Writes a dataset and its truth record.
fn write_synth(
    out: &Path,
    truth: &Path,
    dataset: &mbs_identify::Dataset,
    runs: &[mbs_identify::RunData],
    truth_record: &impl serde::Serialize,
) -> Result<()> {
    dataset
        .write(out, runs)
        .map_err(|e| PianoError::io(out, "write the dataset", e))?;
    let text = serde_json::to_string_pretty(truth_record)
        .map_err(|e| PianoError::file(truth, format!("cannot encode: {e}")))?;
    std::fs::write(truth, text + "\n").map_err(|e| PianoError::io(truth, "write", e))?;
    Ok(())
}

/// Where a synthetic dataset and its truth may go: a folder (not a file), a `.json` truth
/// outside it, neither replaced without `force`.
fn check_synth_paths(out: &Path, truth: &Path, force: bool) -> Result<()> {
    if out.exists() && !out.is_dir() {
        return Err(PianoError::option(
            "--out",
            format!("{} is a file; name a folder", out.display()),
        ));
    }
    if out.join("dataset.json").exists() && !force {
        return Err(PianoError::file(
            &out.join("dataset.json"),
            "exists; choose another --out, or pass --force to replace the dataset",
        ));
    }
    if truth.extension().and_then(|e| e.to_str()) != Some("json") {
        return Err(PianoError::option(
            "--truth",
            format!(
                "{}: the truth is written as JSON, name a .json file",
                truth.display()
            ),
        ));
    }
    // Resolved through links where the folders exist, so a link into the dataset is seen.
    let resolve = |p: &Path| -> PathBuf {
        let abs = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        let mut head = abs.clone();
        let mut tail = Vec::new();
        while !head.exists() {
            match (head.file_name().map(|n| n.to_os_string()), head.parent()) {
                (Some(name), Some(parent)) => {
                    tail.push(name);
                    head = parent.to_path_buf();
                }
                _ => return abs,
            }
        }
        let mut real = head.canonicalize().unwrap_or(head);
        for name in tail.into_iter().rev() {
            real.push(name);
        }
        real
    };
    let out_abs = resolve(out);
    let truth_abs = resolve(truth);
    if truth_abs.starts_with(&out_abs) {
        return Err(PianoError::option(
            "--truth",
            format!(
                "{} is inside the dataset folder: keep the truth apart from the data",
                truth.display()
            ),
        ));
    }
    if truth.exists() && !force {
        return Err(PianoError::file(
            truth,
            "exists; choose another --truth, or pass --force to replace it",
        ));
    }
    Ok(())
}

/// The swing test's library restricted to `ids` (comma-separated; all when `None`).
pub fn library(ids: Option<&str>) -> Result<Vec<&'static mbs_identify::EffectSpec>> {
    library_of(
        ids,
        &PENDULUM_EFFECTS,
        super::effects::effect_spec,
        &library_ids(),
        "library",
    )
}

/// The action family restricted to `ids` (comma-separated; all when `None`), for a
/// key-drive diagnosis.
pub fn action_library(ids: Option<&str>) -> Result<Vec<&'static mbs_identify::EffectSpec>> {
    use super::action_effects::{ACTION_EFFECTS, action_effect_spec, action_library_ids};
    library_of(
        ids,
        &ACTION_EFFECTS,
        action_effect_spec,
        &action_library_ids(),
        "key-drive library",
    )
}

/// `all` restricted to `ids` (comma-separated; all when `None`), each found by `lookup`;
/// messages list `known` and name the library `what`.
fn library_of(
    ids: Option<&str>,
    all: &'static [mbs_identify::EffectSpec],
    lookup: fn(&str) -> Option<&'static mbs_identify::EffectSpec>,
    known: &str,
    what: &str,
) -> Result<Vec<&'static mbs_identify::EffectSpec>> {
    let Some(ids) = ids else {
        return Ok(all.iter().collect());
    };
    let mut out: Vec<&'static mbs_identify::EffectSpec> = Vec::new();
    for id in ids.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let spec = lookup(id).ok_or_else(|| {
            PianoError::option(
                "--library",
                format!("no effect '{id}' in the {what} (known: {known})"),
            )
        })?;
        if out.iter().any(|s| s.id == spec.id) {
            return Err(PianoError::option(
                "--library",
                format!("'{id}' is listed twice"),
            ));
        }
        out.push(spec);
    }
    if out.is_empty() {
        return Err(PianoError::option(
            "--library",
            format!("names no effect (known: {known})"),
        ));
    }
    Ok(out)
}

/// Reads the key-drive dataset in `dir`, diagnoses it and writes the report into `out`
/// (see [`super::key_diagnose`]); returns the diagnosis and the files written.
pub fn diagnose_key_drive_to_disk(
    params: &ActionParams,
    dir: &Path,
    options: &super::key_diagnose::KeyDiagnoseOptions,
    out: &Path,
    force: bool,
    progress: Progress<'_>,
) -> Result<(super::key_diagnose::KeyDriveDiagnosis, Vec<PathBuf>)> {
    super::report::check_out_dir(out, force)?;
    let dataset = Dataset::load(dir).map_err(super::diagnose::dataset_error)?;
    let d = super::key_diagnose::diagnose_key_drive(params, &dataset, options, progress)?;
    let written = super::key_report::write_key_pages(&d, dir, out, force)?;
    Ok((d, written))
}

/// What [`diagnose_dataset_to_disk`] did, by the dataset's experiment.
#[derive(Clone, Debug)]
pub enum Diagnosed {
    /// A swing test (`pendulum`).
    Pendulum(Box<Outcome>),
    /// A key drive (`key_drive`): the diagnosis and the files written.
    KeyDrive(Box<super::key_diagnose::KeyDriveDiagnosis>, Vec<PathBuf>),
}

impl Diagnosed {
    /// The files written (the report's pages, and the corrected parameter file if any).
    pub fn written(&self) -> &[PathBuf] {
        match self {
            Diagnosed::Pendulum(o) => &o.written,
            Diagnosed::KeyDrive(_, w) => w,
        }
    }
}

/// `piano diagnose`: reads the dataset in `dir`, diagnoses it by its experiment (the swing
/// test or the key drive) with the effects `library` names (all by default), and writes the
/// report into `out`; `write_params` (a swing test's only) asks for the corrected parameter
/// file, `source` being the text of the parameter file used.
#[allow(clippy::too_many_arguments)]
pub fn diagnose_dataset_to_disk(
    params: &ActionParams,
    source: &str,
    dir: &Path,
    library_ids: Option<&str>,
    out: &Path,
    write_params: Option<&Path>,
    force: bool,
    progress: Progress<'_>,
) -> Result<Diagnosed> {
    let experiment = Dataset::load(dir).map(|d| d.experiment).unwrap_or_default();
    if experiment == super::key_drive::EXPERIMENT {
        if write_params.is_some() {
            return Err(PianoError::option(
                "--write-params",
                "a key-drive diagnosis names effects that change the action's mechanism (a \
                 split key, a sprung back-check), which a parameter file cannot hold; read \
                 the calibrated values and the effect in report.json",
            ));
        }
        let options = super::key_diagnose::KeyDiagnoseOptions {
            library: action_library(library_ids)?,
            ..Default::default()
        };
        let (d, written) = diagnose_key_drive_to_disk(params, dir, &options, out, force, progress)?;
        return Ok(Diagnosed::KeyDrive(Box::new(d), written));
    }
    let options = DiagnoseOptions {
        library: library(library_ids)?,
        ..DiagnoseOptions::default()
    };
    diagnose_to_disk(
        params,
        source,
        dir,
        &options,
        out,
        write_params,
        force,
        progress,
    )
    .map(|o| Diagnosed::Pendulum(Box::new(o)))
}

/// What `piano diagnose` did.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The diagnosis.
    pub diagnosis: Diagnosis,
    /// The files written.
    pub written: Vec<PathBuf>,
    /// Why the corrected parameter file asked for was not written, if it was not.
    pub params_refused: Option<String>,
}

/// Reads the dataset in `dir` and diagnoses it; writes the report into `out` and, if
/// asked, the corrected parameter file (`source` is the text of the parameter file used,
/// whose comments are kept).
#[allow(clippy::too_many_arguments)]
pub fn diagnose_to_disk(
    params: &ActionParams,
    source: &str,
    dir: &Path,
    options: &DiagnoseOptions,
    out: &Path,
    write_params: Option<&Path>,
    force: bool,
    progress: Progress<'_>,
) -> Result<Outcome> {
    super::report::check_out_dir(out, force)?;
    if let Some(p) = write_params {
        if p.extension().and_then(|e| e.to_str()) != Some("toml") {
            return Err(PianoError::option(
                "--write-params",
                format!("{}: a parameter file ends in .toml", p.display()),
            ));
        }
        if p.exists() && !force {
            return Err(PianoError::file(
                p,
                "exists; choose another --write-params, or pass --force to replace it",
            ));
        }
    }
    let dataset = Dataset::load(dir).map_err(super::diagnose::dataset_error)?;
    let d = diagnose(params, &dataset, options, progress)?;
    let mut written = super::report::write_pages(&d, dir, out, force)?;
    let refusal = if d.decision == "unexplained" || d.decision == "partly_explained" {
        Some(
            "no parameter file written: the model does not explain the data, so its \
             calibrated values are not to be trusted"
                .to_string(),
        )
    } else if !d.at_bound.is_empty() {
        Some(format!(
            "no parameter file written: {} ended at the edge of its search range",
            d.at_bound.join(", ")
        ))
    } else {
        None
    };
    if let (Some(p), None) = (write_params, &refusal) {
        let text = corrected_params(source, &d, dir)?;
        // The written file must read back and carry what the diagnosis found.
        ActionParams::from_toml_str(&text)?;
        std::fs::write(p, text).map_err(|e| PianoError::io(p, "write", e))?;
        written.push(p.to_path_buf());
    }
    Ok(Outcome {
        diagnosis: d,
        written,
        params_refused: refusal.filter(|_| write_params.is_some()),
    })
}

/// The parameter file `source` with the calibrated inertia and flange friction and the
/// named effect appended as `[[effects]]`, each value tagged with where it came from.
pub fn corrected_params(source: &str, d: &Diagnosis, dataset: &Path) -> Result<String> {
    let tag = format!("[identified] piano diagnose {}", dataset.display());
    let mut lines: Vec<String> = source.lines().map(str::to_string).collect();
    let mut section = String::new();
    for key in ["inertia_com_kg_m2", "pivot_friction_n_m"] {
        let path = format!("hammer.{key}");
        let Some(value) = d.calibrated.get(&path) else {
            continue;
        };
        let mut done = false;
        for line in lines.iter_mut() {
            let t = line.trim();
            if t.starts_with('[') {
                section = t.trim_matches(|c| c == '[' || c == ']').trim().to_string();
                continue;
            }
            let is_key = t.split_once('=').is_some_and(|(k, _)| k.trim() == key);
            if section == "hammer" && is_key {
                *line = format!("{key} = {value:.4e}    # {tag}");
                done = true;
                break;
            }
        }
        if !done {
            return Err(PianoError::params(
                path,
                "not found in the parameter file, so the calibrated value cannot be written",
            ));
        }
    }
    let mut text = lines.join("\n");
    text.push('\n');
    for e in &d.effects {
        text.push_str(&format!(
            "\n[[effects]]    # {} ({})\nid = \"{}\"\nlocation = \"{}\"\n",
            d.decision, tag, e.id, e.location
        ));
        for (name, v) in &e.params {
            let ci = e.ci95.get(name).copied().unwrap_or([f64::NAN; 2]);
            text.push_str(&format!(
                "{name} = {v:.4e}    # {tag}; 95 % {:.3e} to {:.3e}\n",
                ci[0], ci[1]
            ));
        }
    }
    Ok(text)
}
