//! The grand actions as mechanism descriptions: `piano describe` writes a file that builds
//! and simulates bit for bit like the built-in model.

mod common;
use common::piano;

use mbs_core::time_function::Constant;
use mbs_mechanism::Mechanism;
use piano_action::describe::grand_mechanism;
use piano_action::identify::effects::EffectEntry;
use piano_action::{Action, ActionParams, ModelKind, Presser};

/// The state after 60 ms of a 10 N press, from the action built in code and from its
/// description read back from `text`.
fn press_both(
    params: &ActionParams,
    kind: ModelKind,
    presser: Option<Presser>,
    text: &str,
) -> (Vec<f64>, Vec<f64>, usize) {
    let run = |mut action: Action| {
        action.add_key_force(Constant(10.0)).unwrap();
        let x0 = action.layout_state().unwrap();
        let sol = action.integrate(&x0, 0.06, f64::INFINITY, None).unwrap();
        (sol.y, sol.events.len())
    };
    let (direct, events) = run(Action::build_with(params, kind, presser).unwrap());
    let mechanism = Mechanism::from_toml_str(text).unwrap();
    let (described, events_back) =
        run(Action::from_mechanism(params, kind, presser, &mechanism).unwrap());
    assert_eq!(events, events_back, "{kind:?}: the same events");
    (direct, described, events)
}

#[test]
fn every_grand_model_read_back_from_its_description_runs_bit_identically() {
    let params = ActionParams::reference();
    for kind in ModelKind::ALL {
        let m = grand_mechanism(&params, kind, None).unwrap();
        let text = m.to_toml_string().unwrap();
        assert_eq!(Mechanism::from_toml_str(&text).unwrap(), m, "{kind:?}");
        let json = m.to_json_string().unwrap();
        assert_eq!(Mechanism::from_json_str(&json).unwrap(), m, "{kind:?}");
        let (direct, described, events) = press_both(&params, kind, None, &text);
        assert!(events > 3, "{kind:?}: a press with events");
        assert!(
            direct
                .iter()
                .zip(&described)
                .all(|(a, b)| a.to_bits() == b.to_bits()),
            "{kind:?}: every state bit for bit"
        );
        assert_eq!(direct.len(), described.len());
    }
}

#[test]
fn a_described_action_keeps_its_presser_and_flange_effects() {
    let mut params = ActionParams::reference();
    params.effects = vec![EffectEntry {
        id: "pivot_viscous".into(),
        location: "hammer_flange".into(),
        params: [("c_n_m_s".to_string(), 4e-5)].into_iter().collect(),
    }];
    let finger = Presser {
        carried: true,
        ..Presser::weight(0.01, 0.0)
    };
    let m = grand_mechanism(&params, ModelKind::Double, Some(finger)).unwrap();
    assert!(m.bodies.iter().any(|b| b.name == "presser"));
    assert_eq!(m.loads.len(), 1, "the arm carries the finger");
    assert_eq!(m.extensions.len(), 1);
    let text = m.to_toml_string().unwrap();
    let (direct, described, _) = press_both(&params, ModelKind::Double, Some(finger), &text);
    assert!(
        direct
            .iter()
            .zip(&described)
            .all(|(a, b)| a.to_bits() == b.to_bits())
    );
    // An unknown effect in a hand-edited file names the extension.
    let bad = text.replace("name = \"pivot_viscous\"", "name = \"pivot_magic\"");
    let e = Action::from_mechanism(
        &params,
        ModelKind::Double,
        Some(finger),
        &Mechanism::from_toml_str(&bad).unwrap(),
    )
    .err()
    .expect("refused");
    assert!(e.to_string().contains("extensions[0]"), "{e}");
    assert!(e.to_string().contains("pivot_magic"), "{e}");
}

