//! The interactive report: one self-contained page whose embedded data match the run.

use std::path::{Path, PathBuf};

use piano_action::ActionParams;
use piano_action::report::{report_html, write_report};
use piano_action::scenario::{Scenario, write_run_dir};

fn run_dir(name: &str, scenario: &str) -> PathBuf {
    let dir = std::env::temp_dir()
        .join(format!("piano-report-{}", std::process::id()))
        .join(name);
    let scenario = Scenario::from_toml_str(scenario).unwrap();
    let params = ActionParams::reference();
    let run = scenario.run(&params).unwrap();
    write_run_dir(&dir, &scenario, &params, &run).unwrap();
    dir
}

const STRUCK: &str = "model = \"double\"\nduration_s = 0.3\n[input]\nkind = \"touch\"\nstyle = \"struck\"\nfinger_speed_m_s = 0.8\n";

/// The JSON embedded in the page.
fn embedded(html: &str) -> serde_json::Value {
    let start = r#"<script type="application/json" id="report-data">"#;
    let a = html.find(start).unwrap() + start.len();
    let b = a + html[a..].find("</script>").unwrap();
    serde_json::from_str(&html[a..b].replace("<\\/", "</")).unwrap()
}

fn csv(dir: &Path, name: &str) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(dir.join(name)).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn the_report_embeds_the_run_and_nothing_from_the_network() {
    let dir = run_dir("struck", STRUCK);
    let html = report_html(std::slice::from_ref(&dir)).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>"));
    // Self-contained: no address of any kind, so no request can leave the page.
    for pattern in ["http://", "https://", "src=", "href=", "@import", "url("] {
        assert!(!html.contains(pattern), "the page contains {pattern}");
    }
    // A 0.3 s run at 1 ms stays well under 2 MB.
    assert!(html.len() < 2_000_000, "{} bytes", html.len());
    eprintln!("report of a 0.3 s run: {} kB", html.len() / 1000);

    let data = embedded(&html);
    let run = &data["runs"][0];
    let (header, rows) = csv(&dir, "trajectory.csv");
    let t = run["t"].as_array().unwrap();
    assert_eq!(t.len(), rows.len(), "one frame per trajectory row");
    // The hammer turns about its flange: its carried angle is its coordinate, and the
    // plotted angle is the same in degrees.
    let hq = header.iter().position(|h| h == "hammer_q").unwrap();
    let angle = run["carry"]["hammer"]["a"].as_array().unwrap();
    let plotted = run["series"]
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["id"] == "hammer_angle_deg")
        .unwrap()["values"]
        .as_array()
        .unwrap();
    for (i, row) in rows.iter().enumerate() {
        assert!(
            (angle[i].as_f64().unwrap() - row[hq]).abs() < 2e-6,
            "frame {i}"
        );
        assert!((plotted[i].as_f64().unwrap() - row[hq].to_degrees()).abs() < 1e-3);
    }
    // Events and summary are the run's own.
    let events: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("events.json")).unwrap()).unwrap();
    assert_eq!(run["events"], events);
    // The string force is on in the frames during the blow and off at rest, and agrees
    // with contacts.csv.
    let (ch, crow) = csv(&dir, "contacts.csv");
    let col = ch
        .iter()
        .position(|h| h == "hammer_string_force_n")
        .unwrap();
    let f = run["contacts"]["hammer_string"]["f"].as_array().unwrap();
    let peak = (0..f.len())
        .max_by(|&a, &b| f[a].as_f64().unwrap().total_cmp(&f[b].as_f64().unwrap()))
        .unwrap();
    assert!(f[peak].as_f64().unwrap() > 5.0, "string force {}", f[peak]);
    assert!(
        (f[peak].as_f64().unwrap() - crow[peak][col]).abs() < 1e-2,
        "report {} vs csv {}",
        f[peak],
        crow[peak][col]
    );
    assert_eq!(f[0].as_f64().unwrap(), 0.0);
    // The force acts on the hammer, pushing it down, at the string's height.
    let ny = run["contacts"]["hammer_string"]["ny"][peak]
        .as_f64()
        .unwrap();
    let py = run["contacts"]["hammer_string"]["py"][peak]
        .as_f64()
        .unwrap();
    assert!(ny < -0.99, "normal {ny}");
    let string_y = ActionParams::reference().regulation.string_y_mm;
    assert!((py - string_y).abs() < 1.0, "contact at y = {py} mm");
    // Zoom presets for the places where millimetres matter.
    for z in ["let-off", "jack and knuckle", "string", "backcheck"] {
        assert!(run["zoom"][z]["center"].is_array(), "zoom {z}");
    }
}

