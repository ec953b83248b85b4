//! Articulated-body algorithm (forward dynamics), Featherstone RBDA table 7.1, specialised to
//! the plane, and its hybrid form (RBDA §9.2) in which some coordinates have prescribed
//! accelerations and return the generalized force that drives them.

use nalgebra::DVector;

use crate::data::{Data, add_to_parent, parent_entry};
use crate::error::{CoreError, Result, check_input};
use crate::kinematics::kinematics_pass;
use crate::model::{BodyModel, JointType, Model};
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
///
/// Always inlined, so that [`aba`] (no external forces, nothing prescribed) gets a copy
/// without the hybrid branches.
#[inline(always)]
pub(crate) fn articulated_pass(
    model: &Model,
    data: &mut Data,
    v: &[f64],
    tau: &[f64],
    f_ext: Option<&[Force]>,
    prescribed: Option<Prescribed<'_>>,
) {
    let bodies = model.bodies.as_slice();
    let nb = bodies.len();
    // Per-body arrays cut to the body count: indexing by the loop counter needs no check.
    let x_up = &data.x_up[..nb];
    let vel = &data.v[..nb];
    let acc = &mut data.a[..nb];
    let ia = &mut data.ia[..nb];
    let pa = &mut data.pa[..nb];
    let c = &mut data.c[..nb];
    let u_col = &mut data.u_col[..nb];
    let d_inv = &mut data.d_inv[..nb];
    let u = &mut data.u[..nb];
    let qdd_out = data.qdd.as_mut_slice();
    let tau_out = data.tau.as_mut_slice();
    // c_i = v_i ×ₘ S q̇ ;  IA_i = I_i ;  pA_i = v_i ×f I_i v_i − f_ext,i
    for i in 1..nb {
        let b = &bodies[i];
        let vi = vel[i];
        c[i] = b.cross_s(&vi, v[b.idx_v]);
        ia[i] = ArticulatedInertia::from(b.inertia);
        let bias = vi.cross_force(&b.inertia.mul_motion(&vi));
        pa[i] = match f_ext {
            Some(fe) => bias - fe[i],
            None => bias,
        };
    }
    // IA_λ += Xᵀ Ia X and pA_λ += Xᵀ pa, children first; the contribution of body i + 1 to
    // body i rides in registers ([`add_to_parent`]).
    let (mut ia_carry, mut pa_carry) = (ArticulatedInertia::default(), Force::ZERO);
    for i in (1..nb).rev() {
        let b = &bodies[i];
        let iv = b.idx_v;
        let ia_i = ia[i] + ia_carry;
        let pa_i = pa[i] + pa_carry;
        ia[i] = ia_i;
        pa[i] = pa_i;
        let (ia_up, pa_up) = match prescribed {
            Some(p) if p.mask[iv] => {
                // Known q̈: the joint transmits IA as if rigid, with bias IA (c + S q̈).
                (ia_i, pa_i + ia_i.mul_motion(&b.add_s(c[i], p.qdd[iv])))
            }
            _ => {
                let (ia_a, pa_a) = project_joint(b, &ia_i, &pa_i, &c[i], tau[iv]);
                u_col[i] = ia_a.u;
                d_inv[i] = ia_a.d_inv;
                u[i] = ia_a.u_bias;
                (ia_a.inertia, pa_a)
            }
        };
        // IA_λ += Xᵀ Ia X ;  pA_λ += Xᵀ pa (a root hands nothing on)
        let p = b.parent;
        if p > 0 {
            let x = &x_up[i];
            ia_carry = add_to_parent(ia, ia_up.to_parent(x), i, p);
            pa_carry = add_to_parent(pa, x.apply_force_transpose(&pa_up), i, p);
        } else {
            (ia_carry, pa_carry) = (ArticulatedInertia::default(), Force::ZERO);
        }
    }
    let g = model.gravity;
    let a0 = Motion::new(0.0, -g[0], -g[1]);
    acc[0] = a0;
    let mut a_prev = a0;
    for i in 1..nb {
        let b = &bodies[i];
        let iv = b.idx_v;
        // a' = X a_λ + c
        let a_pre = x_up[i].apply_motion(&parent_entry(acc, a_prev, i, b.parent)) + c[i];
        let a = match prescribed {
            Some(p) if p.mask[iv] => {
                let qdd = p.qdd[iv];
                let a = b.add_s(a_pre, qdd);
                qdd_out[iv] = qdd;
                // τ = Sᵀ (IA a + pA)
                tau_out[iv] = b.s_dot(&(ia[i].mul_motion(&a) + pa[i]));
                a
            }
            _ => {
                // q̈ = (u − Uᵀ a') / d ;  a = a' + S q̈
                let qdd = (u[i] - a_pre.dot(&u_col[i])) * d_inv[i];
                qdd_out[iv] = qdd;
                if prescribed.is_some() {
                    tau_out[iv] = tau[iv];
                }
                b.add_s(a_pre, qdd)
            }
        };
        acc[i] = a;
        a_prev = a;
    }
}

