//! Synthetic pendulum datasets with a hidden effect: the test bench of `piano diagnose`
//! (`identification.md` §5.1).
//!
//! The truth is the parameter file's hammer with nuisance mismatches drawn per seed (mass
//! ±2 %, inertia ±5 %, flange friction ±10 %), one hidden flange effect or none, release
//! angles off by up to half a degree, a camera clock offset per run, exposure averaging,
//! AR(1) tracking noise (σ 30 µm, ρ 0.8 by default), 0.3 % outlier frames of 10 σ and 0.1 %
//! lost frames. The truth goes to its own file, which the diagnosis never reads.

use mbs_identify::{Camera, Dataset, MarkerSpec, Rng, Role, RunData, RunSpec, SCHEMA_VERSION};
use serde::Serialize;

use super::effects::{EffectEntry, FlangeEffects};
use super::swing_model::SwingModel;
use crate::error::{PianoError, Result};
use crate::params::ActionParams;

/// What to synthesise.
#[derive(Clone, Debug, PartialEq)]
pub struct SynthOptions {
    /// The hidden effect, if any.
    pub effect: Option<EffectEntry>,
    /// The seed: the same seed gives the same dataset.
    pub seed: u64,
    /// Release angles (° above horizontal); the first run is fitted, the others held out.
    pub releases_deg: Vec<f64>,
    /// Length of each run (s).
    pub duration_s: f64,
    /// The camera and its tracker.
    pub camera: CameraSynth,
}

impl Default for SynthOptions {
    fn default() -> Self {
        Self {
            effect: None,
            seed: 0,
            releases_deg: vec![0.0, -35.0],
            duration_s: 4.0,
            camera: CameraSynth::default(),
        }
    }
}

/// A synthetic camera and its tracker: what films the markers of a synthetic dataset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSynth {
    /// Frame rate (frames/s) [S]: the seed study filmed at 3000 fps.
    pub fps: f64,
    /// Exposure of a frame (s): a full frame by default, the strongest blur.
    pub exposure_s: f64,
    /// Tracking noise, marginal SD per coordinate (m) [D] `identification.md` §5.1.
    pub sigma_m: f64,
    /// Lag-one correlation of the tracking noise [D] `identification.md` §5.1.
    pub rho: f64,
    /// Fraction of frames with a gross tracking error.
    pub outlier_fraction: f64,
    /// Size of a gross error, in σ.
    pub outlier_sigmas: f64,
    /// Fraction of frames lost.
    pub lost_fraction: f64,
}

