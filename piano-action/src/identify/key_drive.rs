//! The key-drive experiment (issue 15; the seed's second experiment): a 1 kg mass is
//! released on the key front, the key's motion is tracked at 3000 fps and drives the model,
//! and the other tracked markers (the key's back end, the hammer's head and shank) are
//! compared with the simulated ones.
//!
//! This module holds what a key-drive dataset is (its experiment name, drive marker and
//! default markers, in the parameter file's body frames and world frame, in metres) and
//! its synthesiser: the grand action with nuisance mismatches drawn per seed (masses ±3 %,
//! felt stiffness ±15 %, frictions ±20 %, the figures), the mass dropped from a
//! few millimetres, every marker recorded through the camera model (exposure, clock
//! offset) with AR(1) tracking noise, gross errors and lost frames. The truth goes to its
//! own record, which a diagnosis never reads.

use std::collections::BTreeMap;

use mbs_identify::{Camera, Dataset, MarkerSpec, Rng, Role, RunData, RunSpec, SCHEMA_VERSION};
use serde::Serialize;

use super::synth::{TrackingNoise, tracked};
use crate::ModelKind;
use crate::error::{PianoError, Result};
use crate::key::KeyGeometry;
use crate::params::ActionParams;
use crate::simulate::{Input, prepare, simulate};

/// The experiment's name in `dataset.json`.
pub const EXPERIMENT: &str = "key_drive";
/// The marker that drives the model.
pub const DRIVE_MARKER: &str = "key_front";

/// The tracked markers of a key-drive dataset [D]: the key front (the drive) and back end,
/// the hammer's head (at its strike point) and the middle of its shank, each in its body's
/// frame of the parameter file (m).
pub fn default_markers(params: &ActionParams, sigma_m: f64) -> Vec<MarkerSpec> {
    let k = &params.key;
    let key_back = [
        (k.back_pad_mm[0] - k.pivot_mm[0]) * 1e-3,
        (k.back_pad_mm[1] - k.pivot_mm[1]) * 1e-3,
    ];
    let s = params.hammer.strike_body_mm;
    let marker = |name: &str, body: &str, local_m: [f64; 2]| MarkerSpec {
        name: name.into(),
        body: body.into(),
        local_m,
        sigma_m,
    };
    vec![
        marker(DRIVE_MARKER, "key", KeyGeometry::of(&params.key).finger_m()),
        marker("key_back", "key", key_back),
        marker("hammer_head", "hammer", [s[0] * 1e-3, s[1] * 1e-3]),
        marker("hammer_shank", "hammer", [s[0] * 0.5e-3, s[1] * 0.5e-3]),
    ]
}

/// What to synthesise.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyDriveOptions {
    /// The seed: the same seed gives the same dataset.
    pub seed: u64,
    /// The model.
    pub kind: ModelKind,
    /// The mass released on the key (kg) [S]: the seed study's 1 kg.
    pub mass_kg: f64,
    /// Heights it is released from above the key (m), one run each; the first run is
    /// fitted, the others held out.
    pub release_heights_m: Vec<f64>,
    /// Length of each run (s).
    pub duration_s: f64,
    /// Frame rate (frames/s) [S]: the seed study filmed at 3000 fps.
    pub fps: f64,
    /// Exposure of a frame (s).
    pub exposure_s: f64,
    /// Tracking noise, marginal SD per coordinate (m) [D] `identification.md` §5.1.
    pub sigma_m: f64,
    /// Lag-one correlation of the tracking noise [D].
    pub rho: f64,
    /// Fraction of frames with a gross tracking error.
    pub outlier_fraction: f64,
    /// Size of a gross error, in σ.
    pub outlier_sigmas: f64,
    /// Fraction of frames lost.
    pub lost_fraction: f64,
}

impl Default for KeyDriveOptions {
    fn default() -> Self {
        Self {
            seed: 0,
            kind: ModelKind::Double,
            mass_kg: 1.0,
            release_heights_m: vec![0.0, 0.005],
            duration_s: 0.3,
            fps: 3000.0,
            exposure_s: 1.0 / 3000.0,
            sigma_m: 30e-6,
            rho: 0.8,
            outlier_fraction: 0.003,
            outlier_sigmas: 10.0,
            lost_fraction: 0.001,
        }
    }
}

/// The truth behind a synthetic key-drive dataset.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyDriveTruth {
    /// `"key_drive"`.
    pub experiment: String,
    /// The seed.
    pub seed: u64,
    /// Each mismatched parameter (its path) and the factor it was multiplied by.
    pub nuisance: BTreeMap<String, f64>,
    /// Tracking noise SD (m).
    pub sigma_m: f64,
    /// Per run: id, camera clock offset (s), frames with gross errors, frames lost.
    pub runs: Vec<KeyDriveTruthRun>,
}

