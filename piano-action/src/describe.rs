//! The grand actions as mechanism descriptions: parameters → [`Mechanism`].
//!
//! The parameter file speaks a technician's language (millimetres in the world frame of the
//! action's drawing, grams, regulation screws); a [`Mechanism`] speaks the engine's (SI,
//! every body in its joint's frame). This module is the one place where the first becomes
//! the second for the three grand models; [`crate::Action`] builds its system from the
//! result, so `piano describe --model double > grand.toml` gives a file that simulates
//! exactly like the built-in model.
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
//! μ > 0): key–front rail, key–back rail, capstan–heel, jack–knuckle, lever–knuckle, jack
//! toe–let-off button, lever tip–drop screw, tail–backcheck, shank–rest rail; and
//! hammer–string, the crown's felt (C&A power law) against a modal string, whose internal
//! states (two per mode) end the state. Springs: repetition and jack springs, with their
//! stops as joint limits. Pivot friction at every centre.

use std::collections::BTreeMap;

use mbs_core::{ForceElement, Inertia, Model};
use mbs_mechanism::{
    Body, BodyPoint, ContactFrictionSpec, ContactPair, ContactPhase, ContactSideSpec, EventSpec,
    Extension, Extensions, Input, InputKind, Joint, JointType, LawSpec, Limits, LoadSpec, Marker,
    Mechanism, MechanismError, Metric, PivotFrictionSpec, Quantity, ShapeSpec, StringModes,
    StringPair, TorsionSpring,
};

use crate::action::{ModelKind, PRESSER_PAD_RADIUS_MM, Presser};
use crate::error::Result;
use crate::identify::effects::{EffectEntry, FlangeEffectElement, FlangeEffects, HAMMER_FLANGE};
use crate::params::{ActionParams, ContactParams, GRAVITY_M_S2};

/// The kind of the extension element that carries the pendulum's flange effects.
pub const FLANGE_EFFECT: &str = "flange_effect";

/// The extension parameter that carries the pivot friction's regularisation speed (rad/s)
/// to a flange effect.
const REGULARIZATION_KEY: &str = "regularization_rad_s";

/// mm → m.
fn m(v: [f64; 2]) -> [f64; 2] {
    [v[0] * 1e-3, v[1] * 1e-3]
}

/// `p − origin`, mm → m: the world point `p` in the unturned frame at `origin`.
fn rel(p: [f64; 2], origin: [f64; 2]) -> [f64; 2] {
    mbs_mechanism::WorldFrame::at(origin).local(p)
}

/// A horizontal ground face at height `y` over `x`, facing up or down (mm in, shape in m).
fn ground_face(y: f64, x: [f64; 2], up: bool) -> ShapeSpec {
    let (a, b) = if up {
        ([x[0], y], [x[1], y])
    } else {
        ([x[1], y], [x[0], y])
    };
    ShapeSpec::Segment { a: m(a), b: m(b) }
}

/// A face through `p` along direction `d` (unit), from `back` before to `ahead` after `p`,
/// its outward normal `d` turned a quarter counter-clockwise (mm in, shape in m).
fn face(p: [f64; 2], d: [f64; 2], back: f64, ahead: f64) -> ShapeSpec {
    let a = [p[0] - back * d[0], p[1] - back * d[1]];
    let b = [p[0] + ahead * d[0], p[1] + ahead * d[1]];
    ShapeSpec::Segment { a: m(a), b: m(b) }
}

fn circle(c: [f64; 2], r_mm: f64) -> ShapeSpec {
    ShapeSpec::Circle {
        center: m(c),
        radius: r_mm * 1e-3,
    }
}

fn on(body: &str, shapes: Vec<ShapeSpec>) -> ContactSideSpec {
    ContactSideSpec {
        body: body.to_string(),
        shapes,
    }
}

fn ground(shapes: Vec<ShapeSpec>) -> ContactSideSpec {
    on(mbs_mechanism::GROUND, shapes)
}

fn revolute(parent: &str, at: [f64; 2], angle: f64) -> Joint {
    Joint {
        kind: JointType::Revolute,
        parent: parent.to_string(),
        at,
        angle,
        axis: None,
        limits: None,
        friction: None,
    }
}

