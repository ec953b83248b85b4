//! ROS34PW2, the Rosenbrock–W method of Rang & Angermann, "New Rosenbrock W-methods of
//! order 3 for partial differential algebraic equations of index 1", *BIT Numerical
//! Mathematics* 45 (2005), table 4.5 (the coefficients are also PETSc's `TSROSWRA34PW2`).
//!
//! A step solves four linear systems with the one matrix `W = I − γ h J` and no Newton
//! iteration:
//!
//! ```text
//! W k_i = h f(t + c_i h, y_n + Σ_{j<i} a_ij k_j) + h J Σ_{j<i} γ_ij k_j
//! y_{n+1} = y_n + Σ b_i k_i ,   error estimate Σ (b_i − b̂_i) k_i
//! ```
//!
//! Third order with an embedded second-order solution, L-stable and stiffly accurate. It is
//! a **W-method**: its order conditions hold for any matrix `J`, so a finite-difference
//! Jacobian is kept across steps, and taken again after a rejected step or a step that
//! asks for a smaller next one (a stale `J` shows as a step size held down by stability);
//! the system's own Jacobian is taken at every step. The time derivative of `f` is left
//! out, as a W-method may. Its first stage is `f(t_n, y_n)`, the last step's
//! end-point rate, so an accepted step costs four evaluations (three stages and the new
//! end point, which the dense output and the next step use) and a rejected one three.

// The coefficients as published (Rang & Angermann give 17 digits).
#![allow(clippy::excessive_precision)]

use crate::error::{IntegratorError, Result};
use crate::jacobian::Jacobian;
use crate::linalg::IterationMatrix;
use crate::ode::OdeSystem;
use crate::solution::Stats;
use crate::stepper::{Control, Stepper, clip_step, eval, hermite, non_finite};

const STAGES: usize = 4;
/// The diagonal `γ`.
const GAMMA: f64 = 4.358_665_215_084_590_0e-1;
/// `a_ij` (rows of the strictly lower triangle).
const A: [[f64; 3]; STAGES] = [
    [0.0, 0.0, 0.0],
    [8.717_330_430_169_180_1e-1, 0.0, 0.0],
    [8.445_706_001_536_942_3e-1, -1.129_906_423_648_418_5e-1, 0.0],
    [0.0, 0.0, 1.0],
];
/// `γ_ij` below the diagonal.
const G: [[f64; 3]; STAGES] = [
    [0.0, 0.0, 0.0],
    [-8.717_330_430_169_180_1e-1, 0.0, 0.0],
    [-9.033_805_701_304_408_2e-1, 5.418_067_238_809_532_6e-2, 0.0],
    [
        2.421_238_070_609_534_6e-1,
        -1.223_250_583_904_514_7,
        5.452_602_553_351_021_4e-1,
    ],
];
/// The stage times `c_i = Σ_j a_ij`.
const C: [f64; STAGES] = [
    0.0,
    8.717_330_430_169_180_1e-1,
    7.315_799_577_888_523_8e-1,
    1.0,
];
/// The weights `b_i` (third order) and `b̂_i` (second order).
const B: [f64; STAGES] = [
    2.421_238_070_609_534_6e-1,
    -1.223_250_583_904_514_7,
    1.545_260_255_335_102_0,
    4.358_665_215_084_590_0e-1,
];
const B_HAT: [f64; STAGES] = [
    3.781_090_314_581_936_9e-1,
    -9.604_229_221_242_317_8e-2,
    0.5,
    2.179_332_607_542_295_0e-1,
];

pub(crate) struct Ros34Pw2 {
    ctl: Control,
    n: usize,
    t: f64,
    t_prev: f64,
    h: f64,
    y: Vec<f64>,
    f: Vec<f64>,
    y_prev: Vec<f64>,
    f_prev: Vec<f64>,
    /// The stage increments.
    k: [Vec<f64>; STAGES],
    /// A stage's state, then the step's end point and its rate.
    y_stage: Vec<f64>,
    f_stage: Vec<f64>,
    y_new: Vec<f64>,
    f_new: Vec<f64>,
    /// `Σ γ_ij k_j` of a stage, then the error estimate.
    sum: Vec<f64>,
    est: Vec<f64>,
    jac: Jacobian,
    lu: IterationMatrix,
    /// The `γ h` of the current factorisation (NaN when none).
    lu_c: f64,
    jac_valid: bool,
    /// Whether the Jacobian was taken at the current step's start.
    jac_fresh: bool,
}

impl Ros34Pw2 {
    pub fn new(n: usize, ctl: &Control) -> Self {
        let v = || vec![0.0; n];
        Self {
            ctl: ctl.clone(),
            n,
            t: 0.0,
            t_prev: 0.0,
            h: 0.0,
            y: v(),
            f: v(),
            y_prev: v(),
            f_prev: v(),
            k: [v(), v(), v(), v()],
            y_stage: v(),
            f_stage: v(),
            y_new: v(),
            f_new: v(),
            sum: v(),
            est: v(),
            jac: Jacobian::new(n),
            lu: IterationMatrix::new(n),
            lu_c: f64::NAN,
            jac_valid: false,
            jac_fresh: false,
        }
    }

    /// The Jacobian at the step's start.
    fn update_jacobian(&mut self, sys: &mut dyn OdeSystem, st: &mut Stats) -> Result<()> {
        self.jac.evaluate(sys, self.t, &self.y, &self.f, st)?;
        self.jac_valid = true;
        self.jac_fresh = true;
        self.lu.jacobian_changed(&self.jac.zero_columns);
        self.lu_c = f64::NAN;
        Ok(())
    }

