//! [`Contact`]: a contact between two bodies (or a body and the ground) as a force element
//! of an `mbs_core::System`.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use mbs_core::{
    BodyId, Crossing, ForceContext, ForceElement, LoadJacobian, Loads, Model, central_difference,
};

use crate::error::{ContactError, Result};
use crate::geometry::{Proximity, Shape, proximity};
use crate::laws::{NormalLaw, TangentialLaw};

/// One side of a contact: the frame its shapes are given in (`None` for the ground, shapes
/// then in world coordinates) and the shapes (a profile when there are several).
///
/// A profile is an *open* chain of faces met from its front: each face counts as solid in
/// the whole strip behind it, and the contact takes the smallest gap over the faces. So a
/// closed polygon does not work as a profile (its back faces report the far side as deep
/// penetration: a disc 2 mm above a 20 mm square gets a gap of −24 mm), and behind the end
/// faces of a strongly curved open profile the strips can reach round to a far body. The
/// check against parry2d (`tests/parry_check.rs`) keeps to front approaches for this reason.
#[derive(Clone, Debug)]
pub struct ContactSide {
    /// Frame name, `None` for the ground.
    pub frame: Option<String>,
    /// Shapes in the frame's coordinates.
    pub shapes: Vec<Shape>,
}

impl ContactSide {
    /// Shapes fixed to the named frame.
    pub fn on(frame: &str, shapes: Vec<Shape>) -> Self {
        Self {
            frame: Some(frame.to_string()),
            shapes,
        }
    }

    /// Shapes fixed to the ground (world coordinates).
    pub fn ground(shapes: Vec<Shape>) -> Self {
        Self {
            frame: None,
            shapes,
        }
    }
}

/// A side resolved on a model: body and shapes in the body's joint frame.
#[derive(Clone, Debug)]
pub(crate) struct ResolvedSide {
    pub(crate) body: BodyId,
    pub(crate) shapes: Vec<Shape>,
}

/// What a contact does at one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactOutput {
    /// Whether the surfaces overlap and the force is positive.
    pub active: bool,
    /// Signed gap (m).
    pub gap: f64,
    /// Rate of the gap (m/s): the relative normal velocity of B with respect to A.
    pub gap_rate: f64,
    /// Relative tangential velocity of B with respect to A (m/s), along the tangent.
    pub slip: f64,
    /// Normal force (N, ≥ 0) pushing B away from A.
    pub normal_force: f64,
    /// Tangential force on B along the tangent (N).
    pub tangential_force: f64,
    /// Power of the contact forces on the two bodies (W): negative when the contact absorbs
    /// energy.
    pub power: f64,
    /// Contact point (world), midway between the two surfaces.
    pub point: [f64; 2],
    /// Unit normal from A toward B (world).
    pub normal: [f64; 2],
}

/// A contact between the shapes of two sides, with a normal law and optional friction. The
/// forces act at the midpoint of the two nearest surface points, equal and opposite on the
/// two bodies. Its switching function is the gap, so an integrator can locate onset and
/// release.
pub struct Contact {
    name: String,
    sides: [ResolvedSide; 2],
    normal: Arc<dyn NormalLaw>,
    friction: Option<Arc<dyn TangentialLaw>>,
    /// The earliest time its laws acted ([`Contact::acted_from`]), as `f64` bits
    /// (infinity: never).
    acted: AtomicU64,
}

impl Clone for Contact {
    fn clone(&self) -> Self {
        Self {
            name: self.name.clone(),
            sides: self.sides.clone(),
            normal: self.normal.clone(),
            friction: self.friction.clone(),
            acted: AtomicU64::new(self.acted.load(Ordering::Relaxed)),
        }
    }
}

impl std::fmt::Debug for Contact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Contact")
            .field("name", &self.name)
            .field("normal", &self.normal)
            .field("friction", &self.friction)
            .finish_non_exhaustive()
    }
}

