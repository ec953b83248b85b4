//! The data check of `piano diagnose`: a pendulum dataset read, checked against what a
//! swing test must look like (frame rate, length, marker radii, release at t = 0 and at the
//! declared angle), its gross tracking errors found by a leave-one-out local polynomial and
//! its noise floor and AR(1) correlation estimated from the frames themselves.

use mbs_identify::noise::{self, Ar1, OutlierOptions};
use mbs_identify::{Dataset, Role};
use serde::Serialize;

use crate::error::{PianoError, Result};

/// One observed coordinate of one frame.
#[derive(Clone, Copy, Debug)]
pub(super) struct Obs {
    pub(super) frame: usize,
    pub(super) marker: usize,
    pub(super) axis: usize,
    pub(super) value: f64,
    pub(super) segment_start: bool,
}

/// A run ready to be fitted.
#[derive(Clone, Debug)]
pub(super) struct Run {
    pub(super) id: String,
    pub(super) role: Role,
    /// The release: the angle (rad) of a swing, the height (m) of a key drive.
    pub(super) release: f64,
    pub(super) times: Vec<f64>,
    pub(super) obs: Vec<Obs>,
    pub(super) lost_frames: usize,
    pub(super) outlier_frames: Vec<usize>,
}

/// The data check's result for the report.
#[derive(Clone, Debug, Serialize)]
pub struct DataCheck {
    /// Noise floor (m): the tracking noise's SD per coordinate, from the frames.
    pub noise_floor_m: f64,
    /// Lag-one correlation of the tracking noise.
    pub rho: f64,
    /// The dataset's declared noise (m), for comparison.
    pub declared_sigma_m: f64,
    /// Per run: frames, lost frames, outlier frames.
    pub runs: Vec<RunCheck>,
}

/// One run's data check.
#[derive(Clone, Debug, Serialize)]
pub struct RunCheck {
    /// Its id.
    pub id: String,
    /// `fit` or `heldout`.
    pub role: String,
    /// Frames.
    pub frames: usize,
    /// Frames with a marker lost.
    pub lost_frames: usize,
    /// Frames flagged as gross tracking errors (left out of every fit).
    pub outlier_frames: usize,
}

/// A dataset error as the piano's error: the file, then the line, the field and what is
/// wrong.
pub fn dataset_error(e: mbs_identify::DatasetError) -> PianoError {
    let mut where_ = String::new();
    if let Some(l) = e.line {
        where_.push_str(&format!("line {l}, "));
    }
    if !e.field.is_empty() {
        where_.push_str(&format!("field `{}`: ", e.field));
    }
    PianoError::File {
        path: e.file,
        message: format!("{where_}{}", e.message),
    }
}

/// An error about `field` of `file`.
fn file_error(file: &std::path::Path, field: &str, message: &str) -> PianoError {
    PianoError::File {
        path: file.to_path_buf(),
        message: format!("field `{field}`: {message}"),
    }
}

/// Shortest run the swing can be judged on [D]: half a swing of this hammer.
pub const MIN_RUN_S: f64 = 0.3;
/// A marker further than this fraction from where `local_m` puts it is misplaced [D]: a
/// target is placed to a millimetre on a 60–130 mm radius.
pub const MARKER_RADIUS_TOLERANCE: f64 = 0.05;
/// The hammer must be seen moving (20 σ from its first position) within this time of
/// t = 0 (s) [D]: released 10° from hanging it moves 8 mm at the head in 0.1 s.
pub const RELEASE_WINDOW_S: f64 = 0.1;
/// Largest difference between the declared release angle and the first frames' (°) [D].
pub const RELEASE_MISMATCH_DEG: f64 = 2.0;

