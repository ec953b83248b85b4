//! The pendulum (swing) test: the hammer alone on its flange, released from an angle and
//! left to swing under gravity and flange friction. Its period follows from the hammer's
//! inertia and centre of mass; its decay from the flange friction.

use mbs_core::elements::{FrictionLaw, PivotFriction};
use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement, System};
use mbs_integrators::{EventAction, Method, MultibodyOde, Options, solve_with_events};

use crate::error::{PianoError, Result};
use crate::params::ActionParams;

/// A turning point of the swing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Turn {
    /// Time (s).
    pub time_s: f64,
    /// Angle from the hanging position (rad), signed.
    pub angle_rad: f64,
}

/// The swing test's result.
#[derive(Clone, Debug, PartialEq)]
pub struct Swing {
    /// Turning points in time order (the release is not one).
    pub turns: Vec<Turn>,
    /// Distance from the flange pin to the centre of mass (m).
    pub com_distance_m: f64,
    /// Inertia about the flange pin (kg·m²).
    pub inertia_pin_kg_m2: f64,
    /// Shank angle in the world when the hammer hangs at rest (rad): the angle from
    /// hanging adds to it.
    pub hanging_shank_angle_rad: f64,
    /// Output times on a uniform grid from the release (s).
    pub t: Vec<f64>,
    /// Angle from hanging at each output time (rad).
    pub angle_rad: Vec<f64>,
    /// Angular velocity at each output time (rad/s).
    pub rate_rad_s: Vec<f64>,
}

/// The shank's angle in the world when the hammer hangs at rest on its flange (rad): the
/// centre of mass straight below the pin, i.e. the shank at −90° minus the centre of mass's
/// angle above the shank.
pub fn hanging_shank_angle_rad(params: &ActionParams) -> f64 {
    let com = params.hammer.com_body_mm;
    -std::f64::consts::FRAC_PI_2 - com[1].atan2(com[0])
}

/// Checks a release angle: 0.5° to 170° either side of hanging [D: below 0.5° the swing is
/// lost in the flange friction's dead band; past 170° the hammer would start upside down].
pub fn check_release_angle(release_angle_deg: f64) -> Result<()> {
    if release_angle_deg.is_finite() && (0.5..=170.0).contains(&release_angle_deg.abs()) {
        Ok(())
    } else {
        Err(PianoError::scenario(
            "input.release_angle_deg",
            format!("must be 0.5° to 170° either side of hanging, got {release_angle_deg}"),
        ))
    }
}

/// Releases the hammer at `release_angle_deg` from its hanging position and lets it swing
/// for `duration_s`; the turning points are located as events, the swing is sampled every
/// millisecond (see [`swing_sampled`]).
pub fn swing(params: &ActionParams, release_angle_deg: f64, duration_s: f64) -> Result<Swing> {
    swing_sampled(params, release_angle_deg, duration_s, 1e-3)
}

/// [`swing`], sampled every `output_step_s`.
pub fn swing_sampled(
    params: &ActionParams,
    release_angle_deg: f64,
    duration_s: f64,
    output_step_s: f64,
) -> Result<Swing> {
    check_release_angle(release_angle_deg)?;
    crate::simulate::check_duration(duration_s, output_step_s)?;
    let h = &params.hammer;
    let com = [h.com_body_mm[0] * 1e-3, h.com_body_mm[1] * 1e-3];
    let d = (com[0] * com[0] + com[1] * com[1]).sqrt();
    let mass = h.mass_g * 1e-3;
    let hanging = hanging_shank_angle_rad(params);
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -crate::params::GRAVITY_M_S2]).add_link(
        "hammer",
        None,
        JointKind::Revolute,
        Placement::new(hanging, 0.0, 0.0),
        BodySpec::new(mass, com, h.inertia_com_kg_m2),
    );
    let model = b.build()?;
    let mut system = System::new(model.clone());
    let friction = FrictionLaw::coulomb(
        h.pivot_friction_n_m,
        params.numerics.pivot_friction_regularization_rad_s,
    );
    system.add_element(PivotFriction::new(&model, "hammer", friction)?.with_reversal_events())?;
    if !params.effects.is_empty() {
        let laws = crate::identify::effects::FlangeEffects::from_entries(&params.effects)?;
        system.add_element(crate::identify::effects::FlangeEffectElement::new(
            &model,
            "hammer",
            laws,
            params.numerics.pivot_friction_regularization_rad_s,
            mass,
            com,
            hanging,
        )?)?;
    }
    let x0 = system.initial_state(0.0, &[release_angle_deg.to_radians()], &[0.0])?;
    let opts = Options {
        output_step: Some(output_step_s),
        ..Options::with_tolerances(1e-9, 1e-12)
    };
    // The release itself is at rest: start just after it so it is not counted as a turn.
    let sol = solve_with_events(
        &mut MultibodyOde::new(&system),
        Method::DormandPrince54,
        0.0,
        &x0,
        duration_s,
        &opts,
        &mut |_, _| EventAction::Record,
    )
    .map_err(PianoError::from)?;
    let turns = sol
        .events
        .iter()
        .filter(|e| e.time > 1e-6)
        .map(|e| Turn {
            time_s: e.time,
            angle_rad: e.state[0],
        })
        .collect();
    Ok(Swing {
        turns,
        com_distance_m: d,
        inertia_pin_kg_m2: h.inertia_com_kg_m2 + mass * d * d,
        hanging_shank_angle_rad: hanging,
        angle_rad: (0..sol.len()).map(|i| sol.state(i)[0]).collect(),
        rate_rad_s: (0..sol.len()).map(|i| sol.state(i)[1]).collect(),
        t: sol.t,
    })
}
