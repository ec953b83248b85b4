//! Composite rigid-body algorithm (joint-space mass matrix), Featherstone RBDA table 6.2, and
//! forward dynamics by CRBA with the tree-sparse `LᵀL` factorisation of RBDA §6.5.

use nalgebra::{DMatrix, DVector};

use crate::data::{Data, add_to_parent};
use crate::error::{CoreError, Result, check_input};
use crate::kinematics::joint_transforms;
use crate::model::{BodyModel, JointType, Model};
use crate::rnea::{Output, check_forces, rnea_pass};
use crate::spatial::{Force, Inertia};

/// The joint-space mass matrix `M(q)` (full and symmetric), written to
/// `data.mass_matrix()` and returned.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d DMatrix<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    crba_pass(model, data, q);
    Ok(&data.mass_matrix)
}

/// The CRBA passes: joint transforms and poses for `q`, composite inertias, then the mass
/// matrix column by column.
pub(crate) fn crba_pass(model: &Model, data: &mut Data, q: &[f64]) {
    joint_transforms(model, data, q);
    let bodies = model.bodies.as_slice();
    let nb = bodies.len();
    // Per-body arrays cut to the body count: indexing by the loop counter needs no check.
    let x_up = &data.x_up[..nb];
    let ic = &mut data.ic[..nb];
    ic[0] = Inertia::ZERO;
    for i in 1..nb {
        ic[i] = bodies[i].inertia;
    }
    // IC_λ += Xᵀ IC_i X, children first (higher index), the contribution of body i + 1 to
    // body i riding in registers ([`add_to_parent`]); a rigid-body inertia stays four numbers
    // (m, m c, I_o) in every frame. ic[0] collects the roots' shares, unused: that spares a
    // branch per body.
    let mut carry = Inertia::ZERO;
    for i in (1..nb).rev() {
        let ic_i = ic[i] + carry;
        ic[i] = ic_i;
        carry = add_to_parent(ic, ic_i.to_parent(&x_up[i]), i, bodies[i].parent);
    }
    let n = model.nv();
    let m = data.mass_matrix.as_mut_slice();
    m.fill(0.0);
    for i in 1..nb {
        let bi = &bodies[i];
        let (iv, col) = (bi.idx_v, bi.idx_v * n);
        // F = IC_i S_i ;  H_ii = S_iᵀ F
        let mut f = composite_times_s(bi, &ic[i]);
        m[col + iv] = s_dot_composite(bi, &f);
        let (mut j, mut p) = (i, bi.parent);
        while p > 0 {
            // F = X_jᵀ F ;  j = λ(j) ;  H_ij = H_ji = S_jᵀ F
            f = x_up[j].apply_force_transpose(&f);
            let bp = &bodies[p];
            let h = s_dot_composite(bp, &f);
            m[col + bp.idx_v] = h;
            m[bp.idx_v * n + iv] = h;
            (j, p) = (p, bp.parent);
        }
    }
}

/// `IC S` for a body's joint: the first column of the inertia matrix for a revolute joint
/// (`[I_o, −h_y, h_x]`), two columns combined for a prismatic one.
#[inline(always)]
fn composite_times_s(b: &BodyModel, ic: &Inertia) -> Force {
    match b.joint {
        JointType::Revolute => Force::new(ic.i_o, -ic.hy, ic.hx),
        JointType::Prismatic { .. } => ic.mul_motion(&b.s),
    }
}

/// `Sᵀ F` for `F = IC S` carried up the tree, reading only the components `S` selects
/// (compare [`BodyModel::s_dot`], which keeps the zero products so that overflowed forces
/// show). Here no component can overflow alone: a first moment `m c` too large for a double
/// comes with a rotational inertia `m |c|²` larger still, and that reaches the moment `n`.
#[inline(always)]
fn s_dot_composite(b: &BodyModel, f: &Force) -> f64 {
    match b.joint {
        JointType::Revolute => f.n,
        JointType::Prismatic { .. } => b.s.vx * f.fx + b.s.vy * f.fy,
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
    // The CRBA pass has just set the joint transforms and poses for q.
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