impl Default for CameraSynth {
    fn default() -> Self {
        Self {
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

/// The truth behind a synthetic dataset (written to its own file).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Truth {
    /// `"pendulum"`.
    pub experiment: String,
    /// The seed.
    pub seed: u64,
    /// The hidden effect, if any.
    pub effect: Option<EffectEntry>,
    /// True hammer mass (kg).
    pub mass_kg: f64,
    /// True inertia about the centre of mass (kg·m²).
    pub inertia_com_kg_m2: f64,
    /// True flange Coulomb friction (N·m).
    pub coulomb_n_m: f64,
    /// Tracking noise SD (m).
    pub sigma_m: f64,
    /// Tracking noise lag-one correlation.
    pub rho: f64,
    /// Per run.
    pub runs: Vec<TruthRun>,
}

/// The truth of one run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TruthRun {
    /// The run's id.
    pub id: String,
    /// True release angle (°).
    pub release_angle_deg: f64,
    /// True camera clock offset (s).
    pub offset_s: f64,
    /// Frames with a gross error.
    pub outlier_frames: Vec<usize>,
    /// Frames lost.
    pub lost_frames: Vec<usize>,
    /// When the hammer stuck for good (s), if within the run.
    pub stop_s: Option<f64>,
}

/// The tracked markers of a synthetic pendulum [D]: a target on the head's side and one
/// half-way along the shank.
pub fn default_markers(sigma_m: f64) -> Vec<MarkerSpec> {
    vec![
        MarkerSpec {
            name: "head".into(),
            body: "hammer".into(),
            local_m: [0.125, 0.015],
            sigma_m,
        },
        MarkerSpec {
            name: "shank".into(),
            body: "hammer".into(),
            local_m: [0.060, 0.0],
            sigma_m,
        },
    ]
}

/// Checks a synthetic camera: its frame rate, exposure and tracking noise (messages name
/// the command-line flag).
pub(crate) fn check_camera(camera: &CameraSynth) -> Result<()> {
    let (fps, exposure_s, noise) = (camera.fps, camera.exposure_s, camera);
    let bad = |flag: &str, msg: String| Err(PianoError::option(flag, msg));
    if !(fps.is_finite() && (100.0..=100_000.0).contains(&fps)) {
        return bad("--fps", format!("{fps}: 100 to 100000 frames/s"));
    }
    if !(exposure_s.is_finite() && exposure_s >= 0.0 && exposure_s <= 1.0 / fps) {
        return bad("--exposure", format!("{exposure_s} s: 0 to one frame"));
    }
    if !(noise.sigma_m.is_finite() && noise.sigma_m > 0.0 && noise.sigma_m < 1e-2) {
        return bad(
            "--sigma",
            format!("{} m: positive, below 1 cm", noise.sigma_m),
        );
    }
    if !(noise.rho.is_finite() && (0.0..0.99).contains(&noise.rho)) {
        return bad("--rho", format!("{}: 0 to 0.99", noise.rho));
    }
    for (flag, v) in [
        ("--outliers", noise.outlier_fraction),
        ("--lost", noise.lost_fraction),
    ] {
        if !(v.is_finite() && (0.0..=0.2).contains(&v)) {
            return bad(flag, format!("{v}: a fraction from 0 to 0.2"));
        }
    }
    Ok(())
}

/// Per marker, per frame: a tracked position, or `None` for a lost frame.
pub(crate) type Tracks = Vec<Vec<Option<[f64; 2]>>>;

/// The tracked frames of the clean tracks `clean` (per marker, per frame): AR(1) noise on
/// each marker's coordinates, then gross errors of `outlier_sigmas` σ on one marker's x, y
/// or both and lost frames of one marker, each at random frames. Returns the frames, the
/// frames with a gross error and the frames with a lost marker.
pub(crate) fn tracked(
    rng: &mut Rng,
    clean: Vec<Vec<[f64; 2]>>,
    noise: &CameraSynth,
) -> (Tracks, Vec<usize>, Vec<usize>) {
    let frames = clean.first().map_or(0, Vec::len);
    let mut positions = Vec::new();
    for track in clean {
        let nx = rng.ar1(frames, noise.sigma_m, noise.rho);
        let ny = rng.ar1(frames, noise.sigma_m, noise.rho);
        positions.push(
            track
                .iter()
                .zip(nx.iter().zip(&ny))
                .map(|(p, (ex, ey))| Some([p[0] + ex, p[1] + ey]))
                .collect::<Vec<_>>(),
        );
    }
    let markers = positions.len();
    let mut outliers = Vec::new();
    let mut lost = Vec::new();
    for k in 0..frames {
        if rng.uniform() < noise.outlier_fraction {
            // A gross error on one marker's x, y or both, ±10 σ.
            let m = (rng.uniform() * markers as f64) as usize % markers;
            let which = (rng.uniform() * 3.0) as usize;
            if let Some(Some(p)) = positions[m].get_mut(k) {
                for (axis, v) in p.iter_mut().enumerate() {
                    if which == 2 || which == axis {
                        let sign = if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
                        *v += sign * noise.outlier_sigmas * noise.sigma_m;
                    }
                }
            }
            outliers.push(k);
        }
        if rng.uniform() < noise.lost_fraction {
            let m = (rng.uniform() * markers as f64) as usize % markers;
            if let Some(slot) = positions[m].get_mut(k) {
                *slot = None;
            }
            lost.push(k);
        }
    }
    (positions, outliers, lost)
}

/// A run's id from its release angle: `release_0`, `release_m35`.
pub fn run_id(release_deg: f64) -> String {
    let text = format!("{release_deg}").replace('-', "m").replace('.', "p");
    format!("release_{text}")
}

/// Checks the options (messages name the command-line flag).
fn check(o: &SynthOptions) -> Result<()> {
    let bad = |flag: &str, msg: String| Err(PianoError::option(flag, msg));
    if o.releases_deg.is_empty() {
        return bad("--releases", "needs at least one release angle".into());
    }
    let ids: Vec<String> = o.releases_deg.iter().map(|r| run_id(*r)).collect();
    for (i, id) in ids.iter().enumerate() {
        if ids[..i].contains(id) {
            return bad(
                "--releases",
                format!("{}° is listed twice", o.releases_deg[i]),
            );
        }
    }
    for &r in &o.releases_deg {
        if !(r.is_finite() && (-80.0..=60.0).contains(&r)) {
            return bad(
                "--releases",
                format!("{r}°: a release from −80° to 60° above horizontal"),
            );
        }
    }
    if !(o.duration_s.is_finite() && (0.1..=60.0).contains(&o.duration_s)) {
        return bad("--duration", format!("{} s: 0.1 to 60 s", o.duration_s));
    }
    check_camera(&o.camera)?;
    if let Some(e) = &o.effect {
        e.validate("--effect")?;
    }
    Ok(())
}

/// Synthesises a pendulum dataset from the hammer of `params`: the dataset (its `dir`
/// empty), each run's frames, and the truth.
pub fn synthesize(
    params: &ActionParams,
    options: &SynthOptions,
) -> Result<(Dataset, Vec<RunData>, Truth)> {
    check(options)?;
    let mut rng = Rng::new(options.seed);
    let effects = FlangeEffects::from_entries(options.effect.as_slice())?;
    let mut model = SwingModel::from_params(params, effects);
    // Nuisance mismatches [D] `identification.md` §5.1 / issue 13.
    model.mass_kg *= 1.0 + rng.range(-0.02, 0.02);
    model.inertia_com_kg_m2 *= 1.0 + rng.range(-0.05, 0.05);
    model.coulomb_n_m *= 1.0 + rng.range(-0.10, 0.10);
    // A finer step than the diagnosis uses, so it does not fit its own integration error.
    model.step_s /= 4.0;
    let markers = default_markers(options.camera.sigma_m);
    let frames = (options.duration_s * options.camera.fps).round() as usize;
    let times: Vec<f64> = (0..frames).map(|k| k as f64 / options.camera.fps).collect();
    let mut specs = Vec::new();
    let mut runs = Vec::new();
    let mut truth_runs = Vec::new();
    for (i, &release) in options.releases_deg.iter().enumerate() {
        let id = run_id(release);
        let true_release = release + rng.range(-0.5, 0.5);
        let offset = rng.range(-2.5e-4, 2.5e-4);
        let camera = Camera {
            exposure_s: options.camera.exposure_s,
            offset_s: offset,
        };
        let path = model.simulate(true_release.to_radians(), options.duration_s + 0.01);
        let clean: Vec<Vec<[f64; 2]>> = markers
            .iter()
            .map(|m| path.frames(&camera, &times, m.local_m))
            .collect();
        let (positions, outliers, lost) = tracked(&mut rng, clean, &options.camera);
        specs.push(RunSpec {
            id: id.clone(),
            file: format!("{id}.csv"),
            role: if i == 0 { Role::Fit } else { Role::Heldout },
            conditions: [("release_angle_deg".to_string(), serde_json::json!(release))]
                .into_iter()
                .collect(),
        });
        runs.push(RunData {
            time_s: times.clone(),
            positions,
        });
        truth_runs.push(TruthRun {
            id,
            release_angle_deg: true_release,
            offset_s: offset,
            outlier_frames: outliers,
            lost_frames: lost,
            stop_s: path.stuck.map(|s| s.0),
        });
    }
    let dataset = Dataset {
        dir: Default::default(),
        schema_version: SCHEMA_VERSION,
        experiment: "pendulum".into(),
        description: format!(
            "synthetic swing test from `piano synth`, seed {} (what is hidden in it is in \
             the truth file)",
            options.seed
        ),
        fps: options.camera.fps,
        exposure_s: options.camera.exposure_s,
        markers,
        drive: None,
        runs: specs,
    };
    let truth = Truth {
        experiment: "pendulum".into(),
        seed: options.seed,
        effect: options.effect.clone(),
        mass_kg: model.mass_kg,
        inertia_com_kg_m2: model.inertia_com_kg_m2,
        coulomb_n_m: model.coulomb_n_m,
        sigma_m: options.camera.sigma_m,
        rho: options.camera.rho,
        runs: truth_runs,
    };
    Ok((dataset, runs, truth))
}

/// Parses `--effect ID[:name=value,...]` against a library (`lookup` finds an id, `known`
/// lists them for messages): the spec and every parameter's value, those not given at the
/// effect's typical (clearly visible) value.
pub fn parse_effect_in(
    text: &str,
    lookup: fn(&str) -> Option<&'static mbs_identify::EffectSpec>,
    known: &str,
) -> Result<(
    &'static mbs_identify::EffectSpec,
    std::collections::BTreeMap<String, f64>,
)> {
    let (id, rest) = text.split_once(':').unwrap_or((text, ""));
    let spec = lookup(id.trim()).ok_or_else(|| {
        PianoError::option(
            "--effect",
            format!("no effect '{id}' in the library (known: {known})"),
        )
    })?;
    let mut params: std::collections::BTreeMap<String, f64> = spec
        .params
        .iter()
        .map(|p| (p.name.to_string(), p.typical))
        .collect();
    let mut params_given: Vec<String> = Vec::new();
    for item in rest.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (name, value) = item
            .split_once('=')
            .ok_or_else(|| PianoError::option("--effect", format!("'{item}': write name=value")))?;
        let v: f64 = value
            .trim()
            .parse()
            .map_err(|_| PianoError::option("--effect", format!("'{value}' is not a number")))?;
        if params_given.contains(&name.trim().to_string()) {
            return Err(PianoError::option(
                "--effect",
                format!("'{}' is given twice", name.trim()),
            ));
        }
        params_given.push(name.trim().to_string());
        if spec.param(name.trim()).is_none() {
            return Err(PianoError::option(
                "--effect",
                format!("'{}' has no parameter '{}'", spec.id, name.trim()),
            ));
        }
        params.insert(name.trim().to_string(), v);
    }
    Ok((spec, params))
}

/// Parses `--effect ID[:name=value,...]`; parameters not given take the effect's typical
/// (clearly visible) value.
pub fn parse_effect(text: &str) -> Result<EffectEntry> {
    let (spec, params) = parse_effect_in(
        text,
        super::effects::effect_spec,
        &super::effects::library_ids(),
    )?;
    let entry = EffectEntry {
        id: spec.id.to_string(),
        location: super::effects::HAMMER_FLANGE.to_string(),
        params,
    };
    entry.validate("--effect")?;
    Ok(entry)
}
