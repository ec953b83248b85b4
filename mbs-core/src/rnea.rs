//! Recursive Newton–Euler algorithm (inverse dynamics), Featherstone RBDA table 5.1,
//! specialised to the plane; gravity enters as the base acceleration `a₀ = −g`.

use nalgebra::DVector;

use crate::data::{Data, add_to_parent, parent_entry};
use crate::error::{CoreError, Result, check_input};
use crate::kinematics::joint_transforms_and_poses;
use crate::model::Model;
use crate::spatial::{Force, Motion};

/// Inverse dynamics: the generalized forces `τ = M(q) a + C(q, v) v + g(q)` that produce
/// acceleration `a` at `(q, v)`. Written to `data.tau()` and returned.
///
/// ```
/// use mbs_core::{Data, Model};
/// let json = r#"{"gravity": [0.0, -9.81], "joints": [{"name": "arm", "parent": null,
///   "kind": "revolute", "placement": {"angle": 0.0, "x": 0.0, "y": 0.0},
///   "body": {"mass": 2.0, "com": [0.5, 0.0], "inertia": 0.1}}]}"#;
/// let model = Model::from_json_str(json).unwrap();
/// let mut data = Data::new(&model);
/// // Holding a horizontal arm still takes m g l = 2 · 9.81 · 0.5 N·m.
/// let tau = mbs_core::rnea(&model, &mut data, &[0.0], &[0.0], &[0.0]).unwrap();
/// assert!((tau[0] - 9.81).abs() < 1e-12);
/// ```
pub fn rnea<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Result<&'d DVector<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    check_input("v", v, model.nv())?;
    check_input("a", a, model.nv())?;
    rnea_pass(model, data, Some(q), Some(v), Some(a), None, Output::Tau);
    Ok(&data.tau)
}

/// Inverse dynamics with external forces: `f_ext[b]` is the spatial force applied to body
/// `b`, expressed in its joint frame (length [`Model::nbodies`]; entry 0, the ground, is
/// ignored). Returns `τ = M a + C v + g − Σ Jᵀ f_ext`.
pub fn rnea_with_forces<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
    f_ext: &[Force],
) -> Result<&'d DVector<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    check_input("v", v, model.nv())?;
    check_input("a", a, model.nv())?;
    check_forces(model, f_ext)?;
    rnea_pass(
        model,
        data,
        Some(q),
        Some(v),
        Some(a),
        Some(f_ext),
        Output::Tau,
    );
    Ok(&data.tau)
}

/// Nonlinear effects `C(q, v) v + g(q)` (RNEA with zero acceleration), written to
/// `data.nonlinear_effects()` and returned.
pub fn nonlinear_effects<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
) -> Result<&'d DVector<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    check_input("v", v, model.nv())?;
    rnea_pass(model, data, Some(q), Some(v), None, None, Output::Nle);
    Ok(&data.nle)
}

/// Gravity generalized forces `g(q)` (RNEA with zero velocity and acceleration), written to
/// `data.gravity_torque()` and returned.
pub fn gravity_torque<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
) -> Result<&'d DVector<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    rnea_pass(model, data, Some(q), None, None, None, Output::Gravity);
    Ok(&data.gravity)
}

/// Checks the length and finiteness of a per-body force array.
pub(crate) fn check_forces(model: &Model, f_ext: &[Force]) -> Result<()> {
    if f_ext.len() != model.nbodies() {
        return Err(CoreError::DimensionMismatch {
            what: "f_ext",
            expected: model.nbodies(),
            got: f_ext.len(),
        });
    }
    // Entry 0 (the ground) is ignored, so it may hold anything.
    if let Some(index) = f_ext
        .iter()
        .skip(1)
        .position(|f| !f.is_finite())
        .map(|i| i + 1)
    {
        let f = f_ext[index];
        let value = [f.n, f.fx, f.fy]
            .into_iter()
            .find(|x| !x.is_finite())
            .unwrap_or(f64::NAN);
        return Err(CoreError::NonFiniteInput {
            what: "f_ext",
            index,
            value,
        });
    }
    Ok(())
}

/// Which joint-space vector receives the result.
#[derive(Clone, Copy)]
pub(crate) enum Output {
    Tau,
    Nle,
    Gravity,
}

