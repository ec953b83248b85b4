//! `System`: force elements, prescribed coordinates, internal states and errors.

use mbs_core::elements::{
    AppliedLoad, Attachment, FrictionLaw, JointSpringDamper, LoadFrame, PivotFriction,
    PointSpringDamper, SpringLaw, Stribeck,
};
use mbs_core::time_function::{Constant, Sinusoid, SmoothMove};
use mbs_core::{
    BodySpec, CoreError, Crossing, Data, DriveState, ForceContext, ForceElement, JointKind, Loads,
    Model, ModelBuilder, Placement, System, aba, point_jacobian, update_poses,
};
use nalgebra::{DMatrix, DVector};

fn rk4(system: &System, x: &mut [f64], t: f64, h: f64) {
    let mut ws = system.workspace();
    let n = x.len();
    let mut k = vec![vec![0.0; n]; 4];
    let mut y = x.to_vec();
    system.derivative(&mut ws, t, &y, &mut k[0]).unwrap();
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k[0][i];
    }
    system
        .derivative(&mut ws, t + 0.5 * h, &y, &mut k[1])
        .unwrap();
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k[1][i];
    }
    system
        .derivative(&mut ws, t + 0.5 * h, &y, &mut k[2])
        .unwrap();
    for i in 0..n {
        y[i] = x[i] + h * k[2][i];
    }
    system.derivative(&mut ws, t + h, &y, &mut k[3]).unwrap();
    for i in 0..n {
        x[i] += h / 6.0 * (k[0][i] + 2.0 * k[1][i] + 2.0 * k[2][i] + k[3][i]);
    }
}

/// A double pendulum of rods hanging from the ground.
fn double_pendulum() -> Model {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81])
        .add_link(
            "upper",
            None,
            JointKind::Revolute,
            Placement::default(),
            BodySpec::rod(1.0, 0.6),
        )
        .add_link(
            "lower",
            Some("upper"),
            JointKind::Revolute,
            Placement::offset(0.6, 0.0),
            BodySpec::rod(0.5, 0.4),
        );
    b.build().unwrap()
}

#[test]
fn springs_conserve_total_energy_and_dampers_dissipate_it() {
    let model = double_pendulum();
    for damping in [0.0, 0.05] {
        let mut system = System::new(model.clone());
        system
            .add_element(
                JointSpringDamper::new(
                    &model,
                    "lower",
                    SpringLaw::new(4.0, 0.3)
                        .with_preload(0.2)
                        .with_damping(damping),
                )
                .unwrap(),
            )
            .unwrap();
        system
            .add_element(
                PointSpringDamper::new(
                    &model,
                    "tether",
                    Attachment::on("lower", [0.4, 0.0]),
                    Attachment::ground([0.5, 0.2]),
                    SpringLaw::new(30.0, 0.2)
                        .with_preload(1.0)
                        .with_damping(damping),
                )
                .unwrap(),
            )
            .unwrap();
        let mut ws = system.workspace();
        let mut x = system
            .initial_state(0.0, &[-1.2, 0.5], &[0.0, 1.0])
            .unwrap();
        let e0 = system.energy(&mut ws, 0.0, &x).unwrap();
        assert!(e0.elastic > 0.0 && e0.kinetic > 0.0);
        let h = 5e-4;
        let mut prev = e0.total();
        let mut max_dev: f64 = 0.0;
        for step in 1..=4000 {
            rk4(&system, &mut x, step as f64 * h, h);
            let e = system.energy(&mut ws, step as f64 * h, &x).unwrap().total();
            max_dev = max_dev.max((e - e0.total()).abs());
            if damping > 0.0 {
                assert!(
                    e <= prev + 1e-9,
                    "energy rose at step {step}: {prev} -> {e}"
                );
            }
            prev = e;
        }
        if damping == 0.0 {
            assert!(max_dev < 1e-6, "energy drift {max_dev:e} J with no damping");
        } else {
            assert!(
                e0.total() - prev > 0.01,
                "damping dissipated only {} J",
                e0.total() - prev
            );
        }
    }
}

