//! Reading tracked-marker datasets (schema 1): a good one reads back, and every bad one
//! (issue 13's list) gets an error naming the file, line or field, without a panic.

use std::path::{Path, PathBuf};

use mbs_identify::{Dataset, Role};

const GOOD_JSON: &str = r#"{
  "schema_version": 1,
  "experiment": "pendulum",
  "description": "hammer swinging on its flange, 3000 fps",
  "fps": 3000.0,
  "exposure_s": 0.0002,
  "markers": [
    {"name": "head", "body": "hammer", "local_m": [0.13, 0.03], "sigma_m": 3e-5},
    {"name": "shank", "body": "hammer", "local_m": [0.06, 0.0], "sigma_m": 3e-5}
  ],
  "runs": [
    {"id": "high", "file": "high.csv", "role": "fit", "conditions": {"release_angle_deg": 0}},
    {"id": "low", "file": "low.csv", "role": "heldout", "conditions": {"release_angle_deg": -35}}
  ]
}
"#;

const GOOD_CSV: &str = "time_s,head_x_m,head_y_m,shank_x_m,shank_y_m
0.0,0.13,0.03,0.06,0.0
0.000333,0.1299,0.0295,0.06,-0.0001
0.000667,,,0.0599,-0.0003
0.001,NaN,0.028,0.0598,-0.0006
";

