//! `piano diagnose` for the pendulum (swing) test: check the data, calibrate what the
//! model already has, locate where it disagrees with the measured swing, try each named
//! effect of the library, decide honestly and measure the gap before and after
//! (`identification.md` §3; issue 13).
//!
//! The data check finds gross tracking errors by a leave-one-out local polynomial and the
//! noise floor with its AR(1) correlation from the frames themselves. Every fit is output
//! error: the swing is simulated, filmed by the camera's measurement model (exposure and
//! clock offset) and compared frame by frame, the residuals standardised by the noise
//! floor and whitened with its correlation. A candidate effect is kept when the whitened
//! BIC falls by 10 or more, the worst phase's gap by 20 % or more, the held-out run's gap
//! by 10 % or more, and its strength is plausible and identified.

use std::collections::BTreeMap;

use rayon::prelude::*;

use mbs_identify::explain::{NoiseCheck, NoiseCheckOptions, RunResiduals, Window, check_noise};
use mbs_identify::lm::{FreeParam, LmFit, LmOptions, levenberg_marquardt};
use mbs_identify::noise::{self, Ar1};
use mbs_identify::work::{StageClock, StageWork, WorkCounter};
use mbs_identify::{Camera, Dataset, EffectSpec, Role};
use serde::Serialize;

pub use super::data_check::{DataCheck, RunCheck, dataset_error};
use super::data_check::{Run, prepare, run_residuals};
use super::effects::{EffectEntry, FlangeEffects, HAMMER_FLANGE, PENDULUM_EFFECTS};
use super::swing_model::SwingModel;
use crate::error::{PianoError, Result};
use crate::params::ActionParams;

/// Whitened-BIC drop a candidate needs [D] `identification.md` §3.6 ("very strong" on
/// the Kass–Raftery scale).
pub const DELTA_BIC_MAX: f64 = -10.0;
/// Two kept candidates closer than this in BIC are ambiguous [D] §3.6.
pub const AMBIGUITY_BIC: f64 = 6.0;
/// Least relative fall of the flagged phase's gap [D] §3.6.
pub const EFFECT_SIZE_MIN: f64 = 0.2;
/// Least relative fall of the held-out run's gap [D] §3.6.
pub const HELDOUT_GAIN_MIN: f64 = 0.1;
/// A held-out gap above this many noise floors after the fix is only partly explained
/// [D] §3.6 and §6 (the look-alike of U1).
pub const PARTIAL_FLOORS: f64 = 1.5;
/// Largest relative SD of a kept effect's strength [D] §3.6.
pub const IDENTIFIABLE_REL_SD: f64 = 0.3;
/// A held-out run's release and clock offset are refitted on its frames up to this time
/// (s) [D]: a second holds one and a half swings.
pub const HELDOUT_REFIT_S: f64 = 1.0;
/// A baseline within this many noise floors in every phase explains the data [D].
pub const EXPLAINED_FLOORS: f64 = 1.5;

/// Options of a diagnosis.
#[derive(Clone, Debug)]
pub struct DiagnoseOptions {
    /// The effects tried (by default the whole pendulum library).
    pub library: Vec<&'static EffectSpec>,
    /// Cores to use (by default all): the baseline's fits use them all for their
    /// Jacobians; the candidates' fits run side by side on them, two threads each.
    pub threads: usize,
    /// Relative tolerance of the hammer's weighed mass. The swing shows only torques
    /// relative to the inertia, and the inertia is fitted against the gravity torque
    /// m g d of the file's mass: every fitted torque (N·m…) scales with the true mass over
    /// the file's, so its 95 % interval is widened by this much each way.
    pub mass_tolerance: f64,
}

/// Default weighing tolerance [D]: a 0.1 g scale on a 12 g hammer reads within 1 %; 2 %
/// is the synthetic datasets' nuisance (`identification.md` §5.1).
pub const MASS_TOLERANCE: f64 = 0.02;

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            library: PENDULUM_EFFECTS.iter().collect(),
            threads: std::thread::available_parallelism().map_or(2, |n| n.get()),
            mass_tolerance: MASS_TOLERANCE,
        }
    }
}

/// The model's parameters during a fit: physics, then per run release and clock offset.
#[derive(Clone, Debug, PartialEq)]
struct Setting {
    inertia_com_kg_m2: f64,
    coulomb_n_m: f64,
    effect: Option<(&'static EffectSpec, Vec<f64>)>,
    /// Per fitted run: release (rad), offset (s).
    runs: Vec<(f64, f64)>,
}

/// A phase of a run and its gap.
#[derive(Clone, Debug, Serialize)]
pub struct Phase {
    /// `<run>/<phase>`: large, medium or small amplitude, last swings, stopped.
    pub name: String,
    /// Start (s).
    pub t0_s: f64,
    /// End (s).
    pub t1_s: f64,
    /// RMS gap of the baseline (m).
    pub before_rms_m: f64,
    /// RMS gap of the corrected model (m).
    pub after_rms_m: f64,
}

/// The gap before and after.
#[derive(Clone, Debug, Serialize)]
pub struct Gap {
    /// Noise floor (m).
    pub noise_floor_m: f64,
    /// Fitted runs, baseline (m).
    pub before_rms_m: f64,
    /// Fitted runs, corrected (m).
    pub after_rms_m: f64,
    /// Held-out runs, baseline (m).
    pub heldout_before_rms_m: f64,
    /// Held-out runs, corrected (m).
    pub heldout_after_rms_m: f64,
    /// Per phase of every run.
    pub phases: Vec<Phase>,
    /// The phase with the largest baseline gap against the noise floor.
    pub flagged_phase: String,
    /// When the baseline's gap first leaves the noise (s, fitted run), if it does.
    pub onset_s: Option<f64>,
}

/// One tried candidate.
#[derive(Clone, Debug, Serialize)]
pub struct Candidate {
    /// Effect id.
    pub id: String,
    /// Whitened BIC against the baseline's.
    pub delta_bic: f64,
    /// Fitted runs' RMS gap (m).
    pub fit_rms_m: f64,
    /// Held-out runs' RMS gap (m).
    pub heldout_rms_m: f64,
    /// Held-out runs' RMS gap in the large to small amplitude phases (m), before the last
    /// swings: the test of a partial fit.
    pub heldout_moving_rms_m: f64,
    /// Flagged phase's RMS gap (m).
    pub flagged_rms_m: f64,
    /// Its fitted parameters.
    pub params: BTreeMap<String, f64>,
    /// Their 95 % intervals.
    pub ci95: BTreeMap<String, [f64; 2]>,
    /// Whether it passed every rule.
    pub kept: bool,
    /// Why it was kept or dropped.
    pub why: String,
}

/// A named effect of the decision.
#[derive(Clone, Debug, Serialize)]
pub struct NamedEffect {
    /// Its id.
    pub id: String,
    /// Where it acts.
    pub location: String,
    /// Its parameters.
    pub params: BTreeMap<String, f64>,
    /// Their 95 % intervals.
    pub ci95: BTreeMap<String, [f64; 2]>,
}

/// The diagnosis (`report.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Diagnosis {
    /// `named`, `ambiguous`, `partly_explained`, `none` or `unexplained`.
    pub decision: String,
    /// One sentence on why.
    pub summary: String,
    /// The candidate that explains the most when the decision is `partly_explained` (or
    /// the named one): never added to the model unless named.
    pub best_candidate: Option<String>,
    /// How many times the best candidate shrinks the flagged phase's gap.
    pub flagged_shrink: Option<f64>,
    /// Whether the best candidate's model explains every run to the noise (every phase,
    /// and the residuals' whiteness): the test a name must pass.
    pub noise_check: Option<NoiseCheck>,
    /// The same test of the calibrated baseline.
    pub baseline_noise_check: NoiseCheck,
    /// The effect(s) added (one when named; the best of the set when ambiguous).
    pub effects: Vec<NamedEffect>,
    /// The other effects an ambiguity could not separate from the first.
    pub ambiguous_with: Vec<String>,
    /// The experiment that would separate them.
    pub separating_experiment: Option<String>,
    /// Every candidate tried.
    pub candidates: Vec<Candidate>,
    /// Calibrated parameters by path (with the effect when one is added).
    pub calibrated: BTreeMap<String, f64>,
    /// Calibrated parameters that ended at the edge of their search range (a sign the
    /// model or the data is wrong).
    pub at_bound: Vec<String>,
    /// The paths the baseline calibration frees (each candidate frees its own parameters
    /// besides, `effects.<id>.<name>`); everything else is the parameter file's.
    pub calibration_frees: Vec<String>,
    /// The gap.
    pub gap: Gap,
    /// The data check.
    pub data: DataCheck,
    /// The work of each stage, measured on this run: fits, residual evaluations and
    /// simulations, and their rates per wall-clock second; the last entry is the `total`.
    pub throughput: Vec<StageWork>,
    /// The traces for the report's plots (not in `report.json`).
    #[serde(skip)]
    pub traces: Vec<RunTrace>,
}

