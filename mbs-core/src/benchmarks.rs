//! Standard models for tests, benchmarks and comparisons with other engines (in the spirit
//! of Drake's `multibody/benchmarks`).

use crate::builder::{BodySpec, JointKind, ModelBuilder, Placement};
use crate::model::Model;

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
    }
}