/// The truth of one run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KeyDriveTruthRun {
    /// The run's id.
    pub id: String,
    /// Release height (m).
    pub release_height_m: f64,
    /// Camera clock offset (s).
    pub offset_s: f64,
    /// Frames with a gross error.
    pub outlier_frames: Vec<usize>,
    /// Frames lost.
    pub lost_frames: Vec<usize>,
}

/// The parameters' relative mismatches [D] (issue 15): masses ±3 %, felt stiffness ±15 %,
/// frictions ±20 %. The hammer–string law, the string and the numerics are left alone.
fn nuisance_range(path: &str) -> Option<f64> {
    if path.starts_with("string.") || path.starts_with("numerics.") {
        None
    } else if path.ends_with(".mass_g") {
        Some(0.03)
    } else if path.starts_with("contacts.") && path.ends_with(".k") {
        Some(0.15)
    } else if path.ends_with("pivot_friction_n_m")
        || (path.starts_with("contacts.") && path.ends_with(".mu"))
    {
        Some(0.20)
    } else {
        None
    }
}

/// `params` with the nuisance mismatches drawn from `rng`, and what was drawn.
fn mismatched(
    params: &ActionParams,
    rng: &mut Rng,
) -> Result<(ActionParams, BTreeMap<String, f64>)> {
    let mut out = params.clone();
    let mut drawn = BTreeMap::new();
    for info in params.parameter_list(crate::params::DEFAULT_PARAMS_TOML)? {
        if let Some(range) = nuisance_range(&info.path)
            && info.path != "contacts.hammer_string.k"
        {
            let factor = 1.0 + rng.range(-range, range);
            out.set_parameter(&info.path, info.value * factor)?;
            drawn.insert(info.path, factor);
        }
    }
    out.validate()?;
    Ok((out, drawn))
}

/// Checks the options (messages name the command-line flag).
fn check(o: &KeyDriveOptions) -> Result<()> {
    let bad = |flag: &str, msg: String| Err(PianoError::option(flag, msg));
    if o.release_heights_m.is_empty() {
        return bad("--heights", "needs at least one release height".into());
    }
    for &h in &o.release_heights_m {
        if !(h.is_finite() && (0.0..=0.05).contains(&h)) {
            return bad("--heights", format!("{h} m: 0 to 0.05 m above the key"));
        }
    }
    if !(o.mass_kg.is_finite() && (0.05..=5.0).contains(&o.mass_kg)) {
        return bad("--mass", format!("{} kg: 0.05 to 5 kg", o.mass_kg));
    }
    if !(o.duration_s.is_finite() && (0.05..=2.0).contains(&o.duration_s)) {
        return bad("--duration", format!("{} s: 0.05 to 2 s", o.duration_s));
    }
    if !(o.fps.is_finite() && (100.0..=100_000.0).contains(&o.fps)) {
        return bad("--fps", format!("{}: 100 to 100000 frames/s", o.fps));
    }
    if !(o.exposure_s.is_finite() && o.exposure_s >= 0.0 && o.exposure_s <= 1.0 / o.fps) {
        return bad("--exposure", format!("{} s: 0 to one frame", o.exposure_s));
    }
    if !(o.sigma_m.is_finite() && o.sigma_m > 0.0 && o.sigma_m < 1e-2) {
        return bad("--sigma", format!("{} m: positive, below 1 cm", o.sigma_m));
    }
    if !(o.rho.is_finite() && (0.0..0.99).contains(&o.rho)) {
        return bad("--rho", format!("{}: 0 to 0.99", o.rho));
    }
    for (flag, v) in [
        ("--outliers", o.outlier_fraction),
        ("--lost", o.lost_fraction),
    ] {
        if !(v.is_finite() && (0.0..=0.2).contains(&v)) {
            return bad(flag, format!("{v}: a fraction from 0 to 0.2"));
        }
    }
    Ok(())
}

/// A run's id from its release height: `drop_0mm`, `drop_5mm`.
pub fn run_id(height_m: f64) -> String {
    let mm = format!("{}", (height_m * 1e4).round() / 10.0).replace('.', "p");
    format!("drop_{mm}mm")
}

/// Per marker, per sample: a world position (m).
type CleanTracks = Vec<Vec<[f64; 2]>>;