#[test]
fn several_runs_share_one_page_and_files_are_kept_safe() {
    let a = run_dir("struck-a", STRUCK);
    let b = run_dir(
        "single",
        "model = \"single\"\nduration_s = 0.1\n[input]\nkind = \"force\"\nforce_n = 10.0\n",
    );
    let out = a.parent().unwrap().join("both.html");
    write_report(&[a.clone(), b.clone()], &out, false).unwrap();
    let html = std::fs::read_to_string(&out).unwrap();
    let data = embedded(&html);
    assert_eq!(data["runs"].as_array().unwrap().len(), 2);
    assert_eq!(data["runs"][1]["model"], "single");
    assert!(data["runs"][1]["carry"].get("repetition_lever").is_none());
    // A report is replaced only when asked; any other file never.
    let e = write_report(std::slice::from_ref(&a), &out, false).unwrap_err();
    assert!(e.to_string().contains("--force"), "{e}");
    write_report(std::slice::from_ref(&a), &out, true).unwrap();
    let mine = a.parent().unwrap().join("notes.html");
    std::fs::write(&mine, "my notes").unwrap();
    let e = write_report(std::slice::from_ref(&a), &mine, true).unwrap_err();
    assert!(e.to_string().contains("not a piano report"), "{e}");
    assert_eq!(std::fs::read_to_string(&mine).unwrap(), "my notes");
}

#[test]
fn broken_run_directories_are_named() {
    let dir = run_dir("broken", STRUCK);
    let csv = dir.join("trajectory.csv");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[3] = "0.002,oops";
    std::fs::write(&csv, lines.join("\n")).unwrap();
    let e = report_html(std::slice::from_ref(&dir)).unwrap_err();
    assert!(e.to_string().contains("trajectory.csv line 4"), "{e}");
    let missing = dir.join("nothing-here");
    let e = report_html(&[missing]).unwrap_err();
    assert!(e.to_string().contains("run.json"), "{e}");
    assert!(matches!(
        report_html(&[]),
        Err(e) if e.field() == "RUN_DIR"
    ));
}

#[test]
fn measured_data_beside_a_run_are_embedded_for_overlay() {
    let dir = run_dir("measured", STRUCK);
    std::fs::write(
        dir.join("measured.csv"),
        "time_s,hammer_angle_deg,key_depth_mm\n0.0,0.1,\n0.01,2.5,1.0\n0.02,14.0,\n",
    )
    .unwrap();
    let data = embedded(&report_html(std::slice::from_ref(&dir)).unwrap());
    let m = &data["runs"][0]["measured"];
    assert_eq!(
        m["hammer_angle_deg"]["t"],
        serde_json::json!([0.0, 0.01, 0.02])
    );
    assert_eq!(
        m["hammer_angle_deg"]["v"],
        serde_json::json!([0.1, 2.5, 14.0])
    );
    // Empty cells are gaps.
    assert_eq!(m["key_depth_mm"]["t"], serde_json::json!([0.01]));
    // A column that is not a plotted quantity is refused by name.
    std::fs::write(
        dir.join("measured.csv"),
        "time_s,hammer_velocity\n0.0,1.0\n",
    )
    .unwrap();
    let e = report_html(std::slice::from_ref(&dir)).unwrap_err();
    assert!(
        e.to_string()
            .contains("column `hammer_velocity`: not a plotted quantity"),
        "{e}"
    );
    std::fs::write(dir.join("measured.csv"), "time_s,key_depth_mm\n0.0,deep\n").unwrap();
    let e = report_html(std::slice::from_ref(&dir)).unwrap_err();
    assert!(e.to_string().contains("measured.csv, line 2"), "{e}");
}

/// Events as `events.json` has them, from `(name, time in ms)`.
fn events(list: &[(&str, f64)]) -> Vec<serde_json::Value> {
    list.iter()
        .map(|(n, t)| serde_json::json!({"name": n, "time_s": t * 1e-3}))
        .collect()
}

fn names(listed: &[serde_json::Value]) -> Vec<String> {
    listed
        .iter()
        .map(|e| {
            format!(
                "{}@{}",
                e["name"].as_str().unwrap(),
                (e["time_s"].as_f64().unwrap() * 1e4).round() / 10.0
            )
        })
        .collect()
}

#[test]
fn a_let_off_is_listed_once_per_escapement_and_a_check_once_per_blow() {
    use piano_action::report::listed_events;
    // The struck forte touch's events: after the check the escaped jack's toe touches its
    // button again (41.5 and 51.3 ms) with no jack reset: chatter, not a let-off.
    let struck = events(&[
        ("finger_key", 0.4),
        ("let_off", 21.2),
        ("drop", 21.6),
        ("string_contact_start", 22.6),
        ("string_contact_end", 23.7),
        ("drop_release", 23.9),
        ("drop", 24.7),
        ("let_off_release", 25.9),
        ("check_catch", 27.8),
        ("check_release", 30.0),
        ("check_catch", 33.0),
        ("let_off", 41.5),
        ("let_off_release", 46.7),
        ("let_off", 51.3),
    ]);
    assert_eq!(
        names(&listed_events(&struck)),
        [
            "finger_key@0.4",
            "let_off@21.2",
            "drop@21.6",
            "string_contact_start@22.6",
            "string_contact_end@23.7",
            "check_catch@27.8"
        ]
    );
    // Repeated notes: once the jack is reset under the knuckle, the next let-off is a new
    // one, and the check after the second blow is a new check.
    let repeated = events(&[
        ("let_off", 31.1),
        ("string_contact_start", 31.5),
        ("check_catch", 39.0),
        ("let_off", 50.0),
        ("check_release", 237.2),
        ("jack_reset", 274.8),
        ("let_off", 375.1),
        ("string_contact_start", 378.2),
        ("check_catch", 387.3),
        ("let_off", 393.4),
    ]);
    assert_eq!(
        names(&listed_events(&repeated)),
        [
            "let_off@31.1",
            "string_contact_start@31.5",
            "check_catch@39",
            "jack_reset@274.8",
            "let_off@375.1",
            "string_contact_start@378.2",
            "check_catch@387.3"
        ]
    );
}

