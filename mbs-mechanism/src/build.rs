//! Description → [`System`]: the model from the bodies and joints, then the force elements
//! in a fixed order (springs, cords, stops, extensions, pivot friction, loads, contacts,
//! strings last since their internal states end the state vector).

use std::collections::BTreeMap;
use std::sync::Arc;

use mbs_contact::laws::{Hertz, HuntCrossley, HystereticFelt, KelvinVoigt, RegularizedCoulomb};
use mbs_contact::materials::MaterialLaw;
use mbs_contact::{ArcSide, Contact, ContactSide, Shape, StringContact, TautString};
use mbs_core::elements::{
    AppliedLoad, Attachment, Cord, FrictionLaw, JointLimit, JointSpringDamper, LoadFrame,
    PivotFriction, PointSpringDamper, SpringLaw,
};
use mbs_core::time_function::Constant;
use mbs_core::{BodySpec, ForceElement, JointKind, Model, ModelBuilder, Placement, System};

use crate::description::*;
use crate::error::{MechanismError, Result};
use crate::validate::material;

/// Force elements that the program reading a description provides, by kind (a piano's
/// flange effects, a custom law): [`Mechanism::build_with`] hands it every
/// [`Extension`] of the description.
pub trait Extensions {
    /// The elements for `extensions` (all those of the description, in file order; their
    /// field paths are `extensions[i]`) on `model`, built from `mechanism`. An unknown kind
    /// is an error naming `extensions[i].kind`.
    fn elements(
        &self,
        extensions: &[Extension],
        model: &Model,
        mechanism: &Mechanism,
    ) -> Result<Vec<Box<dyn ForceElement>>>;
}

/// No extensions: a description that asks for one is refused.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoExtensions;

impl Extensions for NoExtensions {
    fn elements(
        &self,
        extensions: &[Extension],
        _model: &Model,
        _mechanism: &Mechanism,
    ) -> Result<Vec<Box<dyn ForceElement>>> {
        match extensions.first() {
            None => Ok(Vec::new()),
            Some(e) => Err(MechanismError::field(
                "extensions[0].kind",
                format!("no element of kind '{}' is known to this program", e.kind),
            )),
        }
    }
}

/// The switching function of a coordinate event: `q − value`, exerting no force.
#[derive(Clone, Debug)]
struct CoordinateWatch {
    name: String,
    coordinate: usize,
    value: f64,
    direction: mbs_core::Crossing,
}

impl ForceElement for CoordinateWatch {
    fn name(&self) -> &str {
        &self.name
    }

    fn check_model(&self, model: &Model) -> mbs_core::Result<()> {
        if self.coordinate < model.nv() {
            Ok(())
        } else {
            Err(mbs_core::CoreError::UnknownName {
                what: "coordinate index",
                name: self.coordinate.to_string(),
            })
        }
    }

    fn apply(
        &self,
        _ctx: &mbs_core::ForceContext<'_>,
        _loads: &mut mbs_core::Loads<'_>,
        _rates: &mut [f64],
    ) {
    }

    /// No loads, no states: nothing to differentiate.
    fn has_load_derivatives(&self) -> bool {
        true
    }

    fn switch_count(&self) -> usize {
        1
    }

    fn switching_functions(&self, ctx: &mbs_core::ForceContext<'_>, out: &mut [f64]) {
        out[0] = ctx.q[self.coordinate] - self.value;
    }

    fn switch_direction(&self, _k: usize) -> mbs_core::Crossing {
        self.direction
    }
}

/// A contact of a built mechanism, kept with its type so that drawings and outputs reach
/// its shapes and outputs directly (no downcast through the system's elements).
#[derive(Clone, Debug)]
pub enum ContactHandle {
    /// Two shapes and a law.
    Plain(Arc<Contact>),
    /// A striker on a modal string.
    String(Arc<StringContact>),
}