/// Measured, baseline and corrected positions of one marker coordinate of a run, for the
/// plots.
#[derive(Clone, Debug)]
pub struct RunTrace {
    /// The run.
    pub run: String,
    /// Fitted or held out.
    pub heldout: bool,
    /// Frame times (s) of the frames where the head marker is seen.
    pub t: Vec<f64>,
    /// Measured head-marker height (m).
    pub measured: Vec<f64>,
    /// Baseline's (m).
    pub baseline: Vec<f64>,
    /// Corrected model's (m), when an effect was added.
    pub corrected: Option<Vec<f64>>,
    /// Measured − baseline along the swing (m): the head marker's residual projected on
    /// the direction it moves, perpendicular to the pin.
    pub baseline_residual: Vec<f64>,
    /// Measured − corrected along the swing (m), when an effect was added.
    pub corrected_residual: Option<Vec<f64>>,
}

/// Progress messages: the stage and its fraction of the whole.
pub type Progress<'a> = &'a (dyn Fn(&str, f64) + Sync);

/// Everything a fit needs, shared by every stage.
struct Problem<'a> {
    params: &'a ActionParams,
    dataset: &'a Dataset,
    runs: Vec<Run>,
    noise: Ar1,
    threads: usize,
    /// The diagnosis's fits, evaluations and simulations, counted.
    work: &'a WorkCounter,
}

impl Problem<'_> {
    fn model(&self, s: &Setting) -> Result<SwingModel> {
        // The parameter file's own effects stay; the candidate adds to them.
        let mut entries = self.params.effects.clone();
        if let Some((spec, values)) = &s.effect {
            entries.push(entry(spec, values));
        }
        let effects = FlangeEffects::from_entries(&entries)?;
        let mut m = SwingModel::from_params(self.params, effects);
        m.inertia_com_kg_m2 = s.inertia_com_kg_m2;
        m.coulomb_n_m = s.coulomb_n_m;
        Ok(m)
    }

    /// Predicted values of run `r`'s observations.
    fn predict(&self, model: &SwingModel, r: &Run, release: f64, offset: f64) -> Vec<f64> {
        self.predict_until(model, r, release, offset, f64::INFINITY)
    }

    /// Predicted values of run `r`'s observations in frames up to `horizon` (s).
    fn predict_until(
        &self,
        model: &SwingModel,
        r: &Run,
        release: f64,
        offset: f64,
        horizon: f64,
    ) -> Vec<f64> {
        let camera = Camera {
            exposure_s: self.dataset.exposure_s,
            offset_s: offset,
        };
        let n = frames_until(r, horizon);
        let end = r.times[..n].last().copied().unwrap_or(0.0) + self.dataset.exposure_s + 0.01;
        let path = model.simulate(release, end.max(0.01));
        self.work.add_simulations(1);
        let tracks: Vec<Vec<[f64; 2]>> = self
            .dataset
            .markers
            .iter()
            .map(|m| path.frames(&camera, &r.times[..n], m.local_m))
            .collect();
        r.obs
            .iter()
            .filter(|o| o.frame < n)
            .map(|o| tracks[o.marker][o.frame][o.axis])
            .collect()
    }

    /// Whitened standardised residuals of run `r` (the observations up to `horizon`).
    fn whitened(&self, r: &Run, predicted: &[f64], horizon: f64) -> Vec<f64> {
        let n = frames_until(r, horizon);
        let obs = r.obs.iter().filter(|o| o.frame < n);
        let std: Vec<f64> = obs
            .clone()
            .zip(predicted)
            .map(|(o, p)| (o.value - p) / self.noise.sigma)
            .collect();
        let starts: Vec<bool> = obs.map(|o| o.segment_start).collect();
        noise::whiten(&std, &starts, self.noise.rho)
    }

    fn fit_runs(&self) -> impl Iterator<Item = &Run> {
        self.runs.iter().filter(|r| r.role == Role::Fit)
    }

    fn heldout_runs(&self) -> impl Iterator<Item = &Run> {
        self.runs.iter().filter(|r| r.role == Role::Heldout)
    }
}

/// Number of frames of `r` up to `horizon` (s).
fn frames_until(r: &Run, horizon: f64) -> usize {
    r.times.partition_point(|&t| t <= horizon)
}

