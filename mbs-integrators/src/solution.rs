//! What a solve returns: output on a grid, the exact event list, statistics.

/// What to do when an event happens (returned by the event handler).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventAction {
    /// Record it and go on unchanged.
    Record,
    /// Record it and end the solve at the event time.
    Stop,
    /// Record it and continue from the state the handler wrote (an impact law, a
    /// switch of mode...). Integration restarts at the event time.
    Reset,
}

/// A located event.
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// Index of the switching function.
    pub index: usize,
    /// Which way it crossed zero (`Rising` or `Falling`, never `Both`).
    pub direction: crate::Crossing,
    /// Where the switching function comes from (the element of a multibody system), when
    /// the system says.
    pub source: Option<crate::EventSource>,
    /// Its name.
    pub name: String,
    /// Time of the zero crossing (located to the event tolerance; just after the crossing).
    pub time: f64,
    /// State at the event (before any reset).
    pub state: Vec<f64>,
    /// The action taken.
    pub action: EventAction,
}

/// Work done by a solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps (error too large, Newton failure or non-finite stage).
    pub rejected: usize,
    /// Of those, the ones rejected because Newton failed (or a stage was not finite) even
    /// with a fresh Jacobian; the rest failed the error estimate.
    pub rejected_newton: usize,
    /// Evaluations of the derivative (including those for finite-difference Jacobians).
    pub derivative_evals: usize,
    /// Jacobian evaluations (analytic or by finite differences).
    pub jacobian_evals: usize,
    /// LU factorisations of the iteration matrix.
    pub lu_decompositions: usize,
    /// Newton iterations.
    pub newton_iterations: usize,
    /// Newton failures (each followed by a fresh Jacobian or a smaller step).
    pub newton_failures: usize,
    /// Evaluations of the switching functions.
    pub event_evals: usize,
}

/// Why a solve ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Termination {
    /// The end time was reached.
    Finished,
    /// An event handler asked to stop.
    Stopped,
}

/// The result of a solve.
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Output times (the grid, or every accepted step).
    pub t: Vec<f64>,
    /// States at the output times, row after row (`n` numbers each).
    pub y: Vec<f64>,
    /// State length.
    pub n: usize,
    /// Events in time order.
    pub events: Vec<Event>,
    /// Work done.
    pub stats: Stats,
    /// Time reached.
    pub t_final: f64,
    /// State reached.
    pub y_final: Vec<f64>,
    /// Why the solve ended.
    pub termination: Termination,
    /// Where each accepted step ended (after a restart at an event, the event's time in
    /// place of the step's), when [`crate::Options::record_steps`] asked: strictly
    /// ascending, a mesh for [`crate::Options::mesh`]. Empty otherwise.
    pub step_ends: Vec<f64>,
}

impl Solution {
    /// Number of output points.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether there is no output point.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The state at output point `i`.
    pub fn state(&self, i: usize) -> &[f64] {
        &self.y[i * self.n..(i + 1) * self.n]
    }

    /// Component `k` at every output point.
    pub fn component(&self, k: usize) -> Vec<f64> {
        (0..self.len()).map(|i| self.y[i * self.n + k]).collect()
    }
}