#[test]
fn point_spring_acts_equally_and_oppositely_on_two_bodies() {
    // Two sliders on the x axis joined by a spring: the generalized forces are opposite.
    let mut b = ModelBuilder::new();
    b.add_link(
        "a",
        None,
        JointKind::Prismatic { axis: [1.0, 0.0] },
        Placement::default(),
        BodySpec::new(1.0, [0.0, 0.0], 0.1),
    )
    .add_link(
        "b",
        None,
        JointKind::Prismatic { axis: [1.0, 0.0] },
        Placement::offset(1.0, 0.0),
        BodySpec::new(2.0, [0.0, 0.0], 0.1),
    );
    let model = b.build().unwrap();
    let mut system = System::new(model.clone());
    system
        .add_element(
            PointSpringDamper::new(
                &model,
                "s",
                Attachment::on("a", [0.0, 0.0]),
                Attachment::on("b", [0.0, 0.0]),
                SpringLaw::new(100.0, 0.8),
            )
            .unwrap(),
        )
        .unwrap();
    let mut ws = system.workspace();
    let mut xdot = [0.0; 4];
    system
        .derivative(&mut ws, 0.0, &[0.0, 0.1, 0.0, 0.0], &mut xdot)
        .unwrap();
    // Length 1.1, rest 0.8: tension 30 N pulls a forward (+x) and b back.
    assert!((xdot[2] - 30.0).abs() < 1e-12);
    assert!((xdot[3] + 15.0).abs() < 1e-12);
    let f = system.element_forces(&mut ws);
    assert!((f[0] + f[1]).abs() < 1e-12 && (f[0] - 30.0).abs() < 1e-12);
    assert_eq!(ws.drive_forces(), &[0.0, 0.0]);
}

#[test]
fn applied_force_equals_the_jacobian_transpose_map() {
    let model = double_pendulum();
    let n = model.nv();
    let at = [0.3, 0.05];
    let dir_body = [0.6, -0.8];
    let mag = 2.5;
    let mut system = System::new(model.clone());
    system
        .add_element(
            AppliedLoad::force(
                &model,
                "push",
                Attachment::on("lower", at),
                dir_body,
                LoadFrame::Body,
                Constant(mag),
            )
            .unwrap(),
        )
        .unwrap();
    system
        .add_element(AppliedLoad::torque(&model, "twist", "upper", Constant(0.7)).unwrap())
        .unwrap();
    let (q, v) = ([0.4, -0.9], [0.3, -0.2]);
    let mut ws = system.workspace();
    let mut xdot = [0.0; 4];
    system
        .derivative(&mut ws, 0.0, &[q[0], q[1], v[0], v[1]], &mut xdot)
        .unwrap();
    // Independent: τ = Jᵀ F at the point (F turned into world), plus the torque on joint 1.
    let mut data = Data::new(&model);
    update_poses(&model, &mut data, &q).unwrap();
    let lower = model.body_id("lower").unwrap();
    let mut j = DMatrix::zeros(2, n);
    point_jacobian(&model, &data, lower, at, &mut j).unwrap();
    let f_w = data
        .body_pose(lower)
        .rotate([mag * dir_body[0], mag * dir_body[1]]);
    let mut tau = j.transpose() * DVector::from_column_slice(&f_w);
    tau[0] += 0.7;
    let qdd = aba(&model, &mut data, &q, &v, tau.as_slice()).unwrap();
    assert!((qdd[0] - xdot[2]).abs() < 1e-12 && (qdd[1] - xdot[3]).abs() < 1e-12);
    assert!((system.element_forces(&mut ws)[0] - tau[0]).abs() < 1e-12);
    assert!((system.element_forces(&mut ws)[1] - tau[1]).abs() < 1e-12);
}

