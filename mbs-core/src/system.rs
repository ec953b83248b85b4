//! [`System`]: a model plus force elements and prescribed coordinates, giving the state
//! derivative of `x = [q, v, internal states]`.

use std::ops::Range;
use std::sync::Arc;

use nalgebra::DMatrix;

use crate::aba::{Prescribed, articulated_pass};
use crate::crba::crba_pass;
use crate::data::Data;
use crate::energy::{kinetic_energy_from_kinematics, potential_energy_from_poses};
use crate::error::{CoreError, Result};
use crate::force::{Crossing, ForceContext, ForceElement, Loads};
use crate::kinematics::kinematics_pass;
use crate::load_jacobian::LoadJacobian;
use crate::model::Model;
use crate::rnea::body_forces_to_generalized;
use crate::rnea::{Output, rnea_pass};
use crate::spatial::Force;
use crate::time_function::{Drive, DriveState};

/// A model with its force elements and prescribed (driven) coordinates. The state is
/// `x = [q (nv), v (nv), internal states of the elements in order]`; [`System::derivative`]
/// gives `ẋ = [v, q̈, state rates]` with `q̈` from the articulated-body algorithm (hybrid
/// dynamics when coordinates are prescribed).
///
/// A `System` is cheap to clone (the model and the elements are shared, behind `Arc`);
/// each thread evaluating it needs its own [`Workspace`].
///
/// ```
/// use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement, System};
/// use mbs_core::elements::{JointSpringDamper, SpringLaw};
/// let mut b = ModelBuilder::new();
/// b.add_link("arm", None, JointKind::Revolute, Placement::default(),
///            BodySpec::new(1.0, [0.0, 0.0], 0.5));
/// let model = b.build().unwrap();
/// let spring = JointSpringDamper::new(&model, "arm", SpringLaw::new(2.0, 0.0)).unwrap();
/// let mut system = System::new(model);
/// system.add_element(spring).unwrap();
/// let mut ws = system.workspace();
/// let x = [0.1, 0.0];
/// let mut xdot = [0.0; 2];
/// system.derivative(&mut ws, 0.0, &x, &mut xdot).unwrap();
/// // θ̈ = −k θ / I = −2 · 0.1 / 0.5
/// assert!((xdot[1] + 0.4).abs() < 1e-12);
/// ```
#[derive(Clone)]
pub struct System {
    model: Arc<Model>,
    entries: Vec<Entry>,
    state_len: usize,
    switch_len: usize,
    drives: Vec<Option<Arc<dyn Drive>>>,
    mask: Vec<bool>,
    /// Length of the position-stage results over all elements.
    position_len: usize,
    /// Changes whenever the system does (an element added, a drive set or released), so a
    /// workspace's position stage is never reused across systems that differ.
    revision: u64,
}

/// A fresh revision number (unique in the process).
fn next_revision() -> u64 {
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(1);
    NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// A force element with the ranges of its internal states (in x), switching functions and
/// position-stage results, fixed when it is added.
#[derive(Clone)]
struct Entry {
    element: Arc<dyn ForceElement>,
    states: Range<usize>,
    switches: Range<usize>,
    positions: Range<usize>,
}

/// Per-thread scratch space for evaluating a [`System`]: allocated once by
/// [`System::workspace`], reused by every evaluation.
#[derive(Clone, Debug)]
pub struct Workspace {
    data: Data,
    q: Vec<f64>,
    v: Vec<f64>,
    tau: Vec<f64>,
    qdd_prescribed: Vec<f64>,
    forces_world: Vec<Force>,
    forces_local: Vec<Force>,
    element_tau: Vec<f64>,
    drive_tau: Vec<f64>,
    scratch_tau: Vec<f64>,
    scratch_forces: Vec<Force>,
    /// The position stage's results ([`ForceElement::positions`]) at `position_key`.
    positions: Vec<f64>,
    /// The system revision, time and coordinates the position stage was computed for
    /// (`None`: not computed).
    position_key: Option<(u64, f64)>,
    position_q: Vec<f64>,
    /// Scratch of [`System::jacobian`] (sized at its first call).
    jacobian: JacobianScratch,
}

/// What [`System::jacobian`] works in.
#[derive(Clone, Debug, Default)]
struct JacobianScratch {
    /// `∂τ/∂x`, nv × len(x).
    dtau: DMatrix<f64>,
    /// Which columns of `x` are outside the Jacobian.
    outside: Vec<bool>,
    /// The relative point Jacobian of [`LoadJacobian::set_point`].
    g: Vec<[f64; 2]>,
    /// The free coordinates, and the Cholesky factor of their mass matrix (row-major).
    free: Vec<usize>,
    chol: Vec<f64>,
    rhs: Vec<f64>,
    /// The derivative at the Jacobian's state (for its accelerations), perturbed
    /// coordinates and velocities, the inverse dynamics there, and the data they are computed in.
    xdot: Vec<f64>,
    qp: Vec<f64>,
    vp: Vec<f64>,
    tau0: Vec<f64>,
    data: Option<Data>,
    /// The kinematics at `q + ε v` ([`LoadJacobian::ahead`]), those coordinates, and the
    /// scratch of a gap rate's gradient.
    ahead: Option<Data>,
    q_ahead: Vec<f64>,
    hv: Vec<f64>,
}

impl Workspace {
    /// The dynamics workspace, holding poses, velocities, `qdd` and `tau` of the last
    /// evaluation.
    pub fn data(&self) -> &Data {
        &self.data
    }

    /// Generalized force each drive supplied in the last evaluation to make its coordinate
    /// follow the prescribed motion (zero for free coordinates).
    pub fn drive_forces(&self) -> &[f64] {
        &self.drive_tau
    }

    /// The coordinates used in the last evaluation (prescribed ones from their drives).
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// The velocities used in the last evaluation (prescribed ones from their drives).
    pub fn v(&self) -> &[f64] {
        &self.v
    }
}

/// The energy of a system state, split by origin (J).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Energy {
    /// Kinetic energy.
    pub kinetic: f64,
    /// Gravitational potential energy.
    pub gravity: f64,
    /// Energy stored in force elements (springs).
    pub elastic: f64,
}

