//! Every error path of `ModelBuilder::build`, `ModelDescription` and `Model::from_json_str`,
//! each checked for the exact `CoreError` variant and the body, joint or field it names; and
//! the positive cases of the builder: declarations out of order, fixed joints merged into
//! their parent, fixed joints on the ground.

use mbs_core::{
    BodyDescription, BodySpec, CoreError, Data, JointDescription, JointKind, JointKindName, Model,
    ModelBuilder, ModelDescription, Placement, PlacementDescription, Transform, crba, frame_pose,
    rnea, update_poses,
};

const REV: JointKind = JointKind::Revolute;
const FIXED: JointKind = JointKind::Fixed;

fn rod() -> BodySpec {
    BodySpec::rod(1.0, 0.5)
}

/// A valid one-link builder to which a test adds the faulty declaration.
fn one_link() -> ModelBuilder {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81])
        .add_link("arm", None, REV, Placement::default(), rod());
    b
}

fn build_err(b: &ModelBuilder) -> CoreError {
    match b.build() {
        Ok(m) => panic!("expected an error, got a model with nv = {}", m.nv()),
        Err(e) => e,
    }
}

fn json_err(text: &str) -> CoreError {
    match Model::from_json_str(text) {
        Ok(m) => panic!("expected an error, got a model with nv = {}", m.nv()),
        Err(e) => e,
    }
}

/// A JSON joint entry; `extra` is spliced in (e.g. an `"axis"`).
fn joint_json(name: &str, parent: Option<&str>, kind: &str, extra: &str) -> String {
    let parent = parent.map_or("null".to_string(), |p| format!("\"{p}\""));
    format!(
        r#"{{"name": "{name}", "parent": {parent}, "kind": "{kind}"{extra},
            "placement": {{"angle": 0.0, "x": 0.5, "y": 0.0}},
            "body": {{"mass": 1.0, "com": [0.25, 0.0], "inertia": 0.02}}}}"#
    )
}

fn model_json(joints: &[String]) -> String {
    format!(
        r#"{{"gravity": [0.0, -9.81], "joints": [{}]}}"#,
        joints.join(",\n")
    )
}

// ---------------------------------------------------------------------------------------
// Non-finite numbers
// ---------------------------------------------------------------------------------------

#[test]
fn nan_gravity_is_rejected() {
    let mut b = one_link();
    b.gravity([f64::NAN, -9.81]);
    let e = build_err(&b);
    assert!(
        matches!(&e, CoreError::NonFinite { item, field: "gravity[0]", value }
            if item == "model" && value.is_nan()),
        "{e:?}"
    );
}

#[test]
fn infinite_gravity_is_rejected() {
    let mut b = one_link();
    b.gravity([0.0, f64::NEG_INFINITY]);
    assert_eq!(
        build_err(&b),
        CoreError::NonFinite {
            item: "model".into(),
            field: "gravity[1]",
            value: f64::NEG_INFINITY,
        }
    );
}

#[test]
fn with_gravity_rejects_non_finite() {
    let model = one_link().build().unwrap();
    assert_eq!(
        model.with_gravity([f64::INFINITY, 0.0]).unwrap_err(),
        CoreError::NonFinite {
            item: "model".into(),
            field: "gravity[0]",
            value: f64::INFINITY,
        }
    );
    assert_eq!(
        model.with_gravity([1.0, 2.0]).unwrap().gravity(),
        [1.0, 2.0]
    );
}

#[test]
fn nan_mass_is_rejected_naming_the_field() {
    let mut b = one_link();
    b.add_link(
        "hammer",
        Some("arm"),
        REV,
        Placement::offset(0.5, 0.0),
        BodySpec::new(f64::NAN, [0.0, 0.0], 0.1),
    );
    let e = build_err(&b);
    assert!(
        matches!(&e, CoreError::NonFinite { item, field: "mass", value }
            if item == "body 'hammer'" && value.is_nan()),
        "{e:?}"
    );
}

#[test]
fn infinite_com_is_rejected_naming_the_component() {
    for (k, field) in [(0, "com[0]"), (1, "com[1]")] {
        let mut com = [0.1, 0.2];
        com[k] = f64::INFINITY;
        let mut b = one_link();
        b.add_link(
            "hammer",
            Some("arm"),
            REV,
            Placement::default(),
            BodySpec::new(1.0, com, 0.1),
        );
        assert_eq!(
            build_err(&b),
            CoreError::NonFinite {
                item: "body 'hammer'".into(),
                field,
                value: f64::INFINITY,
            }
        );
    }
}

