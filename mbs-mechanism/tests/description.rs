//! Reading, checking and building descriptions: round trips, named errors for bad files,
//! and the elements doing what they say.

use mbs_integrators::{Method, MultibodyOde, Options, solve};
use mbs_mechanism::{Mechanism, MechanismError};

/// A small mechanism using every part: a lever on a pivot with a stop, friction and a
/// spring, a slider on it, a cord to the ground, a contact with a preset material, a point
/// spring, a load, a marker, events and a metric.
const LEVER: &str = r#"
name = "lever and striker"
about = "a test mechanism"
gravity = [0.0, -9.81]

[[ground]]
name = "base"
points = [[-0.1, -0.05], [0.1, -0.05], [0.1, -0.04]]
thickness = 0.01

[[bodies]]
name = "lever"
mass = 0.05
com = [0.05, 0.0]
inertia = 4e-5
joint = { kind = "revolute", at = [0.0, 0.0], limits = { lower = -0.5, upper = 0.5, stiffness = 50.0, damping = 0.01 }, friction = { coulomb = 1e-4, regularization = 0.01 } }
outline = [{ points = [[0.0, -0.003], [0.1, -0.003], [0.1, 0.003], [0.0, 0.003]], thickness = 0.01 }]

[[bodies]]
name = "weight"
mass = 0.01
com = [0.0, 0.0]
inertia = 1e-6
joint = { kind = "prismatic", parent = "lever", at = [0.08, 0.0], axis = [0.0, 1.0] }
outline = [{ circle = { center = [0.0, 0.0], radius = 0.004 }, thickness = 0.008, z = 0.002 }]

[[torsion_springs]]
name = "return spring"
joint = "lever"
stiffness = 0.05
preload = -0.01

[[point_springs]]
name = "slider spring"
a = { body = "lever", point = [0.08, 0.0] }
b = { body = "weight", point = [0.0, 0.0] }
stiffness = 200.0
rest_length = 0.0
damping = 0.1

[[cords]]
name = "tape"
a = { body = "lever", point = [0.1, 0.0] }
b = { body = "ground", point = [0.1, -0.03] }
length = 0.035
stiffness = 1000.0

[[loads]]
name = "push"
at = { body = "lever", point = [0.02, 0.0] }
direction = [0.0, -1.0]
magnitude = 0.1

[[contacts]]
name = "stop_felt"
a = { body = "ground", shapes = [{ segment = { a = [0.09, -0.01], b = [0.11, -0.01] } }] }
b = { body = "lever", shapes = [{ circle = { center = [0.1, -0.004], radius = 0.002 } }, { profile = { points = [[0.0, 0.01], [0.02, 0.01], [0.04, 0.012]] } }] }
law = { material = "action_felt" }
friction = { material = { name = "action_felt", regularization = 1e-3 } }

[[markers]]
name = "tip"
at = { body = "lever", point = [0.1, 0.0] }

[[events]]
name = "lands"
contact = "stop_felt"
on = "onset"

[[events]]
name = "half way"
coordinate = "lever"
value = -0.05
direction = "falling"

[[metrics]]
name = "tip speed at landing"
quantity = "speed"
marker = "tip"
at = "lands"
unit = "m/s"
"#;

fn lever() -> Mechanism {
    Mechanism::from_toml_str(LEVER).expect("the lever parses")
}

#[test]
fn toml_and_json_round_trip_exactly() {
    let m = lever();
    m.validate().expect("valid");
    let toml = m.to_toml_string().unwrap();
    assert!(toml.starts_with("# Mechanism description: lever and striker"));
    assert!(toml.contains("# Bodies: mass (kg)"), "{toml}");
    assert_eq!(Mechanism::from_toml_str(&toml).unwrap(), m, "{toml}");
    let json = m.to_json_string().unwrap();
    assert_eq!(Mechanism::from_json_str(&json).unwrap(), m);
    // Numbers that do not print short survive both.
    let mut odd = m.clone();
    odd.bodies[0].inertia = 0.1 + 0.2;
    odd.bodies[0].com[1] = -1.0 / 3.0;
    let back = Mechanism::from_toml_str(&odd.to_toml_string().unwrap()).unwrap();
    assert_eq!(back.bodies[0].inertia.to_bits(), (0.1f64 + 0.2).to_bits());
    assert_eq!(back.bodies[0].com[1].to_bits(), (-1.0f64 / 3.0).to_bits());
    let back = Mechanism::from_json_str(&odd.to_json_string().unwrap()).unwrap();
    assert_eq!(back, odd);
}

