//! [`LoadJacobian`]: where force elements write the derivatives of their loads and state
//! rates, from which [`crate::System::jacobian`] assembles `∂ẋ/∂x`.

use std::ops::Range;

use nalgebra::DMatrix;

use crate::data::Data;
use crate::force::ForceContext;
use crate::jacobian::column;
use crate::model::{BodyId, Model};

/// What a derivative is taken with respect to: a coordinate, a velocity, or one of the
/// element's own internal states (local index).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrt {
    /// Coordinate `q_j`.
    Q(usize),
    /// Velocity `v_j`.
    V(usize),
    /// The element's internal state `local`.
    State(usize),
}

/// Where an element writes the derivatives of its loads and of its internal states' rates
/// at one state ([`crate::ForceElement::load_derivatives`]).
///
/// Loads are differentiated through the relative motion of the material points they act
/// at: for a force `F` on body B and `−F` on body A at the world point `p`, the element
/// gives `∂F/∂Δ` and `∂F/∂Δ̇`, where `Δ` is the displacement of B's material point at `p`
/// relative to A's, and the system maps them with `G = J_B(p) − J_A(p)` to
/// `∂τ/∂q = Gᵀ (∂F/∂Δ) G` and `∂τ/∂v = Gᵀ (∂F/∂Δ̇) G`. What this leaves out is of second
/// order in the geometry: the turning of lever arms and normals with the pose
/// (`∂Gᵀ/∂q · F`) and the convective part of `Δ̇` (`∂(G v)/∂q` at fixed `v`). The latter
/// is not small where a law depends steeply on a rate (a felt's hysteresis switch: `F`
/// changes by `∂F/∂δ̇ · ∂δ̇/∂q`), and an element adds it for its gap rate with
/// [`LoadJacobian::add_gap_rate_convection`]; what remains (the slip's convective part, the
/// geometric stiffness `F ∂(Gᵀ n)/∂q`) is what a linearly implicit method's Jacobian may
/// lack without losing its order.
pub struct LoadJacobian<'a> {
    pub(crate) model: &'a Model,
    pub(crate) data: &'a Data,
    /// `∂τ/∂x`: nv × len(x).
    pub(crate) dtau: &'a mut DMatrix<f64>,
    /// The system's Jacobian `∂ẋ/∂x`, whose rows of this element's states it writes.
    pub(crate) jac: &'a mut DMatrix<f64>,
    /// This element's internal states in `x`.
    pub(crate) states: Range<usize>,
    /// Columns of `x` outside the Jacobian (writes there are dropped).
    pub(crate) outside: &'a [bool],
    /// `G = J_B(p) − J_A(p)` of the point set last, one `[x, y]` per coordinate.
    pub(crate) g: &'a mut [[f64; 2]],
    /// The kinematics at `q + ε v`, those coordinates, and ε (`None` at rest).
    pub(crate) ahead: Option<(&'a Data, &'a [f64], f64)>,
    /// Scratch: the gradient of a gap rate with respect to the coordinates.
    pub(crate) hv: &'a mut [f64],
}

