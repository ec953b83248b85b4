//! A real report in headless Chromium (tests/browser/report.test.mjs, driven with
//! playwright-core): no console error, no network request, Play moves the hammer, the
//! scrubber, `#t=` and plot clicks seek, the string arrow shows at string contact.
//!
//! Needs Node.js, Chromium (Debian's `chromium`) and `npm ci --prefix
//! piano-action/tests/browser`, which `.ci/run` installs; there it is required
//! (`PIANO_BROWSER_TESTS=required`). Elsewhere, without them, it says so and passes.

use std::path::PathBuf;
use std::process::Command;

use piano_action::ActionParams;
use piano_action::report::write_report;
use piano_action::scenario::{Scenario, write_run_dir};

#[test]
fn the_report_works_in_headless_chromium() {
    let here = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/browser");
    let chromium = std::env::var("CHROMIUM").unwrap_or_else(|_| "/usr/bin/chromium".into());
    let node_ok = Command::new("node").arg("--version").output().is_ok();
    let missing: Vec<&str> = [
        (!node_ok).then_some("node"),
        (!PathBuf::from(&chromium).exists()).then_some("chromium"),
        (!here.join("node_modules/playwright-core").exists()).then_some("playwright-core"),
    ]
    .into_iter()
    .flatten()
    .collect();
    if !missing.is_empty() {
        let required = std::env::var("PIANO_BROWSER_TESTS").is_ok_and(|v| v == "required");
        assert!(!required, "browser test required but {missing:?} missing");
        eprintln!(
            "SKIPPED: browser test needs {missing:?} (see .ci/run: apt-get install chromium; \
             npm ci --prefix piano-action/tests/browser)"
        );
        return;
    }

    let root = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("browser");
    let run = root.join("struck");
    let scenario = Scenario::from_toml_str(
        "model = \"double\"\nduration_s = 0.3\n[input]\nkind = \"touch\"\nstyle = \"struck\"\nfinger_speed_m_s = 1.2\n",
    )
    .unwrap();
    let params = ActionParams::reference();
    let result = scenario.run(&params).unwrap();
    // The folder is kept between test runs: replace the last run and report.
    piano_action::scenario::prepare_run_dir(&run, true).unwrap();
    write_run_dir(&run, &scenario, &params, &result).unwrap();
    let report = root.join("report.html");
    write_report(std::slice::from_ref(&run), &report, true).unwrap();
    let strike = result.strikes[0].time_s;
    let shots = root.join("screenshots");
    let out = Command::new("node")
        .current_dir(&here)
        .arg("report.test.mjs")
        .arg(&report)
        .arg(&shots)
        .arg(strike.to_string())
        .env("CHROMIUM", &chromium)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    println!("{text}");
    eprintln!("{}", String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "browser checks failed:\n{text}");
    assert!(shots.join("02-string-contact.png").exists());
    eprintln!("screenshots in {}", shots.display());
}
