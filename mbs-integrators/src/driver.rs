//! The driver: steps a method from `t0` to `t_end`, reports the solution on a uniform grid,
//! and locates events on the dense output.

use crate::dopri5::Dopri5;
use crate::error::{IntegratorError, Result};
use crate::explicit::{Explicit, Scheme};
use crate::ode::{Crossing, OdeSystem};
use crate::options::{Method, Options};
use crate::rosenbrock::Ros34Pw2;
use crate::solution::{Event, EventAction, Solution, Stats, Termination};
use crate::stepper::{Control, Stepper};
use crate::trbdf2::TrBdf2;

/// Integrates `sys` from `(t0, y0)` to `t_end` with `method`, recording every event.
///
/// ```
/// use mbs_integrators::{Method, OdeSystem, Options, SystemError, solve};
/// /// ẏ = −y
/// struct Decay;
/// impl OdeSystem for Decay {
///     fn len(&self) -> usize { 1 }
///     fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
///         dy[0] = -y[0];
///         Ok(())
///     }
/// }
/// let opts = Options::with_tolerances(1e-10, 1e-12);
/// let sol = solve(&mut Decay, Method::DormandPrince54, 0.0, &[1.0], 1.0, &opts).unwrap();
/// assert!((sol.y_final[0] - (-1.0f64).exp()).abs() < 1e-9);
/// ```
pub fn solve(
    sys: &mut dyn OdeSystem,
    method: Method,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    opts: &Options,
) -> Result<Solution> {
    solve_with_events(sys, method, t0, y0, t_end, opts, &mut |_, _| {
        EventAction::Record
    })
}

/// Integrates like [`solve`], calling `handler` at each event with the event and a copy of
/// the state it may modify: returning [`EventAction::Reset`] continues from the modified
/// state, [`EventAction::Stop`] ends the solve, [`EventAction::Record`] goes on unchanged.
pub fn solve_with_events(
    sys: &mut dyn OdeSystem,
    method: Method,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    opts: &Options,
    handler: &mut dyn FnMut(&Event, &mut [f64]) -> EventAction,
) -> Result<Solution> {
    solve_observed(sys, method, t0, y0, t_end, opts, handler, &mut |_| {})
}

/// Integrates like [`solve_with_events`], calling `progress` with the time reached after
/// every accepted step (to drive a progress bar; it must be cheap).
#[allow(clippy::too_many_arguments)]
pub fn solve_observed(
    sys: &mut dyn OdeSystem,
    method: Method,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    opts: &Options,
    handler: &mut dyn FnMut(&Event, &mut [f64]) -> EventAction,
    progress: &mut dyn FnMut(f64),
) -> Result<Solution> {
    let (stepper, mut run) = begin(sys, method, t0, y0, t_end, opts)?;
    go_on(stepper, &mut run, t_end, opts, handler, progress, None)
}

/// A solve's whole state after an accepted step ([`solve_checkpointed`]), from which
/// [`resume`] goes on: the method's state (step size, Jacobian, factorisation), the output
/// and events so far (as counts into the solution it came from), the work counts.
pub struct Checkpoint {
    stepper: Box<dyn Stepper + Send + Sync>,
    method: Method,
    opts: Options,
    t0: f64,
    /// The time reached (s).
    pub t: f64,
    /// The latest time at which the system had been evaluated when it was taken (s): a
    /// step tried and rejected may have looked beyond [`Checkpoint::t`]. A system that
    /// agrees with the one solved wherever it was evaluated before that time goes on from
    /// here exactly as its own solve would, to the last bit.
    pub evaluated_until: f64,
    outputs: usize,
    next_grid: usize,
    events: usize,
    step_ends: usize,
    stats: Stats,
    g_prev: Vec<f64>,
}

impl std::fmt::Debug for Checkpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Checkpoint")
            .field("t", &self.t)
            .field("evaluated_until", &self.evaluated_until)
            .field("outputs", &self.outputs)
            .field("events", &self.events)
            .finish_non_exhaustive()
    }
}

