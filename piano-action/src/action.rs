//! The three progressive grand actions assembled from one parameter set.
//!
//! Bodies and joints (all joint frames at the pivots, world-aligned at rest except the
//! hammer's, which lies along the shank):
//!
//! - key: revolute at the balance pivot, positive when the front goes down;
//! - wippen: revolute at its flange, negative when it rises;
//! - jack: revolute on the wippen (fixed to it in the simplified model), positive when it
//!   turns out from under the knuckle;
//! - repetition lever (double escapement only): revolute on the wippen, positive when pushed
//!   down;
//! - hammer: revolute at its flange, positive when the head rises.
//!
//! Contacts (rate-independent hysteretic felt laws with regularised Coulomb friction where
//! μ > 0):
//! key–front rail, key–back rail, capstan–heel, jack–knuckle, lever–knuckle, jack
//! toe–let-off button, lever tip–drop screw, tail–backcheck, shank–rest rail; and
//! hammer–string, the crown's felt (C&A power law) against a modal string
//! ([`mbs_contact::StringContact`], section `[string]` of the parameters), whose internal
//! states (two per mode) follow the coordinates and velocities in the state.
//! Springs: repetition and jack springs, with their stops as joint limits.
//! Pivot friction at every centre.

use std::collections::BTreeMap;

use mbs_contact::laws::{Hertz, HystereticFelt, RegularizedCoulomb};
use mbs_contact::{Contact, ContactOutput, ContactSide, Shape, StringContact};
use mbs_core::elements::{AppliedLoad, Attachment, LoadFrame};
use mbs_core::elements::{FrictionLaw, JointLimit, JointSpringDamper, PivotFriction, SpringLaw};
use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement, System, TimeFunction};
use mbs_integrators::{EventAction, Method, MultibodyOde, Options, Solution, solve_observed};

use crate::error::Result;
use crate::params::{ActionParams, ContactParams};

/// Which of the three progressive models.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ModelKind {
    /// Key, wippen with the jack fixed to it, hammer: no escapement, no repetition lever.
    Simplified,
    /// Adds the jack with its spring and the let-off button, and the backcheck.
    Single,
    /// Adds the repetition lever, its spring and the drop screw.
    Double,
}

impl ModelKind {
    /// All three, simplest first.
    pub const ALL: [ModelKind; 3] = [ModelKind::Simplified, ModelKind::Single, ModelKind::Double];

    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Simplified => "simplified",
            ModelKind::Single => "single",
            ModelKind::Double => "double",
        }
    }
}

/// An assembled action: the system to integrate, and where things are in it.
pub struct Action {
    /// Which model.
    pub kind: ModelKind,
    /// The parameters it was built from.
    pub params: ActionParams,
    /// The multibody system (model, force elements).
    pub system: System,
    /// Element index of each contact, by name (`"capstan_heel"`, `"hammer_string"`, ...).
    pub contacts: BTreeMap<&'static str, usize>,
    /// The presser over the key front (a weight or a finger), if it was built with one.
    pub presser: Option<Presser>,
}

/// Radius of a [`Presser`]'s round pad (mm): its contact with the key top.
pub const PRESSER_PAD_RADIUS_MM: f64 = 5.0;

/// mm → m.
fn m(v: [f64; 2]) -> [f64; 2] {
    [v[0] * 1e-3, v[1] * 1e-3]
}

fn rel(p: [f64; 2], origin: [f64; 2]) -> [f64; 2] {
    m([p[0] - origin[0], p[1] - origin[1]])
}

/// A horizontal ground face at height `y` over `x`, facing up or down (mm in, shape in m).
fn ground_face(y: f64, x: [f64; 2], up: bool) -> Result<Shape> {
    let (a, b) = if up {
        ([x[0], y], [x[1], y])
    } else {
        ([x[1], y], [x[0], y])
    };
    Ok(Shape::segment(m(a), m(b))?)
}

/// A face through `p` along direction `d` (unit), from `back` before to `ahead` after `p`,
/// its outward normal `d` turned a quarter counter-clockwise (mm in, shape in m).
fn face(p: [f64; 2], d: [f64; 2], back: f64, ahead: f64) -> Result<Shape> {
    let a = [p[0] - back * d[0], p[1] - back * d[1]];
    let b = [p[0] + ahead * d[0], p[1] + ahead * d[1]];
    Ok(Shape::segment(m(a), m(b))?)
}

