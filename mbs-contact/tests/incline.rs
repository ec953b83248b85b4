//! A block on an inclined plane sticks below the friction angle and slides above it with
//! the acceleration theory gives, through `Contact`, an `mbs_core::System` and the stiff
//! integrator.

use mbs_contact::laws::{KelvinVoigt, RegularizedCoulomb};
use mbs_contact::{Contact, ContactSide, Shape};
use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement, System};
use mbs_integrators::{Method, MultibodyOde, Options, solve};

const G: f64 = 9.81;
const MU: f64 = 0.3;

/// Runs the block for `t_end` on a plane tilted by `theta` (gravity tilted instead of the
/// plane) and returns (displacement along the slope, final slope velocity).
fn slide(theta: f64, t_end: f64) -> (f64, f64) {
    let mut b = ModelBuilder::new();
    // x along the slope (down-slope positive), y normal to it.
    b.gravity([G * theta.sin(), -G * theta.cos()])
        .add_link(
            "carrier",
            None,
            JointKind::Prismatic { axis: [1.0, 0.0] },
            Placement::default(),
            BodySpec::new(1e-6, [0.0, 0.0], 1e-9),
        )
        .add_link(
            "block",
            Some("carrier"),
            JointKind::Prismatic { axis: [0.0, 1.0] },
            Placement::default(),
            BodySpec::new(1.0, [0.0, 0.05], 1e-3),
        );
    let model = b.build().unwrap();
    let (k, c) = (1e6, 2e3);
    let contact = Contact::new(
        &model,
        "block-plane",
        ContactSide::ground(vec![Shape::line([0.0, 0.0], [0.0, 1.0]).unwrap()]),
        // The block's bottom face, facing down.
        ContactSide::on(
            "block",
            vec![Shape::segment([0.05, 0.0], [-0.05, 0.0]).unwrap()],
        ),
        KelvinVoigt::new(k, c).unwrap(),
    )
    .unwrap()
    .with_friction(RegularizedCoulomb::new(MU, 1e-4).unwrap());
    let mut system = System::new(model);
    system.add_element(contact).unwrap();
    // Start at the static compression, at rest.
    let y0 = -(1.0 + 1e-6) * G * theta.cos() / k;
    let x0 = system.initial_state(0.0, &[0.0, y0], &[0.0, 0.0]).unwrap();
    let opts = Options::with_tolerances(1e-8, 1e-10);
    let sol = solve(
        &mut MultibodyOde::new(&system),
        Method::TrBdf2,
        0.0,
        &x0,
        t_end,
        &opts,
    )
    .unwrap();
    (sol.y_final[0], sol.y_final[2])
}

#[test]
fn block_sticks_below_the_friction_angle() {
    for deg in [5.0f64, 10.0, 15.0] {
        let theta = deg.to_radians();
        assert!(theta.tan() < MU);
        let (x, v) = slide(theta, 0.5);
        // Regularised friction creeps at about v_ε atanh(tan θ / μ) ≤ 1e-4 m/s.
        assert!(
            x.abs() < 1e-4 && v.abs() < 2e-4,
            "{deg}°: moved {x} m, v = {v}"
        );
    }
}

#[test]
fn block_slides_above_the_friction_angle_at_the_predicted_acceleration() {
    for deg in [20.0f64, 25.0, 35.0] {
        let theta = deg.to_radians();
        assert!(theta.tan() > MU);
        let t = 0.5;
        let (x, v) = slide(theta, t);
        // a = g (sin θ − μ cos θ): x = a t² / 2, v = a t.
        let a = G * (theta.sin() - MU * theta.cos());
        assert!(
            (v - a * t).abs() < 0.01 * a * t,
            "{deg}°: v = {v}, theory {}",
            a * t
        );
        assert!(
            (x - 0.5 * a * t * t).abs() < 0.01 * 0.5 * a * t * t,
            "{deg}°: x = {x}"
        );
    }
}
