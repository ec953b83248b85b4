//! The [`ForceElement`] trait through which springs, friction, contacts and inputs add
//! generalized forces to a [`crate::System`].

use crate::data::Data;
use crate::kinematics;
use crate::model::{BodyId, Model};
use crate::spatial::{Force, Transform};

/// Checks that coordinate `k` of `model` is the joint `joint` (for elements built on one
/// model and added to a system of another).
pub(crate) fn check_coordinate(
    model: &Model,
    element: &str,
    joint: &str,
    k: usize,
) -> crate::Result<()> {
    if model.coordinate_id(joint).ok() == Some(k) {
        Ok(())
    } else {
        Err(crate::CoreError::InvalidParameter {
            item: element.to_string(),
            message: format!(
                "built for another model: this model's coordinate {k} is not joint '{joint}'"
            ),
        })
    }
}

/// Checks that `frame` of `model` is carried by `body` (see [`check_coordinate`]).
pub(crate) fn check_frame(
    model: &Model,
    element: &str,
    frame: Option<&str>,
    body: BodyId,
) -> crate::Result<()> {
    let ok = match frame {
        None => body == BodyId::GROUND,
        Some(f) => model
            .frame_id(f)
            .map(|id| model.frame(id).body == body)
            .unwrap_or(false),
    };
    if ok {
        Ok(())
    } else {
        Err(crate::CoreError::InvalidParameter {
            item: element.to_string(),
            message: format!(
                "built for another model: frame '{}' is not on the same body here",
                frame.unwrap_or("ground")
            ),
        })
    }
}

/// What a force element sees when it is evaluated: the model, the kinematics of the current
/// state (world poses and body velocities are up to date), time, coordinates and the
/// element's own internal states.
pub struct ForceContext<'a> {
    /// The model.
    pub model: &'a Model,
    /// Workspace with poses and velocities of the current `(q, v)`.
    pub data: &'a Data,
    /// Time (s).
    pub t: f64,
    /// Generalized coordinates (prescribed ones already set from their drives).
    pub q: &'a [f64],
    /// Generalized velocities.
    pub v: &'a [f64],
    /// This element's internal states (empty when it has none).
    pub states: &'a [f64],
    /// This element's position-stage results at this state
    /// ([`ForceElement::positions`]), or empty when there are none: they were computed once
    /// for the state's time and coordinates and are shared by every evaluation there.
    pub positions: &'a [f64],
}

impl ForceContext<'_> {
    /// World position of a point fixed to `body` (coordinates in its joint frame).
    pub fn point_position(&self, body: BodyId, p_b: [f64; 2]) -> [f64; 2] {
        kinematics::point_position(self.data, body, p_b)
    }

    /// World velocity of a point fixed to `body`.
    pub fn point_velocity(&self, body: BodyId, p_b: [f64; 2]) -> [f64; 2] {
        kinematics::point_velocity(self.data, body, p_b)
    }

    /// World pose of a body's joint frame.
    pub fn body_pose(&self, body: BodyId) -> Transform {
        self.data.body_pose(body)
    }

    /// Angular velocity of a body (rad/s).
    pub fn angular_velocity(&self, body: BodyId) -> f64 {
        self.data.body_velocity(body).w
    }
}

/// Where force elements put their loads: generalized forces by coordinate, and forces and
/// torques on bodies in world coordinates. Loads on the ground are accepted and ignored.
pub struct Loads<'a> {
    pub(crate) tau: &'a mut [f64],
    /// World spatial force on each body, about the world origin.
    pub(crate) body_forces: &'a mut [Force],
}

impl<'a> Loads<'a> {
    /// Loads accumulating into `tau` (length nv) and `body_forces` (world spatial forces about
    /// the world origin, length nbodies). `System` makes these; build one directly to test an
    /// element's [`ForceElement::apply`] on its own.
    pub fn new(tau: &'a mut [f64], body_forces: &'a mut [Force]) -> Self {
        Self { tau, body_forces }
    }

    /// Generalized forces added so far.
    pub fn generalized(&self) -> &[f64] {
        self.tau
    }

    /// World spatial forces (about the world origin) added so far, per body.
    pub fn body_forces(&self) -> &[Force] {
        self.body_forces
    }

    /// Adds `value` to the generalized force of coordinate `k`.
    #[inline]
    pub fn add_generalized(&mut self, k: usize, value: f64) {
        self.tau[k] += value;
    }

    /// Adds a force `f_w` (world coordinates) applied at the world point `p_w` to `body`.
    #[inline]
    pub fn add_force_at_point(&mut self, body: BodyId, p_w: [f64; 2], f_w: [f64; 2]) {
        self.body_forces[body.index()] += Force::at_point(p_w, f_w);
    }

    /// Adds a pure torque (N·m, about z) to `body`.
    #[inline]
    pub fn add_torque(&mut self, body: BodyId, torque: f64) {
        self.body_forces[body.index()].n += torque;
    }
}

/// Direction of a switching function's zero crossing: which crossings count as events
/// (declared by an element, see [`ForceElement::switch_direction`]), and which way an event
/// went (recorded by the integrators, never `Both` there). The one crossing type of the
/// core and the integrators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// From negative to positive.
    Rising,
    /// From positive to negative.
    Falling,
    /// Either way.
    Both,
}