fn entry(spec: &EffectSpec, values: &[f64]) -> EffectEntry {
    EffectEntry {
        id: spec.id.to_string(),
        location: HAMMER_FLANGE.to_string(),
        params: spec
            .params
            .iter()
            .zip(values)
            .map(|(p, v)| (p.name.to_string(), *v))
            .collect(),
    }
}

/// A fitted setting and what the fit says about it.
struct Fitted {
    setting: Setting,
    fit: LmFit,
    /// Whitened BIC on the fitted runs.
    bic: f64,
}

impl Problem<'_> {
    /// Free parameters of a fit of `effect` started at `start` (the effect's values in
    /// `start.effect`).
    fn free_params(&self, start: &Setting) -> Vec<FreeParam> {
        let h = &self.params.hammer;
        let mut p = vec![
            FreeParam::log(
                "hammer.inertia_com_kg_m2",
                start.inertia_com_kg_m2,
                h.inertia_com_kg_m2 / 3.0,
                h.inertia_com_kg_m2 * 3.0,
            ),
            FreeParam::log("hammer.pivot_friction_n_m", start.coulomb_n_m, 1e-6, 2e-2),
        ];
        if let Some((spec, values)) = &start.effect {
            for (e, v) in spec.params.iter().zip(values) {
                let name = format!("effects.{}.{}", spec.id, e.name);
                // The search range is wider than the plausible one, so an implausible fit
                // shows as such instead of sitting on the bound.
                let hi = 4.0 * e.range[1];
                p.push(if e.log_scale {
                    FreeParam::log(&name, *v, e.range[0], e.range[1])
                } else {
                    FreeParam::linear(&name, *v, e.range[0], hi, e.typical)
                });
            }
        }
        let frame = 1.0 / self.dataset.fps;
        for ((release, offset), r) in start.runs.iter().zip(self.fit_runs()) {
            p.push(FreeParam::linear(
                format!("{}.release_angle_deg", r.id),
                *release,
                r.release - 1f64.to_radians(),
                r.release + 1f64.to_radians(),
                1e-3,
            ));
            p.push(FreeParam::linear(
                format!("{}.offset_s", r.id),
                *offset,
                -1.5 * frame,
                1.5 * frame,
                0.1 * frame,
            ));
        }
        p
    }

    /// The setting of parameter vector `x` laid out as [`Problem::free_params`].
    fn setting_of(&self, template: &Setting, x: &[f64]) -> Setting {
        let mut s = template.clone();
        s.inertia_com_kg_m2 = x[0];
        s.coulomb_n_m = x[1];
        let mut i = 2;
        if let Some((_, values)) = &mut s.effect {
            for v in values.iter_mut() {
                *v = x[i];
                i += 1;
            }
        }
        for run in &mut s.runs {
            *run = (x[i], x[i + 1]);
            i += 2;
        }
        s
    }

    /// Output-error fit from `start` on the fitted runs, by continuation: first the
    /// first second of each run, then two, then all, each fit starting from the last. A
    /// swing fitted whole from a start a few per cent off can lock onto the wrong number
    /// of swings before the hammer sticks; the first second has no such minimum.
    fn fit(&self, start: &Setting) -> Result<Fitted> {
        let mut s = start.clone();
        for horizon in [1.0, 2.0] {
            s = self.fit_until(&s, horizon)?.setting;
        }
        self.fit_until(&s, f64::INFINITY)
    }

    /// Output-error fit from `start` on the fitted runs' frames up to `horizon` (s).
    fn fit_until(&self, start: &Setting, horizon: f64) -> Result<Fitted> {
        let free = self.free_params(start);
        let residuals = |x: &[f64]| -> std::result::Result<Vec<f64>, String> {
            self.work.add_evaluation();
            let s = self.setting_of(start, x);
            let model = self.model(&s).map_err(|e| e.to_string())?;
            let mut out = Vec::new();
            for (r, (release, offset)) in self.fit_runs().zip(&s.runs) {
                let pred = self.predict_until(&model, r, *release, *offset, horizon);
                out.extend(self.whitened(r, &pred, horizon));
            }
            Ok(out)
        };
        let options = LmOptions {
            threads: self.threads,
            // The residuals are standardised: the RSS is about their number, so the
            // default relative tolerance would stop short of the optimum.
            cost_tolerance: 1e-9,
            ..LmOptions::default()
        };
        self.work.add_fit();
        let fit = levenberg_marquardt(&free, residuals, &options)
            .map_err(|e| PianoError::Simulation(format!("calibration: {e}")))?;
        let n = fit.residuals.len() as f64;
        let k = free.len() as f64;
        let bic = n * (fit.rss / n).ln() + k * n.ln();
        Ok(Fitted {
            setting: self.setting_of(start, &fit.values),
            fit,
            bic,
        })
    }

    /// Raw residuals (m) of run `r` under `model`, its release and offset refitted (the
    /// physics held): how a held-out run is judged.
    fn refit_run(&self, model: &SwingModel, r: &Run) -> Result<Vec<f64>> {
        let frame = 1.0 / self.dataset.fps;
        let free = [
            FreeParam::linear(
                "release_rad",
                r.release,
                r.release - 1f64.to_radians(),
                r.release + 1f64.to_radians(),
                1e-3,
            ),
            FreeParam::linear("offset_s", 0.0, -1.5 * frame, 1.5 * frame, 0.1 * frame),
        ];
        // The release and the clock show in the first second; later frames would let a
        // stuck angle a milliradian off (see `heldout_moving_rms_m`) pull them away.
        let horizon = HELDOUT_REFIT_S;
        let residuals = |x: &[f64]| -> std::result::Result<Vec<f64>, String> {
            self.work.add_evaluation();
            let pred = self.predict_until(model, r, x[0], x[1], horizon);
            Ok(self.whitened(r, &pred, horizon))
        };
        let options = LmOptions {
            threads: self.threads,
            // The residuals are standardised: the RSS is about their number, so the
            // default relative tolerance would stop short of the optimum.
            cost_tolerance: 1e-9,
            ..LmOptions::default()
        };
        self.work.add_fit();
        let fit = levenberg_marquardt(&free, residuals, &options)
            .map_err(|e| PianoError::Simulation(format!("held-out fit: {e}")))?;
        Ok(self.raw(model, r, fit.values[0], fit.values[1]))
    }

    /// Raw residuals (m) of run `r`.
    fn raw(&self, model: &SwingModel, r: &Run, release: f64, offset: f64) -> Vec<f64> {
        let pred = self.predict(model, r, release, offset);
        r.obs.iter().zip(&pred).map(|(o, p)| o.value - p).collect()
    }
}

fn rms(v: impl IntoIterator<Item = f64>) -> f64 {
    let (mut s, mut n) = (0.0, 0usize);
    for x in v {
        s += x * x;
        n += 1;
    }
    if n == 0 { 0.0 } else { (s / n as f64).sqrt() }
}