fn circle(c: [f64; 2], r_mm: f64) -> Result<Shape> {
    Ok(Shape::circle(m(c), r_mm * 1e-3)?)
}

/// A body over the key front sliding vertically above the finger point and touching the
/// key top through a pad: a weight resting on or dropped onto the key (the 1 kg
/// experiment), or a finger.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Presser {
    /// Its mass (kg).
    pub mass_kg: f64,
    /// Height of its pad above the key top at t = 0 (mm; 0 = resting on it).
    pub height_mm: f64,
    /// The pad's contact law.
    pub pad: ContactParams,
    /// Whether something else carries its weight (a finger, held by the arm): gravity on it
    /// is balanced by an equal upward force.
    pub carried: bool,
}

impl Presser {
    /// A weight of `mass_kg` with its firm pad (felt law k = 1e7, p = 1.5, e = 0.5
    /// \[D\]) `height_mm` above the key top.
    pub fn weight(mass_kg: f64, height_mm: f64) -> Self {
        Presser {
            mass_kg,
            height_mm,
            pad: ContactParams {
                k: 1.0e7,
                p: 1.5,
                e: 0.5,
                mu: 0.0,
            },
            carried: false,
        }
    }
}

impl Action {
    /// Assembles `kind` from `params`.
    pub fn build(params: &ActionParams, kind: ModelKind) -> Result<Action> {
        Self::build_with(params, kind, None)
    }

