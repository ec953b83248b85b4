//! What a new user hits in the first hour (issue 11): files are never overwritten without
//! `--force`, absurd durations are refused before anything runs, and every error names what
//! it is about (the parameter file, the scenario, a CSV, an option), the file, the line and
//! the field.

use std::path::{Path, PathBuf};

mod common;
use common::piano;

/// A fresh folder for one test.
fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("piano-first-{name}-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

const LOUD: &str =
    "model = \"double\"\nduration_s = 0.05\n[input]\nkind = \"force\"\nforce_n = 20.0\n";
const SOFT: &str =
    "model = \"double\"\nduration_s = 0.03\n[input]\nkind = \"force\"\nforce_n = 2.0\n";

#[test]
fn simulate_into_an_earlier_run_is_refused_and_force_replaces_only_run_files() {
    let dir = folder("rerun");
    let (loud, soft) = (dir.join("loud.toml"), dir.join("soft.toml"));
    std::fs::write(&loud, LOUD).unwrap();
    std::fs::write(&soft, SOFT).unwrap();
    let run = dir.join("run");
    let (ok, _, err) = piano(&["simulate", s(&loud), "--out", s(&run)]);
    assert!(ok, "{err}");
    let first = std::fs::read_to_string(run.join("trajectory.csv")).unwrap();
    // The user's own files beside the run, and a stale figure of the first run.
    std::fs::write(run.join("measured.csv"), "time_s,key_depth_mm\n0,0\n").unwrap();
    std::fs::write(run.join("figure.svg"), "<svg/>").unwrap();
    let (ok, _, err) = piano(&["simulate", s(&soft), "--out", s(&run)]);
    assert!(!ok, "a second run into the same folder must be refused");
    assert!(
        err.contains("holds an earlier run") && err.contains("--force"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(run.join("trajectory.csv")).unwrap(),
        first
    );
    let (ok, _, err) = piano(&["simulate", s(&soft), "--out", s(&run), "--force"]);
    assert!(ok, "{err}");
    let second = std::fs::read_to_string(run.join("trajectory.csv")).unwrap();
    assert_ne!(second, first);
    assert_eq!(second.lines().count(), 1 + 31, "the soft run's 30 ms grid");
    // Old and new are never mixed: the first run's figure is gone, the user's data stay.
    assert!(!run.join("figure.svg").exists());
    assert!(run.join("measured.csv").exists());
    // A file where the folder should be is named.
    let file = dir.join("file");
    std::fs::write(&file, "x").unwrap();
    let (ok, _, err) = piano(&["simulate", s(&soft), "--out", s(&file)]);
    assert!(!ok && err.contains("is a file, not a folder"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn plot_keeps_an_existing_figure_unless_forced() {
    let dir = folder("plot");
    let scenario = dir.join("loud.toml");
    std::fs::write(&scenario, LOUD).unwrap();
    let run = dir.join("run");
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&run)]);
    assert!(ok, "{err}");
    let figure = run.join("figure.svg");
    std::fs::write(&figure, "my figure").unwrap();
    let (ok, _, err) = piano(&["plot", s(&run)]);
    assert!(
        !ok && err.contains("exists") && err.contains("--force"),
        "{err}"
    );
    assert_eq!(std::fs::read_to_string(&figure).unwrap(), "my figure");
    let (ok, _, err) = piano(&["plot", s(&run), "--force"]);
    assert!(ok, "{err}");
    assert!(std::fs::read_to_string(&figure).unwrap().contains("<svg"));
    // The report: refused when it exists, replaced with --force.
    let (ok, _, err) = piano(&["report", s(&run)]);
    assert!(ok, "{err}");
    let (ok, _, err) = piano(&["report", s(&run)]);
    assert!(!ok && err.contains("--force"), "{err}");
    let (ok, _, err) = piano(&["report", s(&run), "--force"]);
    assert!(ok, "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn absurd_durations_and_output_sizes_are_refused_before_running() {
    let dir = folder("duration");
    let scenario = dir.join("long.toml");
    for (text, line, field, what) in [
        (
            LOUD.replace("0.05", "1e9"),
            2,
            "duration_s",
            "longer than the 60 s",
        ),
        (LOUD.replace("0.05", "-1"), 2, "duration_s", "positive"),
        (
            LOUD.replace("duration_s = 0.05", "duration_s = 50\noutput_step_s = 1e-6"),
            3,
            "output_step_s",
            "output points",
        ),
    ] {
        std::fs::write(&scenario, &text).unwrap();
        let out = dir.join("run");
        let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&out)]);
        assert!(!ok, "{text}");
        assert!(
            err.contains(&format!(
                "scenario {}, line {line}, field `{field}`",
                s(&scenario)
            )) && err.contains(what),
            "{err}"
        );
        assert!(!out.exists(), "nothing is written for a refused scenario");
    }
    // The same bound for sweeps.
    let (ok, _, err) = piano(&["sweep", "--duration", "1e9", "--out", s(&dir.join("s.csv"))]);
    assert!(!ok && err.contains("option --duration"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn errors_name_the_file_the_line_and_the_field() {
    let dir = folder("errors");
    // A bad cell in a points table: its own line, not the [input] header.
    let scenario = dir.join("motion.toml");
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.1\n\n[input]\nkind = \"motion\"\npoints = [\n  [0.0, 0.0],\n  [0.01, \"x\"],\n]\n",
    )
    .unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&dir.join("r"))]);
    assert!(!ok);
    assert!(
        err.starts_with(&format!(
            "error: scenario {}, line 8, field `input.points[1][1]`",
            s(&scenario)
        )),
        "{err}"
    );
    assert!(!err.contains("parameters"), "{err}");
    // A value that fails validation inside [input] is found on its line too.
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.1\n[input]\nkind = \"touch\"\nstyle = \"struck\"\nfinger_speed_m_s = 50.0\n",
    )
    .unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&dir.join("r"))]);
    assert!(
        !ok && err.contains("line 6, field `input.finger_speed_m_s`"),
        "{err}"
    );
    // A parameter file: the file, the line and the field of a validation error...
    let (_, text, _) = piano(&["params"]);
    let params = dir.join("params.toml");
    let bad = text.replacen("e = 0.1 ", "e = 1.5 ", 1);
    assert_ne!(
        bad, text,
        "the backcheck's restitution line is in the default file"
    );
    std::fs::write(&params, &bad).unwrap();
    let line = bad.lines().position(|l| l.starts_with("e = 1.5")).unwrap() + 1;
    let (ok, _, err) = piano(&["--params", s(&params), "touchweight"]);
    assert!(!ok);
    assert!(
        err.contains(&format!(
            "parameter file {}, line {line}, field `contacts.backcheck.e`",
            s(&params)
        )) && err.contains("backcheck contact's restitution"),
        "{err}"
    );
    // ... and of a syntax error.
    std::fs::write(&params, text.replacen("[hammer]", "[hammer", 1)).unwrap();
    let (ok, _, err) = piano(&["--params", s(&params), "touchweight"]);
    assert!(
        !ok && err.contains(&format!("parameter file {}, line ", s(&params))),
        "{err}"
    );
    // Options are named as options.
    let (ok, _, err) = piano(&["sweep", "--jobs", "0", "--out", s(&dir.join("s.csv"))]);
    assert!(!ok && err.contains("option --jobs"), "{err}");
    let (ok, _, err) = piano(&["plot", s(&dir), "--format", "gif"]);
    assert!(!ok && err.contains("option --format"), "{err}");
    // A run folder that is not one is named as a run directory.
    let (ok, _, err) = piano(&["report", s(&dir)]);
    assert!(
        !ok && err.contains(&format!("run directory {}", s(&dir))),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn negative_numbers_are_accepted_as_option_values() {
    // `--from -1` is read as a value (and refused for what it is), not as an unknown flag.
    let dir = folder("negative");
    let (ok, _, err) = piano(&[
        "sweep",
        "--touch",
        "force",
        "--from",
        "-1",
        "--to",
        "5",
        "--out",
        s(&dir.join("s.csv")),
    ]);
    assert!(
        !ok && err.contains("option --from") && err.contains("-1"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Regressions found by the review of issue 11.
#[test]
fn review_findings_stay_fixed() {
    let dir = folder("review");
    let scenario = dir.join("s.toml");
    // A motion table running far past the duration finishes (it used to search the whole
    // table in 10 µs steps after the run).
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.1\n[input]\nkind = \"motion\"\npoints = [[0, 0], [1e9, 5]]\n",
    )
    .unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&dir.join("far"))]);
    assert!(ok, "{err}");
    // A motion that starts away from rest would make the key jump at t = 0.
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.1\n[input]\nkind = \"motion\"\npoints = [[0, 10], [0.1, 10]]\n",
    )
    .unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&dir.join("jump"))]);
    assert!(!ok && err.contains("`input.points[0][1]`"), "{err}");
    // A motion CSV from a spreadsheet (byte-order mark, CRLF) reads; a typo in the first
    // row is not taken for a header.
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.05\n[input]\nkind = \"motion\"\ncsv = \"m.csv\"\n",
    )
    .unwrap();
    std::fs::write(dir.join("m.csv"), "\u{feff}0,0\r\n0.02,10\r\n").unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&dir.join("bom"))]);
    assert!(ok, "{err}");
    std::fs::write(dir.join("m.csv"), "0,O\n0.02,10\n").unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&dir.join("typo"))]);
    assert!(
        !ok && err.contains("m.csv, line 1") && err.contains("'O'"),
        "{err}"
    );
    // A refused scenario with --force leaves the earlier run alone.
    let keep = dir.join("keep");
    std::fs::write(&scenario, LOUD).unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&keep)]);
    assert!(ok, "{err}");
    std::fs::write(&scenario, LOUD.replace("20.0", "1e12")).unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&keep), "--force"]);
    assert!(!ok && err.contains("`input.force_n`"), "{err}");
    assert!(keep.join("trajectory.csv").exists());
    // Files of yours that merely share a run's names are not a run: never replaced.
    let mine = dir.join("mine");
    std::fs::create_dir_all(&mine).unwrap();
    std::fs::write(mine.join("summary.json"), "{}").unwrap();
    std::fs::write(&scenario, LOUD).unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&mine), "--force"]);
    assert!(!ok && err.contains("not a run directory"), "{err}");
    assert_eq!(
        std::fs::read_to_string(mine.join("summary.json")).unwrap(),
        "{}"
    );
    // Sweeps: too many runs, levels no run accepts, and a folder as the output.
    let out = dir.join("s.csv");
    let (ok, _, err) = piano(&["sweep", "--runs", "1000000000000", "--out", s(&out)]);
    assert!(!ok && err.contains("option --runs"), "{err}");
    let (ok, _, err) = piano(&["sweep", "--from", "50", "--to", "100", "--out", s(&out)]);
    assert!(!ok && err.contains("option --from"), "{err}");
    let (ok, _, err) = piano(&["sweep", "--runs", "-1", "--out", s(&out)]);
    assert!(
        !ok && err.contains("-1") && !err.contains("unexpected argument"),
        "{err}"
    );
    let (ok, _, err) = piano(&["sweep", "--out", s(&dir)]);
    assert!(!ok && err.contains("option --out"), "{err}");
    assert!(!out.exists());
    // A parameter that resists motion cannot be negative; --params where it is not used.
    let (_, text, _) = piano(&["params"]);
    let params = dir.join("p.toml");
    std::fs::write(
        &params,
        text.replacen(
            "stop_stiffness_n_m_per_rad = 50.0",
            "stop_stiffness_n_m_per_rad = -50.0",
            1,
        ),
    )
    .unwrap();
    let (ok, _, err) = piano(&["--params", s(&params), "touchweight"]);
    assert!(
        !ok && err.contains("field `numerics.stop_stiffness_n_m_per_rad`"),
        "{err}"
    );
    let (ok, _, err) = piano(&["--params", s(&params), "plot", s(&keep)]);
    assert!(!ok && err.contains("option --params"), "{err}");
    // A hammer swing and a keystroke do not share a report.
    let swing = dir.join("swing");
    std::fs::write(
        &scenario,
        "model = \"double\"\nduration_s = 0.5\n[input]\nkind = \"pendulum\"\nrelease_angle_deg = 170\n",
    )
    .unwrap();
    let (ok, _, err) = piano(&["simulate", s(&scenario), "--out", s(&swing)]);
    assert!(ok, "170° is accepted, as its message says: {err}");
    let (ok, _, err) = piano(&[
        "report",
        s(&swing),
        s(&keep),
        "--out",
        s(&dir.join("r.html")),
    ]);
    assert!(!ok && err.contains("separate reports"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