/// Integrates like [`solve_observed`] and keeps a [`Checkpoint`] after the first accepted
/// step past every multiple of `every` (s) from `t0`, in time order. Only the TR-BDF2
/// method offers them: another gives none. The solution is the same as
/// [`solve_observed`]'s, to the last bit.
#[allow(clippy::too_many_arguments)]
pub fn solve_checkpointed(
    sys: &mut dyn OdeSystem,
    method: Method,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    opts: &Options,
    handler: &mut dyn FnMut(&Event, &mut [f64]) -> EventAction,
    progress: &mut dyn FnMut(f64),
    every: f64,
) -> Result<(Solution, Vec<Checkpoint>)> {
    if !(every.is_finite() && every > 0.0) {
        return Err(IntegratorError::InvalidOption {
            option: "every",
            message: format!("checkpoints every {every} s: need a positive time"),
        });
    }
    let until = std::cell::Cell::new(f64::NEG_INFINITY);
    let mut watched = Watched { sys, until: &until };
    let (stepper, mut run) = begin(&mut watched, method, t0, y0, t_end, opts)?;
    let mut kept = Vec::new();
    let mut keep = Keep {
        every,
        next: t0 + every,
        method,
        opts,
        until: &until,
        kept: &mut kept,
    };
    let sol = go_on(
        stepper,
        &mut run,
        t_end,
        opts,
        handler,
        progress,
        Some(&mut keep),
    )?;
    Ok((sol, kept))
}

/// Goes on from `checkpoint`, taken in the solve that gave `base` ([`solve_checkpointed`]),
/// with the system `sys` up to `t_end`: `base`'s output and events up to the checkpoint,
/// then `sys`'s. When `sys` agrees with the system `base` was solved with wherever that one
/// was evaluated before [`Checkpoint::evaluated_until`] (the same number of states, the
/// same rates and Jacobians there), and `t_end` is `base`'s (a step clipped to reach an
/// end, then rejected, leaves its mark on the steps that follow), the result is `sys`'s
/// own solve from `base`'s start, to the last bit (its work counts included). Fails when
/// `opts` or `method` differ from the checkpoint's, or when `base` is shorter than it.
#[allow(clippy::too_many_arguments)]
pub fn resume(
    sys: &mut dyn OdeSystem,
    method: Method,
    base: &Solution,
    checkpoint: &Checkpoint,
    t_end: f64,
    opts: &Options,
    handler: &mut dyn FnMut(&Event, &mut [f64]) -> EventAction,
    progress: &mut dyn FnMut(f64),
) -> Result<Solution> {
    if method != checkpoint.method || *opts != checkpoint.opts {
        return Err(IntegratorError::InvalidOption {
            option: "method",
            message: "a solve resumes with the method and options of its checkpoint".into(),
        });
    }
    let n = sys.len();
    if base.n != n
        || base.t.len() < checkpoint.outputs
        || base.y.len() < checkpoint.outputs * n
        || base.events.len() < checkpoint.events
        || base.step_ends.len() < checkpoint.step_ends
        || sys.event_count() != checkpoint.g_prev.len()
    {
        return Err(IntegratorError::InvalidInitialCondition(
            "the checkpoint does not belong to this solution and system".into(),
        ));
    }
    if !(t_end.is_finite() && t_end >= checkpoint.t) {
        return Err(IntegratorError::InvalidInitialCondition(format!(
            "need a finite t_end >= the checkpoint's {}, got {t_end}",
            checkpoint.t
        )));
    }
    let stepper =
        checkpoint
            .stepper
            .boxed_clone()
            .ok_or_else(|| IntegratorError::InvalidOption {
                option: "method",
                message: "the checkpoint's method cannot be copied".into(),
            })?;
    let mut run = Run::new(sys, opts, n, checkpoint.t0);
    run.t.extend_from_slice(&base.t[..checkpoint.outputs]);
    run.y.extend_from_slice(&base.y[..checkpoint.outputs * n]);
    run.events
        .extend_from_slice(&base.events[..checkpoint.events]);
    run.step_ends
        .extend_from_slice(&base.step_ends[..checkpoint.step_ends]);
    run.next_grid = checkpoint.next_grid;
    run.stats = checkpoint.stats;
    run.g_prev.copy_from_slice(&checkpoint.g_prev);
    go_on(stepper, &mut run, t_end, opts, handler, progress, None)
}