impl Energy {
    /// The sum.
    pub fn total(&self) -> f64 {
        self.kinetic + self.gravity + self.elastic
    }
}

impl System {
    /// A system with no force elements and no prescribed coordinate.
    pub fn new(model: Model) -> Self {
        let nv = model.nv();
        Self {
            state_len: 2 * nv,
            switch_len: 0,
            model: Arc::new(model),
            entries: Vec::new(),
            drives: vec![None; nv],
            mask: vec![false; nv],
            position_len: 0,
            revision: next_revision(),
        }
    }

    /// The model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Adds a force element; returns its index. Fails when the element was built for
    /// another model (its joints or frames do not match this one).
    pub fn add_element(&mut self, element: impl ForceElement + 'static) -> Result<usize> {
        self.add_shared_element(Arc::new(element))
    }

    /// Adds a shared force element; returns its index (see [`System::add_element`]).
    pub fn add_shared_element(&mut self, element: Arc<dyn ForceElement>) -> Result<usize> {
        element.check_model(&self.model)?;
        let states = self.state_len..self.state_len + element.state_count();
        let switches = self.switch_len..self.switch_len + element.switch_count();
        let positions = self.position_len..self.position_len + element.position_len();
        self.state_len = states.end;
        self.switch_len = switches.end;
        self.position_len = positions.end;
        self.revision = next_revision();
        self.entries.push(Entry {
            element,
            states,
            switches,
            positions,
        });
        Ok(self.entries.len() - 1)
    }

