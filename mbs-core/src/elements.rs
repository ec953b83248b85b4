//! Standard force elements: joint spring–damper, point-to-point spring–damper, pivot
//! friction, and loads applied as functions of time.

use std::sync::Arc;

use crate::error::{CoreError, Result};
use crate::force::{Crossing, ForceContext, ForceElement, Loads, check_coordinate, check_frame};
use crate::kinematics::frame_point;
use crate::load_jacobian::{LoadJacobian, Wrt, central_difference};
use crate::model::{BodyId, Model};
use crate::time_function::TimeFunction;

fn param(item: &str, field: &str, value: f64, nonneg: bool) -> Result<f64> {
    use crate::check::{Bound, check_value};
    let bound = if nonneg {
        Bound::NonNegative
    } else {
        Bound::Finite
    };
    check_value(value, bound).map_err(|message| CoreError::InvalidParameter {
        item: format!("{item}.{field}"),
        message,
    })
}

/// Linear spring–damper parameters shared by the spring elements.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpringLaw {
    /// Stiffness (N·m/rad, or N/m), non-negative.
    pub stiffness: f64,
    /// Damping (N·m·s/rad, or N·s/m), non-negative.
    pub damping: f64,
    /// Rest angle, displacement or length.
    pub rest: f64,
    /// Force or torque the spring exerts at its rest position.
    pub preload: f64,
}

impl SpringLaw {
    /// A spring with the given stiffness and rest value, no damping, no preload.
    pub fn new(stiffness: f64, rest: f64) -> Self {
        Self {
            stiffness,
            rest,
            ..Self::default()
        }
    }

    /// The same spring with damping `damping`.
    pub fn with_damping(self, damping: f64) -> Self {
        Self { damping, ..self }
    }

    /// The same spring with preload `preload`.
    pub fn with_preload(self, preload: f64) -> Self {
        Self { preload, ..self }
    }

    fn validated(self, item: &str, rest_nonneg: bool) -> Result<Self> {
        Ok(Self {
            stiffness: param(item, "stiffness", self.stiffness, true)?,
            damping: param(item, "damping", self.damping, true)?,
            rest: param(item, "rest", self.rest, rest_nonneg)?,
            preload: param(item, "preload", self.preload, false)?,
        })
    }
}

/// A torsional (or linear, on a prismatic joint) spring–damper on one joint:
/// `τ = preload − k (q − rest) − c q̇`. The preload is the generalized force the spring
/// exerts at its rest position (a pre-tensioned spring), signed along the coordinate.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSpringDamper {
    name: String,
    joint: String,
    coordinate: usize,
    law: SpringLaw,
}

impl JointSpringDamper {
    /// A spring–damper on the joint named `joint`, named after it; stiffness and damping
    /// must be non-negative and everything finite.
    pub fn new(model: &Model, joint: &str, law: SpringLaw) -> Result<Self> {
        let name = format!("joint spring '{joint}'");
        Ok(Self {
            coordinate: model.coordinate_id(joint)?,
            law: law.validated(&name, false)?,
            joint: joint.to_string(),
            name,
        })
    }

    /// The same element under another name.
    pub fn named(self, name: &str) -> Self {
        Self {
            name: name.to_string(),
            ..self
        }
    }

    /// The spring's parameters.
    pub fn law(&self) -> SpringLaw {
        self.law
    }

    /// The generalized force for coordinate value `q` and rate `v`.
    pub fn force(&self, q: f64, v: f64) -> f64 {
        let l = &self.law;
        l.preload - l.stiffness * (q - l.rest) - l.damping * v
    }
}

impl ForceElement for JointSpringDamper {
    fn name(&self) -> &str {
        &self.name
    }

    fn check_model(&self, model: &Model) -> Result<()> {
        check_coordinate(model, &self.name, &self.joint, self.coordinate)
    }

    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, _rates: &mut [f64]) {
        let k = self.coordinate;
        loads.add_generalized(k, self.force(ctx.q[k], ctx.v[k]));
    }

    fn has_load_derivatives(&self) -> bool {
        true
    }

    fn load_derivatives(&self, _ctx: &ForceContext<'_>, jac: &mut LoadJacobian<'_>) {
        let k = self.coordinate;
        jac.add_generalized(k, Wrt::Q(k), -self.law.stiffness);
        jac.add_generalized(k, Wrt::V(k), -self.law.damping);
    }

    fn potential_energy(&self, ctx: &ForceContext<'_>) -> f64 {
        let d = ctx.q[self.coordinate] - self.law.rest;
        0.5 * self.law.stiffness * d * d - self.law.preload * d
    }
}