impl Crossing {
    /// Whether going from `g0` to `g1` is a crossing in this direction. Zero counts as the
    /// non-negative side, so a crossing is never counted twice and a function reset to
    /// exactly zero still sees its next crossing.
    pub fn crosses(self, g0: f64, g1: f64) -> bool {
        let rising = g0 < 0.0 && g1 >= 0.0;
        let falling = g0 >= 0.0 && g1 < 0.0;
        match self {
            Crossing::Rising => rising,
            Crossing::Falling => falling,
            Crossing::Both => rising || falling,
        }
    }

    /// The way a function went from `g0` (before) to the other side: `Rising` from a
    /// negative value, `Falling` from a non-negative one.
    pub fn observed(g0: f64) -> Crossing {
        if g0 < 0.0 {
            Crossing::Rising
        } else {
            Crossing::Falling
        }
    }
}

/// A source of generalized forces: a spring, friction, a contact, an input. Elements are
/// immutable during a simulation; anything that evolves (felt memory, friction state) is an
/// internal state integrated with the system, whose rate the element writes.
///
/// Implementations must not allocate in [`ForceElement::apply`].
pub trait ForceElement: Send + Sync {
    /// A name for messages and output.
    fn name(&self) -> &str;

    /// Checks that the element fits `model` (the joints and frames it was built with are
    /// there, at the same indices); `System::add_element` calls it. The default accepts any
    /// model.
    fn check_model(&self, _model: &Model) -> crate::Result<()> {
        Ok(())
    }

    /// Number of internal states.
    fn state_count(&self) -> usize {
        0
    }

    /// Initial values of the internal states (zero by default).
    fn initial_states(&self, _model: &Model, out: &mut [f64]) {
        out.fill(0.0);
    }

    /// Adds this element's loads for the state in `ctx`, and writes the rates of its
    /// internal states into `state_rates` (length [`ForceElement::state_count`]).
    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, state_rates: &mut [f64]);

    /// Stored (potential) energy of the element, for energy balances (J); zero by default.
    fn potential_energy(&self, _ctx: &ForceContext<'_>) -> f64 {
        0.0
    }

    /// Which of this element's internal states (local indices) an implicit integrator may
    /// leave out of its Jacobian, their columns taken as zero. That holds for states whose
    /// rates move them only along directions that, at a fixed time, change neither the
    /// loads nor any rate: the part of the iteration matrix left out is then nilpotent at the
    /// Jacobian's time and the modified Newton iteration converges as with the full matrix
    /// there (away from it, as with any Jacobian kept across stages). Example: modal
    /// amplitudes in variation-of-constants form driven by a force that depends on the
    /// modal displacement only (`mbs_contact::StringContact` with a rate-independent
    /// felt). None (`0..0`) by default.
    fn states_outside_jacobian(&self) -> std::ops::Range<usize> {
        0..0
    }

    /// Whether [`ForceElement::load_derivatives`] gives this element's derivatives, so that
    /// a [`crate::System`] made only of such elements has a Jacobian
    /// ([`crate::System::jacobian`]). `false` by default.
    fn has_load_derivatives(&self) -> bool {
        false
    }

    /// Writes the derivatives of this element's loads and internal-state rates at the state
    /// in `ctx` into `jac` (see [`crate::LoadJacobian`] for what is kept and what is left
    /// out). Called only when [`ForceElement::has_load_derivatives`] is `true`; must not
    /// allocate. Columns of [`ForceElement::states_outside_jacobian`] are taken as zero
    /// whatever is written there.
    fn load_derivatives(&self, _ctx: &ForceContext<'_>, _jac: &mut crate::LoadJacobian<'_>) {}

    /// How many numbers this element keeps from the **position stage**: results that depend
    /// on the poses alone (time and coordinates, not velocities nor internal states), such
    /// as a contact's nearest points. The system computes them once per time and
    /// coordinates ([`ForceElement::positions`]) and hands them to every evaluation there in
    /// [`ForceContext::positions`]: the derivative, the switching functions, a Jacobian's
    /// velocity and internal-state columns, outputs. None (0) by default.
    fn position_len(&self) -> usize {
        0
    }

    /// Writes the position-stage results for the poses in `ctx` (its `positions` is empty
    /// here), `out` of length [`ForceElement::position_len`]. Must not allocate, and must
    /// not read velocities or internal states.
    fn positions(&self, _ctx: &ForceContext<'_>, _out: &mut [f64]) {}

    /// Number of switching functions (for event location by integrators).
    fn switch_count(&self) -> usize {
        0
    }

    /// Values of the switching functions (length [`ForceElement::switch_count`]); an event
    /// happens where one crosses zero.
    fn switching_functions(&self, _ctx: &ForceContext<'_>, _out: &mut [f64]) {}

    /// Which crossings of switching function `k` are events.
    fn switch_direction(&self, _k: usize) -> Crossing {
        Crossing::Both
    }

    /// The element as [`Any`](std::any::Any), for code that knows its concrete type and
    /// needs what the trait does not expose (a contact's shapes, to draw them):
    /// `element.as_any()?.downcast_ref::<MyElement>()`. `None` by default; an element that
    /// offers it returns `Some(self)`.
    fn as_any(&self) -> Option<&dyn std::any::Any> {
        None
    }
}
