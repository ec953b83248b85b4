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

use mbs_contact::StringContact;
use mbs_core::elements::{AppliedLoad, Attachment, LoadFrame};
use mbs_core::{System, TimeFunction};
use mbs_integrators::{EventAction, Method, MultibodyOde, Options, Solution, solve_observed};
use mbs_mechanism::ContactHandle;

use crate::error::Result;
use crate::params::{ActionParams, ContactParams};

/// A change to the grand's description before it is built: an effect a diagnosis adds
/// (see [`Action::build_transformed`]).
pub type Transform<'a> =
    &'a (dyn Fn(&mbs_mechanism::Mechanism) -> Result<mbs_mechanism::Mechanism> + Sync);

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
    pub contacts: BTreeMap<String, usize>,
    /// Each contact with its type (shapes and outputs without a downcast), by name.
    pub contact_handles: BTreeMap<String, ContactHandle>,
    /// Element index of every named element (springs, contacts, `"jack limits"`, ...).
    pub elements: BTreeMap<String, usize>,
    /// The presser over the key front (a weight or a finger), if it was built with one.
    pub presser: Option<Presser>,
    /// The description the system was built from (a run directory keeps it).
    pub mechanism: mbs_mechanism::Mechanism,
}

/// Radius of a [`Presser`]'s round pad (mm): its contact with the key top.
pub const PRESSER_PAD_RADIUS_MM: f64 = 5.0;

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
        Self::build_transformed(params, kind, presser, None)
    }

    /// Assembles `kind` like [`Action::build_with`], its description first changed by
    /// `transform` if given (an effect added for a diagnosis: a body split, a contact's law
    /// swapped).
    pub fn build_transformed(
        params: &ActionParams,
        kind: ModelKind,
        presser: Option<Presser>,
        transform: Option<Transform<'_>>,
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
        let mechanism = crate::describe::grand_mechanism(params, kind, presser)?;
        match transform {
            None => Self::from_mechanism(params, kind, presser, &mechanism),
            Some(f) => Self::from_mechanism(params, kind, presser, &f(&mechanism)?),
        }
    }

    /// Assembles the action from `mechanism`, a description of the grand `kind` (as
    /// [`crate::describe::grand_mechanism`] writes it, possibly transformed or read back
    /// from a file); `params` are those it was written from (regulation, touchweight and
    /// the drawings read them).
    pub fn from_mechanism(
        params: &ActionParams,
        kind: ModelKind,
        presser: Option<Presser>,
        mechanism: &mbs_mechanism::Mechanism,
    ) -> Result<Action> {
        let built = mechanism.build_with(&crate::describe::PianoExtensions)?;
        Ok(Action {
            kind,
            params: params.clone(),
            system: built.system,
            contacts: built.contacts,
            contact_handles: built.contact_handles,
            elements: built.elements,
            presser,
            mechanism: mechanism.clone(),
        })
    }

    /// Adds a vertical force pressing down on the key front (the finger point), its
    /// magnitude (N) a function of time.
    pub fn add_key_force(&mut self, magnitude: impl TimeFunction + 'static) -> Result<()> {
        let at = crate::key::KeyGeometry::of(&self.params.key).finger_m();
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
        integrate_system(
            &self.system,
            &self.params.numerics,
            x0,
            t_end,
            max_step,
            output_step,
            progress,
        )
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

    /// The coordinates of `kind` with its description changed by `transform`, settled at
    /// rest with nothing on the key, as [`Action::rest_coordinates`] (the last few
    /// remembered, by parameters and changed description).
    pub fn rest_coordinates_transformed(
        params: &ActionParams,
        kind: ModelKind,
        transform: Transform<'_>,
    ) -> Result<Vec<f64>> {
        type Cache = Vec<(ModelKind, ActionParams, mbs_mechanism::Mechanism, Vec<f64>)>;
        static CACHE: std::sync::Mutex<Cache> = std::sync::Mutex::new(Vec::new());
        let mechanism = transform(&crate::describe::grand_mechanism(params, kind, None)?)?;
        let lookup = |cache: &Cache| {
            cache
                .iter()
                .find(|(k, p, m, _)| *k == kind && p == params && *m == mechanism)
                .map(|(_, _, _, q)| q.clone())
        };
        if let Some(q) = CACHE.lock().ok().and_then(|c| lookup(&c)) {
            return Ok(q);
        }
        let q = Self::from_mechanism(params, kind, None, &mechanism)?.settled_coordinates()?;
        if let Ok(mut cache) = CACHE.lock() {
            if cache.len() >= 8 {
                cache.remove(0);
            }
            cache.push((kind, params.clone(), mechanism, q.clone()));
        }
        Ok(q)
    }

    fn settle(params: &ActionParams, kind: ModelKind) -> Result<Vec<f64>> {
        Action::build(params, kind)?.settled_coordinates()
    }

    /// The coordinates of this action settled at rest from its layout state, as
    /// [`Action::rest_coordinates`] settles the parameter file's (not remembered).
    pub fn settled_coordinates(&self) -> Result<Vec<f64>> {
        let x0 = self.layout_state()?;
        let settled = self.integrate(&x0, 0.3, 2e-3, Some(0.3))?;
        let nv = self.system.model().nv();
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
        let contact = self.contact_handles.get(name).ok_or_else(unknown)?;
        Ok(contact.output(&ctx))
    }

    /// The string the hammer strikes (its element in the system), if the action has one.
    pub fn string_contact(&self) -> Option<&StringContact> {
        self.contact_handles.get("hammer_string")?.string()
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

/// Integrates `system` from `x0` to `t_end` with TR-BDF2 and the tolerances and event
/// sampling of `numerics`, steps of at most `max_step`, output every `output_step` (or
/// every step), recording every event and calling `progress` with the simulated time after
/// every step.
pub fn integrate_system(
    system: &System,
    numerics: &crate::params::NumericsParams,
    x0: &[f64],
    t_end: f64,
    max_step: f64,
    output_step: Option<f64>,
    progress: &mut dyn FnMut(f64),
) -> Result<Solution> {
    let opts = Options {
        max_step,
        output_step,
        event_samples: numerics.event_samples,
        ..Options::with_tolerances(numerics.relative_tolerance, numerics.absolute_tolerance)
    };
    // The system's own Jacobian (the force elements' derivatives through the mass matrix)
    // when every element gives one: a fifth to a quarter fewer derivative evaluations than
    // finite differences, within the accuracy `tests/numerics.rs` asks for.
    let mut ode = MultibodyOde::new(system).with_analytic_jacobian();
    solve_observed(
        &mut ode,
        Method::TrBdf2,
        0.0,
        x0,
        t_end,
        &opts,
        &mut |_, _| EventAction::Record,
        progress,
    )
    .map_err(crate::PianoError::from)
}
