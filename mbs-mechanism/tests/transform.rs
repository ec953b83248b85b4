//! Transformations of a description on a small mechanism: what a split moves and where,
//! the mass properties it keeps, a stiff split that swings like the rigid body, a soft one
//! that rings at its hinge's frequency, a compliant mount, swapped laws, and named errors
//! for bad arguments.

use mbs_core::{Data, Model, update_poses};
use mbs_integrators::{Method, MultibodyOde, Options, solve};
use mbs_mechanism::{
    BodyPoint, ContactFrictionSpec, Flex, LawSpec, MassProps, Mechanism, MechanismError, ShapeSpec,
    Side,
};

/// A 100 mm lever on a pivot, its far end holding a slider, a contact whose lever side has
/// shapes on both halves, a striker on a string, springs, a cord, loads, inputs, markers
/// and an outline across its length.
const LEVER: &str = r#"
name = "lever for transformations"
gravity = [0.0, -9.81]

[[bodies]]
name = "lever"
mass = 0.05
com = [0.05, 0.0]
inertia = 4e-5
joint = { kind = "revolute", at = [0.0, 0.0], limits = { lower = -0.5, upper = 0.5, stiffness = 50.0, damping = 0.01 } }
outline = [{ name = "bar", points = [[0.0, -0.003], [0.1, -0.003], [0.1, 0.003], [0.0, 0.003]], thickness = 0.01 }, { circle = { center = [0.0, 0.0], radius = 0.004 }, thickness = 0.01 }]

[[bodies]]
name = "slider"
mass = 0.01
com = [0.0, 0.0]
inertia = 1e-6
joint = { kind = "prismatic", parent = "lever", at = [0.08, 0.0], angle = 0.3, axis = [0.0, 1.0] }

[[bodies]]
name = "tab"
mass = 0.002
com = [0.0, 0.0]
inertia = 1e-8
joint = { kind = "fixed", parent = "lever", at = [0.02, 0.01] }

[[torsion_springs]]
name = "return spring"
joint = "lever"
stiffness = 0.05

[[point_springs]]
name = "slider spring"
a = { body = "lever", point = [0.08, 0.0] }
b = { body = "slider", point = [0.0, 0.0] }
stiffness = 200.0
rest_length = 0.0

[[cords]]
name = "tape"
a = { body = "lever", point = [0.1, 0.0] }
b = { body = "ground", point = [0.1, -0.03] }
length = 0.035
stiffness = 1000.0

[[loads]]
name = "weight near the pivot"
at = { body = "lever", point = [0.02, 0.0] }
direction = [0.0, -1.0]
magnitude = 0.1

[[contacts]]
name = "stop_felt"
a = { body = "ground", shapes = [{ segment = { a = [0.09, -0.01], b = [0.11, -0.01] } }] }
b = { body = "lever", shapes = [{ circle = { center = [0.1, -0.004], radius = 0.002 } }, { profile = { points = [[0.0, 0.01], [0.02, 0.01], [0.04, 0.012]] } }] }
law = { material = "action_felt" }
friction = { coulomb = { mu = 0.2, regularization = 1e-3 } }

[[contacts]]
name = "tip_pad"
a = { body = "lever", shapes = [{ arc = { center = [0.09, 0.0], radius = 0.003, start = 0.0, sweep = 3.0, side = "convex" } }] }
b = { body = "ground", shapes = [{ segment = { a = [0.12, 0.02], b = [0.06, 0.02] } }] }
law = { hertz = { k = 1e6, p = 1.5 } }

[[strings]]
name = "wire"
line = [[0.15, 0.03], [0.05, 0.03]]
striker = { body = "lever", shapes = [{ circle = { center = [0.095, 0.005], radius = 0.003 } }] }
law = { hertz = { k = 1e8, p = 2.5 } }
string = { length_m = 0.6, fundamental_hz = 262.0, tension_n = 700.0, inharmonicity = 4e-4, striking_ratio = 0.125, strings = 1, loss_b1 = 0.5, loss_b3 = 1e-9, modes = 8, residual_compliance = false }