/// RNEA proper; `None` velocity or acceleration means zero; `None` configuration means the
/// joint transforms and poses in `data` are already those of the configuration.
///
/// Always inlined: each caller passes constant `Some`/`None` arguments, so each gets a copy
/// with the unused terms removed (no velocity products in `gravity_torque`, no `S q̈` in
/// `nonlinear_effects`, no joint transforms after the CRBA has made them).
#[inline(always)]
pub(crate) fn rnea_pass(
    model: &Model,
    data: &mut Data,
    q: Option<&[f64]>,
    v: Option<&[f64]>,
    a: Option<&[f64]>,
    f_ext: Option<&[Force]>,
    output: Output,
) {
    if let Some(q) = q {
        joint_transforms_and_poses(model, data, q);
    }
    let bodies = model.bodies.as_slice();
    let nb = bodies.len();
    let g = model.gravity;
    // Per-body arrays cut to the body count: indexing by the loop counter needs no check.
    let x_up = &data.x_up[..nb];
    let vel = &mut data.v[..nb];
    let acc = &mut data.a[..nb];
    let frc = &mut data.f[..nb];
    let a0 = Motion::new(0.0, -g[0], -g[1]);
    vel[0] = Motion::ZERO;
    acc[0] = a0;
    // The previous body's velocity and acceleration, read from registers when it is the
    // parent ([`parent_entry`]).
    let (mut v_prev, mut a_prev) = (Motion::ZERO, a0);
    for i in 1..nb {
        let b = &bodies[i];
        let p = b.parent;
        let iv = b.idx_v;
        let x = x_up[i];
        // a_i = X a_λ + S q̈ + v_i ×ₘ S q̇
        let mut ai = x.apply_motion(&parent_entry(acc, a_prev, i, p));
        if let Some(a) = a {
            ai = b.add_s(ai, a[iv]);
        }
        let (vi, f) = match v {
            Some(v) => {
                // v_i = X v_λ + S q̇ ;  f_i = I a_i + v_i ×f I v_i
                let qd = v[iv];
                let vi = b.add_s(x.apply_motion(&parent_entry(vel, v_prev, i, p)), qd);
                ai += b.cross_s(&vi, qd);
                let f = b.inertia.mul_motion(&ai) + vi.cross_force(&b.inertia.mul_motion(&vi));
                (vi, f)
            }
            None => (Motion::ZERO, b.inertia.mul_motion(&ai)),
        };
        vel[i] = vi;
        acc[i] = ai;
        (v_prev, a_prev) = (vi, ai);
        // − f_ext,i
        frc[i] = match f_ext {
            Some(fe) => f - fe[i],
            None => f,
        };
    }
    let out = match output {
        Output::Tau => data.tau.as_mut_slice(),
        Output::Nle => data.nle.as_mut_slice(),
        Output::Gravity => data.gravity.as_mut_slice(),
    };
    let mut carry = Force::ZERO;
    for i in (1..nb).rev() {
        let b = &bodies[i];
        // τ_i = Sᵀ f_i ;  f_λ += Xᵀ f_i, the contribution of body i + 1 to body i riding in
        // registers ([`add_to_parent`]); the ground's entry takes the roots' shares.
        let fi = frc[i] + carry;
        frc[i] = fi;
        out[b.idx_v] = b.s_dot(&fi);
        carry = add_to_parent(frc, x_up[i].apply_force_transpose(&fi), i, b.parent);
    }
    // The ground's entry took the base reaction of any root after the first.
    frc[0] = Force::ZERO;
}

/// Generalized forces `Σ Jᵀ f` of body forces `f_local` (body frames), using the joint
/// transforms in `data.x_up`: a backward pass accumulating subtree forces. `acc` is
/// scratch of length nbodies.
pub(crate) fn body_forces_to_generalized(
    model: &Model,
    data: &Data,
    f_local: &[Force],
    acc: &mut [Force],
    out: &mut [f64],
) {
    let bodies = model.bodies.as_slice();
    let nb = bodies.len();
    let x_up = &data.x_up[..nb];
    let acc = &mut acc[..nb];
    acc.copy_from_slice(&f_local[..nb]);
    for i in (1..nb).rev() {
        let b = &bodies[i];
        // τ_i = Sᵀ f_i ;  f_λ += Xᵀ f_i (acc[0], scratch, takes the ground's share)
        let fi = acc[i];
        out[b.idx_v] = b.s_dot(&fi);
        acc[b.parent] += x_up[i].apply_force_transpose(&fi);
    }
}