impl ContactHandle {
    /// The bodies and shapes (in the bodies' frames) of the two sides (the string at rest
    /// for a string).
    pub fn sides(&self) -> [(mbs_core::BodyId, &[mbs_contact::Shape]); 2] {
        match self {
            ContactHandle::Plain(c) => c.sides(),
            ContactHandle::String(s) => s.sides(),
        }
    }

    /// Gap, forces, point and normal at the state in `ctx` (the context of the contact's
    /// element, see [`System::element_context`]).
    pub fn output(&self, ctx: &mbs_core::ForceContext<'_>) -> mbs_contact::ContactOutput {
        match self {
            ContactHandle::Plain(c) => c.output(ctx),
            ContactHandle::String(s) => s.output(ctx),
        }
    }

    /// The string, for a striker on one.
    pub fn string(&self) -> Option<&StringContact> {
        match self {
            ContactHandle::Plain(_) => None,
            ContactHandle::String(s) => Some(s),
        }
    }
}

/// A built mechanism: the system and where its named parts are.
pub struct Built {
    /// The system to integrate.
    pub system: System,
    /// Element index of every named element (springs, cords, loads, contacts, strings,
    /// extensions, and `"<body> limits"` for a joint's stops), by name.
    pub elements: BTreeMap<String, usize>,
    /// Element index of each contact and string, by name.
    pub contacts: BTreeMap<String, usize>,
    /// Each contact and string with its type, by name.
    pub contact_handles: BTreeMap<String, ContactHandle>,
    /// Element index of the switching function of each coordinate event, by event name.
    pub watches: BTreeMap<String, usize>,
}

impl Built {
    /// The input named `name` of `mechanism` (which this was built from).
    fn input<'m>(mechanism: &'m Mechanism, name: &str, kind: InputKind) -> Result<&'m Input> {
        let input = mechanism
            .inputs
            .iter()
            .find(|i| i.name == name)
            .ok_or_else(|| {
                MechanismError::field(
                    "inputs",
                    format!(
                        "no input '{name}' (inputs: {})",
                        mechanism
                            .inputs
                            .iter()
                            .map(|i| i.name.as_str())
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                )
            })?;
        if input.kind != kind {
            return Err(MechanismError::field(
                "inputs",
                format!(
                    "input '{name}' is a {:?} input, not a {kind:?} input",
                    input.kind
                ),
            ));
        }
        Ok(input)
    }

    /// Drives the force input `name` of `mechanism` (which this was built from): a force of
    /// `magnitude(t)` newtons along the input's world direction at its point. Returns the
    /// element's index.
    pub fn drive_force(
        &mut self,
        mechanism: &Mechanism,
        name: &str,
        magnitude: impl mbs_core::TimeFunction + 'static,
    ) -> Result<usize> {
        let input = Self::input(mechanism, name, InputKind::Force)?;
        let model = self.system.model().clone();
        let field = format!("inputs.{name}");
        let load = AppliedLoad::force(
            &model,
            name,
            attachment(&input.at),
            input.direction,
            LoadFrame::World,
            magnitude,
        )
        .map_err(core(&field))?;
        let index = self.system.add_element(load).map_err(core(&field))?;
        self.elements.insert(name.to_string(), index);
        Ok(index)
    }

    /// Drives the motion input `name`: its body's coordinate follows `drive` (rad or m; use
    /// the mechanism's geometry to turn a measured displacement into the coordinate).
    pub fn drive_motion(
        &mut self,
        mechanism: &Mechanism,
        name: &str,
        drive: impl mbs_core::Drive + 'static,
    ) -> Result<()> {
        let input = Self::input(mechanism, name, InputKind::Motion)?;
        self.system
            .prescribe(&input.at.body, drive)
            .map_err(core(&format!("inputs.{name}")))
    }

    /// The state of the layout at rest: every coordinate and velocity zero, internal
    /// states (felt memory, string modes) at their initial values.
    pub fn layout_state(&self) -> Result<Vec<f64>> {
        let n = self.system.model().nv();
        self.system
            .initial_state(0.0, &vec![0.0; n], &vec![0.0; n])
            .map_err(core(""))
    }
}

