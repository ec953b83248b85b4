//! A real report in headless Chromium (tests/browser/report.test.mjs, driven with
//! playwright-core): no console error, no network request, Play advances the clock (less at a
//! slower speed) and moves the hammer, the scrubber, `#t=` and plot clicks seek, the string
//! arrow shows at string contact, and no two labels on the 2D view overlap or leave it.
//! Then the report of mechanism descriptions that are not the grand action
//! (tests/browser/mechanism.test.mjs): the keyboard glockenspiel and the upright action of
//! `examples/mechanisms/`, a body moving, the strike pressed and drawn in 2D and 3D.
//!
//! Needs Node.js, Chromium (Debian's `chromium`) and `npm ci --prefix
//! piano-action/tests/browser`, which `.ci/run` installs. This test has its own `main`
//! (`harness = false`) so that what it prints is not captured: when something is missing
//! it says `SKIPPED` on the terminal of `cargo test`, and it fails instead when the
//! environment asks for it (`PIANO_BROWSER_TESTS=required`, or `CI` set, as on CI
//! services).

use std::path::PathBuf;
use std::process::{Command, ExitCode};

mod harness;
use harness::Outcome;

use piano_action::ActionParams;
use piano_action::report::write_report;
use piano_action::scenario::{Scenario, write_run_dir};

const NAME: &str = "the_report_works_in_headless_chromium";

fn main() -> ExitCode {
    harness::main(
        NAME,
        "browser",
        "see .ci/run: apt-get install chromium; npm ci --prefix piano-action/tests/browser; set \
         PIANO_BROWSER_TESTS=required to make this a failure",
        run,
    )
}

fn run() -> Outcome {
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
        let required = harness::required("PIANO_BROWSER_TESTS");
        let why = format!("the browser test needs {}", missing.join(", "));
        return if required {
            Outcome::Failed(format!(
                "{why}, and it is required here (PIANO_BROWSER_TESTS=required or CI is set)"
            ))
        } else {
            Outcome::Skipped(why)
        };
    }
    match checks(&here, &chromium).and_then(|()| mechanism_checks(&here, &chromium)) {
        Ok(()) => Outcome::Passed,
        Err(e) => Outcome::Failed(e),
    }
}

fn checks(here: &std::path::Path, chromium: &str) -> Result<(), String> {
    let root = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("browser");
    let run = root.join("struck");
    let scenario = Scenario::from_toml_str(
        "model = \"double\"\nduration_s = 0.3\n[input]\nkind = \"touch\"\nstyle = \"struck\"\nfinger_speed_m_s = 1.2\n",
    )
    .map_err(|e| e.to_string())?;
    let params = ActionParams::reference();
    let result = scenario.run(&params).map_err(|e| e.to_string())?;
    // The folder is kept between test runs: replace the last run and report.
    piano_action::scenario::prepare_run_dir(&run, true).map_err(|e| e.to_string())?;
    write_run_dir(&run, &scenario, &params, &result).map_err(|e| e.to_string())?;
    let report = root.join("report.html");
    write_report(std::slice::from_ref(&run), &report, true).map_err(|e| e.to_string())?;
    let strike = result
        .strikes
        .first()
        .ok_or("the struck touch does not strike")?;
    let shots = root.join("screenshots");
    let out = Command::new("node")
        .current_dir(here)
        .arg("report.test.mjs")
        .arg(&report)
        .arg(&shots)
        .arg(strike.time_s.to_string())
        .env("CHROMIUM", chromium)
        .output()
        .map_err(|e| format!("cannot run node: {e}"))?;
    let text = String::from_utf8_lossy(&out.stdout);
    let errors = String::from_utf8_lossy(&out.stderr);
    // What the browser saw, one check a line, and where the screenshots are.
    for line in text.lines() {
        println!("    {line}");
    }
    println!("    screenshots in {}", shots.display());
    if !out.status.success() {
        return Err(format!("browser checks failed:\n{text}\n{errors}"));
    }
    if !shots.join("02-string-contact.png").exists() {
        return Err("no screenshot 02-string-contact.png".into());
    }
    Ok(())
}

/// The report of a mechanism description's run in the browser: each description of
/// `examples/mechanisms/` with the body that must move and the contact pressed at its
/// named event.
fn mechanism_checks(here: &std::path::Path, chromium: &str) -> Result<(), String> {
    let examples = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/mechanisms");
    for (file, body, contact, event, force_n) in [
        ("glockenspiel.toml", "key", "head_bar", "strike", 6.0),
        ("upright.toml", "hammer", "hammer_string", "strike", 10.0),
    ] {
        let mechanism = piano_action::mechanism::Mechanism::load(&examples.join(file))
            .map_err(|e| e.to_string())?;
        let scenario = Scenario::for_mechanism(
            file,
            mechanism,
            piano_action::scenario::ForceSpec {
                force_n: Some(force_n),
                ramp_s: None,
                release_s: None,
                points: None,
            },
            0.1,
            5e-4,
        )
        .map_err(|e| e.to_string())?;
        let params = ActionParams::reference();
        let run = scenario
            .run_mechanism(&params, &mut |_| {})
            .map_err(|e| e.to_string())?;
        let time = run
            .events
            .iter()
            .find(|e| e.name == event)
            .map(|e| e.time_s)
            .ok_or_else(|| format!("{file}: no {event}"))?;
        let root = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("browser-mechanism");
        let dir = root.join(file.trim_end_matches(".toml"));
        piano_action::scenario::prepare_run_dir(&dir, true).map_err(|e| e.to_string())?;
        piano_action::mechanism_run::write_mechanism_run_dir(
            &dir,
            &scenario,
            &params.numerics,
            &run,
        )
        .map_err(|e| e.to_string())?;
        let report = dir.join("report.html");
        write_report(std::slice::from_ref(&dir), &report, true).map_err(|e| e.to_string())?;
        // Seek a little into the contact, where it is surely pressed.
        let shots = dir.join("screenshots");
        let out = Command::new("node")
            .current_dir(here)
            .arg("mechanism.test.mjs")
            .arg(&report)
            .arg(&shots)
            .arg(body)
            .arg((time + 2e-4).to_string())
            .arg(contact)
            .arg(event)
            .env("CHROMIUM", chromium)
            .output()
            .map_err(|e| format!("cannot run node: {e}"))?;
        let text = String::from_utf8_lossy(&out.stdout);
        println!("    {file}:");
        for line in text.lines() {
            println!("    {line}");
        }
        println!("    screenshots in {}", shots.display());
        if !out.status.success() {
            let errors = String::from_utf8_lossy(&out.stderr);
            return Err(format!("{file}: browser checks failed:\n{text}\n{errors}"));
        }
    }
    Ok(())
}