impl LoadJacobian<'_> {
    /// Column of `x` for `wrt`.
    #[inline]
    fn col(&self, wrt: Wrt) -> usize {
        let nv = self.model.nv();
        match wrt {
            Wrt::Q(j) => j,
            Wrt::V(j) => nv + j,
            Wrt::State(s) => self.states.start + s,
        }
    }

    /// Adds `value` to `∂τ_k/∂wrt`: the derivative of a generalized force the element adds
    /// directly ([`crate::Loads::add_generalized`]).
    #[inline]
    pub fn add_generalized(&mut self, k: usize, wrt: Wrt, value: f64) {
        let c = self.col(wrt);
        if !self.outside[c] {
            self.dtau[(k, c)] += value;
        }
    }

    /// Adds `value` to `∂ṡ_r/∂wrt`, `r` a local index of the element's internal states.
    #[inline]
    pub fn add_rate(&mut self, r: usize, wrt: Wrt, value: f64) {
        let c = self.col(wrt);
        if !self.outside[c] {
            self.jac[(self.states.start + r, c)] += value;
        }
    }

    /// Sets the point the next point derivatives refer to: the world point `p` taken as a
    /// material point of body `b` and of body `a` (either may be the ground).
    pub fn set_point(&mut self, a: BodyId, b: BodyId, p: [f64; 2]) {
        self.g.fill([0.0; 2]);
        for (body, sign) in [(b, 1.0), (a, -1.0)] {
            for j in self.model.support(body) {
                let (_, lin) = column(self.model, self.data, j, p);
                let k = self.model.bodies[j.0].idx_v;
                self.g[k][0] += sign * lin[0];
                self.g[k][1] += sign * lin[1];
            }
        }
    }

    /// Adds the derivatives of a force `F` on body B (and `−F` on A) at the point of
    /// [`LoadJacobian::set_point`]: `dq[i][j] = ∂F_i/∂Δ_j`, `dv[i][j] = ∂F_i/∂Δ̇_j` (world
    /// components; `Δ` is B's material point relative to A's).
    pub fn add_point_force(&mut self, dq: [[f64; 2]; 2], dv: [[f64; 2]; 2]) {
        let nv = self.model.nv();
        for c in 0..nv {
            let gc = self.g[c];
            if gc == [0.0; 2] {
                continue;
            }
            // (∂F/∂Δ) g_c and (∂F/∂Δ̇) g_c, then g_rᵀ of each.
            let kq = [
                dq[0][0] * gc[0] + dq[0][1] * gc[1],
                dq[1][0] * gc[0] + dq[1][1] * gc[1],
            ];
            let kv = [
                dv[0][0] * gc[0] + dv[0][1] * gc[1],
                dv[1][0] * gc[0] + dv[1][1] * gc[1],
            ];
            for r in 0..nv {
                let gr = self.g[r];
                if gr == [0.0; 2] {
                    continue;
                }
                self.dtau[(r, c)] += gr[0] * kq[0] + gr[1] * kq[1];
                self.dtau[(r, nv + c)] += gr[0] * kv[0] + gr[1] * kv[1];
            }
        }
    }

    /// Adds `∂F/∂s = df` for the force `F` at the point of [`LoadJacobian::set_point`] and
    /// the element's internal state `s` (local index).
    pub fn add_point_force_state(&mut self, s: usize, df: [f64; 2]) {
        let c = self.states.start + s;
        if self.outside[c] {
            return;
        }
        for r in 0..self.model.nv() {
            let gr = self.g[r];
            self.dtau[(r, c)] += gr[0] * df[0] + gr[1] * df[1];
        }
    }

    /// Adds the derivatives of the rate of internal state `r` (local index) with respect to
    /// the relative displacement (`dq = ∂ṡ_r/∂Δ`) and velocity (`dv = ∂ṡ_r/∂Δ̇`) at the point
    /// of [`LoadJacobian::set_point`].
    pub fn add_rate_at_point(&mut self, r: usize, dq: [f64; 2], dv: [f64; 2]) {
        let nv = self.model.nv();
        let row = self.states.start + r;
        for c in 0..nv {
            let gc = self.g[c];
            if gc == [0.0; 2] {
                continue;
            }
            self.jac[(row, c)] += dq[0] * gc[0] + dq[1] * gc[1];
            self.jac[(row, nv + c)] += dv[0] * gc[0] + dv[1] * gc[1];
        }
    }
}