impl std::fmt::Debug for Built {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Built")
            .field("elements", &self.elements)
            .field("contacts", &self.contacts)
            .finish_non_exhaustive()
    }
}

fn core(field: &str) -> impl Fn(mbs_core::CoreError) -> MechanismError + '_ {
    move |e| MechanismError::caused(field, e)
}

fn contact_err(field: &str) -> impl Fn(mbs_contact::ContactError) -> MechanismError + '_ {
    move |e| MechanismError::caused(field, e)
}

fn attachment(p: &BodyPoint) -> Attachment<'_> {
    if p.body == GROUND {
        Attachment::ground(p.point)
    } else {
        Attachment::on(&p.body, p.point)
    }
}

/// The contact shapes of one description shape (a profile gives one segment per face).
pub fn shapes(field: &str, s: &ShapeSpec) -> Result<Vec<Shape>> {
    let err = contact_err(field);
    Ok(match s {
        ShapeSpec::Circle { center, radius } => vec![Shape::circle(*center, *radius).map_err(err)?],
        ShapeSpec::Segment { a, b } => vec![Shape::segment(*a, *b).map_err(err)?],
        ShapeSpec::Arc {
            center,
            radius,
            start,
            sweep,
            side,
        } => {
            let side = match side {
                ArcSideSpec::Convex => ArcSide::Convex,
                ArcSideSpec::Concave => ArcSide::Concave,
            };
            vec![Shape::arc(*center, *radius, *start, *sweep, side).map_err(err)?]
        }
        ShapeSpec::Profile { points } => points
            .windows(2)
            .map(|w| Shape::segment(w[0], w[1]).map_err(&err))
            .collect::<Result<_>>()?,
    })
}

fn side(field: &str, s: &ContactSideSpec) -> Result<ContactSide> {
    let mut all = Vec::new();
    for (i, sh) in s.shapes.iter().enumerate() {
        all.extend(shapes(&format!("{field}.shapes[{i}]"), sh)?);
    }
    Ok(if s.body == GROUND {
        ContactSide::ground(all)
    } else {
        ContactSide::on(&s.body, all)
    })
}

/// The normal law of a description.
pub fn normal_law(field: &str, l: &LawSpec) -> Result<MaterialLaw> {
    let err = contact_err(field);
    Ok(match l {
        LawSpec::Material(name) => material(&format!("{field}.material"), name)?.normal,
        LawSpec::Felt {
            k,
            p,
            e,
            smoothing,
            alpha,
        } => HystereticFelt::from_restitution(*k, *p, *e, *smoothing)
            .and_then(|f| f.with_rate_damping(*alpha))
            .map_err(err)?
            .into(),
        LawSpec::Hertz { k, p } => Hertz::new(*k, *p).map_err(err)?.into(),
        LawSpec::KelvinVoigt { k, c } => KelvinVoigt::new(*k, *c).map_err(err)?.into(),
        LawSpec::HuntCrossley { k, p, alpha } => {
            HuntCrossley::new(*k, *p, *alpha).map_err(err)?.into()
        }
        LawSpec::Stulov {
            q0,
            p,
            epsilon,
            tau0,
        } => mbs_contact::laws::StulovFelt::from_static_stiffness(*q0, *p, *epsilon, *tau0)
            .map_err(err)?
            .into(),
    })
}

impl StringModes {
    /// The string's modes.
    pub fn build(&self, field: &str) -> Result<TautString> {
        TautString::new(&mbs_contact::StringSpec {
            length_m: self.length_m,
            fundamental_hz: self.fundamental_hz,
            mass_kg: self.mass_kg,
            tension_n: self.tension_n,
            inharmonicity: self.inharmonicity,
            striking_ratio: self.striking_ratio,
            strings: self.strings,
            loss_b1: self.loss_b1,
            loss_b3: self.loss_b3,
            modes: self.modes,
            residual_compliance: self.residual_compliance,
        })
        .map_err(contact_err(field))
    }
}

