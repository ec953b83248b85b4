//! Checks of a description before it is built: every error names the field.

use std::collections::{BTreeMap, BTreeSet};

use crate::description::*;
use crate::error::{MechanismError, Result};
use mbs_core::check::{Bound, check_value};

fn bad(field: impl Into<String>, message: impl Into<String>) -> MechanismError {
    MechanismError::field(field, message)
}

/// `value` finite, else an error at `field`.
pub(crate) fn finite(field: &str, value: f64) -> Result<f64> {
    bounded(field, value, Bound::Finite)
}

pub(crate) fn positive(field: &str, value: f64) -> Result<f64> {
    bounded(field, value, Bound::Positive)
}

pub(crate) fn non_negative(field: &str, value: f64) -> Result<f64> {
    bounded(field, value, Bound::NonNegative)
}

fn bounded(field: &str, value: f64, bound: Bound) -> Result<f64> {
    check_value(value, bound).map_err(|message| bad(field, message))
}

pub(crate) fn point(field: &str, p: [f64; 2]) -> Result<()> {
    finite(&format!("{field}[0]"), p[0])?;
    finite(&format!("{field}[1]"), p[1])?;
    Ok(())
}

fn direction(field: &str, d: [f64; 2]) -> Result<()> {
    point(field, d)?;
    let n = d[0].hypot(d[1]);
    if (n - 1.0).abs() > 1e-6 {
        return Err(bad(
            field,
            format!(
                "must be a unit vector, got [{}, {}] (length {n})",
                d[0], d[1]
            ),
        ));
    }
    Ok(())
}

/// The material presets' file names: `"action felt"` → `action_felt`.
pub fn material_names() -> Vec<String> {
    mbs_contact::materials::Material::presets()
        .iter()
        .map(|m| preset_key(m.name))
        .collect()
}

/// The file name of a preset's display name.
pub(crate) fn preset_key(name: &str) -> String {
    name.replace(['(', ')'], "")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join("_")
}

/// The preset of a file name.
pub(crate) fn material(field: &str, name: &str) -> Result<mbs_contact::materials::Material> {
    mbs_contact::materials::Material::presets()
        .into_iter()
        .find(|m| preset_key(m.name) == name)
        .ok_or_else(|| {
            bad(
                field,
                format!(
                    "no material '{name}' (known: {})",
                    material_names().join(", ")
                ),
            )
        })
}

struct Names<'a> {
    /// Body name → (index, joint kind).
    bodies: BTreeMap<&'a str, (usize, JointType)>,
}

impl<'a> Names<'a> {
    fn body(&self, field: &str, name: &str, ground_ok: bool) -> Result<()> {
        if name == GROUND {
            return if ground_ok {
                Ok(())
            } else {
                Err(bad(field, "must be a moving body, not the ground"))
            };
        }
        if self.bodies.contains_key(name) {
            Ok(())
        } else {
            Err(bad(
                field,
                format!(
                    "no body '{name}' (bodies: {})",
                    self.bodies.keys().copied().collect::<Vec<_>>().join(", ")
                ),
            ))
        }
    }

    fn moving_joint(&self, field: &str, name: &str) -> Result<()> {
        self.body(field, name, false)?;
        if let Some((_, JointType::Fixed)) = self.bodies.get(name) {
            return Err(bad(
                field,
                format!("'{name}' is on a fixed joint: it has no coordinate"),
            ));
        }
        Ok(())
    }
}

fn unique<'a>(seen: &mut BTreeSet<&'a str>, field: &str, name: &'a str) -> Result<()> {
    if name.trim().is_empty() {
        return Err(bad(field, "must not be empty"));
    }
    if !seen.insert(name) {
        return Err(bad(field, format!("'{name}' is used twice")));
    }
    Ok(())
}

fn outline(field: &str, parts: &[OutlinePart]) -> Result<()> {
    for (i, part) in parts.iter().enumerate() {
        let f = format!("{field}[{i}]");
        match (&part.circle, part.points.len()) {
            (Some(c), 0) => {
                point(&format!("{f}.circle.center"), c.center)?;
                positive(&format!("{f}.circle.radius"), c.radius)?;
            }
            (None, n) if n >= 3 => {
                for (k, p) in part.points.iter().enumerate() {
                    point(&format!("{f}.points[{k}]"), *p)?;
                }
            }
            (Some(_), _) => {
                return Err(bad(&f, "has both `points` and `circle`: give one"));
            }
            (None, n) => {
                return Err(bad(
                    format!("{f}.points"),
                    format!("a polygon needs at least 3 corners, got {n} (or give `circle`)"),
                ));
            }
        }
        positive(&format!("{f}.thickness"), part.thickness)?;
        finite(&format!("{f}.z"), part.z)?;
    }
    Ok(())
}

