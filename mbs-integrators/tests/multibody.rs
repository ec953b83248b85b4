//! Running `mbs_core::System`s through the integrators with `MultibodyOde`.

use mbs_core::benchmarks::planar_chain;
use mbs_core::elements::{Attachment, FrictionLaw, PivotFriction, PointSpringDamper, SpringLaw};
use mbs_core::time_function::Sinusoid;
use mbs_core::{BodySpec, Drive, JointKind, ModelBuilder, Placement, System};
use mbs_integrators::{EventAction, Method, MultibodyOde, Options, solve, solve_with_events};

fn energy(system: &System, t: f64, x: &[f64]) -> f64 {
    let mut ws = system.workspace();
    system.energy(&mut ws, t, x).unwrap().total()
}

#[test]
fn five_link_chain_conserves_energy_under_dopri5_and_agrees_with_rk4() {
    let system = System::new(planar_chain(5));
    let x0 = system
        .initial_state(
            0.0,
            &[0.3, -0.2, 0.5, 0.1, -0.4],
            &[0.0, 1.0, -0.5, 0.2, 0.0],
        )
        .unwrap();
    let e0 = energy(&system, 0.0, &x0);
    let opts = Options::with_tolerances(1e-10, 1e-10).output_every(0.1);
    let mut ode = MultibodyOde::new(&system);
    let sol = solve(&mut ode, Method::DormandPrince54, 0.0, &x0, 1.0, &opts).unwrap();
    assert_eq!(sol.len(), 11);
    for i in 0..sol.len() {
        let e = energy(&system, sol.t[i], sol.state(i));
        assert!(
            (e - e0).abs() < 1e-7 * e0.abs().max(1.0),
            "t = {}: ΔE = {:e}",
            sol.t[i],
            e - e0
        );
    }
    let mut ode = MultibodyOde::new(&system);
    let fine = solve(
        &mut ode,
        Method::Rk4,
        0.0,
        &x0,
        1.0,
        &Options::default().fixed(1e-4),
    )
    .unwrap();
    let d = sol
        .y_final
        .iter()
        .zip(&fine.y_final)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(d < 1e-7, "DOPRI5 vs fine RK4 differ by {d:e}");
}

#[test]
fn symplectic_euler_runs_a_multibody_system_with_bounded_energy_error() {
    // A rod pendulum swinging ±1.07 rad about the bottom (q = −π/2).
    let system = System::new(planar_chain(1));
    let x0 = system.initial_state(0.0, &[-0.5], &[0.0]).unwrap();
    let e0 = energy(&system, 0.0, &x0);
    let mut ode = MultibodyOde::new(&system);
    let opts = Options::default().fixed(1e-3).output_every(0.05);
    let sol = solve(&mut ode, Method::SemiImplicitEuler, 0.0, &x0, 10.0, &opts).unwrap();
    let dev: Vec<f64> = (0..sol.len())
        .map(|i| (energy(&system, sol.t[i], sol.state(i)) - e0).abs())
        .collect();
    let (first, last) = (&dev[..20], &dev[dev.len() - 20..]);
    let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
    // Bounded: the error late in the run is of the same size as early on, not growing.
    assert!(
        max(&dev) < 0.05 * e0.abs().max(1.0),
        "max ΔE {:e}",
        max(&dev)
    );
    assert!(max(first) > 0.0);
    assert!(
        max(last) < 2.0 * max(first),
        "{} vs {}",
        max(last),
        max(first)
    );
}

#[test]
fn friction_reversal_events_come_out_named_at_the_turning_points() {
    // A pendulum with light pivot friction swings back and forth: each turning point is a
    // velocity reversal, reported by name.
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81]).add_link(
        "hammer",
        None,
        JointKind::Revolute,
        Placement::default(),
        BodySpec::rod(0.01, 0.1),
    );
    let model = b.build().unwrap();
    let mut system = System::new(model.clone());
    let law = FrictionLaw::coulomb(1e-5, 1e-3).with_viscous(1e-6);
    system
        .add_element(
            PivotFriction::new(&model, "hammer", law)
                .unwrap()
                .with_reversal_events(),
        )
        .unwrap();
    let x0 = system.initial_state(0.0, &[-1.2], &[0.0]).unwrap();
    let mut ode = MultibodyOde::new(&system);
    let opts = Options::with_tolerances(1e-9, 1e-12);
    let sol = solve(&mut ode, Method::DormandPrince54, 1e-3, &x0, 2.0, &opts).unwrap();
    assert!(!sol.events.is_empty());
    assert_eq!(sol.events[0].name, "pivot friction 'hammer' #0");
    // Small-amplitude period of a rod pendulum: T = 2π sqrt(2l / (3g)) ≈ 0.518 s, so
    // reversals come every half period (a little longer at this amplitude).
    let gaps: Vec<f64> = sol
        .events
        .windows(2)
        .map(|w| w[1].time - w[0].time)
        .collect();
    assert!(sol.events.len() >= 6, "{} reversals", sol.events.len());
    for g in &gaps {
        assert!((0.25..0.32).contains(g), "half period {g}");
    }
    for ev in &sol.events {
        assert!(
            ev.state[1].abs() < 1e-6,
            "velocity at reversal {}",
            ev.state[1]
        );
    }
}

