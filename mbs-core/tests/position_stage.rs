//! The position stage: an element's pose-only results are computed once per system
//! revision, time and coordinates, and every evaluation at that state reads them from
//! `ForceContext::positions`: the derivative, the switching functions, the derivative at
//! other velocities (a Jacobian's velocity columns). New coordinates, a new time or a
//! changed system compute them again.

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use mbs_core::time_function::SmoothMove;
use mbs_core::{
    BodySpec, ForceContext, ForceElement, JointKind, Loads, ModelBuilder, Placement, System,
};

/// A spring pulling the tip of the second link toward a fixed point, whose stretch is
/// its position-stage result; it counts the times the stage runs.
struct TipSpring {
    runs: Arc<AtomicUsize>,
}

impl TipSpring {
    fn stretch(ctx: &ForceContext<'_>) -> f64 {
        let b = ctx.model.body_id("b").expect("body b");
        let tip = ctx.point_position(b, [0.1, 0.0]);
        (tip[0] - 0.15).hypot(tip[1] + 0.05)
    }
}

impl ForceElement for TipSpring {
    fn name(&self) -> &str {
        "tip spring"
    }
    fn position_len(&self) -> usize {
        1
    }
    fn positions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        assert!(
            ctx.positions.is_empty(),
            "the stage computes, it does not read"
        );
        self.runs.fetch_add(1, Ordering::Relaxed);
        out[0] = Self::stretch(ctx);
    }
    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, _rates: &mut [f64]) {
        // What the stage handed over is what the poses give.
        assert_eq!(ctx.positions.len(), 1);
        assert_eq!(ctx.positions[0].to_bits(), Self::stretch(ctx).to_bits());
        loads.add_generalized(1, -10.0 * ctx.positions[0]);
    }
    fn switch_count(&self) -> usize {
        1
    }
    fn switching_functions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        out[0] = ctx.positions[0] - 0.1;
    }
}

#[test]
fn pose_results_are_computed_once_per_state() {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81]);
    b.add_link(
        "a",
        None,
        JointKind::Revolute,
        Placement::offset(0.0, 0.0),
        BodySpec::new(0.1, [0.05, 0.0], 1e-4),
    );
    b.add_link(
        "b",
        Some("a"),
        JointKind::Revolute,
        Placement::offset(0.1, 0.0),
        BodySpec::new(0.1, [0.05, 0.0], 1e-4),
    );
    let model = b.build().unwrap();
    let mut system = System::new(model);
    let runs = Arc::new(AtomicUsize::new(0));
    system
        .add_element(TipSpring { runs: runs.clone() })
        .unwrap();
    let mut ws = system.workspace();
    let count = || runs.load(Ordering::Relaxed);
    let x = system
        .initial_state(0.0, &[0.3, -0.2], &[1.0, 2.0])
        .unwrap();
    let mut xdot = vec![0.0; system.state_len()];
    let mut g = vec![0.0; system.switch_len()];

    system.derivative(&mut ws, 0.1, &x, &mut xdot).unwrap();
    assert_eq!(count(), 1);
    // The switching functions at the same state, and the derivative at other velocities,
    // reuse it.
    system
        .switching_functions(&mut ws, 0.1, &x, &mut g)
        .unwrap();
    let mut xv = x.clone();
    xv[2] += 1e-6;
    system.derivative(&mut ws, 0.1, &xv, &mut xdot).unwrap();
    assert_eq!(count(), 1);
    // New coordinates or a new time: computed again.
    let mut xq = x.clone();
    xq[1] += 1e-9;
    system.derivative(&mut ws, 0.1, &xq, &mut xdot).unwrap();
    assert_eq!(count(), 2);
    system.derivative(&mut ws, 0.2, &xq, &mut xdot).unwrap();
    assert_eq!(count(), 3);
    // A changed system (a drive now sets the first joint): computed again, never reused
    // from before the change.
    system
        .prescribe("a", SmoothMove::new(0.0, 0.0, 1.0, 1.0).unwrap())
        .unwrap();
    system.derivative(&mut ws, 0.2, &xq, &mut xdot).unwrap();
    assert_eq!(count(), 4);
    // A workspace of its own computes its own.
    let mut other = system.workspace();
    system.derivative(&mut other, 0.2, &xq, &mut xdot).unwrap();
    assert_eq!(count(), 5);
    // The system's kinematics for outputs need no element results.
    system.kinematics(&mut ws, 0.2, &xq).unwrap();
    assert_eq!(count(), 5);
    let mut xk = xq.clone();
    xk[0] += 1e-3;
    system.kinematics(&mut ws, 0.3, &xk).unwrap();
    assert_eq!(count(), 5);
    // ... and leave the cache of the coordinates it was computed at.
    system.derivative(&mut ws, 0.2, &xq, &mut xdot).unwrap();
    assert_eq!(count(), 5);
    system.derivative(&mut ws, 0.3, &xk, &mut xdot).unwrap();
    assert_eq!(count(), 6);
}
