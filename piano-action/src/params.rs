//! The action's parameters: one documented TOML file, embedded as the default.
//!
//! Every field is named after what it is and carries its unit; see
//! `src/default_params.toml` for the values, their tags and sources.

use serde::{Deserialize, Serialize};

use crate::error::{InputKind, PianoError, Result};

/// The default parameter file (the reference grand action), as text.
pub const DEFAULT_PARAMS_TOML: &str = include_str!("default_params.toml");

/// The key: a lever on the balance rail.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyParams {
    /// Balance pivot (mm).
    pub pivot_mm: [f64; 2],
    /// Key front top, where the finger presses (mm).
    pub finger_mm: [f64; 2],
    /// Mass (g).
    pub mass_g: f64,
    /// Centre of mass (mm).
    pub com_mm: [f64; 2],
    /// Rotational inertia about the balance pivot (kg·m²).
    pub inertia_pivot_kg_m2: f64,
    /// Capstan head centre (mm).
    pub capstan_center_mm: [f64; 2],
    /// Capstan head radius (mm).
    pub capstan_radius_mm: f64,
    /// Rounded key underside over the front-rail punching: centre (mm).
    pub front_pad_mm: [f64; 2],
    /// Its radius (mm).
    pub front_pad_radius_mm: f64,
    /// Rounded key underside over the back-rail cloth: centre (mm).
    pub back_pad_mm: [f64; 2],
    /// Its radius (mm).
    pub back_pad_radius_mm: f64,
    /// Backcheck catch point (mm).
    pub backcheck_mm: [f64; 2],
    /// Backcheck face angle to the key (deg).
    pub backcheck_face_angle_deg: f64,
    /// Half length of the backcheck face (mm).
    pub backcheck_half_length_mm: f64,
    /// Coulomb friction of the key bushings about the balance pin (N·m).
    pub pivot_friction_n_m: f64,
}

/// The wippen, pinned at the rear on its flange.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WippenParams {
    /// Flange centre pin (mm).
    pub pivot_mm: [f64; 2],
    /// Mass (g).
    pub mass_g: f64,
    /// Centre of mass (mm).
    pub com_mm: [f64; 2],
    /// Rotational inertia about the centre of mass (kg·m²).
    pub inertia_com_kg_m2: f64,
    /// Heel contact point on the capstan (mm).
    pub heel_mm: [f64; 2],
    /// Half length of the flat heel (mm).
    pub heel_half_length_mm: f64,
    /// Coulomb friction at the flange (N·m).
    pub pivot_friction_n_m: f64,
}

/// The jack, pinned on the wippen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JackParams {
    /// Centre pin on the wippen (mm).
    pub pivot_mm: [f64; 2],
    /// Mass (g).
    pub mass_g: f64,
    /// Centre of mass (mm).
    pub com_mm: [f64; 2],
    /// Rotational inertia about its pin (kg·m²).
    pub inertia_pivot_kg_m2: f64,
    /// Top contact with the knuckle at rest (mm).
    pub top_mm: [f64; 2],
    /// Jack axis (unit vector, pin toward top).
    pub axis: [f64; 2],
    /// Length of the top behind the contact, toward the strings (mm): sets the escape.
    pub top_back_edge_mm: f64,
    /// Length of the top in front of the contact (mm).
    pub top_front_edge_mm: f64,
    /// Toe contact with the let-off button (mm).
    pub toe_mm: [f64; 2],
    /// Toe rounding radius (mm).
    pub toe_radius_mm: f64,
    /// Jack spring torque at rest (N·m), turning the jack back under the knuckle.
    pub spring_preload_n_m: f64,
    /// Jack spring stiffness (N·m/rad).
    pub spring_stiffness_n_m_per_rad: f64,
    /// Jack stop: the jack cannot turn back past this angle from rest (rad).
    pub stop_angle_rad: f64,
    /// How far the jack can turn out from under the knuckle (rad from rest) before its back
    /// meets the repetition lever's window or the wippen (absent in older files: 0.3).
    #[serde(default = "default_jack_outer_stop")]
    pub outer_stop_rad: f64,
    /// Coulomb friction at the jack centre (N·m).
    pub pivot_friction_n_m: f64,
}

