//! Repetition, the upright against the grand's double escapement, both run from their
//! descriptions by the same code.
//!
//! - **Key rise to repeat** ([`key_rise_to_repeat`]). The key is pressed (a prescribed
//!   motion) in 30 ms to the depth a 10 N hold gives, held until 180 ms (blow, rebound,
//!   check), then let up at a constant speed at the front. The key-front rise from the
//!   bottom when the jack is back under the hammer is what a player must give back before
//!   the note can sound again.
//! - **Fastest repetition at a fixed force** ([`fastest_repetition_hz`]). The finger pushes
//!   with a constant force for the first half of each period and rests on the key with a
//!   light force for the second (0 lets go of it), `presses` times; a rate repeats when
//!   every press strikes the string. The fastest rate is the highest of those tried below
//!   which every rate repeats.
//!
//! The upright's jack is back under the butt when its top's centre has come back past the
//! notch's lip by half its radius ([`crate::jack_top_past_lip_mm`]); the grand's when its
//! jack is back at its stop under the knuckle (within 2 mrad), as `piano simulate`'s
//! `jack_reset` event.

use mbs_core::time_function::BlendedLinear;
use piano_action::key::KeyGeometry;
use piano_action::mechanism::{Built, Input, InputKind, Mechanism};
use piano_action::mechanism_run::{settle, simulate_mechanism};
use piano_action::{ActionParams, ModelKind, PianoError, integrate_system};

type Result<T> = std::result::Result<T, PianoError>;

/// The two actions compared.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Action {
    /// [`crate::upright_mechanism`].
    Upright,
    /// The grand double escapement's description (`piano describe --model double`).
    Grand,
}

/// When the jack starts back up, the key having been held since `HOLD_END_S`.
const HOLD_END_S: f64 = 0.18;
/// The force whose hold sets the pressed depth (N).
const HOLD_FORCE_N: f64 = 10.0;

impl Action {
    /// Its description.
    pub fn mechanism(self) -> Result<Mechanism> {
        match self {
            Action::Upright => crate::upright_mechanism(),
            Action::Grand => piano_action::describe::grand_description(
                &ActionParams::reference(),
                ModelKind::Double,
            ),
        }
    }

    /// Whether the jack is back under the hammer at `(t, x)`.
    fn jack_back(self, built: &Built, t: f64, x: &[f64]) -> Result<bool> {
        Ok(match self {
            Action::Upright => crate::jack_top_past_lip_mm(built, t, x)? > 1.0,
            Action::Grand => {
                let jack = built.system.model().coordinate_id("jack")?;
                coordinates(built, t, x)?[jack]
                    < ActionParams::reference().jack.stop_angle_rad + 2e-3
            }
        })
    }
}

/// The coordinates at `(t, x)`, prescribed ones included (the state holds only the free
/// ones).
fn coordinates(built: &Built, t: f64, x: &[f64]) -> Result<Vec<f64>> {
    let mut ws = built.system.workspace();
    Ok(built.system.kinematics(&mut ws, t, x)?.q.to_vec())
}

/// The key-front rise to repeat, for one action and one rise speed.
#[derive(Clone, Copy, Debug)]
pub struct KeyRise {
    /// The pressed depth (mm, below rest): where a 10 N hold takes the key.
    pub depth_mm: f64,
    /// How far (mm) the key front has risen from the bottom when the jack is back under
    /// the hammer; `None` if it is not back by the time the key is up.
    pub rise_mm: Option<f64>,
}

