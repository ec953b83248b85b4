//! Composite rigid-body algorithm (joint-space mass matrix), Featherstone RBDA table 6.2, and
//! forward dynamics by CRBA with the tree-sparse `LᵀL` factorisation of RBDA §6.5.

use nalgebra::{DMatrix, DVector};

use crate::data::Data;
use crate::error::{CoreError, Result, check_input};
use crate::model::Model;
use crate::rnea::{Output, check_forces, rnea_pass};
use crate::spatial::Force;

/// The joint-space mass matrix `M(q)` (full and symmetric), written to
/// `data.mass_matrix()` and returned.
pub fn crba<'d>(model: &Model, data: &'d mut Data, q: &[f64]) -> Result<&'d DMatrix<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    crba_pass(model, data, q);
    Ok(&data.mass_matrix)
}

pub(crate) fn crba_pass(model: &Model, data: &mut Data, q: &[f64]) {
    let bodies = &model.bodies;
    let nb = bodies.len();
    for i in 1..nb {
        let b = &bodies[i];
        let x = b.joint_transform(q[b.idx_v]);
        data.x_up[i] = x;
        data.x_world[i] = data.x_world[b.parent].compose(&x);
        data.ic[i] = b.inertia;
    }
    // IC_λ += Xᵀ IC_i X
    for i in (1..nb).rev() {
        let p = bodies[i].parent;
        if p > 0 {
            let ic = data.ic[i].to_parent(&data.x_up[i]);
            data.ic[p] += ic;
        }
    }
    let n = model.nv();
    let m = data.mass_matrix.as_mut_slice();
    m.fill(0.0);
    for i in 1..nb {
        let bi = &bodies[i];
        // F = IC_i S_i ;  H_ii = S_iᵀ F
        let mut f = data.ic[i].mul_motion(&bi.s);
        m[bi.idx_v * (n + 1)] = bi.s.dot(&f);
        let mut j = i;
        while bodies[j].parent > 0 {
            // F = X_jᵀ F ;  j = λ(j) ;  H_ij = H_ji = S_jᵀ F
            f = data.x_up[j].apply_force_transpose(&f);
            j = bodies[j].parent;
            let bj = &bodies[j];
            let h = bj.s.dot(&f);
            m[bi.idx_v + n * bj.idx_v] = h;
            m[bj.idx_v + n * bi.idx_v] = h;
        }
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
    // h[r + n c] with r, c = body index − 1.
    for c in 1..bodies.len() {
        for r in 1..bodies.len() {
            h[(r - 1) + n * (c - 1)] = m[bodies[r].idx_v + n * bodies[c].idx_v];
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