/// The repetition lever, pinned on the wippen.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RepetitionLeverParams {
    /// Centre pin on the wippen (mm).
    pub pivot_mm: [f64; 2],
    /// Mass (g).
    pub mass_g: f64,
    /// Centre of mass (mm).
    pub com_mm: [f64; 2],
    /// Rotational inertia about its pin (kg·m²).
    pub inertia_pivot_kg_m2: f64,
    /// A point of its top surface under the knuckle (mm); the surface is parallel to the
    /// jack top.
    pub top_mm: [f64; 2],
    /// Length of the top behind that point (mm).
    pub top_back_edge_mm: f64,
    /// Length of the top in front of that point (mm).
    pub top_front_edge_mm: f64,
    /// Front tip under the drop screw (mm).
    pub tip_mm: [f64; 2],
    /// Tip rounding radius (mm).
    pub tip_radius_mm: f64,
    /// Repetition spring torque at rest (N·m), lifting the lever.
    pub spring_preload_n_m: f64,
    /// Repetition spring stiffness (N·m/rad).
    pub spring_stiffness_n_m_per_rad: f64,
    /// Upper stop angle from rest (rad, negative: lever up).
    pub upper_stop_rad: f64,
    /// Coulomb friction at the lever centre (N·m).
    pub pivot_friction_n_m: f64,
}

/// The hammer on its flange. Body points (`*_body_mm`) are in the shank frame: origin at
/// the centre pin, x along the shank toward the head.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HammerParams {
    /// Flange centre pin (mm).
    pub pivot_mm: [f64; 2],
    /// Shank angle at rest (deg).
    pub rest_angle_deg: f64,
    /// Mass of hammer and shank (g).
    pub mass_g: f64,
    /// Centre of mass (body, mm).
    pub com_body_mm: [f64; 2],
    /// Rotational inertia about the centre of mass (kg·m²).
    pub inertia_com_kg_m2: f64,
    /// Knuckle centre (body, mm).
    pub knuckle_body_mm: [f64; 2],
    /// Knuckle radius (mm).
    pub knuckle_radius_mm: f64,
    /// Strike point on the crown (body, mm).
    pub strike_body_mm: [f64; 2],
    /// Crown radius of curvature (mm).
    pub crown_radius_mm: f64,
    /// Tail catch point (body, mm).
    pub tail_body_mm: [f64; 2],
    /// Tail rounding radius (mm).
    pub tail_radius_mm: f64,
    /// Shank underside over the rest rail (body, mm).
    pub rest_body_mm: [f64; 2],
    /// Coulomb friction at the flange (N·m).
    pub pivot_friction_n_m: f64,
}

/// Positions of the regulating screws, rails and the string.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RegulationParams {
    /// Let-off button lower face height (mm).
    pub let_off_button_y_mm: f64,
    /// Its extent along x (mm).
    pub let_off_button_x_mm: [f64; 2],
    /// Drop screw tip height (mm).
    pub drop_screw_y_mm: f64,
    /// Its extent along x (mm).
    pub drop_screw_x_mm: [f64; 2],
    /// String height (mm).
    pub string_y_mm: f64,
    /// Its extent along x (mm).
    pub string_x_mm: [f64; 2],
    /// Rest-rail cushion top (mm).
    pub rest_rail_top_y_mm: f64,
    /// Its extent along x (mm).
    pub rest_rail_x_mm: [f64; 2],
    /// Front-rail punching top (mm).
    pub front_rail_top_y_mm: f64,
    /// Its extent along x (mm).
    pub front_rail_x_mm: [f64; 2],
    /// Back-rail cloth top (mm).
    pub back_rail_top_y_mm: f64,
    /// Its extent along x (mm).
    pub back_rail_x_mm: [f64; 2],
    /// Capstan turned up (+) or down from the layout (mm).
    pub capstan_raise_mm: f64,
    /// Backcheck moved along its face normal, toward (+) or away from the hammer tail (mm).
    pub backcheck_offset_mm: f64,
}

