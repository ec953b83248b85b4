//! The `Contact` force element in an `mbs_core::System`: action and reaction, the gap as
//! switching function, per-contact output, profiles, ground contacts.

use mbs_contact::{Contact, ContactSide, Shape};
use mbs_core::{BodySpec, Force, ForceElement, JointKind, Loads, ModelBuilder, Placement, System};

mod common;

use common::Linear;

/// A slider carrying a disc, and a pendulum carrying a bar, under gravity.
fn two_bodies() -> mbs_core::Model {
    common::slider_and_arm([0.0, -9.81])
}

#[test]
fn action_and_reaction_are_equal_and_opposite() {
    let model = two_bodies();
    let disc = Shape::circle([0.0, 0.0], 0.05).unwrap();
    // The arm's lower face, from its tip back to the pivot (facing down when horizontal).
    let face = Shape::segment([0.4, 0.0], [0.0, 0.0]).unwrap();
    let contact = Contact::new(
        &model,
        "disc-arm",
        ContactSide::on("slider", vec![disc]),
        ContactSide::on("arm", vec![face]),
        Linear(1e4),
    )
    .unwrap();
    let mut system = System::new(model.clone());
    let e = system.add_element(contact.clone()).unwrap();
    let mut ws = system.workspace();
    // Slider at x = 0.45 under the arm tilted slightly down: the disc presses the bar.
    let x = [0.45, -0.1, 0.2, -0.3];
    let ctx = system.element_context(&mut ws, 0.0, &x, e).unwrap();
    let out = contact.output(&ctx);
    assert!(
        out.active && out.gap < 0.0 && out.normal_force > 0.0,
        "{out:?}"
    );
    assert!((out.normal_force - 1e4 * -out.gap).abs() < 1e-9);
    let mut tau = vec![0.0; 2];
    let mut forces = vec![Force::ZERO; model.nbodies()];
    let mut loads = Loads::new(&mut tau, &mut forces);
    contact.apply(&ctx, &mut loads, &mut []);
    let (fa, fb) = (forces[1], forces[2]);
    // Equal and opposite forces, at the same point: the spatial forces cancel exactly.
    assert!((fa.fx + fb.fx).abs() < 1e-12 && (fa.fy + fb.fy).abs() < 1e-12);
    assert!((fa.n + fb.n).abs() < 1e-12, "moments {} {}", fa.n, fb.n);
    // The force on the arm pushes it away from the disc, along the normal.
    assert!(fb.fx * out.normal[0] + fb.fy * out.normal[1] > 0.0);
}

#[test]
fn ground_contacts_profiles_and_the_gap_switch() {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81]).add_link(
        "ball",
        None,
        JointKind::Prismatic { axis: [0.0, 1.0] },
        Placement::default(),
        BodySpec::new(0.01, [0.0, 0.0], 1e-6),
    );
    let model = b.build().unwrap();
    // A floor made of two faces (a profile), the ball a disc of radius 1 cm.
    let floor = vec![
        Shape::segment([-1.0, 0.0], [0.0, 0.0]).unwrap(),
        Shape::segment([0.0, -0.002], [1.0, -0.002]).unwrap(),
    ];
    let contact = Contact::new(
        &model,
        "ball-floor",
        ContactSide::ground(floor),
        ContactSide::on("ball", vec![Shape::circle([0.0, 0.0], 0.01).unwrap()]),
        Linear(100.0),
    )
    .unwrap();
    let mut system = System::new(model);
    let e = system.add_element(contact.clone()).unwrap();
    assert_eq!(system.switch_len(), 1);
    let mut ws = system.workspace();
    let mut g = [0.0];
    for (height, gap) in [(0.05, 0.04), (0.01, 0.0), (0.008, -0.002)] {
        let state = [height, 0.0];
        system
            .switching_functions(&mut ws, 0.0, &state, &mut g)
            .unwrap();
        assert!((g[0] - gap).abs() < 1e-12, "height {height}: gap {}", g[0]);
        let ctx = system.element_context(&mut ws, 0.0, &state, e).unwrap();
        let out = contact.output(&ctx);
        assert_eq!(out.active, gap < 0.0);
        assert!((out.normal_force - 100.0 * (-gap).max(0.0)).abs() < 1e-12);
    }
    // Resting on the floor: the contact carries the weight at the compression m g / k.
    let mut xdot = [0.0; 2];
    let rest = 0.01 - 0.01 * 9.81 / 100.0;
    system
        .derivative(&mut ws, 0.0, &[rest, 0.0], &mut xdot)
        .unwrap();
    assert!(xdot[1].abs() < 1e-12, "acceleration at rest {}", xdot[1]);
}

