//! Running a keystroke: inputs, the integration, and the piano events and metrics read off
//! the contact events.

use mbs_core::time_function::PiecewiseLinear;
use mbs_integrators::Solution;

use crate::action::{Action, ModelKind};
use crate::error::{PianoError, Result};
use crate::params::ActionParams;

/// What drives the key.
#[derive(Clone, Debug, PartialEq)]
pub enum Input {
    /// A vertical force (N) on the key front from t = 0, released (dropped to zero over
    /// 1 ms) at `release_s` if given.
    Force {
        /// Force (N), pressing down.
        force_n: f64,
        /// Release time (s).
        release_s: Option<f64>,
    },
}

impl Input {
    fn validate(&self) -> Result<()> {
        match *self {
            Input::Force { force_n, release_s } => {
                if !(force_n.is_finite() && force_n >= 0.0) {
                    return Err(PianoError::Params {
                        field: "input.force_n".into(),
                        message: format!("must be a non-negative force, got {force_n}"),
                    });
                }
                if let Some(t) = release_s
                    && !(t.is_finite() && t > 0.0)
                {
                    return Err(PianoError::Params {
                        field: "input.release_s".into(),
                        message: format!("must be positive, got {t}"),
                    });
                }
                Ok(())
            }
        }
    }
}

/// A piano event, in time order.
#[derive(Clone, Debug, PartialEq)]
pub struct PianoEvent {
    /// What happened (`"let_off"`, `"string_contact_start"`, ...).
    pub name: &'static str,
    /// When (s).
    pub time_s: f64,
}

/// One blow of the hammer on the string.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Strike {
    /// Start of string contact (s).
    pub time_s: f64,
    /// Speed of the strike point at contact (m/s).
    pub hammer_velocity_m_s: f64,
    /// How long the felt stays on the string (s); `None` if the run ends in contact.
    pub contact_duration_s: Option<f64>,
}

/// The result of a keystroke.
#[derive(Clone, Debug)]
pub struct Run {
    /// Which model.
    pub kind: ModelKind,
    /// The integrator's solution (state on the output grid, raw events, statistics).
    pub solution: Solution,
    /// Piano events in time order.
    pub events: Vec<PianoEvent>,
    /// The blows.
    pub strikes: Vec<Strike>,
    /// First let-off (jack toe on the button), if any (s).
    pub let_off_time_s: Option<f64>,
    /// First key bottom (key on the front-rail punching) (s).
    pub key_bottom_time_s: Option<f64>,
    /// First check (hammer tail caught after a strike) (s).
    pub check_time_s: Option<f64>,
}

/// Contacts whose onset and release are piano events.
const EVENT_NAMES: [(&str, &str, &str); 5] = [
    ("let_off_button", "let_off", "let_off_release"),
    (
        "hammer_string",
        "string_contact_start",
        "string_contact_end",
    ),
    ("front_rail", "key_bottom", "key_lift"),
    ("backcheck", "check_catch", "check_release"),
    ("drop_screw", "drop", "drop_release"),
];

/// Simulates `kind` driven by `input` for `duration_s`, with output every `output_step_s`.
pub fn simulate(
    params: &ActionParams,
    kind: ModelKind,
    input: &Input,
    duration_s: f64,
    output_step_s: f64,
) -> Result<Run> {
    input.validate()?;
    if !(duration_s.is_finite() && duration_s > 0.0) {
        return Err(PianoError::Params {
            field: "duration_s".into(),
            message: format!("must be positive, got {duration_s}"),
        });
    }
    let mut action = Action::build(params, kind)?;
    let model = action.system.model().clone();
    match *input {
        Input::Force { force_n, release_s } => {
            let table = match release_s {
                None => vec![(0.0, force_n)],
                Some(t) => vec![(0.0, force_n), (t, force_n), (t + 1e-3, 0.0)],
            };
            action.add_key_force(PiecewiseLinear::new(table)?)?;
        }
    }
    let x0 = action.layout_state()?;
    let solution = action.integrate(&x0, duration_s, 1e-3, Some(output_step_s))?;
    let hammer = model.coordinate_id("hammer")?;
    let nv = model.nv();
    let strike_radius = {
        let s = params.hammer.strike_body_mm;
        (s[0] * s[0] + s[1] * s[1]).sqrt() * 1e-3
    };
    let mut events = Vec::new();
    let mut strikes: Vec<Strike> = Vec::new();
    for ev in &solution.events {
        for (contact, on, off) in EVENT_NAMES {
            if ev.name == format!("contact '{contact}' #0") {
                // The event state is just past the crossing: a negative gap is an onset.
                let onset = action.gap(contact, ev.time, &ev.state)? < 0.0;
                events.push(PianoEvent {
                    name: if onset { on } else { off },
                    time_s: ev.time,
                });
                if contact == "hammer_string" {
                    if onset {
                        strikes.push(Strike {
                            time_s: ev.time,
                            hammer_velocity_m_s: ev.state[nv + hammer].abs() * strike_radius,
                            contact_duration_s: None,
                        });
                    } else if let Some(s) = strikes.last_mut()
                        && s.contact_duration_s.is_none()
                    {
                        s.contact_duration_s = Some(ev.time - s.time_s);
                    }
                }
            }
        }
    }
    let first = |name: &str| events.iter().find(|e| e.name == name).map(|e| e.time_s);
    let first_strike = strikes.first().map(|s| s.time_s);
    let check_time_s = events
        .iter()
        .find(|e| e.name == "check_catch" && first_strike.is_some_and(|t| e.time_s > t))
        .map(|e| e.time_s);
    Ok(Run {
        kind,
        let_off_time_s: first("let_off"),
        key_bottom_time_s: first("key_bottom"),
        check_time_s,
        solution,
        events,
        strikes,
    })
}
