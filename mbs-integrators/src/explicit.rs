//! Fixed-step explicit methods: semi-implicit (symplectic) Euler and classic RK4, with
//! cubic Hermite dense output from the end-point derivatives.

use crate::error::{IntegratorError, Result};
use crate::ode::OdeSystem;
use crate::solution::Stats;
use crate::stepper::{Control, Stepper, clip_step, eval, hermite, non_finite};

/// Which fixed-step scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Scheme {
    SemiImplicitEuler,
    Rk4,
}

pub(crate) struct Explicit {
    scheme: Scheme,
    h: f64,
    t: f64,
    t_prev: f64,
    y: Vec<f64>,
    y_prev: Vec<f64>,
    f: Vec<f64>,
    f_prev: Vec<f64>,
    k: [Vec<f64>; 3],
    tmp: Vec<f64>,
    split: usize,
}

impl Explicit {
    pub fn new(scheme: Scheme, n: usize, ctl: &Control, split: Option<usize>) -> Result<Self> {
        let split = match (scheme, split) {
            (Scheme::SemiImplicitEuler, None) => {
                return Err(IntegratorError::InvalidOption {
                    option: "method",
                    message: "semi-implicit Euler needs a second-order system (q̇ = v), \
                              which this system does not declare"
                        .into(),
                });
            }
            (_, s) => s.unwrap_or(0),
        };
        Ok(Self {
            scheme,
            h: ctl.fixed.unwrap_or(0.0),
            t: 0.0,
            t_prev: 0.0,
            y: vec![0.0; n],
            y_prev: vec![0.0; n],
            f: vec![0.0; n],
            f_prev: vec![0.0; n],
            k: [vec![0.0; n], vec![0.0; n], vec![0.0; n]],
            tmp: vec![0.0; n],
            split,
        })
    }
}

impl Stepper for Explicit {
    fn start(&mut self, sys: &mut dyn OdeSystem, t: f64, y: &[f64], st: &mut Stats) -> Result<()> {
        self.t = t;
        self.t_prev = t;
        self.y.copy_from_slice(y);
        self.y_prev.copy_from_slice(y);
        if !eval(sys, t, y, &mut self.f, st)? {
            return Err(non_finite(t, &self.f));
        }
        self.f_prev.copy_from_slice(&self.f);
        Ok(())
    }

    fn step(&mut self, sys: &mut dyn OdeSystem, t_max: f64, st: &mut Stats) -> Result<()> {
        let (h, _) = clip_step(self.t, self.h, t_max);
        let t = self.t;
        self.y_prev.copy_from_slice(&self.y);
        self.f_prev.copy_from_slice(&self.f);
        let n = self.y.len();
        match self.scheme {
            Scheme::SemiImplicitEuler => {
                // v ← v + h a(q, v) (and other states explicitly), then q ← q + h v_new.
                let m = self.split;
                for i in m..n {
                    self.y[i] += h * self.f_prev[i];
                }
                for i in 0..m {
                    self.y[i] += h * self.y[m + i];
                }
            }
            Scheme::Rk4 => {
                let [k2, k3, k4] = &mut self.k;
                let (y0, k1) = (&self.y_prev, &self.f_prev);
                for i in 0..n {
                    self.tmp[i] = y0[i] + 0.5 * h * k1[i];
                }
                eval(sys, t + 0.5 * h, &self.tmp, k2, st)?;
                for i in 0..n {
                    self.tmp[i] = y0[i] + 0.5 * h * k2[i];
                }
                eval(sys, t + 0.5 * h, &self.tmp, k3, st)?;
                for i in 0..n {
                    self.tmp[i] = y0[i] + h * k3[i];
                }
                eval(sys, t + h, &self.tmp, k4, st)?;
                for i in 0..n {
                    self.y[i] = y0[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
                }
            }
        }
        self.t_prev = t;
        self.t = t + h;
        if self.y.iter().any(|v| !v.is_finite()) {
            return Err(non_finite(self.t, &self.y));
        }
        if !eval(sys, self.t, &self.y, &mut self.f, st)? {
            return Err(non_finite(self.t, &self.f));
        }
        st.steps += 1;
        Ok(())
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