/// A felt, cloth or leather contact: rate-independent hysteresis
/// `F = k δ^p (1 + a tanh(δ̇ / v_s))`, `a = (1 − e²)/(1 + e²)`, so every impact keeps the
/// restitution `e` (`mbs_contact::laws::HystereticFelt::from_restitution`), and
/// regularised Coulomb friction `μ`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactParams {
    /// Stiffness (N/m^p).
    pub k: f64,
    /// Exponent.
    pub p: f64,
    /// Restitution at the reference speed.
    pub e: f64,
    /// Friction coefficient (0 for none).
    pub mu: f64,
}

/// All contact laws of the action.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactsParams {
    /// Key on the front-rail punching.
    pub front_rail: ContactParams,
    /// Key tail on the back-rail cloth.
    pub back_rail: ContactParams,
    /// Capstan on the wippen heel.
    pub capstan_heel: ContactParams,
    /// Jack top on the knuckle.
    pub jack_knuckle: ContactParams,
    /// Repetition lever on the knuckle.
    pub lever_knuckle: ContactParams,
    /// Jack toe on the let-off button.
    pub let_off_button: ContactParams,
    /// Repetition lever tip on the drop screw.
    pub drop_screw: ContactParams,
    /// Hammer tail on the backcheck.
    pub backcheck: ContactParams,
    /// Shank on the rest-rail cushion.
    pub rest_rail: ContactParams,
    /// Hammer felt on the string (the string's motion, section `[string]`, gives the
    /// losses and the rebound: no restitution here).
    pub hammer_string: StringFeltParams,
}

/// The hammer felt against the string: C&A's power law `F = k δ^p`, undamped (the string
/// takes the energy the hammer loses).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StringFeltParams {
    /// Stiffness of the whole hammer's felt on the unison (N/m^p).
    pub k: f64,
    /// Exponent.
    pub p: f64,
    /// Friction coefficient along the string: must be 0 (not modelled).
    pub mu: f64,
    /// Restitution: no longer a parameter (read only to refuse it with a clear message;
    /// files written before the string was modelled have it).
    #[serde(default, skip_serializing)]
    pub e: Option<f64>,
}

/// The string the hammer strikes: one note's unison, modal (`mbs_contact::TautString`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StringParams {
    /// Speaking length, agraffe to bridge (m).
    pub length_m: f64,
    /// Fundamental of the ideal string (Hz).
    pub fundamental_hz: f64,
    /// Mass of one string's speaking length (g).
    pub mass_per_string_g: f64,
    /// Tension of one string (N); must agree with `4 L f1^2 Ms` within 1 %.
    pub tension_per_string_n: f64,
    /// Inharmonicity B.
    pub inharmonicity: f64,
    /// Striking ratio x0 / L.
    pub striking_ratio: f64,
    /// Strings in the unison.
    pub strings: usize,
    /// Frequency-independent loss b1 (1/s); sound only.
    pub loss_b1_per_s: f64,
    /// Frequency-dependent loss b3 (s); sound only.
    pub loss_b3_s: f64,
    /// Number of modes.
    pub modes: usize,
    /// Whether the cut modes' static compliance is kept as a spring in series with the
    /// felt.
    pub residual_compliance: bool,
}

impl StringParams {
    /// The string's data in `mbs_contact` form.
    pub fn spec(&self) -> mbs_contact::StringSpec {
        mbs_contact::StringSpec {
            length_m: self.length_m,
            fundamental_hz: self.fundamental_hz,
            mass_kg: Some(self.mass_per_string_g * 1e-3),
            tension_n: Some(self.tension_per_string_n),
            inharmonicity: self.inharmonicity,
            striking_ratio: self.striking_ratio,
            strings: self.strings,
            loss_b1: self.loss_b1_per_s,
            loss_b3: self.loss_b3_s,
            modes: Some(self.modes),
            residual_compliance: self.residual_compliance,
        }
    }