    /// Assembles `kind` from `params` with a [`Presser`] over the key front (coordinate
    /// `"presser"`, positive up, 0 at its starting height; contact `"presser_key"`).
    pub fn build_with(
        params: &ActionParams,
        kind: ModelKind,
        presser: Option<Presser>,
    ) -> Result<Action> {
        params.validate()?;
        if let Some(pr) = presser
            && !(pr.mass_kg.is_finite()
                && pr.mass_kg > 0.0
                && pr.height_mm.is_finite()
                && (0.0..=500.0).contains(&pr.height_mm))
        {
            return Err(crate::PianoError::scenario(
                "input",
                format!(
                    "the mass must be positive and its height 0-500 mm, got {} kg at {} mm",
                    pr.mass_kg, pr.height_mm
                ),
            ));
        }
        let p = params;
        let (k, w, j, r, h) = (&p.key, &p.wippen, &p.jack, &p.repetition_lever, &p.hammer);
        let with_jack = kind != ModelKind::Simplified;
        let with_lever = kind == ModelKind::Double;

        // Bodies: mass (kg), centre of mass in the joint frame (m), inertia about it.
        let mut b = ModelBuilder::new();
        b.gravity([0.0, -crate::params::GRAVITY_M_S2]);
        let key_com = rel(k.com_mm, k.pivot_mm);
        let key_mass = k.mass_g * 1e-3;
        let key_i = k.inertia_pivot_kg_m2 - key_mass * (key_com[0].powi(2) + key_com[1].powi(2));
        b.add_link(
            "key",
            None,
            JointKind::Revolute,
            Placement::offset(k.pivot_mm[0] * 1e-3, k.pivot_mm[1] * 1e-3),
            BodySpec::new(key_mass, key_com, key_i),
        );
        b.add_link(
            "wippen",
            None,
            JointKind::Revolute,
            Placement::offset(w.pivot_mm[0] * 1e-3, w.pivot_mm[1] * 1e-3),
            BodySpec::new(
                w.mass_g * 1e-3,
                rel(w.com_mm, w.pivot_mm),
                w.inertia_com_kg_m2,
            ),
        );
        let jack_at = rel(j.pivot_mm, w.pivot_mm);
        let jack_com = rel(j.com_mm, j.pivot_mm);
        let jack_mass = j.mass_g * 1e-3;
        let jack_i =
            j.inertia_pivot_kg_m2 - jack_mass * (jack_com[0].powi(2) + jack_com[1].powi(2));
        b.add_link(
            "jack",
            Some("wippen"),
            if with_jack {
                JointKind::Revolute
            } else {
                JointKind::Fixed
            },
            Placement::offset(jack_at[0], jack_at[1]),
            BodySpec::new(jack_mass, jack_com, jack_i),
        );
        if with_lever {
            let at = rel(r.pivot_mm, w.pivot_mm);
            let com = rel(r.com_mm, r.pivot_mm);
            let mass = r.mass_g * 1e-3;
            let i = r.inertia_pivot_kg_m2 - mass * (com[0].powi(2) + com[1].powi(2));
            b.add_link(
                "repetition_lever",
                Some("wippen"),
                JointKind::Revolute,
                Placement::offset(at[0], at[1]),
                BodySpec::new(mass, com, i),
            );
        }
        b.add_link(
            "hammer",
            None,
            JointKind::Revolute,
            Placement::new(
                h.rest_angle_deg.to_radians(),
                h.pivot_mm[0] * 1e-3,
                h.pivot_mm[1] * 1e-3,
            ),
            BodySpec::new(h.mass_g * 1e-3, m(h.com_body_mm), h.inertia_com_kg_m2),
        );
        if let Some(pr) = presser {
            b.add_link(
                "presser",
                None,
                JointKind::Prismatic { axis: [0.0, 1.0] },
                Placement::offset(
                    k.finger_mm[0] * 1e-3,
                    (k.finger_mm[1] + PRESSER_PAD_RADIUS_MM + pr.height_mm) * 1e-3,
                ),
                BodySpec::new(pr.mass_kg, [0.0, 0.0], pr.mass_kg * 1e-4),
            );
        }
        let model = b.build()?;
        let mut system = System::new(model.clone());

        // Springs, stops and pivot friction.
        let reg = p.numerics.pivot_friction_regularization_rad_s;
        let mut pivots = vec![
            ("key", k.pivot_friction_n_m),
            ("wippen", w.pivot_friction_n_m),
            ("hammer", h.pivot_friction_n_m),
        ];
        let (stop_k, stop_c) = (
            p.numerics.stop_stiffness_n_m_per_rad,
            p.numerics.stop_damping_n_m_s_per_rad,
        );
        if with_jack {
            pivots.push(("jack", j.pivot_friction_n_m));
            let law = SpringLaw::new(j.spring_stiffness_n_m_per_rad, 0.0)
                .with_preload(-j.spring_preload_n_m);
            system
                .add_element(JointSpringDamper::new(&model, "jack", law)?.named("jack spring"))?;
            system.add_element(JointLimit::new(
                &model,
                "jack",
                j.stop_angle_rad,
                j.outer_stop_rad,
                stop_k,
                stop_c,
            )?)?;
        }
        if with_lever {
            pivots.push(("repetition_lever", r.pivot_friction_n_m));
            let law = SpringLaw::new(r.spring_stiffness_n_m_per_rad, 0.0)
                .with_preload(-r.spring_preload_n_m);
            system.add_element(
                JointSpringDamper::new(&model, "repetition_lever", law)?.named("repetition spring"),
            )?;
            system.add_element(JointLimit::new(
                &model,
                "repetition_lever",
                r.upper_stop_rad,
                f64::INFINITY,
                stop_k,
                stop_c,
            )?)?;
        }
        if !p.effects.is_empty() {
            let laws = crate::identify::effects::FlangeEffects::from_entries(&p.effects)?;
            system.add_element(crate::identify::effects::FlangeEffectElement::new(
                &model,
                "hammer",
                laws,
                reg,
                h.mass_g * 1e-3,
                m(h.com_body_mm),
                h.rest_angle_deg.to_radians(),
            )?)?;
        }
        for (joint, torque) in pivots {
            if torque > 0.0 {
                system.add_element(PivotFriction::new(
                    &model,
                    joint,
                    FrictionLaw::coulomb(torque, reg),
                )?)?;
            }
        }

        // Contact shapes, each in its body's joint frame.
        let g = &p.regulation;
        let kp = k.pivot_mm;
        let capstan = [
            k.capstan_center_mm[0],
            k.capstan_center_mm[1] + g.capstan_raise_mm,
        ];
        let heel = face(
            [w.heel_mm[0] - w.pivot_mm[0], w.heel_mm[1] - w.pivot_mm[1]],
            [-1.0, 0.0],
            w.heel_half_length_mm,
            w.heel_half_length_mm,
        )?;
        // Jack top: along t, facing the jack axis n.
        let n = j.axis;
        let t = [n[1], -n[0]];
        let jack_top = face(
            [j.top_mm[0] - j.pivot_mm[0], j.top_mm[1] - j.pivot_mm[1]],
            t,
            j.top_front_edge_mm,
            j.top_back_edge_mm,
        )?;
        let toe = circle(
            [
                j.toe_mm[0] - j.pivot_mm[0],
                j.toe_mm[1] - j.pivot_mm[1] - j.toe_radius_mm,
            ],
            j.toe_radius_mm,
        )?;
        // Backcheck face on the key, at its angle, facing the hammer tail at rest.
        let a = k.backcheck_face_angle_deg.to_radians();
        let d = [a.cos(), a.sin()];
        let tail_rest = {
            let (s, c) = h.rest_angle_deg.to_radians().sin_cos();
            let tb = h.tail_body_mm;
            [
                h.pivot_mm[0] + c * tb[0] - s * tb[1],
                h.pivot_mm[1] + s * tb[0] + c * tb[1],
            ]
        };
        let to_tail = [
            tail_rest[0] - k.backcheck_mm[0],
            tail_rest[1] - k.backcheck_mm[1],
        ];
        let d = if -d[1] * to_tail[0] + d[0] * to_tail[1] >= 0.0 {
            d
        } else {
            [-d[0], -d[1]]
        };
        // Outward normal of the face (toward the tail); the regulation offset moves it.
        let off = g.backcheck_offset_mm;
        let backcheck = face(
            [
                k.backcheck_mm[0] - kp[0] - off * d[1],
                k.backcheck_mm[1] - kp[1] + off * d[0],
            ],
            d,
            k.backcheck_half_length_mm,
            k.backcheck_half_length_mm,
        )?;
        let knuckle = circle(h.knuckle_body_mm, h.knuckle_radius_mm)?;
        let crown = circle(
            [h.strike_body_mm[0], h.strike_body_mm[1] - h.crown_radius_mm],
            h.crown_radius_mm,
        )?;
        let tail = circle(h.tail_body_mm, h.tail_radius_mm)?;
        let shank_under = circle([h.rest_body_mm[0], h.rest_body_mm[1] + 0.5], 0.5)?;

        let mut contacts = BTreeMap::new();
        let mut add = |name: &'static str,
                       a: ContactSide,
                       b: ContactSide,
                       law: &ContactParams,
                       system: &mut System|
         -> Result<()> {
            // Felt, cloth and leather lose the same share of energy in a slow settle as in a
            // hard blow (rate-independent hysteresis, Boutillon 1988; Hirschkorn et al.
            // 2006): restitution `e` at every speed above the smoothing speed.
            let normal = HystereticFelt::from_restitution(
                law.k,
                law.p,
                law.e,
                p.numerics.felt_smoothing_m_s,
            )?;
            let mut c = Contact::new(&model, name, a, b, normal)?;
            if law.mu > 0.0 {
                c = c.with_friction(RegularizedCoulomb::new(
                    law.mu,
                    p.numerics.friction_regularization_m_s,
                )?);
            }
            contacts.insert(name, system.add_element(c)?);
            Ok(())
        };
        let c = &p.contacts;
        add(
            "front_rail",
            ContactSide::ground(vec![ground_face(
                g.front_rail_top_y_mm,
                g.front_rail_x_mm,
                true,
            )?]),
            ContactSide::on(
                "key",
                vec![circle(
                    [k.front_pad_mm[0] - kp[0], k.front_pad_mm[1] - kp[1]],
                    k.front_pad_radius_mm,
                )?],
            ),
            &c.front_rail,
            &mut system,
        )?;
        add(
            "back_rail",
            ContactSide::ground(vec![ground_face(
                g.back_rail_top_y_mm,
                g.back_rail_x_mm,
                true,
            )?]),
            ContactSide::on(
                "key",
                vec![circle(
                    [k.back_pad_mm[0] - kp[0], k.back_pad_mm[1] - kp[1]],
                    k.back_pad_radius_mm,
                )?],
            ),
            &c.back_rail,
            &mut system,
        )?;
        add(
            "capstan_heel",
            ContactSide::on(
                "key",
                vec![circle(
                    [capstan[0] - kp[0], capstan[1] - kp[1]],
                    k.capstan_radius_mm,
                )?],
            ),
            ContactSide::on("wippen", vec![heel]),
            &c.capstan_heel,
            &mut system,
        )?;
        add(
            "jack_knuckle",
            ContactSide::on("jack", vec![jack_top]),
            ContactSide::on("hammer", vec![knuckle]),
            &c.jack_knuckle,
            &mut system,
        )?;
        if with_jack {
            add(
                "let_off_button",
                ContactSide::ground(vec![ground_face(
                    g.let_off_button_y_mm,
                    g.let_off_button_x_mm,
                    false,
                )?]),
                ContactSide::on("jack", vec![toe]),
                &c.let_off_button,
                &mut system,
            )?;
            add(
                "backcheck",
                ContactSide::on("key", vec![backcheck]),
                ContactSide::on("hammer", vec![tail]),
                &c.backcheck,
                &mut system,
            )?;
        }
        if with_lever {
            let lever_top = face(
                [r.top_mm[0] - r.pivot_mm[0], r.top_mm[1] - r.pivot_mm[1]],
                t,
                r.top_front_edge_mm,
                r.top_back_edge_mm,
            )?;
            let tip = circle(
                [
                    r.tip_mm[0] - r.pivot_mm[0],
                    r.tip_mm[1] - r.pivot_mm[1] - r.tip_radius_mm,
                ],
                r.tip_radius_mm,
            )?;
            add(
                "lever_knuckle",
                ContactSide::on("repetition_lever", vec![lever_top]),
                ContactSide::on("hammer", vec![knuckle]),
                &c.lever_knuckle,
                &mut system,
            )?;
            add(
                "drop_screw",
                ContactSide::ground(vec![ground_face(
                    g.drop_screw_y_mm,
                    g.drop_screw_x_mm,
                    false,
                )?]),
                ContactSide::on("repetition_lever", vec![tip]),
                &c.drop_screw,
                &mut system,
            )?;
        }
        add(
            "rest_rail",
            ContactSide::ground(vec![ground_face(
                g.rest_rail_top_y_mm,
                g.rest_rail_x_mm,
                true,
            )?]),
            ContactSide::on("hammer", vec![shank_under]),
            &c.rest_rail,
            &mut system,
        )?;
        if let Some(pr) = presser {
            if pr.carried {
                let weight = AppliedLoad::force(
                    &model,
                    "presser weight carried",
                    Attachment::on("presser", [0.0, 0.0]),
                    [0.0, 1.0],
                    LoadFrame::World,
                    mbs_core::time_function::Constant(-pr.mass_kg * model.gravity()[1]),
                )?;
                system.add_element(weight)?;
            }
            let kf = [k.finger_mm[0] - kp[0], k.finger_mm[1] - kp[1]];
            add(
                "presser_key",
                ContactSide::on(
                    "key",
                    vec![Shape::segment(
                        m([kf[0] - 12.0, kf[1]]),
                        m([kf[0] + 12.0, kf[1]]),
                    )?],
                ),
                ContactSide::on("presser", vec![circle([0.0, 0.0], PRESSER_PAD_RADIUS_MM)?]),
                &pr.pad,
                &mut system,
            )?;
        }
        // The hammer strikes a modal string lying along the string line (the felt undamped:
        // the string's motion gives the rebound). Added last: its states end the state.
        let string = StringContact::new(
            &model,
            "hammer_string",
            p.string.build()?,
            ground_face(g.string_y_mm, g.string_x_mm, false)?,
            ContactSide::on("hammer", vec![crown]),
            Hertz::new(c.hammer_string.k, c.hammer_string.p)?,
        )?;
        contacts.insert("hammer_string", system.add_element(string)?);
        Ok(Action {
            kind,
            params: params.clone(),
            system,
            contacts,
            presser,
        })
    }