/// The grand action `kind` built from `params`, with a [`Presser`] over the key front if
/// given (body `"presser"`, prismatic, positive up; contact `"presser_key"`). The
/// parameters are checked first.
pub fn grand_mechanism(
    params: &ActionParams,
    kind: ModelKind,
    presser: Option<Presser>,
) -> Result<Mechanism> {
    params.validate()?;
    let p = params;
    let (k, w, j, r, h) = (&p.key, &p.wippen, &p.jack, &p.repetition_lever, &p.hammer);
    let with_jack = kind != ModelKind::Simplified;
    let with_lever = kind == ModelKind::Double;
    let reg = p.numerics.pivot_friction_regularization_rad_s;
    let friction = |torque: f64| {
        (torque > 0.0).then_some(PivotFrictionSpec {
            coulomb: torque,
            regularization: reg,
            viscous: 0.0,
            stribeck: None,
        })
    };
    let (stop_k, stop_c) = (
        p.numerics.stop_stiffness_n_m_per_rad,
        p.numerics.stop_damping_n_m_s_per_rad,
    );
    let tag = "from the parameter file (see its tags)";

    // Bodies: mass (kg), centre of mass in the joint frame (m), inertia about it.
    let mut bodies = Vec::new();
    let key_com = rel(k.com_mm, k.pivot_mm);
    let key_mass = k.mass_g * 1e-3;
    let key_i = k.inertia_pivot_kg_m2 - Inertia::parallel_axis(key_mass, key_com);
    bodies.push(Body {
        name: "key".into(),
        note: format!("balance pivot; {tag}"),
        mass: key_mass,
        com: key_com,
        inertia: key_i,
        joint: Joint {
            friction: friction(k.pivot_friction_n_m),
            ..revolute("ground", [k.pivot_mm[0] * 1e-3, k.pivot_mm[1] * 1e-3], 0.0)
        },
        outline: Vec::new(),
    });
    bodies.push(Body {
        name: "wippen".into(),
        note: format!("wippen flange; {tag}"),
        mass: w.mass_g * 1e-3,
        com: rel(w.com_mm, w.pivot_mm),
        inertia: w.inertia_com_kg_m2,
        joint: Joint {
            friction: friction(w.pivot_friction_n_m),
            ..revolute("ground", [w.pivot_mm[0] * 1e-3, w.pivot_mm[1] * 1e-3], 0.0)
        },
        outline: Vec::new(),
    });
    let jack_at = rel(j.pivot_mm, w.pivot_mm);
    let jack_com = rel(j.com_mm, j.pivot_mm);
    let jack_mass = j.mass_g * 1e-3;
    let jack_i = j.inertia_pivot_kg_m2 - Inertia::parallel_axis(jack_mass, jack_com);
    bodies.push(Body {
        name: "jack".into(),
        note: if with_jack {
            format!("jack centre on the wippen; {tag}")
        } else {
            format!("fixed to the wippen in the simplified model; {tag}")
        },
        mass: jack_mass,
        com: jack_com,
        inertia: jack_i,
        joint: if with_jack {
            Joint {
                limits: Some(Limits {
                    lower: finite_or_none(j.stop_angle_rad),
                    upper: finite_or_none(j.outer_stop_rad),
                    stiffness: stop_k,
                    damping: stop_c,
                }),
                friction: friction(j.pivot_friction_n_m),
                ..revolute("wippen", jack_at, 0.0)
            }
        } else {
            Joint {
                kind: JointType::Fixed,
                ..revolute("wippen", jack_at, 0.0)
            }
        },
        outline: Vec::new(),
    });
    if with_lever {
        let at = rel(r.pivot_mm, w.pivot_mm);
        let com = rel(r.com_mm, r.pivot_mm);
        let mass = r.mass_g * 1e-3;
        let i = r.inertia_pivot_kg_m2 - Inertia::parallel_axis(mass, com);
        bodies.push(Body {
            name: "repetition_lever".into(),
            note: format!("repetition lever centre on the wippen; {tag}"),
            mass,
            com,
            inertia: i,
            joint: Joint {
                limits: Some(Limits {
                    lower: finite_or_none(r.upper_stop_rad),
                    upper: None,
                    stiffness: stop_k,
                    damping: stop_c,
                }),
                friction: friction(r.pivot_friction_n_m),
                ..revolute("wippen", at, 0.0)
            },
            outline: Vec::new(),
        });
    }
    bodies.push(Body {
        name: "hammer".into(),
        note: format!("hammer flange; the frame lies along the shank; {tag}"),
        mass: h.mass_g * 1e-3,
        com: m(h.com_body_mm),
        inertia: h.inertia_com_kg_m2,
        joint: Joint {
            friction: friction(h.pivot_friction_n_m),
            ..revolute(
                "ground",
                [h.pivot_mm[0] * 1e-3, h.pivot_mm[1] * 1e-3],
                h.rest_angle_deg.to_radians(),
            )
        },
        outline: Vec::new(),
    });
    if let Some(pr) = presser {
        bodies.push(Body {
            name: "presser".into(),
            note: "a weight or a finger over the key front, sliding vertically".into(),
            mass: pr.mass_kg,
            com: [0.0, 0.0],
            inertia: pr.mass_kg * 1e-4,
            joint: Joint {
                kind: JointType::Prismatic,
                axis: Some([0.0, 1.0]),
                ..revolute(
                    "ground",
                    [
                        k.finger_mm[0] * 1e-3,
                        (k.finger_mm[1] + PRESSER_PAD_RADIUS_MM + pr.height_mm) * 1e-3,
                    ],
                    0.0,
                )
            },
            outline: Vec::new(),
        });
    }

    // Springs: the spring's torque at the stop is the preload, pushing the jack (lever)
    // back against it.
    let mut torsion_springs = Vec::new();
    if with_jack {
        torsion_springs.push(TorsionSpring {
            name: "jack spring".into(),
            note: format!("{tag}: spring_stiffness_n_m_per_rad, spring_preload_n_m"),
            joint: "jack".into(),
            stiffness: j.spring_stiffness_n_m_per_rad,
            rest: 0.0,
            preload: -j.spring_preload_n_m,
            damping: 0.0,
        });
    }
    if with_lever {
        torsion_springs.push(TorsionSpring {
            name: "repetition spring".into(),
            note: format!("{tag}: spring_stiffness_n_m_per_rad, spring_preload_n_m"),
            joint: "repetition_lever".into(),
            stiffness: r.spring_stiffness_n_m_per_rad,
            rest: 0.0,
            preload: -r.spring_preload_n_m,
            damping: 0.0,
        });
    }
    let extensions = p
        .effects
        .iter()
        .map(|e| {
            let mut params = e.params.clone();
            params.insert(REGULARIZATION_KEY.into(), reg);
            Extension {
                kind: FLANGE_EFFECT.into(),
                name: e.id.clone(),
                body: "hammer".into(),
                params,
            }
        })
        .collect();

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
    );
    // Jack top: along t, facing the jack axis n.
    let n = j.axis;
    let t = [n[1], -n[0]];
    let jack_top = face(
        [j.top_mm[0] - j.pivot_mm[0], j.top_mm[1] - j.pivot_mm[1]],
        t,
        j.top_front_edge_mm,
        j.top_back_edge_mm,
    );
    let toe = circle(
        [
            j.toe_mm[0] - j.pivot_mm[0],
            j.toe_mm[1] - j.pivot_mm[1] - j.toe_radius_mm,
        ],
        j.toe_radius_mm,
    );
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
    );
    let knuckle = circle(h.knuckle_body_mm, h.knuckle_radius_mm);
    let crown = circle(
        [h.strike_body_mm[0], h.strike_body_mm[1] - h.crown_radius_mm],
        h.crown_radius_mm,
    );
    let tail = circle(h.tail_body_mm, h.tail_radius_mm);
    let shank_under = circle([h.rest_body_mm[0], h.rest_body_mm[1] + 0.5], 0.5);

    // Felt, cloth and leather lose the same share of energy in a slow settle as in a hard
    // blow (rate-independent hysteresis, Boutillon 1988; Hirschkorn et al. 2006):
    // restitution `e` at every speed above the smoothing speed.
    let pair =
        |name: &str, a: ContactSideSpec, b: ContactSideSpec, law: &ContactParams| ContactPair {
            name: name.into(),
            note: format!("{tag}: contacts.{name}"),
            a,
            b,
            law: LawSpec::Felt {
                k: law.k,
                p: law.p,
                e: law.e,
                smoothing: p.numerics.felt_smoothing_m_s,
                alpha: 0.0,
            },
            friction: (law.mu > 0.0).then_some(ContactFrictionSpec::Coulomb {
                mu: law.mu,
                regularization: p.numerics.friction_regularization_m_s,
            }),
        };
    let c = &p.contacts;
    let mut contacts = vec![
        pair(
            "front_rail",
            ground(vec![ground_face(
                g.front_rail_top_y_mm,
                g.front_rail_x_mm,
                true,
            )]),
            on(
                "key",
                vec![circle(
                    [k.front_pad_mm[0] - kp[0], k.front_pad_mm[1] - kp[1]],
                    k.front_pad_radius_mm,
                )],
            ),
            &c.front_rail,
        ),
        pair(
            "back_rail",
            ground(vec![ground_face(
                g.back_rail_top_y_mm,
                g.back_rail_x_mm,
                true,
            )]),
            on(
                "key",
                vec![circle(
                    [k.back_pad_mm[0] - kp[0], k.back_pad_mm[1] - kp[1]],
                    k.back_pad_radius_mm,
                )],
            ),
            &c.back_rail,
        ),
        pair(
            "capstan_heel",
            on(
                "key",
                vec![circle(
                    [capstan[0] - kp[0], capstan[1] - kp[1]],
                    k.capstan_radius_mm,
                )],
            ),
            on("wippen", vec![heel]),
            &c.capstan_heel,
        ),
        pair(
            "jack_knuckle",
            on("jack", vec![jack_top]),
            on("hammer", vec![knuckle.clone()]),
            &c.jack_knuckle,
        ),
    ];
    if with_jack {
        contacts.push(pair(
            "let_off_button",
            ground(vec![ground_face(
                g.let_off_button_y_mm,
                g.let_off_button_x_mm,
                false,
            )]),
            on("jack", vec![toe]),
            &c.let_off_button,
        ));
        contacts.push(pair(
            "backcheck",
            on("key", vec![backcheck]),
            on("hammer", vec![tail]),
            &c.backcheck,
        ));
    }
    if with_lever {
        let lever_top = face(
            [r.top_mm[0] - r.pivot_mm[0], r.top_mm[1] - r.pivot_mm[1]],
            t,
            r.top_front_edge_mm,
            r.top_back_edge_mm,
        );
        let tip = circle(
            [
                r.tip_mm[0] - r.pivot_mm[0],
                r.tip_mm[1] - r.pivot_mm[1] - r.tip_radius_mm,
            ],
            r.tip_radius_mm,
        );
        contacts.push(pair(
            "lever_knuckle",
            on("repetition_lever", vec![lever_top]),
            on("hammer", vec![knuckle]),
            &c.lever_knuckle,
        ));
        contacts.push(pair(
            "drop_screw",
            ground(vec![ground_face(
                g.drop_screw_y_mm,
                g.drop_screw_x_mm,
                false,
            )]),
            on("repetition_lever", vec![tip]),
            &c.drop_screw,
        ));
    }
    contacts.push(pair(
        "rest_rail",
        ground(vec![ground_face(
            g.rest_rail_top_y_mm,
            g.rest_rail_x_mm,
            true,
        )]),
        on("hammer", vec![shank_under]),
        &c.rest_rail,
    ));
    let mut loads = Vec::new();
    if let Some(pr) = presser {
        if pr.carried {
            // What holds the finger up (the arm) balances its weight.
            loads.push(LoadSpec {
                name: "presser weight carried".into(),
                note: "the arm carries the finger's weight".into(),
                at: BodyPoint {
                    body: "presser".into(),
                    point: [0.0, 0.0],
                },
                direction: [0.0, 1.0],
                magnitude: -pr.mass_kg * -GRAVITY_M_S2,
            });
        }
        let kf = crate::key::KeyGeometry::of(k).finger_mm;
        let mut presser_key = pair(
            "presser_key",
            on(
                "key",
                vec![ShapeSpec::Segment {
                    a: m([kf[0] - 12.0, kf[1]]),
                    b: m([kf[0] + 12.0, kf[1]]),
                }],
            ),
            on("presser", vec![circle([0.0, 0.0], PRESSER_PAD_RADIUS_MM)]),
            &pr.pad,
        );
        presser_key.note = "the presser's pad on the key top".into();
        contacts.push(presser_key);
    }
    // The hammer strikes a modal string lying along the string line (the felt undamped:
    // the string's motion gives the rebound).
    let spec = p.string.spec();
    let [a, b] = match ground_face(g.string_y_mm, g.string_x_mm, false) {
        ShapeSpec::Segment { a, b } => [a, b],
        _ => unreachable!("ground_face gives a segment"),
    };
    let strings = vec![StringPair {
        name: "hammer_string".into(),
        note: format!("{tag}: [string], contacts.hammer_string"),
        line: [a, b],
        striker: on("hammer", vec![crown]),
        law: LawSpec::Hertz {
            k: c.hammer_string.k,
            p: c.hammer_string.p,
        },
        string: StringModes {
            length_m: spec.length_m,
            fundamental_hz: spec.fundamental_hz,
            mass_kg: spec.mass_kg,
            tension_n: spec.tension_n,
            inharmonicity: spec.inharmonicity,
            striking_ratio: spec.striking_ratio,
            strings: spec.strings,
            loss_b1: spec.loss_b1,
            loss_b3: spec.loss_b3,
            modes: spec.modes,
            residual_compliance: spec.residual_compliance,
        },
    }];

    let kf = crate::key::KeyGeometry::of(k).finger_mm;
    let inputs = vec![Input {
        name: "finger".into(),
        note: "the key front where a finger presses (force positive down)".into(),
        kind: InputKind::Force,
        at: BodyPoint {
            body: "key".into(),
            point: m(kf),
        },
        direction: [0.0, -1.0],
    }];
    let markers = vec![
        Marker {
            name: "key_front".into(),
            note: "the finger point on the key top".into(),
            at: BodyPoint {
                body: "key".into(),
                point: m(kf),
            },
        },
        Marker {
            name: "hammer_crown".into(),
            note: "the crown's striking point".into(),
            at: BodyPoint {
                body: "hammer".into(),
                point: m(h.strike_body_mm),
            },
        },
    ];
    Ok(Mechanism {
        name: format!("grand action, {} model", kind.name()),
        about: format!(
            "The {} grand action written by `piano describe` from the parameter file. Physical \
             constants carry their sources in the parameter file; contact laws are the \
             rate-independent hysteretic felts of the model.",
            kind.name()
        ),
        gravity: [0.0, -GRAVITY_M_S2],
        ground: Vec::new(),
        bodies,
        torsion_springs,
        point_springs: Vec::new(),
        cords: Vec::new(),
        loads,
        contacts,
        strings,
        extensions,
        inputs,
        markers,
        events: Vec::new(),
        metrics: Vec::new(),
    })
}