/// What a free joint leaves of a body's articulated inertia, and the terms the forward pass
/// needs again.
struct Projected {
    /// `Ia = IA − U Uᵀ / d`.
    inertia: ArticulatedInertia,
    /// `U = IA S`.
    u: Force,
    /// `1 / d = 1 / (Sᵀ U)`.
    d_inv: f64,
    /// `u = τ − Sᵀ pA`.
    u_bias: f64,
}

/// The ABA's joint step for a free joint: `U = IA S`, `d = Sᵀ U`, `u = τ − Sᵀ pA`,
/// `Ia = IA − U Uᵀ / d` and `pa = pA + Ia c + U u / d`.
///
/// For a revolute joint `S = [1, 0, 0]`: `U` is the first column of `IA`, `d` its first
/// entry, and `Ia`'s first row and column are zero (`Ia S = U − U d / d`); they are set so
/// rather than computed as differences of equal numbers, and `Ia c` is formed from the
/// remaining 2×2 block (`c` has no angular part). For the same reason the moment of `pa` is
/// `pA_n + u = τ`. `u` keeps the full product `Sᵀ pA` ([`BodyModel::s_dot`]), so an
/// overflowed bias force still shows in `q̈`.
#[inline(always)]
fn project_joint(
    b: &BodyModel,
    ia: &ArticulatedInertia,
    pa: &Force,
    c: &Motion,
    tau: f64,
) -> (Projected, Force) {
    let (inertia, u_col, d_inv, u, pa_a) = match b.joint {
        JointType::Revolute => {
            let u_col = Force::new(ia.a00, ia.a01, ia.a02);
            let d_inv = 1.0 / ia.a00;
            let u = tau - b.s_dot(pa);
            // (products formed while the division runs)
            let a11 = ia.a11 - d_inv * (ia.a01 * ia.a01);
            let a12 = ia.a12 - d_inv * (ia.a01 * ia.a02);
            let a22 = ia.a22 - d_inv * (ia.a02 * ia.a02);
            let ud = u * d_inv;
            // pa = pA + Ia c + U u / d, with Ia c = [0, a11 cx + a12 cy, a12 cx + a22 cy]
            let pa_a = Force::new(
                tau,
                pa.fx + (a11 * c.vx + a12 * c.vy) + ia.a01 * ud,
                pa.fy + (a12 * c.vx + a22 * c.vy) + ia.a02 * ud,
            );
            let inertia = ArticulatedInertia {
                a00: 0.0,
                a01: 0.0,
                a02: 0.0,
                a11,
                a12,
                a22,
            };
            (inertia, u_col, d_inv, u, pa_a)
        }
        JointType::Prismatic { .. } => {
            let u_col = ia.mul_motion(&b.s);
            let d_inv = 1.0 / b.s_dot(&u_col);
            let u = tau - b.s_dot(pa);
            let inertia = ia.sub_outer(&u_col, d_inv);
            let pa_a = *pa + inertia.mul_motion(c) + u_col * (u * d_inv);
            (inertia, u_col, d_inv, u, pa_a)
        }
    };
    (
        Projected {
            inertia,
            u: u_col,
            d_inv,
            u_bias: u,
        },
        pa_a,
    )
}
