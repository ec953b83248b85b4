//! `piano synth` and `piano diagnose` as a user runs them.

mod common;
use common::piano;

fn scratch(name: &str) -> std::path::PathBuf {
    let dir =
        std::env::temp_dir().join(format!("piano-identify-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// The same seed gives the same dataset; nothing is overwritten without --force; the truth
/// stays out of the dataset's folder; a bad effect is named.
#[test]
fn synth_is_reproducible_and_keeps_what_exists() {
    let dir = scratch("synth");
    let s = |p: &std::path::Path| p.to_str().expect("utf-8 path").to_string();
    let (ds, truth) = (dir.join("ds"), dir.join("truth.json"));
    let args = |out: &std::path::Path, truth: &std::path::Path| {
        vec![
            "synth".to_string(),
            "--effect".into(),
            "air_drag:cd_n_m_s2=2e-6".into(),
            "--seed".into(),
            "5".into(),
            "--duration".into(),
            "1".into(),
            "--out".into(),
            s(out),
            "--truth".into(),
            s(truth),
        ]
    };
    let run = |a: Vec<String>| piano(&a.iter().map(String::as_str).collect::<Vec<_>>());
    let (ok, _, err) = run(args(&ds, &truth));
    assert!(ok, "{err}");
    let first = std::fs::read_to_string(ds.join("release_0.csv")).expect("run file");
    let (ok, _, err) = run(args(&ds, &truth));
    assert!(!ok && err.contains("--force"), "{err}");
    let mut again = args(&ds, &truth);
    again.push("--force".into());
    let (ok, _, err) = run(again);
    assert!(ok, "{err}");
    assert_eq!(
        first,
        std::fs::read_to_string(ds.join("release_0.csv")).expect("run file")
    );
    let truth_text = std::fs::read_to_string(&truth).expect("truth");
    assert!(truth_text.contains("\"cd_n_m_s2\": 2e-6"), "{truth_text}");
    let (ok, _, err) = run(args(&dir.join("ds2"), &dir.join("ds2").join("truth.json")));
    assert!(!ok && err.contains("--truth"), "{err}");
    let (ok, _, err) = piano(&[
        "synth", "--effect", "magic", "--out", "x", "--truth", "t.json",
    ]);
    assert!(
        !ok && err.contains("magic") && err.contains("pivot_viscous"),
        "{err}"
    );
    let (ok, _, err) = piano(&[
        "synth",
        "--effect",
        "air_drag:cd_n_m_s2=1",
        "--out",
        "x",
        "--truth",
        "t.json",
    ]);
    assert!(
        !ok && err.contains("cd_n_m_s2") && err.contains("plausible"),
        "{err}"
    );
    let (ok, _, err) = piano(&[
        "synth",
        "--releases",
        "0,0",
        "--out",
        "x",
        "--truth",
        "t.json",
    ]);
    assert!(
        !ok && err.contains("--releases") && err.contains("twice"),
        "{err}"
    );
    let (ok, _, err) = piano(&[
        "synth",
        "--effect",
        "air_drag:cd_n_m_s2=1e-6,cd_n_m_s2=2e-6",
        "--out",
        "x",
        "--truth",
        "t.json",
    ]);
    assert!(!ok && err.contains("twice"), "{err}");
    // The dataset does not give away what is hidden in it.
    let json = std::fs::read_to_string(ds.join("dataset.json")).expect("dataset.json");
    assert!(!json.contains("air_drag"), "{json}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// `piano diagnose` on the README's example dataset: names the hidden viscous flange,
/// writes the three pages and a corrected parameter file that `piano` runs, and refuses to
/// replace them without --force.
#[test]
fn diagnose_the_example_dataset() {
    let dir = scratch("diagnose");
    let data =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/data/pendulum_viscous");
    let out = dir.join("report");
    let corrected = dir.join("corrected.toml");
    let args = [
        "diagnose",
        data.to_str().expect("utf-8"),
        "--out",
        out.to_str().expect("utf-8"),
        "--write-params",
        corrected.to_str().expect("utf-8"),
    ];
    let (ok, text, err) = piano(&args);
    assert!(ok, "{err}");
    assert!(text.contains("decision: named. pivot_viscous"), "{text}");
    for f in ["report.json", "report.md", "report.html"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).expect("json"))
            .expect("valid JSON");
    for key in [
        "decision",
        "effects",
        "ambiguous_with",
        "candidates",
        "calibrated",
        "gap",
    ] {
        assert!(report.get(key).is_some(), "report.json lacks {key}");
    }
    let truth: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(data.with_file_name("pendulum_viscous.truth.json"))
            .expect("truth"),
    )
    .expect("truth JSON");
    let c = report["effects"][0]["params"]["c_n_m_s"]
        .as_f64()
        .expect("c");
    let c_true = truth["effect"]["c_n_m_s"].as_f64().expect("true c");
    assert!((c / c_true - 1.0).abs() < 0.1, "{c} vs {c_true}");
    let (ok, _, err) = piano(&args);
    assert!(!ok && err.contains("--force"), "{err}");
    // A page of the user's own, named like ours, is never replaced, even with --force.
    let mine = dir.join("mine");
    std::fs::create_dir_all(&mine).expect("folder");
    std::fs::write(mine.join("report.md"), "my notes\n").expect("write");
    let (ok, _, err) = piano(&[
        "diagnose",
        data.to_str().expect("utf-8"),
        "--out",
        mine.to_str().expect("utf-8"),
        "--force",
    ]);
    assert!(
        !ok && err.contains("not written by piano diagnose"),
        "{err}"
    );
    assert_eq!(
        std::fs::read_to_string(mine.join("report.md")).expect("read"),
        "my notes\n"
    );
    let (ok, text, err) = piano(&[
        "--params",
        corrected.to_str().expect("utf-8"),
        "params",
        "--list",
    ]);
    assert!(ok, "{err}");
    assert!(text.contains("c_n_m_s"), "{text}");
    let (ok, _, err) = piano(&[
        "diagnose",
        data.to_str().expect("utf-8"),
        "--out",
        dir.join("r2").to_str().expect("utf-8"),
        "--library",
        "pivot_viscous,warp_drive",
    ]);
    assert!(!ok && err.contains("warp_drive"), "{err}");
    for bad in ["", "pivot_viscous,pivot_viscous"] {
        let (ok, _, err) = piano(&[
            "diagnose",
            data.to_str().expect("utf-8"),
            "--out",
            dir.join("r4").to_str().expect("utf-8"),
            "--library",
            bad,
        ]);
        assert!(!ok && err.contains("--library"), "{bad}: {err}");
    }
    let (ok, _, err) = piano(&[
        "diagnose",
        dir.join("nothing").to_str().expect("utf-8"),
        "--out",
        dir.join("r3").to_str().expect("utf-8"),
    ]);
    assert!(!ok && err.contains("dataset.json"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}