#[test]
fn piano_describe_writes_a_commented_description() {
    let (ok, text, err) = piano(&["describe", "--model", "single"]);
    assert!(ok, "{err}");
    assert!(text.starts_with("# Mechanism description: grand action, single model"));
    assert!(text.contains("# Contact pairs:"), "{text}");
    let m = Mechanism::from_toml_str(&text).unwrap();
    m.validate().unwrap();
    assert_eq!(
        m,
        piano_action::describe::grand_description(&ActionParams::reference(), ModelKind::Single)
            .unwrap()
    );
    // The physics is grand_mechanism's; the drawing's outlines, events and metrics are added.
    let mut physics = m.clone();
    physics.ground.clear();
    physics.events.clear();
    physics.metrics.clear();
    for b in &mut physics.bodies {
        assert!(!b.outline.is_empty(), "{} has an outline", b.name);
        b.outline.clear();
    }
    assert_eq!(
        physics,
        grand_mechanism(&ActionParams::reference(), ModelKind::Single, None).unwrap()
    );
    assert!(m.contacts.iter().any(|c| c.name == "let_off_button"));
    assert!(!m.bodies.iter().any(|b| b.name == "repetition_lever"));

    let (ok, json, err) = piano(&["describe", "--json"]);
    assert!(ok, "{err}");
    let m = Mechanism::from_json_str(&json).unwrap();
    assert!(m.bodies.iter().any(|b| b.name == "repetition_lever"));

    // --out never replaces a file without --force.
    let dir = std::env::temp_dir().join(format!("piano-describe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("grand.toml");
    std::fs::write(&out, "mine").unwrap();
    let (ok, _, err) = piano(&["describe", "--out", out.to_str().unwrap()]);
    assert!(!ok && err.contains("--force"), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "mine");
    let (ok, _, err) = piano(&["describe", "--out", out.to_str().unwrap(), "--force"]);
    assert!(ok, "{err}");
    assert!(Mechanism::load(&out).is_ok());
    std::fs::remove_dir_all(&dir).ok();
}

/// A scenario file in `dir`.
fn scenario(dir: &std::path::Path, name: &str, head: &str, input: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!("{head}\nduration_s = 0.06\noutput_step_s = 5e-4\n[input]\n{input}\n"),
    )
    .unwrap();
    path
}

#[test]
fn a_scenario_runs_a_description_file_like_the_built_in_model() {
    let dir = std::env::temp_dir().join(format!("piano-mechanism-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let grand_file = dir.join("grand.toml");
    let (ok, _, err) = piano(&["describe", "--out", grand_file.to_str().unwrap()]);
    assert!(ok, "{err}");
    let force = "kind = \"force\"\nforce_n = 12.0";
    let by_file = scenario(&dir, "file.toml", "mechanism = \"grand.toml\"", force);
    let by_model = scenario(&dir, "model.toml", "model = \"double\"", force);
    let (a, b) = (dir.join("run_file"), dir.join("run_model"));
    let (ok, out, err) = piano(&[
        "simulate",
        by_file.to_str().unwrap(),
        "--out",
        a.to_str().unwrap(),
        "--report",
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("strike"), "{out}");
    let (ok, _, err) = piano(&[
        "simulate",
        by_model.to_str().unwrap(),
        "--out",
        b.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    // The same trajectory, bit for bit (the numbers are printed to the last digit).
    for file in ["trajectory.csv", "internal_states.csv"] {
        assert_eq!(
            std::fs::read_to_string(a.join(file)).unwrap(),
            std::fs::read_to_string(b.join(file)).unwrap(),
            "{file}"
        );
    }
    // The description's events and metrics agree with the grand analysis.
    let read = |p: std::path::PathBuf| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
    };
    let grand = read(b.join("summary.json"));
    let described = read(a.join("summary.json"));
    let strike = &grand["strikes"][0];
    let metric = |name: &str| {
        described["metrics"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["name"] == name)
            .and_then(|m| m["value"].as_f64())
            .unwrap()
    };
    assert_eq!(metric("strike time"), strike["time_s"].as_f64().unwrap());
    let (v_file, v_grand) = (
        metric("hammer speed at the strike"),
        strike["hammer_velocity_m_s"].as_f64().unwrap(),
    );
    assert!(
        (v_file - v_grand).abs() < 1e-12 * v_grand,
        "{v_file} vs {v_grand}"
    );
    assert_eq!(
        metric("let-off time"),
        grand["let_off_time_s"].as_f64().unwrap()
    );
    // Self-contained: the description, poses and contact outputs are in the folder, and
    // the drawings at the named events exist.
    let run = read(a.join("run.json"));
    assert_eq!(run["mechanism"]["name"], "grand action, double model");
    for file in [
        "poses.csv",
        "series.csv",
        "contacts.csv",
        "drawing_rest.svg",
        "drawing_strike.svg",
        "drawing_check.svg",
        "report.html",
    ] {
        assert!(a.join(file).is_file(), "{file}");
    }
    let svg = std::fs::read_to_string(a.join("drawing_strike.svg")).unwrap();
    assert!(svg.contains("id=\"body-hammer\"") && svg.contains("id=\"active-hammer_string\""));
    let html = std::fs::read_to_string(a.join("report.html")).unwrap();
    assert!(html.contains("hammer speed at the strike"));
    // The figure plots the description's own series.
    let (ok, _, err) = piano(&["plot", a.to_str().unwrap()]);
    assert!(ok, "{err}");
    let figure = std::fs::read_to_string(a.join("figure.svg")).unwrap();
    assert!(figure.contains("Hammer angle (deg)") && figure.contains("Jack angle (deg)"));
    // A sweep of the description: the metrics per force, the hammer faster when pushed
    // harder.
    let table = dir.join("sweep.csv");
    let (ok, _, err) = piano(&[
        "sweep",
        "--mechanism",
        grand_file.to_str().unwrap(),
        "--touch",
        "force",
        "--from",
        "4",
        "--to",
        "20",
        "--runs",
        "3",
        "--duration",
        "0.08",
        "--out",
        table.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let csv = std::fs::read_to_string(&table).unwrap();
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let col = header
        .iter()
        .position(|h| *h == "hammer speed at the strike (m/s)")
        .unwrap();
    let speeds: Vec<f64> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect();
    assert_eq!(speeds.len(), 3);
    assert!(speeds[0] < speeds[1] && speeds[1] < speeds[2], "{speeds:?}");
    let (ok, _, err) = piano(&[
        "sweep",
        "--mechanism",
        grand_file.to_str().unwrap(),
        "--touch",
        "struck",
        "--out",
        dir.join("no.csv").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("--touch force"), "{err}");
    // The report replays the run from its files: it reads again after the description
    // file is gone.
    std::fs::remove_file(&grand_file).unwrap();
    let (ok, _, err) = piano(&["report", a.to_str().unwrap(), "--force"]);
    assert!(ok, "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn mechanism_scenarios_refuse_what_they_cannot_run() {
    let dir = std::env::temp_dir().join(format!("piano-mechanism-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let force = "kind = \"force\"\nforce_n = 5.0";
    let run = |path: &std::path::Path| {
        let (ok, _, err) = piano(&[
            "simulate",
            path.to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
        ]);
        assert!(!ok);
        err
    };
    let err = run(&scenario(
        &dir,
        "both.toml",
        "model = \"double\"\nmechanism = \"m.toml\"",
        force,
    ));
    assert!(
        err.contains("field `model`") && err.contains("not both"),
        "{err}"
    );
    let err = run(&scenario(
        &dir,
        "missing.toml",
        "mechanism = \"nowhere.toml\"",
        force,
    ));
    assert!(
        err.contains("field `mechanism`") && err.contains("nowhere.toml"),
        "{err}"
    );
    let touch = "kind = \"touch\"\nstyle = \"struck\"\nfinger_speed_m_s = 1.0";
    let err = run(&scenario(
        &dir,
        "touch.toml",
        "mechanism = \"m.toml\"",
        touch,
    ));
    assert!(err.contains("input.kind"), "{err}");
    let err = run(&scenario(
        &dir,
        "settle.toml",
        "model = \"double\"\nsettle_s = 0.1",
        force,
    ));
    assert!(err.contains("settle_s"), "{err}");
    // A broken description: its own file, line and field.
    std::fs::write(
        dir.join("m.toml"),
        "name = \"m\"\ngravity = [0.0, -9.81]\n[[bodies]]\nname = \"a\"\nmass = -1.0\n\
         com = [0.0, 0.0]\ninertia = 1e-4\njoint = { kind = \"revolute\", at = [0.0, 0.0] }\n",
    )
    .unwrap();
    let err = run(&scenario(
        &dir,
        "broken.toml",
        "mechanism = \"m.toml\"",
        force,
    ));
    assert!(
        err.contains("m.toml:5") && err.contains("bodies[0].mass"),
        "{err}"
    );
    // A description without a force input.
    std::fs::write(
        dir.join("m.toml"),
        "name = \"m\"\ngravity = [0.0, -9.81]\n[[bodies]]\nname = \"a\"\nmass = 1.0\n\
         com = [0.0, 0.0]\ninertia = 1e-4\njoint = { kind = \"revolute\", at = [0.0, 0.0] }\n",
    )
    .unwrap();
    let err = run(&scenario(
        &dir,
        "noinput.toml",
        "mechanism = \"m.toml\"",
        force,
    ));
    assert!(err.contains("no force input"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The example descriptions (a hand-written glockenspiel, the upright written by
/// `examples/upright`) go through the same commands as the grand: `piano simulate` with
/// their drawings at the named events, `piano report`, `piano plot` and `piano sweep`, the
/// metric rising with the force.
#[test]
fn the_example_descriptions_simulate_draw_report_plot_and_sweep() {
    let examples =
        std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/mechanisms");
    let dir = std::env::temp_dir().join(format!("piano-examples-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (file, force, metric, drawings) in [
        (
            "glockenspiel.toml",
            [2.0, 6.0, 12.0],
            "head speed at the strike",
            ["drawing_rest.svg", "drawing_strike.svg"],
        ),
        (
            "upright.toml",
            [4.0, 10.0, 25.0],
            "hammer speed at the strike",
            ["drawing_rest.svg", "drawing_escape.svg"],
        ),
    ] {
        let path = examples.join(file);
        let name = file.trim_end_matches(".toml");
        let head = format!("mechanism = {:?}", path.to_str().unwrap());
        let sc = scenario(
            &dir,
            &format!("{name}_scenario.toml"),
            &head,
            &format!("kind = \"force\"\nforce_n = {}", force[1]),
        );
        let out = dir.join(name);
        let (ok, text, err) = piano(&[
            "simulate",
            sc.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--report",
        ]);
        assert!(ok, "{file}: {err}");
        assert!(text.contains("strike"), "{file}: {text}");
        for f in drawings.iter().chain(&["report.html", "run.json"]) {
            assert!(out.join(f).is_file(), "{file}: {f}");
        }
        let (ok, _, err) = piano(&["plot", out.to_str().unwrap()]);
        assert!(ok, "{file}: {err}");
        assert!(out.join("figure.svg").is_file());
        let table = dir.join(format!("{name}_sweep.csv"));
        let (ok, _, err) = piano(&[
            "sweep",
            "--mechanism",
            path.to_str().unwrap(),
            "--touch",
            "force",
            "--from",
            &force[0].to_string(),
            "--to",
            &force[2].to_string(),
            "--runs",
            "3",
            "--duration",
            "0.1",
            "--out",
            table.to_str().unwrap(),
        ]);
        assert!(ok, "{file}: {err}");
        let csv = std::fs::read_to_string(&table).unwrap();
        let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
        let col = header
            .iter()
            .position(|h| h.starts_with(metric))
            .unwrap_or_else(|| panic!("{file}: no '{metric}' in {header:?}"));
        let speeds: Vec<f64> = csv
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
            .collect();
        assert_eq!(speeds.len(), 3, "{file}");
        assert!(
            speeds[0] < speeds[1] && speeds[1] < speeds[2],
            "{file}: {speeds:?}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
