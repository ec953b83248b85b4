//! Standard stiff test problems with their published reference solutions (in the spirit of
//! Drake's integrator test fixtures and the IVP Test Set of Mazzia & Magherini), for tests,
//! benchmarks and comparisons with other solvers.

use nalgebra::DMatrix;

use crate::error::SystemError;
use crate::ode::OdeSystem;

/// Robertson's chemical kinetics (Hairer & Wanner, *Solving ODEs II*, §IV.1; the IVP Test
/// Set's ROBER): `y1' = −0.04 y1 + 1e4 y2 y3`, `y2' = 0.04 y1 − 1e4 y2 y3 − 3e7 y2²`,
/// `y3' = 3e7 y2²`, from `(1, 0, 0)`. Optionally with its analytic Jacobian.
#[derive(Clone, Copy, Debug, Default)]
pub struct Robertson {
    /// Whether to offer the analytic Jacobian (else the integrator differences).
    pub analytic_jacobian: bool,
}

impl Robertson {
    /// Initial state.
    pub const Y0: [f64; 3] = [1.0, 0.0, 0.0];
    /// Hairer & Wanner's values at t = 40.
    pub const AT_40: [f64; 3] = [0.7158270687, 9.185534764e-6, 0.2841637457];
    /// The IVP Test Set's reference at t = 1e11.
    #[allow(clippy::excessive_precision)]
    pub const AT_1E11: [f64; 3] = [
        0.2083340149701255e-7,
        0.8333360770334713e-13,
        0.9999999791665050,
    ];
}

impl OdeSystem for Robertson {
    fn len(&self) -> usize {
        3
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        let (a, b) = (0.04 * y[0], 1e4 * y[1] * y[2]);
        let c = 3e7 * y[1] * y[1];
        dy[0] = -a + b;
        dy[1] = a - b - c;
        dy[2] = c;
        Ok(())
    }
    fn has_jacobian(&self) -> bool {
        self.analytic_jacobian
    }
    fn jacobian(&mut self, _t: f64, y: &[f64], j: &mut DMatrix<f64>) -> Result<(), SystemError> {
        j[(0, 0)] = -0.04;
        j[(0, 1)] = 1e4 * y[2];
        j[(0, 2)] = 1e4 * y[1];
        j[(1, 0)] = 0.04;
        j[(1, 1)] = -1e4 * y[2] - 6e7 * y[1];
        j[(1, 2)] = -1e4 * y[1];
        j[(2, 0)] = 0.0;
        j[(2, 1)] = 6e7 * y[1];
        j[(2, 2)] = 0.0;
        Ok(())
    }
}

/// Van der Pol's equation in the IVP Test Set's scaled form (VDPOL):
/// `y1' = y2`, `y2' = ((1 − y1²) y2 − y1) / ε`, from `(2, 0)`.
#[derive(Clone, Copy, Debug)]
pub struct VanDerPol {
    /// Stiffness parameter ε (the Test Set uses 1e-6).
    pub eps: f64,
    /// Whether to offer the analytic Jacobian.
    pub analytic_jacobian: bool,
}

impl VanDerPol {
    /// Initial state.
    pub const Y0: [f64; 2] = [2.0, 0.0];
    /// The IVP Test Set's reference at t = 2 for ε = 1e-6.
    #[allow(clippy::excessive_precision)]
    pub const AT_2_EPS_1E6: [f64; 2] = [1.706167732170469, -0.8928097010248125];
}

impl OdeSystem for VanDerPol {
    fn len(&self) -> usize {
        2
    }
    fn derivative(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        dy[0] = y[1];
        dy[1] = ((1.0 - y[0] * y[0]) * y[1] - y[0]) / self.eps;
        Ok(())
    }
    fn has_jacobian(&self) -> bool {
        self.analytic_jacobian
    }
    fn jacobian(&mut self, _t: f64, y: &[f64], j: &mut DMatrix<f64>) -> Result<(), SystemError> {
        j[(0, 0)] = 0.0;
        j[(0, 1)] = 1.0;
        j[(1, 0)] = (-2.0 * y[0] * y[1] - 1.0) / self.eps;
        j[(1, 1)] = (1.0 - y[0] * y[0]) / self.eps;
        Ok(())
    }
}
