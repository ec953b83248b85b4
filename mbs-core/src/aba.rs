//! Articulated-body algorithm (forward dynamics), Featherstone RBDA table 7.1, specialised to
//! the plane, and its hybrid form (RBDA §9.2) in which some coordinates have prescribed
//! accelerations and return the generalized force that drives them.

use nalgebra::DVector;

use crate::data::Data;
use crate::error::{CoreError, Result, check_input};
use crate::kinematics::kinematics_pass;
use crate::model::Model;
use crate::rnea::check_forces;
use crate::spatial::{ArticulatedInertia, Force, Motion};

/// Forward dynamics: the accelerations `q̈` produced by generalized forces `τ` at `(q, v)`.
/// Written to `data.qdd()` and returned.
///
/// ```
/// use mbs_core::{BodySpec, Data, JointKind, ModelBuilder, Placement};
/// let mut b = ModelBuilder::new();
/// b.gravity([0.0, -9.81])
///     .add_link("slider", None, JointKind::Prismatic { axis: [0.0, 1.0] },
///               Placement::default(), BodySpec::new(3.0, [0.0, 0.0], 0.1));
/// let model = b.build().unwrap();
/// let mut data = Data::new(&model);
/// // A free vertical slider falls at g.
/// let qdd = mbs_core::aba(&model, &mut data, &[0.0], &[0.0], &[0.0]).unwrap();
/// assert!((qdd[0] + 9.81).abs() < 1e-12);
/// ```
pub fn aba<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
) -> Result<&'d DVector<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    check_input("v", v, model.nv())?;
    check_input("tau", tau, model.nv())?;
    kinematics_pass(model, data, q, Some(v));
    articulated_pass(model, data, v, tau, None, None);
    Ok(&data.qdd)
}

/// Forward dynamics with external forces `f_ext[b]` on each body, expressed in the body's
/// joint frame (length [`Model::nbodies`]; entry 0, the ground, is ignored).
pub fn aba_with_forces<'d>(
    model: &Model,
    data: &'d mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    f_ext: &[Force],
) -> Result<&'d DVector<f64>> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    check_input("v", v, model.nv())?;
    check_input("tau", tau, model.nv())?;
    check_forces(model, f_ext)?;
    kinematics_pass(model, data, q, Some(v));
    articulated_pass(model, data, v, tau, Some(f_ext), None);
    Ok(&data.qdd)
}

/// Which coordinates are prescribed, and their accelerations, for hybrid dynamics.
#[derive(Clone, Copy, Debug)]
pub struct Prescribed<'a> {
    /// `mask[k]` is true when coordinate `k` is prescribed (length nv).
    pub mask: &'a [bool],
    /// Accelerations of the prescribed coordinates (length nv; other entries ignored).
    pub qdd: &'a [f64],
}

/// Hybrid dynamics: coordinates with `prescribed.mask[k]` follow the given acceleration
/// `prescribed.qdd[k]`; the others are free under the generalized forces `tau[k]` (entries of
/// `tau` at prescribed coordinates are ignored). Afterwards `data.qdd()` holds every
/// acceleration and `data.tau()` every generalized force: the given ones for free
/// coordinates and, for prescribed coordinates, the whole generalized force the joint must
/// transmit (`f_ext`, if any, acts in addition).
///
/// With no coordinate prescribed it is [`aba`] (plus the output of `tau`); with all
/// prescribed it is inverse dynamics.
pub fn hybrid_dynamics(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    tau: &[f64],
    prescribed: Prescribed<'_>,
    f_ext: Option<&[Force]>,
) -> Result<()> {
    let n = model.nv();
    data.check(model)?;
    check_input("q", q, n)?;
    check_input("v", v, n)?;
    if prescribed.mask.len() != n {
        return Err(CoreError::DimensionMismatch {
            what: "prescribed.mask",
            expected: n,
            got: prescribed.mask.len(),
        });
    }
    check_masked("tau", tau, n, prescribed.mask, false)?;
    check_masked("prescribed.qdd", prescribed.qdd, n, prescribed.mask, true)?;
    if let Some(f) = f_ext {
        check_forces(model, f)?;
    }
    kinematics_pass(model, data, q, Some(v));
    articulated_pass(model, data, v, tau, f_ext, Some(prescribed));
    Ok(())
}