#[test]
fn builds_every_part_in_its_place() {
    let built = lever().build().expect("builds");
    let model = built.system.model();
    assert_eq!(model.nv(), 2);
    assert_eq!(model.coordinate_id("lever").unwrap(), 0);
    assert_eq!(model.coordinate_id("weight").unwrap(), 1);
    // Springs, the cord, the stop, friction, the load, the contact, and the switching
    // function of the coordinate event.
    assert_eq!(built.system.elements().len(), 8);
    assert_eq!(built.watches.len(), 1);
    assert!(built.watches.contains_key("half way"));
    assert_eq!(built.contacts.len(), 1);
    for name in [
        "return spring",
        "slider spring",
        "tape",
        "push",
        "stop_felt",
    ] {
        assert!(built.elements.contains_key(name), "{name}");
    }
    let e = built.contacts["stop_felt"];
    assert_eq!(
        built.system.elements().nth(e).unwrap().name(),
        "contact 'stop_felt'"
    );
}

/// `text` with `from` replaced by `to` (which must be there).
fn edit(from: &str, to: &str) -> String {
    assert!(LEVER.contains(from), "{from}");
    LEVER.replacen(from, to, 1)
}

/// The error of a description that must be refused, read as a file.
fn refused(text: &str, ext: &str) -> MechanismError {
    let dir = std::env::temp_dir().join(format!("mbs-mechanism-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    static COUNT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = dir.join(format!("bad-{n}.{ext}"));
    std::fs::write(&path, text).unwrap();
    let err = Mechanism::load(&path).expect_err("must be refused");
    let shown = err.to_string();
    assert!(shown.starts_with(&path.display().to_string()), "{shown}");
    err
}

fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| {
            l.starts_with(needle)
                || l.contains(&format!(" {needle}"))
                || l.contains(&format!("\"{needle}"))
        })
        .map(|i| i + 1)
        .unwrap_or_else(|| panic!("{needle}"))
}

