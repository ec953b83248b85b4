//! Static touchweight, measured as a technician does with weights but by a slow,
//! motion-driven key descent and ascent: the force the hand must supply at the key front.

use mbs_core::time_function::SmoothMove;

use crate::action::{Action, ModelKind};
use crate::error::Result;
use crate::params::ActionParams;

/// Touchweights in grams-force at the key front.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TouchWeight {
    /// Force to keep the key going down slowly (gf).
    pub down_weight_gf: f64,
    /// Force the key still holds while coming up slowly (gf).
    pub up_weight_gf: f64,
    /// (down + up) / 2 (gf).
    pub balance_weight_gf: f64,
    /// (down − up) / 2 (gf).
    pub friction_weight_gf: f64,
}

impl TouchWeight {
    /// The four weights as JSON, as `piano touchweight --json` prints them.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "down_weight_gf": self.down_weight_gf,
            "up_weight_gf": self.up_weight_gf,
            "balance_weight_gf": self.balance_weight_gf,
            "friction_weight_gf": self.friction_weight_gf,
        })
    }
}

/// One gram-force (N): a gram under standard gravity, 9.80665 m/s² [V] (CGPM 1901), as
/// touchweights are quoted in grams.
const GF: f64 = 9.80665e-3;

/// How much tighter than the parameter file's `[numerics]` tolerances the slow moves are
/// integrated. A quasi-static force read off stiff felts is their stiffness times the
/// position error: at the default absolute tolerance (1e-6) a 1e5 N/m felt errs by 0.1 N,
/// 10 gf, per sample. Measured (`touchweight::measure`, reference action, up weight and its
/// change under +0.75 mN m at the hammer flange, relative / absolute tolerance of the
/// moves): 24.315 / −2.83 gf at 1e-5 / 1e-8, 24.316 / −2.19 at 1e-6 / 1e-9, 24.341 /
/// −2.24 at 1e-7 / 1e-10, 24.345 / −2.25 at 1e-8 / 1e-11 and 1e-9 / 1e-12. The change
/// under friction is the sensitive figure (at 1e-5 / 1e-8 it also moved with the
/// integrator's Jacobian and its stage rates); at a thousandth of the default tolerances
/// it is within 0.06 gf of the converged value. The down weight is 52.324 gf at every
/// tolerance. The pair of moves takes about 120 ms.
const QUASI_STATIC_TOLERANCE_FACTOR: f64 = 1e-3;

/// The mean key-front force (gf) while the key turns slowly from `q0` to `q1` over 2 s,
/// averaged over the middle half of the move.
fn slow_move_force_gf(params: &ActionParams, kind: ModelKind, q0: f64, q1: f64) -> Result<f64> {
    let mut params = params.clone();
    // Not below 1e-10 / 1e-13 (unless the file already is): tighter buys nothing here.
    let n = &mut params.numerics;
    n.relative_tolerance =
        (n.relative_tolerance * QUASI_STATIC_TOLERANCE_FACTOR).max(n.relative_tolerance.min(1e-10));
    n.absolute_tolerance =
        (n.absolute_tolerance * QUASI_STATIC_TOLERANCE_FACTOR).max(n.absolute_tolerance.min(1e-13));
    let params = &params;
    let mut action = Action::build(params, kind)?;
    action
        .system
        .prescribe("key", SmoothMove::new(0.2, q0, 2.2, q1)?)?;
    let n = action.system.model().nv();
    let x0 = action
        .system
        .initial_state(0.0, &vec![0.0; n], &vec![0.0; n])?;
    let sol = action.integrate(&x0, 2.2, 2e-3, Some(0.01))?;
    let key = action.system.model().coordinate_id("key")?;
    let k = &params.key;
    let arm = crate::key::KeyGeometry::of(k).arm_m(0.0).abs();
    let mut ws = action.system.workspace();
    let mut xdot = vec![0.0; action.system.state_len()];
    let (mut sum, mut count) = (0.0, 0.0f64);
    for i in 0..sol.len() {
        let t = sol.t[i];
        if (0.7..=1.7).contains(&t) {
            action
                .system
                .derivative(&mut ws, t, sol.state(i), &mut xdot)?;
            // The drive's torque on the key, as a downward force at the key front.
            sum += ws.drive_forces()[key] / arm / GF;
            count += 1.0;
        }
    }
    Ok(sum / count.max(1.0))
}

/// Measures down and up weight by moving the key slowly through the first 6 mm of its dip
/// (before let-off) and back.
pub fn measure(params: &ActionParams, kind: ModelKind) -> Result<TouchWeight> {
    let k = &params.key;
    let arm = crate::key::KeyGeometry::of(k).arm_m(0.0).abs();
    let q = 6e-3 / arm;
    let down = slow_move_force_gf(params, kind, 0.0, q)?;
    let up = slow_move_force_gf(params, kind, q, 0.0)?;
    Ok(TouchWeight {
        down_weight_gf: down,
        up_weight_gf: up,
        balance_weight_gf: 0.5 * (down + up),
        friction_weight_gf: 0.5 * (down - up),
    })
}