#[test]
fn the_page_lists_the_events_a_reader_should_see_and_keeps_them_all() {
    let dir = run_dir("struck-events", STRUCK);
    let data = embedded(&report_html(std::slice::from_ref(&dir)).unwrap());
    let run = &data["runs"][0];
    let all: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("events.json")).unwrap()).unwrap();
    assert_eq!(run["events"], all, "events.json is embedded whole");
    let listed = run["listed_events"].as_array().unwrap();
    let count =
        |list: &[serde_json::Value], name: &str| list.iter().filter(|e| e["name"] == name).count();
    let all = all.as_array().unwrap();
    assert!(count(all, "let_off") >= 1 && count(listed, "let_off") == 1);
    assert_eq!(
        count(listed, "string_contact_start"),
        count(all, "string_contact_start")
    );
}

#[test]
fn the_finger_on_key_arrow_pushes_the_key_down() {
    // Found in review: the arrow named "finger on key" showed the force on the finger (up).
    let dir = run_dir("finger-arrow", STRUCK);
    let data = embedded(&report_html(std::slice::from_ref(&dir)).unwrap());
    let c = &data["runs"][0]["contacts"]["presser_key"];
    let f: Vec<f64> = c["f"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let peak = (0..f.len()).max_by(|&a, &b| f[a].total_cmp(&f[b])).unwrap();
    assert!(f[peak] > 5.0, "the finger presses with {} N", f[peak]);
    let ny = c["ny"][peak].as_f64().unwrap();
    assert!(ny < -0.9, "finger-on-key arrow direction {ny}");
}

/// A run directory replays from its own files (poses, series, contact points, the scene):
/// the report's data are the same as when the action is rebuilt and settled again, as it
/// is for a run directory written before those files, for a touch, a key motion and a
/// dropped mass.
#[test]
fn a_run_replays_from_its_files_exactly_as_rebuilt() {
    let motion = "model = \"single\"\nduration_s = 0.12\n[input]\nkind = \"motion\"\npoints = [[0.0, 0.0], [0.04, 10.0], [0.12, 10.0]]\n";
    let drop = "model = \"double\"\nduration_s = 0.12\n[input]\nkind = \"mass_drop\"\nmass_kg = 1.0\nheight_m = 0.0\n";
    for (name, scenario) in [
        ("replay-struck", STRUCK),
        ("replay-motion", motion),
        ("replay-drop", drop),
    ] {
        let dir = run_dir(name, scenario);
        for file in ["poses.csv", "series.csv", "scene.json"] {
            assert!(dir.join(file).is_file(), "{name}: {file}");
        }
        let run: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("run.json")).unwrap()).unwrap();
        assert!(
            run["mechanism"]["bodies"].is_array(),
            "run.json keeps the description"
        );
        assert!(run["initial_state"].is_array(), "and the initial state");
        let from_files = embedded(&report_html(std::slice::from_ref(&dir)).unwrap());
        // An older run directory: no replay files, so the action is rebuilt and settled.
        std::fs::remove_file(dir.join("scene.json")).unwrap();
        let rebuilt = embedded(&report_html(std::slice::from_ref(&dir)).unwrap());
        assert_eq!(from_files, rebuilt, "{name}");
    }
}

/// The page's script knows no mechanism: every name, colour, plot and headline comes from
/// the data (`report::data`), so an upright, a glockenspiel or a bell striker is drawn by the
/// same code as the grand.
#[test]
fn the_report_script_names_no_part_of_a_piano() {
    let files = [
        ("player.js", include_str!("../src/report/player.js")),
        ("view2d.js", include_str!("../src/report/view2d.js")),
        ("view3d.js", include_str!("../src/report/view3d.js")),
        ("plots.js", include_str!("../src/report/plots.js")),
        ("clock.js", include_str!("../src/report/clock.js")),
    ];
    for (name, text) in files {
        let lower = text.to_lowercase();
        for word in [
            "hammer",
            "jack",
            "wippen",
            "knuckle",
            "capstan",
            "backcheck",
            "presser",
            "repetition",
            "let_off",
            "drop_screw",
        ] {
            assert!(!lower.contains(word), "{name} names '{word}'");
        }
    }
    // The typedef documents every field the Rust side writes.
    let player = files[0].1;
    for field in [
        "headline",
        "contact_colors",
        "plots",
        "minor_events",
        "listed_events",
        "measured",
    ] {
        assert!(
            player.contains(&format!("}} {field} ")),
            "the JSDoc typedef lacks {field}"
        );
    }
}
