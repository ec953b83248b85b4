//! The key-drive diagnosis against truths it did not make (issue 33,
//! `identification.md` §5.5): datasets from the independent generator in `truths/`
//! (the grand's description edited by hand, its own camera and noise), scored in a
//! confusion matrix whose rows are the truths and whose columns are the decisions, with
//! confident wrong names counted apart from honest `partly_explained` / `unexplained`.
//!
//! The CI tier diagnoses two short datasets; the study over seeds is `--ignored`:
//! `cargo test --release -p piano-action --test confusion -- --ignored --nocapture`
//! (`STUDY_SEEDS` seeds from `STUDY_SEED_FROM`, and `STUDY_CASES`, narrow it; each
//! dataset's outcome is appended to
//! `target/confusion/outcomes.jsonl` as it comes, and the matrix printed at the end).

mod truths;

use std::collections::BTreeMap;
use std::io::Write;
use std::path::PathBuf;

use mbs_identify::Dataset;
use piano_action::identify::action_effects::action_effect_spec;
use piano_action::identify::key_diagnose::{
    KeyDiagnoseOptions, KeyDriveDiagnosis, diagnose_key_drive, tolerance_of,
};
use piano_action::identify::key_report::{beyond_tolerance, markdown};
use piano_action::params::ActionParams;
use truths::{Expected, GenOptions};

/// How one diagnosis scores against its truth.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Score {
    /// The family's name, alone.
    NamedRight,
    /// An ambiguity that holds the truth.
    AmbiguousRight,
    /// `none` on a negative.
    NoneRight,
    /// `partly_explained` or `unexplained` where nothing could be named (an effect outside
    /// the library): right too.
    HonestRight,
    /// `partly_explained`, `unexplained` or `none` where the family should have been
    /// named: not right, not wrong.
    Honest,
    /// An ambiguity without the truth, or an outside effect's ambiguity.
    AmbiguousWrong,
    /// A name that is not the truth's (or any name for an effect outside the library, or
    /// on a negative): the column a user pays for.
    NamedWrong,
}

impl Score {
    fn right(self) -> bool {
        matches!(
            self,
            Score::NamedRight | Score::AmbiguousRight | Score::NoneRight | Score::HonestRight
        )
    }
}

fn score(expected: &Expected, d: &KeyDriveDiagnosis) -> Score {
    let held: Vec<&str> = d
        .effects
        .iter()
        .map(|e| e.id.as_str())
        .chain(d.ambiguous_with.iter().map(String::as_str))
        .collect();
    match (expected, d.decision.as_str()) {
        (Expected::Family(id), "named") if held.first() == Some(id) => Score::NamedRight,
        (Expected::Family(id), "ambiguous") if held.contains(id) => Score::AmbiguousRight,
        (Expected::Negative, "none") => Score::NoneRight,
        (Expected::Outside, "partly_explained" | "unexplained") => Score::HonestRight,
        (Expected::Family(_), "partly_explained" | "unexplained" | "none") => Score::Honest,
        // An outside effect's `none`: the diagnosis saw nothing; not a wrong name.
        (Expected::Outside, "none") => Score::Honest,
        (Expected::Negative, "partly_explained" | "unexplained") => Score::Honest,
        (_, "ambiguous") => Score::AmbiguousWrong,
        _ => Score::NamedWrong,
    }
}

/// The column a decision falls in: its outcome and, for a name, the effect.
fn column(d: &KeyDriveDiagnosis) -> String {
    match d.decision.as_str() {
        "named" => format!("named {}", d.effects.first().map_or("?", |e| e.id.as_str())),
        "ambiguous" => format!(
            "ambiguous {}",
            d.effects
                .iter()
                .map(|e| e.id.as_str())
                .chain(d.ambiguous_with.iter().map(String::as_str))
                .collect::<Vec<_>>()
                .join("|")
        ),
        "partly_explained" => format!("partly ({})", d.best_candidate.as_deref().unwrap_or("?")),
        other => other.to_string(),
    }
}