    /// The four stages and the end point of a step `h` into `y_new`, with the error
    /// estimate in `est`. Ok(false) when a stage's rate is not finite.
    fn attempt(&mut self, sys: &mut dyn OdeSystem, h: f64, st: &mut Stats) -> Result<bool> {
        let c = GAMMA * h;
        if self.lu_c != c {
            st.lu_decompositions += 1;
            if !self.lu.factor_shifted(c, self.jac.m.as_slice()) {
                self.lu_c = f64::NAN;
                return Err(IntegratorError::SingularMatrix { t: self.t, h });
            }
            self.lu_c = c;
        }
        let n = self.n;
        for i in 0..STAGES {
            let rate = if i == 0 {
                &self.f
            } else {
                for m in 0..n {
                    let mut v = self.y[m];
                    for (a, k) in A[i][..i].iter().zip(&self.k) {
                        v += a * k[m];
                    }
                    self.y_stage[m] = v;
                }
                if !eval(sys, self.t + C[i] * h, &self.y_stage, &mut self.f_stage, st)? {
                    return Ok(false);
                }
                &self.f_stage
            };
            // h f + h J Σ γ_ij k_j, the product over J's non-zero columns only.
            let (done, rest) = self.k.split_at_mut(i);
            let rhs = &mut rest[0];
            rhs.copy_from_slice(rate);
            if i > 0 {
                for m in 0..n {
                    let mut v = 0.0;
                    for (g, k) in G[i][..i].iter().zip(done.iter()) {
                        v += g * k[m];
                    }
                    self.sum[m] = v;
                }
                let jac = self.jac.m.as_slice();
                for (col, &x) in self.sum.iter().enumerate() {
                    if x != 0.0 && !self.jac.zero_columns[col] {
                        for (r, j) in rhs.iter_mut().zip(&jac[col * n..(col + 1) * n]) {
                            *r += j * x;
                        }
                    }
                }
            }
            for r in rhs.iter_mut() {
                *r *= h;
            }
            self.lu.solve(rhs);
        }
        for m in 0..n {
            let (mut v, mut e) = (self.y[m], 0.0);
            for (i, k) in self.k.iter().enumerate() {
                v += B[i] * k[m];
                e += (B[i] - B_HAT[i]) * k[m];
            }
            self.y_new[m] = v;
            self.est[m] = e;
        }
        Ok(true)
    }
}

impl Stepper for Ros34Pw2 {
    fn start(&mut self, sys: &mut dyn OdeSystem, t: f64, y: &[f64], st: &mut Stats) -> Result<()> {
        self.t = t;
        self.t_prev = t;
        self.y.copy_from_slice(y);
        self.y_prev.copy_from_slice(y);
        if !eval(sys, t, y, &mut self.f, st)? {
            return Err(non_finite(t, &self.f));
        }
        self.f_prev.copy_from_slice(&self.f);
        if self.h == 0.0 {
            self.h = match self.ctl.fixed {
                Some(h) => h,
                None => self.ctl.initial_step(sys, t, y, &self.f, 3, st)?,
            };
        }
        // After a restart (event) the old Jacobian may be far off: refresh lazily.
        self.jac_valid = false;
        Ok(())
    }

    fn step(&mut self, sys: &mut dyn OdeSystem, t_max: f64, st: &mut Stats) -> Result<()> {
        if !self.jac_valid || sys.has_jacobian() {
            self.update_jacobian(sys, st)?;
        }
        let mut rejected_once = false;
        loop {
            let h_min = self.ctl.h_min(self.t);
            let (h, _) = clip_step(self.t, self.h.min(self.ctl.h_max), t_max);
            let finite = self.attempt(sys, h, st)?;
            let err = if finite {
                self.ctl.step_error_norm(&self.est, &self.y, &self.y_new)
            } else {
                f64::INFINITY
            };
            // Third-order local error: h_new = h · 0.9 err^(−1/3), within [0.2, 5].
            let fac = if err > 0.0 {
                0.9 * err.powf(-1.0 / 3.0)
            } else {
                5.0
            };
            let mut fac = if fac.is_nan() {
                0.2
            } else {
                fac.clamp(0.2, 5.0)
            };
            let acceptable = self.ctl.fixed.is_some() || err <= 1.0;
            if finite && acceptable {
                let t_new = self.t + h;
                if eval(sys, t_new, &self.y_new, &mut self.f_new, st)? {
                    std::mem::swap(&mut self.y_prev, &mut self.y);
                    std::mem::swap(&mut self.f_prev, &mut self.f);
                    std::mem::swap(&mut self.y, &mut self.y_new);
                    std::mem::swap(&mut self.f, &mut self.f_new);
                    self.t_prev = self.t;
                    self.t = t_new;
                    self.jac_fresh = false;
                    st.steps += 1;
                    if self.ctl.fixed.is_none() {
                        if rejected_once {
                            fac = fac.min(1.0);
                        }
                        if fac < 1.0 {
                            self.jac_valid = false;
                        }
                        // Keep h (and the LU) when the change would be small.
                        if !(1.0..=1.2).contains(&fac) {
                            self.h = (h * fac).min(self.ctl.h_max);
                        }
                    }
                    return Ok(());
                }
                fac = 0.2;
            }
            if self.ctl.fixed.is_some() {
                return Err(non_finite(self.t + h, &self.f_new));
            }
            st.rejected += 1;
            rejected_once = true;
            // A stale Jacobian is the likely culprit first: take one here.
            if !self.jac_fresh {
                self.update_jacobian(sys, st)?;
            }
            self.h = h * fac.min(0.9);
            if self.h < h_min {
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
        hermite(
            self.t_prev,
            self.t - self.t_prev,
            &self.y_prev,
            &self.f_prev,
            &self.y,
            &self.f,
            t,
            out,
        );
    }
}