/// One end of a point-to-point element or the point of an applied force: a frame name
/// (`None` for the ground) and a point given in that frame (in world coordinates for the
/// ground).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Attachment<'a> {
    /// Frame name, `None` for the ground.
    pub frame: Option<&'a str>,
    /// Point in the frame.
    pub point: [f64; 2],
}

impl<'a> Attachment<'a> {
    /// A point fixed to the named frame.
    pub fn on(frame: &'a str, point: [f64; 2]) -> Self {
        Self {
            frame: Some(frame),
            point,
        }
    }

    /// A point fixed to the ground (world coordinates).
    pub fn ground(point: [f64; 2]) -> Self {
        Self { frame: None, point }
    }

    fn resolve(&self, model: &Model, item: &str) -> Result<ResolvedPoint> {
        param(item, "point[0]", self.point[0], false)?;
        param(item, "point[1]", self.point[1], false)?;
        let (body, point) = match self.frame {
            None => (BodyId::GROUND, self.point),
            Some(f) => frame_point(model, model.frame_id(f)?, self.point),
        };
        Ok(ResolvedPoint {
            frame: self.frame.map(str::to_string),
            body,
            point,
        })
    }
}

/// An attachment resolved on a model: the body carrying it and the point in its frame.
#[derive(Clone, Debug, PartialEq)]
struct ResolvedPoint {
    frame: Option<String>,
    body: BodyId,
    point: [f64; 2],
}

impl ResolvedPoint {
    fn check(&self, model: &Model, item: &str) -> Result<()> {
        check_frame(model, item, self.frame.as_deref(), self.body)
    }
}

/// The line between two attached points at a state: their world positions, the unit
/// vector from `a` to `b`, the distance and its rate.
struct Line2 {
    pa: [f64; 2],
    pb: [f64; 2],
    u: [f64; 2],
    l: f64,
    ldot: f64,
}

impl Line2 {
    /// The line at the state in `ctx`, or `None` when the points are no farther apart than
    /// `min_len` (or the distance is not a number).
    fn between(
        ctx: &ForceContext<'_>,
        a: &ResolvedPoint,
        b: &ResolvedPoint,
        min_len: f64,
    ) -> Option<Line2> {
        let pa = ctx.point_position(a.body, a.point);
        let pb = ctx.point_position(b.body, b.point);
        let d = [pb[0] - pa[0], pb[1] - pa[1]];
        let l = d[0].hypot(d[1]);
        if l.is_nan() || l <= min_len {
            return None;
        }
        let u = [d[0] / l, d[1] / l];
        let va = ctx.point_velocity(a.body, a.point);
        let vb = ctx.point_velocity(b.body, b.point);
        // l̇ = (v_b − v_a) · u
        let ldot = (vb[0] - va[0]) * u[0] + (vb[1] - va[1]) * u[1];
        Some(Line2 { pa, pb, u, l, ldot })
    }

    /// A tension `t` along the line, pulling the points together when positive.
    fn pull(&self, loads: &mut Loads<'_>, a: &ResolvedPoint, b: &ResolvedPoint, t: f64) {
        let u = self.u;
        loads.add_force_at_point(a.body, self.pa, [t * u[0], t * u[1]]);
        loads.add_force_at_point(b.body, self.pb, [-t * u[0], -t * u[1]]);
    }
}

/// A linear spring–damper between two body points (or a body point and a ground point):
/// tension `T = preload + k (l − rest) + c l̇` along the line between the points,
/// pulling them together when positive. When the points coincide the direction is undefined
/// and the element exerts no force.
#[derive(Clone, Debug, PartialEq)]
pub struct PointSpringDamper {
    name: String,
    a: ResolvedPoint,
    b: ResolvedPoint,
    law: SpringLaw,
}

