//! The Jacobian `∂f/∂y` an implicit or linearly implicit method works with: the system's
//! own when it has one, else forward differences that leave out the columns known to be
//! zero (states outside the Jacobian, internal states nothing depends on).

use crate::error::{IntegratorError, Result};
use crate::ode::OdeSystem;
use crate::solution::Stats;
use crate::stepper::{eval, non_finite};

/// A Jacobian and the scratch space of its evaluation (nothing allocated per Jacobian).
#[derive(Clone)]
pub(crate) struct Jacobian {
    n: usize,
    /// `∂f/∂y`, n × n.
    pub m: nalgebra::DMatrix<f64>,
    /// Columns of `m` known to hold zeros (left out of the last evaluations).
    pub zero_columns: Vec<bool>,
    /// A perturbed rate, the perturbed state, which columns are needed, the internal states
    /// probed together.
    tmp: Vec<f64>,
    yp: Vec<f64>,
    needed: Vec<bool>,
    internal: Vec<usize>,
    /// The system's states outside the Jacobian, asked once per solve.
    outside: Option<Vec<std::ops::Range<usize>>>,
}

impl Jacobian {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            m: nalgebra::DMatrix::zeros(n, n),
            zero_columns: vec![false; n],
            tmp: vec![0.0; n],
            yp: vec![0.0; n],
            needed: vec![true; n],
            internal: Vec::with_capacity(n),
            outside: None,
        }
    }

    /// J at `(t, y)` where `f = f(t, y)`: analytic if the system has one, else forward
    /// differences.
    pub fn evaluate(
        &mut self,
        sys: &mut dyn OdeSystem,
        t: f64,
        y: &[f64],
        f: &[f64],
        st: &mut Stats,
    ) -> Result<()> {
        st.jacobian_evals += 1;
        if sys.has_jacobian() {
            // The columns of states outside the Jacobian are zeroed here once and left to
            // the system to skip.
            let outside = self
                .outside
                .get_or_insert_with(|| sys.states_outside_jacobian());
            for r in outside.iter() {
                for j in r.start.min(self.n)..r.end.min(self.n) {
                    if !self.zero_columns[j] {
                        self.m.column_mut(j).fill(0.0);
                        self.zero_columns[j] = true;
                    }
                }
            }
            sys.jacobian_given_rate(t, y, f, &mut self.m)
                .map_err(|source| IntegratorError::System { t, source })?;
            // The columns kept zero are skipped; `v · 0` is NaN exactly for a non-finite
            // `v`, so each column is one vectorizable sum.
            let n = self.n;
            let bad = (0..n).filter(|&c| !self.zero_columns[c]).any(|c| {
                let col = &self.m.as_slice()[c * n..(c + 1) * n];
                !col.iter().fold(0.0, |acc, v| acc + v * 0.0).is_finite()
            });
            if bad {
                return Err(IntegratorError::System {
                    t,
                    source: crate::SystemError::new("the Jacobian has non-finite entries"),
                });
            }
        } else {
            let n = self.n;
            let mut yp = std::mem::take(&mut self.yp);
            yp.clear();
            yp.extend_from_slice(y);
            // States the system marks as outside the Jacobian keep zero columns and cost
            // no evaluation (a string's modal amplitudes, see
            // `OdeSystem::states_outside_jacobian`).
            let mut needed = std::mem::take(&mut self.needed);
            needed.clear();
            needed.resize(n, true);
            let outside = self
                .outside
                .get_or_insert_with(|| sys.states_outside_jacobian());
            for r in outside.iter() {
                for j in r.start.min(n)..r.end.min(n) {
                    needed[j] = false;
                }
            }
            // The other internal states beyond a mechanical [q, v] (force elements'
            // memories) are probed together first: when moving them all at once changes no
            // derivative at all, their columns are zero and their evaluations are saved.
            let grouped = sys.second_order_split().map_or(n, |nv| (2 * nv).min(n));
            let mut internal = std::mem::take(&mut self.internal);
            internal.clear();
            internal.extend((grouped..n).filter(|&j| needed[j]));
            if internal.len() > 1 {
                for &j in &internal {
                    yp[j] = y[j] + f64::EPSILON.sqrt() * y[j].abs().max(1e-5);
                }
                if !eval(sys, t, &yp, &mut self.tmp, st)? {
                    return Err(non_finite(t, &self.tmp));
                }
                yp[grouped..].copy_from_slice(&y[grouped..]);
                if self.tmp == f {
                    for &j in &internal {
                        needed[j] = false;
                    }
                }
            }
            for j in 0..n {
                if !needed[j] {
                    // Zeroed once, kept zero while the column stays out.
                    if !self.zero_columns[j] {
                        self.m.column_mut(j).fill(0.0);
                        self.zero_columns[j] = true;
                    }
                    continue;
                }
                let yj = y[j];
                let dj = f64::EPSILON.sqrt() * yj.abs().max(1e-5);
                yp[j] = yj + dj;
                let dj = yp[j] - yj;
                // `eval` refuses non-finite rates, so every column is finite (barring an
                // overflow of the quotient).
                if !eval(sys, t, &yp, &mut self.tmp, st)? {
                    return Err(non_finite(t, &self.tmp));
                }
                let column = self.m.column_mut(j);
                for ((out, a), b) in column.into_iter().zip(&self.tmp).zip(f) {
                    *out = (a - b) / dj;
                }
                self.zero_columns[j] = false;
                yp[j] = yj;
            }
            self.yp = yp;
            self.needed = needed;
            self.internal = internal;
        }
        Ok(())
    }
}