    /// Adds a vertical force pressing down on the key front (the finger point), its
    /// magnitude (N) a function of time.
    pub fn add_key_force(&mut self, magnitude: impl TimeFunction + 'static) -> Result<()> {
        let k = &self.params.key;
        let at = [
            (k.finger_mm[0] - k.pivot_mm[0]) * 1e-3,
            (k.finger_mm[1] - k.pivot_mm[1]) * 1e-3,
        ];
        let model = self.system.model().clone();
        let finger = AppliedLoad::force(
            &model,
            "finger",
            Attachment::on("key", at),
            [0.0, -1.0],
            LoadFrame::World,
            magnitude,
        )?;
        self.system.add_element(finger)?;
        Ok(())
    }

    /// Integrates from `x0` to `t_end` with TR-BDF2 (tolerances from `[numerics]`), steps of at
    /// most `max_step`, output every `output_step` (or every step), recording every contact
    /// event.
    pub fn integrate(
        &self,
        x0: &[f64],
        t_end: f64,
        max_step: f64,
        output_step: Option<f64>,
    ) -> Result<Solution> {
        self.integrate_observed(x0, t_end, max_step, output_step, &mut |_| {})
    }

    /// Integrates like [`Action::integrate`], calling `progress` with the simulated time
    /// after every step (for a progress bar).
    pub fn integrate_observed(
        &self,
        x0: &[f64],
        t_end: f64,
        max_step: f64,
        output_step: Option<f64>,
        progress: &mut dyn FnMut(f64),
    ) -> Result<Solution> {
        let opts = Options {
            max_step,
            output_step,
            event_samples: self.params.numerics.event_samples,
            ..Options::with_tolerances(
                self.params.numerics.relative_tolerance,
                self.params.numerics.absolute_tolerance,
            )
        };
        solve_observed(
            &mut MultibodyOde::new(&self.system),
            Method::TrBdf2,
            0.0,
            x0,
            t_end,
            &opts,
            &mut |_, _| EventAction::Record,
            progress,
        )
        .map_err(|e| crate::PianoError::Simulation(e.to_string()))
    }