[[inputs]]
name = "finger"
kind = "force"
at = { body = "lever", point = [0.09, 0.0] }
direction = [0.0, -1.0]

[[inputs]]
name = "drive"
kind = "motion"
at = { body = "lever", point = [0.09, 0.0] }
direction = [0.0, -1.0]

[[markers]]
name = "tip"
at = { body = "lever", point = [0.1, 0.0] }

[[markers]]
name = "root"
at = { body = "lever", point = [0.01, 0.0] }

[[events]]
name = "lands"
contact = "stop_felt"
on = "onset"
"#;

fn lever() -> Mechanism {
    Mechanism::from_toml_str(LEVER).expect("the lever parses")
}

/// The outer 60 % of the lever beyond 40 mm: 30 g at 70 mm, a 60 mm bar.
fn outer() -> MassProps {
    MassProps {
        mass: 0.03,
        com: [0.07, 0.0],
        inertia: 0.03 * 0.06f64.powi(2) / 12.0,
    }
}

fn hinge(stiffness: f64) -> Flex {
    Flex {
        stiffness,
        damping: 0.0,
    }
}

fn split(m: &Mechanism) -> Mechanism {
    m.split_body(
        "lever",
        [0.04, 0.0],
        [1.0, 0.0],
        "tip",
        outer(),
        hinge(10.0),
    )
    .expect("splits")
}

/// Poses of `m`'s bodies with every coordinate zero.
fn poses(m: &Mechanism) -> (Model, Data) {
    let model = m.model().expect("builds");
    let mut data = Data::new(&model);
    update_poses(&model, &mut data, &vec![0.0; model.nq()]).unwrap();
    (model, data)
}

/// World position of `p` with every coordinate zero.
fn world(model: &Model, data: &Data, p: &BodyPoint) -> [f64; 2] {
    if p.body == "ground" {
        return p.point;
    }
    // A body on a fixed joint is a frame on its parent.
    let frame = model.frame_id(&p.body).unwrap();
    let (body, point) = mbs_core::frame_point(model, frame, p.point);
    mbs_core::point_position(data, body, point)
}

/// Every named point of `m` in the world at zero coordinates, and the reference points of
/// every contact and striker shape (sorted), and every body frame's origin.
/// Named world points, and places without names.
type Layout = (Vec<(String, [f64; 2])>, Vec<[f64; 2]>);

fn layout(m: &Mechanism) -> Layout {
    let (model, data) = poses(m);
    let mut named = Vec::new();
    for mk in &m.markers {
        named.push((format!("marker {}", mk.name), world(&model, &data, &mk.at)));
    }
    for s in &m.point_springs {
        named.push((format!("{} a", s.name), world(&model, &data, &s.a)));
        named.push((format!("{} b", s.name), world(&model, &data, &s.b)));
    }
    for c in &m.cords {
        named.push((format!("{} a", c.name), world(&model, &data, &c.a)));
    }
    for l in &m.loads {
        named.push((l.name.clone(), world(&model, &data, &l.at)));
    }
    for i in &m.inputs {
        named.push((i.name.clone(), world(&model, &data, &i.at)));
    }
    for b in &m.bodies {
        if b.name != "lever" && b.name != "tip" {
            let pose = mbs_core::frame_pose(&model, &data, model.frame_id(&b.name).unwrap());
            named.push((format!("frame {}", b.name), pose.translation()));
        }
    }
    let mut shapes = Vec::new();
    let sides = m
        .contacts
        .iter()
        .flat_map(|c| [&c.a, &c.b])
        .chain(m.strings.iter().map(|s| &s.striker));
    for side in sides {
        for s in &side.shapes {
            let p = BodyPoint {
                body: side.body.clone(),
                point: s.reference_point(),
            };
            shapes.push(world(&model, &data, &p));
        }
    }
    // A contact cut in two repeats its other side: each place once.
    shapes.sort_by(|a, b| a.partial_cmp(b).unwrap());
    shapes.dedup_by(|a, b| close(*a, *b));
    (named, shapes)
}