#[test]
fn minus_infinite_inertia_is_non_finite_not_non_positive() {
    let mut b = one_link();
    b.add_link(
        "hammer",
        Some("arm"),
        REV,
        Placement::default(),
        BodySpec::new(1.0, [0.0, 0.0], f64::NEG_INFINITY),
    );
    assert_eq!(
        build_err(&b),
        CoreError::NonFinite {
            item: "body 'hammer'".into(),
            field: "inertia",
            value: f64::NEG_INFINITY,
        }
    );
}

#[test]
fn non_finite_body_via_description_struct() {
    // JSON cannot spell NaN, but a description built in Rust can hold one.
    let mut desc = ModelDescription {
        gravity: [0.0, -9.81],
        joints: vec![JointDescription {
            name: "arm".into(),
            parent: None,
            kind: JointKindName::Revolute,
            axis: None,
            placement: PlacementDescription {
                angle: 0.0,
                x: 0.0,
                y: 0.0,
            },
            body: BodyDescription {
                mass: 1.0,
                com: [0.5, 0.0],
                inertia: f64::NAN,
            },
        }],
    };
    let e = desc.build().unwrap_err();
    assert!(
        matches!(&e, CoreError::NonFinite { item, field: "inertia", value }
            if item == "body 'arm'" && value.is_nan()),
        "{e:?}"
    );
    desc.joints[0].body.inertia = 0.1;
    desc.joints[0].placement.y = f64::INFINITY;
    assert_eq!(
        desc.build().unwrap_err(),
        CoreError::NonFinite {
            item: "joint 'arm'".into(),
            field: "placement.y",
            value: f64::INFINITY,
        }
    );
}

#[test]
fn non_finite_placement_is_rejected_naming_the_field() {
    let cases: [(Placement, &str); 3] = [
        (Placement::new(f64::NAN, 0.0, 0.0), "placement.angle"),
        (Placement::new(0.0, f64::INFINITY, 0.0), "placement.x"),
        (Placement::new(0.0, 0.0, f64::NEG_INFINITY), "placement.y"),
    ];
    for (placement, want_field) in cases {
        let mut b = one_link();
        b.add_link("elbow", Some("arm"), REV, placement, rod());
        let e = build_err(&b);
        match &e {
            CoreError::NonFinite { item, field, value } => {
                assert_eq!(item, "joint 'elbow'");
                assert_eq!(*field, want_field);
                assert!(!value.is_finite());
            }
            other => panic!("expected NonFinite, got {other:?}"),
        }
    }
}

#[test]
fn non_finite_prismatic_axis_is_rejected() {
    let mut b = one_link();
    b.add_link(
        "slider",
        Some("arm"),
        JointKind::Prismatic {
            axis: [1.0, f64::NAN],
        },
        Placement::default(),
        rod(),
    );
    let e = build_err(&b);
    assert!(
        matches!(&e, CoreError::NonFinite { item, field: "axis[1]", value }
            if item == "joint 'slider'" && value.is_nan()),
        "{e:?}"
    );
}

// ---------------------------------------------------------------------------------------
// Non-positive mass properties
// ---------------------------------------------------------------------------------------

#[test]
fn zero_and_negative_mass_are_rejected() {
    for mass in [0.0, -0.0, -1.5] {
        let mut b = one_link();
        b.add_link(
            "hammer",
            Some("arm"),
            REV,
            Placement::default(),
            BodySpec::new(mass, [0.0, 0.0], 0.1),
        );
        let e = build_err(&b);
        assert_eq!(
            e,
            CoreError::NonPositiveMass {
                body: "hammer".into(),
                mass,
            }
        );
        let msg = e.to_string();
        assert!(msg.contains("'hammer'"), "{msg}");
        assert!(msg.contains("mass must be positive"), "{msg}");
    }
}

#[test]
fn zero_and_negative_inertia_are_rejected() {
    for inertia in [0.0, -0.25] {
        let mut b = one_link();
        b.add_link(
            "hammer",
            Some("arm"),
            REV,
            Placement::default(),
            BodySpec::new(1.0, [0.1, 0.0], inertia),
        );
        let e = build_err(&b);
        assert_eq!(
            e,
            CoreError::NonPositiveInertia {
                body: "hammer".into(),
                inertia,
            }
        );
        assert!(e.to_string().contains("body 'hammer'"), "{e}");
    }
}

