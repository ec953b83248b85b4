//! An upright (vertical) piano action written as a mechanism description through
//! `piano-action`'s public API: key, wippen, jack, hammer (butt, shank, head and catcher as
//! one body), hammer rest rail, let-off button, back-check on the wippen, bridle tape (a
//! cord), butt spring, jack spring, and the string in a vertical plane in front of the
//! hammer.
//!
//! The layout is `docs/reference/upright_layout.md`, §4–§6, every value tagged there
//! and here: \[V\] read in a source, \[S\] secondhand, \[M\] judged, \[D\] derived. Points
//! are given in the layout's world frame (mm, origin at the balance pivot, x toward the
//! strings, y up) and turned into each body's frame here, so the numbers can be checked
//! against the layout's tables line by line.
//!
//! **The jack in the butt notch.** In the upright the wippen and the hammer turn the same
//! way, so no rolling point exists between the jack top and the butt: the jack sits in the
//! notch and works as the coupler of a four-bar (wippen pin, jack pin, notch, butt pin;
//! layout §2.3). The engine is a tree of joints, so the loop is closed by two contacts: the
//! jack top (a 2 mm circle) against the notch's **seat** (the butt felt, which it lifts) and
//! against its **wall** (on the string side, which the jack spring presses it into). At
//! let-off the toe meets the button, the jack turns toward the player and its top slides
//! along the seat and off its lip (2 mm): the hammer flies free. In front of the lip the
//! butt's **face** rises: the escaped top leans on it and gets back into the notch only when
//! the notch comes down to it. At rest the top sits 0.5 mm under the seat (the **lost
//! motion**), so it can swing back in once the key is up; the dip, the let-off button and
//! the back-check are regulated for it (see the constants).
//!
//! [`repetition`] compares its repetition with the grand's double escapement.
//!
//! Not modelled: the damper (lever, spoon, spring: optional for hammer velocity, layout
//! §2.2), the jack-slap rail (a joint stop on the jack stands in for it), balance-rail
//! lift-off. The string is the grand's C4 unison (an upright's is shorter \[M\]).

pub mod repetition;

use piano_action::ActionParams;
use piano_action::mechanism::{
    Body, BodyPoint, ContactFrictionSpec, ContactPair, ContactPhase, ContactSideSpec, CordSpec,
    EventSpec, Input, InputKind, Joint, JointType, LawSpec, Limits, Marker, Mechanism, Metric,
    OutlinePart, PivotFrictionSpec, Quantity, ShapeSpec, StringPair, TorsionSpring, WorldFrame,
};

type P = [f64; 2];

/// mm → m.
fn m(p: P) -> P {
    [p[0] * 1e-3, p[1] * 1e-3]
}

/// A body frame at rest: its origin in the world (mm) and its angle (rad).
type Frame = WorldFrame;

/// The jack's frame: at its pin, unturned.
const JACK_FRAME: Frame = WorldFrame::at(J);

/// The hammer's frame: x along the shank (e1), y = e1 turned a quarter counter-clockwise
/// (= −e2: the layout's hammer axes are left-handed).
fn hammer_frame() -> Frame {
    WorldFrame::turned(H, E1[1].atan2(E1[0]))
}

/// How far (mm) the back-check face is set back along its normal (0.112, 0.994) from the
/// layout's (§4.2 \[D\], 15 mm check at 10.0 mm dip), as a technician bends the wire for
/// the deeper dip: a slow press is checked about 15 mm from the string again \[D\].
const BACKCHECK_SET_BACK_MM: f64 = 0.6;

/// A back-check point of the layout (mm, at rest), set back by [`BACKCHECK_SET_BACK_MM`].
fn backcheck_regulated(p: P) -> P {
    [
        p[0] - BACKCHECK_SET_BACK_MM * 0.112,
        p[1] - BACKCHECK_SET_BACK_MM * 0.994,
    ]
}

/// The jack top's centre at rest, N = J + 68.38 a0, a0 = (0.1506, 0.9886) \[D\] (a 2 mm
/// circle).
const JACK_TOP: P = [104.30, 131.36];
/// The notch's lip (mm, at rest): the seat's end on the player's side \[D\].
const LIP: P = [102.3, SEAT_Y];
/// The seat's other end, at the wall (mm, at rest) \[D\].
const SEAT_AT_WALL: P = [106.3, SEAT_Y];