    /// The force elements, in order.
    pub fn elements(&self) -> impl ExactSizeIterator<Item = &dyn ForceElement> + '_ {
        self.entries.iter().map(|e| e.element.as_ref())
    }

    /// Makes the joint named `joint` follow `drive`: its coordinate and velocity are taken
    /// from the drive (whatever the state holds) and the force needed is reported by
    /// [`Workspace::drive_forces`].
    pub fn prescribe(&mut self, joint: &str, drive: impl Drive + 'static) -> Result<()> {
        let k = self.model.coordinate_id(joint)?;
        self.drives[k] = Some(Arc::new(drive));
        self.mask[k] = true;
        self.revision = next_revision();
        Ok(())
    }

    /// Removes the drive of a joint, making it free again.
    pub fn release(&mut self, joint: &str) -> Result<()> {
        let k = self.model.coordinate_id(joint)?;
        self.drives[k] = None;
        self.mask[k] = false;
        self.revision = next_revision();
        Ok(())
    }

    /// Whether each coordinate is prescribed.
    pub fn prescribed_mask(&self) -> &[bool] {
        &self.mask
    }

    /// Length of the state vector.
    pub fn state_len(&self) -> usize {
        self.state_len
    }

    /// Number of switching functions over all elements.
    pub fn switch_len(&self) -> usize {
        self.switch_len
    }

    /// Range of element `e`'s internal states in the state vector (`None` if there is no
    /// element `e`).
    pub fn element_state_range(&self, e: usize) -> Option<Range<usize>> {
        self.entries.get(e).map(|en| en.states.clone())
    }

    /// The ranges of internal states an implicit integrator may leave out of its Jacobian
    /// ([`ForceElement::states_outside_jacobian`]).
    pub fn states_outside_jacobian(&self) -> Vec<Range<usize>> {
        self.states_outside_ranges().collect()
    }

    /// The element and local index of switching function `k`, and its crossing direction.
    pub fn switch_info(&self, k: usize) -> Option<(usize, usize, Crossing)> {
        let e = self
            .entries
            .iter()
            .position(|en| en.switches.contains(&k))?;
        let local = k - self.entries[e].switches.start;
        Some((e, local, self.entries[e].element.switch_direction(local)))
    }

    /// A workspace for evaluating this system.
    pub fn workspace(&self) -> Workspace {
        let nv = self.model.nv();
        let nb = self.model.nbodies();
        Workspace {
            data: Data::new(&self.model),
            q: vec![0.0; nv],
            v: vec![0.0; nv],
            tau: vec![0.0; nv],
            qdd_prescribed: vec![0.0; nv],
            forces_world: vec![Force::ZERO; nb],
            forces_local: vec![Force::ZERO; nb],
            element_tau: vec![0.0; nv],
            drive_tau: vec![0.0; nv],
            scratch_tau: vec![0.0; nv],
            scratch_forces: vec![Force::ZERO; nb],
            positions: vec![0.0; self.position_len],
            position_key: None,
            position_q: vec![0.0; nv],
            jacobian: JacobianScratch::default(),
        }
    }

    /// The initial state for coordinates `q0` and velocities `v0` at time `t0`: prescribed
    /// coordinates take their drive's values, internal states their elements' initial
    /// values.
    pub fn initial_state(&self, t0: f64, q0: &[f64], v0: &[f64]) -> Result<Vec<f64>> {
        let nv = self.model.nv();
        crate::error::check_input("q0", q0, nv)?;
        crate::error::check_input("v0", v0, nv)?;
        let mut x = vec![0.0; self.state_len];
        x[..nv].copy_from_slice(q0);
        x[nv..2 * nv].copy_from_slice(v0);
        for (k, d) in self.drives.iter().enumerate() {
            if let Some(d) = d {
                let s = self.eval_drive(d.as_ref(), k, t0)?;
                x[k] = s.q;
                x[nv + k] = s.v;
            }
        }
        for en in &self.entries {
            en.element
                .initial_states(&self.model, &mut x[en.states.clone()]);
        }
        Ok(x)
    }

    fn eval_drive(&self, d: &dyn Drive, k: usize, t: f64) -> Result<DriveState> {
        let s = d.eval(t);
        if s.q.is_finite() && s.v.is_finite() && s.a.is_finite() {
            Ok(s)
        } else {
            Err(CoreError::NonFiniteOutput {
                t,
                source_name: format!("drive of joint '{}'", self.model.joint_names[k]),
                quantity: "motion",
            })
        }
    }

    /// What entry `index` of the state vector is, for messages.
    pub fn state_meaning(&self, index: usize) -> String {
        let nv = self.model.nv();
        if index < nv {
            format!("q of joint '{}'", self.model.joint_names[index])
        } else if index < 2 * nv {
            format!("v of joint '{}'", self.model.joint_names[index - nv])
        } else if let Some(en) = self.entries.iter().find(|en| en.states.contains(&index)) {
            format!(
                "internal state {} of {}",
                index - en.states.start,
                en.element.name()
            )
        } else {
            format!("index {index} beyond the state length {}", self.state_len)
        }
    }

    fn check_state(&self, t: f64, x: &[f64]) -> Result<()> {
        crate::error::check_input("x", x, self.state_len).map_err(|e| match e {
            CoreError::NonFiniteInput { index, value, .. } => CoreError::NonFiniteState {
                t,
                index,
                meaning: self.state_meaning(index),
                value,
            },
            other => other,
        })
    }

    /// What element code sees: kinematics of the workspace, time, its own states and its
    /// position-stage results.
    #[allow(clippy::too_many_arguments)]
    fn context<'a>(
        &'a self,
        data: &'a Data,
        q: &'a [f64],
        v: &'a [f64],
        t: f64,
        states: &'a [f64],
        positions: &'a [f64],
    ) -> ForceContext<'a> {
        ForceContext {
            model: &self.model,
            data,
            t,
            q,
            v,
            states,
            positions,
        }
    }

    /// The context of entry `en` at `(t, x)` from the workspace's last `prepare`.
    fn entry_context<'a>(
        &'a self,
        ws: &'a Workspace,
        t: f64,
        x: &'a [f64],
        en: &Entry,
    ) -> ForceContext<'a> {
        self.context(
            &ws.data,
            &ws.q,
            &ws.v,
            t,
            &x[en.states.clone()],
            &ws.positions[en.positions.clone()],
        )
    }

    /// Loads q, v (drives applied) and runs kinematics.
    fn prepare(&self, ws: &mut Workspace, t: f64, x: &[f64]) -> Result<()> {
        self.prepare_kinematics(ws, t, x)?;
        self.position_stage(ws, t);
        Ok(())
    }

    /// [`System::prepare`] without the position stage: the poses and velocities alone, for
    /// outputs that read no element's results.
    fn prepare_kinematics(&self, ws: &mut Workspace, t: f64, x: &[f64]) -> Result<()> {
        if ws.q.len() != self.model.nv() || ws.forces_world.len() != self.model.nbodies() {
            return Err(CoreError::WorkspaceMismatch {
                expected: self.model.nbodies(),
                got: ws.forces_world.len(),
            });
        }
        self.check_state(t, x)?;
        let nv = self.model.nv();
        ws.q.copy_from_slice(&x[..nv]);
        ws.v.copy_from_slice(&x[nv..2 * nv]);
        for (k, d) in self.drives.iter().enumerate() {
            if let Some(d) = d {
                let s = self.eval_drive(d.as_ref(), k, t)?;
                ws.q[k] = s.q;
                ws.v[k] = s.v;
                ws.qdd_prescribed[k] = s.a;
            }
        }
        kinematics_pass(&self.model, &mut ws.data, &ws.q, Some(&ws.v));
        Ok(())
    }

    /// The position stage: every element's results that depend on the poses alone, computed
    /// once per system revision, time and coordinates (a Jacobian's velocity columns, the
    /// switching functions after a derivative at the same state, outputs reuse them).
    fn position_stage(&self, ws: &mut Workspace, t: f64) {
        if self.position_len == 0 {
            return;
        }
        if ws.positions.len() != self.position_len {
            // A workspace made before an element was added (allocates once).
            ws.positions.resize(self.position_len, 0.0);
            ws.position_key = None;
        }
        // Bit for bit: the same coordinates give the same poses, hence the same results.
        let same = ws.position_key.is_some_and(|(rev, t0)| {
            rev == self.revision
                && t0.to_bits() == t.to_bits()
                && ws
                    .position_q
                    .iter()
                    .zip(&ws.q)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
        });
        if same {
            return;
        }
        for en in &self.entries {
            if en.positions.is_empty() {
                continue;
            }
            let ctx = ForceContext {
                model: &self.model,
                data: &ws.data,
                t,
                q: &ws.q,
                v: &ws.v,
                states: &[],
                positions: &[],
            };
            en.element
                .positions(&ctx, &mut ws.positions[en.positions.clone()]);
        }
        ws.position_key = Some((self.revision, t));
        ws.position_q.copy_from_slice(&ws.q);
    }

    /// The state derivative `ẋ = f(t, x)`, written into `xdot`. Allocates nothing.
    ///
    /// Errors: wrong lengths, a non-finite state (named), a drive or element producing a
    /// non-finite value (named).
    pub fn derivative(
        &self,
        ws: &mut Workspace,
        t: f64,
        x: &[f64],
        xdot: &mut [f64],
    ) -> Result<()> {
        if xdot.len() != self.state_len {
            return Err(CoreError::DimensionMismatch {
                what: "xdot",
                expected: self.state_len,
                got: xdot.len(),
            });
        }
        self.prepare(ws, t, x)?;
        let nv = self.model.nv();
        ws.tau.fill(0.0);
        ws.forces_world.fill(Force::ZERO);
        let (head, rates) = xdot.split_at_mut(2 * nv);
        for en in &self.entries {
            let r = en.states.clone();
            let ctx = self.context(
                &ws.data,
                &ws.q,
                &ws.v,
                t,
                &x[r.clone()],
                &ws.positions[en.positions.clone()],
            );
            let mut loads = Loads::new(&mut ws.tau, &mut ws.forces_world);
            en.element.apply(
                &ctx,
                &mut loads,
                &mut rates[r.start - 2 * nv..r.end - 2 * nv],
            );
        }
        let loads_finite = ws.tau.iter().all(|v| v.is_finite())
            && ws.forces_world.iter().all(Force::is_finite)
            && rates.iter().all(|v| v.is_finite());
        if !loads_finite {
            return Err(self.find_bad_element(ws, t, x));
        }
        // World forces about the world origin → body frames.
        for i in 1..self.model.nbodies() {
            ws.forces_local[i] = ws.data.x_world[i].apply_force(&ws.forces_world[i]);
        }
        let prescribed = self.mask.iter().any(|&m| m).then_some(Prescribed {
            mask: &self.mask,
            qdd: &ws.qdd_prescribed,
        });
        articulated_pass(
            &self.model,
            &mut ws.data,
            &ws.v,
            &ws.tau,
            Some(&ws.forces_local),
            prescribed,
        );
        // What the drives had to add to the elements' direct generalized forces.
        for k in 0..nv {
            ws.drive_tau[k] = if self.mask[k] {
                ws.data.tau[k] - ws.tau[k]
            } else {
                0.0
            };
        }
        head[..nv].copy_from_slice(&ws.v);
        head[nv..].copy_from_slice(ws.data.qdd.as_slice());
        if let Some(k) = head[nv..].iter().position(|a| !a.is_finite()) {
            return Err(CoreError::NonFiniteOutput {
                t,
                source_name: format!("dynamics of joint '{}'", self.model.joint_names[k]),
                quantity: "acceleration",
            });
        }
        Ok(())
    }

    /// Whether every force element gives its load derivatives
    /// ([`ForceElement::has_load_derivatives`]), so that [`System::jacobian`] applies.
    pub fn has_jacobian(&self) -> bool {
        self.entries
            .iter()
            .all(|en| en.element.has_load_derivatives())
    }

    /// The Jacobian `∂ẋ/∂x` of [`System::derivative`] at `(t, x)`, written into `jac`
    /// (len(x) × len(x)), from the force elements' load derivatives
    /// ([`ForceElement::load_derivatives`]):
    ///
    /// - `∂q̇/∂v = I` for the free coordinates;
    /// - `∂q̈_f/∂x = M_ff⁻¹ ∂τ_f/∂x` for the free ones `f` (`M_ff` their block of the mass
    ///   matrix, prescribed accelerations held), zero for prescribed ones;
    /// - the internal states' rows as their elements give them;
    /// - the columns of prescribed coordinates zero (their states are not read).
    ///
    /// with the inertial part `−∂(M q̈ + C + g)/∂q` and `−∂C/∂v` at this state's
    /// accelerations taken by forward differences of inverse dynamics (a stiff contact makes
    /// `q̈` large, and with it the change of `M q̈` with the pose).
    ///
    /// It is not the exact derivative. Left out are the geometric terms listed on
    /// [`LoadJacobian`]
    /// that the elements do not add (lever arms and normals turning with the pose, a slip's
    /// convective part), which touch the coordinate columns only. On the piano action's
    /// loud keystroke the velocity columns agree with central differences to 1e-3
    /// (`piano-action/tests/jacobian.rs`); the coordinate columns of the levers whose
    /// contacts slide under friction can be off by tens of per cent. A Newton iteration or
    /// a Rosenbrock–W method keeps its order with such a matrix; how many steps it costs
    /// depends on what is missing (without the gap rate's convective part, a Rosenbrock
    /// method needed 1 219 steps for the loud keystroke; with it, 751, as many as with
    /// finite differences at every step).
    ///
    /// The columns of [`System::states_outside_jacobian`] are not written: the caller keeps
    /// them zero (they are zero in this Jacobian). Errors: wrong shape, a bad state, an
    /// element without load derivatives (named), a mass matrix that is not positive
    /// definite, a non-finite entry.
    pub fn jacobian(
        &self,
        ws: &mut Workspace,
        t: f64,
        x: &[f64],
        jac: &mut DMatrix<f64>,
    ) -> Result<()> {
        self.jacobian_with_rate(ws, t, x, None, jac)
    }

    /// [`System::jacobian`] given the derivative `xdot` at `(t, x)` when the caller has it
    /// (an integrator always does), which saves evaluating it again for the accelerations.
    pub fn jacobian_with_rate(
        &self,
        ws: &mut Workspace,
        t: f64,
        x: &[f64],
        xdot: Option<&[f64]>,
        jac: &mut DMatrix<f64>,
    ) -> Result<()> {
        let n = self.state_len;
        if let Some(f) = xdot
            && f.len() != n
        {
            return Err(CoreError::DimensionMismatch {
                what: "xdot",
                expected: n,
                got: f.len(),
            });
        }
        if jac.nrows() != n || jac.ncols() != n {
            return Err(CoreError::ShapeMismatch {
                what: "system jacobian",
                expected: (n, n),
                got: (jac.nrows(), jac.ncols()),
            });
        }
        if let Some(en) = self
            .entries
            .iter()
            .find(|en| !en.element.has_load_derivatives())
        {
            return Err(CoreError::InvalidParameter {
                item: en.element.name().to_string(),
                message: "gives no load derivatives, so the system has no Jacobian".into(),
            });
        }
        self.prepare(ws, t, x)?;
        let nv = self.model.nv();
        let mut sc = std::mem::take(&mut ws.jacobian);
        if sc.dtau.shape() != (nv, n) {
            sc.dtau = DMatrix::zeros(nv, n);
            sc.g = vec![[0.0; 2]; nv];
            sc.rhs = vec![0.0; nv];
            sc.chol = vec![0.0; nv * nv];
            sc.free = Vec::with_capacity(nv);
        }
        sc.outside.clear();
        sc.outside.resize(n, false);
        for r in self.states_outside_ranges() {
            sc.outside[r].fill(true);
        }
        sc.dtau.as_mut_slice().fill(0.0);
        for c in 0..n {
            if !sc.outside[c] {
                jac.as_mut_slice()[c * n..(c + 1) * n].fill(0.0);
            }
        }
        // The poses a short time ahead along the velocities, for the elements' convective
        // terms: ε moves no coordinate by more than 1e-7 (rad or m).
        let v_max = ws.v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let eps = if v_max > 0.0 { 1e-7 / v_max } else { 0.0 };
        if eps > 0.0 {
            sc.q_ahead.clear();
            sc.q_ahead
                .extend(ws.q.iter().zip(&ws.v).map(|(q, v)| q + eps * v));
            let d = sc.ahead.get_or_insert_with(|| Data::new(&self.model));
            kinematics_pass(&self.model, d, &sc.q_ahead, Some(&ws.v));
        }
        sc.hv.resize(nv, 0.0);
        for en in &self.entries {
            let ctx = self.entry_context(ws, t, x, en);
            let ahead = match (&sc.ahead, eps > 0.0) {
                (Some(d), true) => Some((d, sc.q_ahead.as_slice(), eps)),
                _ => None,
            };
            let mut lj = LoadJacobian {
                ahead,
                hv: &mut sc.hv,
                model: &self.model,
                data: &ws.data,
                dtau: &mut sc.dtau,
                jac,
                states: en.states.clone(),
                outside: &sc.outside,
                g: &mut sc.g,
            };
            en.element.load_derivatives(&ctx, &mut lj);
        }
        // The inertial part at the accelerations of this state: −∂(M q̈ + C + g)/∂q at fixed
        // q̈ and v, and −∂C/∂v, by forward differences of inverse dynamics (stiff loads make
        // q̈ large, and with it the change of M q̈ with the pose).
        sc.xdot.resize(n, 0.0);
        match xdot {
            Some(f) => sc.xdot.copy_from_slice(f),
            None => {
                let mut xdot = std::mem::take(&mut sc.xdot);
                let derivative = self.derivative(ws, t, x, &mut xdot);
                sc.xdot = xdot;
                if let Err(e) = derivative {
                    ws.jacobian = sc;
                    return Err(e);
                }
            }
        }
        {
            let qdd = &sc.xdot[nv..2 * nv];
            let data = sc.data.get_or_insert_with(|| Data::new(&self.model));
            let inverse_dynamics = |data: &mut Data, q: &[f64], v: &[f64]| {
                rnea_pass(
                    &self.model,
                    data,
                    Some(q),
                    Some(v),
                    Some(qdd),
                    None,
                    Output::Tau,
                );
            };
            sc.qp.clear();
            sc.qp.extend_from_slice(&ws.q);
            inverse_dynamics(data, &sc.qp, &ws.v);
            sc.tau0.clear();
            sc.tau0.extend_from_slice(data.tau.as_slice());
            // Each free coordinate, then each free velocity, moved in turn.
            sc.vp.clear();
            sc.vp.extend_from_slice(&ws.v);
            for (velocity, offset) in [(false, 0), (true, nv)] {
                for j in (0..nv).filter(|&j| !self.mask[j]) {
                    let moved = if velocity { &mut sc.vp } else { &mut sc.qp };
                    let old = moved[j];
                    moved[j] = old + 1e-7 * (1.0 + old.abs());
                    let h = moved[j] - old;
                    inverse_dynamics(data, &sc.qp, &sc.vp);
                    for i in 0..nv {
                        sc.dtau[(i, offset + j)] -= (data.tau[i] - sc.tau0[i]) / h;
                    }
                    let moved = if velocity { &mut sc.vp } else { &mut sc.qp };
                    moved[j] = old;
                }
            }
        }
        // The free block of the mass matrix, factored.
        crba_pass(&self.model, &mut ws.data, &ws.q);
        sc.free.clear();
        sc.free.extend((0..nv).filter(|&k| !self.mask[k]));
        let nf = sc.free.len();
        for (a, &i) in sc.free.iter().enumerate() {
            for (b, &j) in sc.free.iter().enumerate() {
                sc.chol[a * nf + b] = ws.data.mass_matrix[(i, j)];
            }
        }
        if !cholesky_in_place(&mut sc.chol[..nf * nf], nf) {
            ws.jacobian = sc;
            return Err(CoreError::NonFiniteOutput {
                t,
                source_name: "mass matrix".into(),
                quantity: "positive-definite factor",
            });
        }
        for &k in &sc.free {
            jac[(k, nv + k)] = 1.0;
        }
        for c in 0..n {
            if sc.outside[c] {
                continue;
            }
            let mut any = false;
            for (a, &i) in sc.free.iter().enumerate() {
                sc.rhs[a] = sc.dtau[(i, c)];
                any |= sc.rhs[a] != 0.0;
            }
            if !any {
                continue;
            }
            cholesky_solve(&sc.chol[..nf * nf], nf, &mut sc.rhs[..nf]);
            for (a, &i) in sc.free.iter().enumerate() {
                jac[(nv + i, c)] = sc.rhs[a];
            }
        }
        for k in (0..nv).filter(|&k| self.mask[k]) {
            jac.as_mut_slice()[k * n..(k + 1) * n].fill(0.0);
            jac.as_mut_slice()[(nv + k) * n..(nv + k + 1) * n].fill(0.0);
        }
        // `v · 0` is NaN exactly for a non-finite `v`: one vectorizable sum per column.
        let bad = (0..n).filter(|&c| !sc.outside[c]).find(|&c| {
            let col = &jac.as_slice()[c * n..(c + 1) * n];
            !col.iter().fold(0.0, |acc, v| acc + v * 0.0).is_finite()
        });
        ws.jacobian = sc;
        if let Some(c) = bad {
            return Err(CoreError::NonFiniteOutput {
                t,
                source_name: format!("Jacobian column of {}", self.state_meaning(c)),
                quantity: "derivative",
            });
        }
        Ok(())
    }

    /// [`System::states_outside_jacobian`] without collecting.
    fn states_outside_ranges(&self) -> impl Iterator<Item = Range<usize>> + '_ {
        self.entries.iter().filter_map(|en| {
            let local = en.element.states_outside_jacobian();
            let len = en.states.len();
            let (a, b) = (local.start.min(len), local.end.min(len));
            (a < b).then(|| en.states.start + a..en.states.start + b)
        })
    }

    /// Re-evaluates the elements one at a time to name the one producing non-finite loads
    /// (cold path: only after a failure).
    fn find_bad_element(&self, ws: &mut Workspace, t: f64, x: &[f64]) -> CoreError {
        for en in &self.entries {
            ws.scratch_tau.fill(0.0);
            ws.scratch_forces.fill(Force::ZERO);
            let ctx = self.context(
                &ws.data,
                &ws.q,
                &ws.v,
                t,
                &x[en.states.clone()],
                &ws.positions[en.positions.clone()],
            );
            let mut loads = Loads::new(&mut ws.scratch_tau, &mut ws.scratch_forces);
            let mut rates = vec![0.0; en.states.len()];
            en.element.apply(&ctx, &mut loads, &mut rates);
            let bad = ws.scratch_tau.iter().any(|v| !v.is_finite())
                || ws.scratch_forces.iter().any(|f| !f.is_finite())
                || rates.iter().any(|v| !v.is_finite());
            if bad {
                return CoreError::NonFiniteOutput {
                    t,
                    source_name: en.element.name().to_string(),
                    quantity: "load or state rate",
                };
            }
        }
        CoreError::NonFiniteOutput {
            t,
            source_name: "force elements".into(),
            quantity: "load or state rate",
        }
    }

    /// Total generalized force of the force elements in the last [`System::derivative`],
    /// per coordinate: their direct generalized forces plus their forces on bodies mapped
    /// through the Jacobians (`τ + Σ Jᵀ f`). Computed on request (one backward pass).
    pub fn element_forces<'w>(&self, ws: &'w mut Workspace) -> &'w [f64] {
        body_forces_to_generalized(
            &self.model,
            &ws.data,
            &ws.forces_local,
            &mut ws.scratch_forces,
            &mut ws.element_tau,
        );
        for (e, t) in ws.element_tau.iter_mut().zip(&ws.tau) {
            *e += t;
        }
        &ws.element_tau
    }

    /// Values of all switching functions at `(t, x)`, written into `out` (length
    /// [`System::switch_len`]).
    pub fn switching_functions(
        &self,
        ws: &mut Workspace,
        t: f64,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<()> {
        if out.len() != self.switch_len {
            return Err(CoreError::DimensionMismatch {
                what: "switching function output",
                expected: self.switch_len,
                got: out.len(),
            });
        }
        self.prepare(ws, t, x)?;
        for en in &self.entries {
            let ctx = self.entry_context(ws, t, x, en);
            let out = &mut out[en.switches.clone()];
            // Unwritten values show up as NaN rather than as the caller's stale numbers.
            out.fill(f64::NAN);
            en.element.switching_functions(&ctx, out);
            if out.iter().any(|v| !v.is_finite()) {
                return Err(CoreError::NonFiniteOutput {
                    t,
                    source_name: en.element.name().to_string(),
                    quantity: "switching function",
                });
            }
        }
        Ok(())
    }

    /// The context element `element` sees at `(t, x)` (kinematics computed): for reading an
    /// element's own outputs (a contact's gap and forces, a spring's length) at a state.
    pub fn element_context<'a>(
        &'a self,
        ws: &'a mut Workspace,
        t: f64,
        x: &'a [f64],
        element: usize,
    ) -> Result<ForceContext<'a>> {
        let (states, positions) = self
            .entries
            .get(element)
            .map(|en| (en.states.clone(), en.positions.clone()))
            .ok_or_else(|| CoreError::UnknownName {
                what: "element index",
                name: element.to_string(),
            })?;
        self.prepare(ws, t, x)?;
        Ok(self.context(
            &ws.data,
            &ws.q,
            &ws.v,
            t,
            &x[states],
            &ws.positions[positions],
        ))
    }

    /// The kinematics at `(t, x)`: poses and velocities of every body, with prescribed
    /// coordinates taken from their drives (the context of no element: its `states` are
    /// empty). For outputs such as a marker's speed or a body's pose at a state.
    pub fn kinematics<'a>(
        &'a self,
        ws: &'a mut Workspace,
        t: f64,
        x: &'a [f64],
    ) -> Result<ForceContext<'a>> {
        // No element's results: the contacts' nearest points are not searched.
        self.prepare_kinematics(ws, t, x)?;
        Ok(self.context(&ws.data, &ws.q, &ws.v, t, &x[..0], &[]))
    }

    /// The energy of state `x` at time `t`: kinetic, gravitational and stored in elements.
    pub fn energy(&self, ws: &mut Workspace, t: f64, x: &[f64]) -> Result<Energy> {
        self.prepare(ws, t, x)?;
        let mut elastic = 0.0;
        for en in &self.entries {
            let ctx = self.entry_context(ws, t, x, en);
            let e = en.element.potential_energy(&ctx);
            if !e.is_finite() {
                return Err(CoreError::NonFiniteOutput {
                    t,
                    source_name: en.element.name().to_string(),
                    quantity: "potential energy",
                });
            }
            elastic += e;
        }
        Ok(Energy {
            kinetic: kinetic_energy_from_kinematics(&self.model, &ws.data),
            gravity: potential_energy_from_poses(&self.model, &ws.data),
            elastic,
        })
    }
}

/// Cholesky factor `L` (lower, row-major, in place) of the symmetric `n × n` matrix `a`;
/// `false` when it is not positive definite.
fn cholesky_in_place(a: &mut [f64], n: usize) -> bool {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d.is_nan() || d <= 0.0 {
            return false;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    true
}

/// Solves `L Lᵀ y = b` in place with the factor of [`cholesky_in_place`].
fn cholesky_solve(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * n + k] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[k * n + i] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
}