/// Measures the key rise to repeat for `action`, the key let up at `speed_mm_s` at the front.
pub fn key_rise_to_repeat(action: Action, speed_mm_s: f64) -> Result<KeyRise> {
    let params = ActionParams::reference();
    let numerics = &params.numerics;
    let mut m = action.mechanism()?;
    // The pressed depth: the key front under a 10 N hold, hammer checked.
    let held = simulate_mechanism(
        &m,
        &piano_action::simulate::Input::Force {
            force_n: HOLD_FORCE_N,
            release_s: None,
        },
        numerics,
        0.3,
        0.15,
        1e-3,
        &mut |_| {},
    )?;
    let key_lever = KeyGeometry::from_mechanism(&m, "finger")?;
    let front = m
        .inputs
        .iter()
        .find(|i| i.name == "finger")
        .map(|i| i.at.clone())
        .ok_or_else(|| PianoError::option("inputs", "the description has no 'finger' input"))?;
    let key = held.built.system.model().coordinate_id(&front.body)?;
    let q0 = held.x0[key];
    let depth_mm = key_lever.height_mm(q0) - key_lever.height_mm(held.solution.y_final[key]);

    m.inputs.push(Input {
        name: "key motion".into(),
        note: String::new(),
        kind: InputKind::Motion,
        at: front.clone(),
        direction: [0.0, -1.0],
    });
    let q_bottom = key_lever.angle_below(q0, depth_mm);
    let up_s = depth_mm / speed_mm_s;
    let drive = BlendedLinear::new(
        &[
            (0.0, q0),
            (0.005, q0),
            (0.035, q_bottom),
            (HOLD_END_S, q_bottom),
            (HOLD_END_S + up_s, q0),
        ],
        5e-3,
    )?;
    let x_settled = settle(&m, numerics, 0.3)?;
    let mut built = m.build_with(&piano_action::describe::PianoExtensions)?;
    built.drive_motion(&m, "key motion", drive)?;
    let nv = built.system.model().nv();
    let x0 = built
        .system
        .initial_state(0.0, &x_settled, &vec![0.0; nv])?;
    let t_end = HOLD_END_S + up_s + 0.05;
    let sol = integrate_system(
        &built.system,
        numerics,
        &x0,
        t_end,
        1e-3,
        Some(1e-3),
        &mut |_| {},
    )?;
    let mut rise = None;
    let mut escaped = false;
    for i in 0..sol.len() {
        let (t, x) = (sol.t[i], sol.state(i));
        let back = action.jack_back(&built, t, x)?;
        if t <= HOLD_END_S {
            // Out from under the hammer by the end of the hold.
            escaped = !back;
        } else if escaped && back {
            let q = coordinates(&built, t, x)?;
            rise = Some(key_lever.height_mm(q[key]) - key_lever.height_mm(q_bottom));
            break;
        }
    }
    if !escaped {
        return Err(PianoError::option(
            "repetition",
            "the jack was still under the hammer at the end of the hold: it never escaped",
        ));
    }
    Ok(KeyRise {
        depth_mm,
        rise_mm: rise,
    })
}

/// Strikes per press: `presses` presses at `rate_hz`, the finger pushing `force_n` for the
/// first half of each period and resting on the key with `rest_n` for the second (2 ms
/// ramps; 0 lets go of the key).
pub fn strikes_per_press(
    action: Action,
    force_n: f64,
    rest_n: f64,
    rate_hz: f64,
    presses: usize,
) -> Result<Vec<usize>> {
    let m = action.mechanism()?;
    let period = 1.0 / rate_hz;
    let mut points = vec![(0.0, 0.0)];
    for k in 0..presses {
        let t0 = k as f64 * period;
        if k > 0 {
            points.push((t0, rest_n));
        }
        points.push((t0 + 2e-3, force_n));
        points.push((t0 + 0.5 * period, force_n));
        points.push((t0 + 0.5 * period + 2e-3, rest_n));
    }
    let run = simulate_mechanism(
        &m,
        &piano_action::simulate::Input::ForceTable { points },
        &ActionParams::reference().numerics,
        0.3,
        presses as f64 * period,
        1e-3,
        &mut |_| {},
    )?;
    let mut per = vec![0; presses];
    for e in run.events.iter().filter(|e| e.name == "strike") {
        let k = ((e.time_s / period).floor() as usize).min(presses - 1);
        per[k] += 1;
    }
    Ok(per)
}

/// The fastest of `rates_hz` (ascending) below which every rate repeats: each of
/// `presses` presses of `force_n` (the finger resting with `rest_n` between) strikes.
/// `None` if the slowest does not.
pub fn fastest_repetition_hz(
    action: Action,
    force_n: f64,
    rest_n: f64,
    rates_hz: &[f64],
    presses: usize,
) -> Result<Option<f64>> {
    let mut fastest = None;
    for &rate in rates_hz {
        if strikes_per_press(action, force_n, rest_n, rate, presses)?
            .iter()
            .all(|&n| n > 0)
        {
            fastest = Some(rate);
        } else {
            break;
        }
    }
    Ok(fastest)
}