    /// The coordinates of `kind` settled at rest with nothing on the key: the layout state
    /// integrated for 0.3 s (the key drops onto its cloths and the hammer onto its rail,
    /// and the ringing dies away). Keystrokes start here.
    /// The last few results are remembered (a sweep or a benchmark settles the same action
    /// once).
    pub fn rest_coordinates(params: &ActionParams, kind: ModelKind) -> Result<Vec<f64>> {
        type Cache = Vec<(ModelKind, ActionParams, Vec<f64>)>;
        static CACHE: std::sync::Mutex<Cache> = std::sync::Mutex::new(Vec::new());
        let lookup = |cache: &Cache| {
            cache
                .iter()
                .find(|(k, p, _)| *k == kind && p == params)
                .map(|(_, _, q)| q.clone())
        };
        if let Some(q) = CACHE.lock().ok().and_then(|c| lookup(&c)) {
            return Ok(q);
        }
        let q = Self::settle(params, kind)?;
        if let Ok(mut cache) = CACHE.lock() {
            if cache.len() >= 8 {
                cache.remove(0);
            }
            cache.push((kind, params.clone(), q.clone()));
        }
        Ok(q)
    }

    fn settle(params: &ActionParams, kind: ModelKind) -> Result<Vec<f64>> {
        let action = Action::build(params, kind)?;
        let x0 = action.layout_state()?;
        let settled = action.integrate(&x0, 0.3, 2e-3, Some(0.3))?;
        let nv = action.system.model().nv();
        let last = settled.len().saturating_sub(1);
        Ok(settled.state(last)[..nv].to_vec())
    }