impl PointSpringDamper {
    /// A spring–damper from `a` to `b`; stiffness, damping and rest length must be
    /// non-negative (the preload is the tension at rest length). At least one end must be
    /// on a moving body.
    pub fn new(
        model: &Model,
        name: &str,
        a: Attachment<'_>,
        b: Attachment<'_>,
        law: SpringLaw,
    ) -> Result<Self> {
        let item = format!("point spring '{name}'");
        let a = a.resolve(model, &format!("{item}.a"))?;
        let b = b.resolve(model, &format!("{item}.b"))?;
        if a.body == BodyId::GROUND && b.body == BodyId::GROUND {
            return Err(CoreError::InvalidParameter {
                item,
                message: "both ends are fixed to the ground, so it would act on nothing".into(),
            });
        }
        Ok(Self {
            a,
            b,
            law: law.validated(&item, true)?,
            name: item,
        })
    }

    /// The spring's parameters.
    pub fn law(&self) -> SpringLaw {
        self.law
    }

    /// Current length (m), from the poses in `ctx`.
    pub fn length(&self, ctx: &ForceContext<'_>) -> f64 {
        let pa = ctx.point_position(self.a.body, self.a.point);
        let pb = ctx.point_position(self.b.body, self.b.point);
        (pb[0] - pa[0]).hypot(pb[1] - pa[1])
    }
}

impl ForceElement for PointSpringDamper {
    fn name(&self) -> &str {
        &self.name
    }

    fn check_model(&self, model: &Model) -> Result<()> {
        self.a.check(model, &self.name)?;
        self.b.check(model, &self.name)
    }

    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, _rates: &mut [f64]) {
        let Some(line) = Line2::between(ctx, &self.a, &self.b, 1e-12) else {
            return;
        };
        // T = preload + k (l − l₀) + c l̇
        let law = &self.law;
        let t = law.preload + law.stiffness * (line.l - law.rest) + law.damping * line.ldot;
        line.pull(loads, &self.a, &self.b, t);
    }

    fn potential_energy(&self, ctx: &ForceContext<'_>) -> f64 {
        let e = self.length(ctx) - self.law.rest;
        0.5 * self.law.stiffness * e * e + self.law.preload * e
    }
}

/// A cord (a tape, a string, a wire loop) between two body points: it pulls with tension
/// `T = k (l − length) + c l̇` when stretched beyond its slack `length` and never pushes
/// (`T ≥ 0`; slack, it exerts nothing). An upright action's bridle tape is one. Its switching
/// function is `l − length`, so an integrator can locate the moment it goes taut or slack.
#[derive(Clone, Debug, PartialEq)]
pub struct Cord {
    name: String,
    a: ResolvedPoint,
    b: ResolvedPoint,
    stiffness: f64,
    damping: f64,
    length: f64,
}

impl Cord {
    /// A cord from `a` to `b` of slack length `length` (> 0), stiffness and damping
    /// non-negative. At least one end must be on a moving body.
    pub fn new(
        model: &Model,
        name: &str,
        a: Attachment<'_>,
        b: Attachment<'_>,
        length: f64,
        stiffness: f64,
        damping: f64,
    ) -> Result<Self> {
        let item = format!("cord '{name}'");
        let a = a.resolve(model, &format!("{item}.a"))?;
        let b = b.resolve(model, &format!("{item}.b"))?;
        if a.body == BodyId::GROUND && b.body == BodyId::GROUND {
            return Err(CoreError::InvalidParameter {
                item,
                message: "both ends are fixed to the ground, so it would act on nothing".into(),
            });
        }
        let length = param(&item, "length", length, true)?;
        if length <= 0.0 {
            return Err(CoreError::InvalidParameter {
                item: format!("{item}.length"),
                message: format!("must be positive (the cord's slack length), got {length}"),
            });
        }
        Ok(Self {
            a,
            b,
            stiffness: param(&item, "stiffness", stiffness, true)?,
            damping: param(&item, "damping", damping, true)?,
            length,
            name: item,
        })
    }

    /// The distance (m) between the ends, from the poses in `ctx`.
    pub fn span(&self, ctx: &ForceContext<'_>) -> f64 {
        let pa = ctx.point_position(self.a.body, self.a.point);
        let pb = ctx.point_position(self.b.body, self.b.point);
        (pb[0] - pa[0]).hypot(pb[1] - pa[1])
    }

