//! Recursive Newton–Euler algorithm (inverse dynamics), Featherstone RBDA table 5.1,
//! specialised to the plane; gravity enters as the base acceleration `a₀ = −g`.

use nalgebra::DVector;

use crate::data::Data;
use crate::error::{CoreError, Result, check_input};
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
pub(crate) fn rnea_pass(
    model: &Model,
    data: &mut Data,
    q: Option<&[f64]>,
    v: Option<&[f64]>,
    a: Option<&[f64]>,
    f_ext: Option<&[Force]>,
    output: Output,
) {
    let g = model.gravity;
    data.v[0] = Motion::ZERO;
    data.a[0] = Motion::new(0.0, -g[0], -g[1]);
    let bodies = &model.bodies;
    for i in 1..bodies.len() {
        let b = &bodies[i];
        let iv = b.idx_v;
        let x = match q {
            Some(q) => {
                let x = b.joint_transform(q[iv]);
                data.x_up[i] = x;
                data.x_world[i] = data.x_world[b.parent].compose(&x);
                x
            }
            None => data.x_up[i],
        };
        let qd = v.map_or(0.0, |v| v[iv]);
        let qdd = a.map_or(0.0, |a| a[iv]);
        let vj = b.s * qd;
        // v_i = X v_λ + S q̇ ;  a_i = X a_λ + S q̈ + v_i ×ₘ S q̇
        let vi = x.apply_motion(&data.v[b.parent]) + vj;
        let ai = x.apply_motion(&data.a[b.parent]) + b.s * qdd + vi.cross_motion(&vj);
        data.v[i] = vi;
        data.a[i] = ai;
        // f_i = I a_i + v_i ×f I v_i − f_ext,i
        let mut f = b.inertia.mul_motion(&ai) + vi.cross_force(&b.inertia.mul_motion(&vi));
        if let Some(fe) = f_ext {
            f -= fe[i];
        }
        data.f[i] = f;
    }
    let out = match output {
        Output::Tau => data.tau.as_mut_slice(),
        Output::Nle => data.nle.as_mut_slice(),
        Output::Gravity => data.gravity.as_mut_slice(),
    };
    for i in (1..bodies.len()).rev() {
        let b = &bodies[i];
        // τ_i = Sᵀ f_i ;  f_λ += Xᵀ f_i
        out[b.idx_v] = b.s.dot(&data.f[i]);
        if b.parent > 0 {
            let fp = data.x_up[i].apply_force_transpose(&data.f[i]);
            data.f[b.parent] += fp;
        }
    }
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
    let bodies = &model.bodies;
    acc.copy_from_slice(f_local);
    for i in (1..bodies.len()).rev() {
        let b = &bodies[i];
        out[b.idx_v] = b.s.dot(&acc[i]);
        if b.parent > 0 {
            let fp = data.x_up[i].apply_force_transpose(&acc[i]);
            acc[b.parent] += fp;
        }
    }
}
