//! What a fitting job did and how fast: fits, residual evaluations and simulations,
//! counted as they happen (from any thread) and reported per stage with their rates, so a
//! diagnosis can say where its time went in the units a user can act on.
//!
//! A **fit** is one call of the optimiser; an **evaluation** one call of its residual
//! function; a **simulation** one run of the model (an evaluation simulates each fitted
//! run, and may reuse a simulation it has already run, e.g. when only the camera's clock
//! moved).

use std::ops::Sub;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use serde::Serialize;

/// Counts of work done.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct WorkCount {
    /// Fits (optimiser calls).
    pub fits: usize,
    /// Residual evaluations.
    pub evaluations: usize,
    /// Simulations run.
    pub simulations: usize,
}

impl Sub for WorkCount {
    type Output = WorkCount;

    fn sub(self, earlier: WorkCount) -> WorkCount {
        WorkCount {
            fits: self.fits - earlier.fits,
            evaluations: self.evaluations - earlier.evaluations,
            simulations: self.simulations - earlier.simulations,
        }
    }
}

/// Counters the threads of a job add to.
///
/// ```
/// use mbs_identify::work::WorkCounter;
/// let work = WorkCounter::default();
/// std::thread::scope(|s| {
///     s.spawn(|| work.add_evaluation());
///     s.spawn(|| work.add_simulations(2));
/// });
/// work.add_fit();
/// let n = work.count();
/// assert_eq!((n.fits, n.evaluations, n.simulations), (1, 1, 2));
/// ```
#[derive(Debug, Default)]
pub struct WorkCounter {
    fits: AtomicUsize,
    evaluations: AtomicUsize,
    simulations: AtomicUsize,
}

impl WorkCounter {
    /// Counts a fit.
    pub fn add_fit(&self) {
        self.fits.fetch_add(1, Ordering::Relaxed);
    }

    /// Counts a residual evaluation.
    pub fn add_evaluation(&self) {
        self.evaluations.fetch_add(1, Ordering::Relaxed);
    }

    /// Counts `n` simulations.
    pub fn add_simulations(&self, n: usize) {
        self.simulations.fetch_add(n, Ordering::Relaxed);
    }

    /// The counts so far.
    pub fn count(&self) -> WorkCount {
        WorkCount {
            fits: self.fits.load(Ordering::Relaxed),
            evaluations: self.evaluations.load(Ordering::Relaxed),
            simulations: self.simulations.load(Ordering::Relaxed),
        }
    }
}

/// One stage's work and its rates, measured on the run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StageWork {
    /// The stage.
    pub stage: String,
    /// Its wall-clock time (s).
    pub wall_s: f64,
    /// Fits.
    pub fits: usize,
    /// Residual evaluations.
    pub evaluations: usize,
    /// Simulations run.
    pub simulations: usize,
    /// Fits per wall-clock second (0 for a stage without time).
    pub fits_per_s: f64,
    /// Residual evaluations per wall-clock second.
    pub evaluations_per_s: f64,
    /// Simulations per wall-clock second.
    pub simulations_per_s: f64,
}

impl StageWork {
    /// The stage `stage` that did `work` in `wall_s` seconds.
    pub fn new(stage: impl Into<String>, work: WorkCount, wall_s: f64) -> Self {
        let rate = |n: usize| if wall_s > 0.0 { n as f64 / wall_s } else { 0.0 };
        Self {
            stage: stage.into(),
            wall_s,
            fits: work.fits,
            evaluations: work.evaluations,
            simulations: work.simulations,
            fits_per_s: rate(work.fits),
            evaluations_per_s: rate(work.evaluations),
            simulations_per_s: rate(work.simulations),
        }
    }

    /// One line: `screening: 94 fits, 1450 evaluations, 1246 simulations in 34.3 s (2.74
    /// fits/s, 36.3 simulations/s)`.
    pub fn line(&self) -> String {
        format!(
            "{}: {} fits, {} evaluations, {} simulations in {:.1} s ({:.2} fits/s, {:.1} \
             simulations/s)",
            self.stage,
            self.fits,
            self.evaluations,
            self.simulations,
            self.wall_s,
            self.fits_per_s,
            self.simulations_per_s
        )
    }
}

/// Times the stages of a job and counts the work each did.
///
/// ```
/// use mbs_identify::work::{StageClock, WorkCounter};
/// let work = WorkCounter::default();
/// let mut clock = StageClock::new(&work);
/// work.add_fit();
/// work.add_evaluation();
/// clock.lap("calibration");
/// clock.lap("report");
/// let stages = clock.stages();
/// assert_eq!(stages.len(), 2);
/// assert_eq!((stages[0].fits, stages[1].fits), (1, 0));
/// ```
#[derive(Debug)]
pub struct StageClock<'a> {
    counter: &'a WorkCounter,
    start: Instant,
    last: (Instant, WorkCount),
    stages: Vec<StageWork>,
}

impl<'a> StageClock<'a> {
    /// A clock started now, reading `counter`.
    pub fn new(counter: &'a WorkCounter) -> Self {
        let now = Instant::now();
        Self {
            counter,
            start: now,
            last: (now, counter.count()),
            stages: Vec::new(),
        }
    }

    /// Ends the stage `stage` (begun at the last lap, or at the start).
    pub fn lap(&mut self, stage: &str) {
        let now = (Instant::now(), self.counter.count());
        let wall = now.0.duration_since(self.last.0).as_secs_f64();
        self.stages
            .push(StageWork::new(stage, now.1 - self.last.1, wall));
        self.last = now;
    }

    /// The whole job so far, as one stage named `total`.
    pub fn total(&self) -> StageWork {
        let wall = self.start.elapsed().as_secs_f64();
        let work = self
            .stages
            .iter()
            .fold(WorkCount::default(), |sum, s| WorkCount {
                fits: sum.fits + s.fits,
                evaluations: sum.evaluations + s.evaluations,
                simulations: sum.simulations + s.simulations,
            });
        StageWork::new("total", work, wall)
    }

    /// The stages so far, in order.
    pub fn stages(&self) -> Vec<StageWork> {
        self.stages.clone()
    }
}