/// The world frame.
const WORLD: Frame = WorldFrame::WORLD;

/// Balance pivot (origin) \[def\].
const KEY_PIVOT: P = [0.0, 0.0];
/// Wippen centre pin W \[D\] (layout §4.2).
const W: P = [132.00, 51.76];
/// Jack centre pin J \[D\].
const J: P = [94.00, 63.76];
/// Butt centre pin H \[S/D\]: W + (−12.7, 81.6) (Abendschein 1919, 3 1/4" and 1/2").
const H: P = [119.30, 133.36];
/// The shank's direction at rest e1 \[D\]: it leans 23.19° toward the player.
const E1: P = [-0.3938, 0.9192];
/// The second hammer axis e2 of the layout (toward the crown side) \[D\].
const E2: P = [0.9192, 0.3938];
/// The string plane x (mm) \[S\]: H_x + 53.95 (butt centre → strings ≈ 2 1/8").
const STRING_X: f64 = 173.25;
/// Lost motion at the jack top (mm): the gap between the jack top and the butt's seat at
/// rest, with the hammer on its rail. The layout's nominal zero (§4.4) leaves an escaped
/// jack no way back in: its pin is below and the top leans 8.7° toward the strings, so the
/// top rises 0.28 mm on its arc as it swings back to the lip \[D\]. In practice 0.2–0.5 mm
/// at the jack top \[M\], "just enough to let the jack slip back under the butt" (Page,
/// MMD 2003.01.20.11 \[V\]): the upper end, which clears the arc.
pub const LOST_MOTION_MM: f64 = 0.5;
/// The notch's seat height at rest (mm): the jack top's (133.36, layout §4.2 \[D\]) plus
/// the lost motion.
const SEAT_Y: f64 = 133.36 + LOST_MOTION_MM;
/// Key dip at the front (mm): the deeper end of the usual 10.0–10.5 mm (layout §3 \[V\]),
/// which the lost motion needs to leave aftertouch \[D\].
pub const DIP_MM: f64 = 10.5;
/// The front punching's top (mm): the key's contact point, 215 mm before the balance pin
/// (§4.2 \[V/D\]), goes down `DIP_MM` × 215/235.
const FRONT_RAIL_Y: f64 = -DIP_MM * 215.0 / 235.0;
/// The let-off button's underside (mm), regulated as a technician does, on a slow press:
/// the layout's y = 69.17 (§4.2 \[D\]) raised by what the toe rises while the wippen takes
/// up the lost motion (toe 48.19 mm, jack top 27.70 mm before the wippen pin in x: 0.87 mm
/// \[D\]), then lowered 0.40 mm so that a slow press (0.8 N) lets off about 4 mm from the
/// string as the layout's rigid pose did (3.8 mm; 3.9 mm before; 2.1 mm at 10 N) \[D\].
const BUTTON_Y: f64 = 69.17 + LOST_MOTION_MM * (132.00 - 83.81) / (132.00 - 104.30) - 0.40;

/// A point given in the layout's hammer coordinates (mm along e1 and e2 from H) in the
/// world (mm).
fn hammer_world(u: f64, v: f64) -> P {
    [H[0] + u * E1[0] + v * E2[0], H[1] + u * E1[1] + v * E2[1]]
}

/// A felt or leather contact law: rate-independent hysteretic felt, p = 2 (layout §6,
/// carried over from action_layout.md §6 \[D/M\]), smoothing as the grand's numerics.
fn felt(k: f64, e: f64) -> LawSpec {
    LawSpec::Felt {
        k,
        p: 2.0,
        e,
        smoothing: 1e-3,
        alpha: 0.0,
    }
}

fn coulomb(mu: f64) -> Option<ContactFrictionSpec> {
    Some(ContactFrictionSpec::Coulomb {
        mu,
        regularization: 1e-3,
    })
}

fn side(body: &str, shapes: Vec<ShapeSpec>) -> ContactSideSpec {
    ContactSideSpec {
        body: body.into(),
        shapes,
    }
}