fn scratch(tag: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("piano-confusion-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// Generates `case` at `seed` and diagnoses it with `options`.
fn diagnose_case(
    case: &str,
    seed: u64,
    generate: &GenOptions,
    options: &KeyDiagnoseOptions,
) -> KeyDriveDiagnosis {
    diagnose_with_truth(case, seed, generate, options).0
}

/// Where a truth's effect has a value the library's parameter stands for (the same
/// quantity of the same form): each such parameter and its true value. A flex at one
/// place: its compliance (the truth's 1/k) and place; a felt's exponent; a friction's
/// coefficient step and slip speed; a shank bent at two places, its whole compliance and the share at
/// the head's root. Forms the library has no parameter for (three hinges, a slide) have
/// none.
///
/// A library parameter that is a change of a file value the truth's nuisance also
/// changes (the punching's stiffness factor, the knuckle's friction step) is compared with
/// the truth's whole change of that value, effect and nuisance together: a named effect's
/// refit holds the nuisance's value at the file's, so what it fits is the whole (a
/// punching drawn at 0.277 of the file's force with its stiffness's nuisance 0.90 is a
/// punching at 0.249 of the file's).
fn comparable(
    case: &str,
    effect: &BTreeMap<String, f64>,
    nuisance: &BTreeMap<String, f64>,
) -> Vec<(&'static str, f64)> {
    let get = |k: &str| effect.get(k).copied();
    let factor = |k: &str| nuisance.get(k).copied().unwrap_or(1.0);
    let mut out = Vec::new();
    match case {
        "key_flex_far" | "shank_flex_mid" => {
            if let Some(k) = get("k_n_m_per_rad") {
                out.push(("compliance_rad_n_m", 1.0 / k));
            }
        }
        "shank_flex_two" => {
            // Two hinges, the second near the head's root where the library's sits: the
            // whole compliance and the share of it there.
            if let (Some(k1), Some(k2)) = (get("k1_n_m_per_rad"), get("k2_n_m_per_rad")) {
                let whole = 1.0 / k1 + 1.0 / k2;
                out.push(("compliance_rad_n_m", whole));
                out.push(("head_share", (1.0 / k2) / whole));
            }
        }
        "keybed_felt_p3" => {
            // The same felt law: its exponent and restitution, and its stiffness as the
            // library's factor at the punching's working compression (0.5 mm), where the
            // truth's force is its ratio at 1 mm times 0.5^(p − 2).
            if let (Some(p), Some(e), Some(ratio)) = (get("p"), get("e"), get("force_ratio_at_1mm"))
            {
                out.push(("p", p));
                out.push(("e", e));
                out.push((
                    "k_scale",
                    ratio * 0.5f64.powf(p - 2.0) * factor("contacts.front_rail.k"),
                ));
            }
        }
        "knuckle_felt_hc" => {
            // The exponent is the same quantity, and so is the restitution of an impact
            // at the library's reference speed (`de` from the file's): Hunt–Crossley's
            // exact relation, whatever the stiffness and mass. (Not the share: its truth,
            // 1, lies on its bound, which any interval reaching it holds.)
            if let Some(p) = get("p") {
                out.push(("p", p));
            }
            if let Some(law) = get("alpha_s_per_m")
                .and_then(|alpha| mbs_contact::laws::HuntCrossley::new(1.0, 2.0, alpha).ok())
            {
                let file = ActionParams::reference().contacts.jack_knuckle.e;
                let e = law.restitution_at(
                    piano_action::identify::action_effects::FELT_REFERENCE_SPEED_M_S,
                );
                out.push(("de", e - file));
            }
        }
        "knuckle_friction_visc" => {
            if let Some(d) = get("dmu") {
                let file = ActionParams::reference().contacts.jack_knuckle.mu;
                out.push(("dmu", d + file * (factor("contacts.jack_knuckle.mu") - 1.0)));
            }
            // The regularised law is the library's: its slip speed is the same quantity.
            if let Some(v) = get("regularization_m_s") {
                out.push(("slip_speed", v));
            }
        }
        _ => {}
    }
    out
}

/// [`diagnose_case`], with the truth's record (its effect's values and nuisance).
fn diagnose_with_truth(
    case: &str,
    seed: u64,
    generate: &GenOptions,
    options: &KeyDiagnoseOptions,
) -> (KeyDriveDiagnosis, truths::TruthRecord) {
    let dir = scratch(&format!("{case}-{seed}"));
    let truth = dir.with_extension("truth.json");
    let record = truths::generate(case, seed, &dir, &truth, generate).expect("generates");
    let ds = Dataset::load(&dir).expect("reads back");
    let d = diagnose_key_drive(&ActionParams::reference(), &ds, options, &|_, _| {})
        .expect("diagnoses");
    std::fs::remove_dir_all(&dir).ok();
    std::fs::remove_file(&truth).ok();
    (d, record)
}

fn short() -> GenOptions {
    GenOptions {
        duration_s: 0.15,
        heights: truths::Heights::FittedOnly,
        ..GenOptions::default()
    }
}

fn library(ids: &[&str]) -> KeyDiagnoseOptions {
    KeyDiagnoseOptions {
        library: ids
            .iter()
            .map(|id| action_effect_spec(id).expect("in the library"))
            .collect(),
        ..KeyDiagnoseOptions::default()
    }
}

/// A part the model leaves out (the damper lever on the key's back end) is never named,
/// whatever the library offers to stand in for it.
#[test]
fn a_damper_the_model_leaves_out_is_not_named() {
    let d = diagnose_case(
        "damper",
        1,
        &short(),
        &library(&["key_flex", "keybed_felt", "knuckle_friction"]),
    );
    assert_ne!(
        score(&Expected::Outside, &d),
        Score::NamedWrong,
        "{}",
        d.summary
    );
    assert!(
        d.decision != "named" && d.decision != "ambiguous",
        "{}",
        d.summary
    );
}

/// The action with its nuisance only, filmed by another camera: nothing is named.
#[test]
fn an_independent_action_without_an_effect_is_none() {
    let d = diagnose_case(
        "none",
        2,
        &short(),
        &library(&["key_flex", "knuckle_friction"]),
    );
    assert_eq!(d.decision, "none", "{}", d.summary);
}

/// Two drops (0 and 5 mm, 0.3 s) of the action with its nuisance only: after the check of
/// the 5 mm drop its hammer slides up the back-check, at a speed the fitted 0 mm drop's
/// calibrated values predict 6.4 noise floors off (the friction of the repetition lever's
/// knuckle, 18 % over the file's, is not calibrated). Refitted on both drops with the
/// values the gaps lean on free within their makers' tolerance, one action explains both
/// to the noise, and nothing is named.
#[test]
fn a_held_out_drop_is_judged_with_the_action_its_makers_tolerate() {
    let (d, _) = diagnose_with_truth(
        "none",
        3,
        &GenOptions::default(),
        &library(&["knuckle_friction"]),
    );
    assert_eq!(d.decision, "none", "{}", d.summary);
    let p = d.tolerated_p.expect("a joint refit with a held-out run");
    assert!(p >= 0.01, "the tolerated moves' probability {p}");
    assert!(!d.tolerated.is_empty());
    let held = d.heldout_before_rms_m.expect("a held-out run");
    assert!(
        held < 1.3 * d.noise_floor_m,
        "held-out gap {:.1} µm against a floor of {:.1}",
        held * 1e6,
        d.noise_floor_m * 1e6
    );
}

/// A front-rail punching of another exponent (2.84 for the file's 2, 0.6 of its force at
/// 1 mm, restitution 0.58 for 0.4) is named `keybed_felt` with its exponent and loss: the
/// exponent and the restitution are screened (from the file's alone the refit stopped at
/// exponent 2.2, its gap 3.6 noise floors), and a punching told from the file's by its
/// exponent and loss is identified even where its stiffness at the working compression
/// is not (before, its stiffness factor near 1 left it "not identified" and the
/// knuckle's friction, shrinking the gap 1.4 times, was the best candidate).
#[test]
fn a_punching_of_another_exponent_is_named_with_its_exponent() {
    let (d, truth) = diagnose_with_truth(
        "keybed_felt_p3",
        1,
        &short(),
        &library(&["keybed_felt", "knuckle_friction"]),
    );
    assert_eq!(d.decision, "named", "{}", d.summary);
    let named = d.effects.first().expect("a named effect");
    assert_eq!(named.id, "keybed_felt");
    for (param, truth) in [("p", truth.effect["p"]), ("e", truth.effect["e"])] {
        let [lo, hi] = named.ci95[param];
        assert!(
            (lo..=hi).contains(&truth),
            "{param}: [{lo}, {hi}] misses the truth's {truth}"
        );
    }
}

/// The study: every case over `STUDY_SEEDS` seeds (5 by default), two 0.3 s drops, the
/// whole library. Prints the confusion matrix and checks issue 33's rates: right ≥ 90 %,
/// confident wrong names ≤ 2 %, effects outside the library never named, negatives
/// `none` ≥ 90 %.
#[test]
#[ignore]
fn confusion_matrix_over_independent_truths() {
    let seeds: u64 = std::env::var("STUDY_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let first: u64 = std::env::var("STUDY_SEED_FROM")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let only: Option<Vec<String>> = std::env::var("STUDY_CASES")
        .ok()
        .map(|s| s.split(',').map(String::from).collect());
    // The code's revision, so that outcomes of different code in the log stay apart.
    let rev = std::process::Command::new("git")
        .args(["describe", "--always", "--dirty"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .map_or_else(|| "unknown".to_string(), |s| s.trim().to_string());
    let out_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/confusion");
    std::fs::create_dir_all(&out_dir).expect("target/confusion");
    let mut log = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(out_dir.join("outcomes.jsonl"))
        .expect("outcomes.jsonl");
    let mut matrix: BTreeMap<String, BTreeMap<String, usize>> = BTreeMap::new();
    let mut scores: BTreeMap<Score, usize> = BTreeMap::new();
    let (mut total, mut right) = (0usize, 0usize);
    let (mut outside_named, mut negatives, mut negatives_none) = (0usize, 0usize, 0usize);
    let (mut intervals, mut covered) = (0usize, 0usize);
    // Seed by seed over every case, so that a study cut short still covers every case.
    let cases: Vec<truths::Case> = truths::cases()
        .into_iter()
        .filter(|c| only.as_ref().is_none_or(|o| o.iter().any(|x| x == c.id)))
        .collect();
    for seed in first..first + seeds {
        for case in &cases {
            let (d, truth) = diagnose_with_truth(
                case.id,
                seed,
                &GenOptions::default(),
                &KeyDiagnoseOptions::default(),
            );
            let s = score(&case.expected, &d);
            // A named effect's comparable values: inside their 95 % interval?
            let mut inside = Vec::new();
            if let (Score::NamedRight, Some(e)) = (s, d.effects.first()) {
                for (name, value) in comparable(case.id, &truth.effect, &truth.nuisance) {
                    if let Some(&[lo, hi]) = e.ci95.get(name) {
                        let hit = (lo..=hi).contains(&value);
                        intervals += 1;
                        covered += usize::from(hit);
                        inside.push(serde_json::json!({"param": name, "truth": value, "ci95": [lo, hi], "inside": hit}));
                    }
                }
            }
            let col = column(&d);
            let secs: f64 = d.timing.iter().map(|(_, t)| t).sum();
            eprintln!(
                "{:24} seed {seed}: {:40} {:?} ({secs:.0} s) {}",
                case.id, col, s, d.summary
            );
            let _ = writeln!(
                log,
                "{}",
                serde_json::json!({
                    "case": case.id, "seed": seed, "expected": format!("{:?}", case.expected),
                    "decision": d.decision, "column": col, "score": format!("{s:?}"),
                    "summary": d.summary, "best": d.best_candidate, "shrink": d.flagged_shrink,
                    "effects": d.effects.iter().map(|e| serde_json::json!({"id": e.id, "params": e.params, "ci95": e.ci95})).collect::<Vec<_>>(),
                    "best_params": d.best_candidate.as_ref().and_then(|b| d.candidates.iter().find(|c| &c.id == b)).map(|c| c.params.clone()),
                    "best_ci95_fitted": d.best_candidate.as_ref().and_then(|b| d.candidates.iter().find(|c| &c.id == b)).map(|c| c.ci95.clone()),
                    "noise_check": d.noise_check.as_ref().map(|c| serde_json::json!({"explained": c.explained, "summary": c.summary()})),
                    "baseline_explained": d.baseline_noise_check.explained,
                    "truth": truth.effect, "nuisance": truth.nuisance, "intervals": inside,
                    "seconds": secs, "rev": rev,
                })
            );
            *matrix
                .entry(case.id.to_string())
                .or_default()
                .entry(col)
                .or_default() += 1;
            *scores.entry(s).or_default() += 1;
            total += 1;
            right += usize::from(s.right());
            if case.expected == Expected::Outside && s == Score::NamedWrong {
                outside_named += 1;
            }
            if case.expected == Expected::Negative {
                negatives += 1;
                negatives_none += usize::from(d.decision == "none");
            }
        }
    }
    eprintln!("\nconfusion matrix (rows: truths; columns: decisions)");
    for (case, cols) in &matrix {
        let cells: Vec<String> = cols.iter().map(|(c, n)| format!("{c}: {n}")).collect();
        eprintln!("  {case:24} {}", cells.join(", "));
    }
    let wrong = scores.get(&Score::NamedWrong).copied().unwrap_or(0);
    eprintln!(
        "right {right}/{total}; confident wrong names {wrong}/{total}; outside the library \
         named {outside_named}; negatives none {negatives_none}/{negatives}; named values \
         inside their 95 % interval {covered}/{intervals}; {scores:?}"
    );
    assert!(right * 10 >= total * 9, "right {right}/{total}");
    assert!(wrong * 50 <= total, "confident wrong names {wrong}/{total}");
    assert_eq!(outside_named, 0, "effects outside the library named");
    assert!(
        covered * 10 >= intervals * 8,
        "named values inside their 95 % interval {covered}/{intervals}"
    );
    assert!(
        negatives_none * 10 >= negatives * 9,
        "none {negatives_none}/{negatives}"
    );
}

/// The mass on a soft rubber foot (seed 1), an effect the library does not hold: the
/// library's bending key takes more than half of the gap after the check (3.3×) but leaves
/// cells at several noise floors and residuals that are not white, and its refit on both
/// drops needs file values past their makers' tolerance even with the runs' evidence
/// weighted by the inverse of how much more their score varies than the noise says. The
/// decision is a partial explanation; the report's values are that tempered refit's, the
/// one moved farthest named in the summary, each listed with its tolerance.
#[test]
fn a_partial_explanation_reports_the_values_it_had_to_move() {
    let d = diagnose_case(
        "mass_pad",
        1,
        &GenOptions::default(),
        &library(&["key_flex"]),
    );
    assert_eq!(d.decision, "partly_explained", "{}", d.summary);
    assert_eq!(d.best_candidate.as_deref(), Some("key_flex"));
    assert_eq!(d.values_of, "key_flex");
    let shrink = d.flagged_shrink.expect("a best candidate's shrink");
    assert!(shrink >= 2.0, "shrink {shrink}");
    let check = d.noise_check.as_ref().expect("the candidate's noise check");
    assert!(!check.explained);
    let c = d
        .tolerated_tempered
        .expect("the refit on every run tempered");
    assert_eq!(
        d.summary
            .matches(&format!("even with the runs' evidence weighted 1/{c:.1}"))
            .count(),
        1,
        "the weighting said once: {}",
        d.summary
    );
    let p = d.tolerated_p.expect("a joint refit with a held-out run");
    assert!(p < 0.01, "the tolerated moves' probability {p}");
    // The values are the candidate's refit on both drops: the p its summary gives, and
    // its effect among the calibrated values.
    assert!(
        d.summary.contains(&format!("p {p:.1e}")),
        "p {p:.1e}: {}",
        d.summary
    );
    assert!(
        d.calibrated
            .contains_key("effects.key_flex.compliance_rad_n_m")
    );
    // The value the summary names as moved beyond its tolerance is one moved farthest
    // (ties at a bound are equal).
    let farthest = d
        .tolerated
        .values()
        .map(|f| f.ln().abs())
        .fold(0.0, f64::max);
    let clause = d
        .summary
        .split("moved beyond their tolerance (")
        .nth(1)
        .expect("the moves' clause");
    let named = d
        .tolerated
        .iter()
        .find(|(k, _)| clause.starts_with(&format!("{k} ×")))
        .map(|(_, f)| f.ln().abs())
        .expect("a tolerated value named in the summary");
    assert!((named - farthest).abs() < 1e-9, "{named} vs {farthest}");
    // The page lists every tolerated value with its tolerance, those beyond it marked,
    // and says how the refit was weighted.
    let md = markdown(&d, std::path::Path::new("mass_pad"));
    assert!(md.contains("the baseline with key_flex (the partial explanation)"));
    assert!(md.contains(&format!("weighted 1/{c:.1}")), "{md}");
    assert!(
        d.tolerated.len() >= 20,
        "{} tolerated values",
        d.tolerated.len()
    );
    assert!(d.tolerated.iter().any(|(k, v)| beyond_tolerance(k, *v)));
    for (k, v) in &d.tolerated {
        let tol = tolerance_of(k, 1.0).expect("a tolerance");
        let beyond = if beyond_tolerance(k, *v) {
            ", beyond it"
        } else {
            ""
        };
        assert!(
            md.contains(&format!(
                "`{k}` ×{v:.3} (tolerance ±{:.0} %{beyond})",
                100.0 * tol
            )),
            "{k}"
        );
    }
}

/// A shank bent at two places (seed 1: 12.5 and 10.1 N·m/rad at 50 and 110 mm), two
/// drops: the library's bending key fits the fitted drop better than its bent shank, but
/// its refit on every run leaves residuals that are not white; the bent shank, judged
/// next, explains every run. The fitted drop favours one, the noise check the other, and
/// neither says more: the outcome is an ambiguity that holds the truth, the key's failure
/// said, never the key's name (before, the key alone was judged: `partly_explained`).
#[test]
fn the_next_candidate_is_judged_when_the_fitted_drops_best_leaves_the_noise() {
    let d = diagnose_case(
        "shank_flex_two",
        1,
        &GenOptions::default(),
        &library(&["key_flex", "shank_flex"]),
    );
    assert_eq!(d.decision, "ambiguous", "{}", d.summary);
    assert_eq!(
        score(&Expected::Family("shank_flex"), &d),
        Score::AmbiguousRight
    );
    let key = d
        .candidates
        .iter()
        .find(|c| c.id == "key_flex")
        .expect("the key judged");
    let shank = d
        .candidates
        .iter()
        .find(|c| c.id == "shank_flex")
        .expect("the shank judged");
    assert!(
        key.delta_bic < shank.delta_bic,
        "the key fits the fitted drop better"
    );
    assert!(key.heldout_rms_m.is_some() && shank.heldout_rms_m.is_some());
    assert_eq!(d.best_candidate.as_deref(), Some("shank_flex"));
    assert!(d.noise_check.as_ref().is_some_and(|c| c.explained));
    assert!(
        d.summary.contains(
            "key_flex fits the fitted drop better, but its refit on every run does not \
             explain the data: residuals not white"
        ),
        "{}",
        d.summary
    );
}