#[test]
fn non_positive_mass_in_json_names_the_body() {
    let json = model_json(&[joint_json("arm", None, "revolute", "")])
        .replace("\"mass\": 1.0", "\"mass\": -2.0");
    assert_eq!(
        json_err(&json),
        CoreError::NonPositiveMass {
            body: "arm".into(),
            mass: -2.0,
        }
    );
}

// ---------------------------------------------------------------------------------------
// Names
// ---------------------------------------------------------------------------------------

#[test]
fn duplicate_body_name_is_rejected() {
    let mut b = one_link();
    b.add_body("hammer", rod())
        .add_body("hammer", rod())
        .add_joint("j", REV, Some("arm"), "hammer", Placement::default());
    let e = build_err(&b);
    assert_eq!(
        e,
        CoreError::DuplicateName {
            what: "body",
            name: "hammer".into(),
        }
    );
    assert_eq!(e.to_string(), "duplicate body name 'hammer'");
}

#[test]
fn duplicate_joint_name_is_rejected() {
    let mut b = one_link();
    b.add_body("b1", rod())
        .add_body("b2", rod())
        .add_joint("knee", REV, Some("arm"), "b1", Placement::default())
        .add_joint("knee", REV, Some("arm"), "b2", Placement::default());
    assert_eq!(
        build_err(&b),
        CoreError::DuplicateName {
            what: "joint",
            name: "knee".into(),
        }
    );
}

#[test]
fn duplicate_name_in_json_is_rejected() {
    // A JSON joint carries its body under its own name, so the body check fires first.
    let json = model_json(&[
        joint_json("arm", None, "revolute", ""),
        joint_json("hand", Some("arm"), "revolute", ""),
        joint_json("hand", Some("arm"), "revolute", ""),
    ]);
    assert_eq!(
        json_err(&json),
        CoreError::DuplicateName {
            what: "body",
            name: "hand".into(),
        }
    );
}

// ---------------------------------------------------------------------------------------
// Axes
// ---------------------------------------------------------------------------------------

#[test]
fn prismatic_zero_axis_is_rejected() {
    for axis in [[0.0, 0.0], [1e-13, -1e-13]] {
        let mut b = one_link();
        b.add_link(
            "slider",
            Some("arm"),
            JointKind::Prismatic { axis },
            Placement::default(),
            rod(),
        );
        let e = build_err(&b);
        assert_eq!(
            e,
            CoreError::ZeroAxis {
                joint: "slider".into(),
                axis,
            }
        );
        assert!(e.to_string().contains("joint 'slider'"), "{e}");
    }
}

#[test]
fn json_prismatic_without_axis_is_rejected() {
    let json = model_json(&[
        joint_json("arm", None, "revolute", ""),
        joint_json("slider", Some("arm"), "prismatic", ""),
    ]);
    let e = json_err(&json);
    assert!(
        matches!(&e, CoreError::BadAxis { joint, message }
            if joint == "slider" && message.contains("needs")),
        "{e:?}"
    );
}