fn segment(frame: &Frame, a: P, b: P) -> ShapeSpec {
    ShapeSpec::Segment {
        a: frame.local(a),
        b: frame.local(b),
    }
}

fn circle(frame: &Frame, c: P, r_mm: f64) -> ShapeSpec {
    ShapeSpec::Circle {
        center: frame.local(c),
        radius: r_mm * 1e-3,
    }
}

fn friction(coulomb: f64) -> Option<PivotFrictionSpec> {
    Some(PivotFrictionSpec {
        coulomb,
        regularization: 1e-2,
        viscous: 0.0,
        stribeck: None,
    })
}

fn outline(frame: &Frame, name: &str, pts: &[P], thickness_mm: f64, color: &str) -> OutlinePart {
    OutlinePart {
        name: name.into(),
        points: pts.iter().map(|&p| frame.local(p)).collect(),
        circle: None,
        thickness: thickness_mm * 1e-3,
        z: 0.0,
        color: Some(color.into()),
    }
}

fn contact(
    name: &str,
    note: &str,
    a: ContactSideSpec,
    b: ContactSideSpec,
    law: LawSpec,
    friction: Option<ContactFrictionSpec>,
) -> ContactPair {
    ContactPair {
        name: name.into(),
        note: note.into(),
        a,
        b,
        law,
        friction,
    }
}

fn onset(name: &str, contact: &str, on: ContactPhase) -> EventSpec {
    EventSpec {
        name: name.into(),
        contact: Some(contact.into()),
        on: Some(on),
        coordinate: None,
        value: None,
        direction: None,
    }
}