    /// The tension (N, ≥ 0) at span `l` and rate `l_dot`.
    pub fn tension(&self, l: f64, l_dot: f64) -> f64 {
        if l <= self.length {
            return 0.0;
        }
        (self.stiffness * (l - self.length) + self.damping * l_dot).max(0.0)
    }
}

impl ForceElement for Cord {
    fn name(&self) -> &str {
        &self.name
    }

    fn check_model(&self, model: &Model) -> Result<()> {
        self.a.check(model, &self.name)?;
        self.b.check(model, &self.name)
    }

    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, _rates: &mut [f64]) {
        // Slack (or its ends together): no force.
        let Some(line) = Line2::between(ctx, &self.a, &self.b, self.length) else {
            return;
        };
        line.pull(loads, &self.a, &self.b, self.tension(line.l, line.ldot));
    }

    fn potential_energy(&self, ctx: &ForceContext<'_>) -> f64 {
        let e = (self.span(ctx) - self.length).max(0.0);
        0.5 * self.stiffness * e * e
    }

    fn switch_count(&self) -> usize {
        1
    }

    fn switching_functions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        out[0] = self.span(ctx) - self.length;
    }
}

/// The Stribeck curve, the one friction level every friction law here uses: the breakaway
/// level `breakaway` at rest decays to the kinetic level `kinetic` over the speed scale
/// `v_stribeck` as `kinetic + (breakaway − kinetic) e^{−(v/v_s)²}` (the Gaussian form of
/// Armstrong-Hélouvry, Dupont & Canudas de Wit, Automatica 30(7):1083, 1994). Pivot
/// friction (torques), contact friction (coefficients) and the identified flange effects
/// (an extra level over zero) call it.
///
/// ```
/// use mbs_core::elements::stribeck_level;
/// // The breakaway level at rest, 1/e of the way down at the Stribeck speed, kinetic beyond.
/// assert_eq!(stribeck_level(0.2, 0.5, 0.1, 0.0), 0.5);
/// let e = std::f64::consts::E;
/// assert!((stribeck_level(0.2, 0.5, 0.1, -0.1) - (0.2 + 0.3 / e)).abs() < 1e-15);
/// assert!((stribeck_level(0.2, 0.5, 0.1, 1.0) - 0.2).abs() < 1e-12);
/// ```
pub fn stribeck_level(kinetic: f64, breakaway: f64, v_stribeck: f64, v: f64) -> f64 {
    let r = v / v_stribeck;
    kinetic + (breakaway - kinetic) * (-r * r).exp()
}

/// The optional Stribeck part of pivot friction: the breakaway torque `static_torque` decays
/// to the Coulomb level over the speed scale `velocity` as `exp(−(v / velocity)²)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stribeck {
    /// Breakaway (static) friction torque, ≥ the Coulomb torque (N·m, or N on a slider).
    pub static_torque: f64,
    /// Stribeck velocity (rad/s or m/s), positive.
    pub velocity: f64,
}

/// Parameters of pivot friction (see [`PivotFriction`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrictionLaw {
    /// Coulomb (kinetic) friction torque (N·m, or N on a slider), non-negative.
    pub coulomb: f64,
    /// Viscous coefficient (N·m·s/rad, or N·s/m), non-negative.
    pub viscous: f64,
    /// Regularisation velocity `v_ε` of the `tanh` (rad/s or m/s), positive: smaller is
    /// closer to true Coulomb friction and stiffer for the integrator.
    pub regularization: f64,
    /// Optional Stribeck peak.
    pub stribeck: Option<Stribeck>,
}

impl FrictionLaw {
    /// Coulomb friction `coulomb`, regularised over `regularization`; no viscous part, no
    /// Stribeck peak.
    pub fn coulomb(coulomb: f64, regularization: f64) -> Self {
        Self {
            coulomb,
            viscous: 0.0,
            regularization,
            stribeck: None,
        }
    }

    /// The same law with viscous coefficient `viscous`.
    pub fn with_viscous(self, viscous: f64) -> Self {
        Self { viscous, ..self }
    }

