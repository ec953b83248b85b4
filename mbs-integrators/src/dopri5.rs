//! Dormand–Prince 5(4) (Dormand & Prince 1980) as in Hairer's `DOPRI5`: seven stages with
//! the first same as last (FSAL), an embedded 4th-order error estimate, the PI step-size
//! controller of Hairer, Nørsett & Wanner (*Solving ODEs I*, §II.4, β = 0.04), and the
//! 4th-order continuous extension of §II.6 (Shampine's dense output coefficients).

use crate::error::{IntegratorError, Result};
use crate::ode::OdeSystem;
use crate::solution::Stats;
use crate::stepper::{Control, Stepper, clip_step, eval, non_finite};

// Butcher tableau (nodes c, matrix a, 5th-order weights = row 7 of a).
const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// Error estimate: difference of the 5th- and 4th-order solutions.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Dense output.
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

// PI controller (Hairer): safety, step factor bounds, β.
const SAFE: f64 = 0.9;
const FAC_MIN: f64 = 0.2;
const FAC_MAX: f64 = 10.0;
const BETA: f64 = 0.04;

pub(crate) struct Dopri5 {
    ctl: Control,
    t: f64,
    t_prev: f64,
    h: f64,
    y: Vec<f64>,
    y_new: Vec<f64>,
    k: [Vec<f64>; 7],
    tmp: Vec<f64>,
    err: Vec<f64>,
    /// Dense output coefficients of the last step (Hairer's `rcont1..5`).
    cont: [Vec<f64>; 5],
    fac_old: f64,
    last_rejected: bool,
}

impl Dopri5 {
    pub fn new(n: usize, ctl: &Control) -> Self {
        let v = || vec![0.0; n];
        Self {
            ctl: ctl.clone(),
            t: 0.0,
            t_prev: 0.0,
            h: 0.0,
            y: v(),
            y_new: v(),
            k: [v(), v(), v(), v(), v(), v(), v()],
            tmp: v(),
            err: v(),
            cont: [v(), v(), v(), v(), v()],
            fac_old: 1e-4,
            last_rejected: false,
        }
    }

