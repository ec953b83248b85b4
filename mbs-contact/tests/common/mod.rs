//! What several test files share: a linear law and a two-body model.

use mbs_contact::laws::NormalLaw;
use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement};

/// A linear spring law for these tests, `F = k δ`, with no closed-form derivatives.
#[derive(Debug)]
pub struct Linear(pub f64);

impl NormalLaw for Linear {
    fn force(&self, delta: f64, _rate: f64, _s: &[f64], _r: &mut [f64]) -> f64 {
        if delta > 0.0 { self.0 * delta } else { 0.0 }
    }
}

/// Two bodies on the ground under `gravity`: a slider along x, and a pendulum (a 0.4 m rod
/// of 0.2 kg) pivoted at (0.3, 0).
pub fn slider_and_arm(gravity: [f64; 2]) -> mbs_core::Model {
    let mut b = ModelBuilder::new();
    b.gravity(gravity)
        .add_link(
            "slider",
            None,
            JointKind::Prismatic { axis: [1.0, 0.0] },
            Placement::default(),
            BodySpec::new(0.5, [0.0, 0.0], 1e-3),
        )
        .add_link(
            "arm",
            None,
            JointKind::Revolute,
            Placement::offset(0.3, 0.0),
            BodySpec::rod(0.2, 0.4),
        );
    b.build().unwrap()
}
