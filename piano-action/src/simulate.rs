//! Running a keystroke: inputs, the integration, and the piano events and metrics read off
//! the contact events.

pub use mbs_core::time_function::BlendedLinear;
use mbs_core::time_function::{Drive, PiecewiseLinear};
use mbs_integrators::Solution;

use mbs_core::elements::{AppliedLoad, Attachment, JointSpringDamper, LoadFrame, SpringLaw};

use crate::action::{Action, ModelKind, Presser, Transform};
use crate::error::{PianoError, Result};
use crate::params::{ActionParams, ContactParams};

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
    /// A vertical force on the key front following a table of `(time_s, force_n)` points,
    /// piecewise linear, held at the last value (a ramp is two points).
    ForceTable {
        /// `(time_s, force_n)` points, times increasing; pressing down is positive.
        points: Vec<(f64, f64)>,
    },
    /// Prescribed key-front depth: `(time_s, depth_mm)` points, piecewise linear (corners
    /// rounded over at most 5 ms so the key's acceleration stays finite), held before the
    /// first point and after the last. Depth is measured at the finger point from the key's
    /// rest (where it settles with nothing on it), positive down. The force the hand needs is in
    /// [`Run::key_drive_force_n`].
    Motion {
        /// `(time_s, depth_mm)` points, times increasing.
        points: Vec<(f64, f64)>,
    },
    /// A mass released at rest `height_m` above the key front (0: placed on it), falling
    /// onto it through a firm pad (the 1 kg experiment).
    MassDrop {
        /// Mass (kg).
        mass_kg: f64,
        /// Drop height (m).
        height_m: f64,
    },
    /// A finger playing the key: its pad touches the key top at the finger point.
    Touch {
        /// Pressed (resting, force building up) or struck (arriving with a speed).
        style: TouchStyle,
        /// The finger's mass, pad and arm.
        finger: Finger,
    },
}

/// How the finger plays the key (Goebl, Bresin & Galembo 2005: pressed and struck touch).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TouchStyle {
    /// The finger rests on the key and its force builds up linearly to `peak_force_n` over
    /// [`Finger::rise_s`], then holds.
    Pressed {
        /// Force reached at the end of the rise (N).
        peak_force_n: f64,
    },
    /// The finger arrives at `finger_speed_m_s`, its pad [`STRUCK_START_MM`] above the key
    /// top at t = 0; the arm keeps pushing toward that speed through a viscous coupling
    /// ([`Finger::arm_damping_n_s_m`]), so it pushes harder the more the key resists and
    /// holds `arm_damping × speed` on the bottomed key.
    Struck {
        /// Finger speed on arrival (m/s, downward).
        finger_speed_m_s: f64,
    },
}

/// Height of a struck finger's pad above the key top at t = 0 (mm).
pub const STRUCK_START_MM: f64 = 0.5;

/// The finger of a touch. Its weight is carried by the arm: only the touch force and its
/// inertia act on the key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Finger {
    /// Effective mass of the fingertip and the part of the hand moving with it (g).
    pub mass_g: f64,
    /// Rise time of a pressed touch's force (s).
    pub rise_s: f64,
    /// Viscous coupling of the arm driving a struck finger (N·s/m).
    pub arm_damping_n_s_m: f64,
    /// Pulp of the fingertip against the key top (a soft, lossy felt-type law).
    pub pad: ContactParams,
}

impl Default for Finger {
    /// A fingertip derived for this model \[D\]: 20 g effective mass, the pressed force
    /// rising over 30 ms, an arm coupling of 20 N·s/m (a 1 m/s finger holds 20 N on the
    /// bottomed key, inside the 8-50 N staccato peaks of Kinoshita et al. 2007), and a pulp
    /// stiffening as `k δ²` with k = 2e6 N/m² (2 N at 1 mm, 50 N at 5 mm), restitution 0.2.
    fn default() -> Self {
        Finger {
            mass_g: 20.0,
            rise_s: 0.03,
            arm_damping_n_s_m: 20.0,
            pad: ContactParams {
                k: 2.0e6,
                p: 2.0,
                e: 0.2,
                mu: 0.0,
            },
        }
    }
}

