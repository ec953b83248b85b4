//! Checkpointed solves and solves resumed from a checkpoint with another system.

use mbs_integrators::{
    Crossing, EventAction, Method, OdeSystem, Options, Solution, SystemError, resume,
    solve_checkpointed, solve_observed,
};

/// A damped oscillator pushed by `a` once `t` passes `from`; its position crossing zero is
/// an event.
struct Pushed {
    a: f64,
    from: f64,
}

impl OdeSystem for Pushed {
    fn len(&self) -> usize {
        2
    }
    fn derivative(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        let push = if t > self.from { self.a } else { 0.0 };
        dy[0] = y[1];
        dy[1] = -400.0 * y[0] - 2.0 * y[1] + push;
        Ok(())
    }
    fn event_count(&self) -> usize {
        1
    }
    fn events(&mut self, _t: f64, y: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        out[0] = y[0];
        Ok(())
    }
    fn event_direction(&self, _k: usize) -> Crossing {
        Crossing::Both
    }
}

/// With the step ends recorded, so that a resumed solve's are checked too.
fn options() -> Options {
    Options {
        output_step: Some(1e-3),
        record_steps: true,
        ..Options::with_tolerances(1e-6, 1e-9)
    }
}

fn full(a: f64) -> Solution {
    solve_observed(
        &mut Pushed { a, from: 0.5 },
        Method::TrBdf2,
        0.0,
        &[0.01, 0.0],
        1.0,
        &options(),
        &mut |_, _| EventAction::Record,
        &mut |_| {},
    )
    .unwrap()
}

/// Checkpoints leave the solve as it was; a solve resumed with a system that differs only
/// after a checkpoint's last evaluation is that system's own solve, to the last bit
/// (output, events, work counts); resumed from later, it is not.
#[test]
fn a_resumed_solve_is_the_other_systems_own_solve() {
    let opts = options();
    let (base, checkpoints) = solve_checkpointed(
        &mut Pushed { a: 1.0, from: 0.5 },
        Method::TrBdf2,
        0.0,
        &[0.01, 0.0],
        1.0,
        &opts,
        &mut |_, _| EventAction::Record,
        &mut |_| {},
        0.05,
    )
    .unwrap();
    assert_eq!(base, full(1.0));
    assert_eq!(base.step_ends.len(), base.stats.steps);
    assert!(base.events.len() >= 4, "{} events", base.events.len());
    assert!(checkpoints.len() >= 18, "{} checkpoints", checkpoints.len());
    assert!(checkpoints.windows(2).all(|w| w[0].t < w[1].t));
    let other = full(3.0);
    let (mut before, mut after) = (0, 0);
    for c in &checkpoints {
        assert!(c.evaluated_until >= c.t);
        let resumed = resume(
            &mut Pushed { a: 3.0, from: 0.5 },
            Method::TrBdf2,
            &base,
            c,
            1.0,
            &opts,
            &mut |_, _| EventAction::Record,
            &mut |_| {},
        )
        .unwrap();
        if c.evaluated_until < 0.5 {
            assert_eq!(resumed, other, "from the checkpoint at {} s", c.t);
            before += 1;
        } else if c.t > 0.5 {
            assert_ne!(resumed.y_final, other.y_final, "from {} s", c.t);
            after += 1;
        }
    }
    assert!(before >= 8 && after >= 8, "{before} before, {after} after");
    // Other options, or another method: refused.
    let looser = Options::with_tolerances(1e-4, 1e-7);
    let refused = resume(
        &mut Pushed { a: 3.0, from: 0.5 },
        Method::TrBdf2,
        &base,
        &checkpoints[0],
        1.0,
        &looser,
        &mut |_, _| EventAction::Record,
        &mut |_| {},
    );
    assert!(refused.is_err());
    let bad_every = solve_checkpointed(
        &mut Pushed { a: 1.0, from: 0.5 },
        Method::TrBdf2,
        0.0,
        &[0.01, 0.0],
        1.0,
        &opts,
        &mut |_, _| EventAction::Record,
        &mut |_| {},
        0.0,
    );
    assert!(bad_every.is_err());
}
