//! Composite rigid-body algorithm (joint-space mass matrix), Featherstone RBDA table 6.2, and
//! forward dynamics by CRBA with the tree-sparse `LᵀL` factorisation of RBDA §6.5.

use nalgebra::{DMatrix, DVector};

use crate::data::{Data, add_to_parent};
use crate::error::{CoreError, Result, check_input};
use crate::kinematics::{joint_sin_cos, transforms_from_sin_cos, world_poses};
use crate::layout::{CrbaBody, CrbaJoint};
use crate::model::Model;
use crate::rnea::{Output, check_forces, rnea_pass};
use crate::spatial::{Force, Inertia, Motion, Transform};

/// The joint-space mass matrix `M(q)` (full and symmetric), written to
/// `data.mass_matrix()` and returned.
///
/// Only the mass matrix is computed: the world poses in `data` (see [`Data::body_pose`]) are
/// left as the last other call set them, since the algorithm needs only the joint transforms
/// (as Pinocchio's `crba` does); [`crate::update_poses`] gives them.
///
/// ```
/// use mbs_core::{Data, benchmarks::planar_chain, crba};
/// let model = planar_chain(2);
/// let mut data = Data::new(&model);
/// let m = crba(&model, &mut data, &[0.0, 0.0]).unwrap();
/// // Two unit rods stretched out: 1/3 + (1/12 + 1.5²) = 8/3 about the base, 1/3 about the
/// // elbow.
/// assert!((m[(0, 0)] - 8.0 / 3.0).abs() < 1e-12);
/// assert!((m[(1, 1)] - 1.0 / 3.0).abs() < 1e-12);
/// assert_eq!(m[(0, 1)], m[(1, 0)]);
/// ```
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d DMatrix<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    crba_pass(model, data, q);
    Ok(&data.mass_matrix)
}

