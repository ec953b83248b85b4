//! `System::jacobian`: the force elements' derivatives assembled through the mass matrix,
//! against central differences of `System::derivative`.

use mbs_core::elements::{
    AppliedLoad, Attachment, Cord, FrictionLaw, JointLimit, JointSpringDamper, PivotFriction,
    SpringLaw,
};
use mbs_core::time_function::Constant;
use mbs_core::{
    BodySpec, DriveState, JointKind, Model, ModelBuilder, Placement, System, Workspace,
};
use nalgebra::DMatrix;

/// Central differences of the derivative over every column.
fn fd_jacobian(sys: &System, ws: &mut Workspace, t: f64, x: &[f64]) -> DMatrix<f64> {
    let n = x.len();
    let mut j = DMatrix::zeros(n, n);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for c in 0..n {
        let h = 1e-6 * (1.0 + x[c].abs());
        let mut xp = x.to_vec();
        xp[c] = x[c] + h;
        sys.derivative(ws, t, &xp, &mut fp).unwrap();
        xp[c] = x[c] - h;
        sys.derivative(ws, t, &xp, &mut fm).unwrap();
        for r in 0..n {
            j[(r, c)] = (fp[r] - fm[r]) / (2.0 * h);
        }
    }
    j
}

/// Two levers pivoted on the ground, no gravity: the mass matrix is constant and there are
/// no velocity products, so the elements' derivatives are the whole Jacobian.
fn two_levers() -> Model {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, 0.0]);
    b.add_link(
        "a",
        None,
        JointKind::Revolute,
        Placement::default(),
        BodySpec::new(0.3, [0.1, 0.0], 2e-3),
    );
    b.add_link(
        "b",
        None,
        JointKind::Revolute,
        Placement::offset(0.5, 0.0),
        BodySpec::new(0.2, [0.05, 0.01], 1e-3),
    );
    b.build().unwrap()
}

fn levers_with_elements(model: &Model) -> System {
    let mut sys = System::new(model.clone());
    let spring = SpringLaw::new(40.0, 0.05).with_damping(0.3);
    sys.add_element(JointSpringDamper::new(model, "a", spring).unwrap())
        .unwrap();
    let friction = FrictionLaw::coulomb(0.02, 0.01)
        .with_viscous(1e-3)
        .with_stribeck(0.03, 0.05);
    sys.add_element(PivotFriction::new(model, "a", friction).unwrap())
        .unwrap();
    sys.add_element(JointLimit::new(model, "b", 0.1, 0.6, 1e4, 2.0).unwrap())
        .unwrap();
    sys.add_element(AppliedLoad::torque(model, "push", "b", Constant(0.4)).unwrap())
        .unwrap();
    sys
}

#[test]
fn joint_elements_give_the_exact_jacobian() {
    let model = two_levers();
    let sys = levers_with_elements(&model);
    assert!(sys.has_jacobian());
    let mut ws = sys.workspace();
    // Lever b inside its lower stop and moving into it; lever a where the tanh of its
    // friction is steep (v = 0.004 rad/s against a regularization of 0.01).
    for (qa, va, qb, vb) in [(0.2, 0.004, 0.09, -0.3), (-0.1, -0.5, 0.3, 0.2)] {
        let x = [qa, qb, va, vb];
        let mut ja = DMatrix::from_element(4, 4, f64::NAN);
        sys.jacobian(&mut ws, 0.0, &x, &mut ja).unwrap();
        let jf = fd_jacobian(&sys, &mut ws, 0.0, &x);
        for r in 0..4 {
            for c in 0..4 {
                let (a, f) = (ja[(r, c)], jf[(r, c)]);
                assert!(
                    (a - f).abs() <= 1e-6 * (1.0 + f.abs()),
                    "state {x:?}: J[{r},{c}] = {a} against {f} by differences"
                );
            }
        }
    }
    // The stop's stiffness shows where it pushes: ∂q̈_b/∂q_b = −k / I_b(pivot).
    let x = [0.2, 0.09, 0.0, 0.0];
    let mut ja = DMatrix::zeros(4, 4);
    sys.jacobian(&mut ws, 0.0, &x, &mut ja).unwrap();
    let i_b = 1e-3 + 0.2 * (0.05f64.powi(2) + 0.01f64.powi(2));
    assert!((ja[(3, 1)] + 1e4 / i_b).abs() < 1e-6 * 1e4 / i_b);
}