    /// The string's modes; an error names the field (`string.tension_per_string_n`).
    pub fn build(&self) -> Result<mbs_contact::TautString> {
        mbs_contact::TautString::new(&self.spec()).map_err(|e| match e {
            mbs_contact::ContactError::InvalidParameter { item, message } => {
                let field = match item.trim_start_matches("string.") {
                    "mass_kg" => "mass_per_string_g",
                    "tension_n" => "tension_per_string_n",
                    "loss_b1" => "loss_b1_per_s",
                    "loss_b3" => "loss_b3_s",
                    other => other,
                };
                PianoError::params(format!("string.{field}"), message)
            }
            other => PianoError::params("string", other.to_string()),
        })
    }
}

impl ContactsParams {
    /// The contacts by their field names.
    pub fn named(&self) -> [(&'static str, &ContactParams); 9] {
        [
            ("front_rail", &self.front_rail),
            ("back_rail", &self.back_rail),
            ("capstan_heel", &self.capstan_heel),
            ("jack_knuckle", &self.jack_knuckle),
            ("lever_knuckle", &self.lever_knuckle),
            ("let_off_button", &self.let_off_button),
            ("drop_screw", &self.drop_screw),
            ("backcheck", &self.backcheck),
            ("rest_rail", &self.rest_rail),
        ]
    }

    /// The contact of field name `name` (`backcheck`), to change; `None` for another name
    /// (the hammer–string felt has a law of its own).
    pub fn named_mut(&mut self, name: &str) -> Option<&mut ContactParams> {
        Some(match name {
            "front_rail" => &mut self.front_rail,
            "back_rail" => &mut self.back_rail,
            "capstan_heel" => &mut self.capstan_heel,
            "jack_knuckle" => &mut self.jack_knuckle,
            "lever_knuckle" => &mut self.lever_knuckle,
            "let_off_button" => &mut self.let_off_button,
            "drop_screw" => &mut self.drop_screw,
            "backcheck" => &mut self.backcheck,
            "rest_rail" => &mut self.rest_rail,
            _ => return None,
        })
    }

    /// Checks every contact law: stiffness positive, exponent 1 to 5, restitution in
    /// (0, 1], friction 0 to 2, naming the contact and the field (`contacts.backcheck.e`);
    /// the hammer–string felt has no restitution and no friction.
    pub fn check(&self) -> Result<()> {
        let h = &self.hammer_string;
        let field = |f: &str| format!("contacts.hammer_string.{f}");
        if h.e.is_some() {
            return Err(PianoError::params(
                field("e"),
                "the hammer-string contact has no restitution any more: the string's motion \
                 gives the rebound (section [string]); remove this line",
            ));
        }
        if !(h.k.is_finite() && h.k > 0.0) {
            return Err(PianoError::params(
                field("k"),
                format!("the hammer felt's stiffness must be positive, got {}", h.k),
            ));
        }
        if !(1.0..=5.0).contains(&h.p) {
            return Err(PianoError::params(
                field("p"),
                format!("the hammer felt's exponent must be 1 to 5, got {}", h.p),
            ));
        }
        if h.mu != 0.0 {
            return Err(PianoError::params(
                field("mu"),
                format!(
                    "friction along the string is not modelled: must be 0, got {}",
                    h.mu
                ),
            ));
        }
        for (name, c) in self.named() {
            let field = |f: &str| format!("contacts.{name}.{f}");
            if !(c.k.is_finite() && c.k > 0.0) {
                return Err(PianoError::params(
                    field("k"),
                    format!(
                        "the {name} contact's stiffness must be positive, got {}",
                        c.k
                    ),
                ));
            }
            // Felt and cloth laws have exponents 1.5-4 (Stulov; Hirschkorn et al. 2006);
            // outside 1-5 is a typing error [D].
            if !(1.0..=5.0).contains(&c.p) {
                return Err(PianoError::params(
                    field("p"),
                    format!("the {name} contact's exponent must be 1 to 5, got {}", c.p),
                ));
            }
            if !(c.e > 0.0 && c.e <= 1.0) {
                return Err(PianoError::params(
                    field("e"),
                    format!(
                        "the {name} contact's restitution must be in (0, 1] (1: no loss), got {}",
                        c.e
                    ),
                ));
            }
            if !(0.0..=2.0).contains(&c.mu) {
                return Err(PianoError::params(
                    field("mu"),
                    format!(
                        "the {name} contact's friction coefficient must be 0 to 2, got {}",
                        c.mu
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// Numerical settings of the model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NumericsParams {
    /// Velocity scale over which a felt contact passes from its unloading to its loading
    /// branch (m/s): a smoothing of the rate-independent hysteresis, not a material constant.
    pub felt_smoothing_m_s: f64,
    /// Velocity scale of contact friction (m/s).
    pub friction_regularization_m_s: f64,
    /// Angular velocity scale of pivot friction (rad/s).
    pub pivot_friction_regularization_rad_s: f64,
    /// Stiffness of the jack and repetition-lever stops (N·m/rad).
    pub stop_stiffness_n_m_per_rad: f64,
    /// Damping of those stops (N·m·s/rad).
    pub stop_damping_n_m_s_per_rad: f64,
    /// Relative error tolerance of the integrator (per step).
    pub relative_tolerance: f64,
    /// Absolute error tolerance of the integrator (rad, m, rad/s, m/s).
    pub absolute_tolerance: f64,
    /// Points per step at which the contacts' gaps are checked for onsets and releases
    /// (at least 1).
    pub event_samples: usize,
}

/// Gravity (m/s², downward) for every model the crate builds: standard gravity 9.80665
/// m/s² [V] (CGPM 1901) rounded to 9.81 as the project's results have always used [D]. The
/// one place it is written; code that holds a model reads `Model::gravity` instead.
pub const GRAVITY_M_S2: f64 = 9.81;

/// The whole parameter set.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActionParams {
    /// The key.
    pub key: KeyParams,
    /// The wippen.
    pub wippen: WippenParams,
    /// The jack.
    pub jack: JackParams,
    /// The repetition lever.
    pub repetition_lever: RepetitionLeverParams,
    /// The hammer.
    pub hammer: HammerParams,
    /// Screws, rails and string.
    pub regulation: RegulationParams,
    /// Contact laws.
    pub contacts: ContactsParams,
    /// The string the hammer strikes.
    pub string: StringParams,
    /// Numerical settings.
    pub numerics: NumericsParams,
    /// Effects added to the model, usually by `piano diagnose --write-params` (none in the
    /// reference file): `[[effects]]` tables with `id`, `location` and the effect's
    /// parameters (see [`crate::identify::effects`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<crate::identify::effects::EffectEntry>,
}

impl ActionParams {
    /// The reference grand action (the embedded default file).
    pub fn reference() -> Self {
        // The embedded file is tested to parse; a failure here is a build defect.
        Self::from_toml_str(DEFAULT_PARAMS_TOML)
            .unwrap_or_else(|e| unreachable!("the embedded parameter file is invalid: {e}"))
    }

    /// Parses a parameter file; an error names the field (as a path such as
    /// `hammer.mass_g`) and where it is.
    pub fn from_toml_str(text: &str) -> Result<Self> {
        let params: ActionParams = crate::toml_lines::from_toml(text, InputKind::Parameters)?;
        params.validate().map_err(|e| e.locate_in_toml(text))?;
        Ok(params)
    }

    /// Reads and parses the parameter file at `path`; errors name the file, the line and
    /// the field.
    pub fn load(path: &std::path::Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| PianoError::io(path, "read the parameter file", e))?;
        Self::from_toml_str(&text).map_err(|e| e.in_file(path))
    }

    /// Checks every number is finite and every mass, inertia, radius and stiffness is
    /// positive, naming the first bad field; then that the geometry and body data describe
    /// an action that can work ([`crate::geometry_check`]).
    pub fn validate(&self) -> Result<()> {
        let table = toml::Table::try_from(self)
            .map_err(|e| PianoError::params(String::new(), e.to_string()))?;
        check_table("", &table)?;
        for (i, e) in self.effects.iter().enumerate() {
            e.validate(&format!("effects[{i}]"))?;
        }
        let positive = [
            ("key.mass_g", self.key.mass_g),
            ("key.inertia_pivot_kg_m2", self.key.inertia_pivot_kg_m2),
            ("key.capstan_radius_mm", self.key.capstan_radius_mm),
            ("wippen.mass_g", self.wippen.mass_g),
            ("wippen.inertia_com_kg_m2", self.wippen.inertia_com_kg_m2),
            ("jack.mass_g", self.jack.mass_g),
            ("jack.inertia_pivot_kg_m2", self.jack.inertia_pivot_kg_m2),
            ("repetition_lever.mass_g", self.repetition_lever.mass_g),
            (
                "repetition_lever.inertia_pivot_kg_m2",
                self.repetition_lever.inertia_pivot_kg_m2,
            ),
            ("hammer.mass_g", self.hammer.mass_g),
            ("hammer.inertia_com_kg_m2", self.hammer.inertia_com_kg_m2),
            ("hammer.knuckle_radius_mm", self.hammer.knuckle_radius_mm),
            ("hammer.crown_radius_mm", self.hammer.crown_radius_mm),
            (
                "numerics.felt_smoothing_m_s",
                self.numerics.felt_smoothing_m_s,
            ),
            (
                "numerics.relative_tolerance",
                self.numerics.relative_tolerance,
            ),
            (
                "numerics.absolute_tolerance",
                self.numerics.absolute_tolerance,
            ),
        ];
        self.contacts.check()?;
        self.string.build()?;
        // Beyond 10 % per step the integrator's error control means nothing [D].
        if self.numerics.relative_tolerance > 0.1 {
            return Err(PianoError::params(
                "numerics.relative_tolerance",
                format!(
                    "must be at most 0.1 (the default is 1e-3), got {}",
                    self.numerics.relative_tolerance
                ),
            ));
        }
        // Four samples per step see every event of the tests; 64 is plenty [D].
        if self.numerics.event_samples > 64 {
            return Err(PianoError::params(
                "numerics.event_samples",
                format!("must be at most 64, got {}", self.numerics.event_samples),
            ));
        }
        if self.numerics.event_samples == 0 {
            return Err(PianoError::params(
                "numerics.event_samples",
                "must be at least 1",
            ));
        }
        for (field, v) in positive {
            if v <= 0.0 {
                return Err(PianoError::params(
                    field,
                    format!("must be positive, got {v}"),
                ));
            }
        }
        crate::geometry_check::ensure_plausible(self)
    }

    /// The parameters as TOML text (for `piano params`; the embedded default keeps its
    /// comments, this form does not).
    pub fn to_toml_string(&self) -> Result<String> {
        toml::to_string_pretty(self).map_err(|e| PianoError::params(String::new(), e.to_string()))
    }
}

/// Every number in the table must be finite.
fn check_table(prefix: &str, table: &toml::Table) -> Result<()> {
    for (k, v) in table {
        let path = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        check_value(&path, v)?;
    }
    Ok(())
}

fn check_value(path: &str, v: &toml::Value) -> Result<()> {
    let name = path.rsplit('.').next().unwrap_or(path);
    // Frictions, stiffnesses and dampings resist motion; a negative one would feed it.
    let non_negative =
        name.ends_with("friction_n_m") || name.contains("stiffness") || name.contains("damping");
    let positive = name.contains("regularization");
    match v {
        toml::Value::Float(x) if !x.is_finite() => {
            Err(PianoError::params(path, format!("must be finite, got {x}")))
        }
        toml::Value::Float(x) if non_negative && *x < 0.0 => Err(PianoError::params(
            path,
            format!("must not be negative (it resists motion), got {x}"),
        )),
        toml::Value::Float(x) if positive && *x <= 0.0 => Err(PianoError::params(
            path,
            format!("must be positive, got {x}"),
        )),
        toml::Value::Table(t) => check_table(path, t),
        toml::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                check_value(&format!("{path}[{i}]"), x)?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// The jack's outer stop of files written before it existed (rad) \[M\].
fn default_jack_outer_stop() -> f64 {
    0.3
}