/// The CRBA for `q` (inputs already checked): the joint angles' sines and cosines, then one
/// backward pass that completes each body's composite inertia and, while it is at hand, fills
/// that body's row and column of the mass matrix.
///
/// Leaves first, so that when body i is reached all its descendants have been and
/// `IC_i = I_i + Σ_children Xᵀ IC_c X` is complete. For the column of body j, the force
/// `F_j = IC_j S_j` is carried up the tree, one joint transform at a time, and
/// `H_ij = H_ji = S_iᵀ F_j` read off at each ancestor i (Featherstone RBDA table 6.2). Here the
/// forces of all of i's descendants are carried up together: they sit in consecutive slots
/// (the model's depth-first preorder, [`crate::layout`]), body i reads its row and column of
/// the mass matrix off that block, then moves the block into its parent's frame. Every
/// entry comes out of the same operations in the same order as the one-column-at-a-time
/// recursion, so the matrix is the same to the bit (the unit tests compare the two).
///
/// Leaves `data.x_up` and the poses alone: [`forward_dynamics_crba`] makes them after.
pub(crate) fn crba_pass(model: &Model, data: &mut Data, q: &[f64]) {
    joint_sin_cos(model, data, q);
    let layout = &model.layout;
    let plan = layout.crba.as_slice();
    let nb = plan.len();
    let n = model.nv();
    // Per-body arrays cut to the body count: indexing by the loop counter needs no check.
    let (sin_q, cos_q) = (&data.sin_q[..n], &data.cos_q[..n]);
    let ic = &mut data.ic[..nb];
    // Only a body with children other than the next body keeps a running sum in ic, which
    // they add into; every other body starts from its own inertia, read from the model.
    ic[0] = Inertia::ZERO;
    for &i in &layout.gathering {
        ic[i] = plan[i].inertia;
    }
    let m = data.mass_matrix.as_mut_slice();
    // Entries between bodies on different branches (a chain has none) are never written
    // here: zeroed once, when the workspace last held another model's matrix, they stay so.
    if data.mass_matrix_zeros_for != layout.id {
        m.fill(0.0);
        data.mass_matrix_zeros_for = layout.id;
    }
    let column_force = &mut data.column_force[..n];
    // IC_λ += Xᵀ IC_i X, the contribution of body i + 1 to body i riding in registers
    // ([`add_to_parent`]); a rigid-body inertia stays four numbers (m, m c, I_o) in every
    // frame. ic[0] collects the roots' shares, unused: that spares a branch per body.
    let mut carry = Inertia::ZERO;
    for i in (1..nb).rev() {
        let b = &plan[i];
        let own = if b.gathers { &ic[i] } else { &b.inertia };
        let ic_i = *own + carry;
        let iv = b.coordinate;
        // X_i (the joint transform) ;  Xᵀ IC_i X ;  F_i = IC_i S_i
        let (x, share, f) = match b.joint {
            CrbaJoint::Revolute { origin, offsets } => {
                let x = Transform {
                    c: cos_q[iv],
                    s: sin_q[iv],
                    x: origin[0],
                    y: origin[1],
                };
                let f = Force::new(ic_i.i_o, -ic_i.hy, ic_i.hx);
                (x, composite_to_parent(&ic_i, &x, &offsets), f)
            }
            CrbaJoint::Prismatic {
                axis,
                at_zero,
                axis_parent,
            } => {
                // As BodyModel::joint_transform.
                let x = Transform {
                    x: at_zero.x + q[iv] * axis_parent[0],
                    y: at_zero.y + q[iv] * axis_parent[1],
                    ..at_zero
                };
                let f = ic_i.mul_motion(&Motion::new(0.0, axis[0], axis[1]));
                (x, ic_i.to_parent(&x), f)
            }
        };
        carry = add_to_parent(ic, share, i, b.parent);
        // The block of i's subtree: F_i, in registers, then the forces the descendants have
        // brought into frame i; F_i, moved into the parent's frame, joins them after.
        let (slot_i, below) = column_force[b.first..b.end].split_at_mut(1);
        slot_i[0] = if layout.coordinates_in_preorder {
            // The block's rows of column i run down from its diagonal; row i mirrors them.
            let top = iv * n + iv;
            column_block(b, &x, f, below, |t, h| {
                m[top + t] = h;
                m[top + t * n] = h;
            })
        } else {
            let rows = &layout.coordinate_in_preorder[b.first..b.end];
            column_block(b, &x, f, below, |t, h| {
                m[iv * n + rows[t]] = h;
                m[rows[t] * n + iv] = h;
            })
        };
    }
}

/// Body i's pass over its block of columns: `H_ij = S_iᵀ F_j` handed to `write(t, H_ij)` for
/// the block's t-th column, then, unless i is a root, `F_j = X_iᵀ F_j` into the parent's
/// frame. The block is `F_i = f`, still in registers, then the descendants' forces
/// `below` (in frame i), which are written back in place; `F_i` in the parent's frame is
/// returned. The joint kind and the root test are settled once, outside the loop.
///
/// `S_iᵀ F` reads only the components `S_i` selects (compare [`BodyModel::s_dot`], which
/// keeps the zero products so that overflowed forces show). Here no component can overflow
/// alone: a first moment `m c` too large for a double comes with a rotational inertia
/// `m |c|²` larger still, and that reaches the moment `n`.
///
/// [`BodyModel::s_dot`]: crate::model::BodyModel::s_dot
#[inline(always)]
fn column_block(
    b: &CrbaBody,
    x: &Transform,
    f: Force,
    below: &mut [Force],
    write: impl FnMut(usize, f64),
) -> Force {
    #[inline(always)]
    fn each<const TO_PARENT: bool>(
        s_dot: impl Fn(&Force) -> f64,
        x: Transform,
        f: Force,
        below: &mut [Force],
        mut write: impl FnMut(usize, f64),
    ) -> Force {
        write(0, s_dot(&f));
        for (t, f) in below.iter_mut().enumerate() {
            write(t + 1, s_dot(f));
            if TO_PARENT {
                *f = x.apply_force_transpose(f);
            }
        }
        if TO_PARENT {
            x.apply_force_transpose(&f)
        } else {
            f
        }
    }
    let x = *x;
    match (b.joint, b.parent > 0) {
        (CrbaJoint::Revolute { .. }, true) => each::<true>(|f| f.n, x, f, below, write),
        (CrbaJoint::Revolute { .. }, false) => each::<false>(|f| f.n, x, f, below, write),
        (CrbaJoint::Prismatic { axis: [ax, ay], .. }, true) => {
            each::<true>(|f| ax * f.fx + ay * f.fy, x, f, below, write)
        }
        (CrbaJoint::Prismatic { axis: [ax, ay], .. }, false) => {
            each::<false>(|f| ax * f.fx + ay * f.fy, x, f, below, write)
        }
    }
}