/// The phases of a swing from its simulation: large, medium and small amplitude (above
/// 2/3, 1/3 and below 1/3 of the release amplitude), the last two half swings before the
/// hammer sticks, and stopped. Empty phases are left out.
fn swing_phases(model: &SwingModel, release: f64, end: f64) -> Vec<(&'static str, f64, f64)> {
    let path = model.simulate(release, end);
    // Hanging: the gravity torque vanishes with the centre of mass below the pin.
    let [cx, cy] = model.com_m;
    let hanging = -std::f64::consts::FRAC_PI_2 - cy.atan2(cx);
    let a0 = (release - hanging).abs().max(1e-9);
    let mut bounds: Vec<(f64, f64)> = vec![(0.0, a0)];
    bounds.extend(
        path.reversals
            .iter()
            .map(|&(t, p)| (t, (p - hanging).abs())),
    );
    let stop = path.stuck.map(|s| s.0);
    let n_half = bounds.len() - 1 + usize::from(stop.is_none());
    let mut phases: Vec<(&'static str, f64, f64)> = Vec::new();
    let mut push = |name: &'static str, t0: f64, t1: f64| {
        if t1 <= t0 {
            return;
        }
        match phases.last_mut() {
            Some(last) if last.0 == name => last.2 = t1,
            _ => phases.push((name, t0, t1)),
        }
    };
    for i in 0..n_half {
        let (t0, amp) = bounds[i];
        let t1 = bounds.get(i + 1).map_or(end, |b| b.0);
        let name = if stop.is_some() && i + 2 >= n_half {
            "last swings"
        } else if amp > 2.0 / 3.0 * a0 {
            "large amplitude"
        } else if amp > a0 / 3.0 {
            "medium amplitude"
        } else {
            "small amplitude"
        };
        push(name, t0, t1.min(end));
    }
    if let Some(ts) = stop {
        push("stopped", ts, end);
    }
    phases
}

/// A candidate's fit and its scores.
struct Tried {
    spec: &'static EffectSpec,
    fitted: Fitted,
    model: SwingModel,
    fit_raw: Vec<Vec<f64>>,
    heldout_raw: Vec<Vec<f64>>,
    candidate: Candidate,
}

