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
    /// once; see [`Action::rest_coordinates_transformed`] for what counts as the same).
    pub fn rest_coordinates(params: &ActionParams, kind: ModelKind) -> Result<Vec<f64>> {
        let mechanism = crate::describe::grand_mechanism(params, kind, None)?;
        remembered_rest(params, kind, mechanism)
    }

    /// The coordinates of `kind` with its description changed by `transform`, settled at
    /// rest with nothing on the key, as [`Action::rest_coordinates`]. The last few are
    /// remembered, each with the contacts whose laws never acted while it settled (the
    /// back-check, the let-off button, ...): an action that differs from a remembered one
    /// only in those contacts' laws settles exactly as it did (the integration makes the
    /// same evaluations, to the last bit: see [`mbs_contact::Contact::touched`]), so a
    /// fit that varies only them, or a finite difference in one of them, settles once.
    pub fn rest_coordinates_transformed(
        params: &ActionParams,
        kind: ModelKind,
        transform: Transform<'_>,
    ) -> Result<Vec<f64>> {
        let mechanism = transform(&crate::describe::grand_mechanism(params, kind, None)?)?;
        remembered_rest(params, kind, mechanism)
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

    /// The contacts (by name) whose laws have not acted since this action was built
    /// ([`mbs_contact::Contact::touched`]; a string's always counts as acted).
    fn contacts_not_touched(&self) -> Vec<String> {
        self.contact_handles
            .iter()
            .filter(|(_, h)| matches!(h, ContactHandle::Plain(c) if !c.touched()))
            .map(|(name, _)| name.clone())
            .collect()
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
    let opts = integration_options(numerics, max_step, output_step);
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

/// The integrator's options for an action: `numerics`' tolerances and event sampling.
fn integration_options(
    numerics: &crate::params::NumericsParams,
    max_step: f64,
    output_step: Option<f64>,
) -> Options {
    Options {
        max_step,
        output_step,
        event_samples: numerics.event_samples,
        ..Options::with_tolerances(numerics.relative_tolerance, numerics.absolute_tolerance)
    }
}

/// A run remembered to go on from ([`resumed_or_solved`]): what it was simulated from,
/// its solution and checkpoints, and when each contact's laws first acted in it.
struct Remembered {
    input: crate::simulate::Input,
    t_end: f64,
    max_step: f64,
    output_step: f64,
    params: ActionParams,
    mechanism: mbs_mechanism::Mechanism,
    x0: Vec<f64>,
    solution: Solution,
    checkpoints: Vec<mbs_integrators::Checkpoint>,
    /// Per contact of `mechanism`, the earliest time its laws acted (a string's: its
    /// start, it always acts), absent if never.
    acted_from: BTreeMap<String, f64>,
}

/// How many runs are remembered to go on from [D]: a fit's point and the points of
/// the fits beside it, while its finite differences come and go (each holds its output
/// and checkpoints, tens of megabytes on a drop of the grand).
const RUNS_REMEMBERED: usize = 6;

/// How often a remembered run keeps a checkpoint (s of simulated time) [D]: a resumed
/// run redoes at most this much of what it shares with the remembered one, and each
/// checkpoint copies the method's Jacobian and factorisation (every 2.5 ms, a diagnosis
/// held 1.2 GB and its refits on every run went no faster).
const CHECKPOINT_EVERY_S: f64 = 10e-3;

/// The most checkpoints a remembered run keeps [D]: a longer run keeps them further
/// apart (each holds the method's Jacobian and factorisation).
const CHECKPOINTS_MAX: usize = 64;

/// The contacts of `b` whose laws or friction differ from `a`'s (by name), when the two
/// hold the same contacts between the same shapes; `None` otherwise.
fn contacts_whose_laws_differ(
    a: &mbs_mechanism::Mechanism,
    b: &mbs_mechanism::Mechanism,
) -> Option<Vec<String>> {
    if a.contacts.len() != b.contacts.len() {
        return None;
    }
    let mut differ = Vec::new();
    for (x, y) in a.contacts.iter().zip(&b.contacts) {
        if x.name != y.name || x.a != y.a || x.b != y.b {
            return None;
        }
        if x.law != y.law || x.friction != y.friction || x.note != y.note {
            differ.push(x.name.clone());
        }
    }
    Some(differ)
}

/// Integrates `action` (assembled for the mass drop `input`) from `x0` to `t_end`, output
/// every `output_step` (s), as [`Action::integrate_observed`] would, to the last bit: from
/// a remembered run of an action that differs from it only in the laws of contacts
/// that had not acted by one of that run's checkpoints, from that checkpoint
/// ([`mbs_integrators::resume`]: its evaluations before it are this action's as well); else
/// solved whole and remembered, with a checkpoint every [`CHECKPOINT_EVERY_S`]. Also
/// returns the time of the checkpoint it went on from, if it did.
pub(crate) fn resumed_or_solved(
    action: &Action,
    input: &crate::simulate::Input,
    x0: &[f64],
    t_end: f64,
    max_step: f64,
    output_step: f64,
) -> Result<(Solution, Option<f64>)> {
    // Each with how many runs went on from it, least recently used first.
    static RUNS: std::sync::Mutex<Vec<(std::sync::Arc<Remembered>, usize)>> =
        std::sync::Mutex::new(Vec::new());
    let opts = integration_options(&action.params.numerics, max_step, Some(output_step));
    // The latest checkpoint of a remembered run this one may go on from.
    let usable = |r: &Remembered| -> Option<usize> {
        if r.input != *input
            || r.t_end != t_end
            || r.max_step != max_step
            || r.output_step != output_step
            || r.x0 != x0
        {
            return None;
        }
        let differ = contacts_whose_laws_differ(&r.mechanism, &action.mechanism)?;
        let (p, m) = without_laws(&action.params, &action.mechanism, &differ);
        let (rp, rm) = without_laws(&r.params, &r.mechanism, &differ);
        if p != rp || m != rm {
            return None;
        }
        let from = differ
            .iter()
            .map(|name| r.acted_from.get(name).copied().unwrap_or(f64::INFINITY))
            .fold(f64::INFINITY, f64::min);
        r.checkpoints.iter().rposition(|c| c.evaluated_until < from)
    };
    let found = RUNS.lock().ok().and_then(|mut runs| {
        let (i, k) = runs
            .iter()
            .enumerate()
            .filter_map(|(i, (r, _))| usable(r).map(|k| (i, k)))
            .max_by(|a, b| {
                let t = |(i, k): &(usize, usize)| runs[*i].0.checkpoints[*k].t;
                t(a).total_cmp(&t(b))
            })?;
        // The one found moves to the back: the least recently used goes first.
        let (r, uses) = runs.remove(i);
        runs.push((r.clone(), uses + 1));
        Some((r, k))
    });
    let mut ode = MultibodyOde::new(&action.system).with_analytic_jacobian();
    if let Some((r, k)) = found {
        let from = &r.checkpoints[k];
        return mbs_integrators::resume(
            &mut ode,
            Method::TrBdf2,
            &r.solution,
            from,
            t_end,
            &opts,
            &mut |_, _| EventAction::Record,
            &mut |_| {},
        )
        .map(|s| (s, Some(from.t)))
        .map_err(crate::PianoError::from);
    }
    let (solution, checkpoints) = mbs_integrators::solve_checkpointed(
        &mut ode,
        Method::TrBdf2,
        0.0,
        x0,
        t_end,
        &opts,
        &mut |_, _| EventAction::Record,
        &mut |_| {},
        CHECKPOINT_EVERY_S.max(t_end / CHECKPOINTS_MAX as f64),
    )
    .map_err(crate::PianoError::from)?;
    let acted_from = action
        .contact_handles
        .iter()
        .filter_map(|(name, h)| match h {
            ContactHandle::Plain(c) => c.acted_from().map(|t| (name.clone(), t)),
            ContactHandle::String(_) => Some((name.clone(), f64::NEG_INFINITY)),
        })
        .collect();
    let remembered = std::sync::Arc::new(Remembered {
        input: input.clone(),
        t_end,
        max_step,
        output_step,
        params: action.params.clone(),
        mechanism: action.mechanism.clone(),
        x0: x0.to_vec(),
        solution: solution.clone(),
        checkpoints,
        acted_from,
    });
    if let Ok(mut runs) = RUNS.lock() {
        // Full: the least recently used of those no run went on from goes (a finite
        // difference in a law that acts from the start, say), else the least recently
        // used (a fit's point whose differences found it outlives them).
        if runs.len() >= RUNS_REMEMBERED {
            let i = runs.iter().position(|(_, uses)| *uses == 0).unwrap_or(0);
            runs.remove(i);
        }
        runs.push((remembered, 0));
    }
    Ok((solution, None))
}

/// A remembered rest ([`Action::rest_coordinates_transformed`]): the action's parameters and
/// description with the laws of the contacts that never acted while it settled taken out
/// ([`without_laws`]), those contacts, and the coordinates at rest.
struct Rest {
    kind: ModelKind,
    params: ActionParams,
    mechanism: mbs_mechanism::Mechanism,
    untouched: Vec<String>,
    q: Vec<f64>,
}

/// How many rests are remembered: a diagnosis's fits side by side each vary their own
/// action, and each finite difference in a law that acts at rest settles anew.
const RESTS_REMEMBERED: usize = 8;

/// `params` and `mechanism` with the laws of `contacts` (by name) taken out: set to one
/// fixed placeholder, so that two actions that differ only there compare equal.
fn without_laws(
    params: &ActionParams,
    mechanism: &mbs_mechanism::Mechanism,
    contacts: &[String],
) -> (ActionParams, mbs_mechanism::Mechanism) {
    let (mut p, mut m) = (params.clone(), mechanism.clone());
    for name in contacts {
        if let Some(c) = p.contacts.named_mut(name) {
            *c = crate::params::ContactParams {
                k: 0.0,
                p: 0.0,
                e: 0.0,
                mu: 0.0,
            };
        }
    }
    for c in m.contacts.iter_mut().filter(|c| contacts.contains(&c.name)) {
        // The placeholder keeps how many states the law adds (they change the state
        // vector, and a law with states acts from the start); a law that does not build
        // stays as it is, and matches only itself.
        use mbs_contact::laws::NormalLaw;
        if let Ok(law) = mbs_mechanism::normal_law(&c.name, &c.law) {
            c.law = mbs_mechanism::LawSpec::Material(format!("{} states", law.state_count()));
        }
        c.friction = None;
        c.note.clear();
    }
    (p, m)
}

/// The rest of the action `mechanism` (described from `params`), remembered.
fn remembered_rest(
    params: &ActionParams,
    kind: ModelKind,
    mechanism: mbs_mechanism::Mechanism,
) -> Result<Vec<f64>> {
    static CACHE: std::sync::Mutex<Vec<Rest>> = std::sync::Mutex::new(Vec::new());
    let same = |r: &Rest| {
        r.kind == kind && {
            let (p, m) = without_laws(params, &mechanism, &r.untouched);
            p == r.params && m == r.mechanism
        }
    };
    // The one found moves to the back: the first goes when the cache is full, the least
    // recently used (a fit's point, whose finite differences in untouched laws all find
    // it, outlives the columns that settle anew).
    if let Ok(mut cache) = CACHE.lock()
        && let Some(i) = cache.iter().position(same)
    {
        let rest = cache.remove(i);
        let q = rest.q.clone();
        cache.push(rest);
        return Ok(q);
    }
    let action = Action::from_mechanism(params, kind, None, &mechanism)?;
    let q = action.settled_coordinates()?;
    let untouched = action.contacts_not_touched();
    let (params, mechanism) = without_laws(params, &mechanism, &untouched);
    if let Ok(mut cache) = CACHE.lock() {
        if cache.len() >= RESTS_REMEMBERED {
            cache.remove(0);
        }
        cache.push(Rest {
            kind,
            params,
            mechanism,
            untouched,
            q: q.clone(),
        });
    }
    Ok(q)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// At rest the hammer hangs on the jack and the key lies on its back rail: the
    /// back-check, the let-off button, the drop screw, the front rail's punching and the
    /// rest rail never act while the action settles, and an action that differs only in
    /// their laws settles to the very same bits; one that differs in a law that acts at
    /// rest (the back rail's cloth) settles elsewhere.
    #[test]
    fn a_rest_is_remembered_across_laws_that_never_acted_while_settling() {
        let kind = ModelKind::Double;
        let file = ActionParams::reference();
        let action = Action::build(&file, kind).unwrap();
        let q = action.settled_coordinates().unwrap();
        let untouched = action.contacts_not_touched();
        for name in ["backcheck", "let_off_button", "drop_screw", "front_rail"] {
            assert!(untouched.iter().any(|u| u == name), "{name}: {untouched:?}");
        }
        for name in ["back_rail", "capstan_heel", "jack_knuckle"] {
            assert!(
                !untouched.iter().any(|u| u == name),
                "{name}: {untouched:?}"
            );
        }
        assert_eq!(Action::rest_coordinates(&file, kind).unwrap(), q);
        let mut other = file.clone();
        other.contacts.backcheck.k *= 1.3;
        other.contacts.backcheck.mu *= 0.7;
        other.contacts.let_off_button.k *= 2.0;
        let fresh = Action::build(&other, kind)
            .unwrap()
            .settled_coordinates()
            .unwrap();
        assert_eq!(fresh, q, "the untouched laws moved the rest");
        assert_eq!(Action::rest_coordinates(&other, kind).unwrap(), fresh);
        let mut cloth = file.clone();
        cloth.contacts.back_rail.k *= 1.3;
        let settled = Action::rest_coordinates(&cloth, kind).unwrap();
        let fresh = Action::build(&cloth, kind)
            .unwrap()
            .settled_coordinates()
            .unwrap();
        assert_eq!(settled, fresh);
        assert_ne!(
            settled, q,
            "a softer back-rail cloth leaves the key where it was"
        );
        // A back-check of a law with a state (Stulov's felt) acts from the start and takes
        // the system's Jacobian by differences: it settles on its own, whatever is
        // remembered for the file's back-check.
        let stulov = |m: &mbs_mechanism::Mechanism| -> Result<mbs_mechanism::Mechanism> {
            let mut m = m.clone();
            for c in m.contacts.iter_mut().filter(|c| c.name == "backcheck") {
                c.law = mbs_mechanism::LawSpec::Material("hammer_felt_Stulov".into());
            }
            Ok(m)
        };
        let remembered = Action::rest_coordinates_transformed(&file, kind, &stulov).unwrap();
        let mechanism = stulov(&crate::describe::grand_mechanism(&file, kind, None).unwrap());
        let own = Action::from_mechanism(&file, kind, None, &mechanism.unwrap()).unwrap();
        assert_eq!(remembered, own.settled_coordinates().unwrap());
        assert!(own.contacts_not_touched().iter().all(|c| c != "backcheck"));
    }

    /// A mass drop whose back-check differs from one simulated before goes on from that
    /// run's last checkpoint before the hammer first met the back-check, and its run is
    /// the one simulated whole, to the last bit (output, events, the work's counts); one
    /// whose back-rail cloth differs (it acts from the start) is simulated whole.
    #[test]
    fn a_drop_that_differs_in_a_law_not_yet_acted_goes_on_from_a_remembered_run() {
        use crate::simulate::{Input, prepare, simulate};
        let kind = ModelKind::Double;
        let file = ActionParams::reference();
        // An uncommon height: no other test's runs are remembered for it.
        let input = Input::MassDrop {
            mass_kg: 1.0,
            height_m: 0.371e-3,
        };
        let (t_end, step) = (0.12, 2e-5);
        let drop = |p: &ActionParams| {
            let prepared = prepare(p, kind, &input).unwrap();
            resumed_or_solved(&prepared.action, &input, &prepared.x0, t_end, 1e-3, step).unwrap()
        };
        let mut check = file.clone();
        check.contacts.backcheck.k *= 1.3;
        check.contacts.backcheck.mu *= 0.7;
        let whole = simulate(&check, kind, &input, t_end, step).unwrap();
        let caught = whole
            .check_time_s
            .expect("the back-check catches the hammer");
        // Other tests' runs may push the first out of the memory meanwhile: tried again.
        let mut resumed = None;
        for _ in 0..3 {
            let (base, _) = drop(&file);
            let plain = simulate(&file, kind, &input, t_end, step).unwrap();
            assert_eq!(base, plain.solution);
            let (solution, from) = drop(&check);
            assert_eq!(solution, whole.solution);
            if let Some(t) = from {
                resumed = Some(t);
                break;
            }
        }
        let from = resumed.expect("it went on from the remembered run");
        assert!(
            from > 0.5 * caught && from < caught,
            "from {from} s, caught at {caught} s"
        );
        let mut cloth = file.clone();
        cloth.contacts.back_rail.k *= 1.3;
        let (solution, from) = drop(&cloth);
        assert_eq!(from, None);
        let plain = simulate(&cloth, kind, &input, t_end, step).unwrap();
        assert_eq!(solution, plain.solution);
    }
}