fn close(a: [f64; 2], b: [f64; 2]) -> bool {
    (a[0] - b[0]).abs() < 1e-15 && (a[1] - b[1]).abs() < 1e-15
}

#[test]
fn a_split_moves_what_lies_beyond_the_cut_and_leaves_the_world_in_place() {
    let before = lever();
    let after = split(&before);
    assert_eq!(before, lever(), "the original is untouched");

    // The new body right after the lever, on a hinge at the cut with its spring.
    let names: Vec<&str> = after.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["lever", "tip", "slider", "tab"]);
    let tip = &after.bodies[1];
    assert_eq!(tip.joint.parent, "lever");
    assert_eq!(tip.joint.at, [0.04, 0.0]);
    assert_eq!(tip.joint.angle, 0.0);
    assert_eq!(tip.com, [0.07 - 0.04, 0.0]);
    let spring = after.torsion_springs.last().unwrap();
    assert_eq!(
        (spring.name.as_str(), spring.joint.as_str()),
        ("tip flex", "tip")
    );
    assert_eq!((spring.stiffness, spring.rest), (10.0, 0.0));

    // The slider's joint at 80 mm goes with the tip, re-expressed; the tab at 20 mm stays.
    let slider = &after.bodies[2];
    assert_eq!(slider.joint.parent, "tip");
    assert!(close(slider.joint.at, [0.04, 0.0]));
    assert_eq!(slider.joint.angle, 0.3);
    assert_eq!(after.bodies[3].joint.parent, "lever");

    // Points by side of the cut; the motion input stays with the lever's coordinate.
    let body_of = |name: &str| {
        after
            .markers
            .iter()
            .find(|m| m.name == name)
            .map(|m| m.at.body.as_str())
            .unwrap()
    };
    assert_eq!((body_of("tip"), body_of("root")), ("tip", "lever"));
    assert_eq!(after.point_springs[0].a.body, "tip");
    assert_eq!(after.cords[0].a.body, "tip");
    assert_eq!(after.loads[0].at.body, "lever");
    assert_eq!(after.inputs[0].at.body, "tip");
    assert_eq!(after.inputs[1].at.body, "lever");
    assert_eq!(after.strings[0].striker.body, "tip");
    assert_eq!(
        after.contacts[2].a.body, "tip",
        "the tip pad's arc goes whole"
    );

    // The felt's lever side had a shape on each half: two contacts now, same law.
    let contacts: Vec<&str> = after.contacts.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(contacts, ["stop_felt", "stop_felt on tip", "tip_pad"]);
    let (near, far) = (&after.contacts[0], &after.contacts[1]);
    assert_eq!(near.b.body, "lever");
    assert!(matches!(near.b.shapes[..], [ShapeSpec::Profile { .. }]));
    assert_eq!(far.b.body, "tip");
    assert!(matches!(far.b.shapes[..], [ShapeSpec::Circle { .. }]));
    assert_eq!(
        (&far.a, &far.law, &far.friction),
        (&near.a, &near.law, &near.friction)
    );
    assert_eq!(after.events[0].contact.as_deref(), Some("stop_felt"));

    // The bar's outline is clipped at the cut; the pivot's circle stays.
    let lever_outline = &after.bodies[0].outline;
    assert_eq!(lever_outline.len(), 2);
    assert!(lever_outline[0].points.iter().all(|p| p[0] <= 0.04 + 1e-15));
    assert!(tip.outline[0].points.iter().all(|p| p[0] >= -1e-15));
    assert_eq!(tip.outline[0].points.len(), 4);

    // At zero coordinates every point is where it was in the world.
    let ((named0, shapes0), (named1, shapes1)) = (layout(&before), layout(&after));
    assert_eq!(named0.len(), named1.len());
    for ((n0, p0), (n1, p1)) in named0.iter().zip(&named1) {
        assert_eq!(n0, n1);
        assert!(close(*p0, *p1), "{n0}: {p0:?} then {p1:?}");
    }
    assert_eq!(shapes0.len(), shapes1.len());
    for (p0, p1) in shapes0.iter().zip(&shapes1) {
        assert!(close(*p0, *p1), "shape at {p0:?} then {p1:?}");
    }
    // And it builds, with one more coordinate and one more contact element.
    let (b0, b1) = (before.build().unwrap(), after.build().unwrap());
    assert_eq!(b1.system.model().nv(), b0.system.model().nv() + 1);
    assert_eq!(b1.contacts.len(), b0.contacts.len() + 1);
}