#[test]
fn contacts_that_cannot_work_are_refused() {
    let model = two_bodies();
    let c = Shape::circle([0.0, 0.0], 0.1).unwrap();
    let l = Shape::line([0.0, 0.0], [0.0, 1.0]).unwrap();
    let e = Contact::new(
        &model,
        "x",
        ContactSide::ground(vec![c]),
        ContactSide::ground(vec![c]),
        Linear(1.0),
    )
    .unwrap_err();
    assert!(e.to_string().contains("ground"), "{e}");
    let e = Contact::new(
        &model,
        "x",
        ContactSide::on("arm", vec![l]),
        ContactSide::ground(vec![l]),
        Linear(1.0),
    )
    .unwrap_err();
    assert!(e.to_string().contains("contact 'x'"), "{e}");
    let e = Contact::new(
        &model,
        "x",
        ContactSide::on("nowhere", vec![c]),
        ContactSide::ground(vec![l]),
        Linear(1.0),
    )
    .unwrap_err();
    assert!(e.to_string().contains("nowhere"), "{e}");
    let e = Contact::new(
        &model,
        "x",
        ContactSide::on("arm", vec![]),
        ContactSide::ground(vec![l]),
        Linear(1.0),
    )
    .unwrap_err();
    assert!(e.to_string().contains("no shape"), "{e}");
}

#[test]
fn gap_rate_and_slip_match_finite_differences_of_the_motion() {
    let model = two_bodies();
    let contact = Contact::new(
        &model,
        "disc-arm",
        ContactSide::on("slider", vec![Shape::circle([0.0, 0.02], 0.05).unwrap()]),
        ContactSide::on(
            "arm",
            vec![
                Shape::arc(
                    [0.2, -0.1],
                    0.08,
                    0.0,
                    std::f64::consts::PI,
                    mbs_contact::ArcSide::Convex,
                )
                .unwrap(),
            ],
        ),
        Linear(1e4),
    )
    .unwrap();
    let mut system = System::new(model);
    let e = system.add_element(contact.clone()).unwrap();
    let mut ws = system.workspace();
    let (q, v) = ([0.52, 0.1], [0.3, -0.7]);
    let x = [q[0], q[1], v[0], v[1]];
    let out = contact.output(&system.element_context(&mut ws, 0.0, &x, e).unwrap());
    let h = 1e-7;
    let gap_at = |s: f64, ws: &mut mbs_core::Workspace| {
        let xs = [q[0] + s * v[0], q[1] + s * v[1], v[0], v[1]];
        contact
            .output(&system.element_context(ws, 0.0, &xs, e).unwrap())
            .gap
    };
    let fd = (gap_at(h, &mut ws) - gap_at(-h, &mut ws)) / (2.0 * h);
    assert!(
        (fd - out.gap_rate).abs() < 1e-6,
        "gap rate {} vs finite difference {fd}",
        out.gap_rate
    );
    // Slip: the tangential relative velocity, from the two material points' velocities.
    assert!(out.slip.is_finite() && out.slip.abs() > 1e-3);
}

#[test]
fn contact_forces_map_to_generalized_forces_through_the_point_jacobians() {
    let model = two_bodies();
    let contact = Contact::new(
        &model,
        "disc-arm",
        ContactSide::on("slider", vec![Shape::circle([0.0, 0.0], 0.05).unwrap()]),
        ContactSide::on("arm", vec![Shape::segment([0.4, 0.0], [0.0, 0.0]).unwrap()]),
        Linear(1e4),
    )
    .unwrap()
    .with_friction(mbs_contact::laws::RegularizedCoulomb::new(0.3, 1e-3).unwrap());
    let mut system = System::new(model.clone());
    let e = system.add_element(contact.clone()).unwrap();
    let mut ws = system.workspace();
    let x = [0.45, -0.1, 0.2, -0.3];
    let out = contact.output(&system.element_context(&mut ws, 0.0, &x, e).unwrap());
    assert!(out.active && out.tangential_force != 0.0);
    system.derivative(&mut ws, 0.0, &x, &mut [0.0; 4]).unwrap();
    let tau = system.element_forces(&mut ws).to_vec();
    // τ = J_B(p)ᵀ F − J_A(p)ᵀ F with F = Fn n + Ft t the force on B at the contact point p.
    let (n, t) = (out.normal, [-out.normal[1], out.normal[0]]);
    let f = [
        out.normal_force * n[0] + out.tangential_force * t[0],
        out.normal_force * n[1] + out.tangential_force * t[1],
    ];
    let data = ws.data();
    let mut expect = [0.0; 2];
    for (name, sign) in [("arm", 1.0), ("slider", -1.0)] {
        let body = model.body_id(name).unwrap();
        let p_b = data.body_pose(body).inverse_transform_point(out.point);
        let mut j = nalgebra::DMatrix::zeros(2, 2);
        mbs_core::point_jacobian(&model, data, body, p_b, &mut j).unwrap();
        for k in 0..2 {
            expect[k] += sign * (j[(0, k)] * f[0] + j[(1, k)] * f[1]);
        }
    }
    for k in 0..2 {
        assert!(
            (tau[k] - expect[k]).abs() < 1e-9 * (1.0 + expect[k].abs()),
            "τ[{k}] {} vs Jᵀ F {}",
            tau[k],
            expect[k]
        );
    }
}