#[test]
fn bad_descriptions_name_the_field_and_line() {
    // An unknown body in a contact.
    let text = edit(
        "b = { body = \"lever\", shapes = [{ circle",
        "b = { body = \"levr\", shapes = [{ circle",
    );
    let e = refused(&text, "toml");
    assert_eq!(e.field, "contacts[0].b.body");
    assert!(e.message.contains("no body 'levr'"), "{e}");
    assert_eq!(e.line, Some(line_of(&text, "levr")), "{e}");

    // A cycle: the lever hangs from the weight, which hangs from the lever.
    let text = edit(
        "joint = { kind = \"revolute\", at = [0.0, 0.0],",
        "joint = { kind = \"revolute\", parent = \"weight\", at = [0.0, 0.0],",
    );
    let e = refused(&text, "toml");
    assert_eq!(e.field, "bodies[0].joint.parent");
    assert!(e.message.contains("cycle (lever → weight → lever)"), "{e}");

    // A negative mass.
    let text = edit("mass = 0.01", "mass = -0.01");
    let e = refused(&text, "toml");
    assert_eq!(e.field, "bodies[1].mass");
    assert!(e.message.contains("positive"), "{e}");
    assert_eq!(e.line, Some(line_of(&text, "mass = -0.01")));

    // An unknown material.
    let text = edit(
        "law = { material = \"action_felt\" }",
        "law = { material = \"velvet\" }",
    );
    let e = refused(&text, "toml");
    assert_eq!(e.field, "contacts[0].law.material");
    assert!(e.message.contains("no material 'velvet'"), "{e}");
    assert!(e.message.contains("action_felt"), "lists the presets: {e}");

    // A felt whose rate damping would give energy back; written without it, a felt
    // reads as rate-independent and writes as it was read.
    let text = edit(
        "law = { material = \"action_felt\" }",
        "law = { felt = { k = 1e7, p = 2.0, e = 0.4, smoothing = 1e-3, alpha = -0.5 } }",
    );
    let e = refused(&text, "toml");
    assert_eq!(e.field, "contacts[0].law.felt.alpha");
    assert_eq!(e.line, Some(line_of(&text, "alpha = -0.5")), "{e}");
    let plain = Mechanism::from_toml_str(&edit(
        "law = { material = \"action_felt\" }",
        "law = { felt = { k = 1e7, p = 2.0, e = 0.4, smoothing = 1e-3 } }",
    ))
    .expect("a felt without alpha");
    assert!(matches!(
        plain.contacts[0].law,
        mbs_mechanism::LawSpec::Felt { alpha, .. } if alpha == 0.0
    ));
    assert!(!plain.to_toml_string().unwrap().contains("alpha"));

    // A contact between a body and itself.
    let text = edit(
        "a = { body = \"ground\", shapes = [{ segment",
        "a = { body = \"lever\", shapes = [{ segment",
    );
    let e = refused(&text, "toml");
    assert_eq!(e.field, "contacts[0].b.body");
    assert!(e.message.contains("'lever' and itself"), "{e}");

    // A cord with zero length.
    let text = edit("length = 0.035", "length = 0.0");
    let e = refused(&text, "toml");
    assert_eq!(e.field, "cords[0].length");
    assert_eq!(e.line, Some(line_of(&text, "length = 0.0")));

    // A misspelt field, a wrong type, a syntax error.
    let e = refused(&edit("inertia = 4e-5", "inertya = 4e-5"), "toml");
    assert!(e.message.contains("inertya"), "{e}");
    let e = refused(&edit("mass = 0.05", "mass = \"heavy\""), "toml");
    assert_eq!(e.field, "bodies[0].mass", "{e}");
    let e = refused(&edit("mass = 0.05", "mass = [0.05"), "toml");
    assert!(e.line.is_some(), "{e}");

    // JSON: the same checks, with the line of the parser.
    let mut m = lever();
    m.bodies[1].mass = -1.0;
    let e = refused(&m.to_json_string().unwrap(), "json");
    assert_eq!(e.field, "bodies[1].mass");
    let e = refused(
        "{\"name\": \"x\", \"gravity\": [0, -9.81],\n \"bodies\": 3}",
        "json",
    );
    assert_eq!(e.field, "bodies");
    assert_eq!(e.line, Some(2));
}