/// [`Inertia::to_parent`] for the composite inertia of a body on a revolute joint, whose
/// origin `(x.x, x.y)` does not move: the terms `[m x, m y, m (x² + y²)]` that involve only
/// that origin and the subtree's mass `m` (a constant of the model) come from the model's
/// layout, and the rest is computed as `to_parent` computes it, so the result is the same to
/// the bit.
#[inline(always)]
fn composite_to_parent(ic: &Inertia, x: &Transform, offsets: &[f64; 3]) -> Inertia {
    let rh = x.rotate([ic.hx, ic.hy]);
    Inertia {
        m: ic.m,
        hx: rh[0] + offsets[0],
        hy: rh[1] + offsets[1],
        i_o: ic.i_o + 2.0 * (x.x * rh[0] + x.y * rh[1]) + offsets[2],
    }
}

/// Forward dynamics by CRBA and Cholesky: `q̈ = M⁻¹ (τ − C v − g)`, written to
/// `data.qdd()` and returned. Equal to [`crate::aba`] to rounding; cheaper when the mass
/// matrix is wanted anyway (implicit integrators, contact Jacobians). Also leaves
/// `data.mass_matrix()` filled, and `data.nonlinear_effects()` holding `C v + g − Σ Jᵀ f_ext`
/// (the external forces included when given).
pub fn forward_dynamics_crba<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: Option<&[Force]>,
) -> Result<&'d DVector<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    check_input("v", v, model.nv())?;
    check_input("tau", tau, model.nv())?;
    if let Some(f) = f_ext {
        check_forces(model, f)?;
    }
    crba_pass(model, data, q);
    // The CRBA pass has just taken the joint angles' sines and cosines for q; the joint
    // transforms and poses complete the kinematics that every dynamics call leaves.
    transforms_from_sin_cos(model, data, q);
    world_poses(model, data);
    rnea_pass(model, data, None, Some(v), None, f_ext, Output::Nle);
    factor_mass_matrix(model, data)?;
    let bodies = &model.bodies;
    for i in 1..bodies.len() {
        let iv = bodies[i].idx_v;
        data.rhs[i - 1] = tau[iv] - data.nle[iv];
    }
    solve_factored(model, &data.factor, &mut data.rhs);
    for i in 1..bodies.len() {
        data.qdd[bodies[i].idx_v] = data.rhs[i - 1];
    }
    Ok(&data.qdd)
}