#[test]
fn pivot_friction_opposes_motion_with_a_stribeck_peak() {
    let model = double_pendulum();
    let law = FrictionLaw::coulomb(0.01, 1e-4)
        .with_viscous(0.002)
        .with_stribeck(0.03, 0.05);
    let f = PivotFriction::new(&model, "upper", law)
        .unwrap()
        .with_reversal_events();
    assert_eq!(
        law.stribeck,
        Some(Stribeck {
            static_torque: 0.03,
            velocity: 0.05
        })
    );
    assert_eq!(f.torque(0.0), 0.0);
    assert!(f.torque(1.0) < 0.0 && f.torque(-1.0) > 0.0);
    // Just past the regularisation the breakaway level shows; far above, Coulomb + viscous.
    assert!((f.torque(1e-3) + 0.03).abs() < 1e-3);
    assert!((f.torque(2.0) + (0.01 + 0.004)).abs() < 1e-9);
    assert!(f.torque(-2.0) == -f.torque(2.0));
    // Its switching function is the joint velocity.
    let mut system = System::new(model);
    system.add_element(f).unwrap();
    let mut ws = system.workspace();
    let mut s = [0.0];
    system
        .switching_functions(&mut ws, 0.0, &[0.0, 0.0, -0.25, 1.0], &mut s)
        .unwrap();
    assert_eq!(s[0], -0.25);
    assert_eq!(system.switch_info(0), Some((0, 0, Crossing::Both)));
    assert_eq!(system.switch_info(1), None);
    // Friction only dissipates: a free swing loses energy.
    let mut x = vec![-0.5, 0.0, 0.0, 0.0];
    let e0 = system.energy(&mut ws, 0.0, &x).unwrap().total();
    for k in 0..2000 {
        rk4(&system, &mut x, k as f64 * 5e-4, 5e-4);
    }
    assert!(system.energy(&mut ws, 1.0, &x).unwrap().total() < e0 - 1e-3);
}

#[test]
fn prescribed_cart_returns_the_driving_force() {
    // Cart on a slider with a pendulum; the cart follows a sinusoid. Lagrange:
    //   I_o θ̈ = m lc sin θ ẍ − m g lc cos θ,   F = (mc + m) ẍ − m lc (sin θ θ̈ + cos θ θ̇²)
    let (mc, m, lc, ic, g) = (2.0, 0.5, 0.3, 0.02, 9.81);
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -g])
        .add_link(
            "cart",
            None,
            JointKind::Prismatic { axis: [1.0, 0.0] },
            Placement::default(),
            BodySpec::new(mc, [0.0, 0.0], 0.1),
        )
        .add_link(
            "pole",
            Some("cart"),
            JointKind::Revolute,
            Placement::default(),
            BodySpec::new(m, [lc, 0.0], ic),
        );
    let model = b.build().unwrap();
    let drive = Sinusoid {
        offset: 0.1,
        amplitude: 0.05,
        omega: 7.0,
        phase: 0.3,
    };
    let mut system = System::new(model);
    system.prescribe("cart", drive).unwrap();
    assert_eq!(system.prescribed_mask(), &[true, false]);
    let mut ws = system.workspace();
    let x0 = system
        .initial_state(0.2, &[99.0, 0.4], &[99.0, -1.0])
        .unwrap();
    let d0 = mbs_core::Drive::eval(&drive, 0.2);
    assert_eq!(
        (x0[0], x0[2]),
        (d0.q, d0.v),
        "initial state takes the drive's values"
    );
    for (t, th, thd) in [(0.2, 0.4, -1.0), (0.9, -1.1, 2.0)] {
        // The state's cart entries are overridden by the drive.
        let x = [123.0, th, -5.0, thd];
        let mut xdot = [0.0; 4];
        system.derivative(&mut ws, t, &x, &mut xdot).unwrap();
        let d: DriveState = mbs_core::Drive::eval(&drive, t);
        let i_o = ic + m * lc * lc;
        let thdd = (m * lc * th.sin() * d.a - m * g * lc * th.cos()) / i_o;
        let f = (mc + m) * d.a - m * lc * (th.sin() * thdd + th.cos() * thd * thd);
        assert_eq!(xdot[0], d.v);
        assert_eq!(xdot[2], d.a);
        assert!((xdot[3] - thdd).abs() < 1e-12);
        assert!((ws.drive_forces()[0] - f).abs() < 1e-12);
        assert_eq!(ws.drive_forces()[1], 0.0);
        assert_eq!(ws.q()[0], d.q);
    }
    // A spring on the driven cart helps the drive: the drive supplies only the rest.
    let spring = JointSpringDamper::new(system.model(), "cart", SpringLaw::new(40.0, 0.0)).unwrap();
    system.add_element(spring.clone()).unwrap();
    let mut ws = system.workspace();
    let mut xdot = [0.0; 4];
    system
        .derivative(&mut ws, 0.9, &[0.0, 0.3, 0.0, 0.5], &mut xdot)
        .unwrap();
    let total = ws.drive_forces()[0] + system.element_forces(&mut ws)[0];
    let without = {
        let mut bare = System::new(system.model().clone());
        bare.prescribe("cart", drive).unwrap();
        let mut w = bare.workspace();
        bare.derivative(&mut w, 0.9, &[0.0, 0.3, 0.0, 0.5], &mut [0.0; 4])
            .unwrap();
        w.drive_forces()[0]
    };
    let d = mbs_core::Drive::eval(&drive, 0.9);
    assert!((system.element_forces(&mut ws)[0] - spring.force(d.q, d.v)).abs() < 1e-12);
    assert!(
        (total - without).abs() < 1e-12,
        "drive + spring = bare drive force"
    );
    // Released, the cart is free again.
    system.release("cart").unwrap();
    let mut xdot = [0.0; 4];
    system
        .derivative(&mut ws, 0.0, &[0.0, 0.5, 0.0, 0.0], &mut xdot)
        .unwrap();
    assert!(
        xdot[2].abs() > 1e-3,
        "a free cart recoils from the falling pole"
    );
    assert_eq!(ws.drive_forces()[0], 0.0);
}