/// The world positions (m) of `markers` along a simulated run, on its output grid.
fn marker_tracks(
    params: &ActionParams,
    kind: ModelKind,
    input: &Input,
    duration_s: f64,
    markers: &[MarkerSpec],
) -> Result<(Vec<f64>, CleanTracks)> {
    let run = simulate(params, kind, input, duration_s, 2e-5)?;
    let prepared = prepare(params, kind, input)?;
    let system = &prepared.action.system;
    let model = system.model();
    let points: Vec<_> = markers
        .iter()
        .map(|m| {
            let frame = model.frame_id(&m.body)?;
            Ok(mbs_core::frame_point(model, frame, m.local_m))
        })
        .collect::<Result<_>>()?;
    let sol = &run.solution;
    let mut ws = system.workspace();
    let mut tracks = vec![Vec::with_capacity(sol.len()); markers.len()];
    for i in 0..sol.len() {
        let ctx = system.kinematics(&mut ws, sol.t[i], sol.state(i))?;
        for (track, &(body, p)) in tracks.iter_mut().zip(&points) {
            track.push(ctx.point_position(body, p));
        }
    }
    Ok((sol.t.clone(), tracks))
}

/// The position at `t` of a track sampled at `times` (linear; held before the first and
/// after the last sample).
fn at(times: &[f64], track: &[[f64; 2]], t: f64) -> [f64; 2] {
    let i = times.partition_point(|&s| s <= t);
    if i == 0 {
        return track[0];
    }
    if i >= times.len() {
        return track[track.len() - 1];
    }
    let u = (t - times[i - 1]) / (times[i] - times[i - 1]);
    let (a, b) = (track[i - 1], track[i]);
    [a[0] + u * (b[0] - a[0]), a[1] + u * (b[1] - a[1])]
}

/// Synthesises a key-drive dataset from the action of `params`: the dataset (its `dir`
/// empty), each run's frames, and the truth.
pub fn synthesize(
    params: &ActionParams,
    options: &KeyDriveOptions,
) -> Result<(Dataset, Vec<RunData>, KeyDriveTruth)> {
    check(options)?;
    let mut rng = Rng::new(options.seed);
    let (truth_params, nuisance) = mismatched(params, &mut rng)?;
    let markers = default_markers(params, options.sigma_m);
    let frames = (options.duration_s * options.fps).round() as usize;
    let times: Vec<f64> = (0..frames).map(|k| k as f64 / options.fps).collect();
    let noise = TrackingNoise {
        sigma_m: options.sigma_m,
        rho: options.rho,
        outlier_fraction: options.outlier_fraction,
        outlier_sigmas: options.outlier_sigmas,
        lost_fraction: options.lost_fraction,
    };
    let (mut specs, mut runs, mut truth_runs) = (Vec::new(), Vec::new(), Vec::new());
    for (i, &height) in options.release_heights_m.iter().enumerate() {
        let id = run_id(height);
        let offset = rng.range(-2.5e-4, 2.5e-4);
        let camera = Camera {
            exposure_s: options.exposure_s,
            offset_s: offset,
        };
        let input = Input::MassDrop {
            mass_kg: options.mass_kg,
            height_m: height,
        };
        // A little past the last frame, for the exposure and the offset.
        let (sim_t, tracks) = marker_tracks(
            &truth_params,
            options.kind,
            &input,
            options.duration_s + 1e-3,
            &markers,
        )?;
        let clean: CleanTracks = tracks
            .iter()
            .map(|track| {
                times
                    .iter()
                    .map(|&t| {
                        camera
                            .frame(t, |s| Some(at(&sim_t, track, s)))
                            .unwrap_or(track[0])
                    })
                    .collect()
            })
            .collect();
        let (positions, outliers, lost) = tracked(&mut rng, clean, &noise);
        specs.push(RunSpec {
            id: id.clone(),
            file: format!("{id}.csv"),
            role: if i == 0 { Role::Fit } else { Role::Heldout },
            conditions: [
                ("mass_kg".to_string(), serde_json::json!(options.mass_kg)),
                ("release_height_m".to_string(), serde_json::json!(height)),
            ]
            .into_iter()
            .collect(),
        });
        runs.push(RunData {
            time_s: times.clone(),
            positions,
        });
        truth_runs.push(KeyDriveTruthRun {
            id,
            release_height_m: height,
            offset_s: offset,
            outlier_frames: outliers,
            lost_frames: lost,
        });
    }
    let dataset = Dataset {
        dir: Default::default(),
        schema_version: SCHEMA_VERSION,
        experiment: EXPERIMENT.into(),
        description: format!(
            "synthetic key drive from `piano synth`, {} kg released on the key, seed {} (what \
             is hidden in it is in the truth file)",
            options.mass_kg, options.seed
        ),
        fps: options.fps,
        exposure_s: options.exposure_s,
        markers,
        drive: Some(DRIVE_MARKER.into()),
        runs: specs,
    };
    let truth = KeyDriveTruth {
        experiment: EXPERIMENT.into(),
        seed: options.seed,
        nuisance,
        sigma_m: options.sigma_m,
        runs: truth_runs,
    };
    Ok((dataset, runs, truth))
}
