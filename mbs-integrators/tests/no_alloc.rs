//! One driver step allocates nothing: with the counting allocator of `mbs_core` installed,
//! the allocations made between two accepted steps of a solve are counted (the `progress`
//! callback runs after every accepted step) and must be zero once the integrator has warmed
//! up, for TR-BDF2 (Newton, Jacobian, stage solves) and Dormand–Prince, with switching
//! functions scanned on every step, Newton failures and Jacobians at the failed iterate
//! included. A step that records an event stores its state (that allocates by design) and
//! is left out.

use mbs_core::alloc_count::{Counting, allocations, allocations_in};
use mbs_core::elements::{FrictionLaw, JointLimit, PivotFriction};
use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement, System};
use mbs_integrators::{Method, MultibodyOde, Options, solve_observed};

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_counter_sees_allocations() {
    let n = allocations_in(|| drop(std::hint::black_box(vec![1.0f64; 16])));
    assert!(n >= 1);
}

/// A pendulum released from the horizontal onto a stiff stop just past the bottom, with
/// friction in its pivot: smooth swinging, then stiff contact with the stop.
fn pendulum_on_a_stop() -> System {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81]);
    b.add_link(
        "arm",
        None,
        JointKind::Revolute,
        Placement::offset(0.0, 0.0),
        BodySpec::new(0.05, [0.1, 0.0], 2e-5),
    );
    let model = b.build().unwrap();
    let mut system = System::new(model.clone());
    system
        .add_element(PivotFriction::new(&model, "arm", FrictionLaw::coulomb(1e-4, 1e-2)).unwrap())
        .unwrap();
    system
        .add_element(JointLimit::new(&model, "arm", -1.4, 0.5, 2e3, 0.05).unwrap())
        .unwrap();
    system
}

/// Allocations between consecutive accepted steps, as (end of the step, count), and the
/// event times of the solve.
fn per_step(method: Method) -> (Vec<(f64, usize)>, Vec<f64>) {
    let system = pendulum_on_a_stop();
    let mut ode = MultibodyOde::new(&system);
    let y0 = system.initial_state(0.0, &[0.0], &[0.0]).unwrap();
    let t_end = 0.6;
    // Output only at the start and the end: output points are stored, by design.
    let opts = Options::with_tolerances(1e-6, 1e-9).output_every(t_end);
    let mut marks: Vec<(f64, usize)> = Vec::with_capacity(100_000);
    let sol = solve_observed(
        &mut ode,
        method,
        0.0,
        &y0,
        t_end,
        &opts,
        &mut |_, _| mbs_integrators::EventAction::Record,
        &mut |t| {
            if marks.len() < marks.capacity() {
                marks.push((t, allocations()));
            }
        },
    )
    .unwrap();
    let events = sol.events.iter().map(|e| e.time).collect();
    (marks, events)
}

fn check(method: Method) {
    let (marks, events) = per_step(method);
    assert!(
        !events.is_empty(),
        "{method:?}: the pendulum reaches its stop"
    );
    assert!(marks.len() > 40, "{method:?}: {} steps", marks.len());
    let mut checked = 0;
    for w in marks.windows(3).skip(5) {
        let ((t_before, _), (t0, a0), (t1, a1)) = (w[0], w[1], w[2]);
        // `progress` runs before a step's events are located and recorded, so an event of
        // the step before shows in this one's count: both are left out.
        if events
            .iter()
            .any(|&e| e > t_before - 1e-9 && e <= t1 + 1e-9)
        {
            continue;
        }
        assert_eq!(
            a1 - a0,
            0,
            "{method:?}: the step from {t0:.6} s to {t1:.6} s allocated {} times",
            a1 - a0
        );
        checked += 1;
    }
    assert!(checked > 30, "{method:?}: only {checked} steps checked");
}

#[test]
fn a_trbdf2_step_does_not_allocate() {
    check(Method::TrBdf2);
}

#[test]
fn a_dormand_prince_step_does_not_allocate() {
    check(Method::DormandPrince54);
}