/// Copies `data.mass_matrix` into `data.factor` in body order and factors it in place as
/// `H = Lᵀ L` (Featherstone RBDA table 6.3): the factor keeps the sparsity of the tree, so
/// the cost is O(n d²) for depth d and nothing fills in between branches.
pub(crate) fn factor_mass_matrix(model: &Model, data: &mut Data) -> Result<()> {
    let bodies = &model.bodies;
    let n = model.nv();
    let m = data.mass_matrix.as_slice();
    let h = &mut data.factor;
    // h[r + n c] with r, c = body index − 1, for c = r and its ancestors: the only entries
    // the factorisation reads or writes (the others stay zero in L), so the only ones copied.
    for r in 1..bodies.len() {
        let row = bodies[r].idx_v;
        let mut c = r;
        while c > 0 {
            h[(r - 1) + n * (c - 1)] = m[row + n * bodies[c].idx_v];
            c = bodies[c].parent;
        }
    }
    let parent = |k: usize| bodies[k + 1].parent.checked_sub(1);
    for k in (0..n).rev() {
        let hkk = h[k + n * k];
        if hkk.is_nan() || hkk <= 0.0 {
            return Err(CoreError::NotPositiveDefinite {
                coordinate: model.joint_names[bodies[k + 1].idx_v].clone(),
            });
        }
        let lkk = hkk.sqrt();
        h[k + n * k] = lkk;
        let mut i = parent(k);
        while let Some(ii) = i {
            h[k + n * ii] /= lkk;
            i = parent(ii);
        }
        // H_ij −= L_ki L_kj for the ancestors i of k and the ancestors j of i.
        let mut i = parent(k);
        while let Some(ii) = i {
            let lki = h[k + n * ii];
            let mut j = Some(ii);
            while let Some(jj) = j {
                h[ii + n * jj] -= lki * h[k + n * jj];
                j = parent(jj);
            }
            i = parent(ii);
        }
    }
    Ok(())
}

