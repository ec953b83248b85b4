//! The library of named effects the pendulum (swing) test can reveal at the hammer flange,
//! and how each adds itself to a model.
//!
//! All are torques about the flange centre pin, ω the hammer's angular velocity
//! (`identification.md` §3.5, issue 13's table):
//!
//! | id | torque | parameters |
//! |---|---|---|
//! | `pivot_viscous` | −c ω | `c_n_m_s` |
//! | `air_drag` | −c_d ω\|ω\| | `cd_n_m_s2` |
//! | `pivot_stribeck` | extra static friction d_s e^{−(ω/ω_s)²}, opposing motion | `ds_n_m`, `ws_rad_s` |
//! | `pivot_load_friction` | μ_r \|F_pin\| opposing motion | `mu_r_m` |
//!
//! `F_pin` is the pin's reaction from the rigid-body dynamics of the hammer on its pin.

use std::collections::BTreeMap;

use mbs_identify::{EffectParam, EffectSpec};
use serde::{Deserialize, Serialize};

use crate::error::{PianoError, Result};

/// Where the pendulum effects act: the hammer's flange (its centre pin).
pub const HAMMER_FLANGE: &str = "hammer_flange";

/// Viscous pin friction. Range [D]: up to c/I = 3 s⁻¹ with I = 1.54e-4 kg·m², ten times
/// what would halve a swing's amplitude in 3 s.
pub const PIVOT_VISCOUS: EffectSpec = EffectSpec {
    id: "pivot_viscous",
    summary: "viscous pin friction, torque −c ω",
    params: &[EffectParam {
        name: "c_n_m_s",
        unit: "N·m·s",
        null: Some(0.0),
        range: [0.0, 5e-4],
        typical: 4e-5,
        log_scale: false,
        screen: &[],
    }],
    confusable_with: &["air_drag"],
    discriminating_experiment: "releases from two or more amplitudes: viscous decay is the same \
        fraction per swing at every amplitude, drag decays large swings faster",
};

/// Aerodynamic drag on the swinging hammer. Range [D]: the head (≈ 2.5e-4 m² at 0.13 m,
/// C_D ≈ 1.2) gives c_d ≈ ½ ρ C_D A r³ ≈ 4e-7 N·m·s²; the range allows 50 times that.
pub const AIR_DRAG: EffectSpec = EffectSpec {
    id: "air_drag",
    summary: "air drag on the hammer, torque −c_d ω|ω|",
    params: &[EffectParam {
        name: "cd_n_m_s2",
        unit: "N·m·s²",
        null: Some(0.0),
        range: [0.0, 2e-5],
        typical: 3e-6,
        log_scale: false,
        screen: &[],
    }],
    confusable_with: &["pivot_viscous", "pivot_load_friction"],
    discriminating_experiment: "releases from two or more amplitudes: drag grows with the \
        square of the speed, viscous friction linearly, load friction with the centripetal load",
};

/// Stribeck (static) friction peak. Ranges [D]: up to twice Hirschkorn's 1.0 mN·m Coulomb
/// level; velocity scales 0.02–5 rad/s (`identification.md` §3.5).
pub const PIVOT_STRIBECK: EffectSpec = EffectSpec {
    id: "pivot_stribeck",
    summary: "Stribeck peak of the pin friction, extra d_s e^{−(ω/ω_s)²} opposing motion",
    params: &[
        EffectParam {
            name: "ds_n_m",
            unit: "N·m",
            null: Some(0.0),
            range: [0.0, 2e-3],
            typical: 5e-4,
            log_scale: false,
            screen: &[],
        },
        EffectParam {
            name: "ws_rad_s",
            unit: "rad/s",
            null: None,
            range: [0.02, 5.0],
            typical: 0.5,
            log_scale: true,
            screen: &[],
        },
    ],
    confusable_with: &["pivot_load_friction"],
    discriminating_experiment: "a low-amplitude release (a few degrees): the Stribeck peak \
        acts at every reversal and decides where the hammer sticks",
};