/// Diagnoses `dataset` against the hammer of `params`.
pub fn diagnose(
    params: &ActionParams,
    dataset: &Dataset,
    options: &DiagnoseOptions,
    progress: Progress<'_>,
) -> Result<Diagnosis> {
    let work = WorkCounter::default();
    let mut clock = StageClock::new(&work);
    progress("checking the data", 0.0);
    let (runs, noise) = prepare(dataset)?;
    let problem = Problem {
        params,
        dataset,
        runs,
        noise,
        threads: options.threads.max(1),
        work: &work,
    };
    let sigma = noise.sigma;
    let data = DataCheck::of(dataset, &problem.runs, &noise);
    clock.lap("data check");
    let steps = 2.0 + options.library.len() as f64;

    // A. The baseline: inertia, Coulomb friction, each fitted run's release and offset;
    // three starts around the parameter file's friction.
    progress("calibrating the baseline", 1.0 / steps);
    let h = &params.hammer;
    let mut baseline: Option<Fitted> = None;
    for scale in [1.0, 0.8, 1.25] {
        let start = Setting {
            inertia_com_kg_m2: h.inertia_com_kg_m2,
            coulomb_n_m: h.pivot_friction_n_m * scale,
            effect: None,
            runs: problem.fit_runs().map(|r| (r.release, 0.0)).collect(),
        };
        let f = problem.fit(&start)?;
        if baseline.as_ref().is_none_or(|b| f.fit.rss < b.fit.rss) {
            baseline = Some(f);
        }
    }
    let baseline = baseline.ok_or_else(|| PianoError::Simulation("no baseline fit".into()))?;
    clock.lap("baseline calibration");
    let base_model = problem.model(&baseline.setting)?;
    let fit_raw = |model: &SwingModel, s: &Setting| -> Vec<Vec<f64>> {
        problem
            .fit_runs()
            .zip(&s.runs)
            .map(|(r, (rel, off))| problem.raw(model, r, *rel, *off))
            .collect()
    };
    let base_fit_raw = fit_raw(&base_model, &baseline.setting);
    let base_heldout_raw: Vec<Vec<f64>> = problem
        .heldout_runs()
        .map(|r| problem.refit_run(&base_model, r))
        .collect::<Result<_>>()?;
    clock.lap("baseline held-out");

    // B. Where the baseline disagrees: the phases of every run, the flagged one (largest
    // gap against the noise floor, fitted runs) and the onset.
    struct PhaseWindow {
        run: usize,
        name: String,
        t0: f64,
        t1: f64,
    }
    let mut windows = Vec::new();
    for (i, r) in problem.runs.iter().enumerate() {
        let (release, _) = problem
            .fit_runs()
            .position(|f| f.id == r.id)
            .map_or((r.release, 0.0), |j| baseline.setting.runs[j]);
        let end = r.times.last().copied().unwrap_or(0.0) + 1.0 / dataset.fps;
        for (name, t0, t1) in swing_phases(&base_model, release, end) {
            windows.push(PhaseWindow {
                run: i,
                name: format!("{}/{name}", r.id),
                t0,
                t1,
            });
        }
    }
    // Raw residuals of run i under (fit residuals, held-out residuals).
    let residuals_of = |i: usize, fit: &[Vec<f64>], held: &[Vec<f64>]| -> Vec<f64> {
        let r = &problem.runs[i];
        let list = match r.role {
            Role::Fit => fit,
            Role::Heldout => held,
        };
        let same_role = problem.runs[..i]
            .iter()
            .filter(|x| x.role == r.role)
            .count();
        list.get(same_role).cloned().unwrap_or_default()
    };
    let window_rms = |w: &PhaseWindow, res: &[f64]| -> f64 {
        let r = &problem.runs[w.run];
        rms(r
            .obs
            .iter()
            .zip(res)
            .filter(|(o, _)| (w.t0..w.t1).contains(&r.times[o.frame]))
            .map(|(_, e)| *e))
    };
    // Whether a model (its fitted and held-out runs' raw residuals) explains every run to
    // the noise, phase by phase (`mbs_identify::explain`).
    let noise_check = |fit: &[Vec<f64>], held: &[Vec<f64>]| -> NoiseCheck {
        let runs: Vec<RunResiduals> = problem
            .runs
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let phases = windows
                    .iter()
                    .filter(|w| w.run == i)
                    .map(|w| Window {
                        name: w.name.clone(),
                        t0_s: w.t0,
                        t1_s: w.t1,
                    })
                    .collect();
                let raw = residuals_of(i, fit, held);
                run_residuals(r, &raw, sigma, problem.noise.rho, phases)
            })
            .collect();
        let names: Vec<String> = dataset.markers.iter().map(|m| m.name.clone()).collect();
        check_noise(&runs, &names, &NoiseCheckOptions::default())
    };
    let mut flagged: Option<(usize, f64)> = None;
    for (k, w) in windows.iter().enumerate() {
        if problem.runs[w.run].role != Role::Fit {
            continue;
        }
        let g = window_rms(w, &residuals_of(w.run, &base_fit_raw, &base_heldout_raw));
        if flagged.is_none_or(|(_, best)| g > best) {
            flagged = Some((k, g));
        }
    }
    let (flagged_k, flagged_before) = flagged.unwrap_or((0, 0.0));
    let flagged_window = windows.get(flagged_k);
    let flagged_rms = |fit: &[Vec<f64>], held: &[Vec<f64>]| -> f64 {
        flagged_window.map_or(0.0, |w| window_rms(w, &residuals_of(w.run, fit, held)))
    };
    let onset = onset_s(&problem, &base_fit_raw, sigma);

    // C–D. Each candidate of the library, refitted with the baseline's parameters free.
    let base_fit_rms = rms(base_fit_raw.iter().flatten().copied());
    let base_held_rms = rms(base_heldout_raw.iter().flatten().copied());
    // Every start of every candidate, then each candidate's held-out refits, side by
    // side on the cores, each fit's Jacobian on two threads so that a fit trying a step,
    // or the last one left, leaves no core idle; the results are taken in the library's
    // order whatever finished first.
    let library = &options.library;
    progress(&format!("trying {} effects", library.len()), 2.0 / steps);
    let width = problem.threads;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(width)
        .build()
        .map_err(|e| PianoError::Simulation(format!("the diagnosis's threads: {e}")))?;
    let side_by_side = Problem {
        runs: problem.runs.clone(),
        threads: width.min(2),
        ..problem
    };
    let jobs: Vec<(usize, Vec<f64>)> = library
        .iter()
        .enumerate()
        .flat_map(|(c, spec)| starts_of(spec).into_iter().map(move |v| (c, v)))
        .collect();
    let fits: Vec<Result<Fitted>> = pool.install(|| {
        jobs.par_iter()
            .with_max_len(1)
            .map(|(c, values)| {
                side_by_side.fit(&Setting {
                    effect: Some((library[*c], values.clone())),
                    ..baseline.setting.clone()
                })
            })
            .collect()
    });
    let mut best: Vec<Option<Fitted>> = library.iter().map(|_| None).collect();
    for ((c, _), f) in jobs.iter().zip(fits) {
        match f {
            Ok(f) if best[*c].as_ref().is_none_or(|b| f.fit.rss < b.fit.rss) => {
                best[*c] = Some(f);
            }
            _ => {}
        }
    }
    type Judged = Option<(Fitted, SwingModel, Vec<Vec<f64>>, Vec<Vec<f64>>)>;
    let judged: Vec<Result<Judged>> = pool.install(|| {
        best.into_par_iter()
            .with_max_len(1)
            .map(|fitted| {
                let Some(fitted) = fitted else {
                    return Ok(None);
                };
                let model = side_by_side.model(&fitted.setting)?;
                let c_fit_raw = fit_raw(&model, &fitted.setting);
                let c_held_raw: Vec<Vec<f64>> = side_by_side
                    .heldout_runs()
                    .map(|r| side_by_side.refit_run(&model, r))
                    .collect::<Result<_>>()?;
                Ok(Some((fitted, model, c_fit_raw, c_held_raw)))
            })
            .collect()
    });
    let mut tried: Vec<Tried> = Vec::new();
    for (spec, judged) in library.iter().zip(judged) {
        let Some((fitted, model, c_fit_raw, c_held_raw)) = judged? else {
            continue;
        };
        // The held-out gap while the swing is large: where the hammer makes its last
        // small swings and sticks hangs on whether one reversal falls just inside or
        // just outside the static friction, a threshold a model right to a per cent can
        // miss; the amplitude dependence that exposes a look-alike shows before.
        let swinging: Vec<f64> = windows
            .iter()
            .filter(|w| {
                problem.runs[w.run].role == Role::Heldout
                    && !w.name.ends_with("last swings")
                    && !w.name.ends_with("stopped")
            })
            .flat_map(|w| {
                let r = &problem.runs[w.run];
                let res = residuals_of(w.run, &[], &c_held_raw);
                r.obs
                    .iter()
                    .zip(res)
                    .filter(|(o, _)| (w.t0..w.t1).contains(&r.times[o.frame]))
                    .map(|(_, e)| e)
                    .collect::<Vec<_>>()
            })
            .collect();
        let heldout_moving = rms(swinging);
        let values = fitted
            .setting
            .effect
            .as_ref()
            .map(|e| e.1.clone())
            .unwrap_or_default();
        let mut cand = Candidate {
            id: spec.id.to_string(),
            delta_bic: fitted.bic - baseline.bic,
            fit_rms_m: rms(c_fit_raw.iter().flatten().copied()),
            heldout_rms_m: rms(c_held_raw.iter().flatten().copied()),
            heldout_moving_rms_m: heldout_moving,
            flagged_rms_m: flagged_rms(&c_fit_raw, &c_held_raw),
            params: spec
                .params
                .iter()
                .zip(&values)
                .map(|(p, v)| (p.name.to_string(), *v))
                .collect(),
            ci95: spec
                .params
                .iter()
                .enumerate()
                .map(|(j, p)| {
                    let [lo, hi] = fitted.fit.ci95[2 + j];
                    let widen = if p.unit.starts_with("N·m") {
                        1.0 + options.mass_tolerance.max(0.0)
                    } else {
                        1.0
                    };
                    (p.name.to_string(), [lo / widen, hi * widen])
                })
                .collect(),
            kept: false,
            why: String::new(),
        };
        let strength = values.first().copied().unwrap_or(0.0);
        let strength_sd = fitted.fit.sd.get(2).copied().unwrap_or(f64::NAN);
        let has_heldout = !c_held_raw.is_empty();
        let reasons = judge(
            spec,
            &values,
            strength_sd / strength.max(1e-300),
            &cand,
            flagged_before,
            has_heldout.then_some(base_held_rms),
        );
        cand.kept = reasons.is_empty();
        cand.why = if cand.kept {
            format!(
                "kept: ΔBIC {:.0}, flagged phase {:.0} % lower{}",
                cand.delta_bic,
                100.0 * (1.0 - cand.flagged_rms_m / flagged_before.max(1e-300)),
                if has_heldout {
                    format!(
                        ", held-out {:.0} % lower",
                        100.0 * (1.0 - cand.heldout_rms_m / base_held_rms.max(1e-300))
                    )
                } else {
                    String::new()
                }
            )
        } else {
            format!("dropped: {}", reasons.join("; "))
        };
        tried.push(Tried {
            spec,
            fitted,
            model,
            fit_raw: c_fit_raw,
            heldout_raw: c_held_raw,
            candidate: cand,
        });
    }
    clock.lap("candidates: fits and held-out");
    progress("writing the diagnosis", 1.0);

    // E. The decision.
    let kept: Vec<&Tried> = tried.iter().filter(|t| t.candidate.kept).collect();
    let base_worst_floors = windows
        .iter()
        .map(|w| window_rms(w, &residuals_of(w.run, &base_fit_raw, &base_heldout_raw)) / sigma)
        .fold(0.0, f64::max);
    let contenders: Vec<Contender> = kept
        .iter()
        .map(|t| Contender {
            bic: t.fitted.bic,
            heldout_floors: (!t.heldout_raw.is_empty())
                .then(|| t.candidate.heldout_moving_rms_m / sigma),
        })
        .collect();
    let verdict = decide(&contenders, base_worst_floors);
    // No name without the data explained (issue 33): the best's model must bring every
    // run to the noise and shrink the flagged phase's gap twice or more.
    let base_check = noise_check(&base_fit_raw, &base_heldout_raw);
    let best_of = |v: &Verdict| match v {
        Verdict::Named(i) | Verdict::Ambiguous(i, _) | Verdict::Partial(i, _) => Some(kept[*i]),
        Verdict::None | Verdict::Unexplained => None,
    };
    let best = best_of(&verdict);
    let best_check = best.map(|t| noise_check(&t.fit_raw, &t.heldout_raw));
    let shrink = best.map(|t| {
        super::key_diagnose::plain_shrink(flagged_before, flagged_rms(&t.fit_raw, &t.heldout_raw))
    });
    let explains = best_check.as_ref().is_some_and(|c| c.explained)
        && shrink.is_some_and(|x| x >= super::key_diagnose::SHRINK_MIN);
    let verdict = match verdict {
        // A baseline that explains the data already needs nothing.
        Verdict::Named(_) | Verdict::Ambiguous(..) | Verdict::Partial(..)
            if base_check.explained && !explains =>
        {
            Verdict::None
        }
        Verdict::Named(i) | Verdict::Ambiguous(i, _) if !explains => {
            Verdict::Partial(i, best_check.as_ref().map_or(f64::NAN, worst_floors))
        }
        Verdict::None | Verdict::Unexplained => {
            if base_check.explained {
                Verdict::None
            } else {
                Verdict::Unexplained
            }
        }
        v => v,
    };
    let best = best_of(&verdict);
    let mut ambiguous_with = Vec::new();
    let mut separating = None;
    let chosen = match &verdict {
        Verdict::Named(i) | Verdict::Ambiguous(i, _) | Verdict::Partial(i, _) => Some(kept[*i]),
        Verdict::None | Verdict::Unexplained => None,
    };
    let (decision, summary) = match &verdict {
        Verdict::Partial(i, _) => {
            let x = shrink.unwrap_or(1.0);
            let mut left = Vec::new();
            if let Some(floors) = contenders[*i]
                .heldout_floors
                .filter(|f| *f > PARTIAL_FLOORS)
            {
                left.push(format!(
                    "the held-out run keeps a gap of {floors:.1} noise floors before its last \
                     swings (a look-alike of something outside the library)"
                ));
            }
            if x < super::key_diagnose::SHRINK_MIN {
                left.push(format!(
                    "it shrinks the flagged phase's gap only {} (needs {}×)",
                    super::key_diagnose::shrink_text(x),
                    super::key_diagnose::SHRINK_MIN
                ));
            }
            if let Some(c) = best_check.as_ref().filter(|c| !c.explained) {
                left.push(format!("left: {}", c.summary()));
            }
            (
                "partly_explained".to_string(),
                format!(
                    "{} takes {:.0} % of the gap in {} ({:.1} → {:.1} µm), but {}",
                    kept[*i].spec.id,
                    100.0 * (1.0 - (1.0 / (x * x)).min(1.0)),
                    flagged_window.map_or("the data", |w| w.name.as_str()),
                    flagged_before * 1e6,
                    flagged_before / x * 1e6,
                    left.join("; ")
                ),
            )
        }
        Verdict::Named(i) => (
            "named".to_string(),
            format!(
                "{}: {}; the gap falls from {:.1} to {:.1} µm",
                kept[*i].spec.id,
                kept[*i].spec.summary,
                base_fit_rms * 1e6,
                kept[*i].candidate.fit_rms_m * 1e6
            ),
        ),
        Verdict::Ambiguous(i, rivals) => {
            ambiguous_with = rivals
                .iter()
                .map(|j| kept[*j].spec.id.to_string())
                .collect();
            separating = Some(kept[*i].spec.discriminating_experiment.to_string());
            (
                "ambiguous".to_string(),
                format!(
                    "{} or {}: the data cannot separate them (whitened BIC within {})",
                    kept[*i].spec.id,
                    ambiguous_with.join(" or "),
                    AMBIGUITY_BIC
                ),
            )
        }
        Verdict::None => (
            "none".to_string(),
            format!(
                "the baseline explains the data to the noise floor (worst phase {:.2} floors)",
                base_worst_floors
            ),
        ),
        Verdict::Unexplained => (
            "unexplained".to_string(),
            format!(
                "the baseline misses something in {} ({:.1} noise floors) that no effect of \
                 the library accounts for",
                flagged_window.map_or("the data", |w| w.name.as_str()),
                flagged_before / sigma
            ),
        ),
    };
    let corrected = match (decision.as_str(), chosen) {
        ("named" | "ambiguous", Some(t)) => Some(t),
        _ => None,
    };
    let (after_fit, after_held, after_setting) = match corrected {
        Some(t) => (&t.fit_raw, &t.heldout_raw, &t.fitted.setting),
        None => (&base_fit_raw, &base_heldout_raw, &baseline.setting),
    };
    let phases = windows
        .iter()
        .map(|w| Phase {
            name: w.name.clone(),
            t0_s: w.t0,
            t1_s: w.t1,
            before_rms_m: window_rms(w, &residuals_of(w.run, &base_fit_raw, &base_heldout_raw)),
            after_rms_m: window_rms(w, &residuals_of(w.run, after_fit, after_held)),
        })
        .collect();
    let gap = Gap {
        noise_floor_m: sigma,
        before_rms_m: base_fit_rms,
        after_rms_m: rms(after_fit.iter().flatten().copied()),
        heldout_before_rms_m: base_held_rms,
        heldout_after_rms_m: rms(after_held.iter().flatten().copied()),
        phases,
        flagged_phase: flagged_window.map_or(String::new(), |w| w.name.clone()),
        onset_s: onset,
    };
    let final_fit = corrected.map_or(&baseline, |t| &t.fitted);
    let at_bound: Vec<String> = problem
        .free_params(&final_fit.setting)
        .into_iter()
        .zip(&final_fit.fit.at_bound)
        .filter(|(p, at)| **at && !p.name.starts_with("effects."))
        .map(|(p, _)| p.name)
        .collect();
    let mut calibrated = BTreeMap::new();
    calibrated.insert(
        "hammer.inertia_com_kg_m2".to_string(),
        after_setting.inertia_com_kg_m2,
    );
    calibrated.insert(
        "hammer.pivot_friction_n_m".to_string(),
        after_setting.coulomb_n_m,
    );
    for (r, (rel, off)) in problem.fit_runs().zip(&after_setting.runs) {
        calibrated.insert(format!("{}.release_angle_deg", r.id), rel.to_degrees());
        calibrated.insert(format!("{}.offset_s", r.id), *off);
    }
    let effects: Vec<NamedEffect> = corrected
        .map(|t| NamedEffect {
            id: t.spec.id.to_string(),
            location: HAMMER_FLANGE.to_string(),
            params: t.candidate.params.clone(),
            ci95: t.candidate.ci95.clone(),
        })
        .into_iter()
        .collect();
    for e in &effects {
        for (name, v) in &e.params {
            calibrated.insert(format!("effects.{}.{name}", e.id), *v);
        }
    }
    let corrected_model = corrected.map(|t| &t.model);
    let traces = traces(
        &problem,
        &base_model,
        &baseline.setting,
        corrected_model.zip(corrected.map(|t| &t.fitted.setting)),
    )?;
    clock.lap("report");
    let mut throughput = clock.stages();
    throughput.push(clock.total());
    Ok(Diagnosis {
        best_candidate: best.map(|t| t.spec.id.to_string()),
        flagged_shrink: best.and(shrink),
        noise_check: best.and(best_check),
        baseline_noise_check: base_check,
        decision,
        summary,
        effects,
        ambiguous_with,
        separating_experiment: separating,
        candidates: tried.into_iter().map(|t| t.candidate).collect(),
        calibrated,
        at_bound,
        calibration_frees: problem
            .free_params(&baseline.setting)
            .into_iter()
            .map(|p| p.name)
            .collect(),
        gap,
        data,
        throughput,
        traces,
    })
}