/// A first-order lag `ż = (u − z) / T` driven by the first joint's angle, pushing back on
/// it with torque −z: exercises internal states.
struct Lag {
    time_constant: f64,
}

impl ForceElement for Lag {
    fn name(&self) -> &str {
        "lag"
    }
    fn state_count(&self) -> usize {
        1
    }
    fn initial_states(&self, _model: &Model, out: &mut [f64]) {
        out[0] = 0.25;
    }
    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, rates: &mut [f64]) {
        rates[0] = (ctx.q[0] - ctx.states[0]) / self.time_constant;
        loads.add_generalized(0, -ctx.states[0]);
    }
    fn switch_count(&self) -> usize {
        2
    }
    fn switching_functions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        out[0] = ctx.states[0];
        out[1] = ctx.q[0];
    }
    fn switch_direction(&self, k: usize) -> Crossing {
        if k == 0 {
            Crossing::Rising
        } else {
            Crossing::Falling
        }
    }
}

#[test]
fn internal_states_are_initialised_integrated_and_named() {
    let model = double_pendulum();
    let mut system = System::new(model.clone());
    system
        .add_element(
            PivotFriction::new(
                &model,
                "lower",
                FrictionLaw::coulomb(0.0, 1e-3).with_viscous(0.01),
            )
            .unwrap()
            .with_reversal_events(),
        )
        .unwrap();
    let e = system.add_element(Lag { time_constant: 0.5 }).unwrap();
    assert_eq!(system.state_len(), 5);
    assert_eq!(system.element_state_range(e), Some(4..5));
    assert_eq!(system.element_state_range(9), None);
    let x = system.initial_state(0.0, &[1.0, 0.0], &[0.0, 0.0]).unwrap();
    assert_eq!(x[4], 0.25);
    let mut ws = system.workspace();
    let mut xdot = [0.0; 5];
    system.derivative(&mut ws, 0.0, &x, &mut xdot).unwrap();
    assert!((xdot[4] - (1.0 - 0.25) / 0.5).abs() < 1e-15);
    assert_eq!(system.element_forces(&mut ws)[0], -0.25);
    assert_eq!(system.switch_len(), 3);
    assert_eq!(system.switch_info(1), Some((1, 0, Crossing::Rising)));
    assert_eq!(system.switch_info(2), Some((1, 1, Crossing::Falling)));
    assert!(system.state_meaning(4).contains("lag"));
    assert!(system.state_meaning(3).contains("v of joint 'lower'"));
    assert!(system.state_meaning(99).contains("beyond"));
    assert!(System::new(model).state_meaning(7).contains("beyond"));
}