/// Solves `Lᵀ L x = b` in place (body order), `L` from [`factor_mass_matrix`].
pub(crate) fn solve_factored(model: &Model, l: &[f64], b: &mut [f64]) {
    let bodies = &model.bodies;
    let n = b.len();
    let parent = |k: usize| bodies[k + 1].parent.checked_sub(1);
    // y = L⁻ᵀ b, from the leaves up.
    for k in (0..n).rev() {
        b[k] /= l[k + n * k];
        let bk = b[k];
        let mut i = parent(k);
        while let Some(ii) = i {
            b[ii] -= l[k + n * ii] * bk;
            i = parent(ii);
        }
    }
    // x = L⁻¹ y, from the roots down.
    for k in 0..n {
        let mut i = parent(k);
        let mut s = b[k];
        while let Some(ii) = i {
            s -= l[k + n * ii] * b[ii];
            i = parent(ii);
        }
        b[k] = s / l[k + n * k];
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::DMatrix;

    use crate::kinematics::joint_transforms;
    use crate::model::{JointType, Model};
    use crate::spatial::{Force, Inertia};
    use crate::{BodySpec, Data, JointKind, ModelBuilder, Placement, crba};

    /// The textbook CRBA (Featherstone RBDA table 6.2) on the same joint transforms: composite
    /// inertias summed into each parent in decreasing body order, then each column's force
    /// carried up its ancestors one joint transform at a time. The pass under test must give
    /// the same matrix to the bit.
    fn textbook_crba(model: &Model, data: &mut Data, q: &[f64]) -> DMatrix<f64> {
        joint_transforms(model, data, q);
        let (bodies, x_up) = (&model.bodies, &data.x_up);
        let n = model.nv();
        let mut ic: Vec<Inertia> = bodies.iter().map(|b| b.inertia).collect();
        for i in (1..bodies.len()).rev() {
            let share = ic[i].to_parent(&x_up[i]);
            ic[bodies[i].parent] += share;
        }
        let s_dot = |i: usize, f: &Force| match bodies[i].joint {
            JointType::Revolute => f.n,
            JointType::Prismatic { .. } => bodies[i].s.vx * f.fx + bodies[i].s.vy * f.fy,
        };
        let mut m = DMatrix::zeros(n, n);
        for i in 1..bodies.len() {
            let iv = bodies[i].idx_v;
            let mut f = match bodies[i].joint {
                JointType::Revolute => Force::new(ic[i].i_o, -ic[i].hy, ic[i].hx),
                JointType::Prismatic { .. } => ic[i].mul_motion(&bodies[i].s),
            };
            m[(iv, iv)] = s_dot(i, &f);
            let (mut j, mut p) = (i, bodies[i].parent);
            while p > 0 {
                f = x_up[j].apply_force_transpose(&f);
                let pv = bodies[p].idx_v;
                m[(pv, iv)] = s_dot(p, &f);
                m[(iv, pv)] = m[(pv, iv)];
                (j, p) = (p, bodies[p].parent);
            }
        }
        m
    }

    /// A deterministic stream of numbers in [0, 1).
    struct Lcg(u64);
    impl Lcg {
        fn next(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }
        fn pick(&mut self, n: usize) -> usize {
            ((self.next() * n as f64) as usize).min(n - 1)
        }
    }

    /// A random forest of up to 12 links, declared in random order: revolute, prismatic and
    /// fixed joints, links hanging from any earlier link or from the ground.
    fn random_model(rng: &mut Lcg) -> Model {
        let links = 1 + rng.pick(12);
        let mut b = ModelBuilder::new();
        for i in 0..links {
            let parent = rng.pick(i + 1).checked_sub(1).map(|p| format!("l{p}"));
            let kind = match rng.pick(5) {
                _ if i == 0 => JointKind::Revolute,
                0..=2 => JointKind::Revolute,
                3 => JointKind::Prismatic {
                    axis: [rng.next() - 0.5, rng.next() + 0.1],
                },
                _ => JointKind::Fixed,
            };
            let at = Placement::new(6.0 * rng.next() - 3.0, rng.next() - 0.5, rng.next() - 0.5);
            let body = BodySpec::new(0.1 + rng.next(), [rng.next() - 0.5, 0.2], 0.01 + rng.next());
            b.add_link(&format!("l{i}"), parent.as_deref(), kind, at, body);
        }
        b.build().expect("a valid random model")
    }

    #[test]
    fn block_pass_equals_the_textbook_recursion_to_the_bit() {
        let mut rng = Lcg(7);
        for case in 0..400 {
            let model = random_model(&mut rng);
            let mut data = Data::new(&model);
            let mut reference = Data::new(&model);
            for round in 0..3 {
                // Round 2 takes some angles beyond the fast sine's range (|θ| > 1e5).
                let scale = if round == 2 { 3e5 } else { 4.0 };
                let q: Vec<f64> = (0..model.nv())
                    .map(|_| scale * (rng.next() - 0.5))
                    .collect();
                let want = textbook_crba(&model, &mut reference, &q);
                let got = crba(&model, &mut data, &q).unwrap();
                for (g, w) in got.iter().zip(want.iter()) {
                    assert_eq!(
                        g.to_bits(),
                        w.to_bits(),
                        "case {case}, round {round}\n{got}{want}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_workspace_passed_between_models_of_one_size_keeps_the_right_zeros() {
        // Two models with five coordinates: a chain (no zero entries) and a fan (four
        // branches off one body, zeros between them).
        let spec = BodySpec::new(1.0, [0.3, 0.1], 0.05);
        let build = |fan: bool| {
            let mut b = ModelBuilder::new();
            for i in 0..5 {
                let parent = match (i, fan) {
                    (0, _) => None,
                    (_, true) => Some("l0".to_string()),
                    (_, false) => Some(format!("l{}", i - 1)),
                };
                let at = Placement::new(0.1 * i as f64, 0.5, 0.0);
                b.add_link(
                    &format!("l{i}"),
                    parent.as_deref(),
                    JointKind::Revolute,
                    at,
                    spec,
                );
            }
            b.build().unwrap()
        };
        let (chain, fan) = (build(false), build(true));
        let q = [0.3, -0.4, 0.5, 1.1, -2.0];
        let mut shared = Data::new(&chain);
        for model in [&chain, &fan, &chain, &fan] {
            let want = crba(model, &mut Data::new(model), &q).unwrap().clone();
            assert_eq!(crba(model, &mut shared, &q).unwrap(), &want);
        }
        assert_eq!(crba(&fan, &mut shared, &q).unwrap()[(1, 2)], 0.0);
    }
}