/// Where a checkpointed solve keeps its checkpoints.
struct Keep<'k> {
    every: f64,
    next: f64,
    method: Method,
    opts: &'k Options,
    /// The latest time the system was evaluated at ([`Watched`]).
    until: &'k std::cell::Cell<f64>,
    kept: &'k mut Vec<Checkpoint>,
}

/// A system that notes the latest time it is evaluated at (for [`Checkpoint`]); it
/// forwards every call.
struct Watched<'a> {
    sys: &'a mut dyn OdeSystem,
    until: &'a std::cell::Cell<f64>,
}

impl Watched<'_> {
    fn saw(&mut self, t: f64) {
        if t > self.until.get() {
            self.until.set(t);
        }
    }
}

impl OdeSystem for Watched<'_> {
    fn len(&self) -> usize {
        self.sys.len()
    }
    fn is_empty(&self) -> bool {
        self.sys.is_empty()
    }
    fn derivative(
        &mut self,
        t: f64,
        y: &[f64],
        dy: &mut [f64],
    ) -> std::result::Result<(), crate::SystemError> {
        self.saw(t);
        self.sys.derivative(t, y, dy)
    }
    fn has_jacobian(&self) -> bool {
        self.sys.has_jacobian()
    }
    fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        jac: &mut nalgebra::DMatrix<f64>,
    ) -> std::result::Result<(), crate::SystemError> {
        self.saw(t);
        self.sys.jacobian(t, y, jac)
    }
    fn jacobian_given_rate(
        &mut self,
        t: f64,
        y: &[f64],
        f: &[f64],
        jac: &mut nalgebra::DMatrix<f64>,
    ) -> std::result::Result<(), crate::SystemError> {
        self.saw(t);
        self.sys.jacobian_given_rate(t, y, f, jac)
    }
    fn states_outside_jacobian(&self) -> Vec<std::ops::Range<usize>> {
        self.sys.states_outside_jacobian()
    }
    fn second_order_split(&self) -> Option<usize> {
        self.sys.second_order_split()
    }
    fn event_count(&self) -> usize {
        self.sys.event_count()
    }
    fn events(
        &mut self,
        t: f64,
        y: &[f64],
        out: &mut [f64],
    ) -> std::result::Result<(), crate::SystemError> {
        self.saw(t);
        self.sys.events(t, y, out)
    }
    fn event_direction(&self, k: usize) -> Crossing {
        self.sys.event_direction(k)
    }
    fn event_source(&self, k: usize) -> Option<crate::EventSource> {
        self.sys.event_source(k)
    }
    fn event_name(&self, k: usize) -> String {
        self.sys.event_name(k)
    }
}

/// Checks the start and builds the method and the bookkeeping, at `(t0, y0)`.
fn begin<'s>(
    sys: &'s mut dyn OdeSystem,
    method: Method,
    t0: f64,
    y0: &[f64],
    t_end: f64,
    opts: &Options,
) -> Result<(Box<dyn Stepper + 's>, Run<'s>)> {
    opts.validate(method)?;
    if let Some(mesh) = &opts.mesh
        && mesh.last().is_none_or(|&last| last < t_end * (1.0 - 1e-12))
    {
        return Err(IntegratorError::InvalidOption {
            option: "mesh",
            message: format!(
                "it ends at {} s, before the solve's end {t_end} s",
                mesh.last().copied().unwrap_or(f64::NAN)
            ),
        });
    }
    let n = sys.len();
    if y0.len() != n {
        return Err(IntegratorError::InvalidInitialCondition(format!(
            "y0 has length {}, the system {n}",
            y0.len()
        )));
    }
    if let Some((i, v)) = y0.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(IntegratorError::InvalidInitialCondition(format!(
            "y0[{i}] is not finite ({v})"
        )));
    }
    if !(t0.is_finite() && t_end.is_finite() && t_end >= t0) {
        return Err(IntegratorError::InvalidInitialCondition(format!(
            "need finite t0 <= t_end, got t0 = {t0}, t_end = {t_end}"
        )));
    }
    let ctl = Control::new(opts);
    let mut stepper: Box<dyn Stepper> = match method {
        Method::SemiImplicitEuler => Box::new(Explicit::new(
            Scheme::SemiImplicitEuler,
            n,
            &ctl,
            sys.second_order_split(),
        )?),
        Method::Rk4 => Box::new(Explicit::new(Scheme::Rk4, n, &ctl, None)?),
        Method::DormandPrince54 => Box::new(Dopri5::new(n, &ctl)),
        Method::TrBdf2 => Box::new(TrBdf2::new(n, &ctl)),
        Method::Ros34Pw2 => Box::new(Ros34Pw2::new(n, &ctl)),
    };
    let mut run = Run::new(sys, opts, n, t0);
    stepper.start(run.sys, t0, y0, &mut run.stats)?;
    run.output_point(t0, y0);
    run.init_events(t0, y0)?;
    Ok((stepper, run))
}