impl Contact {
    /// A contact named `name` between sides `a` and `b` under `normal`. Fails on an unknown
    /// frame, an empty side, both sides on the ground, or a pair of shapes that cannot touch
    /// (two lines, two concave arcs).
    pub fn new(
        model: &Model,
        name: &str,
        a: ContactSide,
        b: ContactSide,
        normal: impl NormalLaw + 'static,
    ) -> Result<Self> {
        let sides = [resolve(model, name, &a)?, resolve(model, name, &b)?];
        if sides[0].body == BodyId::GROUND && sides[1].body == BodyId::GROUND {
            return Err(ContactError::UnsupportedPair {
                contact: name.into(),
                message: "both sides are on the ground".into(),
            });
        }
        for sa in &sides[0].shapes {
            for sb in &sides[1].shapes {
                proximity(sa, sb).map_err(|e| ContactError::UnsupportedPair {
                    contact: name.into(),
                    message: e.to_string(),
                })?;
            }
        }
        Ok(Self {
            name: format!("contact '{name}'"),
            sides,
            normal: Arc::new(normal),
            friction: None,
            acted: AtomicU64::new(f64::INFINITY.to_bits()),
        })
    }

    /// The earliest time (s) at which its laws acted since it was built (or cloned from one
    /// that had), `None` if they never did: an evaluation of its loads or their derivatives
    /// where the shapes overlapped, or any where its normal law keeps states (whose rates
    /// it gives apart as well). Until then every evaluation went as if its laws were any
    /// others: a solve that agrees with another everywhere else gives the same result, to
    /// the last bit, as long as it is evaluated only before that time (see
    /// `mbs_integrators::Checkpoint`).
    pub fn acted_from(&self) -> Option<f64> {
        let t = f64::from_bits(self.acted.load(Ordering::Relaxed));
        (t != f64::INFINITY).then_some(t)
    }

    /// Whether its laws have acted since it was built ([`Contact::acted_from`]).
    pub fn touched(&self) -> bool {
        self.acted_from().is_some()
    }

    /// Notes that its laws acted at time `t` (a time that is not a number counts as the
    /// earliest).
    fn touch(&self, t: f64) {
        let t = if t.is_nan() { f64::NEG_INFINITY } else { t };
        let mut seen = self.acted.load(Ordering::Relaxed);
        while t < f64::from_bits(seen) {
            match self.acted.compare_exchange_weak(
                seen,
                t.to_bits(),
                Ordering::Relaxed,
                Ordering::Relaxed,
            ) {
                Ok(_) => break,
                Err(now) => seen = now,
            }
        }
    }

    /// The same contact with friction.
    pub fn with_friction(self, law: impl TangentialLaw + 'static) -> Self {
        Self {
            friction: Some(Arc::new(law)),
            ..self
        }
    }

    /// The nearest points of the two sides (the pair of shapes with the smallest gap), in
    /// world coordinates, from the poses in `ctx`: the system's position stage when it has
    /// computed them for this state, else found here.
    pub fn proximity(&self, ctx: &ForceContext<'_>) -> Proximity {
        if let [gap, nx, ny, ax, ay, bx, by] = *ctx.positions {
            return Proximity {
                gap,
                normal: [nx, ny],
                point_a: [ax, ay],
                point_b: [bx, by],
            };
        }
        self.find_proximity(ctx)
    }

    /// [`Contact::proximity`] found from the poses.
    fn find_proximity(&self, ctx: &ForceContext<'_>) -> Proximity {
        let (pa, pb) = (
            ctx.body_pose(self.sides[0].body),
            ctx.body_pose(self.sides[1].body),
        );
        let mut best: Option<Proximity> = None;
        for sa in &self.sides[0].shapes {
            let wa = sa.placed(&pa);
            for sb in &self.sides[1].shapes {
                // Pairs were checked at construction.
                if let Ok(p) = proximity(&wa, &sb.placed(&pb))
                    && best.is_none_or(|b| p.gap < b.gap)
                {
                    best = Some(p);
                }
            }
        }
        best.unwrap_or(Proximity {
            gap: f64::INFINITY,
            normal: [1.0, 0.0],
            point_a: [0.0, 0.0],
            point_b: [0.0, 0.0],
        })
    }