#[test]
fn a_split_keeps_the_mass_centre_of_mass_and_inertia_about_the_joint() {
    let before = lever();
    let after = split(&before);
    let whole = MassProps::of(&before.bodies[0]);
    let rest = MassProps::of(&after.bodies[0]);
    let tip = &after.bodies[1];
    // The tip's properties back in the lever frame (its frame is the lever's moved to the
    // cut).
    let tip_in_lever = MassProps {
        mass: tip.mass,
        com: [tip.com[0] + 0.04, tip.com[1]],
        inertia: tip.inertia,
    };
    assert_eq!(tip_in_lever, outer());
    let again = rest.plus(&tip_in_lever);
    assert!((again.mass - whole.mass).abs() < 1e-17);
    assert!((again.com[0] - whole.com[0]).abs() < 1e-16);
    assert!(again.com[1].abs() < 1e-16);
    let rel = (again.inertia_about_origin() - whole.inertia_about_origin()).abs()
        / whole.inertia_about_origin();
    assert!(rel < 1e-14, "{rel}");
    // The remainder: 20 g at 30 mm.
    assert!((rest.mass - 0.02).abs() < 1e-16);
    assert!((rest.com[0] - 0.02).abs() < 1e-15, "{:?}", rest.com);
}

/// An arm swinging under gravity from horizontal, rigid and split with a stiff hinge.
#[test]
fn a_stiff_split_swings_like_the_rigid_body() {
    let arm = r#"
name = "arm"
gravity = [0.0, -9.81]
[[bodies]]
name = "arm"
mass = 0.05
com = [0.05, 0.0]
inertia = 4e-5
joint = { kind = "revolute", at = [0.0, 0.0] }
[[markers]]
name = "end"
at = { body = "arm", point = [0.1, 0.0] }
"#;
    let rigid = Mechanism::from_toml_str(arm).unwrap();
    let stiff = rigid
        .split_body("arm", [0.04, 0.0], [1.0, 0.0], "outer", outer(), hinge(1e3))
        .unwrap();
    let end = |m: &Mechanism, t_end: f64| {
        let built = m.build().unwrap();
        let sys = &built.system;
        let n = sys.model().nv();
        let x0 = sys
            .initial_state(0.0, &vec![0.0; n], &vec![0.0; n])
            .unwrap();
        let opts = Options {
            max_step: 1e-4,
            ..Options::with_tolerances(1e-9, 1e-12)
        };
        let sol = solve(
            &mut MultibodyOde::new(sys),
            Method::TrBdf2,
            0.0,
            &x0,
            t_end,
            &opts,
        )
        .unwrap();
        let model = sys.model();
        let mut data = Data::new(model);
        update_poses(model, &mut data, &sol.y_final[..n]).unwrap();
        world(model, &data, &m.markers[0].at)
    };
    // A quarter swing and more. The hinge bends under the outer part's weight and swing
    // by about τ/k ≈ m g r / k = 0.03 · 9.81 · 0.03 / 1000 ≈ 1e-5 rad, moving the end
    // by 0.6 µm: the two agree to a few µm.
    for t in [0.05, 0.15] {
        let (a, b) = (end(&rigid, t), end(&stiff, t));
        let d = (a[0] - b[0]).hypot(a[1] - b[1]);
        assert!(d < 5e-6, "at {t} s the ends differ by {d} m: {a:?} {b:?}");
    }
}