/// The largest key-front force a run accepts (N) [D]: staccato fortissimo peaks reach
/// 50 N (Kinoshita et al. 2007); 200 N is four times that.
pub const MAX_KEY_FORCE_N: f64 = 200.0;

/// The slowest struck finger (m/s) [D]: below about 0.05 m/s the key does not reach the
/// let-off; 0.01 m/s is a tenth of the softest measured touch (Goebl et al. 2005).
pub const MIN_FINGER_SPEED_M_S: f64 = 0.01;

/// How far from rest a key motion may start (mm) [D]: a measured table's first sample.
pub const MOTION_START_TOLERANCE_MM: f64 = 0.05;

impl Input {
    /// Checks the input's values (forces, speeds, masses, tables), naming the bad field.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Input::Force { force_n, release_s } => {
                if !(force_n.is_finite() && (0.0..=MAX_KEY_FORCE_N).contains(&force_n)) {
                    return Err(PianoError::scenario(
                        "input.force_n",
                        format!("must be a force of 0 to {MAX_KEY_FORCE_N} N, got {force_n}"),
                    ));
                }
                if let Some(t) = release_s
                    && !(t.is_finite() && t > 0.0)
                {
                    return Err(PianoError::scenario(
                        "input.release_s",
                        format!("must be positive, got {t}"),
                    ));
                }
                Ok(())
            }
            Input::MassDrop { mass_kg, height_m } => {
                if !(mass_kg.is_finite() && mass_kg > 0.0 && mass_kg <= 20.0) {
                    return Err(PianoError::scenario(
                        "input.mass_kg",
                        format!("must be a mass of up to 20 kg, got {mass_kg}"),
                    ));
                }
                if !(height_m.is_finite() && (0.0..=0.5).contains(&height_m)) {
                    return Err(PianoError::scenario(
                        "input.height_m",
                        format!("must be 0 to 0.5 m, got {height_m}"),
                    ));
                }
                Ok(())
            }
            Input::Touch { style, finger } => {
                let bad = |field: &str, message: String| {
                    PianoError::scenario(format!("input.{field}"), message)
                };
                match style {
                    TouchStyle::Pressed { peak_force_n } => {
                        if !(peak_force_n.is_finite()
                            && (0.0..=MAX_KEY_FORCE_N).contains(&peak_force_n))
                        {
                            return Err(bad(
                                "peak_force_n",
                                format!(
                                    "must be a force of 0 to {MAX_KEY_FORCE_N} N, got {peak_force_n}"
                                ),
                            ));
                        }
                    }
                    TouchStyle::Struck { finger_speed_m_s } => {
                        if !(MIN_FINGER_SPEED_M_S..=10.0).contains(&finger_speed_m_s) {
                            return Err(bad(
                                "finger_speed_m_s",
                                format!(
                                    "must be a speed of {MIN_FINGER_SPEED_M_S} to 10 m/s, got {finger_speed_m_s}"
                                ),
                            ));
                        }
                    }
                }
                let positive = [
                    ("finger_mass_g", finger.mass_g),
                    ("rise_s", finger.rise_s),
                    ("arm_damping_n_s_m", finger.arm_damping_n_s_m),
                ];
                for (field, v) in positive {
                    if !(v.is_finite() && v > 0.0) {
                        return Err(bad(field, format!("must be positive, got {v}")));
                    }
                }
                Ok(())
            }
            Input::Motion { ref points } => {
                check_table(points, "[time_s, depth_mm]", |d| {
                    (-20.0..=20.0).contains(&d).then_some(()).ok_or_else(|| {
                        format!("depth {d} mm is outside -20..20 mm (a key dips about 10)")
                    })
                })?;
                // The key starts at rest: the table holds its first depth from t = 0.
                let first = points[0].1;
                if first.abs() > MOTION_START_TOLERANCE_MM {
                    return Err(PianoError::scenario(
                        "input.points[0][1]",
                        format!(
                            "the key starts at rest, so the first depth must be 0 mm, got \
                             {first} mm (the key would jump there at t = 0)"
                        ),
                    ));
                }
                Ok(())
            }
            Input::ForceTable { ref points } => check_table(points, "[time_s, force_n]", |f| {
                (-MAX_KEY_FORCE_N..=MAX_KEY_FORCE_N)
                    .contains(&f)
                    .then_some(())
                    .ok_or_else(|| format!("force {f} N is outside ±{MAX_KEY_FORCE_N} N"))
            }),
        }
    }
}