fn shape(field: &str, s: &ShapeSpec) -> Result<()> {
    match s {
        ShapeSpec::Circle { center, radius } => {
            point(&format!("{field}.circle.center"), *center)?;
            positive(&format!("{field}.circle.radius"), *radius)?;
        }
        ShapeSpec::Segment { a, b } => {
            point(&format!("{field}.segment.a"), *a)?;
            point(&format!("{field}.segment.b"), *b)?;
            if a == b {
                return Err(bad(
                    format!("{field}.segment"),
                    "its two ends coincide: a face needs a length",
                ));
            }
        }
        ShapeSpec::Arc {
            center,
            radius,
            start,
            sweep,
            ..
        } => {
            point(&format!("{field}.arc.center"), *center)?;
            positive(&format!("{field}.arc.radius"), *radius)?;
            finite(&format!("{field}.arc.start"), *start)?;
            let s = positive(&format!("{field}.arc.sweep"), *sweep)?;
            if s > 2.0 * std::f64::consts::PI + 1e-12 {
                return Err(bad(
                    format!("{field}.arc.sweep"),
                    format!("must be at most 2π, got {s}"),
                ));
            }
        }
        ShapeSpec::Profile { points } => {
            if points.len() < 2 {
                return Err(bad(
                    format!("{field}.profile.points"),
                    format!("needs at least 2 points, got {}", points.len()),
                ));
            }
            for (k, p) in points.iter().enumerate() {
                point(&format!("{field}.profile.points[{k}]"), *p)?;
            }
            for (k, w) in points.windows(2).enumerate() {
                if w[0] == w[1] {
                    return Err(bad(
                        format!("{field}.profile.points[{}]", k + 1),
                        "repeats the previous point",
                    ));
                }
            }
        }
    }
    Ok(())
}

fn side(field: &str, s: &ContactSideSpec, names: &Names<'_>) -> Result<()> {
    names.body(&format!("{field}.body"), &s.body, true)?;
    if s.shapes.is_empty() {
        return Err(bad(format!("{field}.shapes"), "needs at least one shape"));
    }
    for (i, sh) in s.shapes.iter().enumerate() {
        shape(&format!("{field}.shapes[{i}]"), sh)?;
    }
    Ok(())
}

pub(crate) fn law(field: &str, l: &LawSpec) -> Result<()> {
    match l {
        LawSpec::Material(name) => {
            material(&format!("{field}.material"), name)?;
        }
        LawSpec::Felt {
            k,
            p,
            e,
            smoothing,
            alpha,
        } => {
            positive(&format!("{field}.felt.k"), *k)?;
            positive(&format!("{field}.felt.p"), *p)?;
            let e = positive(&format!("{field}.felt.e"), *e)?;
            if e > 1.0 {
                return Err(bad(
                    format!("{field}.felt.e"),
                    format!("a restitution lies in (0, 1], got {e}"),
                ));
            }
            positive(&format!("{field}.felt.smoothing"), *smoothing)?;
            non_negative(&format!("{field}.felt.alpha"), *alpha)?;
        }
        LawSpec::Hertz { k, p } => {
            positive(&format!("{field}.hertz.k"), *k)?;
            positive(&format!("{field}.hertz.p"), *p)?;
        }
        LawSpec::KelvinVoigt { k, c } => {
            positive(&format!("{field}.kelvin_voigt.k"), *k)?;
            non_negative(&format!("{field}.kelvin_voigt.c"), *c)?;
        }
        LawSpec::HuntCrossley { k, p, alpha } => {
            positive(&format!("{field}.hunt_crossley.k"), *k)?;
            positive(&format!("{field}.hunt_crossley.p"), *p)?;
            non_negative(&format!("{field}.hunt_crossley.alpha"), *alpha)?;
        }
        LawSpec::Stulov {
            q0,
            p,
            epsilon,
            tau0,
        } => {
            positive(&format!("{field}.stulov.q0"), *q0)?;
            positive(&format!("{field}.stulov.p"), *p)?;
            let e = non_negative(&format!("{field}.stulov.epsilon"), *epsilon)?;
            if e >= 1.0 {
                return Err(bad(
                    format!("{field}.stulov.epsilon"),
                    format!("must lie in [0, 1), got {e}"),
                ));
            }
            positive(&format!("{field}.stulov.tau0"), *tau0)?;
        }
    }
    Ok(())
}