/// The largest gap, plain or whitened, of the cells a noise check failed (noise floors).
fn worst_floors(c: &NoiseCheck) -> f64 {
    c.worst
        .as_ref()
        .map_or(0.0, |w| w.floors.max(w.whitened_rms))
}

/// A candidate that passed every rule, as the decision sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contender {
    /// Its whitened BIC on the fitted runs.
    pub bic: f64,
    /// Its held-out gap in the large swings, in noise floors (`None` without a held-out
    /// run).
    pub heldout_floors: Option<f64>,
}

/// The decision, indices into the contenders.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    /// One effect.
    Named(usize),
    /// The best and the others within [`AMBIGUITY_BIC`] of it.
    Ambiguous(usize, Vec<usize>),
    /// The best explains part of the gap only: the held-out one keeps a gap (this many
    /// noise floors) of a look-alike of something outside the library, or its model leaves
    /// a phase (the worst this many floors) or the residuals' whiteness beyond the noise,
    /// or it shrinks the flagged gap less than twice. Reported as `partly_explained`.
    Partial(usize, f64),
    /// Nothing kept (or nothing needed), and the baseline explains the data to the noise
    /// (within [`EXPLAINED_FLOORS`] everywhere in [`decide`]; the noise check of
    /// `mbs_identify::explain` in the diagnosis).
    None,
    /// Nothing kept, and the baseline does not explain the data.
    Unexplained,
}