    /// The same law with a Stribeck peak.
    pub fn with_stribeck(self, static_torque: f64, velocity: f64) -> Self {
        Self {
            stribeck: Some(Stribeck {
                static_torque,
                velocity,
            }),
            ..self
        }
    }

    fn validated(self, name: &str) -> Result<Self> {
        let coulomb = param(name, "coulomb", self.coulomb, true)?;
        let viscous = param(name, "viscous", self.viscous, true)?;
        let regularization = param(name, "regularization", self.regularization, true)?;
        if regularization <= 0.0 {
            return Err(CoreError::InvalidParameter {
                item: format!("{name}.regularization"),
                message: "must be positive".into(),
            });
        }
        if let Some(s) = self.stribeck {
            param(name, "stribeck.static_torque", s.static_torque, true)?;
            param(name, "stribeck.velocity", s.velocity, true)?;
            if s.velocity <= 0.0 || s.static_torque < coulomb {
                return Err(CoreError::InvalidParameter {
                    item: format!("{name}.stribeck"),
                    message: format!(
                        "needs velocity > 0 and static_torque >= coulomb ({coulomb}), got {s:?}"
                    ),
                });
            }
        }
        Ok(Self {
            coulomb,
            viscous,
            regularization,
            stribeck: self.stribeck,
        })
    }
}

/// Friction in a pivot (or slider): regularised Coulomb plus viscous, with an optional
/// Stribeck peak:
/// `τ = −[(T_c + (T_s − T_c) e^{−(v/v_s)²}) tanh(v / v_ε) + b v]`.
///
/// The law is smooth, so by default it declares no switching function; with
/// [`PivotFriction::with_reversal_events`] the joint velocity becomes one, for integrators
/// that should stop at each reversal (stick–slip studies).
#[derive(Clone, Debug, PartialEq)]
pub struct PivotFriction {
    name: String,
    joint: String,
    coordinate: usize,
    law: FrictionLaw,
    reversal_events: bool,
}

impl PivotFriction {
    /// Friction on the joint named `joint`, named after it.
    pub fn new(model: &Model, joint: &str, law: FrictionLaw) -> Result<Self> {
        let name = format!("pivot friction '{joint}'");
        Ok(Self {
            coordinate: model.coordinate_id(joint)?,
            law: law.validated(&name)?,
            joint: joint.to_string(),
            name,
            reversal_events: false,
        })
    }

    /// The same element under another name.
    pub fn named(self, name: &str) -> Self {
        Self {
            name: name.to_string(),
            ..self
        }
    }

    /// The same element, declaring the joint velocity as a switching function (an event at
    /// each reversal of the motion).
    pub fn with_reversal_events(self) -> Self {
        Self {
            reversal_events: true,
            ..self
        }
    }

    /// The friction parameters.
    pub fn law(&self) -> FrictionLaw {
        self.law
    }

    /// Friction torque at joint velocity `v`.
    pub fn torque(&self, v: f64) -> f64 {
        let law = &self.law;
        let level = match law.stribeck {
            None => law.coulomb,
            Some(s) => stribeck_level(law.coulomb, s.static_torque, s.velocity, v),
        };
        -(level * (v / law.regularization).tanh() + law.viscous * v)
    }
}

impl ForceElement for PivotFriction {
    fn name(&self) -> &str {
        &self.name
    }

    fn check_model(&self, model: &Model) -> Result<()> {
        check_coordinate(model, &self.name, &self.joint, self.coordinate)
    }

    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, _rates: &mut [f64]) {
        let k = self.coordinate;
        loads.add_generalized(k, self.torque(ctx.v[k]));
    }

    fn has_load_derivatives(&self) -> bool {
        true
    }

    /// `∂τ/∂v` by a central difference on the scale of the regularization velocity.
    fn load_derivatives(&self, ctx: &ForceContext<'_>, jac: &mut LoadJacobian<'_>) {
        let k = self.coordinate;
        let d = central_difference(|v| self.torque(v), ctx.v[k], self.law.regularization);
        jac.add_generalized(k, Wrt::V(k), d);
    }

    fn switch_count(&self) -> usize {
        usize::from(self.reversal_events)
    }

    fn switching_functions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        if let Some(s) = out.first_mut() {
            *s = ctx.v[self.coordinate];
        }
    }

    fn switch_direction(&self, _k: usize) -> Crossing {
        Crossing::Both
    }
}

