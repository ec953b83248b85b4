//! Constitutive laws: the normal force as a function of penetration (and its rate and
//! history), and the tangential (friction) force.

use crate::error::{ContactError, Result};

/// A normal contact law: the compressive force between two bodies as a function of the
/// penetration `δ` (m, positive when the surfaces overlap), its rate `δ̇` (m/s, positive
/// when approaching) and, for hereditary laws, internal states integrated with the system.
///
/// Laws never pull: the force is ≥ 0, and 0 whenever `δ ≤ 0`.
pub trait NormalLaw: Send + Sync + std::fmt::Debug {
    /// Number of internal states (0 for memoryless laws).
    fn state_count(&self) -> usize {
        0
    }

    /// The normal force (N, ≥ 0). `states` are the law's internal states; their rates are
    /// written into `rates` (same length), also when out of contact (memory relaxes).
    fn force(&self, delta: f64, delta_dot: f64, states: &[f64], rates: &mut [f64]) -> f64;
}

/// A tangential (friction) law: the friction force opposing the slip velocity, given the
/// normal force.
pub trait TangentialLaw: Send + Sync + std::fmt::Debug {
    /// Friction force along the tangent (N), opposing `slip` (m/s), for normal force
    /// `normal` (N, ≥ 0).
    fn force(&self, normal: f64, slip: f64) -> f64;
}

/// Checks a parameter is finite (and positive or non-negative), naming it.
pub(crate) fn check(law: &str, field: &str, value: f64, positive: bool) -> Result<f64> {
    let ok = value.is_finite() && if positive { value > 0.0 } else { value >= 0.0 };
    if ok {
        Ok(value)
    } else {
        Err(ContactError::InvalidParameter {
            item: format!("{law}.{field}"),
            message: format!(
                "must be {} and finite, got {value}",
                if positive { "positive" } else { "non-negative" }
            ),
        })
    }
}