/// Decides among the kept candidates (`identification.md` §3.6): the lowest BIC wins;
/// a held-out gap above [`PARTIAL_FLOORS`] makes it partial; rivals within
/// [`AMBIGUITY_BIC`] make it ambiguous; with none kept, the baseline's worst phase
/// (`baseline_worst_floors`) tells `none` from `unexplained`.
pub fn decide(kept: &[Contender], baseline_worst_floors: f64) -> Verdict {
    let mut order: Vec<usize> = (0..kept.len()).collect();
    order.sort_by(|&a, &b| kept[a].bic.total_cmp(&kept[b].bic));
    let Some(&best) = order.first() else {
        return if baseline_worst_floors <= EXPLAINED_FLOORS {
            Verdict::None
        } else {
            Verdict::Unexplained
        };
    };
    if let Some(floors) = kept[best].heldout_floors.filter(|f| *f > PARTIAL_FLOORS) {
        return Verdict::Partial(best, floors);
    }
    let rivals: Vec<usize> = order[1..]
        .iter()
        .copied()
        .filter(|&j| kept[j].bic - kept[best].bic < AMBIGUITY_BIC)
        .collect();
    if rivals.is_empty() {
        Verdict::Named(best)
    } else {
        Verdict::Ambiguous(best, rivals)
    }
}

/// Starting values of a candidate's parameters: the strength at a tenth of its typical
/// value (inside its range, off the null so it has a gradient), shape parameters over a
/// grid of decades.
fn starts_of(spec: &EffectSpec) -> Vec<Vec<f64>> {
    let mut starts = vec![Vec::new()];
    for p in spec.params {
        let choices: Vec<f64> = if p.null.is_some() {
            vec![0.1 * p.typical]
        } else {
            vec![0.2 * p.typical, p.typical, 5.0 * p.typical]
                .into_iter()
                .map(|v: f64| v.clamp(p.range[0], p.range[1]))
                .collect()
        };
        starts = starts
            .into_iter()
            .flat_map(|s| {
                choices.iter().map(move |c| {
                    let mut s = s.clone();
                    s.push(*c);
                    s
                })
            })
            .collect();
    }
    starts
}