/// A joint limit: a one-sided stiff spring–damper that acts only beyond `lower` or `upper`
/// (a stop, a rail, the jack's window): `τ = k (lower − q) − c q̇` below the lower limit,
/// `τ = −k (q − upper) − c q̇` above the upper one, zero in between (the damping never
/// pulls the joint back into a stop). Its switching functions are `q − lower` and
/// `upper − q`, so an integrator can locate the impacts.
#[derive(Clone, Debug, PartialEq)]
pub struct JointLimit {
    name: String,
    joint: String,
    coordinate: usize,
    lower: f64,
    upper: f64,
    stiffness: f64,
    damping: f64,
}

impl JointLimit {
    /// A limit on the joint named `joint` (use `f64::NEG_INFINITY` / `f64::INFINITY` for a
    /// side without a stop); stiffness and damping non-negative, `lower < upper`.
    pub fn new(
        model: &Model,
        joint: &str,
        lower: f64,
        upper: f64,
        stiffness: f64,
        damping: f64,
    ) -> Result<Self> {
        let name = format!("joint limit '{joint}'");
        if lower.is_nan() || upper.is_nan() || lower >= upper {
            return Err(CoreError::InvalidParameter {
                item: name,
                message: format!("needs lower < upper, got {lower} and {upper}"),
            });
        }
        Ok(Self {
            coordinate: model.coordinate_id(joint)?,
            stiffness: param(&name, "stiffness", stiffness, true)?,
            damping: param(&name, "damping", damping, true)?,
            lower,
            upper,
            joint: joint.to_string(),
            name,
        })
    }

    /// The generalized force at coordinate `q` and rate `v`.
    pub fn torque(&self, q: f64, v: f64) -> f64 {
        if q < self.lower {
            (self.stiffness * (self.lower - q) - self.damping * v).max(0.0)
        } else if q > self.upper {
            (-self.stiffness * (q - self.upper) - self.damping * v).min(0.0)
        } else {
            0.0
        }
    }
}

impl ForceElement for JointLimit {
    fn name(&self) -> &str {
        &self.name
    }

    fn check_model(&self, model: &Model) -> Result<()> {
        check_coordinate(model, &self.name, &self.joint, self.coordinate)
    }

    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, _rates: &mut [f64]) {
        let k = self.coordinate;
        loads.add_generalized(k, self.torque(ctx.q[k], ctx.v[k]));
    }

    fn has_load_derivatives(&self) -> bool {
        true
    }

    /// `−k` and `−c` where the stop pushes (zero where the clamp that keeps the damping
    /// from pulling holds the torque at zero).
    fn load_derivatives(&self, ctx: &ForceContext<'_>, jac: &mut LoadJacobian<'_>) {
        let k = self.coordinate;
        if self.torque(ctx.q[k], ctx.v[k]) != 0.0 {
            jac.add_generalized(k, Wrt::Q(k), -self.stiffness);
            jac.add_generalized(k, Wrt::V(k), -self.damping);
        }
    }

    fn potential_energy(&self, ctx: &ForceContext<'_>) -> f64 {
        let q = ctx.q[self.coordinate];
        let e = if q < self.lower {
            self.lower - q
        } else if q > self.upper {
            q - self.upper
        } else {
            0.0
        };
        0.5 * self.stiffness * e * e
    }

    fn switch_count(&self) -> usize {
        2
    }

    fn switching_functions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        let q = ctx.q[self.coordinate];
        // Infinite limits never cross.
        out[0] = if self.lower.is_finite() {
            q - self.lower
        } else {
            1.0
        };
        out[1] = if self.upper.is_finite() {
            self.upper - q
        } else {
            1.0
        };
    }
}

/// The frame in which an applied force's direction is fixed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadFrame {
    /// The direction stays fixed in the world.
    World,
    /// The direction turns with the body.
    Body,
}

#[derive(Clone)]
enum LoadKind {
    Force {
        point: [f64; 2],
        direction: [f64; 2],
        frame: LoadFrame,
    },
    Torque,
}