/// The upright action's description (see the crate docs), checked.
pub fn upright_mechanism() -> Result<Mechanism, piano_action::PianoError> {
    let key = WORLD;
    let wippen = WorldFrame::at(W);
    let jack = JACK_FRAME;
    let hammer = hammer_frame();
    let hw = |u: f64, v: f64| hammer_world(u, v);
    let n = JACK_TOP;
    let bodies = vec![
        Body {
            name: "key".into(),
            note: "0.091 kg, CoM (−20, 11) mm, I about the balance pin 1.46e-3 kg·m² [M/D] \
                   (layout §5); 235 mm balance → front [V Shuster]"
                .into(),
            mass: 0.091,
            com: m([-20.0, 11.0]),
            // I_c = I_pivot − m |c|² [D].
            inertia: 1.46e-3 - 0.091 * (0.020f64.powi(2) + 0.011f64.powi(2)),
            joint: Joint {
                kind: JointType::Revolute,
                parent: "ground".into(),
                at: m(KEY_PIVOT),
                angle: 0.0,
                axis: None,
                limits: None,
                // The grand's key pivot friction [S] (layout §6 gives none for the key).
                friction: friction(6.4e-3),
            },
            outline: vec![
                outline(
                    &key,
                    "key",
                    &[[-240.0, 0.0], [150.0, 0.0], [150.0, 22.0], [-240.0, 22.0]],
                    22.0,
                    "#dccaa4",
                ),
                outline(
                    &key,
                    "capstan",
                    &[[99.0, 22.0], [105.0, 22.0], [105.0, 36.0], [99.0, 36.0]],
                    8.0,
                    "#c8a85a",
                ),
            ],
        },
        Body {
            name: "wippen".into(),
            note: "0.010 kg with back-check, wires and spoon, CoM (92, 59.8) mm, I 2.0e-5 kg·m² \
                   [M/D] (layout §5)"
                .into(),
            mass: 0.010,
            com: wippen.local([92.0, 59.8]),
            inertia: 2.0e-5,
            joint: Joint {
                kind: JointType::Revolute,
                parent: "ground".into(),
                at: m(W),
                angle: 0.0,
                axis: None,
                limits: None,
                friction: friction(1.0e-3),
            },
            outline: vec![
                outline(
                    &wippen,
                    "wippen",
                    &[
                        [96.0, 38.0],
                        [136.0, 46.0],
                        [136.0, 58.0],
                        [90.0, 68.0],
                        [84.0, 60.0],
                    ],
                    14.0,
                    "#b9c9a4",
                ),
                outline(
                    &wippen,
                    "back-check wire",
                    &[[66.0, 60.0], [68.0, 60.0], [72.0, 125.0], [70.0, 125.0]],
                    2.0,
                    "#9a9a9a",
                ),
                outline(
                    &wippen,
                    "back-check",
                    &[[67.0, 124.0], [81.0, 122.5], [80.5, 128.8], [68.6, 130.2]]
                        .map(backcheck_regulated),
                    12.0,
                    "#a88d6c",
                ),
            ],
        },
        Body {
            name: "jack".into(),
            note: "2.5 g, CoM 0.4 of the way pin → top, I 3.9e-6 kg·m² about its pin [M/D]".into(),
            mass: 0.0025,
            com: jack.local([J[0] + 0.4 * (n[0] - J[0]), J[1] + 0.4 * (n[1] - J[1])]),
            inertia: 3.9e-6 - 0.0025 * (0.4f64 * 0.06838).powi(2),
            joint: Joint {
                kind: JointType::Revolute,
                parent: "wippen".into(),
                at: wippen.local(J),
                angle: 0.0,
                axis: None,
                // A stop 0.35 rad each way stands in for the jack-slap rail and the
                // wippen's cloth (layout §4.2 "optional") [M].
                limits: Some(Limits {
                    lower: Some(-0.35),
                    upper: Some(0.35),
                    stiffness: 50.0,
                    damping: 0.01,
                }),
                friction: friction(0.3e-3),
            },
            outline: vec![
                outline(
                    &jack,
                    "jack",
                    &[[92.5, 63.0], [95.5, 63.0], [105.8, 130.8], [102.8, 131.4]],
                    8.0,
                    "#cfa7a2",
                ),
                outline(
                    &jack,
                    "toe",
                    &[[82.0, 62.0], [93.0, 62.0], [93.0, 65.0], [82.0, 65.0]],
                    8.0,
                    "#cfa7a2",
                ),
            ],
        },
        Body {
            name: "hammer".into(),
            note: "butt + shank + head + catcher, 17.5 g, CoM body (69.4, 10.2) mm, I_G 6.7e-5 \
                   kg·m² [M/D] (layout §5)"
                .into(),
            mass: 0.0175,
            com: hammer.local(hw(69.4, 10.2)),
            inertia: 6.7e-5,
            joint: Joint {
                kind: JointType::Revolute,
                parent: "ground".into(),
                at: m(H),
                angle: hammer.angle,
                axis: None,
                limits: None,
                friction: friction(1.0e-3),
            },
            outline: vec![
                outline(
                    &hammer,
                    "butt",
                    &[
                        hw(-8.0, -35.0),
                        hw(22.0, -35.0),
                        hw(24.0, 8.0),
                        hw(-8.0, 8.0),
                    ],
                    14.0,
                    "#b89c74",
                ),
                outline(
                    &hammer,
                    "shank",
                    &[
                        hw(20.0, -4.0),
                        hw(120.0, -4.0),
                        hw(120.0, 4.0),
                        hw(20.0, 4.0),
                    ],
                    6.0,
                    "#e0cfa8",
                ),
                outline(
                    &hammer,
                    "head",
                    &[
                        hw(108.0, 2.0),
                        hw(148.0, 2.0),
                        hw(144.0, 52.0),
                        hw(128.0, 64.0),
                        hw(112.0, 52.0),
                    ],
                    14.0,
                    "#efe9da",
                ),
            ],
        },
    ];

    let torsion_springs = vec![
        TorsionSpring {
            name: "butt spring".into(),
            note: "τ = 4.0e-3 + 8.0e-3 (−θh) N·m toward the rail [D/M] (layout §6; ≈ Jankura's \
                   +17 gf maximum [V])"
                .into(),
            joint: "hammer".into(),
            stiffness: 8.0e-3,
            rest: 0.0,
            preload: 4.0e-3,
            damping: 0.0,
        },
        TorsionSpring {
            name: "jack spring".into(),
            note: "τ = 1.5e-3 + 4e-3 ψ N·m pushing the top toward the strings [M] (layout §6)"
                .into(),
            joint: "jack".into(),
            stiffness: 4.0e-3,
            rest: 0.0,
            preload: -1.5e-3,
            damping: 0.0,
        },
    ];

    // The bridle tape: catcher dowel (hammer body (16, −22)) to the wippen's bridle hook
    // (70, 112), 36.64 mm, 1.0 mm slack at rest [D]; k 2e4 N/m [M].
    let cords = vec![CordSpec {
        name: "bridle tape".into(),
        note:
            "36.64 mm, slack 1.0 mm at rest [D]; k ≈ 2e4 N/m, light damping [M] (layout §4.3, §6)"
                .into(),
        a: BodyPoint {
            body: "hammer".into(),
            point: hammer.local(hw(16.0, -22.0)),
        },
        b: BodyPoint {
            body: "wippen".into(),
            point: wippen.local([70.0, 112.0]),
        },
        length: 0.03664,
        stiffness: 2.0e4,
        damping: 2.0,
    }];

    let ground = |shapes| side("ground", shapes);
    // The rest rail's cushion faces e2 through the shank's rest contact (92.0, 186.9).
    let rail_p = [92.0, 186.9];
    let t = [E2[1], -E2[0]];
    let contacts = vec![
        contact(
            "front_rail",
            "front punching, top y = −9.61 mm (10.5 mm dip [V/D]); k 1.3e7 [D/M]",
            ground(vec![segment(
                &WORLD,
                [-225.0, FRONT_RAIL_Y],
                [-205.0, FRONT_RAIL_Y],
            )]),
            side("key", vec![circle(&key, [-215.0, 2.0], 2.0)]),
            felt(1.3e7, 0.4),
            None,
        ),
        contact(
            "back_rail",
            "back-rail cloth, top y = 0 [M]; k 5e6 [M]",
            ground(vec![segment(&WORLD, [130.0, 0.0], [150.0, 0.0])]),
            side("key", vec![circle(&key, [140.0, 2.0], 2.0)]),
            felt(5e6, 0.4),
            None,
        ),
        contact(
            "capstan_heel",
            "capstan r 4 at (102, 36) on the heel cloth [V/D]; k 1e8 [D]",
            side("key", vec![circle(&key, [102.0, 36.0], 4.0)]),
            side(
                "wippen",
                vec![segment(&wippen, [110.0, 40.0], [94.0, 40.0])],
            ),
            felt(1e8, 0.4),
            coulomb(0.2),
        ),
        contact(
            "jack_seat",
            "the butt felt the jack top lifts, ending at the lip (102.3) [D], 0.5 mm over the \
             jack top at rest (lost motion [M/D]); buckskin k 5e7 [D/M]",
            side("hammer", vec![segment(&hammer, SEAT_AT_WALL, LIP)]),
            side("jack", vec![circle(&jack, n, 2.0)]),
            felt(5e7, 0.4),
            coulomb(0.15),
        ),
        contact(
            "jack_wall",
            "the notch wall on the string side of the jack top [D]",
            side(
                "hammer",
                vec![segment(&hammer, [106.3, SEAT_Y - 5.0], [106.3, SEAT_Y])],
            ),
            side("jack", vec![circle(&jack, n, 2.0)]),
            felt(5e7, 0.4),
            coulomb(0.15),
        ),
        contact(
            "butt_face",
            "the butt's face rising from the lip on the player's side: the escaped jack top \
             leans on it until the notch comes back down to it [M]; buckskin as the seat. It \
             starts 1 mm over the lip, so the lip's corner is the seat's alone (the 2 mm top \
             cannot pass the gap)",
            side(
                "hammer",
                vec![segment(
                    &hammer,
                    [102.3, SEAT_Y + 7.0],
                    [102.3, SEAT_Y + 1.0],
                )],
            ),
            side("jack", vec![circle(&jack, n, 2.0)]),
            felt(5e7, 0.4),
            coulomb(0.15),
        ),
        contact(
            "let_off_button",
            "button underside y = 69.64: the layout's 69.17 [D] regulated for the lost motion \
             [D], 4.35 mm over the toe; k 2e7 [D/M]",
            ground(vec![segment(&WORLD, [92.0, BUTTON_Y], [76.0, BUTTON_Y])]),
            side("jack", vec![circle(&jack, [83.81, 63.29], 2.0)]),
            felt(2e7, 0.4),
            coulomb(0.25),
        ),
        contact(
            "rest_rail",
            "hammer rail cushion, normal e2 through (92.0, 186.9) [M]; k 1e6 [M]",
            ground(vec![segment(
                &WORLD,
                [rail_p[0] - 10.0 * t[0], rail_p[1] - 10.0 * t[1]],
                [rail_p[0] + 10.0 * t[0], rail_p[1] + 10.0 * t[1]],
            )]),
            side("hammer", vec![circle(&hammer, hw(60.0, 0.0), 4.0)]),
            felt(1e6, 0.3),
            None,
        ),
        contact(
            "backcheck",
            "catcher r 5 at body (14, −30) on the back-check face [D/M], the face set 0.6 mm \
             lower than the layout's for the 10.5 mm dip [D]; k 5e6, e 0.1 [D/M]",
            side(
                "wippen",
                vec![segment(
                    &wippen,
                    backcheck_regulated([68.6, 130.19]),
                    backcheck_regulated([80.5, 128.85]),
                )],
            ),
            side("hammer", vec![circle(&hammer, hw(14.0, -30.0), 5.0)]),
            felt(5e6, 0.1),
            coulomb(0.5),
        ),
    ];

    // The string: the grand's C4 unison and crown felt [S], in the vertical plane
    // x = 173.25 mm, facing the hammer; the crown a 15 mm circle touching the strike point
    // (body (128, 63.5)) [M].
    let grand = piano_action::describe::grand_mechanism(
        &ActionParams::reference(),
        piano_action::ModelKind::Double,
        None,
    )?;
    let g = &grand.strings[0];
    let strings = vec![StringPair {
        name: "hammer_string".into(),
        note: "the grand's C4 unison and crown felt (Chaigne & Askenfelt) [S]; upright strings are shorter [M]".into(),
        line: [m([STRING_X, 240.0]), m([STRING_X, 300.0])],
        striker: side("hammer", vec![circle(&hammer, hw(128.0, 48.5), 15.0)]),
        law: g.law.clone(),
        string: g.string,
    }];

    let finger = m([-235.0, 22.0]);
    let mech = Mechanism {
        name: "upright action".into(),
        about: "An upright piano action after upright_layout.md (§4–§6): key, wippen, jack in \
                the butt notch, hammer with butt spring, bridle tape and back-check, let-off \
                button, rest rail, the string in a vertical plane."
            .into(),
        gravity: [0.0, -piano_action::params::GRAVITY_M_S2],
        ground: vec![
            outline(
                &WORLD,
                "key frame",
                &[
                    [-240.0, -20.0],
                    [160.0, -20.0],
                    [160.0, -12.0],
                    [-240.0, -12.0],
                ],
                36.0,
                "#c9c5bd",
            ),
            outline(
                &WORLD,
                "let-off rail",
                &[
                    [72.0, BUTTON_Y],
                    [95.0, BUTTON_Y],
                    [95.0, 76.0],
                    [72.0, 76.0],
                ],
                20.0,
                "#8aa37a",
            ),
            outline(
                &WORLD,
                "hammer rail",
                &[
                    hw(45.0, -4.0),
                    hw(75.0, -4.0),
                    hw(75.0, -14.0),
                    hw(45.0, -14.0),
                ],
                36.0,
                "#8aa37a",
            ),
            outline(
                &WORLD,
                "string",
                &[
                    [STRING_X, 230.0],
                    [STRING_X + 1.0, 230.0],
                    [STRING_X + 1.0, 310.0],
                    [STRING_X, 310.0],
                ],
                2.0,
                "#555555",
            ),
        ],
        bodies,
        torsion_springs,
        point_springs: Vec::new(),
        cords,
        loads: Vec::new(),
        contacts,
        strings,
        extensions: Vec::new(),
        inputs: vec![Input {
            name: "finger".into(),
            note: "the key front (235 mm before the balance pin) [V Shuster]".into(),
            kind: InputKind::Force,
            at: BodyPoint {
                body: "key".into(),
                point: finger,
            },
            direction: [0.0, -1.0],
        }],
        markers: vec![
            Marker {
                name: "key_front".into(),
                note: String::new(),
                at: BodyPoint {
                    body: "key".into(),
                    point: finger,
                },
            },
            Marker {
                name: "hammer_crown".into(),
                note: "the strike point, body (128, 63.5) mm [D]".into(),
                at: BodyPoint {
                    body: "hammer".into(),
                    point: hammer.local(hw(128.0, 63.5)),
                },
            },
        ],
        events: vec![
            onset("key_bottom", "front_rail", ContactPhase::Onset),
            onset("let_off", "let_off_button", ContactPhase::Onset),
            onset("escape", "jack_seat", ContactPhase::Release),
            onset("strike", "hammer_string", ContactPhase::Onset),
            onset("check", "backcheck", ContactPhase::Onset),
            onset("jack_on_seat", "jack_seat", ContactPhase::Onset),
        ],
        metrics: vec![
            Metric {
                name: "hammer speed at the strike".into(),
                quantity: Quantity::Speed,
                marker: Some("hammer_crown".into()),
                at: "strike".into(),
                unit: "m/s".into(),
            },
            Metric {
                name: "strike time".into(),
                quantity: Quantity::Time,
                marker: None,
                at: "strike".into(),
                unit: "s".into(),
            },
        ],
    };
    mech.validate()?;
    Ok(mech)
}