#[test]
fn json_axis_on_revolute_or_fixed_is_rejected() {
    for kind in ["revolute", "fixed"] {
        let json = model_json(&[
            joint_json("arm", None, "revolute", ""),
            joint_json("pin", Some("arm"), kind, r#", "axis": [1.0, 0.0]"#),
        ]);
        let e = json_err(&json);
        assert!(
            matches!(&e, CoreError::BadAxis { joint, message }
                if joint == "pin" && message.contains("only allowed on prismatic")),
            "{kind}: {e:?}"
        );
    }
}

#[test]
fn json_prismatic_zero_axis_is_rejected() {
    let json = model_json(&[joint_json(
        "slider",
        None,
        "prismatic",
        r#", "axis": [0.0, 0.0]"#,
    )]);
    assert_eq!(
        json_err(&json),
        CoreError::ZeroAxis {
            joint: "slider".into(),
            axis: [0.0, 0.0],
        }
    );
}

// ---------------------------------------------------------------------------------------
// Topology
// ---------------------------------------------------------------------------------------

#[test]
fn unknown_parent_in_json_is_rejected() {
    let json = model_json(&[
        joint_json("arm", None, "revolute", ""),
        joint_json("hand", Some("amr"), "revolute", ""),
    ]);
    let e = json_err(&json);
    assert_eq!(
        e,
        CoreError::UnknownBody {
            joint: "hand".into(),
            role: "parent",
            body: "amr".into(),
        }
    );
    assert_eq!(e.to_string(), "joint 'hand': unknown parent body 'amr'");
}

#[test]
fn unknown_child_body_is_rejected() {
    let mut b = one_link();
    b.add_joint("wrist", REV, Some("arm"), "hnad", Placement::default());
    assert_eq!(
        build_err(&b),
        CoreError::UnknownBody {
            joint: "wrist".into(),
            role: "child",
            body: "hnad".into(),
        }
    );
}

#[test]
fn body_child_of_two_joints_is_rejected_naming_both() {
    let mut b = one_link();
    b.add_body("hand", rod())
        .add_joint("zeta", REV, Some("arm"), "hand", Placement::default())
        .add_joint("alpha", REV, None, "hand", Placement::default());
    let e = build_err(&b);
    assert_eq!(
        e,
        CoreError::MultipleParents {
            body: "hand".into(),
            joints: vec!["alpha".into(), "zeta".into()],
        }
    );
    let msg = e.to_string();
    assert!(
        msg.contains("'hand'") && msg.contains("alpha, zeta"),
        "{msg}"
    );
}

#[test]
fn two_cycle_in_json_is_rejected() {
    let json = model_json(&[
        joint_json("root", None, "revolute", ""),
        joint_json("b", Some("a"), "revolute", ""),
        joint_json("a", Some("b"), "revolute", ""),
    ]);
    let e = json_err(&json);
    assert_eq!(
        e,
        CoreError::Cycle {
            joints: vec!["a".into(), "b".into()],
        }
    );
    assert_eq!(e.to_string(), "the joints a, b form a cycle");
}

#[test]
fn self_parent_joint_is_a_cycle() {
    let json = model_json(&[
        joint_json("root", None, "revolute", ""),
        joint_json("ouroboros", Some("ouroboros"), "revolute", ""),
    ]);
    assert_eq!(
        json_err(&json),
        CoreError::Cycle {
            joints: vec!["ouroboros".into()],
        }
    );
    // The same with a separately named joint in the builder.
    let mut b = one_link();
    b.add_body("ring", rod())
        .add_joint("loop", REV, Some("ring"), "ring", Placement::default());
    assert_eq!(
        build_err(&b),
        CoreError::Cycle {
            joints: vec!["loop".into()],
        }
    );
}

#[test]
fn three_cycle_with_a_tail_lists_only_the_cycle_joints() {
    let json = model_json(&[
        joint_json("root", None, "revolute", ""),
        joint_json("c", Some("b"), "revolute", ""),
        joint_json("tail", Some("c"), "revolute", ""),
        joint_json("a", Some("c"), "fixed", ""),
        joint_json("b", Some("a"), "prismatic", r#", "axis": [0.0, 1.0]"#),
    ]);
    assert_eq!(
        json_err(&json),
        CoreError::Cycle {
            joints: vec!["a".into(), "b".into(), "c".into()],
        }
    );
}

#[test]
fn body_without_joint_is_not_connected() {
    let mut b = one_link();
    b.add_body("floating", rod());
    let e = build_err(&b);
    assert_eq!(
        e,
        CoreError::NotConnected {
            body: "floating".into(),
        }
    );
    assert!(e.to_string().contains("body 'floating'"), "{e}");
}

#[test]
fn empty_models_are_rejected() {
    assert_eq!(build_err(&ModelBuilder::new()), CoreError::EmptyModel);

    let mut b = ModelBuilder::new();
    b.add_link("base", None, FIXED, Placement::offset(1.0, 0.0), rod())
        .add_link("plate", Some("base"), FIXED, Placement::default(), rod());
    assert_eq!(build_err(&b), CoreError::EmptyModel);

    assert_eq!(
        json_err(r#"{"gravity": [0.0, -9.81], "joints": []}"#),
        CoreError::EmptyModel
    );
    let json = model_json(&[joint_json("base", None, "fixed", "")]);
    assert_eq!(json_err(&json), CoreError::EmptyModel);
}

// ---------------------------------------------------------------------------------------
// Parse errors
// ---------------------------------------------------------------------------------------

fn parse_message(text: &str) -> String {
    match json_err(text) {
        CoreError::Parse(msg) => msg,
        other => panic!("expected Parse, got {other:?}"),
    }
}

#[test]
fn malformed_json_is_a_parse_error() {
    let good = model_json(&[joint_json("arm", None, "revolute", "")]);
    let truncated = &good[..good.len() - 3];
    let msg = parse_message(truncated);
    assert!(msg.contains("line"), "{msg}");
    let msg = parse_message("{\"gravity\": [0.0, -9.81],, \"joints\": []}");
    assert!(msg.contains("line 1"), "{msg}");
    // Display prefixes the context.
    let e = json_err("not json");
    assert!(e.to_string().starts_with("model description: "), "{e}");
}

#[test]
fn misspelt_field_is_a_parse_error_naming_it() {
    let json =
        model_json(&[joint_json("arm", None, "revolute", "")]).replace("\"mass\"", "\"masss\"");
    let msg = parse_message(&json);
    assert!(msg.contains("unknown field `masss`"), "{msg}");
    assert!(
        msg.contains("`mass`"),
        "the expected fields are listed: {msg}"
    );

    let json = model_json(&[joint_json(
        "arm",
        None,
        "revolute",
        r#", "axes": [1.0, 0.0]"#,
    )]);
    let msg = parse_message(&json);
    assert!(msg.contains("unknown field `axes`"), "{msg}");

    let json =
        model_json(&[joint_json("arm", None, "revolute", "")]).replace("\"gravity\"", "\"gravty\"");
    let msg = parse_message(&json);
    assert!(msg.contains("gravty"), "{msg}");
}

#[test]
fn missing_field_is_a_parse_error_naming_it() {
    let json =
        model_json(&[joint_json("arm", None, "revolute", "")]).replace(", \"inertia\": 0.02", "");
    let msg = parse_message(&json);
    assert!(msg.contains("missing field `inertia`"), "{msg}");
}

#[test]
fn unknown_joint_kind_is_a_parse_error_naming_it() {
    let json = model_json(&[joint_json("arm", None, "revolve", "")]);
    let msg = parse_message(&json);
    assert!(msg.contains("unknown variant `revolve`"), "{msg}");
}

#[test]
fn wrong_type_is_a_parse_error_with_location() {
    let json = model_json(&[joint_json("arm", None, "revolute", "")])
        .replace("\"mass\": 1.0", "\"mass\": \"heavy\"");
    let msg = parse_message(&json);
    // serde_json reports the offending value and its position, not the field's name.
    assert!(msg.contains("invalid type"), "{msg}");
    assert!(msg.contains("\"heavy\""), "{msg}");
    assert!(msg.contains("line 3"), "{msg}");

    let json = model_json(&[joint_json("arm", None, "revolute", "")])
        .replace("\"com\": [0.25, 0.0]", "\"com\": [0.25]");
    let msg = parse_message(&json);
    assert!(msg.contains("invalid length 1"), "{msg}");
}

// ---------------------------------------------------------------------------------------
// Positive cases
// ---------------------------------------------------------------------------------------

const ORDERED: &str = r#"{"gravity": [0.3, -9.81], "joints": [
  {"name": "shoulder", "parent": null, "kind": "revolute",
   "placement": {"angle": 0.2, "x": 0.1, "y": -0.2},
   "body": {"mass": 2.0, "com": [0.4, 0.05], "inertia": 0.07}},
  {"name": "elbow", "parent": "shoulder", "kind": "revolute",
   "placement": {"angle": -0.4, "x": 0.8, "y": 0.0},
   "body": {"mass": 1.2, "com": [0.3, -0.02], "inertia": 0.03}},
  {"name": "slide", "parent": "shoulder", "kind": "prismatic", "axis": [0.6, 0.8],
   "placement": {"angle": 1.1, "x": 0.3, "y": 0.1},
   "body": {"mass": 0.7, "com": [0.0, 0.1], "inertia": 0.01}},
  {"name": "wrist", "parent": "elbow", "kind": "revolute",
   "placement": {"angle": 0.0, "x": 0.6, "y": 0.05},
   "body": {"mass": 0.5, "com": [0.1, 0.0], "inertia": 0.004}}]}"#;

#[test]
fn child_listed_before_parent_builds_and_keeps_file_order() {
    let ordered_desc = ModelDescription::from_json_str(ORDERED).unwrap();
    let mut shuffled_desc = ordered_desc.clone();
    // wrist, slide, elbow, shoulder: every child before its parent.
    shuffled_desc.joints.reverse();
    let ordered = ordered_desc.build().unwrap();
    let shuffled = Model::from_json_str(&shuffled_desc.to_json_string()).unwrap();

    assert_eq!(
        ordered.coordinate_names(),
        ["shoulder", "elbow", "slide", "wrist"]
    );
    assert_eq!(
        shuffled.coordinate_names(),
        ["wrist", "slide", "elbow", "shoulder"]
    );
    // Bodies are still topologically ordered.
    for b in shuffled.moving_bodies() {
        let p = shuffled.parent(b).unwrap();
        assert!(p < b, "{:?} before its parent", shuffled.body_name(b));
    }
    for k in 0..shuffled.nv() {
        let b = shuffled.body_of_coordinate(k).unwrap();
        assert_eq!(
            shuffled.body_name(b),
            Some(shuffled.coordinate_names()[k].as_str())
        );
        assert_eq!(shuffled.coordinate_of(b), Some(k));
    }

    // perm[i] = coordinate of shuffled coordinate i in the ordered model.
    let perm: Vec<usize> = shuffled
        .coordinate_names()
        .iter()
        .map(|n| ordered.coordinate_id(n).unwrap())
        .collect();
    assert_eq!(perm, [3, 2, 1, 0]);
    let q_ord = [0.3, -0.7, 0.15, 1.2];
    let v_ord = [1.0, -0.5, 0.3, 2.0];
    let a_ord = [-0.2, 0.4, 1.5, -1.0];
    let permute = |x: &[f64; 4]| -> Vec<f64> { perm.iter().map(|&p| x[p]).collect() };
    let (q_sh, v_sh, a_sh) = (permute(&q_ord), permute(&v_ord), permute(&a_ord));

    let mut d_ord = Data::new(&ordered);
    let mut d_sh = Data::new(&shuffled);
    let m_ord = crba(&ordered, &mut d_ord, &q_ord).unwrap().clone();
    let m_sh = crba(&shuffled, &mut d_sh, &q_sh).unwrap().clone();
    for i in 0..4 {
        for j in 0..4 {
            let (got, want) = (m_sh[(i, j)], m_ord[(perm[i], perm[j])]);
            assert!((got - want).abs() <= 1e-12, "M[{i},{j}]: {got} vs {want}");
        }
    }
    let t_ord = rnea(&ordered, &mut d_ord, &q_ord, &v_ord, &a_ord)
        .unwrap()
        .clone();
    let t_sh = rnea(&shuffled, &mut d_sh, &q_sh, &v_sh, &a_sh)
        .unwrap()
        .clone();
    for i in 0..4 {
        assert!(
            (t_sh[i] - t_ord[perm[i]]).abs() <= 1e-12,
            "tau[{i}]: {} vs {}",
            t_sh[i],
            t_ord[perm[i]]
        );
    }
}

/// Parallel-axis combination of two bodies given in the same frame: (mass, com, I_com).
fn combine(m1: f64, c1: [f64; 2], i1: f64, m2: f64, c2: [f64; 2], i2: f64) -> BodySpec {
    let m = m1 + m2;
    let c = [(m1 * c1[0] + m2 * c2[0]) / m, (m1 * c1[1] + m2 * c2[1]) / m];
    let d2 = |p: [f64; 2]| (p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2);
    BodySpec::new(m, c, i1 + m1 * d2(c1) + i2 + m2 * d2(c2))
}

#[test]
fn fixed_joint_merges_inertia_into_parent() {
    let (m1, c1, i1) = (2.0, [0.4, 0.05], 0.07);
    let (m2, c2, i2) = (0.8, [0.1, -0.2], 0.02);
    let fixed_at = Placement::new(0.7, 0.9, 0.1);
    let tip_at = Placement::new(-0.3, 0.25, 0.4);
    let tip = BodySpec::new(0.6, [0.2, 0.0], 0.01);

    // Upper arm, a fixed weight on it, and a moving tip carried by the weight.
    let mut with_fixed = ModelBuilder::new();
    with_fixed
        .gravity([0.5, -9.81])
        .add_link(
            "upper",
            None,
            REV,
            Placement::offset(0.1, 0.2),
            BodySpec::new(m1, c1, i1),
        )
        .add_link(
            "weight",
            Some("upper"),
            FIXED,
            fixed_at,
            BodySpec::new(m2, c2, i2),
        )
        .add_link("tip", Some("weight"), REV, tip_at, tip);
    let with_fixed = with_fixed.build().unwrap();
    assert_eq!(with_fixed.nv(), 2);
    assert_eq!(with_fixed.nbodies(), 3);
    assert_eq!(with_fixed.coordinate_names(), ["upper", "tip"]);

    // The same by hand: the weight's centre of mass in the upper frame, parallel axes.
    let xf = Transform::new(fixed_at.angle, fixed_at.x, fixed_at.y);
    let c2_in_1 = xf.transform_point(c2);
    let merged = combine(m1, c1, i1, m2, c2_in_1, i2);
    let xt = xf.compose(&Transform::new(tip_at.angle, tip_at.x, tip_at.y));
    let mut by_hand = ModelBuilder::new();
    by_hand
        .gravity([0.5, -9.81])
        .add_link("upper", None, REV, Placement::offset(0.1, 0.2), merged)
        .add_link(
            "tip",
            Some("upper"),
            REV,
            Placement::new(xt.angle(), xt.x, xt.y),
            tip,
        );
    let by_hand = by_hand.build().unwrap();

    let upper = with_fixed.body_id("upper").unwrap();
    let (got, want) = (
        with_fixed.inertia(upper).unwrap(),
        by_hand.inertia(upper).unwrap(),
    );
    for (g, w) in [
        (got.m, want.m),
        (got.hx, want.hx),
        (got.hy, want.hy),
        (got.i_o, want.i_o),
    ] {
        assert!((g - w).abs() <= 1e-12, "merged inertia {got:?} vs {want:?}");
    }
    assert!((with_fixed.total_mass() - (m1 + m2 + 0.6)).abs() <= 1e-12);

    let mut d1 = Data::new(&with_fixed);
    let mut d2 = Data::new(&by_hand);
    for q in [[0.0, 0.0], [0.4, -1.3], [2.5, 0.9], [-3.0, 3.0]] {
        let m_fixed = crba(&with_fixed, &mut d1, &q).unwrap().clone();
        let m_hand = crba(&by_hand, &mut d2, &q).unwrap().clone();
        for i in 0..2 {
            for j in 0..2 {
                assert!(
                    (m_fixed[(i, j)] - m_hand[(i, j)]).abs() <= 1e-12,
                    "q = {q:?}: M[{i},{j}] {} vs {}",
                    m_fixed[(i, j)],
                    m_hand[(i, j)]
                );
            }
        }
        let v = [0.7, -1.1];
        let a = [0.3, 0.2];
        let t1 = rnea(&with_fixed, &mut d1, &q, &v, &a).unwrap().clone();
        let t2 = rnea(&by_hand, &mut d2, &q, &v, &a).unwrap().clone();
        assert!((t1 - t2).amax() <= 1e-12);
    }
    // The merged body keeps its named frame on the host.
    let weight = with_fixed.frame_id("weight").unwrap();
    assert_eq!(with_fixed.frame(weight).body, upper);
    assert!(with_fixed.body_id("weight").is_err());
}

#[test]
fn fixed_joint_on_ground_places_its_moving_child() {
    let base_at = Placement::new(0.3, 1.0, 2.0);
    let arm_at = Placement::new(0.2, 0.5, -0.1);
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -9.81])
        .add_link(
            "base",
            None,
            FIXED,
            base_at,
            BodySpec::new(5.0, [0.0, 0.0], 1.0),
        )
        .add_link("arm", Some("base"), REV, arm_at, rod())
        .add_link(
            "slider",
            Some("arm"),
            JointKind::Prismatic { axis: [0.0, 2.0] },
            Placement::new(-0.5, 0.4, 0.0),
            rod(),
        );
    let model = b.build().unwrap();
    assert_eq!(model.nv(), 2);
    assert_eq!(model.nbodies(), 3);
    // The base's mass is carried by the ground, not by any moving body.
    assert!((model.total_mass() - 2.0).abs() <= 1e-15);

    let arm = model.body_id("arm").unwrap();
    let slider = model.body_id("slider").unwrap();
    assert_eq!(model.parent(arm), Some(mbs_core::BodyId::GROUND));
    let mut data = Data::new(&model);
    let x_base = Transform::new(base_at.angle, base_at.x, base_at.y);
    for q in [[0.0, 0.0], [0.9, 0.3], [-2.0, -1.0]] {
        update_poses(&model, &mut data, &q).unwrap();
        let want_arm = x_base.compose(&Transform::new(arm_at.angle + q[0], arm_at.x, arm_at.y));
        // The prismatic axis is normalised and lies in the slider's own joint frame.
        let want_slider = want_arm
            .compose(&Transform::new(-0.5, 0.4, 0.0))
            .compose(&Transform::new(0.0, 0.0, q[1]));
        for (got, want) in [
            (data.body_pose(arm), want_arm),
            (data.body_pose(slider), want_slider),
        ] {
            for (g, w) in [
                (got.c, want.c),
                (got.s, want.s),
                (got.x, want.x),
                (got.y, want.y),
            ] {
                assert!((g - w).abs() <= 1e-12, "q = {q:?}: {got:?} vs {want:?}");
            }
        }
        let base = frame_pose(&model, &data, model.frame_id("base").unwrap());
        assert_eq!(base, x_base);
    }
}