    /// The state at rest as laid out: every coordinate zero, at rest, internal states at
    /// their initial values.
    pub fn layout_state(&self) -> Result<Vec<f64>> {
        let n = self.system.model().nv();
        Ok(self
            .system
            .initial_state(0.0, &vec![0.0; n], &vec![0.0; n])?)
    }

    /// What the named contact does at time `t` and state `x`: gap, forces, point, normal.
    pub fn contact_output(
        &self,
        name: &str,
        t: f64,
        x: &[f64],
    ) -> Result<mbs_contact::ContactOutput> {
        let unknown = || mbs_core::CoreError::UnknownName {
            what: "contact",
            name: name.to_string(),
        };
        let e = *self.contacts.get(name).ok_or_else(unknown)?;
        let mut ws = self.system.workspace();
        let ctx = self.system.element_context(&mut ws, t, x, e)?;
        let element = self.system.elements().nth(e).ok_or_else(unknown)?;
        let contact = ContactElement::of(element).ok_or_else(unknown)?;
        Ok(contact.output(&ctx))
    }

    /// The string the hammer strikes (its element in the system), if the action has one.
    pub fn string_contact(&self) -> Option<&StringContact> {
        let e = *self.contacts.get("hammer_string")?;
        self.system.elements().nth(e).and_then(StringContact::of)
    }