pub(crate) fn friction(field: &str, f: &ContactFrictionSpec) -> Result<()> {
    match f {
        ContactFrictionSpec::Coulomb { mu, regularization } => {
            non_negative(&format!("{field}.coulomb.mu"), *mu)?;
            positive(&format!("{field}.coulomb.regularization"), *regularization)?;
        }
        ContactFrictionSpec::Material {
            name,
            regularization,
        } => {
            material(&format!("{field}.material.name"), name)?;
            positive(&format!("{field}.material.regularization"), *regularization)?;
        }
    }
    Ok(())
}

fn body_point(field: &str, p: &BodyPoint, names: &Names<'_>) -> Result<()> {
    names.body(&format!("{field}.body"), &p.body, true)?;
    point(&format!("{field}.point"), p.point)
}

fn two_ends(field: &str, a: &BodyPoint, b: &BodyPoint, names: &Names<'_>) -> Result<()> {
    body_point(&format!("{field}.a"), a, names)?;
    body_point(&format!("{field}.b"), b, names)?;
    if a.body == GROUND && b.body == GROUND {
        return Err(bad(
            field,
            "both ends are on the ground, so it would act on nothing",
        ));
    }
    Ok(())
}

impl Mechanism {
    /// Checks the description: names exist and are unique, the joints form a tree (no
    /// cycle, a parent before its children), every number is finite and in its range,
    /// every material is known. The first problem is returned, naming its field.
    pub fn validate(&self) -> Result<()> {
        point("gravity", self.gravity)?;
        outline("ground", &self.ground)?;
        if self.bodies.is_empty() {
            return Err(bad("bodies", "a mechanism needs at least one moving body"));
        }
        // Names and the tree.
        let mut names = Names {
            bodies: BTreeMap::new(),
        };
        for (i, b) in self.bodies.iter().enumerate() {
            let f = format!("bodies[{i}].name");
            if b.name == GROUND {
                return Err(bad(
                    f,
                    "'ground' is the fixed world; name the body otherwise",
                ));
            }
            if b.name.trim().is_empty() {
                return Err(bad(f, "must not be empty"));
            }
            if names
                .bodies
                .insert(b.name.as_str(), (i, b.joint.kind))
                .is_some()
            {
                return Err(bad(f, format!("'{}' is used twice", b.name)));
            }
        }
        for (i, b) in self.bodies.iter().enumerate() {
            let f = format!("bodies[{i}]");
            let parent = b.joint.parent.as_str();
            if parent == b.name {
                return Err(bad(
                    format!("{f}.joint.parent"),
                    format!("'{}' cannot be its own parent", b.name),
                ));
            }
            if parent != GROUND {
                names.body(&format!("{f}.joint.parent"), parent, true)?;
                // Follow the parents: a cycle never reaches the ground.
                let mut chain = vec![b.name.as_str()];
                let mut at = parent;
                while at != GROUND {
                    if chain.contains(&at) {
                        chain.push(at);
                        return Err(bad(
                            format!("{f}.joint.parent"),
                            format!(
                                "the joints form a cycle ({}): a mechanism is a tree of \
                                 joints from the ground (close a loop with a contact or a \
                                 spring)",
                                chain.join(" → ")
                            ),
                        ));
                    }
                    chain.push(at);
                    let (k, _) = names.bodies[at];
                    at = self.bodies[k].joint.parent.as_str();
                }
                let (k, _) = names.bodies[parent];
                if k > i {
                    return Err(bad(
                        format!("{f}.joint.parent"),
                        format!(
                            "'{parent}' is declared after '{}' (bodies[{k}]): list a parent \
                             before its children",
                            b.name
                        ),
                    ));
                }
            }
        }
        for (i, b) in self.bodies.iter().enumerate() {
            let f = format!("bodies[{i}]");
            positive(&format!("{f}.mass"), b.mass)?;
            point(&format!("{f}.com"), b.com)?;
            positive(&format!("{f}.inertia"), b.inertia)?;
            let j = &b.joint;
            point(&format!("{f}.joint.at"), j.at)?;
            finite(&format!("{f}.joint.angle"), j.angle)?;
            match (j.kind, j.axis) {
                (JointType::Prismatic, Some(a)) => direction(&format!("{f}.joint.axis"), a)?,
                (JointType::Prismatic, None) => {
                    return Err(bad(
                        format!("{f}.joint.axis"),
                        "a prismatic joint needs its sliding axis",
                    ));
                }
                (_, Some(_)) => {
                    return Err(bad(
                        format!("{f}.joint.axis"),
                        "only a prismatic joint has an axis",
                    ));
                }
                (_, None) => {}
            }
            if j.kind == JointType::Fixed && (j.limits.is_some() || j.friction.is_some()) {
                return Err(bad(
                    format!("{f}.joint"),
                    "a fixed joint has no stops and no friction",
                ));
            }
            if let Some(l) = j.limits {
                let lf = format!("{f}.joint.limits");
                if let Some(v) = l.lower {
                    finite(&format!("{lf}.lower"), v)?;
                }
                if let Some(v) = l.upper {
                    finite(&format!("{lf}.upper"), v)?;
                }
                if let (Some(lo), Some(hi)) = (l.lower, l.upper)
                    && lo >= hi
                {
                    return Err(bad(&lf, format!("needs lower < upper, got {lo} and {hi}")));
                }
                if l.lower.is_none() && l.upper.is_none() {
                    return Err(bad(&lf, "give `lower`, `upper` or both"));
                }
                non_negative(&format!("{lf}.stiffness"), l.stiffness)?;
                non_negative(&format!("{lf}.damping"), l.damping)?;
            }
            if let Some(fr) = j.friction {
                let ff = format!("{f}.joint.friction");
                non_negative(&format!("{ff}.coulomb"), fr.coulomb)?;
                positive(&format!("{ff}.regularization"), fr.regularization)?;
                non_negative(&format!("{ff}.viscous"), fr.viscous)?;
                if let Some(s) = fr.stribeck {
                    if finite(&format!("{ff}.stribeck.static_torque"), s.static_torque)?
                        < fr.coulomb
                    {
                        return Err(bad(
                            format!("{ff}.stribeck.static_torque"),
                            format!(
                                "the breakaway torque must be at least the Coulomb torque {}, \
                                 got {}",
                                fr.coulomb, s.static_torque
                            ),
                        ));
                    }
                    positive(&format!("{ff}.stribeck.velocity"), s.velocity)?;
                }
            }
            outline(&format!("{f}.outline"), &b.outline)?;
        }

        // Force elements.
        let mut elements = BTreeSet::new();
        for (i, s) in self.torsion_springs.iter().enumerate() {
            let f = format!("torsion_springs[{i}]");
            unique(&mut elements, &format!("{f}.name"), &s.name)?;
            names.moving_joint(&format!("{f}.joint"), &s.joint)?;
            non_negative(&format!("{f}.stiffness"), s.stiffness)?;
            finite(&format!("{f}.rest"), s.rest)?;
            finite(&format!("{f}.preload"), s.preload)?;
            non_negative(&format!("{f}.damping"), s.damping)?;
        }
        for (i, s) in self.point_springs.iter().enumerate() {
            let f = format!("point_springs[{i}]");
            unique(&mut elements, &format!("{f}.name"), &s.name)?;
            two_ends(&f, &s.a, &s.b, &names)?;
            non_negative(&format!("{f}.stiffness"), s.stiffness)?;
            non_negative(&format!("{f}.rest_length"), s.rest_length)?;
            finite(&format!("{f}.preload"), s.preload)?;
            non_negative(&format!("{f}.damping"), s.damping)?;
        }
        for (i, c) in self.cords.iter().enumerate() {
            let f = format!("cords[{i}]");
            unique(&mut elements, &format!("{f}.name"), &c.name)?;
            two_ends(&f, &c.a, &c.b, &names)?;
            let l = finite(&format!("{f}.length"), c.length)?;
            if l <= 0.0 {
                return Err(bad(
                    format!("{f}.length"),
                    format!("a cord's slack length must be positive, got {l}"),
                ));
            }
            non_negative(&format!("{f}.stiffness"), c.stiffness)?;
            non_negative(&format!("{f}.damping"), c.damping)?;
        }
        for (i, l) in self.loads.iter().enumerate() {
            let f = format!("loads[{i}]");
            unique(&mut elements, &format!("{f}.name"), &l.name)?;
            body_point(&format!("{f}.at"), &l.at, &names)?;
            names.body(&format!("{f}.at.body"), &l.at.body, false)?;
            direction(&format!("{f}.direction"), l.direction)?;
            finite(&format!("{f}.magnitude"), l.magnitude)?;
        }
        let mut contacts = BTreeSet::new();
        for (i, c) in self.contacts.iter().enumerate() {
            let f = format!("contacts[{i}]");
            unique(&mut contacts, &format!("{f}.name"), &c.name)?;
            side(&format!("{f}.a"), &c.a, &names)?;
            side(&format!("{f}.b"), &c.b, &names)?;
            if c.a.body == c.b.body {
                return Err(bad(
                    format!("{f}.b.body"),
                    format!(
                        "a contact between '{}' and itself: its shapes never move apart",
                        c.a.body
                    ),
                ));
            }
            law(&format!("{f}.law"), &c.law)?;
            if let Some(fr) = &c.friction {
                friction(&format!("{f}.friction"), fr)?;
            }
        }
        for (i, s) in self.strings.iter().enumerate() {
            let f = format!("strings[{i}]");
            unique(&mut contacts, &format!("{f}.name"), &s.name)?;
            point(&format!("{f}.line[0]"), s.line[0])?;
            point(&format!("{f}.line[1]"), s.line[1])?;
            if s.line[0] == s.line[1] {
                return Err(bad(format!("{f}.line"), "its two ends coincide"));
            }
            side(&format!("{f}.striker"), &s.striker, &names)?;
            names.body(&format!("{f}.striker.body"), &s.striker.body, false)?;
            law(&format!("{f}.law"), &s.law)?;
            if let LawSpec::Stulov { .. } = s.law {
                return Err(bad(
                    format!("{f}.law"),
                    "a striker on a string takes an elastic law (the string gives the loss)",
                ));
            }
        }
        for (i, e) in self.extensions.iter().enumerate() {
            let f = format!("extensions[{i}]");
            names.body(&format!("{f}.body"), &e.body, false)?;
            for (k, v) in &e.params {
                finite(&format!("{f}.params.{k}"), *v)?;
            }
        }

        // Inputs, markers, events, metrics.
        let mut inputs = BTreeSet::new();
        for (i, input) in self.inputs.iter().enumerate() {
            let f = format!("inputs[{i}]");
            unique(&mut inputs, &format!("{f}.name"), &input.name)?;
            body_point(&format!("{f}.at"), &input.at, &names)?;
            match input.kind {
                InputKind::Force => names.body(&format!("{f}.at.body"), &input.at.body, false)?,
                InputKind::Motion => names.moving_joint(&format!("{f}.at.body"), &input.at.body)?,
            }
            direction(&format!("{f}.direction"), input.direction)?;
        }
        let mut markers = BTreeSet::new();
        for (i, m) in self.markers.iter().enumerate() {
            let f = format!("markers[{i}]");
            unique(&mut markers, &format!("{f}.name"), &m.name)?;
            body_point(&format!("{f}.at"), &m.at, &names)?;
        }
        let mut events = BTreeSet::new();
        for (i, e) in self.events.iter().enumerate() {
            let f = format!("events[{i}]");
            unique(&mut events, &format!("{f}.name"), &e.name)?;
            match (&e.contact, &e.coordinate) {
                (Some(c), None) => {
                    if !contacts.contains(c.as_str()) {
                        return Err(bad(
                            format!("{f}.contact"),
                            format!("no contact or string '{c}'"),
                        ));
                    }
                    if e.on.is_none() {
                        return Err(bad(format!("{f}.on"), "say `onset` or `release`"));
                    }
                    if e.value.is_some() || e.direction.is_some() {
                        return Err(bad(
                            &f,
                            "`value` and `direction` belong to a coordinate event",
                        ));
                    }
                }
                (None, Some(c)) => {
                    names.moving_joint(&format!("{f}.coordinate"), c)?;
                    match e.value {
                        Some(v) => {
                            finite(&format!("{f}.value"), v)?;
                        }
                        None => {
                            return Err(bad(
                                format!("{f}.value"),
                                "a coordinate event needs the value it crosses",
                            ));
                        }
                    }
                    if e.on.is_some() {
                        return Err(bad(format!("{f}.on"), "`on` belongs to a contact event"));
                    }
                }
                _ => {
                    return Err(bad(
                        &f,
                        "give either `contact` (with `on`) or `coordinate` (with `value`)",
                    ));
                }
            }
        }
        let mut metrics = BTreeSet::new();
        for (i, m) in self.metrics.iter().enumerate() {
            let f = format!("metrics[{i}]");
            unique(&mut metrics, &format!("{f}.name"), &m.name)?;
            if !events.contains(m.at.as_str()) {
                return Err(bad(format!("{f}.at"), format!("no event '{}'", m.at)));
            }
            match (&m.marker, m.quantity) {
                (None, Quantity::Time) => {}
                (Some(_), Quantity::Time) => {
                    return Err(bad(format!("{f}.marker"), "a time needs no marker"));
                }
                (Some(mk), _) if markers.contains(mk.as_str()) => {}
                (Some(mk), _) => {
                    return Err(bad(format!("{f}.marker"), format!("no marker '{mk}'")));
                }
                (None, _) => {
                    return Err(bad(format!("{f}.marker"), "this quantity needs a marker"));
                }
            }
        }
        Ok(())
    }
}