/// The grand action `kind` as `piano describe` writes it: [`grand_mechanism`] with the
/// drawing's outlines (so any tool draws it like the built-in model), the grand's named
/// events (`key_bottom`, `let_off`, `strike`, `string_release`, `check`) and metrics (the
/// crown's speed and the time at the first strike, the let-off time).
pub fn grand_description(params: &ActionParams, kind: ModelKind) -> Result<Mechanism> {
    let mut m = grand_mechanism(params, kind, None)?;
    let action = crate::Action::from_mechanism(params, kind, None, &m)?;
    let (ground, mut outlines) = crate::drawing::grand_outlines(&action)?;
    m.ground = ground;
    for body in &mut m.bodies {
        body.outline = outlines.remove(&body.name).unwrap_or_default();
    }
    let contact = |name: &str, contact: &str, on: ContactPhase| EventSpec {
        name: name.into(),
        contact: Some(contact.into()),
        on: Some(on),
        coordinate: None,
        value: None,
        direction: None,
    };
    m.events
        .push(contact("key_bottom", "front_rail", ContactPhase::Onset));
    if kind != ModelKind::Simplified {
        m.events
            .push(contact("let_off", "let_off_button", ContactPhase::Onset));
    }
    m.events
        .push(contact("strike", "hammer_string", ContactPhase::Onset));
    m.events.push(contact(
        "string_release",
        "hammer_string",
        ContactPhase::Release,
    ));
    if kind != ModelKind::Simplified {
        m.events
            .push(contact("check", "backcheck", ContactPhase::Onset));
    }
    let metric =
        |name: &str, quantity: Quantity, marker: Option<&str>, at: &str, unit: &str| Metric {
            name: name.into(),
            quantity,
            marker: marker.map(str::to_string),
            at: at.into(),
            unit: unit.into(),
        };
    m.metrics.push(metric(
        "hammer speed at the strike",
        Quantity::Speed,
        Some("hammer_crown"),
        "strike",
        "m/s",
    ));
    m.metrics
        .push(metric("strike time", Quantity::Time, None, "strike", "s"));
    if kind != ModelKind::Simplified {
        m.metrics
            .push(metric("let-off time", Quantity::Time, None, "let_off", "s"));
    }
    m.validate()?;
    Ok(m)
}