/// The lever clamped (fixed joint), split soft: the tip rings on its hinge at
/// `sqrt(k / (I_c + m d²)) / 2π`, d the distance from the hinge to its centre of mass.
#[test]
fn a_soft_split_of_a_clamped_bar_rings_at_its_hinge_frequency() {
    let text = r#"
name = "clamped bar"
gravity = [0.0, 0.0]
[[bodies]]
name = "bar"
mass = 0.05
com = [0.05, 0.0]
inertia = 4e-5
joint = { kind = "fixed", at = [0.0, 0.0] }
[[markers]]
name = "end"
at = { body = "bar", point = [0.1, 0.0] }
"#;
    let clamped = Mechanism::from_toml_str(text).unwrap();
    let k = 10.0;
    let bent = clamped
        .split_body("bar", [0.04, 0.0], [1.0, 0.0], "outer", outer(), hinge(k))
        .unwrap();
    let built = bent.build().unwrap();
    let sys = &built.system;
    assert_eq!(sys.model().nv(), 1, "only the hinge moves");
    let x0 = sys.initial_state(0.0, &[0.0], &[1.0]).unwrap();
    let opts = Options {
        max_step: 1e-5,
        output_step: Some(1e-5),
        ..Options::with_tolerances(1e-10, 1e-13)
    };
    let sol = solve(
        &mut MultibodyOde::new(sys),
        Method::DormandPrince54,
        0.0,
        &x0,
        0.1,
        &opts,
    )
    .unwrap();
    // Upward crossings of the angle through zero.
    let q = sol.component(0);
    let ups: Vec<f64> = (1..q.len())
        .filter(|&i| q[i - 1] < 0.0 && q[i] >= 0.0)
        .map(|i| sol.t[i - 1] + (sol.t[i] - sol.t[i - 1]) * q[i - 1] / (q[i - 1] - q[i]))
        .collect();
    assert!(ups.len() >= 5, "{} cycles", ups.len());
    let measured = (ups.len() - 1) as f64 / (ups[ups.len() - 1] - ups[0]);
    let d = 0.07 - 0.04;
    let inertia = outer().inertia + outer().mass * d * d;
    let predicted = (k / inertia).sqrt() / (2.0 * std::f64::consts::PI);
    assert!(
        (measured / predicted - 1.0).abs() < 1e-4,
        "measured {measured} Hz, predicted {predicted} Hz"
    );
}

#[test]
fn a_contact_side_mounts_on_a_sprung_pivot() {
    let m = lever();
    // The ground face of the stop felt on a blade pivoting 30 mm below it.
    let blade = MassProps {
        mass: 0.002,
        com: [0.1, -0.02],
        inertia: 1e-7,
    };
    let on_ground = m
        .mount_compliant(
            "stop_felt",
            Side::A,
            "blade",
            [0.1, -0.04],
            blade,
            hinge(5.0),
        )
        .unwrap();
    let b = on_ground.bodies.last().unwrap();
    assert_eq!(
        (b.name.as_str(), b.joint.parent.as_str()),
        ("blade", "ground")
    );
    assert_eq!(b.joint.at, [0.1, -0.04]);
    assert!(close(b.com, [0.0, 0.02]));
    assert_eq!(on_ground.contacts[0].a.body, "blade");
    assert_eq!(on_ground.bodies[..3], m.bodies[..], "nothing else changes");
    assert_eq!(on_ground.torsion_springs.last().unwrap().name, "blade flex");
    let (_, s0) = layout(&m);
    let (_, s1) = layout(&on_ground);
    assert!(s0.iter().zip(&s1).all(|(a, b)| close(*a, *b)));

    // The lever's side: the lever gives the blade's share of its mass.
    let on_lever = m
        .mount_compliant("tip_pad", Side::A, "pad", [0.09, -0.01], blade, hinge(5.0))
        .unwrap();
    let names: Vec<&str> = on_lever.bodies.iter().map(|b| b.name.as_str()).collect();
    assert_eq!(names, ["lever", "pad", "slider", "tab"]);
    let total = MassProps::of(&on_lever.bodies[0]).plus(&blade);
    let whole = MassProps::of(&m.bodies[0]);
    assert!((total.mass - whole.mass).abs() < 1e-17);
    assert!(
        (total.inertia_about_origin() - whole.inertia_about_origin()).abs() < 1e-18,
        "{total:?}"
    );
    on_lever.build().unwrap();
}