/// Regression: a body named "ground" used to be unfindable by `Model::body_id` because the
/// search met the ground's placeholder name first.
#[test]
fn a_body_named_ground_can_be_looked_up() {
    let mut b = ModelBuilder::new();
    b.add_link(
        "ground",
        None,
        JointKind::Revolute,
        Placement::default(),
        BodySpec::rod(1.0, 1.0),
    );
    let m = b.build().unwrap();
    assert_eq!(m.body_id("ground").unwrap().index(), 1);
}

#[test]
fn wrong_type_in_json_names_the_field_path() {
    let json = r#"{"gravity": [0.0, -9.81], "joints": [{"name": "a", "parent": null,
        "kind": "revolute", "placement": {"angle": 0.0, "x": 0.0, "y": 0.0},
        "body": {"mass": "heavy", "com": [0.0, 0.0], "inertia": 1.0}}]}"#;
    let e = Model::from_json_str(json).unwrap_err();
    assert!(e.to_string().contains("joints[0].body.mass"), "{e}");
}

#[test]
fn massless_frames_mark_points_without_changing_the_dynamics() {
    let build = |with_frames: bool| {
        let mut b = ModelBuilder::new();
        b.gravity([0.0, -9.81])
            .add_link(
                "arm",
                None,
                JointKind::Revolute,
                Placement::default(),
                BodySpec::rod(1.0, 1.0),
            )
            .add_link(
                "hand",
                Some("arm"),
                JointKind::Revolute,
                Placement::offset(1.0, 0.0),
                BodySpec::rod(0.5, 0.5),
            );
        if with_frames {
            b.add_frame("tip", Some("hand"), Placement::new(0.5, 0.5, 0.0))
                .add_frame("nail", Some("tip"), Placement::offset(0.1, 0.0))
                .add_frame("rail", None, Placement::offset(2.0, -1.0));
        }
        b.build().unwrap()
    };
    let (plain, marked) = (build(false), build(true));
    let q = [0.3, -0.8];
    let mut d1 = Data::new(&plain);
    let mut d2 = Data::new(&marked);
    assert_eq!(
        crba(&plain, &mut d1, &q).unwrap(),
        crba(&marked, &mut d2, &q).unwrap()
    );
    update_poses(&marked, &mut d2, &q).unwrap();
    // nail = hand ∘ (rotate 0.5 about (0.5, 0)) ∘ (0.1, 0)
    let nail = frame_pose(&marked, &d2, marked.frame_id("nail").unwrap());
    let hand = d2.body_pose(marked.body_id("hand").unwrap());
    let expect = hand.transform_point([0.5 + 0.1 * 0.5f64.cos(), 0.1 * 0.5f64.sin()]);
    assert!((nail.x - expect[0]).abs() < 1e-14 && (nail.y - expect[1]).abs() < 1e-14);
    assert!((nail.angle() - (hand.angle() + 0.5)).abs() < 1e-14);
    let rail = marked.frame(marked.frame_id("rail").unwrap());
    assert_eq!(rail.body, mbs_core::BodyId::GROUND);
    // Errors name the frame.
    let mut b = ModelBuilder::new();
    b.add_link(
        "arm",
        None,
        JointKind::Revolute,
        Placement::default(),
        BodySpec::rod(1.0, 1.0),
    );
    let e = b
        .clone()
        .add_frame("arm", None, Placement::default())
        .build()
        .unwrap_err();
    assert_eq!(
        e,
        CoreError::DuplicateName {
            what: "frame",
            name: "arm".into()
        }
    );
    let e = b
        .clone()
        .add_frame("tip", Some("leg"), Placement::default())
        .build()
        .unwrap_err();
    assert!(
        e.to_string().contains("frame 'tip'") && e.to_string().contains("leg"),
        "{e}"
    );
    let e = b
        .clone()
        .add_frame("tip", None, Placement::offset(f64::NAN, 0.0))
        .build()
        .unwrap_err();
    assert!(
        matches!(
            e,
            CoreError::NonFinite {
                field: "placement.x",
                ..
            }
        ),
        "{e:?}"
    );
}