/// Pin friction growing with the pin's load. Range [D]: μ ≈ 0.1–0.5 on a pin of radius
/// 0.6–0.7 mm gives μ r ≈ 1e-4 m; the range allows 50 times that.
pub const PIVOT_LOAD_FRICTION: EffectSpec = EffectSpec {
    id: "pivot_load_friction",
    summary: "load-dependent pin friction, μ_r |F_pin| opposing motion",
    params: &[EffectParam {
        name: "mu_r_m",
        unit: "m",
        null: Some(0.0),
        range: [0.0, 5e-3],
        typical: 2.5e-3,
        log_scale: false,
        screen: &[],
    }],
    confusable_with: &["air_drag"],
    discriminating_experiment: "releases from two or more amplitudes, or with a weight added \
        to the hammer: load friction follows the pin's load, drag the speed alone",
};

/// The pendulum family, in the order the diagnosis tries them.
pub const PENDULUM_EFFECTS: [EffectSpec; 4] =
    [PIVOT_VISCOUS, AIR_DRAG, PIVOT_STRIBECK, PIVOT_LOAD_FRICTION];

/// The spec of effect `id` in the library.
pub fn effect_spec(id: &str) -> Option<&'static EffectSpec> {
    PENDULUM_EFFECTS.iter().find(|e| e.id == id)
}

/// The ids of the library, for messages.
pub fn library_ids() -> String {
    PENDULUM_EFFECTS.map(|e| e.id).join(", ")
}

/// An effect added to the model: an entry of the parameter file's `[[effects]]` list.
///
/// ```toml
/// [[effects]]
/// id = "pivot_viscous"
/// location = "hammer_flange"
/// c_n_m_s = 4.1e-5
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct EffectEntry {
    /// The effect's id in the library.
    pub id: String,
    /// Where it acts (`hammer_flange`).
    pub location: String,
    /// Its parameters by name.
    #[serde(flatten)]
    pub params: BTreeMap<String, f64>,
}