/// Checks a `(time, value)` table (field `input.points`): at least one point, finite,
/// times from 0 on and increasing, each value accepted by `value_ok`. The error names the
/// point (`input.points[3][1]`).
fn check_table(
    points: &[(f64, f64)],
    what: &str,
    value_ok: impl Fn(f64) -> std::result::Result<(), String>,
) -> Result<()> {
    let bad = |field: String, message: String| PianoError::scenario(field, message);
    if points.is_empty() {
        return Err(bad(
            "input.points".into(),
            format!("needs at least one {what} point"),
        ));
    }
    for (i, &(t, v)) in points.iter().enumerate() {
        let (time, value) = (
            format!("input.points[{i}][0]"),
            format!("input.points[{i}][1]"),
        );
        if !t.is_finite() {
            return Err(bad(time, format!("time is not finite: {t}")));
        }
        if !v.is_finite() {
            return Err(bad(value, format!("value is not finite: {v}")));
        }
        if t < 0.0 {
            return Err(bad(
                time,
                format!("time {t} s is negative (times count from the run's start)"),
            ));
        }
        value_ok(v).map_err(|m| bad(value, m))?;
        if i > 0 && t <= points[i - 1].0 {
            return Err(bad(
                time,
                format!(
                    "times must increase: {t} s comes after {} s",
                    points[i - 1].0
                ),
            ));
        }
    }
    Ok(())
}

/// The key angle (rad) that puts the finger point `depth_mm` below its layout position.
pub fn key_angle_for_depth(params: &ActionParams, depth_mm: f64) -> f64 {
    crate::key::KeyGeometry::of(&params.key).angle_for_depth(depth_mm)
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
    /// Speed of the strike point leaving the string (m/s, away from it); `None` if the run
    /// ends in contact. Over the strike speed it is the restitution the string gives.
    pub rebound_velocity_m_s: Option<f64>,
    /// Contact pulses in the blow (1 for a clean blow): the pulse reflected from the agraffe
    /// can lift a slow hammer off the string for a fraction of a millisecond, and the
    /// contacts that follow within [`BLOW_PULSE_GAP_S`] belong to the same blow;
    /// `contact_duration_s` runs from the first touch to the last release.
    pub pulses: usize,
}

/// Contacts of the hammer on the string that start less than this after the last one ended
/// are pulses of the same blow, not a second strike (s): 5 ms, more than a C4 string period
/// (3.8 ms), so the string's reflections cannot split a blow, and far less than a hammer
/// thrown back up by the action needs to return (a double strike takes 20 ms or more).
pub const BLOW_PULSE_GAP_S: f64 = 5e-3;

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
    /// When the key front has first gone [`KEY_START_MM`] below its rest (s).
    pub key_start_time_s: Option<f64>,
    /// From key start to the first string contact (s): the travel time of Askenfelt &
    /// Jansson and Goebl et al.
    pub travel_time_s: Option<f64>,
    /// First let-off (jack toe on the button), if any (s).
    pub let_off_time_s: Option<f64>,
    /// First key bottom (key on the front-rail punching) (s).
    pub key_bottom_time_s: Option<f64>,
    /// First check (hammer tail caught after a strike) (s).
    pub check_time_s: Option<f64>,
    /// Under a prescribed key motion, the vertical force the hand applies at the finger
    /// point (N, pressing down positive) on the output grid; empty otherwise.
    pub key_drive_force_n: Vec<f64>,
}

/// Key-front depth below its rest (mm) that marks the key's start: the finger has begun to
/// move it.
pub const KEY_START_MM: f64 = 0.1;

