//! Running an `mbs_core::System` through the integrators.

use mbs_core::{Crossing, System, Workspace};

use crate::error::SystemError;
use crate::ode::{EventSource, OdeSystem};

/// An `mbs_core::System` seen as an [`OdeSystem`]: the state is the system's
/// `[q, v, internal states]`, the switching functions are the force elements', named
/// `"<element> #<k>"`. It is second order (`q̇ = v`), so every method applies.
pub struct MultibodyOde<'a> {
    system: &'a System,
    ws: Workspace,
    names: Vec<String>,
    /// Whether the integrators get [`System::jacobian`] (else finite differences).
    analytic: bool,
}

impl<'a> MultibodyOde<'a> {
    /// Wraps a system (with its own workspace).
    pub fn new(system: &'a System) -> Self {
        let names = (0..system.switch_len())
            .map(|k| match system.switch_info(k) {
                Some((e, local, _)) => {
                    let name = system.elements().nth(e).map_or("element", |el| el.name());
                    format!("{name} #{local}")
                }
                None => format!("switch {k}"),
            })
            .collect();
        Self {
            system,
            ws: system.workspace(),
            names,
            analytic: false,
        }
    }

    /// The same, giving the integrators the system's own Jacobian ([`System::jacobian`],
    /// the stiff part of `∂ẋ/∂x` from the force elements' derivatives) instead of finite
    /// differences, when every element has load derivatives. Linearly implicit methods
    /// ([`crate::Method::Ros34Pw2`]) then take a fresh one at every step for about the cost
    /// of one evaluation.
    pub fn with_analytic_jacobian(mut self) -> Self {
        self.analytic = self.system.has_jacobian();
        self
    }

    /// The workspace of the last evaluation (poses, forces, drive forces).
    pub fn workspace(&self) -> &Workspace {
        &self.ws
    }

    /// The wrapped system.
    pub fn system(&self) -> &System {
        self.system
    }
}

impl OdeSystem for MultibodyOde<'_> {
    fn len(&self) -> usize {
        self.system.state_len()
    }

    fn derivative(&mut self, t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SystemError> {
        self.system
            .derivative(&mut self.ws, t, y, dy)
            .map_err(SystemError::new)
    }

    fn has_jacobian(&self) -> bool {
        self.analytic
    }

    /// [`System::jacobian`]: the stiff part of `∂ẋ/∂x` from the force elements' own
    /// derivatives; the columns of the states outside the Jacobian are left as they are.
    fn jacobian(
        &mut self,
        t: f64,
        y: &[f64],
        jac: &mut nalgebra::DMatrix<f64>,
    ) -> Result<(), SystemError> {
        self.system
            .jacobian(&mut self.ws, t, y, jac)
            .map_err(SystemError::new)
    }

    fn jacobian_given_rate(
        &mut self,
        t: f64,
        y: &[f64],
        f: &[f64],
        jac: &mut nalgebra::DMatrix<f64>,
    ) -> Result<(), SystemError> {
        self.system
            .jacobian_with_rate(&mut self.ws, t, y, Some(f), jac)
            .map_err(SystemError::new)
    }

    fn states_outside_jacobian(&self) -> Vec<std::ops::Range<usize>> {
        self.system.states_outside_jacobian()
    }

    fn second_order_split(&self) -> Option<usize> {
        Some(self.system.model().nv())
    }

    fn event_count(&self) -> usize {
        self.system.switch_len()
    }

    fn events(&mut self, t: f64, y: &[f64], out: &mut [f64]) -> Result<(), SystemError> {
        self.system
            .switching_functions(&mut self.ws, t, y, out)
            .map_err(SystemError::new)
    }

    fn event_direction(&self, k: usize) -> Crossing {
        self.system
            .switch_info(k)
            .map_or(Crossing::Both, |(_, _, c)| c)
    }

    fn event_source(&self, k: usize) -> Option<EventSource> {
        self.system
            .switch_info(k)
            .map(|(element, local, _)| EventSource { element, local })
    }

    fn event_name(&self, k: usize) -> String {
        self.names
            .get(k)
            .cloned()
            .unwrap_or_else(|| format!("switch {k}"))
    }
}