/// Checks length, and finiteness of the entries where `mask[k] == want`.
fn check_masked(what: &'static str, x: &[f64], n: usize, mask: &[bool], want: bool) -> Result<()> {
    if x.len() != n {
        return Err(CoreError::DimensionMismatch {
            what,
            expected: n,
            got: x.len(),
        });
    }
    for (index, (&value, &m)) in x.iter().zip(mask).enumerate() {
        if m == want && !value.is_finite() {
            return Err(CoreError::NonFiniteInput { what, index, value });
        }
    }
    Ok(())
}

/// The articulated-body passes, given `data.x_up` and `data.v` for the current `(q, v)`.
pub(crate) fn articulated_pass(
    model: &Model,
    data: &mut Data,
    v: &[f64],
    tau: &[f64],
    f_ext: Option<&[Force]>,
    prescribed: Option<Prescribed<'_>>,
) {
    let bodies = &model.bodies;
    let nb = bodies.len();
    // c_i = v_i ×ₘ S q̇ ;  IA_i = I_i ;  pA_i = v_i ×f I_i v_i − f_ext,i
    for i in 1..nb {
        let b = &bodies[i];
        let vi = data.v[i];
        data.c[i] = vi.cross_motion(&(b.s * v[b.idx_v]));
        data.ia[i] = ArticulatedInertia::from(b.inertia);
        let mut pa = vi.cross_force(&b.inertia.mul_motion(&vi));
        if let Some(fe) = f_ext {
            pa -= fe[i];
        }
        data.pa[i] = pa;
    }
    for i in (1..nb).rev() {
        let b = &bodies[i];
        let iv = b.idx_v;
        let ia = data.ia[i];
        let (ia_up, pa_up) = match prescribed {
            Some(p) if p.mask[iv] => {
                // Known q̈: the joint transmits IA as if rigid, with bias IA (c + S q̈).
                let pa = data.pa[i] + ia.mul_motion(&(data.c[i] + b.s * p.qdd[iv]));
                (ia, pa)
            }
            _ => {
                // U = IA S ; d = Sᵀ U ; u = τ − Sᵀ pA
                // Ia = IA − U Uᵀ / d ; pa = pA + Ia c + U u / d
                let u_col = ia.mul_motion(&b.s);
                let d_inv = 1.0 / b.s.dot(&u_col);
                let u = tau[iv] - b.s.dot(&data.pa[i]);
                data.u_col[i] = u_col;
                data.d_inv[i] = d_inv;
                data.u[i] = u;
                let ia_a = ia.sub_outer(&u_col, d_inv);
                let pa = data.pa[i] + ia_a.mul_motion(&data.c[i]) + u_col * (u * d_inv);
                (ia_a, pa)
            }
        };
        let p = b.parent;
        if p > 0 {
            let x = &data.x_up[i];
            let ia_p = ia_up.to_parent(x);
            let pa_p = x.apply_force_transpose(&pa_up);
            data.ia[p] += ia_p;
            data.pa[p] += pa_p;
        }
    }
    let g = model.gravity;
    data.a[0] = Motion::new(0.0, -g[0], -g[1]);
    for i in 1..nb {
        let b = &bodies[i];
        let iv = b.idx_v;
        // a' = X a_λ + c
        let a_pre = data.x_up[i].apply_motion(&data.a[b.parent]) + data.c[i];
        match prescribed {
            Some(p) if p.mask[iv] => {
                let qdd = p.qdd[iv];
                let a = a_pre + b.s * qdd;
                data.a[i] = a;
                data.qdd[iv] = qdd;
                // τ = Sᵀ (IA a + pA)
                data.tau[iv] = b.s.dot(&(data.ia[i].mul_motion(&a) + data.pa[i]));
            }
            _ => {
                // q̈ = (u − Uᵀ a') / d ;  a = a' + S q̈
                let qdd = (data.u[i] - a_pre.dot(&data.u_col[i])) * data.d_inv[i];
                data.a[i] = a_pre + b.s * qdd;
                data.qdd[iv] = qdd;
                if prescribed.is_some() {
                    data.tau[iv] = tau[iv];
                }
            }
        }
    }
}
