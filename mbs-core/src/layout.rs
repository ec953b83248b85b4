//! Tables derived once from a model's bodies, laid out for the algorithms' hot loops: the
//! revolute joints whose sines and cosines the joint transforms take a few at a time, and the
//! CRBA's per-body plan with a depth-first preorder of the bodies, in which every subtree is
//! a contiguous run (so a body's share of the mass matrix is a block of consecutive columns).
//!
//! Everything here is a function of [`BodyModel`]s only, computed when the model is built;
//! the algorithms read it and never change it.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::data::add_to_parent;
use crate::model::{BodyModel, JointType};
use crate::spatial::{Inertia, Transform};

/// The hot loops' tables of one model (see the module documentation).
#[derive(Clone, Debug)]
pub(crate) struct Layout {
    /// A number no other layout built in this process has (clones of a model share it, as
    /// they share the topology): a workspace records the layout its mass matrix's zeros
    /// were laid out for (see [`crate::Data`]).
    pub id: u64,
    /// The revolute joints, in body order.
    pub revolute_joints: Vec<RevoluteJoint>,
    /// The bodies moved by prismatic joints, in body order.
    pub prismatic_bodies: Vec<usize>,
    /// Per coordinate, the joint angle at `q = 0` (revolute joints; 0 for prismatic ones):
    /// the joint angle is `angle_at_zero + q`.
    pub angle_at_zero: Vec<f64>,
    /// The coordinates of the revolute joints, in increasing order (the joint angles whose
    /// sines and cosines the CRBA takes).
    pub revolute_coordinates: Vec<usize>,
    /// Per body (index 0, the ground, unused), what the CRBA's backward pass reads.
    pub crba: Vec<CrbaBody>,
    /// The bodies with a child other than the next body (see [`CrbaBody::gathers`]).
    pub gathering: Vec<usize>,
    /// The coordinate of the body at each position of the depth-first preorder.
    pub coordinate_in_preorder: Vec<usize>,
    /// True when every body's coordinate is its position in the preorder (bodies and joints
    /// declared depth-first, as most models are): a subtree's coordinates are then a
    /// contiguous run too, and so is its part of a column of the mass matrix.
    pub coordinates_in_preorder: bool,
}

/// A revolute joint as [`crate::kinematics::joint_transforms`] reads it: what its joint
/// transform `(cos θ, sin θ, x, y)` with `θ = θ_tree + q` needs, in one place.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RevoluteJoint {
    /// The body the joint moves (index into per-body arrays).
    pub body: usize,
    /// The joint's coordinate (index into `q`).
    pub coordinate: usize,
    /// Angle of the joint frame in the parent's joint frame at `q = 0`.
    pub theta_tree: f64,
    /// Origin of the joint frame in the parent's joint frame, x.
    pub x: f64,
    /// Origin of the joint frame in the parent's joint frame, y.
    pub y: f64,
}

/// What the CRBA's backward pass reads of one body.
#[derive(Clone, Copy, Debug)]
pub(crate) struct CrbaBody {
    /// Parent body (0 = ground).
    pub parent: usize,
    /// The body's coordinate.
    pub coordinate: usize,
    /// Positions of the body's subtree in the depth-first preorder, the body's own first:
    /// `first..end`.
    pub first: usize,
    /// See `first`.
    pub end: usize,
    /// The joint, with what the pass needs of it.
    pub joint: CrbaJoint,
    /// Whether a child other than the next body (body i + 1) hangs from this body: such
    /// children add their composite inertias into the body's slot of the workspace, which
    /// then starts from the body's own inertia; the next body's share, and every share
    /// along a chain, rides in registers instead.
    pub gathers: bool,
    /// The body's own rigid-body inertia (with merged fixed children), in its joint frame.
    pub inertia: Inertia,
}