#[test]
fn more_bad_descriptions_never_panic() {
    let cases = [
        (
            "kind = \"prismatic\", parent = \"lever\", at = [0.08, 0.0], axis = [0.0, 1.0]",
            "kind = \"prismatic\", parent = \"lever\", at = [0.08, 0.0]",
            "bodies[1].joint.axis",
        ),
        (
            "axis = [0.0, 1.0]",
            "axis = [0.0, 2.0]",
            "bodies[1].joint.axis",
        ),
        (
            "lower = -0.5, upper = 0.5",
            "lower = 0.5, upper = -0.5",
            "bodies[0].joint.limits",
        ),
        (
            "regularization = 0.01 }",
            "regularization = 0.0 }",
            "bodies[0].joint.friction.regularization",
        ),
        (
            "joint = \"lever\"",
            "joint = \"nothing\"",
            "torsion_springs[0].joint",
        ),
        (
            "b = { body = \"ground\", point = [0.1, -0.03] }",
            "b = { body = \"ground\", point = [0.1, nan] }",
            "cords[0].b.point[1]",
        ),
        ("on = \"onset\"", "value = 1.0", "events[0].on"),
        ("marker = \"tip\"", "marker = \"toe\"", "metrics[0].marker"),
        ("at = \"lands\"", "at = \"never\"", "metrics[0].at"),
        (
            "radius = 0.004 }, thickness = 0.008",
            "radius = 0.004 }, thickness = 0.0",
            "bodies[1].outline[0].thickness",
        ),
        ("name = \"weight\"", "name = \"lever\"", "bodies[1].name"),
        ("name = \"weight\"", "name = \"ground\"", "bodies[1].name"),
        (
            "{ segment = { a = [0.09, -0.01], b = [0.11, -0.01] } }",
            "{ segment = { a = [0.09, -0.01], b = [0.09, -0.01] } }",
            "contacts[0].a.shapes[0].segment",
        ),
    ];
    for (from, to, field) in cases {
        let text = edit(from, to);
        let e = refused(&text, "toml");
        assert_eq!(e.field, field, "{to}: {e}");
    }
    // Extensions need a program that provides them.
    let mut m = lever();
    m.extensions.push(mbs_mechanism::Extension {
        kind: "magic".into(),
        name: "m".into(),
        body: "lever".into(),
        params: Default::default(),
    });
    let e = m.build().expect_err("refused");
    assert_eq!(e.field, "extensions[0].kind");
    // A missing file names itself and keeps its cause.
    let e = Mechanism::load(std::path::Path::new("/nonexistent/m.toml")).expect_err("missing");
    assert!(e.to_string().starts_with("/nonexistent/m.toml"), "{e}");
    assert!(std::error::Error::source(&e).is_some());
}

/// A 20 g bob on a slider hanging from a cord: slack, it falls freely; taut, it bounces on
/// the cord's stiffness at `sqrt(k / m)`.
#[test]
fn a_cord_only_pulls() {
    let text = r#"
name = "bob on a cord"
gravity = [0.0, -9.81]
[[bodies]]
name = "bob"
mass = 0.02
com = [0.0, 0.0]
inertia = 1e-6
joint = { kind = "prismatic", at = [0.0, 0.0], axis = [0.0, 1.0] }
[[cords]]
name = "cord"
a = { body = "ground", point = [0.0, 0.1] }
b = { body = "bob", point = [0.0, 0.0] }
length = 0.105
stiffness = 2000.0
"#;
    let m = Mechanism::from_toml_str(text).unwrap();
    let built = m.build().unwrap();
    let sys = &built.system;
    let x0 = sys.initial_state(0.0, &[0.0], &[0.0]).unwrap();
    let opts = Options {
        max_step: 1e-4,
        ..Options::with_tolerances(1e-9, 1e-12)
    };
    let sol = solve(
        &mut MultibodyOde::new(sys),
        Method::DormandPrince54,
        0.0,
        &x0,
        0.05,
        &opts,
    )
    .unwrap();
    // Free fall until the cord goes taut 5 mm down: t = sqrt(2 · 0.005 / g).
    let taut = sol.events.first().expect("the cord goes taut").time;
    let expect = (2.0 * 0.005 / 9.81f64).sqrt();
    assert!(
        (taut - expect).abs() < 1e-6,
        "taut at {taut}, free fall says {expect}"
    );
    // Then it is caught: the lowest point is where the cord's energy takes the fall's,
    // 0.5 k s² = m g (0.005 + s) + 0 ... solved for the stretch s.
    let (mass, k, g) = (0.02f64, 2000.0f64, 9.81f64);
    let s = (mass * g + ((mass * g).powi(2) + 2.0 * k * mass * g * 0.005).sqrt()) / k;
    let lowest = (0..sol.len())
        .map(|i| sol.state(i)[0])
        .fold(f64::INFINITY, f64::min);
    assert!(
        (lowest + 0.005 + s).abs() < 2e-6,
        "lowest {lowest}, energy says {}",
        -0.005 - s
    );
    // And it never pushes: the bob rises back to no higher than where it started.
    let highest = (0..sol.len())
        .map(|i| sol.state(i)[0])
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(highest <= 1e-9, "{highest}");
}