    /// Where the string's internal states lie in the state vector (its modal amplitudes
    /// `[A_1..A_N, B_1..B_N]` first), if the action has a string.
    pub fn string_state_range(&self) -> Option<std::ops::Range<usize>> {
        self.string_contact()?;
        let e = *self.contacts.get("hammer_string")?;
        self.system.element_state_range(e)
    }

    /// The distance (m) from the hammer crown to the string line at rest at time `t` and
    /// state `x`: what a technician measures (blow distance, check), free of the string's
    /// ringing; [`Action::gap`] gives the felt's own gap (negative in contact).
    pub fn string_rest_gap(&self, t: f64, x: &[f64]) -> Result<f64> {
        self.with_string(t, x, |string, ctx| string.rest_gap(ctx))
    }

    /// The string at time `t` and state `x`: displacement and velocity at the strike
    /// point, bridge force, energy.
    pub fn string_output(&self, t: f64, x: &[f64]) -> Result<mbs_contact::StringOutput> {
        self.with_string(t, x, |string, ctx| string.string_output(ctx))
    }

    /// `read` applied to the string element and its context at time `t`, state `x`.
    fn with_string<T>(
        &self,
        t: f64,
        x: &[f64],
        read: impl FnOnce(&StringContact, &mbs_core::ForceContext<'_>) -> T,
    ) -> Result<T> {
        let unknown = || mbs_core::CoreError::UnknownName {
            what: "contact",
            name: "hammer_string".to_string(),
        };
        let e = *self.contacts.get("hammer_string").ok_or_else(unknown)?;
        let string = self.string_contact().ok_or_else(unknown)?;
        let mut ws = self.system.workspace();
        let ctx = self.system.element_context(&mut ws, t, x, e)?;
        Ok(read(string, &ctx))
    }

    /// The gap (m) of the named contact at time `t` and state `x` (the time matters when a
    /// coordinate is prescribed: the drive, not the state, then places it).
    pub fn gap(&self, name: &str, t: f64, x: &[f64]) -> Result<f64> {
        let e = *self
            .contacts
            .get(name)
            .ok_or_else(|| mbs_core::CoreError::UnknownName {
                what: "contact",
                name: name.to_string(),
            })?;
        let mut ws = self.system.workspace();
        let ctx = self.system.element_context(&mut ws, t, x, e)?;
        let mut g = [0.0];
        if let Some(el) = self.system.elements().nth(e) {
            el.switching_functions(&ctx, &mut g);
        }
        Ok(g[0])
    }
}

/// A contact element of the action: a plain [`Contact`] or the hammer on the string
/// ([`StringContact`]), seen through what drawings and outputs need of both.
#[derive(Clone, Copy, Debug)]
pub enum ContactElement<'a> {
    /// Two shapes and a law.
    Plain(&'a Contact),
    /// The hammer crown on the modal string.
    String(&'a StringContact),
}

impl<'a> ContactElement<'a> {
    /// The contact behind a force element, if it is one.
    pub fn of(element: &'a dyn mbs_core::ForceElement) -> Option<Self> {
        Contact::of(element)
            .map(ContactElement::Plain)
            .or_else(|| StringContact::of(element).map(ContactElement::String))
    }

    /// The bodies and shapes of the two sides (the string at rest for the string).
    pub fn sides(&self) -> [(mbs_core::BodyId, &'a [Shape]); 2] {
        match self {
            ContactElement::Plain(c) => c.sides(),
            ContactElement::String(s) => s.sides(),
        }
    }

    /// Gap, forces, point and normal at the state in `ctx`.
    pub fn output(&self, ctx: &mbs_core::ForceContext<'_>) -> ContactOutput {
        match self {
            ContactElement::Plain(c) => c.output(ctx),
            ContactElement::String(s) => s.output(ctx),
        }
    }
}