/// The first time the key front is [`KEY_START_MM`] below its rest: from the prescribed table under a
/// motion input, otherwise interpolated on the output grid.
fn key_start_time(
    params: &ActionParams,
    input: &Input,
    solution: &Solution,
    key: usize,
    rest_depth_mm: f64,
) -> Option<f64> {
    if let Input::Motion { points } = input {
        // The table was checked before the run.
        let depth = BlendedLinear::new(points, 5e-3).ok()?;
        // Search from the table's start to its end, but not past the run's end.
        let end = solution.t.last().copied().unwrap_or(0.0);
        let (t0, t1) = (
            (points[0].0 - 5e-3).max(0.0),
            (points[points.len() - 1].0 + 5e-3).min(end),
        );
        if t1 < t0 {
            return None;
        }
        let n = ((t1 - t0) / 1e-5).ceil() as usize;
        return (0..=n)
            .map(|i| t0 + i as f64 * 1e-5)
            .find(|&t| depth.eval(t).q >= KEY_START_MM)
            .map(|t| t.max(0.0));
    }
    let depth_at = |i: usize| key_depth_mm(params, solution.state(i)[key]) - rest_depth_mm;
    let mut before = (solution.t[0], depth_at(0));
    if before.1 >= KEY_START_MM {
        return Some(before.0);
    }
    for i in 1..solution.len() {
        let now = (solution.t[i], depth_at(i));
        if now.1 >= KEY_START_MM {
            let u = (KEY_START_MM - before.1) / (now.1 - before.1);
            return Some(before.0 + u * (now.0 - before.0));
        }
        before = now;
    }
    None
}

/// Key-front depth (mm, down positive) at key angle `q`.
pub fn key_depth_mm(params: &ActionParams, q: f64) -> f64 {
    crate::key::KeyGeometry::of(&params.key).depth_mm(q)
}