struct Broken;

impl ForceElement for Broken {
    fn name(&self) -> &str {
        "broken felt"
    }
    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, _rates: &mut [f64]) {
        if ctx.t > 1.0 {
            loads.add_generalized(1, f64::NAN);
        }
    }
}

#[test]
fn bad_states_elements_and_drives_are_named() {
    let model = double_pendulum();
    let mut system = System::new(model.clone());
    system.add_element(Broken).unwrap();
    let mut ws = system.workspace();
    let mut xdot = [0.0; 4];
    let e = system
        .derivative(&mut ws, 0.5, &[0.0, 0.0, f64::NAN, 0.0], &mut xdot)
        .unwrap_err();
    assert!(
        matches!(e, CoreError::NonFiniteState { index: 2, .. }),
        "{e:?}"
    );
    assert!(e.to_string().contains("v of joint 'upper'"), "{e}");
    let e = system
        .derivative(&mut ws, 2.0, &[0.0; 4], &mut xdot)
        .unwrap_err();
    assert!(e.to_string().contains("broken felt"), "{e}");
    let e = system
        .derivative(&mut ws, 0.0, &[0.0; 3], &mut xdot)
        .unwrap_err();
    assert!(
        matches!(e, CoreError::DimensionMismatch { what: "x", .. }),
        "{e:?}"
    );
    let e = system
        .derivative(&mut ws, 0.0, &[0.0; 4], &mut [0.0; 5])
        .unwrap_err();
    assert!(
        matches!(e, CoreError::DimensionMismatch { what: "xdot", .. }),
        "{e:?}"
    );
    let mut driven = System::new(model.clone());
    driven
        .prescribe("lower", |t: f64| DriveState {
            q: t.ln(),
            v: 1.0 / t,
            a: -1.0 / (t * t),
        })
        .unwrap();
    let mut ws = driven.workspace();
    let e = driven
        .derivative(&mut ws, -1.0, &[0.0; 4], &mut xdot)
        .unwrap_err();
    assert!(e.to_string().contains("drive of joint 'lower'"), "{e}");
    assert!(
        driven
            .prescribe("elbow", SmoothMove::new(0.0, 0.0, 1.0, 1.0).unwrap())
            .is_err()
    );
    // Element parameters are validated at construction, naming the field.
    let e = JointSpringDamper::new(&model, "upper", SpringLaw::new(-1.0, 0.0)).unwrap_err();
    assert!(e.to_string().contains("stiffness"), "{e}");
    let e = PivotFriction::new(&model, "upper", FrictionLaw::coulomb(0.1, 0.0)).unwrap_err();
    assert!(e.to_string().contains("regularization"), "{e}");
    let e = PointSpringDamper::new(
        &model,
        "s",
        Attachment::on("nowhere", [0.0, 0.0]),
        Attachment::ground([0.0, 0.0]),
        SpringLaw::new(1.0, 0.0),
    )
    .unwrap_err();
    assert!(e.to_string().contains("nowhere"), "{e}");
}