    /// The seven stages from (t, y) with step h; `k[0]` holds f(t, y). Returns false when a
    /// stage is not finite.
    fn stages(&mut self, sys: &mut dyn OdeSystem, h: f64, st: &mut Stats) -> Result<bool> {
        let n = self.y.len();
        let t = self.t;
        let y = &self.y;
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        let tmp = &mut self.tmp;
        for i in 0..n {
            tmp[i] = y[i] + h * A21 * k1[i];
        }
        if !eval(sys, t + C2 * h, tmp, k2, st)? {
            return Ok(false);
        }
        for i in 0..n {
            tmp[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        if !eval(sys, t + C3 * h, tmp, k3, st)? {
            return Ok(false);
        }
        for i in 0..n {
            tmp[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        if !eval(sys, t + C4 * h, tmp, k4, st)? {
            return Ok(false);
        }
        for i in 0..n {
            tmp[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        if !eval(sys, t + C5 * h, tmp, k5, st)? {
            return Ok(false);
        }
        for i in 0..n {
            tmp[i] =
                y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        if !eval(sys, t + h, tmp, k6, st)? {
            return Ok(false);
        }
        let y_new = &mut self.y_new;
        for i in 0..n {
            y_new[i] =
                y[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        if !eval(sys, t + h, y_new, k7, st)? {
            return Ok(false);
        }
        for i in 0..n {
            self.err[i] =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
        }
        Ok(true)
    }

    /// Stores the dense-output coefficients of the accepted step from y to y_new.
    fn store_dense(&mut self, h: f64) {
        let n = self.y.len();
        let k = &self.k;
        for i in 0..n {
            let dy = self.y_new[i] - self.y[i];
            let bspl = h * k[0][i] - dy;
            self.cont[0][i] = self.y[i];
            self.cont[1][i] = dy;
            self.cont[2][i] = bspl;
            self.cont[3][i] = dy - h * k[6][i] - bspl;
            self.cont[4][i] = h
                * (D1 * k[0][i]
                    + D3 * k[2][i]
                    + D4 * k[3][i]
                    + D5 * k[4][i]
                    + D6 * k[5][i]
                    + D7 * k[6][i]);
        }
    }
}

impl Stepper for Dopri5 {
    fn start(&mut self, sys: &mut dyn OdeSystem, t: f64, y: &[f64], st: &mut Stats) -> Result<()> {
        self.t = t;
        self.t_prev = t;
        self.y.copy_from_slice(y);
        if !eval(sys, t, y, &mut self.k[0], st)? {
            return Err(non_finite(t, &self.k[0]));
        }
        if self.h == 0.0 {
            self.h = match self.ctl.fixed {
                Some(h) => h,
                None => self.ctl.initial_step(sys, t, y, &self.k[0], 5, st)?,
            };
        }
        self.last_rejected = false;
        for c in &mut self.cont {
            c.fill(0.0);
        }
        self.cont[0].copy_from_slice(y);
        Ok(())
    }

    fn step(&mut self, sys: &mut dyn OdeSystem, t_max: f64, st: &mut Stats) -> Result<()> {
        loop {
            let h_min = self.ctl.h_min(self.t);
            let (h, _) = clip_step(self.t, self.h.min(self.ctl.h_max), t_max);
            let finite = self.stages(sys, h, st)?;
            if self.ctl.fixed.is_some() {
                if !finite {
                    return Err(non_finite(self.t + h, &self.y_new));
                }
                self.accept(h, st);
                return Ok(());
            }
            let err = if finite {
                self.ctl.step_error_norm(&self.err, &self.y, &self.y_new)
            } else {
                f64::INFINITY
            };
            // fac11 = err^(1/5 − 0.75 β); h_new = h / clamp(fac11 / fac_old^β / safe)
            let expo1 = 0.2 - BETA * 0.75;
            let fac11 = err.powf(expo1);
            if err <= 1.0 {
                let fac =
                    (fac11 / self.fac_old.powf(BETA) / SAFE).clamp(1.0 / FAC_MAX, 1.0 / FAC_MIN);
                let mut h_new = h / fac;
                self.fac_old = err.max(1e-4);
                if self.last_rejected {
                    h_new = h_new.min(h);
                }
                self.accept(h, st);
                self.h = h_new.min(self.ctl.h_max);
                self.last_rejected = false;
                return Ok(());
            }
            st.rejected += 1;
            self.last_rejected = true;
            self.h = if err.is_finite() {
                h / (fac11 / SAFE).min(1.0 / FAC_MIN)
            } else {
                0.25 * h
            };
            if self.h < h_min {
                if !finite {
                    return Err(non_finite(self.t + h, &self.y_new));
                }
                return Err(IntegratorError::StepSizeTooSmall {
                    t: self.t,
                    h: self.h,
                    h_min,
                    reason: "local error above tolerance",
                });
            }
        }
    }

    fn t_prev(&self) -> f64 {
        self.t_prev
    }

    fn t(&self) -> f64 {
        self.t
    }

    fn y(&self) -> &[f64] {
        &self.y
    }

    fn interpolate(&self, t: f64, out: &mut [f64]) {
        let h = self.t - self.t_prev;
        if h == 0.0 {
            out.copy_from_slice(&self.y);
            return;
        }
        let s = (t - self.t_prev) / h;
        let s1 = 1.0 - s;
        let c = &self.cont;
        for i in 0..out.len() {
            out[i] = c[0][i] + s * (c[1][i] + s1 * (c[2][i] + s * (c[3][i] + s1 * c[4][i])));
        }
    }
}

impl Dopri5 {
    fn accept(&mut self, h: f64, st: &mut Stats) {
        self.store_dense(h);
        self.t_prev = self.t;
        self.t += h;
        std::mem::swap(&mut self.y, &mut self.y_new);
        // FSAL: the last stage is f at the new point.
        let [k1, .., k7] = &mut self.k;
        std::mem::swap(k1, k7);
        st.steps += 1;
    }
}