#[test]
fn a_swinging_chain_under_gravity_gets_its_inertial_terms() {
    // A double pendulum under gravity, swinging fast, its elbow held by a stiff spring that
    // makes the accelerations large: the change of M q̈, of gravity and of the velocity
    // products with the state is in the Jacobian (by differences of inverse dynamics), so
    // with joint elements only it is the exact one.
    let mut b = ModelBuilder::new();
    b.add_link(
        "upper",
        None,
        JointKind::Revolute,
        Placement::default(),
        BodySpec::new(1.0, [0.25, 0.0], 5e-3),
    );
    b.add_link(
        "lower",
        Some("upper"),
        JointKind::Revolute,
        Placement::offset(0.5, 0.0),
        BodySpec::new(0.5, [0.2, 0.0], 2e-3),
    );
    let model = b.build().unwrap();
    let mut sys = System::new(model.clone());
    let spring = SpringLaw::new(5e3, 0.0).with_damping(1.0);
    sys.add_element(JointSpringDamper::new(&model, "lower", spring).unwrap())
        .unwrap();
    let mut ws = sys.workspace();
    let x = [0.4, -0.3, 2.0, -1.5];
    let mut ja = DMatrix::zeros(4, 4);
    sys.jacobian(&mut ws, 0.0, &x, &mut ja).unwrap();
    let jf = fd_jacobian(&sys, &mut ws, 0.0, &x);
    // The spring's entries are large (k/I ~ 1e5 s⁻²), and so is the inertial coupling at
    // these accelerations: without it the difference was a third of them.
    let stiff = jf[(3, 1)].abs();
    assert!(stiff > 1e5, "{stiff}");
    let worst = (ja - jf).abs().max();
    assert!(worst < 1e-6 * stiff, "worst {worst} against {stiff}");
}

#[test]
fn a_prescribed_coordinate_has_zero_rows_and_columns() {
    let model = two_levers();
    let mut sys = levers_with_elements(&model);
    sys.prescribe("a", |t: f64| DriveState {
        q: 0.1 * t,
        v: 0.1,
        a: 0.0,
    })
    .unwrap();
    let mut ws = sys.workspace();
    let x = [0.3, 0.09, 1.0, -0.2];
    let mut ja = DMatrix::from_element(4, 4, f64::NAN);
    sys.jacobian(&mut ws, 0.5, &x, &mut ja).unwrap();
    let jf = fd_jacobian(&sys, &mut ws, 0.5, &x);
    // The state of a prescribed coordinate is not read, and its rates are the drive's.
    for i in 0..4 {
        for c in [0, 2] {
            assert_eq!(ja[(i, c)], 0.0);
            assert_eq!(ja[(c, i)], 0.0);
        }
    }
    for r in 0..4 {
        for c in 0..4 {
            assert!((ja[(r, c)] - jf[(r, c)]).abs() <= 1e-6 * (1.0 + jf[(r, c)].abs()));
        }
    }
}

#[test]
fn an_element_without_derivatives_is_named() {
    let model = two_levers();
    let mut sys = levers_with_elements(&model);
    sys.add_element(
        Cord::new(
            &model,
            "tape",
            Attachment::on("a", [0.2, 0.0]),
            Attachment::on("b", [0.1, 0.0]),
            0.3,
            1e3,
            0.0,
        )
        .unwrap(),
    )
    .unwrap();
    assert!(!sys.has_jacobian());
    let mut ws = sys.workspace();
    let mut ja = DMatrix::zeros(4, 4);
    let e = sys
        .jacobian(&mut ws, 0.0, &[0.0; 4], &mut ja)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tape") && e.contains("no load derivatives"),
        "{e}"
    );
    // A wrong shape is refused before anything is written.
    let mut small = DMatrix::zeros(3, 4);
    let e = levers_with_elements(&model)
        .jacobian(&mut ws, 0.0, &[0.0; 4], &mut small)
        .unwrap_err()
        .to_string();
    assert!(e.contains("jacobian"), "{e}");
}
