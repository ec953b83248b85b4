//! Measuring the regulation the way a technician does, on the simulated action: blow at
//! rest, let-off and drop by a slow key descent, check after a loud blow with the key held,
//! dip and aftertouch at the key front.

use mbs_core::time_function::PiecewiseLinear;
use mbs_integrators::Solution;

use crate::action::{Action, ModelKind};
use crate::error::Result;
use crate::params::ActionParams;

/// The regulation achieved (mm), as `piano regulate --json` reports it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Regulation {
    /// Key-front travel from rest to key bottom under a firm 20 N press.
    pub key_dip_mm: f64,
    /// Hammer crown to string at rest.
    pub blow_distance_mm: f64,
    /// Hammer crown to string when the jack escapes the knuckle in a slow press.
    pub let_off_mm: f64,
    /// How far the hammer drops after let-off, the key held down (rests on the repetition
    /// lever; 0 without one).
    pub drop_mm: f64,
    /// Hammer crown to string when caught by the backcheck after a loud blow, key held.
    pub check_mm: f64,
    /// Key-front travel left after let-off.
    pub aftertouch_mm: f64,
}

/// Key-front depth (mm) for key angle `q` (finger point rotating about the pivot).
fn key_depth_mm(params: &ActionParams, q: f64) -> f64 {
    let f = [
        params.key.finger_mm[0] - params.key.pivot_mm[0],
        params.key.finger_mm[1] - params.key.pivot_mm[1],
    ];
    let (s, c) = q.sin_cos();
    f[1] - (s * f[0] + c * f[1])
}

/// Runs `action` under a key-front force following `table` ((time, newtons) points).
fn run(action: &mut Action, table: Vec<(f64, f64)>, t_end: f64, max_step: f64) -> Result<Solution> {
    action.add_key_force(PiecewiseLinear::new(table)?)?;
    let x0 = action.layout_state()?;
    action.integrate(&x0, t_end, max_step, None)
}

/// Runs `action` with the key angle prescribed: a smooth move from `q0` to `q1` over
/// `t_move`, then held until `t_end` (a hand pressing slowly, as a technician does).
fn run_motion(action: &mut Action, q0: f64, q1: f64, t_move: f64, t_end: f64) -> Result<Solution> {
    let drive = mbs_core::time_function::SmoothMove::new(0.0, q0, t_move, q1)?;
    action.system.prescribe("key", drive)?;
    let n = action.system.model().nv();
    let x0 = action
        .system
        .initial_state(0.0, &vec![0.0; n], &vec![0.0; n])?;
    action.integrate(&x0, t_end, 2e-3, None)
}

/// Measures the regulation of `kind` built from `params`:
///
/// 1. blow: the action settles at rest for 0.3 s; crown-to-string gap;
/// 2. dip and check: a firm 20 N on the key front held for 0.3 s: key-front travel, and the
///    crown-to-string gap where the backcheck holds the hammer;
/// 3. let-off, aftertouch and drop: the key turned slowly (2 s) from rest to the dip and
///    held: the gap when the jack leaves the knuckle with its toe on the button, the key
///    travel left then, and how far the hammer falls onto the repetition lever afterwards.
pub fn measure(params: &ActionParams, kind: ModelKind) -> Result<Regulation> {
    let gap_mm = |a: &Action, x: &[f64]| -> Result<f64> { Ok(a.gap("hammer_string", x)? * 1e3) };
    let mut rest = Action::build(params, kind)?;
    let key = rest.system.model().coordinate_id("key")?;
    let settled = run(&mut rest, vec![(0.0, 0.0)], 0.3, 2e-3)?;
    let blow = gap_mm(&rest, &settled.y_final)?;
    let q_rest = settled.y_final[key];
    let rest_depth = key_depth_mm(params, q_rest);

    let mut firm = Action::build(params, kind)?;
    let held = run(&mut firm, vec![(0.0, 20.0)], 0.3, 1e-3)?;
    let q_dip = held.y_final[key];
    let dip = key_depth_mm(params, q_dip) - rest_depth;
    let check = if kind == ModelKind::Simplified {
        0.0
    } else {
        gap_mm(&firm, &held.y_final)?
    };

    let (mut let_off, mut aftertouch, mut drop) = (0.0, 0.0, 0.0);
    if kind != ModelKind::Simplified {
        let mut slow = Action::build(params, kind)?;
        let press = run_motion(&mut slow, q_rest, q_dip, 2.0, 2.5)?;
        let escape = press.events.iter().find(|e| {
            e.name == "contact 'jack_knuckle' #0"
                && slow.gap("jack_knuckle", &e.state).is_ok_and(|g| g > 0.0)
                && slow.gap("let_off_button", &e.state).is_ok_and(|g| g < 0.0)
        });
        if let Some(e) = escape {
            let_off = gap_mm(&slow, &e.state)?;
            aftertouch = dip - (key_depth_mm(params, e.state[key]) - rest_depth);
            if kind == ModelKind::Double {
                drop = gap_mm(&slow, &press.y_final)? - let_off;
            }
        }
    }
    Ok(Regulation {
        key_dip_mm: dip,
        blow_distance_mm: blow,
        let_off_mm: let_off,
        drop_mm: drop,
        check_mm: check,
        aftertouch_mm: aftertouch,
    })
}