/// A dataset directory with `json` and both runs holding `csv`.
fn write(name: &str, json: &str, csv: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("mbs-identify-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("dataset.json"), json).unwrap();
    std::fs::write(dir.join("high.csv"), csv).unwrap();
    std::fs::write(dir.join("low.csv"), csv).unwrap();
    dir
}

fn cleanup(dir: &Path) {
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_good_dataset_reads_back_with_its_lost_frames() {
    let dir = write("good", GOOD_JSON, GOOD_CSV);
    let d = Dataset::load(&dir).expect("reads");
    assert_eq!((d.fps, d.markers.len(), d.runs.len()), (3000.0, 2, 2));
    assert_eq!(d.markers[0].local_m, [0.13, 0.03]);
    assert_eq!(d.runs[1].role, Role::Heldout);
    assert_eq!(d.runs[1].conditions["release_angle_deg"], -35);
    d.check_bodies(&["hammer"]).expect("the hammer is a body");
    let run = d.read_run(&d.runs[0]).expect("reads");
    assert_eq!(run.time_s, vec![0.0, 0.000333, 0.000667, 0.001]);
    // An empty cell and a NaN are lost frames (a half-lost position is lost).
    assert_eq!(run.positions[0][1], Some([0.1299, 0.0295]));
    assert_eq!((run.positions[0][2], run.positions[0][3]), (None, None));
    assert_eq!((run.seen(0), run.seen(1)), (2, 4));
    cleanup(&dir);
}

#[test]
fn every_bad_dataset_is_named_by_file_line_and_field() {
    // (what to break, the file the error must name, its field, its line, words in it)
    type Case = (
        &'static str,
        String,
        String,
        &'static str,
        &'static str,
        Option<usize>,
        &'static str,
    );
    let cases: Vec<Case> = vec![
        (
            "schema",
            GOOD_JSON.replace("\"schema_version\": 1", "\"schema_version\": 2"),
            GOOD_CSV.into(),
            "dataset.json",
            "schema_version",
            Some(2),
            "schema 2",
        ),
        (
            "missing-column",
            GOOD_JSON.into(),
            GOOD_CSV.replace("shank_y_m", "shank_z_m"),
            "high.csv",
            "shank_y_m",
            Some(1),
            "missing",
        ),
        (
            "unknown-marker-field",
            GOOD_JSON.replace("\"sigma_m\": 3e-5}", "\"sigma\": 3e-5}"),
            GOOD_CSV.into(),
            "dataset.json",
            "markers[0]",
            Some(8),
            "sigma",
        ),
        (
            "bad-type",
            GOOD_JSON.replace("\"fps\": 3000.0", "\"fps\": \"fast\""),
            GOOD_CSV.into(),
            "dataset.json",
            "fps",
            Some(5),
            "invalid type",
        ),
        (
            "time-back",
            GOOD_JSON.into(),
            GOOD_CSV.replace("0.000667,", "0.0002,"),
            "high.csv",
            "time_s",
            Some(4),
            "increase",
        ),
        (
            "all-lost",
            GOOD_JSON.into(),
            "time_s,head_x_m,head_y_m,shank_x_m,shank_y_m\n0,,,0.06,0\n0.1,NaN,NaN,0.06,0\n".into(),
            "high.csv",
            "head_x_m",
            None,
            "every frame",
        ),
        (
            "not-a-number",
            GOOD_JSON.into(),
            GOOD_CSV.replace("0.1299", "0.12x"),
            "high.csv",
            "head_x_m",
            Some(3),
            "not a number",
        ),
        (
            "run-file-missing",
            GOOD_JSON.replace("\"file\": \"low.csv\"", "\"file\": \"gone.csv\""),
            GOOD_CSV.into(),
            "dataset.json",
            "runs[1].file",
            Some(13),
            "does not exist",
        ),
        (
            "duplicate-marker",
            GOOD_JSON.replace("\"name\": \"shank\"", "\"name\": \"head\""),
            GOOD_CSV.into(),
            "dataset.json",
            "markers[1].name",
            Some(9),
            "twice",
        ),
        (
            "negative-sigma",
            GOOD_JSON.replace(
                "[0.06, 0.0], \"sigma_m\": 3e-5",
                "[0.06, 0.0], \"sigma_m\": -1",
            ),
            GOOD_CSV.into(),
            "dataset.json",
            "markers[1].sigma_m",
            Some(9),
            "positive",
        ),
        (
            "short-row",
            GOOD_JSON.into(),
            GOOD_CSV.replace("0.001,NaN,0.028,0.0598,-0.0006", "0.001,NaN,0.028"),
            "high.csv",
            "",
            Some(5),
            "3 cells",
        ),
    ];
    for (name, json, csv, file, field, line, words) in cases {
        assert!(
            json != GOOD_JSON || csv != GOOD_CSV,
            "{name}: nothing broken"
        );
        let dir = write(name, &json, &csv);
        let e = Dataset::load(&dir).and_then(|d| {
            for r in &d.runs {
                d.read_run(r)?;
            }
            Ok(())
        });
        let e = e.expect_err(name);
        let text = e.to_string();
        assert!(e.file.ends_with(file), "{name}: {text}");
        assert!(
            e.field.starts_with(field),
            "{name}: field {:?} in {text}",
            e.field
        );
        if line.is_some() {
            assert_eq!(e.line, line, "{name}: {text}");
        }
        assert!(text.contains(words), "{name}: {text}");
        cleanup(&dir);
    }
}

#[test]
fn a_marker_on_an_unknown_body_and_a_missing_dataset_are_named() {
    let dir = write(
        "body",
        &GOOD_JSON.replace(
            "\"body\": \"hammer\", \"local_m\": [0.06",
            "\"body\": \"shank\", \"local_m\": [0.06",
        ),
        GOOD_CSV,
    );
    let d = Dataset::load(&dir).unwrap();
    let e = d.check_bodies(&["hammer"]).unwrap_err();
    assert_eq!(e.field, "markers[1].body");
    assert!(e.to_string().contains("no body 'shank'"), "{e}");
    cleanup(&dir);
    let e = Dataset::load(Path::new("/nonexistent/dataset")).unwrap_err();
    assert!(
        e.to_string().contains("dataset.json") && e.to_string().contains("cannot read"),
        "{e}"
    );
}

/// A dataset driven by a measured motion names its drive marker; one naming no marker is
/// refused at the `drive` field with its line.
#[test]
fn the_drive_marker_must_be_a_marker() {
    let with = |drive: &str| {
        GOOD_JSON.replace(
            "  \"runs\": [",
            &format!("  \"drive\": \"{drive}\",\n  \"runs\": ["),
        )
    };
    let dir = write("drive-good", &with("shank"), GOOD_CSV);
    let d = Dataset::load(&dir).expect("reads");
    assert_eq!(d.drive.as_deref(), Some("shank"));
    cleanup(&dir);
    let dir = write("drive-bad", &with("key_front"), GOOD_CSV);
    let e = Dataset::load(&dir).unwrap_err();
    assert_eq!(e.field, "drive");
    assert_eq!(e.line, Some(11), "the line of \"drive\"");
    assert!(
        e.message
            .contains("'key_front' is not one of the markers (head, shank)"),
        "{e}"
    );
    cleanup(&dir);
    // Without one (a pendulum), nothing is written for it.
    let dir = write("drive-none", GOOD_JSON, GOOD_CSV);
    let d = Dataset::load(&dir).unwrap();
    assert!(d.drive.is_none());
    assert!(!serde_json::to_string(&d).unwrap().contains("drive"));
    cleanup(&dir);
}