/// Contacts whose onset and release are piano events.
const EVENT_NAMES: [(&str, &str, &str); 6] = [
    ("presser_key", "finger_key", "finger_key_release"),
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

/// An action assembled for an input, and its starting state.
pub struct Prepared {
    /// The action with the input's bodies and forces (presser, finger, drive).
    pub action: Action,
    /// The state at t = 0: the action settled at rest, the presser placed and moving.
    pub x0: Vec<f64>,
    /// Key-front depth of the rest below the layout (mm).
    pub rest_depth_mm: f64,
}

/// Assembles `kind` with what `input` adds (a presser and its forces, a key force or a
/// key drive) and the starting state, settled at rest; the input is checked first.
pub fn prepare(params: &ActionParams, kind: ModelKind, input: &Input) -> Result<Prepared> {
    prepare_transformed(params, kind, input, None)
}

/// The body an input puts on the key front (a mass, a finger), if any.
fn presser_for(input: &Input) -> Option<Presser> {
    match *input {
        Input::MassDrop { mass_kg, height_m } => Some(Presser::weight(mass_kg, height_m * 1e3)),
        Input::Touch { style, finger } => Some(Presser {
            mass_kg: finger.mass_g * 1e-3,
            height_mm: match style {
                TouchStyle::Pressed { .. } => 0.0,
                TouchStyle::Struck { .. } => STRUCK_START_MM,
            },
            pad: finger.pad,
            carried: true,
        }),
        _ => None,
    }
}

/// The coordinates of a run of `input` on `kind`, in the order of its states: the action's,
/// then the presser's (`"presser"`) for a mass drop or a touch. Builds the action without
/// settling it.
pub fn coordinate_names(
    params: &ActionParams,
    kind: ModelKind,
    input: &Input,
) -> Result<Vec<String>> {
    input.validate()?;
    let action = Action::build_transformed(params, kind, presser_for(input), None)?;
    Ok(action.system.model().coordinate_names().to_vec())
}

/// Assembles like [`prepare`], the grand's description changed by `transform` if given
/// (an effect a diagnosis adds); the rest is then settled on the changed action.
pub fn prepare_transformed(
    params: &ActionParams,
    kind: ModelKind,
    input: &Input,
    transform: Option<Transform<'_>>,
) -> Result<Prepared> {
    input.validate()?;
    let presser = presser_for(input);
    // Start from the action settled at rest (the presser, if any, last, with its pad where
    // the layout put it relative to the key top).
    let rest = match transform {
        None => Action::rest_coordinates(params, kind)?,
        Some(f) => Action::rest_coordinates_transformed(params, kind, f)?,
    };
    let rest_depth_mm = key_depth_mm(params, rest[0]);
    let mut action = Action::build_transformed(params, kind, presser, transform)?;
    let model = action.system.model().clone();
    let nv = model.nv();
    let mut q0 = rest.clone();
    q0.resize(nv, -rest_depth_mm * 1e-3);
    let mut v0 = vec![0.0; nv];
    match *input {
        Input::MassDrop { .. } => {}
        Input::Touch { style, finger } => match style {
            TouchStyle::Pressed { peak_force_n } => {
                let push = AppliedLoad::force(
                    &model,
                    "finger",
                    Attachment::on("presser", [0.0, 0.0]),
                    [0.0, -1.0],
                    LoadFrame::World,
                    PiecewiseLinear::new(vec![(0.0, 0.0), (finger.rise_s, peak_force_n)])?,
                )?;
                action.system.add_element(push)?;
            }
            TouchStyle::Struck { finger_speed_m_s } => {
                // τ = −c (v + v₀): no force while the finger moves at v₀ (downward).
                let c = finger.arm_damping_n_s_m;
                let arm = SpringLaw::new(0.0, 0.0)
                    .with_damping(c)
                    .with_preload(-c * finger_speed_m_s);
                action
                    .system
                    .add_element(JointSpringDamper::new(&model, "presser", arm)?.named("arm"))?;
                v0[model.coordinate_id("presser")?] = -finger_speed_m_s;
            }
        },
        Input::Force { force_n, release_s } => {
            let table = match release_s {
                None => vec![(0.0, force_n)],
                Some(t) => vec![(0.0, force_n), (t, force_n), (t + 1e-3, 0.0)],
            };
            action.add_key_force(PiecewiseLinear::new(table)?)?;
        }
        Input::ForceTable { ref points } => {
            action.add_key_force(PiecewiseLinear::new(points.clone())?)?;
        }
        Input::Motion { ref points } => {
            let table: Vec<(f64, f64)> = points
                .iter()
                .map(|&(t, d)| (t, key_angle_for_depth(params, d + rest_depth_mm)))
                .collect();
            action
                .system
                .prescribe("key", BlendedLinear::new(&table, 5e-3)?)?;
        }
    }
    let x0 = action.system.initial_state(0.0, &q0, &v0)?;
    Ok(Prepared {
        action,
        x0,
        rest_depth_mm,
    })
}

/// The longest simulated time a run accepts (s) [D]: a keystroke is over in well under a
/// second, a repeated-note pattern in a few, the hammer swing test rings down in tens.
pub const MAX_DURATION_S: f64 = 60.0;

/// The most output points a run keeps [D]: 200 000 rows of `trajectory.csv` and
/// `contacts.csv` are already some 120 MB (a minute at 0.3 ms).
pub const MAX_OUTPUT_POINTS: f64 = 2e5;

/// Checks a run's `duration_s` and `output_step_s` before anything runs: positive, finite,
/// at most [`MAX_DURATION_S`], and at most [`MAX_OUTPUT_POINTS`] output points.
pub fn check_duration(duration_s: f64, output_step_s: f64) -> Result<()> {
    if !(duration_s.is_finite() && duration_s > 0.0) {
        return Err(PianoError::scenario(
            "duration_s",
            format!("must be a positive number of seconds, got {duration_s}"),
        ));
    }
    if duration_s > MAX_DURATION_S {
        return Err(PianoError::scenario(
            "duration_s",
            format!(
                "{duration_s} s is longer than the {MAX_DURATION_S} s a run may last (a \
                 keystroke is over in under a second); simulate less time"
            ),
        ));
    }
    if !(output_step_s.is_finite() && output_step_s > 0.0) {
        return Err(PianoError::scenario(
            "output_step_s",
            format!("must be a positive number of seconds, got {output_step_s}"),
        ));
    }
    let points = duration_s / output_step_s;
    if points > MAX_OUTPUT_POINTS {
        return Err(PianoError::scenario(
            "output_step_s",
            format!(
                "{output_step_s} s over {duration_s} s gives {points:.3e} output points, more \
                 than the {MAX_OUTPUT_POINTS} a run keeps; choose a longer output step"
            ),
        ));
    }
    Ok(())
}

/// Simulates `kind` driven by `input` for `duration_s`, with output every `output_step_s`.
pub fn simulate(
    params: &ActionParams,
    kind: ModelKind,
    input: &Input,
    duration_s: f64,
    output_step_s: f64,
) -> Result<Run> {
    simulate_observed(params, kind, input, duration_s, output_step_s, &mut |_| {})
}

/// Simulates like [`simulate()`], calling `progress` with the simulated time after every
/// integration step (for a progress bar).
pub fn simulate_observed(
    params: &ActionParams,
    kind: ModelKind,
    input: &Input,
    duration_s: f64,
    output_step_s: f64,
    progress: &mut dyn FnMut(f64),
) -> Result<Run> {
    simulate_transformed(
        params,
        kind,
        input,
        duration_s,
        output_step_s,
        None,
        progress,
    )
}

/// Simulates like [`simulate_observed`], the grand's description changed by `transform`
/// if given (see [`prepare_transformed`]).
pub fn simulate_transformed(
    params: &ActionParams,
    kind: ModelKind,
    input: &Input,
    duration_s: f64,
    output_step_s: f64,
    transform: Option<Transform<'_>>,
    progress: &mut dyn FnMut(f64),
) -> Result<Run> {
    check_duration(duration_s, output_step_s)?;
    let Prepared {
        action,
        x0,
        rest_depth_mm,
    } = prepare_transformed(params, kind, input, transform)?;
    let solution =
        action.integrate_observed(&x0, duration_s, MAX_STEP_S, Some(output_step_s), progress)?;
    run_of(params, kind, input, &action, solution, rest_depth_mm)
}

/// The longest step of a keystroke's integration (s) [D].
const MAX_STEP_S: f64 = 1e-3;

/// Simulates like [`simulate_transformed`] (without progress), to the same result to the
/// last bit, but from a remembered run where one allows: a mass drop whose action differs
/// from one simulated before only in the laws of contacts that had not yet acted goes on
/// from that run's last checkpoint before they did (a fit that varies only the
/// back-check's felt, or a finite difference in it, simulates only what follows the
/// hammer's check). See [`crate::action::resumed_or_solved`].
pub fn simulate_transformed_resuming(
    params: &ActionParams,
    kind: ModelKind,
    input: &Input,
    duration_s: f64,
    output_step_s: f64,
    transform: Option<Transform<'_>>,
) -> Result<Run> {
    check_duration(duration_s, output_step_s)?;
    let Prepared {
        action,
        x0,
        rest_depth_mm,
    } = prepare_transformed(params, kind, input, transform)?;
    let solution = if matches!(input, Input::MassDrop { .. }) {
        crate::action::resumed_or_solved(
            &action,
            input,
            &x0,
            duration_s,
            MAX_STEP_S,
            output_step_s,
        )?
        .0
    } else {
        action.integrate_observed(
            &x0,
            duration_s,
            MAX_STEP_S,
            Some(output_step_s),
            &mut |_| {},
        )?
    };
    run_of(params, kind, input, &action, solution, rest_depth_mm)
}

/// The run of `action` (assembled for `input` from `params`) from its `solution`: the
/// strikes, the events by name, the key drive's force.
fn run_of(
    params: &ActionParams,
    kind: ModelKind,
    input: &Input,
    action: &Action,
    solution: Solution,
    rest_depth_mm: f64,
) -> Result<Run> {
    let model = action.system.model().clone();
    let nv = model.nv();
    let mut key_drive_force_n = Vec::new();
    if matches!(input, Input::Motion { .. }) {
        let key = model.coordinate_id("key")?;
        let mut ws = action.system.workspace();
        let mut dx = vec![0.0; action.system.state_len()];
        for i in 0..solution.len() {
            let (t, x) = (solution.t[i], solution.state(i));
            action.system.derivative(&mut ws, t, x, &mut dx)?;
            // The torque the drive applies about the balance pivot, as a vertical force at
            // the finger point (the lever arm is its horizontal distance).
            let arm = crate::key::KeyGeometry::of(&params.key).arm_m(x[key]);
            key_drive_force_n.push(-ws.drive_forces()[key] / arm);
        }
    }
    let hammer = model.coordinate_id("hammer")?;
    let strike_radius = {
        let s = params.hammer.strike_body_mm;
        (s[0] * s[0] + s[1] * s[1]).sqrt() * 1e-3
    };
    let key_start_time_s = key_start_time(
        params,
        input,
        &solution,
        model.coordinate_id("key")?,
        rest_depth_mm,
    );
    let mut events = Vec::new();
    if let Some(t) = key_start_time_s {
        events.push(PianoEvent {
            name: "key_start",
            time_s: t,
        });
    }
    let mut strikes: Vec<Strike> = Vec::new();
    // The jack is reset when it comes back to its stop under the knuckle after a let-off,
    // once the key has begun to rise from the front rail.
    // Events are read through the element that raised them and the way they crossed.
    let jack_limit = action.elements.get("jack limits").copied();
    let jack = model.coordinate_id("jack").ok();
    let (mut escaped, mut key_rising) = (false, false);
    for ev in &solution.events {
        let source = ev.source.map(|s| (s.element, s.local));
        if source.is_some()
            && source == jack_limit.map(|e| (e, 0))
            && let Some(j) = jack
            && ev.state[j] < params.jack.stop_angle_rad
            && escaped
            && key_rising
        {
            events.push(PianoEvent {
                name: "jack_reset",
                time_s: ev.time,
            });
            (escaped, key_rising) = (false, false);
        }
        for (contact, on, off) in EVENT_NAMES {
            if source.is_some() && source == action.contacts.get(contact).map(|&e| (e, 0)) {
                // A contact's switching function is its gap: falling through zero, the
                // shapes touch.
                let onset = ev.direction == mbs_integrators::Crossing::Falling;
                let (on, off) = match input {
                    Input::MassDrop { .. } if contact == "presser_key" => ("mass_key", "mass_lift"),
                    _ => (on, off),
                };
                let name = if onset { on } else { off };
                events.push(PianoEvent {
                    name,
                    time_s: ev.time,
                });
                match name {
                    "let_off" => (escaped, key_rising) = (true, false),
                    "key_lift" => key_rising = escaped,
                    _ => {}
                }
                if contact == "hammer_string" {
                    let same_blow = strikes.last_mut().filter(|s| {
                        s.contact_duration_s
                            .is_some_and(|d| ev.time - (s.time_s + d) < BLOW_PULSE_GAP_S)
                    });
                    if onset {
                        if let Some(s) = same_blow {
                            s.pulses += 1;
                            s.contact_duration_s = None;
                        } else {
                            strikes.push(Strike {
                                time_s: ev.time,
                                hammer_velocity_m_s: ev.state[nv + hammer].abs() * strike_radius,
                                contact_duration_s: None,
                                rebound_velocity_m_s: None,
                                pulses: 1,
                            });
                        }
                    } else if let Some(s) = strikes.last_mut()
                        && s.contact_duration_s.is_none()
                    {
                        s.contact_duration_s = Some(ev.time - s.time_s);
                        // The hammer turns away from the string: a negative rate.
                        s.rebound_velocity_m_s = Some(-ev.state[nv + hammer] * strike_radius);
                    }
                }
            }
        }
    }
    events.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    let first = |name: &str| events.iter().find(|e| e.name == name).map(|e| e.time_s);
    let first_strike = strikes.first().map(|s| s.time_s);
    let check_time_s = events
        .iter()
        .find(|e| e.name == "check_catch" && first_strike.is_some_and(|t| e.time_s > t))
        .map(|e| e.time_s);
    let travel_time_s = match (key_start_time_s, strikes.first()) {
        (Some(t0), Some(s)) => Some(s.time_s - t0),
        _ => None,
    };
    Ok(Run {
        kind,
        key_start_time_s,
        travel_time_s,
        let_off_time_s: first("let_off"),
        key_bottom_time_s: first("key_bottom"),
        check_time_s,
        solution,
        events,
        strikes,
        key_drive_force_n,
    })
}