impl Mechanism {
    /// The model alone (bodies and joints), checked.
    pub fn model(&self) -> Result<Model> {
        self.validate()?;
        let mut b = ModelBuilder::new();
        b.gravity(self.gravity);
        for body in &self.bodies {
            let j = &body.joint;
            let kind = match j.kind {
                JointType::Revolute => JointKind::Revolute,
                JointType::Fixed => JointKind::Fixed,
                JointType::Prismatic => JointKind::Prismatic {
                    axis: j.axis.unwrap_or([1.0, 0.0]),
                },
            };
            let parent = (j.parent != GROUND).then_some(j.parent.as_str());
            b.add_link(
                &body.name,
                parent,
                kind,
                Placement::new(j.angle, j.at[0], j.at[1]),
                BodySpec::new(body.mass, body.com, body.inertia),
            );
        }
        b.build().map_err(core("bodies"))
    }

    /// Builds the system; a description with extensions is refused (see
    /// [`Mechanism::build_with`]).
    pub fn build(&self) -> Result<Built> {
        self.build_with(&NoExtensions)
    }

    /// Builds the system, `extensions` providing the elements of kinds this crate does not
    /// know.
    pub fn build_with(&self, extensions: &dyn Extensions) -> Result<Built> {
        let model = self.model()?;
        let mut system = System::new(model.clone());
        let mut elements = BTreeMap::new();
        let mut contacts = BTreeMap::new();
        let mut contact_handles = BTreeMap::new();

        for (i, s) in self.torsion_springs.iter().enumerate() {
            let f = format!("torsion_springs[{i}]");
            let mut law = SpringLaw::new(s.stiffness, s.rest).with_preload(s.preload);
            if s.damping != 0.0 {
                law = law.with_damping(s.damping);
            }
            let e = JointSpringDamper::new(&model, &s.joint, law)
                .map_err(core(&f))?
                .named(&s.name);
            elements.insert(s.name.clone(), system.add_element(e).map_err(core(&f))?);
        }
        for (i, s) in self.point_springs.iter().enumerate() {
            let f = format!("point_springs[{i}]");
            let law = SpringLaw::new(s.stiffness, s.rest_length)
                .with_preload(s.preload)
                .with_damping(s.damping);
            let e =
                PointSpringDamper::new(&model, &s.name, attachment(&s.a), attachment(&s.b), law)
                    .map_err(core(&f))?;
            elements.insert(s.name.clone(), system.add_element(e).map_err(core(&f))?);
        }
        for (i, c) in self.cords.iter().enumerate() {
            let f = format!("cords[{i}]");
            let e = Cord::new(
                &model,
                &c.name,
                attachment(&c.a),
                attachment(&c.b),
                c.length,
                c.stiffness,
                c.damping,
            )
            .map_err(core(&f))?;
            elements.insert(c.name.clone(), system.add_element(e).map_err(core(&f))?);
        }
        for (i, body) in self.bodies.iter().enumerate() {
            if let Some(l) = body.joint.limits {
                let f = format!("bodies[{i}].joint.limits");
                let e = JointLimit::new(
                    &model,
                    &body.name,
                    l.lower.unwrap_or(f64::NEG_INFINITY),
                    l.upper.unwrap_or(f64::INFINITY),
                    l.stiffness,
                    l.damping,
                )
                .map_err(core(&f))?;
                let index = system.add_element(e).map_err(core(&f))?;
                elements.insert(format!("{} limits", body.name), index);
            }
        }
        if !self.extensions.is_empty() {
            let built = extensions.elements(&self.extensions, &model, self)?;
            for (k, e) in built.into_iter().enumerate() {
                let name = e.name().to_string();
                let index = system
                    .add_shared_element(Arc::from(e))
                    .map_err(core(&format!("extensions[{k}]")))?;
                elements.insert(name, index);
            }
        }
        for (i, body) in self.bodies.iter().enumerate() {
            if let Some(fr) = body.joint.friction {
                let f = format!("bodies[{i}].joint.friction");
                let mut law = FrictionLaw::coulomb(fr.coulomb, fr.regularization);
                if fr.viscous != 0.0 {
                    law = law.with_viscous(fr.viscous);
                }
                if let Some(s) = fr.stribeck {
                    law = law.with_stribeck(s.static_torque, s.velocity);
                }
                let e = PivotFriction::new(&model, &body.name, law).map_err(core(&f))?;
                system.add_element(e).map_err(core(&f))?;
            }
        }
        for (i, l) in self.loads.iter().enumerate() {
            let f = format!("loads[{i}]");
            let e = AppliedLoad::force(
                &model,
                &l.name,
                attachment(&l.at),
                l.direction,
                LoadFrame::World,
                Constant(l.magnitude),
            )
            .map_err(core(&f))?;
            elements.insert(l.name.clone(), system.add_element(e).map_err(core(&f))?);
        }
        for (i, c) in self.contacts.iter().enumerate() {
            let f = format!("contacts[{i}]");
            let normal = normal_law(&format!("{f}.law"), &c.law)?;
            let mut e = Contact::new(
                &model,
                &c.name,
                side(&format!("{f}.a"), &c.a)?,
                side(&format!("{f}.b"), &c.b)?,
                normal,
            )
            .map_err(contact_err(&f))?;
            match &c.friction {
                None => {}
                Some(ContactFrictionSpec::Coulomb { mu, regularization }) if *mu > 0.0 => {
                    e = e.with_friction(
                        RegularizedCoulomb::new(*mu, *regularization)
                            .map_err(contact_err(&format!("{f}.friction")))?,
                    );
                }
                // No friction at μ = 0 (the law needs μ > 0).
                Some(ContactFrictionSpec::Coulomb { .. }) => {}
                Some(ContactFrictionSpec::Material {
                    name,
                    regularization,
                }) => {
                    let ff = format!("{f}.friction.material");
                    let law = material(&format!("{ff}.name"), name)?
                        .tangential_law(*regularization)
                        .map_err(contact_err(&ff))?;
                    e = e.with_friction(law);
                }
            }
            let e = Arc::new(e);
            let index = system.add_shared_element(e.clone()).map_err(core(&f))?;
            elements.insert(c.name.clone(), index);
            contacts.insert(c.name.clone(), index);
            contact_handles.insert(c.name.clone(), ContactHandle::Plain(e));
        }
        for (i, s) in self.strings.iter().enumerate() {
            let f = format!("strings[{i}]");
            let e = StringContact::new(
                &model,
                &s.name,
                s.string.build(&format!("{f}.string"))?,
                Shape::segment(s.line[0], s.line[1]).map_err(contact_err(&format!("{f}.line")))?,
                side(&format!("{f}.striker"), &s.striker)?,
                normal_law(&format!("{f}.law"), &s.law)?,
            )
            .map_err(contact_err(&f))?;
            let e = Arc::new(e);
            let index = system.add_shared_element(e.clone()).map_err(core(&f))?;
            elements.insert(s.name.clone(), index);
            contacts.insert(s.name.clone(), index);
            contact_handles.insert(s.name.clone(), ContactHandle::String(e));
        }
        // Coordinate events last: they exert nothing, and the integrator locates them.
        let mut watches = BTreeMap::new();
        for (i, e) in self.events.iter().enumerate() {
            if let (Some(body), Some(value)) = (&e.coordinate, e.value) {
                let f = format!("events[{i}]");
                let watch = CoordinateWatch {
                    name: format!("event '{}'", e.name),
                    coordinate: model.coordinate_id(body).map_err(core(&f))?,
                    value,
                    direction: match e.direction.unwrap_or(CrossingSpec::Both) {
                        CrossingSpec::Rising => mbs_core::Crossing::Rising,
                        CrossingSpec::Falling => mbs_core::Crossing::Falling,
                        CrossingSpec::Both => mbs_core::Crossing::Both,
                    },
                };
                watches.insert(e.name.clone(), system.add_element(watch).map_err(core(&f))?);
            }
        }
        Ok(Built {
            system,
            elements,
            contacts,
            contact_handles,
            watches,
        })
    }
}