impl<'a> LoadJacobian<'a> {
    /// The context at `q + ε v` (the poses a short time `ε` ahead along the current
    /// velocities, velocities and states unchanged), and `ε`; `None` when nothing moves.
    /// An element reads there what its convective terms need: how a pose-dependent
    /// quantity changes along the motion (see [`LoadJacobian::add_gap_rate_convection`]).
    pub fn ahead<'c>(&'c self, ctx: &ForceContext<'c>) -> Option<(ForceContext<'c>, f64)> {
        let (data, q, eps) = self.ahead?;
        let ahead = ForceContext {
            model: self.model,
            data,
            t: ctx.t,
            q,
            v: ctx.v,
            states: ctx.states,
            positions: &[],
        };
        Some((ahead, eps))
    }

    /// Adds the convective part of a contact's gap rate to the coordinate columns: for a
    /// force on B (−on A) along `dir` that changes by `coef` per unit of the gap rate
    /// `ġ = a(q)·v`, `a = Gᵀ n` the gradient of the gap, it adds `Gᵀ dir · coef · ∂ġ/∂q`
    /// at the point of [`LoadJacobian::set_point`]. Since `a` is a gradient, `∂ġ/∂q` is
    /// its Hessian times `v`, the derivative of `a` along the motion:
    /// `(a(q + εv) − a(q))/ε`, from the normal `n` here and the contact point `p_ahead`
    /// and normal `n_ahead` found in [`LoadJacobian::ahead`]. Does nothing at rest.
    #[allow(clippy::too_many_arguments)]
    pub fn add_gap_rate_convection(
        &mut self,
        a: BodyId,
        b: BodyId,
        n: [f64; 2],
        p_ahead: [f64; 2],
        n_ahead: [f64; 2],
        dir: [f64; 2],
        coef: f64,
    ) {
        let Some((data, _, eps)) = self.ahead else {
            return;
        };
        let nv = self.model.nv();
        for k in 0..nv {
            self.hv[k] = -(self.g[k][0] * n[0] + self.g[k][1] * n[1]);
        }
        for (body, sign) in [(b, 1.0), (a, -1.0)] {
            for j in self.model.support(body) {
                let (_, lin) = column(self.model, data, j, p_ahead);
                let k = self.model.bodies[j.0].idx_v;
                self.hv[k] += sign * (lin[0] * n_ahead[0] + lin[1] * n_ahead[1]);
            }
        }
        for k in 0..nv {
            self.hv[k] /= eps;
        }
        for r in 0..nv {
            let gr = self.g[r];
            let u = coef * (gr[0] * dir[0] + gr[1] * dir[1]);
            if u == 0.0 {
                continue;
            }
            for c in 0..nv {
                self.dtau[(r, c)] += u * self.hv[c];
            }
        }
    }
}

impl LoadJacobian<'_> {
    /// Adds the derivatives of the rates of internal states `rates` (local indices), each
    /// `coef(r)` times the same direction: `∂ṡ_r/∂Δ = coef(r) dq`, `∂ṡ_r/∂Δ̇ = coef(r) dv`
    /// at the point of [`LoadJacobian::set_point`] (a string's modal amplitudes, all driven
    /// by one contact force).
    pub fn add_rates_at_point(
        &mut self,
        rates: Range<usize>,
        dq: [f64; 2],
        dv: [f64; 2],
        coef: impl Fn(usize) -> f64,
    ) {
        let nv = self.model.nv();
        let n = self.jac.nrows();
        let rows = self.states.start + rates.start..self.states.start + rates.end;
        for c in 0..nv {
            let gc = self.g[c];
            if gc == [0.0; 2] {
                continue;
            }
            for (col, w) in [
                (c, dq[0] * gc[0] + dq[1] * gc[1]),
                (nv + c, dv[0] * gc[0] + dv[1] * gc[1]),
            ] {
                if w == 0.0 || self.outside[col] {
                    continue;
                }
                let column = &mut self.jac.as_mut_slice()[col * n..(col + 1) * n];
                for (r, out) in rates.clone().zip(&mut column[rows.clone()]) {
                    *out += coef(r) * w;
                }
            }
        }
    }
}

/// `df/dx` of a scalar function by a central difference with step `1e-6 (|x| + scale)`,
/// `scale` the size below which `x` counts as small (a law's regularization velocity, a
/// penetration). For force laws that give no closed form.
pub fn central_difference(f: impl Fn(f64) -> f64, x: f64, scale: f64) -> f64 {
    let h = 1e-6 * (x.abs() + scale.abs());
    let (lo, hi) = (x - h, x + h);
    (f(hi) - f(lo)) / (hi - lo)
}