/// The rules a candidate must pass; the reasons it fails (empty when kept).
fn judge(
    spec: &EffectSpec,
    values: &[f64],
    strength_rel_sd: f64,
    c: &Candidate,
    flagged_before: f64,
    heldout_before: Option<f64>,
) -> Vec<String> {
    let mut why = Vec::new();
    if c.delta_bic > DELTA_BIC_MAX {
        why.push(format!("ΔBIC {:.1} > {DELTA_BIC_MAX}", c.delta_bic));
    }
    let fall = 1.0 - c.flagged_rms_m / flagged_before.max(1e-300);
    if fall < EFFECT_SIZE_MIN {
        why.push(format!(
            "flagged phase only {:.0} % lower (needs {:.0} %)",
            100.0 * fall,
            100.0 * EFFECT_SIZE_MIN
        ));
    }
    if let Some(before) = heldout_before {
        let gain = 1.0 - c.heldout_rms_m / before.max(1e-300);
        if gain < HELDOUT_GAIN_MIN {
            why.push(format!(
                "held-out run {:.0} % lower (needs {:.0} %)",
                100.0 * gain,
                100.0 * HELDOUT_GAIN_MIN
            ));
        }
    }
    for (p, v) in spec.params.iter().zip(values) {
        if !(p.range[0]..=p.range[1]).contains(v) {
            why.push(format!(
                "{} = {v:.3e} {} outside the plausible [{:.1e}, {:.1e}]",
                p.name, p.unit, p.range[0], p.range[1]
            ));
        }
    }
    let strength = values.first().copied().unwrap_or(0.0);
    if strength <= 0.0 {
        why.push("the fit puts its strength at zero".to_string());
    } else if strength_rel_sd.is_nan() || strength_rel_sd > IDENTIFIABLE_REL_SD {
        why.push(if strength_rel_sd < 1e3 {
            format!(
                "strength not identified (relative SD {strength_rel_sd:.2} > \
                 {IDENTIFIABLE_REL_SD})"
            )
        } else {
            "strength not identified (the data do not constrain it)".to_string()
        });
    }
    why
}

/// When the baseline's gap first leaves the noise on the fitted runs: the start of the
/// first 30 ms window whose RMS exceeds twice the noise floor.
fn onset_s(problem: &Problem<'_>, fit_raw: &[Vec<f64>], sigma: f64) -> Option<f64> {
    let r = problem.fit_runs().next()?;
    let res = fit_raw.first()?;
    let n = r.times.len();
    let (mut sum, mut count) = (vec![0.0; n], vec![0usize; n]);
    for (o, e) in r.obs.iter().zip(res) {
        sum[o.frame] += e * e;
        count[o.frame] += 1;
    }
    let w = ((0.03 * problem.dataset.fps).round() as usize).max(1);
    let (mut s, mut c) = (0.0, 0usize);
    for k in 0..n {
        s += sum[k];
        c += count[k];
        if k >= w {
            s -= sum[k - w];
            c -= count[k - w];
        }
        if k + 1 >= w && c > 0 && (s / c as f64).sqrt() > 2.0 * sigma {
            return Some(r.times[k + 1 - w]);
        }
    }
    None
}

/// The head marker's height (the first marker's y), measured and modelled, per run.
fn traces(
    problem: &Problem<'_>,
    base: &SwingModel,
    base_setting: &Setting,
    corrected: Option<(&SwingModel, &Setting)>,
) -> Result<Vec<RunTrace>> {
    let mut out = Vec::new();
    for r in &problem.runs {
        let fitted = |model: &SwingModel, s: &Setting| -> Result<Vec<f64>> {
            let pred = match problem.fit_runs().position(|f| f.id == r.id) {
                Some(j) => problem.predict(model, r, s.runs[j].0, s.runs[j].1),
                None => {
                    let raw = problem.refit_run(model, r)?;
                    r.obs.iter().zip(raw).map(|(o, e)| o.value - e).collect()
                }
            };
            Ok(pred)
        };
        let b = fitted(base, base_setting)?;
        let c = corrected.map(|(m, s)| fitted(m, s)).transpose()?;
        // Head marker (the first) per frame: measured and modelled x, y.
        let n = r.times.len();
        let mut meas = vec![[f64::NAN; 2]; n];
        let mut base_p = vec![[f64::NAN; 2]; n];
        let mut corr_p = vec![[f64::NAN; 2]; n];
        for (i, o) in r.obs.iter().enumerate().filter(|(_, o)| o.marker == 0) {
            meas[o.frame][o.axis] = o.value;
            base_p[o.frame][o.axis] = b[i];
            if let Some(c) = &c {
                corr_p[o.frame][o.axis] = c[i];
            }
        }
        // The residual along the swing: (Δx, Δy)·(−y, x)/r.
        let along = |m: [f64; 2], p: [f64; 2]| {
            let r = m[0].hypot(m[1]);
            ((m[0] - p[0]) * -m[1] + (m[1] - p[1]) * m[0]) / r
        };
        let mut t = RunTrace {
            run: r.id.clone(),
            heldout: r.role == Role::Heldout,
            t: Vec::new(),
            measured: Vec::new(),
            baseline: Vec::new(),
            corrected: c.as_ref().map(|_| Vec::new()),
            baseline_residual: Vec::new(),
            corrected_residual: c.as_ref().map(|_| Vec::new()),
        };
        for k in 0..n {
            if !(meas[k][0].is_finite() && meas[k][1].is_finite()) {
                continue;
            }
            t.t.push(r.times[k]);
            t.measured.push(meas[k][1]);
            t.baseline.push(base_p[k][1]);
            t.baseline_residual.push(along(meas[k], base_p[k]));
            if let (Some(cy), Some(cr)) = (t.corrected.as_mut(), t.corrected_residual.as_mut()) {
                cy.push(corr_p[k][1]);
                cr.push(along(meas[k], corr_p[k]));
            }
        }
        out.push(t);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(bic: f64, held: Option<f64>) -> Contender {
        Contender {
            bic,
            heldout_floors: held,
        }
    }

    #[test]
    fn the_decision_follows_the_rules() {
        // Nothing kept: the baseline's worst phase decides.
        assert_eq!(decide(&[], 1.2), Verdict::None);
        assert_eq!(decide(&[], 4.0), Verdict::Unexplained);
        // One clear winner, whatever the order.
        assert_eq!(
            decide(&[c(-50.0, Some(1.1)), c(-900.0, Some(1.0))], 9.0),
            Verdict::Named(1)
        );
        // A rival within 6 BIC units: ambiguous, rivals listed.
        assert_eq!(
            decide(
                &[c(-900.0, Some(1.0)), c(-896.0, Some(1.1)), c(-100.0, None)],
                9.0
            ),
            Verdict::Ambiguous(0, vec![1])
        );
        // The best leaves the held-out run 2.4 floors off: a look-alike.
        assert_eq!(
            decide(&[c(-900.0, Some(2.4)), c(-800.0, Some(1.0))], 9.0),
            Verdict::Partial(0, 2.4)
        );
        // No held-out run: nothing to fail on.
        assert_eq!(decide(&[c(-900.0, None)], 9.0), Verdict::Named(0));
    }
}