/// Steps `stepper` on to `t_end`, keeping checkpoints in `keep` if given.
fn go_on(
    mut stepper: Box<dyn Stepper + '_>,
    run: &mut Run<'_>,
    t_end: f64,
    opts: &Options,
    handler: &mut dyn FnMut(&Event, &mut [f64]) -> EventAction,
    progress: &mut dyn FnMut(f64),
    mut keep: Option<&mut Keep<'_>>,
) -> Result<Solution> {
    let mut termination = Termination::Finished;
    let mut since_check = 0;
    while stepper.t() < t_end {
        since_check += 1;
        if since_check >= crate::interrupt::EVERY {
            since_check = 0;
            if crate::interrupt::interrupted() {
                return Err(IntegratorError::Interrupted { t: stepper.t() });
            }
        }
        if run.stats.steps >= opts.max_steps {
            return Err(IntegratorError::TooManySteps {
                t: stepper.t(),
                max_steps: opts.max_steps,
            });
        }
        stepper.step(run.sys, t_end, &mut run.stats)?;
        let t_reached = stepper.t();
        if opts.record_steps {
            run.step_ends.push(t_reached);
        }
        progress(t_reached);
        match run.scan_events(stepper.as_ref(), handler)? {
            None => {
                run.output_until(stepper.as_ref(), t_reached, true);
                run.g_prev.copy_from_slice(&run.g_end);
            }
            Some((t_event, action, y_event)) => {
                run.output_until(stepper.as_ref(), t_event, false);
                // The step, cut back, ends at the event (none is left if that is where
                // the one before ended).
                if opts.record_steps {
                    run.step_ends.pop();
                    if run.step_ends.last().is_none_or(|&e| e < t_event) {
                        run.step_ends.push(t_event);
                    }
                }
                if action == EventAction::Stop {
                    run.output_point_if_stepwise(t_event, &y_event);
                    run.finish_at(t_event, &y_event);
                    termination = Termination::Stopped;
                    break;
                }
                stepper.start(run.sys, t_event, &y_event, &mut run.stats)?;
                run.init_events(t_event, &y_event)?;
            }
        }
        if let Some(k) = keep.as_deref_mut()
            && stepper.t() >= k.next
            && stepper.t() < t_end
        {
            while k.next <= stepper.t() {
                k.next += k.every;
            }
            if let Some(copy) = stepper.boxed_clone() {
                k.kept.push(Checkpoint {
                    stepper: copy,
                    method: k.method,
                    opts: k.opts.clone(),
                    t0: run.t0,
                    t: stepper.t(),
                    evaluated_until: k.until.get(),
                    outputs: run.t.len(),
                    next_grid: run.next_grid,
                    events: run.events.len(),
                    step_ends: run.step_ends.len(),
                    stats: run.stats,
                    g_prev: run.g_prev.clone(),
                });
            }
        }
    }
    if termination == Termination::Finished {
        let (t, y) = (stepper.t(), stepper.y().to_vec());
        if opts.output_step.is_some() {
            // The grid may not land on t_end: close the record there.
            if run.t.last().is_none_or(|&last| last < t) {
                run.output_point(t, &y);
            }
        }
        run.finish_at(t, &y);
    }
    Ok(Solution {
        t: std::mem::take(&mut run.t),
        y: std::mem::take(&mut run.y),
        n: run.n,
        events: std::mem::take(&mut run.events),
        stats: run.stats,
        t_final: run.t_final,
        y_final: std::mem::take(&mut run.y_final),
        termination,
        step_ends: std::mem::take(&mut run.step_ends),
    })
}