    /// Gap, forces and power at the state in `ctx`; `rates` receives the normal law's state
    /// rates.
    fn compute(&self, ctx: &ForceContext<'_>, rates: &mut [f64]) -> ContactOutput {
        self.compute_at(self.proximity(ctx), ctx, rates)
    }

    /// [`Contact::compute`] with the proximity already found.
    fn compute_at(&self, p: Proximity, ctx: &ForceContext<'_>, rates: &mut [f64]) -> ContactOutput {
        let mid = [
            0.5 * (p.point_a[0] + p.point_b[0]),
            0.5 * (p.point_a[1] + p.point_b[1]),
        ];
        let [a, b] = &self.sides;
        let va = velocity_at(ctx, a.body, mid);
        let vb = velocity_at(ctx, b.body, mid);
        let vrel = [vb[0] - va[0], vb[1] - va[1]];
        let n = p.normal;
        let t = p.tangent();
        // ġ = (v_B − v_A) · n ; slip = (v_B − v_A) · t
        let gap_rate = vrel[0] * n[0] + vrel[1] * n[1];
        let slip = vrel[0] * t[0] + vrel[1] * t[1];
        let fn_ = if p.gap.is_finite() {
            self.normal
                .force(-p.gap, -gap_rate, ctx.states, rates)
                .max(0.0)
        } else {
            rates.fill(0.0);
            0.0
        };
        let ft = match &self.friction {
            Some(f) if fn_ > 0.0 => f.force(fn_, slip),
            _ => 0.0,
        };
        ContactOutput {
            active: fn_ > 0.0,
            gap: p.gap,
            gap_rate,
            slip,
            normal_force: fn_,
            tangential_force: ft,
            power: fn_ * gap_rate + ft * slip,
            point: mid,
            normal: n,
        }
    }

    /// Gap, forces and power at the state in `ctx` (per-contact output).
    pub fn output(&self, ctx: &ForceContext<'_>) -> ContactOutput {
        let mut rates = vec![0.0; self.normal.state_count()];
        self.compute(ctx, &mut rates)
    }

    /// The body of each side (A, then B) and that side's shapes in the body's joint frame
    /// (world coordinates for the ground), exactly as the contact uses them: place them with
    /// the body's pose ([`Shape::placed`]) to draw or inspect the contact.
    ///
    /// ```
    /// use mbs_contact::laws::KelvinVoigt;
    /// use mbs_contact::{Contact, ContactSide, Shape};
    /// use mbs_core::{BodyId, BodySpec, JointKind, ModelBuilder, Placement};
    /// let mut b = ModelBuilder::new();
    /// b.add_link("arm", None, JointKind::Revolute, Placement::offset(0.0, 1.0),
    ///            BodySpec::new(1.0, [0.5, 0.0], 0.1));
    /// let model = b.build()?;
    /// let floor = Shape::segment([1.0, 0.0], [-1.0, 0.0])?;
    /// let tip = Shape::circle([1.0, 0.0], 0.01)?;
    /// let c = Contact::new(&model, "tip", ContactSide::ground(vec![floor]),
    ///                      ContactSide::on("arm", vec![tip]), KelvinVoigt::new(1e4, 0.0)?)?;
    /// let [(a, floor_shapes), (b, tip_shapes)] = c.sides();
    /// assert_eq!(a, BodyId::GROUND);
    /// assert_eq!((floor_shapes, tip_shapes), (&[floor][..], &[tip][..]));
    /// assert_eq!(b, model.body_id("arm")?);
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn sides(&self) -> [(BodyId, &[Shape]); 2] {
        let [a, b] = &self.sides;
        [(a.body, &a.shapes), (b.body, &b.shapes)]
    }