#[test]
fn the_integrator_locates_contact_onset_and_release() {
    use mbs_integrators::{EventAction, Method, MultibodyOde, Options, solve_with_events};
    // A 10 g disc dropped from 5 cm (centre height) onto a stiff floor, radius 1 cm.
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81]).add_link(
        "ball",
        None,
        JointKind::Prismatic { axis: [0.0, 1.0] },
        Placement::default(),
        BodySpec::new(0.01, [0.0, 0.0], 1e-6),
    );
    let model = b.build().unwrap();
    let contact = Contact::new(
        &model,
        "ball-floor",
        ContactSide::ground(vec![Shape::line([0.0, 0.0], [0.0, 1.0]).unwrap()]),
        ContactSide::on("ball", vec![Shape::circle([0.0, 0.0], 0.01).unwrap()]),
        Linear(1e4),
    )
    .unwrap();
    let mut system = System::new(model);
    system.add_element(contact).unwrap();
    let x0 = system.initial_state(0.0, &[0.05], &[0.0]).unwrap();
    let opts = Options::with_tolerances(1e-10, 1e-12);
    let sol = solve_with_events(
        &mut MultibodyOde::new(&system),
        Method::DormandPrince54,
        0.0,
        &x0,
        0.12,
        &opts,
        &mut |_, _| EventAction::Record,
    )
    .unwrap();
    assert!(sol.events.len() >= 2, "{:?}", sol.events);
    assert_eq!(sol.events[0].name, "contact 'ball-floor' #0");
    // Touch-down when the centre has fallen 4 cm: t = sqrt(2 · 0.04 / g).
    let t_touch = (2.0 * 0.04 / 9.81f64).sqrt();
    assert!(
        (sol.events[0].time - t_touch).abs() < 1e-9,
        "{} vs {t_touch}",
        sol.events[0].time
    );
    // A linear spring contact lasts half a period π sqrt(m/k) (gravity shifts it slightly).
    let duration = sol.events[1].time - sol.events[0].time;
    let half_period = std::f64::consts::PI * (0.01f64 / 1e4).sqrt();
    assert!(
        (duration - half_period).abs() < 0.02 * half_period,
        "{duration} vs {half_period}"
    );
}

/// A contact whose shapes stay apart has not acted, and a solve's result does not depend
/// on its laws; once the shapes overlap at an evaluation, it has; a clone keeps the mark.
#[test]
fn a_contact_knows_whether_its_laws_have_acted() {
    let model = two_bodies();
    let disc = Shape::circle([0.0, 0.0], 0.05).unwrap();
    let face = Shape::segment([0.4, 0.0], [0.0, 0.0]).unwrap();
    let build = |k: f64| {
        Contact::new(
            &model,
            "disc-arm",
            ContactSide::on("slider", vec![disc]),
            ContactSide::on("arm", vec![face]),
            Linear(k),
        )
        .unwrap()
    };
    let (soft, stiff) = (build(1e3), build(1e6));
    let loads_of = |contact: &Contact, x: &[f64]| {
        let mut system = System::new(model.clone());
        let e = system.add_element(contact.clone()).unwrap();
        let mut ws = system.workspace();
        let ctx = system.element_context(&mut ws, 0.0, x, e).unwrap();
        let mut tau = vec![0.0; 2];
        let mut forces = vec![Force::ZERO; model.nbodies()];
        contact.apply(&ctx, &mut Loads::new(&mut tau, &mut forces), &mut []);
        (
            tau,
            forces.iter().map(|f| [f.fx, f.fy, f.n]).collect::<Vec<_>>(),
        )
    };
    // The slider far from the arm: no load, whatever the stiffness, and nothing acted.
    let apart = [2.0, 0.0, 0.0, 0.0];
    assert_eq!(loads_of(&soft, &apart), loads_of(&stiff, &apart));
    assert!(!soft.touched() && !stiff.touched());
    // Pressed into the arm: loads that differ with the law, and both marked.
    let pressed = [0.45, -0.1, 0.2, -0.3];
    assert_ne!(loads_of(&soft, &pressed), loads_of(&stiff, &pressed));
    assert!(soft.touched() && stiff.touched());
    assert_eq!(soft.acted_from(), Some(0.0));
    assert!(soft.clone().touched());
    assert!(!build(1e3).clone().touched());
}