#[test]
fn a_prescribed_joint_follows_its_drive_through_the_integrator() {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81])
        .add_link(
            "cart",
            None,
            JointKind::Prismatic { axis: [1.0, 0.0] },
            Placement::default(),
            BodySpec::new(1.0, [0.0, 0.0], 0.1),
        )
        .add_link(
            "pole",
            Some("cart"),
            JointKind::Revolute,
            Placement::default(),
            BodySpec::rod(0.2, 0.5),
        );
    let drive = Sinusoid {
        offset: 0.0,
        amplitude: 0.02,
        omega: 20.0,
        phase: 0.0,
    };
    let mut system = System::new(b.build().unwrap());
    system.prescribe("cart", drive).unwrap();
    let x0 = system
        .initial_state(0.0, &[0.0, -1.5], &[0.0, 0.0])
        .unwrap();
    let mut ode = MultibodyOde::new(&system);
    let opts = Options::with_tolerances(1e-9, 1e-12).output_every(0.01);
    let sol = solve(&mut ode, Method::DormandPrince54, 0.0, &x0, 1.0, &opts).unwrap();
    for i in 0..sol.len() {
        let d = drive.eval(sol.t[i]);
        assert!((sol.state(i)[0] - d.q).abs() < 1e-8, "cart at {}", sol.t[i]);
        assert!((sol.state(i)[2] - d.v).abs() < 1e-7);
    }
}

#[test]
fn tr_bdf2_takes_a_stiff_spring_in_far_fewer_evaluations_than_dopri5() {
    // A light hammer on a very stiff spring to the ground (felt-like, k = 1e7 N/m with
    // damping): the stiff mode is fast and decays; what matters is the slow swing.
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81])
        .add_link(
            "hammer",
            None,
            JointKind::Revolute,
            Placement::default(),
            BodySpec::rod(0.01, 0.1),
        )
        .add_link(
            "felt",
            Some("hammer"),
            JointKind::Prismatic { axis: [1.0, 0.0] },
            Placement::offset(0.1, 0.0),
            BodySpec::new(0.002, [0.0, 0.0], 1e-6),
        );
    let model = b.build().unwrap();
    let mut system = System::new(model.clone());
    system
        .add_element(
            mbs_core::elements::JointSpringDamper::new(
                &model,
                "felt",
                SpringLaw::new(1e7, 0.0).with_damping(50.0),
            )
            .unwrap(),
        )
        .unwrap();
    system
        .add_element(
            PointSpringDamper::new(
                &model,
                "tether",
                Attachment::on("felt", [0.0, 0.0]),
                Attachment::ground([0.1, 0.05]),
                SpringLaw::new(1.0, 0.0),
            )
            .unwrap(),
        )
        .unwrap();
    let x0 = system
        .initial_state(0.0, &[-0.5, 0.0], &[0.0, 0.0])
        .unwrap();
    let opts = Options::with_tolerances(1e-6, 1e-9);
    let mut ode = MultibodyOde::new(&system);
    let stiff = solve(&mut ode, Method::TrBdf2, 0.0, &x0, 0.5, &opts).unwrap();
    let mut ode = MultibodyOde::new(&system);
    let explicit = solve(&mut ode, Method::DormandPrince54, 0.0, &x0, 0.5, &opts).unwrap();
    let (s, e) = (stiff.stats, explicit.stats);
    println!("stiff hammer, 0.5 s: TR-BDF2 {s:?}\n                      DOPRI5  {e:?}");
    assert!(
        s.derivative_evals * 5 < e.derivative_evals,
        "{s:?} vs {e:?}"
    );
    assert!(s.jacobian_evals < s.steps, "the Jacobian is reused");
    // Same swing angle.
    assert!((stiff.y_final[0] - explicit.y_final[0]).abs() < 1e-3);
    // Reset actions work through the adapter too (stop at the first reversal).
    let mut ode = MultibodyOde::new(&system);
    let stopped = solve_with_events(
        &mut ode,
        Method::TrBdf2,
        0.0,
        &x0,
        0.5,
        &opts,
        &mut |_, _| EventAction::Stop,
    )
    .unwrap();
    assert!(
        stopped.events.is_empty(),
        "no switching functions declared here"
    );
}