    /// The contact behind a force element of a `System` (`None` when the element is not a
    /// [`Contact`]).
    ///
    /// ```
    /// use mbs_contact::laws::KelvinVoigt;
    /// use mbs_contact::{Contact, ContactSide, Shape};
    /// use mbs_core::elements::{JointSpringDamper, SpringLaw};
    /// use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement, System};
    /// let mut b = ModelBuilder::new();
    /// b.add_link("arm", None, JointKind::Revolute, Placement::offset(0.0, 1.0),
    ///            BodySpec::new(1.0, [0.5, 0.0], 0.1));
    /// let model = b.build()?;
    /// let mut system = System::new(model.clone());
    /// let spring = system.add_element(JointSpringDamper::new(&model, "arm",
    ///                                                        SpringLaw::new(1.0, 0.0))?)?;
    /// let tip = system.add_element(Contact::new(
    ///     &model, "tip",
    ///     ContactSide::ground(vec![Shape::segment([1.0, 0.0], [-1.0, 0.0])?]),
    ///     ContactSide::on("arm", vec![Shape::circle([1.0, 0.0], 0.01)?]),
    ///     KelvinVoigt::new(1e4, 0.0)?)?)?;
    /// let element = |e: usize| system.elements().nth(e).ok_or("no such element");
    /// assert!(Contact::of(element(tip)?).is_some());
    /// assert!(Contact::of(element(spring)?).is_none());
    /// # Ok::<(), Box<dyn std::error::Error>>(())
    /// ```
    pub fn of(element: &dyn ForceElement) -> Option<&Contact> {
        element.as_any()?.downcast_ref::<Contact>()
    }
}

pub(crate) fn resolve(model: &Model, contact: &str, side: &ContactSide) -> Result<ResolvedSide> {
    if side.shapes.is_empty() {
        return Err(ContactError::UnsupportedPair {
            contact: contact.into(),
            message: "a side has no shape".into(),
        });
    }
    let (body, placement) = match &side.frame {
        None => (BodyId::GROUND, mbs_core::Transform::IDENTITY),
        Some(f) => {
            let frame = model.frame(model.frame_id(f)?);
            (frame.body, frame.placement)
        }
    };
    Ok(ResolvedSide {
        body,
        shapes: side.shapes.iter().map(|s| s.placed(&placement)).collect(),
    })
}

/// World velocity of the material point of `body` at the world point `p`.
pub(crate) fn velocity_at(ctx: &ForceContext<'_>, body: BodyId, p: [f64; 2]) -> [f64; 2] {
    let p_b = ctx.body_pose(body).inverse_transform_point(p);
    ctx.point_velocity(body, p_b)
}

impl ForceElement for Contact {
    fn name(&self) -> &str {
        &self.name
    }

    fn check_model(&self, model: &Model) -> mbs_core::Result<()> {
        for s in &self.sides {
            if s.body.index() >= model.nbodies() {
                return Err(mbs_core::CoreError::InvalidParameter {
                    item: self.name.clone(),
                    message: "built for another model".into(),
                });
            }
        }
        Ok(())
    }