/// Checks that run `i`'s frames can be a swing released at t = 0 from `declared` (rad)
/// and filmed with this dataset's markers: frames at the declared rate, long enough, the
/// markers at their declared distance from the pin, the release at t = 0 and at the
/// declared angle. Returns the release angle the first frames show (rad).
fn check_run(
    dataset: &Dataset,
    spec: &mbs_identify::RunSpec,
    i: usize,
    data: &mbs_identify::RunData,
    declared: f64,
) -> Result<f64> {
    let json = dataset.dir.join("dataset.json");
    let csv = dataset.dir.join(&spec.file);
    let t = &data.time_s;
    let n = t.len();
    let span = t[n - 1] - t[0];
    if n < 100 || span < MIN_RUN_S {
        return Err(file_error(
            &csv,
            "time_s",
            &format!(
                "{n} frames over {span:.3} s: a swing test needs at least {MIN_RUN_S} s and 100 \
                 frames"
            ),
        ));
    }
    let mut steps: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_by(f64::total_cmp);
    let step = steps[steps.len() / 2];
    if ((step * dataset.fps) - 1.0).abs() > 0.01 {
        return Err(file_error(
            &json,
            "fps",
            &format!(
                "{} frames/s, but the frames of {} are {:.4e} s apart ({:.1} frames/s)",
                dataset.fps,
                spec.file,
                step,
                1.0 / step
            ),
        ));
    }
    if t[0] > step {
        return Err(file_error(
            &csv,
            "time_s",
            &format!(
                "the first frame is at {} s: time is counted from the release (t = 0; frames \
                 before it have negative times)",
                t[0]
            ),
        ));
    }
    let mut angles = Vec::new();
    for (m, marker) in dataset.markers.iter().enumerate() {
        let r_local = marker.local_m[0].hypot(marker.local_m[1]);
        let mut radii: Vec<f64> = data.positions[m]
            .iter()
            .flatten()
            .map(|p| p[0].hypot(p[1]))
            .collect();
        radii.sort_by(f64::total_cmp);
        let r_seen = radii[radii.len() / 2];
        if (r_seen / r_local - 1.0).abs() > MARKER_RADIUS_TOLERANCE {
            return Err(file_error(
                &csv,
                &format!("{}_x_m", marker.name),
                &format!(
                    "marker '{}' is {r_seen:.4} m from the pin in the frames, but its local_m \
                     puts it {r_local:.4} m away: positions in metres, origin at the flange's \
                     centre pin, and each marker's columns its own",
                    marker.name
                ),
            ));
        }
        // Where the release is: the first seen frames, and when the marker leaves it.
        let seen: Vec<(f64, [f64; 2])> = t
            .iter()
            .zip(&data.positions[m])
            .filter_map(|(t, p)| p.map(|p| (*t, p)))
            .collect();
        let first = seen[0].1;
        angles.push(first[1].atan2(first[0]) - marker.local_m[1].atan2(marker.local_m[0]));
        let moved = seen
            .iter()
            .find(|(_, p)| (p[0] - first[0]).hypot(p[1] - first[1]) > 20.0 * marker.sigma_m);
        if let Some((t_move, _)) = moved
            && *t_move > RELEASE_WINDOW_S
        {
            return Err(file_error(
                &csv,
                "time_s",
                &format!(
                    "marker '{}' starts moving at {t_move:.3} s: time is counted from the \
                     release (t = 0); shift the times so the release is at 0",
                    marker.name
                ),
            ));
        }
    }
    let seen = angles.iter().sum::<f64>() / angles.len() as f64;
    let seen =
        (seen + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
    if (seen - declared).abs().to_degrees() > RELEASE_MISMATCH_DEG {
        return Err(file_error(
            &json,
            &format!("runs[{i}].conditions.release_angle_deg"),
            &format!(
                "says {:.1}°, but the first frames of {} show the shank at {:.1}° above \
                 horizontal",
                declared.to_degrees(),
                spec.file,
                seen.to_degrees()
            ),
        ));
    }
    Ok(seen)
}

/// Reads a dataset's runs, checks them for the pendulum and finds lost frames and
/// outliers.
pub(super) fn prepare(dataset: &Dataset) -> Result<(Vec<Run>, Ar1)> {
    let file = dataset.dir.join("dataset.json");
    let data_err = dataset_error;
    if dataset.experiment != "pendulum" {
        return Err(PianoError::File {
            path: file,
            message: format!(
                "field `experiment`: '{}': `piano diagnose` knows the 'pendulum' experiment{}",
                dataset.experiment,
                if dataset.experiment == super::key_drive::EXPERIMENT {
                    " (a key-drive dataset is diagnosed by `identify::key_diagnose`, which \
                     `piano diagnose` picks from the experiment)"
                } else {
                    ""
                }
            ),
        });
    }
    dataset.check_bodies(&["hammer"]).map_err(data_err)?;
    let mut runs = Vec::new();
    for (i, spec) in dataset.runs.iter().enumerate() {
        let field = format!("runs[{i}].conditions.release_angle_deg");
        let declared = match spec.conditions.get("release_angle_deg") {
            None => {
                return Err(file_error(
                    &file,
                    &field,
                    "missing: a pendulum run needs its release angle (° above horizontal)",
                ));
            }
            Some(v) => v.as_f64().filter(|v| v.is_finite()).ok_or_else(|| {
                file_error(&file, &field, &format!("{v} is not a number of degrees"))
            })?,
        };
        if !(-90.0..=90.0).contains(&declared) {
            return Err(file_error(
                &file,
                &field,
                &format!("{declared}° is out of range: −90° (hanging straight down) to 90°"),
            ));
        }
        let data = dataset.read_run(spec).map_err(data_err)?;
        let release = check_run(dataset, spec, i, &data, declared.to_radians())?;
        let (obs, outliers, lost) = observations(&data);
        runs.push(Run {
            id: spec.id.clone(),
            role: spec.role,
            release,
            times: data.time_s,
            obs,
            lost_frames: lost,
            outlier_frames: outliers,
        });
    }
    if !runs.iter().any(|r| r.role == Role::Fit) {
        return Err(PianoError::File {
            path: file,
            message: "field `runs`: no run has role \"fit\"".into(),
        });
    }
    let noise = noise_floor(&file, &runs, dataset.markers.len())?;
    Ok((runs, noise))
}

/// A run's observations (every seen coordinate of every marker, in marker, axis, frame
/// order), the frames flagged as gross errors (left out) and the number of frames with a
/// marker lost.
pub(super) fn observations(data: &mbs_identify::RunData) -> (Vec<Obs>, Vec<usize>, usize) {
    let channels: Vec<Vec<Option<f64>>> = data
        .positions
        .iter()
        .flat_map(|track| (0..2).map(move |a| track.iter().map(|p| p.map(|p| p[a])).collect()))
        .collect();
    let refs: Vec<&[Option<f64>]> = channels.iter().map(Vec::as_slice).collect();
    let outliers = noise::detect_outliers(&data.time_s, &refs, &OutlierOptions::default());
    let mut obs = Vec::new();
    for (m, track) in data.positions.iter().enumerate() {
        for axis in 0..2 {
            let mut prev_ok = false;
            for (k, p) in track.iter().enumerate() {
                match p {
                    Some(p) if !outliers[k] => {
                        obs.push(Obs {
                            frame: k,
                            marker: m,
                            axis,
                            value: p[axis],
                            segment_start: !prev_ok,
                        });
                        prev_ok = true;
                    }
                    _ => prev_ok = false,
                }
            }
        }
    }
    let lost = (0..data.time_s.len())
        .filter(|&k| data.positions.iter().any(|t| t[k].is_none()))
        .count();
    (
        obs,
        (0..outliers.len()).filter(|&k| outliers[k]).collect(),
        lost,
    )
}

/// The noise floor and its AR(1) correlation from the frames themselves, outliers left
/// out: every run's coordinates as channels over a common frame index (shorter runs padded
/// as lost). `file` is the dataset's, for the error.
pub(super) fn noise_floor(file: &std::path::Path, runs: &[Run], markers: usize) -> Result<Ar1> {
    let width = runs.iter().map(|r| r.times.len()).max().unwrap_or(0);
    let mut channels: Vec<Vec<Option<f64>>> = Vec::new();
    for r in runs {
        let first = channels.len();
        channels.extend((0..2 * markers).map(|_| vec![None; width]));
        for o in &r.obs {
            channels[first + 2 * o.marker + o.axis][o.frame] = Some(o.value);
        }
    }
    let refs: Vec<&[Option<f64>]> = channels.iter().map(Vec::as_slice).collect();
    noise::estimate_ar1(&refs, &vec![false; width]).ok_or_else(|| PianoError::File {
        path: file.to_path_buf(),
        message: "too few frames to estimate the tracking noise".into(),
    })
}

impl DataCheck {
    /// The data check of `runs` of `dataset`, with the noise floor `noise`.
    pub(super) fn of(dataset: &mbs_identify::Dataset, runs: &[Run], noise: &Ar1) -> DataCheck {
        DataCheck {
            noise_floor_m: noise.sigma,
            rho: noise.rho,
            declared_sigma_m: dataset
                .markers
                .iter()
                .map(|m| m.sigma_m)
                .fold(0.0, f64::max),
            runs: runs
                .iter()
                .map(|r| RunCheck {
                    id: r.id.clone(),
                    role: match r.role {
                        Role::Fit => "fit".into(),
                        Role::Heldout => "heldout".into(),
                    },
                    frames: r.times.len(),
                    lost_frames: r.lost_frames,
                    outlier_frames: r.outlier_frames.len(),
                })
                .collect(),
        }
    }
}

/// Run `r`'s raw residuals `raw` (measured − model, m, aligned with its observations)
/// standardized by the noise floor `sigma`, whitened with the noise's correlation `rho`
/// in the stretches the observations make, and cut by `phases`: what
/// `mbs_identify::explain::check_noise` judges.
pub(super) fn run_residuals(
    r: &Run,
    raw: &[f64],
    sigma: f64,
    rho: f64,
    phases: Vec<mbs_identify::explain::Window>,
) -> mbs_identify::explain::RunResiduals {
    let standardized: Vec<f64> = raw.iter().map(|e| e / sigma).collect();
    let starts: Vec<bool> = r.obs.iter().map(|o| o.segment_start).collect();
    let whitened = noise::whiten(&standardized, &starts, rho);
    mbs_identify::explain::RunResiduals {
        run: r.id.clone(),
        phases,
        residuals: r
            .obs
            .iter()
            .zip(standardized.iter().zip(&whitened))
            .map(|(o, (&s, &w))| mbs_identify::explain::Residual {
                marker: o.marker,
                time_s: r.times[o.frame],
                standardized: s,
                whitened: w,
                segment_start: o.segment_start,
            })
            .collect(),
    }
}