#[test]
fn elements_workspaces_and_loads_that_cannot_work_are_refused() {
    let model = double_pendulum();
    let chain = mbs_core::benchmarks::planar_chain(3);
    // An element built on another model is refused, whether its joint is missing here...
    let spring = JointSpringDamper::new(&chain, "link3", SpringLaw::new(1.0, 0.0)).unwrap();
    let mut system = System::new(model.clone());
    let e = system.add_element(spring).unwrap_err();
    assert!(e.to_string().contains("another model"), "{e}");
    // ...or present under another index.
    let mut b = ModelBuilder::new();
    b.add_link(
        "lower",
        None,
        JointKind::Revolute,
        Placement::default(),
        BodySpec::rod(1.0, 1.0),
    )
    .add_link(
        "upper",
        Some("lower"),
        JointKind::Revolute,
        Placement::offset(1.0, 0.0),
        BodySpec::rod(1.0, 1.0),
    );
    let swapped = b.build().unwrap();
    let friction = PivotFriction::new(&swapped, "upper", FrictionLaw::coulomb(0.1, 1e-3)).unwrap();
    assert!(system.add_element(friction).is_err());
    let load = AppliedLoad::torque(&swapped, "t", "upper", Constant(1.0)).unwrap();
    assert!(system.add_element(load).is_err());
    // Loads on the ground act on nothing: refused when built.
    let e = AppliedLoad::force(
        &model,
        "p",
        Attachment::ground([0.0, 0.0]),
        [1.0, 0.0],
        LoadFrame::World,
        Constant(1.0),
    )
    .unwrap_err();
    assert!(e.to_string().contains("ground"), "{e}");
    let mut b = ModelBuilder::new();
    b.add_link(
        "base",
        None,
        JointKind::Fixed,
        Placement::default(),
        BodySpec::rod(1.0, 1.0),
    )
    .add_link(
        "arm",
        Some("base"),
        JointKind::Revolute,
        Placement::default(),
        BodySpec::rod(1.0, 1.0),
    );
    let based = b.build().unwrap();
    assert!(AppliedLoad::torque(&based, "t", "base", Constant(1.0)).is_err());
    assert!(AppliedLoad::torque(&based, "t", "arm", Constant(1.0)).is_ok());
    let e = PointSpringDamper::new(
        &based,
        "s",
        Attachment::on("base", [0.0, 0.0]),
        Attachment::ground([1.0, 0.0]),
        SpringLaw::new(1.0, 0.0),
    )
    .unwrap_err();
    assert!(e.to_string().contains("both ends"), "{e}");
    // A workspace of another system is refused, as is a Data of another model.
    let other = System::new(chain.clone());
    let mut ws = other.workspace();
    let e = system
        .derivative(&mut ws, 0.0, &[0.0; 4], &mut [0.0; 4])
        .unwrap_err();
    assert!(matches!(e, CoreError::WorkspaceMismatch { .. }), "{e:?}");
    let mut data = Data::new(&chain);
    let e = aba(&model, &mut data, &[0.0; 2], &[0.0; 2], &[0.0; 2]).unwrap_err();
    assert!(matches!(e, CoreError::WorkspaceMismatch { .. }), "{e:?}");
}

/// An element whose switching function is undefined somewhere.
struct BadSwitch;

impl ForceElement for BadSwitch {
    fn name(&self) -> &str {
        "bad switch"
    }
    fn apply(&self, _ctx: &ForceContext<'_>, _loads: &mut Loads<'_>, _rates: &mut [f64]) {}
    fn switch_count(&self) -> usize {
        2
    }
    fn switching_functions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        // Forgets out[1]; out[0] is NaN for negative angles.
        out[0] = ctx.q[0].sqrt();
    }
    fn potential_energy(&self, ctx: &ForceContext<'_>) -> f64 {
        ctx.q[1].ln()
    }
}

#[test]
fn switching_functions_and_energies_are_checked() {
    let mut system = System::new(double_pendulum());
    system.add_element(BadSwitch).unwrap();
    let mut ws = system.workspace();
    let mut out = [7.0, 7.0];
    let e = system
        .switching_functions(&mut ws, 0.0, &[1.0, 1.0, 0.0, 0.0], &mut out)
        .unwrap_err();
    assert!(
        e.to_string().contains("bad switch") && e.to_string().contains("switching"),
        "{e}"
    );
    let e = system
        .energy(&mut ws, 0.0, &[1.0, -1.0, 0.0, 0.0])
        .unwrap_err();
    assert!(
        e.to_string().contains("bad switch") && e.to_string().contains("energy"),
        "{e}"
    );
}