impl EffectEntry {
    /// Checks the entry against the library: a known id at a known location, exactly its
    /// parameters, each finite and within the effect's plausible range. `field` names the
    /// entry in messages (`effects[0]`).
    pub fn validate(&self, field: &str) -> Result<()> {
        let spec = effect_spec(&self.id).ok_or_else(|| {
            PianoError::params(
                format!("{field}.id"),
                format!(
                    "no effect '{}' in the library (known: {})",
                    self.id,
                    library_ids()
                ),
            )
        })?;
        if self.location != HAMMER_FLANGE {
            return Err(PianoError::params(
                format!("{field}.location"),
                format!(
                    "'{}': the pendulum effects act at '{HAMMER_FLANGE}'",
                    self.location
                ),
            ));
        }
        for name in self.params.keys() {
            if spec.param(name).is_none() {
                return Err(PianoError::params(
                    format!("{field}.{name}"),
                    format!(
                        "'{}' has no parameter '{name}' (its parameters: {})",
                        spec.id,
                        spec.params
                            .iter()
                            .map(|p| p.name)
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                ));
            }
        }
        for p in spec.params {
            let v = *self.params.get(p.name).ok_or_else(|| {
                PianoError::params(format!("{field}.{}", p.name), "missing".to_string())
            })?;
            if !(v.is_finite() && (p.range[0]..=p.range[1]).contains(&v)) {
                return Err(PianoError::params(
                    format!("{field}.{}", p.name),
                    format!(
                        "{v} {} is outside the plausible range [{}, {}]",
                        p.unit, p.range[0], p.range[1]
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The flange's extra laws, summed from a list of effects (absent effects are zero).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FlangeEffects {
    /// Viscous coefficient c (N·m·s).
    pub viscous_n_m_s: f64,
    /// Drag coefficient c_d (N·m·s²).
    pub drag_n_m_s2: f64,
    /// Stribeck peak d_s (N·m).
    pub stribeck_n_m: f64,
    /// Stribeck velocity ω_s (rad/s).
    pub stribeck_rad_s: f64,
    /// Load friction μ_r (m).
    pub load_friction_m: f64,
}

impl FlangeEffects {
    /// The laws of `effects` (validated entries; an unknown id is an error).
    pub fn from_entries(effects: &[EffectEntry]) -> Result<Self> {
        let mut f = FlangeEffects {
            stribeck_rad_s: 1.0,
            ..Self::default()
        };
        for e in effects {
            let p = |name: &str| e.params.get(name).copied().unwrap_or(0.0);
            match e.id.as_str() {
                "pivot_viscous" => f.viscous_n_m_s += p("c_n_m_s"),
                "air_drag" => f.drag_n_m_s2 += p("cd_n_m_s2"),
                "pivot_stribeck" => {
                    f.stribeck_n_m = p("ds_n_m");
                    f.stribeck_rad_s = p("ws_rad_s");
                }
                "pivot_load_friction" => f.load_friction_m += p("mu_r_m"),
                other => {
                    return Err(PianoError::params(
                        "effects",
                        format!(
                            "no effect '{other}' in the library (known: {})",
                            library_ids()
                        ),
                    ));
                }
            }
        }
        Ok(f)
    }

    /// The torque of the rate-dependent laws (viscous and drag) at `omega` (N·m).
    pub fn damping_torque(&self, omega: f64) -> f64 {
        -self.viscous_n_m_s * omega - self.drag_n_m_s2 * omega * omega.abs()
    }

    /// The extra friction level (N·m, ≥ 0, to be applied against the motion) at `omega`
    /// with the pin's load `pin_force_n`.
    pub fn friction_level(&self, omega: f64, pin_force_n: f64) -> f64 {
        let stribeck = if self.stribeck_n_m > 0.0 {
            mbs_core::elements::stribeck_level(0.0, self.stribeck_n_m, self.stribeck_rad_s, omega)
        } else {
            0.0
        };
        stribeck + self.load_friction_m * pin_force_n
    }

    /// Whether any load friction is present (its torque needs the pin's reaction).
    pub fn needs_pin_force(&self) -> bool {
        self.load_friction_m > 0.0
    }
}

/// The flange effects as a force element on a revolute joint whose body hangs on a fixed
/// pin (the hammer on its flange).
///
/// Friction-type effects (Stribeck peak, load friction) act against the motion through the
/// same `tanh(ω / v_ε)` as the model's pivot friction. The load friction's pin reaction is
/// the body's own, `m |ω² r + g|` for a centre of mass at `r` from the pin: gravity and
/// the centripetal load; the tangential term and forces from contacts on the body are left
/// out, so in the full action it is a lower bound (the pendulum diagnosis uses the whole
/// reaction, [`super::swing_model`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FlangeEffectElement {
    name: String,
    coordinate: usize,
    laws: FlangeEffects,
    regularization_rad_s: f64,
    mass_kg: f64,
    com_m: [f64; 2],
    angle_offset_rad: f64,
}

impl FlangeEffectElement {
    /// The effects `laws` on joint `joint` of `model`; the body's world angle is
    /// `angle_offset_rad` plus the joint coordinate, its centre of mass at `com_m` (body
    /// frame, from the pin) and its mass `mass_kg`.
    pub fn new(
        model: &mbs_core::Model,
        joint: &str,
        laws: FlangeEffects,
        regularization_rad_s: f64,
        mass_kg: f64,
        com_m: [f64; 2],
        angle_offset_rad: f64,
    ) -> Result<Self> {
        Ok(Self {
            name: format!("flange effects '{joint}'"),
            coordinate: model.coordinate_id(joint)?,
            laws,
            regularization_rad_s,
            mass_kg,
            com_m,
            angle_offset_rad,
        })
    }

    /// The torque at angle `q` and rate `omega` of the joint (N·m).
    pub fn torque(&self, q: f64, omega: f64) -> f64 {
        let pin = if self.laws.needs_pin_force() {
            let (s, c) = (self.angle_offset_rad + q).sin_cos();
            let r = [
                c * self.com_m[0] - s * self.com_m[1],
                s * self.com_m[0] + c * self.com_m[1],
            ];
            let w2 = omega * omega;
            self.mass_kg * (w2 * r[0]).hypot(super::swing_model::GRAVITY_M_S2 - w2 * r[1])
        } else {
            0.0
        };
        self.laws.damping_torque(omega)
            - (omega / self.regularization_rad_s).tanh() * self.laws.friction_level(omega, pin)
    }
}

impl mbs_core::ForceElement for FlangeEffectElement {
    fn name(&self) -> &str {
        &self.name
    }

    fn apply(
        &self,
        ctx: &mbs_core::ForceContext<'_>,
        loads: &mut mbs_core::Loads<'_>,
        _rates: &mut [f64],
    ) {
        let k = self.coordinate;
        loads.add_generalized(k, self.torque(ctx.q[k], ctx.v[k]));
    }
}