fn finite_or_none(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// The piano's extension elements: the pendulum's flange effects (`"flange_effect"`, on
/// the hammer's joint), all gathered into one element.
#[derive(Clone, Copy, Debug, Default)]
pub struct PianoExtensions;

impl Extensions for PianoExtensions {
    fn elements(
        &self,
        extensions: &[Extension],
        model: &Model,
        mechanism: &Mechanism,
    ) -> mbs_mechanism::Result<Vec<Box<dyn ForceElement>>> {
        let mut by_body: BTreeMap<&str, (Vec<EffectEntry>, f64)> = BTreeMap::new();
        for (i, e) in extensions.iter().enumerate() {
            if e.kind != FLANGE_EFFECT {
                return Err(MechanismError::field(
                    format!("extensions[{i}].kind"),
                    format!(
                        "no element of kind '{}' here (the piano provides '{FLANGE_EFFECT}')",
                        e.kind
                    ),
                ));
            }
            let mut params = e.params.clone();
            let reg = params.remove(REGULARIZATION_KEY).ok_or_else(|| {
                MechanismError::field(
                    format!("extensions[{i}].params.{REGULARIZATION_KEY}"),
                    "a flange effect needs the regularisation speed of its pivot (rad/s)",
                )
            })?;
            let entry = EffectEntry {
                id: e.name.clone(),
                location: HAMMER_FLANGE.into(),
                params,
            };
            entry
                .validate(&format!("extensions[{i}]"))
                .map_err(|err| MechanismError::caused(format!("extensions[{i}]"), err))?;
            let slot = by_body.entry(e.body.as_str()).or_insert((Vec::new(), reg));
            slot.0.push(entry);
            slot.1 = reg;
        }
        let mut out: Vec<Box<dyn ForceElement>> = Vec::new();
        for (body, (entries, reg)) in by_body {
            let b = mechanism
                .bodies
                .iter()
                .find(|b| b.name == body)
                .ok_or_else(|| MechanismError::field("extensions", format!("no body '{body}'")))?;
            let laws = FlangeEffects::from_entries(&entries)
                .map_err(|err| MechanismError::caused("extensions", err))?;
            let element =
                FlangeEffectElement::new(model, body, laws, reg, b.mass, b.com, b.joint.angle)
                    .map_err(|err| MechanismError::caused("extensions", err))?;
            out.push(Box::new(element));
        }
        Ok(out)
    }
}