#[test]
fn poses_and_accelerations_are_valid_after_the_dynamics_calls() {
    // Regression (review): aba/rnea left world poses stale, and body accelerations carried
    // the −g of the base.
    let model = double_pendulum();
    let (q, v, tau) = ([0.7, -0.4], [1.5, -2.0], [0.3, 0.1]);
    let mut data = Data::new(&model);
    let qdd = aba(&model, &mut data, &q, &v, &tau).unwrap().clone();
    let lower = model.body_id("lower").unwrap();
    let (pose, vel, acc) = (
        data.body_pose(lower),
        mbs_core::point_velocity(&data, lower, [0.4, 0.0]),
        mbs_core::point_acceleration(&data, lower, [0.4, 0.0]),
    );
    let mut reference = Data::new(&model);
    mbs_core::forward_kinematics_acc(&model, &mut reference, &q, &v, qdd.as_slice()).unwrap();
    assert_eq!(pose, reference.body_pose(lower));
    let rv = mbs_core::point_velocity(&reference, lower, [0.4, 0.0]);
    let ra = mbs_core::point_acceleration(&reference, lower, [0.4, 0.0]);
    for k in 0..2 {
        assert!((vel[k] - rv[k]).abs() < 1e-12);
        assert!((acc[k] - ra[k]).abs() < 1e-12, "{acc:?} vs {ra:?}");
    }
    // The same after rnea at that acceleration, and through a System (free slider falls at g).
    mbs_core::rnea(&model, &mut data, &q, &v, qdd.as_slice()).unwrap();
    let a2 = mbs_core::point_acceleration(&data, lower, [0.4, 0.0]);
    assert!((a2[0] - ra[0]).abs() < 1e-12 && (a2[1] - ra[1]).abs() < 1e-12);
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81]).add_link(
        "slider",
        None,
        JointKind::Prismatic { axis: [0.0, 1.0] },
        Placement::default(),
        BodySpec::new(1.0, [0.0, 0.0], 0.1),
    );
    let system = System::new(b.build().unwrap());
    let mut ws = system.workspace();
    system
        .derivative(&mut ws, 0.0, &[0.0, 0.0], &mut [0.0; 2])
        .unwrap();
    let body = system.model().body_id("slider").unwrap();
    let a = mbs_core::point_acceleration(ws.data(), body, [0.0, 0.0]);
    assert!((a[1] + 9.81).abs() < 1e-12 && a[0].abs() < 1e-12, "{a:?}");
}

#[test]
fn joint_limits_act_only_beyond_their_stops() {
    let model = double_pendulum();
    let lim = mbs_core::elements::JointLimit::new(&model, "lower", -0.2, 0.3, 100.0, 1.0).unwrap();
    assert_eq!(lim.torque(0.0, 5.0), 0.0);
    assert!((lim.torque(-0.25, 0.0) - 5.0).abs() < 1e-12);
    assert!((lim.torque(0.35, 0.0) + 5.0).abs() < 1e-12);
    // Damping resists entering the stop but never pulls the joint back into it.
    assert!((lim.torque(-0.25, -1.0) - 6.0).abs() < 1e-12);
    assert_eq!(lim.torque(-0.201, 10.0), 0.0);
    assert!(mbs_core::elements::JointLimit::new(&model, "lower", 0.3, 0.3, 1.0, 0.0).is_err());
    let mut system = System::new(model);
    system.add_element(lim).unwrap();
    let mut ws = system.workspace();
    let mut g = [0.0; 2];
    system
        .switching_functions(&mut ws, 0.0, &[0.0, 0.1, 0.0, 0.0], &mut g)
        .unwrap();
    assert!((g[0] - 0.3).abs() < 1e-15 && (g[1] - 0.2).abs() < 1e-15);
    let e = system.energy(&mut ws, 0.0, &[0.0, 0.4, 0.0, 0.0]).unwrap();
    assert!((e.elastic - 0.5).abs() < 1e-12);
}