/// A body's joint as the CRBA reads it.
#[derive(Clone, Copy, Debug)]
pub(crate) enum CrbaJoint {
    /// Revolute, whose origin `(x, y)` in the parent frame is fixed.
    Revolute {
        /// The joint frame's origin in the parent frame.
        origin: [f64; 2],
        /// The terms of the composite inertia's move into the parent frame that depend only
        /// on the origin `(x, y)` and the subtree's mass `m`, `[m x, m y, m (x² + y²)]`,
        /// each computed as [`crate::spatial::Inertia::to_parent`] computes it, with `m`
        /// summed in the order the CRBA sums it, so that they are the same numbers to the bit.
        offsets: [f64; 3],
    },
    /// Prismatic along the unit `axis` of the body frame (`S = [0, ax, ay]`).
    Prismatic {
        /// The axis in the body frame.
        axis: [f64; 2],
        /// The joint frame's pose in the parent frame at `q = 0`.
        at_zero: Transform,
        /// The axis in the parent frame: the joint frame's origin moves by `q` times it.
        axis_parent: [f64; 2],
    },
}

/// The next [`Layout::id`].
static NEXT_LAYOUT_ID: AtomicU64 = AtomicU64::new(1);

impl Layout {
    /// The tables of the model whose bodies are `bodies` (index 0 the ground, parents before
    /// children).
    pub fn new(bodies: &[BodyModel]) -> Layout {
        let nb = bodies.len();
        let mut revolute_joints = Vec::new();
        let mut prismatic_bodies = Vec::new();
        for (i, b) in bodies.iter().enumerate().skip(1) {
            match b.joint {
                JointType::Revolute => revolute_joints.push(RevoluteJoint {
                    body: i,
                    coordinate: b.idx_v,
                    theta_tree: b.theta_tree,
                    x: b.x_tree.x,
                    y: b.x_tree.y,
                }),
                JointType::Prismatic { .. } => prismatic_bodies.push(i),
            }
        }
        let nv = nb.saturating_sub(1);
        let mut angle_at_zero = vec![0.0; nv];
        for j in &revolute_joints {
            angle_at_zero[j.coordinate] = j.theta_tree;
        }

        // Depth-first preorder from the ground, children in body order: a body takes the
        // next position, and its subtree ends once all its descendants have theirs.
        let mut children = vec![Vec::new(); nb];
        for (i, b) in bodies.iter().enumerate().skip(1) {
            children[b.parent].push(i);
        }
        let mut subtree = vec![(0, 0); nb];
        let mut coordinate_in_preorder = Vec::with_capacity(nb.saturating_sub(1));
        let mut stack = vec![(0, false)];
        while let Some((i, closing)) = stack.pop() {
            if closing {
                subtree[i].1 = coordinate_in_preorder.len();
                continue;
            }
            subtree[i].0 = coordinate_in_preorder.len();
            if i > 0 {
                coordinate_in_preorder.push(bodies[i].idx_v);
            }
            stack.push((i, true));
            stack.extend(children[i].iter().rev().map(|&c| (c, false)));
        }
        let coordinates_in_preorder = coordinate_in_preorder
            .iter()
            .enumerate()
            .all(|(t, &k)| t == k);

        // The subtree masses, summed as the CRBA sums its composite inertias (into a
        // parent, its farther children first, in decreasing index, then the next body).
        let mut mass: Vec<f64> = bodies.iter().map(|b| b.inertia.m).collect();
        let mut crba = vec![
            CrbaBody {
                parent: 0,
                coordinate: 0,
                first: 0,
                end: 0,
                joint: CrbaJoint::Prismatic {
                    axis: [0.0, 0.0],
                    at_zero: Transform::IDENTITY,
                    axis_parent: [0.0, 0.0],
                },
                gathers: false,
                inertia: Inertia::ZERO,
            };
            nb
        ];
        let gathers = |i: usize| children[i].iter().any(|&c| c != i + 1);
        let mut carry = 0.0;
        for i in (1..nb).rev() {
            let b = &bodies[i];
            let m = mass[i] + carry;
            carry = add_to_parent(&mut mass, m, i, b.parent);
            let joint = match b.joint {
                JointType::Revolute => {
                    let (x, y) = (b.x_tree.x, b.x_tree.y);
                    CrbaJoint::Revolute {
                        origin: [x, y],
                        offsets: [m * x, m * y, m * (x * x + y * y)],
                    }
                }
                JointType::Prismatic { .. } => CrbaJoint::Prismatic {
                    axis: [b.s.vx, b.s.vy],
                    at_zero: b.x_tree,
                    axis_parent: b.axis_parent,
                },
            };
            crba[i] = CrbaBody {
                parent: b.parent,
                coordinate: b.idx_v,
                first: subtree[i].0,
                end: subtree[i].1,
                joint,
                gathers: gathers(i),
                inertia: b.inertia,
            };
        }
        let mut revolute_coordinates: Vec<usize> =
            revolute_joints.iter().map(|j| j.coordinate).collect();
        revolute_coordinates.sort_unstable();
        Layout {
            id: NEXT_LAYOUT_ID.fetch_add(1, Ordering::Relaxed),
            revolute_joints,
            prismatic_bodies,
            angle_at_zero,
            revolute_coordinates,
            gathering: (1..nb).filter(|&i| gathers(i)).collect(),
            crba,
            coordinate_in_preorder,
            coordinates_in_preorder,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::benchmarks::{branching_tree, planar_chain};
    use crate::{BodySpec, JointKind, ModelBuilder, Placement};

    #[test]
    fn a_chain_is_its_own_preorder() {
        let layout = &planar_chain(5).layout;
        assert!(layout.coordinates_in_preorder);
        assert_eq!(layout.revolute_joints.len(), 5);
        let blocks: Vec<(usize, usize)> =
            layout.crba[1..].iter().map(|b| (b.first, b.end)).collect();
        assert_eq!(blocks, [(0, 5), (1, 5), (2, 5), (3, 5), (4, 5)]);
    }

    #[test]
    fn the_tree_declared_depth_first_keeps_its_order() {
        let layout = &branching_tree().layout;
        assert!(layout.coordinates_in_preorder);
        assert_eq!(
            (layout.revolute_joints.len(), layout.prismatic_bodies.len()),
            (10, 3)
        );
        // trunk, then branch0 with its three twigs, ...
        assert_eq!((layout.crba[1].first, layout.crba[1].end), (0, 13));
        assert_eq!((layout.crba[2].first, layout.crba[2].end), (1, 5));
        assert_eq!((layout.crba[5].first, layout.crba[5].end), (4, 5));
    }

    #[test]
    fn subtrees_are_contiguous_in_any_declaration_order() {
        // Bodies declared breadth-first: a, b on the ground, then a1 on a, b1 on b, a2 on a.
        let mut mb = ModelBuilder::new();
        let spec = BodySpec::new(1.0, [0.1, 0.0], 0.01);
        for (name, parent) in [
            ("a", None),
            ("b", None),
            ("a1", Some("a")),
            ("b1", Some("b")),
        ] {
            mb.add_link(
                name,
                parent,
                JointKind::Revolute,
                Placement::offset(0.2, 0.0),
                spec,
            );
        }
        mb.add_link(
            "a2",
            Some("a"),
            JointKind::Revolute,
            Placement::offset(0.3, 0.0),
            spec,
        );
        let model = mb.build().unwrap();
        let layout = &model.layout;
        assert!(!layout.coordinates_in_preorder);
        // Preorder: a, a1, a2, b, b1.
        let name_at: Vec<&str> = layout
            .coordinate_in_preorder
            .iter()
            .map(|&k| model.coordinate_names()[k].as_str())
            .collect();
        assert_eq!(name_at, ["a", "a1", "a2", "b", "b1"]);
        for b in model.moving_bodies() {
            let entry = &layout.crba[b.index()];
            let members: Vec<usize> =
                layout.coordinate_in_preorder[entry.first..entry.end].to_vec();
            let mut expected: Vec<usize> = model
                .moving_bodies()
                .filter(|&d| model.support(d).any(|s| s == b))
                .map(|d| model.coordinate_of(d).unwrap())
                .collect();
            expected.sort();
            let mut got = members.clone();
            got.sort();
            assert_eq!(got, expected, "subtree of {:?}", model.body_name(b));
            assert_eq!(members[0], model.coordinate_of(b).unwrap());
        }
    }
}