/// The string plane's x in the world (m).
pub const STRING_X_M: f64 = STRING_X * 1e-3;

/// The world position (m) of the named marker of `mechanism` at `(t, x)` of `built` (the
/// system built from it).
pub fn marker_position(
    mechanism: &Mechanism,
    built: &piano_action::mechanism::Built,
    marker: &str,
    t: f64,
    x: &[f64],
) -> Result<[f64; 2], piano_action::PianoError> {
    let mk = mechanism
        .markers
        .iter()
        .find(|m| m.name == marker)
        .ok_or_else(|| {
            piano_action::PianoError::option("marker", format!("no marker '{marker}'"))
        })?;
    let model = built.system.model();
    let frame = model.frame_id(&mk.at.body)?;
    let (body, point) = mbs_core::frame_point(model, frame, mk.at.point);
    let mut ws = built.system.workspace();
    let ctx = built.system.kinematics(&mut ws, t, x)?;
    Ok(ctx.point_position(body, point))
}

/// The crown's distance to the string plane (mm) at `(t, x)`: blow at rest, let-off at
/// escape, checking distance when caught.
pub fn crown_to_string_mm(
    mechanism: &Mechanism,
    built: &piano_action::mechanism::Built,
    t: f64,
    x: &[f64],
) -> Result<f64, piano_action::PianoError> {
    Ok((STRING_X_M - marker_position(mechanism, built, "hammer_crown", t, x)?[0]) * 1e3)
}