/// A force at a body point, or a torque on a body, whose magnitude is a function of time:
/// `F(t) = magnitude(t) · direction`.
#[derive(Clone)]
pub struct AppliedLoad {
    name: String,
    frame: String,
    body: BodyId,
    kind: LoadKind,
    magnitude: Arc<dyn TimeFunction>,
}

impl std::fmt::Debug for AppliedLoad {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("AppliedLoad")
            .field("name", &self.name)
            .field("frame", &self.frame)
            .finish_non_exhaustive()
    }
}

fn moving_frame(model: &Model, item: &str, frame: Option<&str>) -> Result<(String, BodyId)> {
    let Some(frame) = frame else {
        return Err(CoreError::InvalidParameter {
            item: item.to_string(),
            message: "a load on the ground acts on nothing: attach it to a moving body".into(),
        });
    };
    let body = model.frame(model.frame_id(frame)?).body;
    if body == BodyId::GROUND {
        return Err(CoreError::InvalidParameter {
            item: item.to_string(),
            message: format!(
                "frame '{frame}' is fixed to the ground, so the load would act on nothing"
            ),
        });
    }
    Ok((frame.to_string(), body))
}

impl AppliedLoad {
    /// A force `magnitude(t) · direction` at `at` (a point of a moving frame). With
    /// [`LoadFrame::Body`] the direction is given in the frame and turns with it; with
    /// [`LoadFrame::World`] it is fixed in world coordinates. `direction` is used as given
    /// (not normalised).
    pub fn force(
        model: &Model,
        name: &str,
        at: Attachment<'_>,
        direction: [f64; 2],
        frame: LoadFrame,
        magnitude: impl TimeFunction + 'static,
    ) -> Result<Self> {
        let item = format!("applied force '{name}'");
        let (frame_name, _) = moving_frame(model, &item, at.frame)?;
        let resolved = at.resolve(model, &item)?;
        param(&item, "direction[0]", direction[0], false)?;
        param(&item, "direction[1]", direction[1], false)?;
        let direction = match frame {
            LoadFrame::Body => model
                .frame(model.frame_id(&frame_name)?)
                .placement
                .rotate(direction),
            LoadFrame::World => direction,
        };
        Ok(Self {
            name: item,
            frame: frame_name,
            body: resolved.body,
            kind: LoadKind::Force {
                point: resolved.point,
                direction,
                frame,
            },
            magnitude: Arc::new(magnitude),
        })
    }

    /// A torque `magnitude(t)` (N·m, counter-clockwise) on the body carrying the named frame.
    pub fn torque(
        model: &Model,
        name: &str,
        frame: &str,
        magnitude: impl TimeFunction + 'static,
    ) -> Result<Self> {
        let item = format!("applied torque '{name}'");
        let (frame, body) = moving_frame(model, &item, Some(frame))?;
        Ok(Self {
            name: item,
            frame,
            body,
            kind: LoadKind::Torque,
            magnitude: Arc::new(magnitude),
        })
    }
}

impl ForceElement for AppliedLoad {
    fn name(&self) -> &str {
        &self.name
    }

    fn check_model(&self, model: &Model) -> Result<()> {
        check_frame(model, &self.name, Some(&self.frame), self.body)
    }

    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, _rates: &mut [f64]) {
        let m = self.magnitude.value(ctx.t);
        match self.kind {
            LoadKind::Torque => loads.add_torque(self.body, m),
            LoadKind::Force {
                point,
                direction,
                frame,
            } => {
                let pose = ctx.body_pose(self.body);
                let dir = match frame {
                    LoadFrame::World => direction,
                    LoadFrame::Body => pose.rotate(direction),
                };
                let p = pose.transform_point(point);
                loads.add_force_at_point(self.body, p, [m * dir[0], m * dir[1]]);
            }
        }
    }

    fn has_load_derivatives(&self) -> bool {
        true
    }

    /// None: a load given as a function of time changes with the state only through its
    /// lever arm, a geometric term [`System::jacobian`](crate::System::jacobian) leaves out.
    fn load_derivatives(&self, _ctx: &ForceContext<'_>, _jac: &mut LoadJacobian<'_>) {}
}
