//! Standard models for tests, benchmarks and comparisons with other engines (in the spirit
//! of Drake's `multibody/benchmarks`).

use crate::builder::{BodySpec, JointKind, ModelBuilder, Placement};
use crate::elements::{
    AppliedLoad, Attachment, FrictionLaw, JointSpringDamper, LoadFrame, PivotFriction,
    PointSpringDamper, SpringLaw,
};
use crate::error::Result;
use crate::model::Model;
use crate::system::System;
use crate::time_function::{PiecewiseLinear, SmoothMove};

/// Featherstone's `planar(n)` chain (spatial_v2): `n` unit links of 1 kg along their x axes,
/// centre of mass at mid-link, inertia 1/12 kg·m² about it, revolute joints at the link
/// ends, gravity (0, −9.81). `planar_chain(5)` is the model of the Pinocchio reference file.
/// `n = 0` is taken as 1 (a model needs a moving body).
pub fn planar_chain(n: usize) -> Model {
    let n = n.max(1);
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81]);
    for i in 0..n {
        let name = format!("link{}", i + 1);
        let parent = (i > 0).then(|| format!("link{i}"));
        let x = if i == 0 { 0.0 } else { 1.0 };
        b.add_link(
            &name,
            parent.as_deref(),
            JointKind::Revolute,
            Placement::offset(x, 0.0),
            BodySpec::new(1.0, [0.5, 0.0], 1.0 / 12.0),
        );
    }
    b.build()
        .unwrap_or_else(|e| unreachable!("planar_chain is valid: {e}"))
}

/// The state at which benchmarks and the Pinocchio comparison (`benches/compare/`) evaluate
/// a model: `(q, v, a)` of the Pinocchio reference file for the 5-link chain, and for any
/// other model the deterministic spread `2 sin((i + 1) k)` with `k = 0.7, 1.3, 2.9`.
pub fn benchmark_state(model: &Model) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = model.nv();
    if n == 5 {
        (
            vec![
                1.721316619099806,
                -0.38403808930179695,
                2.2531371815723604,
                1.2400999002927886,
                -2.5498589250729733,
            ],
            vec![
                1.9024894065470237,
                1.0445588079614119,
                1.1442572211078152,
                -1.4875454692978165,
                -0.19845624841773146,
            ],
            vec![
                -1.2920197576741876,
                4.267649888486018,
                1.4386512008066452,
                3.227616132708299,
                -0.5658580117266885,
            ],
        )
    } else {
        (spread(n, 0.7), spread(n, 1.3), spread(n, 2.9))
    }
}

/// `2 sin((i + 1) k)` for `i` in `0..n`: a deterministic spread of values.
pub fn spread(n: usize, k: f64) -> Vec<f64> {
    (0..n).map(|i| ((i as f64 + 1.0) * k).sin() * 2.0).collect()
}

/// A branching tree of 13 bodies on the ground: a trunk, three branches on it and three
/// twigs on each branch, mixing revolute and prismatic joints (every third twig slides),
/// with unequal masses and offsets so no symmetry hides an error.
pub fn branching_tree() -> Model {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81]);
    b.add_link(
        "trunk",
        None,
        JointKind::Revolute,
        Placement::default(),
        BodySpec::new(2.0, [0.4, 0.02], 0.15),
    );
    for i in 0..3 {
        let branch = format!("branch{i}");
        let fi = i as f64;
        b.add_link(
            &branch,
            Some("trunk"),
            JointKind::Revolute,
            Placement::new(0.3 * fi - 0.3, 0.8, 0.1 * fi - 0.1),
            BodySpec::new(1.0 + 0.2 * fi, [0.3, -0.01 * fi], 0.05 + 0.01 * fi),
        );
        for k in 0..3 {
            let fk = k as f64;
            let kind = if k == 2 {
                JointKind::Prismatic {
                    axis: [1.0, 0.2 * fi],
                }
            } else {
                JointKind::Revolute
            };
            b.add_link(
                &format!("twig{i}{k}"),
                Some(&branch),
                kind,
                Placement::new(0.2 * fk - 0.2, 0.5 + 0.05 * fk, 0.03 * fk),
                BodySpec::new(0.3 + 0.1 * fk, [0.2, 0.01], 0.01 + 0.002 * fk),
            );
        }
    }
    b.build()
        .unwrap_or_else(|e| unreachable!("branching_tree is valid: {e}"))
}

/// The [`branching_tree`] with one of every standard force element and a prescribed
/// coordinate: a preloaded joint spring–damper, a point spring–damper to the ground, pivot
/// friction (with a Stribeck peak and reversal events) on every joint, a force that follows a
/// table and turns with its body, a torque given by a closure, and a smooth prescribed move
/// of one twig. The workload of an integrator step, for benchmarks and allocation tests.
pub fn branching_tree_system() -> Result<System> {
    let model = branching_tree();
    let mut system = System::new(model.clone());
    let spring = SpringLaw::new(3.0, 0.1).with_damping(0.2).with_preload(0.5);
    system.add_element(JointSpringDamper::new(&model, "branch1", spring)?)?;
    system.add_element(PointSpringDamper::new(
        &model,
        "tether",
        Attachment::on("twig02", [0.1, 0.0]),
        Attachment::ground([1.0, 1.0]),
        SpringLaw::new(50.0, 0.3).with_damping(1.0),
    )?)?;
    let friction = FrictionLaw::coulomb(0.01, 1e-3)
        .with_viscous(0.001)
        .with_stribeck(0.02, 0.1);
    for joint in model.coordinate_names() {
        system.add_element(PivotFriction::new(&model, joint, friction)?.with_reversal_events())?;
    }
    let push = PiecewiseLinear::new(vec![(0.0, 0.0), (0.1, 5.0), (0.2, 0.0)])?;
    system.add_element(AppliedLoad::force(
        &model,
        "push",
        Attachment::on("twig11", [0.2, 0.0]),
        [0.0, -1.0],
        LoadFrame::Body,
        push,
    )?)?;
    system.add_element(AppliedLoad::torque(
        &model,
        "twist",
        "branch2",
        |t: f64| t.sin(),
    )?)?;
    system.prescribe("twig21", SmoothMove::new(0.0, 0.0, 0.5, 0.3)?)?;
    Ok(system)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn standard_models_have_expected_sizes() {
        assert_eq!(planar_chain(5).nv(), 5);
        let t = branching_tree();
        assert_eq!(t.nv(), 13);
        assert_eq!(t.nbodies(), 14);
        // Depth: trunk → branch → twig.
        let twig = t.body_id("twig21").unwrap();
        assert_eq!(t.support(twig).count(), 3);
        let s = branching_tree_system().unwrap();
        assert_eq!(s.elements().len(), 17);
        assert_eq!(s.switch_len(), 13);
    }
}