/// The bookkeeping of one solve.
struct Run<'s> {
    sys: &'s mut dyn OdeSystem,
    n: usize,
    t0: f64,
    output_step: Option<f64>,
    next_grid: usize,
    event_tol: f64,
    samples: usize,
    t: Vec<f64>,
    y: Vec<f64>,
    events: Vec<Event>,
    step_ends: Vec<f64>,
    stats: Stats,
    m: usize,
    g_prev: Vec<f64>,
    g_end: Vec<f64>,
    g_a: Vec<f64>,
    g_b: Vec<f64>,
    g_mid: Vec<f64>,
    y_tmp: Vec<f64>,
    t_final: f64,
    y_final: Vec<f64>,
}

impl<'s> Run<'s> {
    fn new(sys: &'s mut dyn OdeSystem, opts: &Options, n: usize, t0: f64) -> Self {
        let m = sys.event_count();
        Self {
            sys,
            n,
            t0,
            output_step: opts.output_step,
            next_grid: 0,
            event_tol: opts.event_tolerance,
            samples: opts.event_samples,
            t: Vec::new(),
            y: Vec::new(),
            events: Vec::new(),
            step_ends: Vec::new(),
            stats: Stats::default(),
            m,
            g_prev: vec![0.0; m],
            g_end: vec![0.0; m],
            g_a: vec![0.0; m],
            g_b: vec![0.0; m],
            g_mid: vec![0.0; m],
            y_tmp: vec![0.0; n],
            t_final: t0,
            y_final: Vec::new(),
        }
    }

    fn output_point(&mut self, t: f64, y: &[f64]) {
        self.t.push(t);
        self.y.extend_from_slice(y);
        if self.output_step.is_some() {
            self.next_grid += 1;
        }
    }

    /// After a stop with output at every step, the stopping point is a step end.
    fn output_point_if_stepwise(&mut self, t: f64, y: &[f64]) {
        if self.output_step.is_none() && self.t.last() != Some(&t) {
            self.output_point(t, y);
        }
    }

    fn finish_at(&mut self, t: f64, y: &[f64]) {
        self.t_final = t;
        self.y_final = y.to_vec();
    }

    /// Output up to `t_until` from the stepper's last step: grid points at or before it
    /// (interpolated), or, without a grid, the step end when `step_end` is set.
    fn output_until(&mut self, st: &dyn Stepper, t_until: f64, step_end: bool) {
        match self.output_step {
            None => {
                if step_end {
                    self.t.push(st.t());
                    self.y.extend_from_slice(st.y());
                }
            }
            Some(dt) => loop {
                let tg = self.t0 + self.next_grid as f64 * dt;
                if tg > t_until + 1e-12 * dt {
                    break;
                }
                let tg = tg.min(t_until);
                // Into the scratch state, then appended: no allocation per output point.
                let mut y = std::mem::take(&mut self.y_tmp);
                st.interpolate(tg.max(st.t_prev()), &mut y);
                self.t.push(tg);
                self.y.extend_from_slice(&y);
                self.y_tmp = y;
                self.next_grid += 1;
            },
        }
    }

    fn eval_events(&mut self, t: f64, y: &[f64], out_b: bool) -> Result<()> {
        if self.m == 0 {
            return Ok(());
        }
        self.stats.event_evals += 1;
        let out = if out_b {
            &mut self.g_b
        } else {
            &mut self.g_mid
        };
        self.sys
            .events(t, y, out)
            .map_err(|source| IntegratorError::System { t, source })?;
        if let Some(k) = out.iter().position(|g| !g.is_finite()) {
            return Err(IntegratorError::System {
                t,
                source: crate::SystemError::new(format!(
                    "switching function '{}' is not finite",
                    self.sys.event_name(k)
                )),
            });
        }
        Ok(())
    }

    fn init_events(&mut self, t: f64, y: &[f64]) -> Result<()> {
        if self.m == 0 {
            return Ok(());
        }
        self.eval_events(t, y, true)?;
        self.g_prev.copy_from_slice(&self.g_b);
        Ok(())
    }