#[test]
fn laws_and_friction_swap() {
    let m = lever();
    let hertz = LawSpec::Hertz { k: 2e6, p: 1.5 };
    let swapped = m.swap_law("stop_felt", hertz.clone()).unwrap();
    assert_eq!(swapped.contacts[0].law, hertz);
    assert_eq!(swapped.contacts[1..], m.contacts[1..]);
    let string = m.swap_law("wire", hertz.clone()).unwrap();
    assert_eq!(string.strings[0].law, hertz);
    // The same law gives the same description.
    assert_eq!(
        m.swap_law("stop_felt", m.contacts[0].law.clone()).unwrap(),
        m
    );

    let frictionless = m.swap_friction("stop_felt", None).unwrap();
    assert_eq!(frictionless.contacts[0].friction, None);
    let gripping = m
        .swap_friction(
            "tip_pad",
            Some(ContactFrictionSpec::Coulomb {
                mu: 0.5,
                regularization: 1e-3,
            }),
        )
        .unwrap();
    assert!(gripping.contacts[1].friction.is_some());
    gripping.build().unwrap();
}

fn field(e: MechanismError) -> String {
    assert!(!e.message.is_empty());
    e.field
}

#[test]
fn bad_arguments_are_named_and_never_panic() {
    let m = lever();
    let split_err = |body: &str, at: [f64; 2], along: [f64; 2], new: &str, p: MassProps| {
        field(
            m.split_body(body, at, along, new, p, hinge(1.0))
                .expect_err("refused"),
        )
    };
    let o = outer();
    let x = [1.0, 0.0];
    assert_eq!(
        split_err("levr", [0.04, 0.0], x, "tip", o),
        "split_body.body"
    );
    assert_eq!(
        split_err("ground", [0.04, 0.0], x, "tip", o),
        "split_body.body"
    );
    assert_eq!(
        split_err("lever", [0.04, 0.0], x, "slider", o),
        "split_body.new_body"
    );
    assert_eq!(
        split_err("lever", [0.04, 0.0], x, "ground", o),
        "split_body.new_body"
    );
    assert_eq!(
        split_err("lever", [0.04, 0.0], x, " ", o),
        "split_body.new_body"
    );
    assert_eq!(
        split_err("lever", [f64::NAN, 0.0], x, "tip", o),
        "split_body.at[0]"
    );
    assert_eq!(
        split_err("lever", [0.04, 0.0], [0.0, 0.0], "tip", o),
        "split_body.along"
    );
    // Nothing beyond 150 mm (the distal part's centre of mass put there too).
    let far = MassProps {
        mass: 0.001,
        com: [0.16, 0.0],
        inertia: 1e-9,
    };
    assert_eq!(
        split_err("lever", [0.15, 0.0], x, "tip", far),
        "split_body.at"
    );
    // The distal centre of mass on the wrong side: `along` reversed.
    assert_eq!(
        split_err("lever", [0.04, 0.0], [-1.0, 0.0], "tip", o),
        "split_body.distal.com"
    );
    // As heavy as the lever: nothing would remain.
    let heavy = MassProps { mass: 0.05, ..o };
    assert_eq!(
        split_err("lever", [0.04, 0.0], x, "tip", heavy),
        "split_body.distal.mass"
    );
    let negative = MassProps { mass: -0.01, ..o };
    assert_eq!(
        split_err("lever", [0.04, 0.0], x, "tip", negative),
        "split_body.distal.mass"
    );
    // 30 g at 95 mm takes more inertia about the pivot than the lever has to give.
    let outlying = MassProps {
        com: [0.095, 0.0],
        ..o
    };
    let e = m
        .split_body("lever", [0.04, 0.0], x, "tip", outlying, hinge(1.0))
        .expect_err("refused");
    assert_eq!(e.field, "split_body.distal.inertia", "{e}");
    assert!(e.to_string().contains("lever"), "{e}");
    // A cut through the striker's shapes... the striker has one shape; give it two.
    let mut two = m.clone();
    two.strings[0].striker.shapes.push(ShapeSpec::Circle {
        center: [0.02, 0.005],
        radius: 0.002,
    });
    let e = two
        .split_body("lever", [0.04, 0.0], x, "tip", o, hinge(1.0))
        .expect_err("refused");
    assert_eq!(e.field, "split_body.at");
    assert!(e.message.contains("strings[0].striker"), "{e}");
    // A spring name already taken.
    let mut taken = m.clone();
    taken.torsion_springs[0].name = "tip flex".into();
    assert_eq!(
        field(
            taken
                .split_body("lever", [0.04, 0.0], x, "tip", o, hinge(1.0))
                .expect_err("refused")
        ),
        "split_body.new_body"
    );
    // A negative stiffness.
    let e = m
        .split_body("lever", [0.04, 0.0], x, "tip", o, hinge(-1.0))
        .expect_err("refused");
    assert_eq!(e.field, "split_body.flex.stiffness");

    // Mounts.
    let blade = MassProps {
        mass: 0.002,
        com: [0.1, -0.02],
        inertia: 1e-7,
    };
    let mount_err = |contact: &str, props: MassProps| {
        field(
            m.mount_compliant(contact, Side::B, "blade", [0.1, -0.04], props, hinge(5.0))
                .expect_err("refused"),
        )
    };
    assert_eq!(mount_err("stop_fel", blade), "mount_compliant.contact");
    let e = m
        .mount_compliant("wire", Side::A, "blade", [0.0, 0.0], blade, hinge(5.0))
        .expect_err("refused");
    assert!(e.message.contains("string"), "{e}");
    let heavy = MassProps { mass: 0.1, ..blade };
    assert_eq!(mount_err("stop_felt", heavy), "mount_compliant.props.mass");
    let flat = MassProps {
        inertia: 0.0,
        ..blade
    };
    assert_eq!(
        mount_err("stop_felt", flat),
        "mount_compliant.props.inertia"
    );

    // Swaps.
    let e = m
        .swap_law("stop", LawSpec::Hertz { k: 1e6, p: 1.5 })
        .expect_err("refused");
    assert_eq!(e.field, "swap_law.contact");
    assert!(e.message.contains("stop_felt, tip_pad, wire"), "{e}");
    let e = m
        .swap_law("stop_felt", LawSpec::Hertz { k: -1.0, p: 1.5 })
        .expect_err("refused");
    assert_eq!(e.field, "swap_law.law.hertz.k");
    let e = m
        .swap_law("stop_felt", LawSpec::Material("velvet".into()))
        .expect_err("refused");
    assert_eq!(e.field, "swap_law.law.material");
    let stulov = LawSpec::Stulov {
        q0: 1e9,
        p: 2.5,
        epsilon: 0.9,
        tau0: 1e-6,
    };
    assert_eq!(
        field(m.swap_law("wire", stulov).expect_err("refused")),
        "swap_law.law"
    );
    assert_eq!(
        field(m.swap_friction("wire", None).expect_err("refused")),
        "swap_friction.contact"
    );
    let e = m
        .swap_friction(
            "stop_felt",
            Some(ContactFrictionSpec::Coulomb {
                mu: -0.1,
                regularization: 1e-3,
            }),
        )
        .expect_err("refused");
    assert_eq!(e.field, "swap_friction.friction.coulomb.mu");

    // A description that is already wrong says so, naming its own field.
    let mut broken = m.clone();
    broken.bodies[1].mass = -1.0;
    assert_eq!(
        field(
            broken
                .swap_friction("stop_felt", None)
                .expect_err("refused")
        ),
        "bodies[1].mass"
    );
}
