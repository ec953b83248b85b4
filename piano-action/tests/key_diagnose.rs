//! The key-drive diagnosis (issue 15) on synthetic data with a hidden effect: the CI tier
//! runs short drops with a reduced library; the study over seeds is `--ignored` (the
//! nightly tier of `identification.md` §5.4) and prints its confusion table.

mod common;

use common::piano;
use mbs_identify::Dataset;
use piano_action::identify::action_effects::{ActionEffect, action_effect_spec};
use piano_action::identify::key_diagnose::{KeyDiagnoseOptions, diagnose_key_drive};
use piano_action::identify::key_drive::{KeyDriveOptions, synthesize};
use piano_action::params::ActionParams;

/// Writes a synthetic key-drive dataset into a fresh temporary folder and reads it back.
fn dataset(tag: &str, options: &KeyDriveOptions) -> (Dataset, std::path::PathBuf) {
    let params = ActionParams::reference();
    let (dataset, runs, _) = synthesize(&params, options).expect("synthesises");
    let dir = std::env::temp_dir().join(format!("piano-kdiag-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dataset.write(&dir, &runs).expect("writes");
    (Dataset::load(&dir).expect("reads back"), dir)
}

fn options(ids: &[&str]) -> KeyDiagnoseOptions {
    KeyDiagnoseOptions {
        library: ids
            .iter()
            .map(|id| action_effect_spec(id).expect("in the library"))
            .collect(),
        ..KeyDiagnoseOptions::default()
    }
}

/// The CI tier's diagnosis: one 0.15 s drop from rest (seed `seed`, effect `effect` at
/// its visible strength), four markers, three candidates; the dataset removed after.
fn short_drop_diagnosis(
    tag: &str,
    seed: u64,
    effect: Option<&str>,
) -> piano_action::identify::key_diagnose::KeyDriveDiagnosis {
    let (ds, dir) = dataset(
        tag,
        &KeyDriveOptions {
            seed,
            release_heights_m: vec![0.0],
            duration_s: 0.15,
            effect: effect.map(|e| ActionEffect::parse(e).expect("parses")),
            ..KeyDriveOptions::default()
        },
    );
    let d = diagnose_key_drive(
        &ActionParams::reference(),
        &ds,
        &options(&["key_flex", "knuckle_friction", "felt_hysteresis"]),
        &|_, _| {},
    )
    .expect("diagnoses");
    std::fs::remove_dir_all(&dir).ok();
    d
}

/// A key that bends (its back arm on a spring of 1000 N·m/rad, 3 times softer than a
/// basswood key's estimated stiffness) is found and named among three candidates on one 0.15 s drop
/// tracked at the key front and back and the hammer head and shank; the gap comes down to
/// within 1.5 noise floors, and the bending's compliance within a factor 3.
#[test]
fn a_bending_key_is_named() {
    let d = short_drop_diagnosis("flex", 1, Some("key_flex"));
    assert_eq!(d.decision, "named", "{}", d.summary);
    assert_eq!(d.effects[0].id, "key_flex");
    let c = d.effects[0].params["compliance_rad_n_m"];
    assert!((3.3e-4..3e-3).contains(&c), "compliance {c:e} (truth 1e-3)");
    assert!(
        d.after_rms_m < 1.5 * d.noise_floor_m,
        "gap {:.1} µm against a floor of {:.1}",
        d.after_rms_m * 1e6,
        d.noise_floor_m * 1e6
    );
    assert!(d.before_rms_m > 1.3 * d.after_rms_m);
}

/// The file's own action, camera noise and nuisance only: nothing is added.
#[test]
fn nothing_is_added_to_an_action_without_a_hidden_effect() {
    let d = short_drop_diagnosis("none", 2, None);
    assert_eq!(d.decision, "none", "{}", d.summary);
    assert!(d.effects.is_empty());
    assert!(d.before_rms_m < 1.5 * d.noise_floor_m);
}

/// `piano diagnose` reads a key-drive dataset, writes its three pages (the replay in the
/// HTML), refuses `--write-params` and a dataset without its mass, naming the field.
#[test]
fn the_cli_diagnoses_a_key_drive_and_refuses_what_it_cannot_do() {
    let (_, dir) = dataset(
        "cli",
        &KeyDriveOptions {
            seed: 3,
            release_heights_m: vec![0.0],
            duration_s: 0.1,
            ..KeyDriveOptions::default()
        },
    );
    let out = dir.join("report");
    let (ok, stdout, err) = piano(&[
        "diagnose",
        dir.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--library",
        "knuckle_friction",
    ]);
    assert!(ok, "{err}");
    assert!(stdout.contains("decision: "), "{stdout}");
    assert!(stdout.contains("time: "), "{stdout}");
    let html = std::fs::read_to_string(out.join("report.html")).expect("report.html");
    assert!(html.contains("const REPLAY = {"), "the replay's data");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["experiment"], "key_drive");
    assert!(json["phases"].as_array().is_some_and(|p| !p.is_empty()));
    // A parameter file cannot hold a split key.
    let (ok, _, err) = piano(&[
        "diagnose",
        dir.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--force",
        "--write-params",
        dir.join("c.toml").to_str().unwrap(),
    ]);
    assert!(!ok && err.contains("--write-params"), "{err}");
    // An effect of the other library is named as such.
    let (ok, _, err) = piano(&[
        "diagnose",
        dir.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--force",
        "--library",
        "air_drag",
    ]);
    assert!(!ok && err.contains("key-drive library"), "{err}");
    // Without its mass the key cannot be driven.
    let json_path = dir.join("dataset.json");
    let text = std::fs::read_to_string(&json_path).unwrap();
    std::fs::write(&json_path, text.replace("\"mass_kg\"", "\"weight\"")).unwrap();
    let (ok, _, err) = piano(&[
        "diagnose",
        dir.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--force",
    ]);
    assert!(
        !ok && err.contains("dataset.json") && err.contains("conditions.mass_kg"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The study of issue 15 (nightly tier, 1–1.5 minutes per dataset on 2 cores): 5 seeds of each
/// effect at its visible strength and 5 negatives, two drops of 0.3 s tracked at the key
/// front and back and the hammer head and shank; prints the outcomes and the rates the
/// issue asks for, and checks them: the right effect (or an ambiguity holding it) in
/// ≥ 80 %, a wrong confident name in ≤ 10 %, `none` in ≥ 80 % of the negatives; the gap
/// after the check's catch 3 times lower, pooled over the datasets whose effect shows
/// there (the two rise effects, `felt_hysteresis` and `knuckle_friction`, change the
/// hammer's flight, not its catch).
#[test]
#[ignore]
fn study_over_seeds() {
    let params = ActionParams::reference();
    let seeds: u64 = std::env::var("STUDY_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    // STUDY_EFFECTS (ids, `none` for the negatives) and STUDY_MARKERS (names) narrow it,
    // e.g. the confusable effects with only the key front and the hammer head tracked.
    let only: Option<Vec<String>> = std::env::var("STUDY_EFFECTS")
        .ok()
        .map(|s| s.split(',').map(String::from).collect());
    let markers: Vec<String> = std::env::var("STUDY_MARKERS")
        .map(|s| s.split(',').map(String::from).collect())
        .unwrap_or_default();
    let effects: Vec<Option<&str>> = std::iter::once(None)
        .chain(
            piano_action::identify::action_effects::ACTION_EFFECTS
                .iter()
                .map(|e| Some(e.id)),
        )
        .filter(|e| {
            only.as_ref()
                .is_none_or(|o| o.iter().any(|x| x == e.unwrap_or("none")))
        })
        .collect();
    let (mut ambiguous, mut unexplained, mut partly) = (0, 0, 0);
    let (mut right, mut wrong, mut total, mut none_ok, mut negatives) = (0, 0, 0, 0, 0);
    // The gap after the check's catch, before and after, of the datasets whose effect
    // shows there (the baseline misses it by 3 noise floors or more): squared sums.
    let (mut post_before, mut post_after, mut post_n) = (0.0, 0.0, 0);
    for effect in effects {
        for seed in 1..=seeds {
            let (ds, dir) = dataset(
                &format!("study-{}-{seed}", effect.unwrap_or("none")),
                &KeyDriveOptions {
                    seed,
                    effect: effect.map(|e| ActionEffect::parse(e).expect("parses")),
                    markers: markers.clone(),
                    ..KeyDriveOptions::default()
                },
            );
            let d = diagnose_key_drive(&params, &ds, &KeyDiagnoseOptions::default(), &|_, _| {})
                .expect("diagnoses");
            let named: Vec<String> = d
                .effects
                .iter()
                .map(|e| e.id.clone())
                .chain(d.ambiguous_with.iter().cloned())
                .collect();
            let post_gap = piano_action::identify::key_report::post_check_gap(&d);
            let post = post_gap.map_or(String::new(), |(b, a)| {
                format!(
                    " post-check {:.0} -> {:.0} um ({:.1}x)",
                    b * 1e6,
                    a * 1e6,
                    b / a
                )
            });
            if let (Some((b, a)), Some(_)) = (post_gap, effect)
                && b >= 3.0 * d.noise_floor_m
            {
                post_before += b * b;
                post_after += a * a;
                post_n += 1;
            }
            let secs: f64 = d.timing.iter().map(|(_, t)| t).sum();
            eprintln!(
                "{:22} seed {seed}: {:11} {:40} gap {:.0} -> {:.0} um{post} ({secs:.0} s)",
                effect.unwrap_or("none"),
                d.decision,
                named.join(" | "),
                d.before_rms_m * 1e6,
                d.after_rms_m * 1e6
            );
            match effect {
                None => {
                    negatives += 1;
                    none_ok += usize::from(d.decision == "none");
                }
                Some(id) => {
                    total += 1;
                    ambiguous += usize::from(d.decision == "ambiguous");
                    unexplained += usize::from(d.decision == "unexplained");
                    partly += usize::from(d.decision == "partly_explained");
                    if named.iter().any(|n| n == id) {
                        right += 1;
                    } else if d.decision == "named" {
                        wrong += 1;
                    }
                }
            }
            std::fs::remove_dir_all(&dir).ok();
        }
    }
    eprintln!(
        "markers: {}",
        if markers.is_empty() {
            "all four".to_string()
        } else {
            markers.join(", ")
        }
    );
    eprintln!(
        "right (named or in the ambiguity): {right}/{total}; wrong confident name: \
         {wrong}/{total} (ambiguous {ambiguous}, partly explained {partly}, unexplained \
         {unexplained}); none on negatives: {none_ok}/{negatives}"
    );
    let post_ratio = (post_before / post_after.max(1e-300)).sqrt();
    eprintln!(
        "gap after the check's catch, over the {post_n} datasets whose effect shows there: \
         {post_ratio:.1}x lower"
    );
    assert!(right * 5 >= total * 4, "right {right}/{total}");
    assert!(
        post_n == 0 || post_ratio >= 3.0,
        "post-check {post_ratio:.1}x"
    );
    assert!(wrong * 10 <= total, "wrong {wrong}/{total}");
    assert!(none_ok * 5 >= negatives * 4, "none {none_ok}/{negatives}");
}

/// A maker's tolerance is read as a uniform spread of the factor over 1 ± tol: the SD of
/// its logarithm, against a midpoint-rule integral of the spread.
#[test]
fn a_tolerance_is_read_as_a_uniform_spread() {
    use piano_action::identify::key_diagnose::tolerance_sd;
    for tol in [0.03, 0.15, 0.2] {
        let n = 200_000;
        let (mut m1, mut m2) = (0.0, 0.0);
        for i in 0..n {
            let x = 1.0 - tol + 2.0 * tol * (i as f64 + 0.5) / n as f64;
            m1 += x.ln() / n as f64;
            m2 += x.ln().powi(2) / n as f64;
        }
        let sd = (m2 - m1 * m1).sqrt();
        assert!(
            (tolerance_sd(tol) - sd).abs() < 1e-6 * sd,
            "±{tol}: {} vs {sd}",
            tolerance_sd(tol)
        );
        // Wider than the plain tol/√3 on the log scale for a wide spread (the log stretches
        // the low side), and close to it for a narrow one.
        assert!(tolerance_sd(tol) >= tol / 3f64.sqrt());
    }
    assert!((tolerance_sd(0.2) - 0.117).abs() < 5e-4);
}
