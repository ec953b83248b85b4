//! A contact's load derivatives in `System::jacobian`, against central differences of the
//! system's derivative.

use mbs_contact::laws::{HystereticFelt, NormalLaw, RegularizedCoulomb};
use mbs_contact::{Contact, ContactSide, Shape};
use mbs_core::{System, Workspace};
use nalgebra::DMatrix;

mod common;

use common::Linear;

/// A slider carrying a disc under a lever carrying a bar, no gravity: the mass matrix is
/// constant and there are no velocity products, so what the Jacobian leaves out is the
/// contact's geometry only.
fn disc_under_bar(law: impl NormalLaw + 'static, friction: bool) -> System {
    let model = common::slider_and_arm([0.0, 0.0]);
    let disc = Shape::circle([0.0, 0.0], 0.05).unwrap();
    let face = Shape::segment([0.4, 0.0], [0.0, 0.0]).unwrap();
    let mut contact = Contact::new(
        &model,
        "disc-bar",
        ContactSide::on("slider", vec![disc]),
        ContactSide::on("arm", vec![face]),
        law,
    )
    .unwrap();
    if friction {
        contact = contact.with_friction(RegularizedCoulomb::new(0.3, 1e-2).unwrap());
    }
    let mut sys = System::new(model);
    sys.add_element(contact).unwrap();
    sys
}

fn fd_jacobian(sys: &System, ws: &mut Workspace, x: &[f64]) -> DMatrix<f64> {
    let n = x.len();
    let mut j = DMatrix::zeros(n, n);
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for c in 0..n {
        let h = 1e-8 * (1.0 + x[c].abs());
        let mut xp = x.to_vec();
        xp[c] = x[c] + h;
        sys.derivative(ws, 0.0, &xp, &mut fp).unwrap();
        xp[c] = x[c] - h;
        sys.derivative(ws, 0.0, &xp, &mut fm).unwrap();
        for r in 0..n {
            j[(r, c)] = (fp[r] - fm[r]) / (2.0 * h);
        }
    }
    j
}

/// Largest difference in column `c`, relative to that column's largest entry.
fn column_error(a: &DMatrix<f64>, f: &DMatrix<f64>, c: usize) -> f64 {
    let scale = f.column(c).abs().max();
    (a.column(c) - f.column(c)).abs().max() / scale
}

#[test]
fn the_contact_stiffness_and_damping_match_differences() {
    // The bar's face (its axis) passes 0.15 sin θ from the disc's centre at x = 0.45: at
    // θ = 0.3377 the disc is 0.3 mm into it (about 100 N from the felt).
    let laws: Vec<(&str, System)> = vec![
        (
            "hysteretic felt with friction",
            disc_under_bar(HystereticFelt::new(2e7, 1.5, 0.4, 1e-2).unwrap(), true),
        ),
        ("linear, differenced", disc_under_bar(Linear(1e5), false)),
    ];
    for (name, sys) in laws {
        let mut ws = sys.workspace();
        let mut ja = DMatrix::zeros(4, 4);
        // At rest the gap rate has no convective part: every column is the contact's
        // stiffness and damping, up to the bar's turning under the force (F/k ≪ lengths).
        let at_rest = [0.45, 0.3377, 0.0, 0.0];
        sys.jacobian(&mut ws, 0.0, &at_rest, &mut ja).unwrap();
        let jf = fd_jacobian(&sys, &mut ws, &at_rest);
        assert!(jf[(2, 0)].abs() > 1e3, "{name}: not in contact: {jf}");
        for c in 0..4 {
            let e = column_error(&ja, &jf, c);
            assert!(e < 1e-2, "{name}, at rest, column {c}: {e:.2e}\n{ja}\n{jf}");
        }
        // Moving: the velocity columns are exact (the gap rate and slip are linear in v).
        let moving = [0.45, 0.3377, 0.03, -0.02];
        sys.jacobian(&mut ws, 0.0, &moving, &mut ja).unwrap();
        let jf = fd_jacobian(&sys, &mut ws, &moving);
        for c in 2..4 {
            let e = column_error(&ja, &jf, c);
            assert!(e < 1e-5, "{name}, moving, column {c}: {e:.2e}\n{ja}\n{jf}");
        }
    }
}

#[test]
fn the_gap_rate_convection_is_in_the_coordinate_columns() {
    // The disc slides under the bar at 0.3 m/s while the bar turns so that the gap closes at
    // 0.5 mm/s, inside the felt's hysteresis switch (v_ε = 1 mm/s, as the piano's): there
    // the force depends steeply on the gap rate, and the gap rate on the pose through the
    // sliding (the bar's normal turns under the moving disc).
    let sys = disc_under_bar(HystereticFelt::new(2e7, 1.5, 0.4, 1e-3).unwrap(), false);
    let e = 0;
    let mut ws = sys.workspace();
    let gap_rate = |ws: &mut Workspace, w: f64| {
        let x = [0.45, 0.3377, 0.3, w];
        let ctx = sys.element_context(ws, 0.0, &x, e).unwrap();
        let c = sys.elements().next().and_then(Contact::of).unwrap();
        c.output(&ctx).gap_rate
    };
    let (g0, g1) = (gap_rate(&mut ws, 0.0), gap_rate(&mut ws, 1.0));
    let w = (-5e-4 - g0) / (g1 - g0);
    let x = [0.45, 0.3377, 0.3, w];
    assert!((gap_rate(&mut ws, w) + 5e-4).abs() < 1e-9);
    let mut ja = DMatrix::zeros(4, 4);
    sys.jacobian(&mut ws, 0.0, &x, &mut ja).unwrap();
    let jf = fd_jacobian(&sys, &mut ws, &x);
    for c in 0..4 {
        let e = column_error(&ja, &jf, c);
        assert!(e < 1e-2, "column {c}: {e:.2e}\n{ja}\n{jf}");
    }
}

#[test]
fn apart_the_contact_adds_nothing() {
    let sys = disc_under_bar(HystereticFelt::new(2e7, 1.5, 0.4, 1e-2).unwrap(), true);
    let mut ws = sys.workspace();
    let mut ja = DMatrix::from_element(4, 4, f64::NAN);
    sys.jacobian(&mut ws, 0.0, &[0.45, 0.6, 0.1, 0.0], &mut ja)
        .unwrap();
    let expected = DMatrix::from_row_slice(
        4,
        4,
        &[
            0.0, 0.0, 1.0, 0.0, //
            0.0, 0.0, 0.0, 1.0, //
            0.0, 0.0, 0.0, 0.0, //
            0.0, 0.0, 0.0, 0.0,
        ],
    );
    assert_eq!(ja, expected);
}