    /// Looks for crossings during the last step, at `samples` points of the dense output.
    /// Events are handled in time order; returns the first that stops or resets the
    /// solve, with the state to go on from.
    fn scan_events(
        &mut self,
        st: &dyn Stepper,
        handler: &mut dyn FnMut(&Event, &mut [f64]) -> EventAction,
    ) -> Result<Option<(f64, EventAction, Vec<f64>)>> {
        if self.m == 0 {
            return Ok(None);
        }
        let (t0, t1) = (st.t_prev(), st.t());
        // Found crossings: (time, function).
        let mut found: Vec<(f64, usize, Crossing)> = Vec::new();
        self.g_a.copy_from_slice(&self.g_prev);
        let mut ta = t0;
        for s in 1..=self.samples {
            let tb = if s == self.samples {
                t1
            } else {
                t0 + (t1 - t0) * s as f64 / self.samples as f64
            };
            if s == self.samples {
                let mut y = std::mem::take(&mut self.y_tmp);
                y.copy_from_slice(st.y());
                let r = self.eval_events(tb, &y, true);
                self.y_tmp = y;
                r?;
            } else {
                let mut y = std::mem::take(&mut self.y_tmp);
                st.interpolate(tb, &mut y);
                let r = self.eval_events(tb, &y, true);
                self.y_tmp = y;
                r?;
            }
            for k in 0..self.m {
                let dir = self.sys.event_direction(k);
                if dir.crosses(self.g_a[k], self.g_b[k]) {
                    let tk = self.locate(st, k, ta, tb, self.g_a[k], self.g_b[k])?;
                    found.push((tk, k, Crossing::observed(self.g_a[k])));
                }
            }
            ta = tb;
            self.g_a.copy_from_slice(&self.g_b);
        }
        self.g_end.copy_from_slice(&self.g_b);
        found.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for (te, k, direction) in found {
            let mut y = vec![0.0; self.n];
            st.interpolate(te, &mut y);
            let mut event = Event {
                index: k,
                direction,
                source: self.sys.event_source(k),
                name: self.sys.event_name(k),
                time: te,
                state: y.clone(),
                action: EventAction::Record,
            };
            let action = handler(&event, &mut y);
            event.action = action;
            self.events.push(event);
            match action {
                EventAction::Record => {}
                EventAction::Stop => {
                    let y0 = self.events.last().map(|e| e.state.clone()).unwrap_or(y);
                    return Ok(Some((te, action, y0)));
                }
                EventAction::Reset => {
                    if let Some((i, v)) = y.iter().enumerate().find(|(_, v)| !v.is_finite()) {
                        return Err(IntegratorError::NonFiniteState {
                            t: te,
                            index: i,
                            value: *v,
                        });
                    }
                    return Ok(Some((te, action, y)));
                }
            }
        }
        Ok(None)
    }

    /// The crossing of function `k` between `ta` (value `ga`) and `tb` (value `gb`), by the
    /// Illinois variant of regula falsi on the dense output, to the event tolerance. The
    /// time returned is on the far side of the crossing.
    fn locate(
        &mut self,
        st: &dyn Stepper,
        k: usize,
        ta: f64,
        tb: f64,
        ga: f64,
        gb: f64,
    ) -> Result<f64> {
        let (mut a, mut b, mut fa, mut fb) = (ta, tb, ga, gb);
        // Sides: negative, or non-negative (zero included), as in `Crossing::crosses`.
        let a_negative = ga < 0.0;
        let mut side = 0i32;
        let mut y = vec![0.0; self.n];
        let tol = self.event_tol.max(4.0 * f64::EPSILON * tb.abs());
        let mut widths = [f64::INFINITY; 2];
        for _ in 0..500 {
            let w = b - a;
            if w <= tol {
                break;
            }
            // Regula falsi (Illinois), but bisect when the bracket has not halved in two
            // iterations, so the worst case is bisection's.
            let mut c = if w > 0.5 * widths[0] {
                0.5 * (a + b)
            } else {
                b - fb * (b - a) / (fb - fa)
            };
            if !(c > a && c < b) {
                c = 0.5 * (a + b);
            }
            widths = [widths[1], w];
            st.interpolate(c, &mut y);
            self.eval_events(c, &y, false)?;
            let fc = self.g_mid[k];
            if (fc < 0.0) == a_negative {
                a = c;
                fa = fc;
                if side == -1 {
                    fb *= 0.5;
                }
                side = -1;
            } else {
                b = c;
                fb = fc;
                if side == 1 {
                    fa *= 0.5;
                }
                side = 1;
            }
        }
        Ok(b)
    }
}