    fn state_count(&self) -> usize {
        self.normal.state_count()
    }

    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, rates: &mut [f64]) {
        let p = self.proximity(ctx);
        // Apart, a memoryless law gives no force (laws never pull: 0 whenever δ ≤ 0), so
        // the velocities and the law need not be evaluated.
        if p.gap >= 0.0 && self.normal.state_count() == 0 {
            return;
        }
        self.touch(ctx.t);
        let out = self.compute_at(p, ctx, rates);
        if !out.active {
            return;
        }
        let (n, t) = (out.normal, [-out.normal[1], out.normal[0]]);
        // Force on B: F = Fn n + Ft t ; on A: −F, both at the contact point.
        let f = [
            out.normal_force * n[0] + out.tangential_force * t[0],
            out.normal_force * n[1] + out.tangential_force * t[1],
        ];
        loads.add_force_at_point(self.sides[1].body, out.point, f);
        loads.add_force_at_point(self.sides[0].body, out.point, [-f[0], -f[1]]);
    }

    /// Laws without memory only (a law's internal states would need their own rows).
    fn has_load_derivatives(&self) -> bool {
        self.normal.state_count() == 0
    }

    /// The normal law's `∂F_n/∂δ`, `∂F_n/∂δ̇` (closed form where the law has one, else
    /// central differences) and the friction law's `∂F_t/∂F_n`, `∂F_t/∂slip` (central
    /// differences), through the gap `δ = −n·Δ` and the slip `t·Δ̇` at the contact point,
    /// and the convective part of the gap rate (the nearest points found again a short
    /// time ahead along the motion).
    fn load_derivatives(&self, ctx: &ForceContext<'_>, jac: &mut LoadJacobian<'_>) {
        let p = self.proximity(ctx);
        if p.gap.is_nan() || p.gap >= 0.0 {
            return;
        }
        self.touch(ctx.t);
        let out = self.compute_at(p, ctx, &mut []);
        if !out.active {
            return;
        }
        let (delta, delta_dot) = (-out.gap, -out.gap_rate);
        let law = |d: f64, dd: f64| self.normal.force(d, dd, &[], &mut []).max(0.0);
        let kn = match self.normal.tangent_stiffness(delta, delta_dot, &[]) {
            Some(k) => k,
            None => central_difference(|d| law(d, delta_dot), delta, delta),
        };
        let cn = match self.normal.rate_derivative(delta, delta_dot, &[]) {
            Some(c) => c,
            None => central_difference(|dd| law(delta, dd), delta_dot, 1e-4),
        };
        let (mu, st) = match &self.friction {
            Some(f) => (
                central_difference(|fnn| f.force(fnn, out.slip), out.normal_force, 1.0),
                central_difference(|s| f.force(out.normal_force, s), out.slip, 1e-4),
            ),
            None => (0.0, 0.0),
        };
        let n = out.normal;
        let t = [-n[1], n[0]];
        // F = F_n n + F_t t with δ = −n·Δ, δ̇ = −n·Δ̇, slip = t·Δ̇ and F_t = F_t(F_n, slip).
        let dir = [n[0] + mu * t[0], n[1] + mu * t[1]];
        let mut dq = [[0.0; 2]; 2];
        let mut dv = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                dq[i][j] = -kn * dir[i] * n[j];
                dv[i][j] = -cn * dir[i] * n[j] + st * t[i] * t[j];
            }
        }
        jac.set_point(self.sides[0].body, self.sides[1].body, out.point);
        jac.add_point_force(dq, dv);
        // The gap rate's convective part: F changes by c_n ∂δ̇/∂q = −c_n ∂ġ/∂q along
        // `dir`, with ∂ġ/∂q from the nearest points a short time ahead.
        if cn != 0.0 {
            let ahead = jac.ahead(ctx).map(|(c, _)| self.find_proximity(&c));
            if let Some(p1) = ahead {
                let mid = [
                    0.5 * (p1.point_a[0] + p1.point_b[0]),
                    0.5 * (p1.point_a[1] + p1.point_b[1]),
                ];
                let [a, b] = [self.sides[0].body, self.sides[1].body];
                jac.add_gap_rate_convection(a, b, n, mid, p1.normal, dir, -cn);
            }
        }
    }

    fn position_len(&self) -> usize {
        7
    }

    /// The nearest points: gap, normal, point on A, point on B.
    fn positions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        let p = self.find_proximity(ctx);
        out.copy_from_slice(&[
            p.gap,
            p.normal[0],
            p.normal[1],
            p.point_a[0],
            p.point_a[1],
            p.point_b[0],
            p.point_b[1],
        ]);
    }

    fn switch_count(&self) -> usize {
        1
    }

    fn switching_functions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        out[0] = self.proximity(ctx).gap;
    }

    fn switch_direction(&self, _k: usize) -> Crossing {
        Crossing::Both
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}
