//! The `piano` command as a user runs it.

mod common;
use common::piano;

#[test]
fn params_writes_the_default_file_and_params_loads_it_back() {
    let (ok, text, _) = piano(&["params"]);
    assert!(ok);
    let p = piano_action::ActionParams::from_toml_str(&text).unwrap();
    assert_eq!(p, piano_action::ActionParams::reference());
    // A broken copy is refused with the field named, and nothing runs.
    let dir = std::env::temp_dir().join(format!("piano-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, text.replace("mass_g = 11.74", "mass_g = 0.0")).unwrap();
    let (ok, _, err) = piano(&["--params", bad.to_str().unwrap(), "touchweight"]);
    assert!(!ok);
    assert!(err.contains("hammer.mass_g"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn touchweight_json_reports_the_four_weights() {
    let (ok, out, err) = piano(&["touchweight", "--json"]);
    assert!(ok, "{err}");
    for field in [
        "down_weight_gf",
        "up_weight_gf",
        "balance_weight_gf",
        "friction_weight_gf",
    ] {
        assert!(out.contains(field), "{out}");
    }
    let (ok, _, err) = piano(&["touchweight", "--model", "upright"]);
    assert!(!ok && err.contains("unknown model 'upright'"), "{err}");
}

#[test]
fn simulate_writes_a_run_directory_with_the_summary() {
    let dir = std::env::temp_dir().join(format!("piano-sim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = dir.join("loud.toml");
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.08\n[input]\nkind = \"force\"\nforce_n = 20.0\n",
    )
    .unwrap();
    let out = dir.join("run");
    let (ok, stdout, err) = piano(&[
        "simulate",
        scenario.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("strike at"), "{stdout}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let strikes = summary["strikes"].as_array().unwrap();
    assert!(!strikes.is_empty());
    let v = strikes[0]["hammer_velocity_m_s"].as_f64().unwrap();
    assert!((4.0..7.0).contains(&v), "loud strike at {v} m/s");
    assert!(summary["let_off_time_s"].as_f64().unwrap() < strikes[0]["time_s"].as_f64().unwrap());
    assert!(summary["events"].as_array().unwrap().len() >= 4);
    let csv = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert!(
        csv.starts_with("time_s,key_q,wippen_q,jack_q,repetition_lever_q,hammer_q,key_v"),
        "{}",
        &csv[..80]
    );
    assert_eq!(csv.lines().count(), 1 + 81, "header and 81 grid rows");
    assert!(out.join("run.json").exists() && out.join("events.json").exists());
    // Gaps and forces of every contact on the same grid; the string's force is up during
    // the blow and zero at rest.
    let contacts = std::fs::read_to_string(out.join("contacts.csv")).unwrap();
    let header: Vec<&str> = contacts.lines().next().unwrap().split(',').collect();
    assert_eq!(contacts.lines().count(), 1 + 81);
    let col = header
        .iter()
        .position(|h| *h == "hammer_string_force_n")
        .unwrap();
    let peak = contacts
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(col).unwrap().parse::<f64>().unwrap())
        .fold(0.0, f64::max);
    assert!(peak > 10.0, "string force peaks at {peak} N on the grid");
    // The drawings, with the string contact marked in its own.
    for name in ["rest", "let_off", "string_contact", "check"] {
        let svg = std::fs::read_to_string(out.join(format!("drawing_{name}.svg"))).unwrap();
        assert!(
            svg.starts_with("<svg") || svg.starts_with("<?xml"),
            "{name}"
        );
        assert_eq!(
            svg.contains("active-hammer_string"),
            name == "string_contact",
            "{name}"
        );
    }
    // A key-motion scenario: a quick 10 mm press in 20 ms strikes, and the hand's force is
    // in the trajectory.
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.06\n[input]\nkind = \"motion\"\npoints = [[0.0, 0.0], [0.02, 10.0]]\n",
    )
    .unwrap();
    let moved = dir.join("moved");
    let (ok, stdout, err) = piano(&[
        "simulate",
        scenario.to_str().unwrap(),
        "--out",
        moved.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("strike at"), "{stdout}");
    let csv = std::fs::read_to_string(moved.join("trajectory.csv")).unwrap();
    assert!(csv.lines().next().unwrap().ends_with(",key_drive_force_n"));
    // Times that go backwards are refused, naming the field.
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.06\n[input]\nkind = \"motion\"\npoints = [[0.02, 0.0], [0.01, 10.0]]\n",
    )
    .unwrap();
    let (ok, _, err) = piano(&[
        "simulate",
        scenario.to_str().unwrap(),
        "--out",
        moved.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("input.points"), "{err}");
    // A bad scenario names the field.
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.08\n[input]\nkind = \"force\"\nforce = 20.0\n",
    )
    .unwrap();
    let (ok, _, err) = piano(&[
        "simulate",
        scenario.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("input"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn regulate_json_reports_the_six_measurements_in_band_and_writes_the_file() {
    let dir = std::env::temp_dir().join(format!("piano-regulate-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("regulated.toml");
    let (ok, out, err) = piano(&[
        "regulate",
        "--json",
        "--model",
        "single",
        "--write",
        file.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let band = |name: &str, lo: f64, hi: f64| {
        let x = v[name].as_f64().unwrap_or(f64::NAN);
        assert!((lo..=hi).contains(&x), "{name} = {x}");
    };
    band("key_dip_mm", 9.5, 11.0);
    band("blow_distance_mm", 44.0, 48.0);
    band("let_off_mm", 1.5, 2.5);
    band("check_mm", 12.0, 16.0);
    band("aftertouch_mm", 0.5, 1.5);
    // The single action has no repetition lever, hence no drop.
    assert!(v["drop_mm"].is_null());
    // The written file loads, and a second run refuses to overwrite it.
    let text = std::fs::read_to_string(&file).unwrap();
    piano_action::ActionParams::from_toml_str(&text).unwrap();
    let (ok, _, err) = piano(&["regulate", "--write", file.to_str().unwrap()]);
    assert!(!ok && err.contains("exists"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_pendulum_scenario_writes_the_swing_and_its_period() {
    let dir = std::env::temp_dir().join(format!("piano-swing-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = dir.join("swing.toml");
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 3.0\n[input]\nkind = \"pendulum\"\nrelease_angle_deg = 30.0\n",
    )
    .unwrap();
    let out = dir.join("run");
    let (ok, stdout, err) = piano(&[
        "simulate",
        scenario.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("turning points"), "{stdout}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(summary["strikes"].as_array().unwrap().is_empty());
    let p = &summary["pendulum"];
    let (period, small) = (
        p["period_s"].as_f64().unwrap(),
        p["small_amplitude_period_s"].as_f64().unwrap(),
    );
    // From 30° the period exceeds the small-swing one by 1.7 % (less as friction shrinks the
    // swing; at 5° the flange friction would hold the hammer still). The hammer's inertia
    // and centre of mass give 0.715 s for small swings (literature file).
    assert!(
        (1.0..1.025).contains(&(period / small)),
        "{period} vs {small}"
    );
    assert!((small - 0.715).abs() < 0.005, "{small}");
    // Coulomb flange friction takes about 10° off each half swing: three turns from 30°.
    let turns = p["turns"].as_array().unwrap();
    assert!((2..=4).contains(&turns.len()), "{turns:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_pendulum_scenario_is_viewable_as_report_plot_and_drawings() {
    let dir = std::env::temp_dir().join(format!("piano-swing-view-{}", std::process::id()));
    let out = dir.join("run");
    let scenario = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/pendulum.toml");
    let (ok, _, err) = piano(&["simulate", scenario, "--out", out.to_str().unwrap()]);
    assert!(ok, "{err}");
    let read = |name: &str| std::fs::read_to_string(out.join(name)).unwrap();

    // The trajectory: time, angle from hanging (rad), rate (rad/s), starting at the release.
    let text = read("trajectory.csv");
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("time_s,hammer_q,hammer_v"));
    let rows: Vec<[f64; 3]> = lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect();
    assert!(rows.len() > 2000, "{} rows", rows.len());
    assert_eq!(rows[0][0], 0.0);
    assert!(
        (rows[0][1] - 30f64.to_radians()).abs() < 1e-12,
        "{:?}",
        rows[0]
    );
    assert_eq!(rows[0][2], 0.0);

    // The turning points of events.json are the summary's, and the sampled swing turns
    // there: no sample within 20 ms of one lies beyond its angle.
    let events: serde_json::Value = serde_json::from_str(&read("events.json")).unwrap();
    let summary: serde_json::Value = serde_json::from_str(&read("summary.json")).unwrap();
    let turns = summary["pendulum"]["turns"].as_array().unwrap();
    let events = events.as_array().unwrap();
    assert!(turns.len() >= 2 && events.len() == turns.len());
    for (e, turn) in events.iter().zip(turns) {
        assert_eq!(e["name"], "turn");
        let t = e["time_s"].as_f64().unwrap();
        assert_eq!(Some(t), turn["time_s"].as_f64());
        let angle = turn["angle_deg"].as_f64().unwrap().to_radians();
        let near: Vec<&[f64; 3]> = rows.iter().filter(|r| (r[0] - t).abs() <= 0.02).collect();
        // A low turn (the swing came down to it) or a high one.
        let low = rows.iter().find(|r| r[0] >= t - 0.05).unwrap()[1] > angle;
        for r in near {
            let beyond = if low { angle - r[1] } else { r[1] - angle };
            assert!(beyond < 1e-6, "turn at {t} s, {angle} rad: sample {r:?}");
        }
    }

    // Drawings: the hammer on its flange at the release and at the first turning point.
    for name in ["drawing_release.svg", "drawing_turn.svg"] {
        assert!(read(name).contains(r#"id="body-hammer""#), "{name}");
    }

    // The report and the figure work on it, and show the swing.
    let (ok, stdout, err) = piano(&["report", out.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(stdout.contains("report.html"), "{stdout}");
    let html = read("report.html");
    assert!(html.contains("hammer angle from hanging"));
    let (ok, _, err) = piano(&["plot", out.to_str().unwrap()]);
    if !ok {
        // Without any font on the machine the error says how to give one.
        assert!(err.contains("--font"), "{err}");
    } else {
        let figure = read("figure.svg");
        assert!(figure.contains("Hammer angle from hanging (deg)"));
        assert_eq!(
            figure.matches(">\nturn\n<").count(),
            turns.len(),
            "a mark per turn"
        );
        // What a pendulum does not have is not plotted.
        assert!(!figure.contains("Key-front depth") && !figure.contains("Contact forces"));
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn simulate_runs_finger_touches_and_names_what_is_missing() {
    let dir = std::env::temp_dir().join(format!("piano-touch-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = dir.join("touch.toml");
    let run = |text: &str, out: &str| {
        std::fs::write(&scenario, text).unwrap();
        piano(&[
            "simulate",
            scenario.to_str().unwrap(),
            "--out",
            dir.join(out).to_str().unwrap(),
        ])
    };
    let summary = |out: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("summary.json")).unwrap())
            .unwrap()
    };
    let head = "model = \"double\"\nduration_s = 0.1\n[input]\nkind = \"touch\"\n";
    let (ok, _, err) = run(
        &format!("{head}style = \"struck\"\nfinger_speed_m_s = 0.8\n"),
        "struck",
    );
    assert!(ok, "{err}");
    let s = summary("struck");
    let names: Vec<&str> = s["events"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["name"].as_str().unwrap())
        .collect();
    assert_eq!(names[..2], ["finger_key", "key_start"], "{names:?}");
    let travel = s["travel_time_s"].as_f64().unwrap();
    let strike = s["strikes"][0]["time_s"].as_f64().unwrap();
    let start = s["key_start_time_s"].as_f64().unwrap();
    assert!((travel - (strike - start)).abs() < 1e-12);
    assert!(s["key_bottom_minus_string_contact_s"].as_f64().is_some());
    // A heavier finger, pressed.
    let (ok, _, err) = run(
        &format!("{head}style = \"pressed\"\npeak_force_n = 10.0\nfinger_mass_g = 40.0\n"),
        "pressed",
    );
    assert!(ok, "{err}");
    let v = summary("pressed")["strikes"][0]["hammer_velocity_m_s"]
        .as_f64()
        .unwrap();
    assert!((2.0..6.0).contains(&v), "pressed 10 N gives {v} m/s");
    // Missing, misplaced and misspelt fields are named.
    for (body, field) in [
        ("style = \"struck\"\n", "input.finger_speed_m_s"),
        (
            "style = \"pressed\"\npeak_force_n = 2.0\nfinger_speed_m_s = 1.0\n",
            "input.finger_speed_m_s",
        ),
        ("style = \"tapped\"\npeak_force_n = 2.0\n", "input"),
        (
            "style = \"pressed\"\npeak_force_n = 2.0\nrise_s = 0.0\n",
            "input.rise_s",
        ),
    ] {
        let (ok, _, err) = run(&format!("{head}{body}"), "bad");
        assert!(!ok && err.contains(field), "{body}: {err}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn sweep_writes_one_row_per_run_and_keeps_existing_files() {
    let dir = std::env::temp_dir().join(format!("piano-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join("sweep.csv");
    let args = [
        "sweep",
        "--touch",
        "pressed",
        "--from",
        "1",
        "--to",
        "30",
        "--runs",
        "4",
        "--duration",
        "0.2",
        "--out",
    ];
    let (ok, stdout, err) = piano(&[&args[..], &[out.to_str().unwrap()]].concat());
    assert!(ok, "{err}");
    assert!(stdout.contains("4 pressed runs"), "{stdout}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().count(), 5, "{text}");
    // A second sweep to the same file is refused and the first file is kept.
    let (ok, _, err) = piano(&[&args[..], &[out.to_str().unwrap()]].concat());
    assert!(!ok && err.contains("exists"), "{err}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), text);
    let (ok, _, err) = piano(&["sweep", "--touch", "slapped", "--out", "x.csv"]);
    assert!(!ok && err.contains("--touch"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn report_and_plot_write_their_files_and_keep_yours() {
    let dir = std::env::temp_dir().join(format!("piano-report-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = dir.join("s.toml");
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.05\n[input]\nkind = \"force\"\nforce_n = 20.0\n",
    )
    .unwrap();
    let run = dir.join("run");
    let (ok, out, err) = piano(&[
        "simulate",
        scenario.to_str().unwrap(),
        "--out",
        run.to_str().unwrap(),
        "--report",
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("report: ") && run.join("report.html").exists(),
        "{out}"
    );
    let other = dir.join("mine.html");
    std::fs::write(&other, "mine").unwrap();
    let (ok, _, err) = piano(&[
        "report",
        run.to_str().unwrap(),
        "--out",
        other.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("not a piano report"), "{err}");
    assert_eq!(std::fs::read_to_string(&other).unwrap(), "mine");
    // A figure is written only to a file named for its format, and never over yours.
    let (ok, _, err) = piano(&[
        "plot",
        run.to_str().unwrap(),
        "--out",
        other.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("must end in .svg"), "{err}");
    assert_eq!(std::fs::read_to_string(&other).unwrap(), "mine");
    let mine_svg = dir.join("mine.svg");
    std::fs::write(&mine_svg, "mine").unwrap();
    let (ok, _, err) = piano(&[
        "plot",
        run.to_str().unwrap(),
        "--out",
        mine_svg.to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("exists"), "{err}");
    assert_eq!(std::fs::read_to_string(&mine_svg).unwrap(), "mine");
    let (ok, out, err) = piano(&["plot", run.to_str().unwrap(), "--format", "png"]);
    if ok {
        assert!(run.join("figure.png").exists(), "{out}");
    } else {
        assert!(err.contains("--font"), "{err}");
    }
    let (ok, _, err) = piano(&["plot", run.to_str().unwrap(), "--format", "gif"]);
    assert!(!ok && err.contains("--format"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_demo_prints_its_table_and_writes_a_report() {
    let (ok, out, err) = piano(&[]);
    assert!(ok, "{err}");
    assert!(
        out.contains("pressed 10 N") && out.contains("struck 0.80 m/s"),
        "{out}"
    );
    let path = out
        .lines()
        .find_map(|l| l.strip_prefix("report: "))
        .expect("the demo prints the report's path");
    let html = std::fs::read_to_string(path).unwrap();
    assert!(html.contains(r#"id="report-data""#));
    assert!(html.contains("pressed touch 10 N") && html.contains("struck touch 0.8 m/s"));
}

#[test]
fn simulate_wav_writes_the_blow_as_sound_and_keeps_existing_files() {
    let dir = std::env::temp_dir().join(format!("piano-wav-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scenario = dir.join("loud.toml");
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.06\n[input]\nkind = \"force\"\nforce_n = 20.0\n",
    )
    .unwrap();
    let wav = dir.join("loud.wav");
    let sim = |out: &str, wav: &std::path::Path, force: bool| {
        let out = dir.join(out);
        let mut args = vec![
            "simulate",
            scenario.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--wav",
            wav.to_str().unwrap(),
        ];
        if force {
            args.push("--force");
        }
        piano(&args)
    };
    let (ok, stdout, err) = sim("a", &wav, false);
    assert!(ok, "{err}");
    assert!(
        stdout.contains("sound: ") && stdout.contains("bridge force peak"),
        "{stdout}"
    );
    // Two seconds at 48 kHz, 16 bit: 44 header bytes and 192 000 of samples.
    assert_eq!(std::fs::metadata(&wav).unwrap().len(), 44 + 192_000);
    // An existing file is refused before the run (no run directory is written) ...
    let (ok, _, err) = sim("b", &wav, false);
    assert!(
        !ok && err.contains("exists") && err.contains("--wav"),
        "{err}"
    );
    assert!(!dir.join("b").exists());
    // ... and replaced with --force.
    let (ok, _, err) = sim("c", &wav, true);
    assert!(ok, "{err}");
    // Another extension, and the swing test (no string), are refused.
    let (ok, _, err) = sim("d", &dir.join("loud.mp3"), false);
    assert!(
        !ok && err.contains("option --wav") && err.contains(".wav"),
        "{err}"
    );
    let swing = dir.join("swing.toml");
    std::fs::write(
        &swing,
        "model = \"double\"\nduration_s = 0.5\n[input]\nkind = \"pendulum\"\nrelease_angle_deg = 30.0\n",
    )
    .unwrap();
    let out = dir.join("e");
    let (ok, _, err) = piano(&[
        "simulate",
        swing.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--wav",
        dir.join("swing.wav").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("no string"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}