/// How far (mm) the jack top's centre has come back past the notch's lip, along the seat
/// toward the wall, at `(t, x)` of `built` (the system built from [`upright_mechanism`]):
/// 2 mm when seated against the wall, 0 at the lip, negative when the jack has escaped
/// toward the player. Past about 1 mm (half the top's radius) the jack is back under the
/// butt: a press lifts the hammer again.
pub fn jack_top_past_lip_mm(
    built: &piano_action::mechanism::Built,
    t: f64,
    x: &[f64],
) -> Result<f64, piano_action::PianoError> {
    let model = built.system.model();
    let mut ws = built.system.workspace();
    let ctx = built.system.kinematics(&mut ws, t, x)?;
    let at = |body: &str, p: P| -> Result<[f64; 2], piano_action::PianoError> {
        let frame = model.frame_id(body)?;
        let (b, point) = mbs_core::frame_point(model, frame, p);
        Ok(ctx.point_position(b, point))
    };
    let hammer = hammer_frame();
    let top = at("jack", JACK_FRAME.local(JACK_TOP))?;
    let lip = at("hammer", hammer.local(LIP))?;
    let wall = at("hammer", hammer.local(SEAT_AT_WALL))?;
    let (ux, uy) = (wall[0] - lip[0], wall[1] - lip[1]);
    let len = ux.hypot(uy);
    Ok(((top[0] - lip[0]) * ux + (top[1] - lip[1]) * uy) / len * 1e3)
}
