//! The key-drive diagnosis's pages: `report.json` (the contract), `report.md` and a
//! self-contained `report.html` with the replay of the action under the measured markers
//! (baseline and corrected), each marker's gap against the noise floor, the gap per phase
//! and marker, and the candidate table.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::key_diagnose::KeyDriveDiagnosis;
use super::report::{
    FILES, OUTCOMES, calibrated_table, check_out_dir, data_items, generator_mark, noise_check_html,
    noise_check_markdown, noise_check_section, throughput_html, throughput_markdown,
};
use crate::error::{PianoError, Result};
use crate::validate::page::PAGE_STYLE;
use crate::validate::svg::{Axis, Chart, Corner, Mark, Series, escape};

/// The replay's script.
const REPLAY_JS: &str = include_str!("key_replay.js");

/// Writes the three pages of `d` into `dir` (created if missing); returns their paths.
pub fn write_key_pages(
    d: &KeyDriveDiagnosis,
    dataset: &Path,
    dir: &Path,
    force: bool,
) -> Result<Vec<PathBuf>> {
    check_out_dir(dir, force)?;
    std::fs::create_dir_all(dir).map_err(|e| PianoError::io(dir, "create the folder", e))?;
    let mut json = serde_json::to_value(d)
        .map_err(|e| PianoError::file(dir, format!("cannot encode the report: {e}")))?;
    if let Some(map) = json.as_object_mut() {
        map.insert("generator".into(), "piano diagnose".into());
        map.insert("dataset".into(), dataset.display().to_string().into());
    }
    let json = serde_json::to_string_pretty(&json)
        .map_err(|e| PianoError::file(dir, format!("cannot encode the report: {e}")))?;
    let mut written = Vec::new();
    for (name, text) in [
        (FILES[0], json + "\n"),
        (FILES[1], markdown(d, dataset)),
        (FILES[2], html(d, dataset)),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| PianoError::io(&path, "write", e))?;
        written.push(path);
    }
    Ok(written)
}

fn um(m: f64) -> String {
    if m.is_finite() {
        format!("{:.1}", m * 1e6)
    } else {
        "—".into()
    }
}

fn opt_um(m: Option<f64>) -> String {
    m.map_or("—".into(), um)
}

/// The onset in words.
fn onset_text(d: &KeyDriveDiagnosis) -> String {
    match &d.onset {
        None => "the rise-calibrated model stays within the noise everywhere".into(),
        Some(o) => {
            let after = match &o.after_event {
                Some((e, dt)) => format!(", {:.1} ms after the model's {e}", dt * 1e3),
                None => String::new(),
            };
            format!(
                "the gap leaves the noise at {:.1} ms on {} ({} phase{after})",
                o.time_s * 1e3,
                o.marker,
                o.phase
            )
        }
    }
}

/// The gap after the check's catch (m; the check and post-check phases of the fitted runs,
/// every marker), before and after, if the hammer was caught: the seed study's "after the
/// check".
pub fn post_check_gap(d: &KeyDriveDiagnosis) -> Option<(f64, f64)> {
    let fit: Vec<&str> = d
        .data
        .runs
        .iter()
        .filter(|r| r.role == "fit")
        .map(|r| r.id.as_str())
        .collect();
    let cells: Vec<_> = d
        .phases
        .iter()
        .filter(|p| {
            (p.phase == "check" || p.phase == "post_check") && fit.contains(&p.run.as_str())
        })
        .collect();
    if cells.is_empty() {
        return None;
    }
    let n = cells.len() as f64;
    let q = |f: &dyn Fn(&super::key_diagnose::PhaseGap) -> f64| {
        (cells.iter().map(|p| f(p).powi(2)).sum::<f64>() / n).sqrt()
    };
    Some((q(&|p| p.before_rms_m), q(&|p| p.after_rms_m)))
}

/// The model whose values the report gives ([`KeyDriveDiagnosis::values_of`]), in words.
pub fn model_of(d: &KeyDriveDiagnosis) -> String {
    if d.values_of == "baseline" {
        "the baseline".to_string()
    } else if d.decision == "partly_explained" {
        format!(
            "the baseline with {} (the partial explanation)",
            d.values_of
        )
    } else {
        format!("the baseline with {}", d.values_of)
    }
}

/// What the calibrated values are: with a held-out run, those of one refit on every run
/// with the values held at the file's free within their tolerance; as a paragraph (HTML
/// when `html`).
fn tolerated_text(d: &KeyDriveDiagnosis, html: bool) -> String {
    let Some(p) = d.tolerated_p else {
        return String::new();
    };
    let model = model_of(d);
    let text = format!(
        "The values of {model}, refitted once on every run, fitted and held out (each \
         held-out run's release and clock free), with the {} values the calibration holds \
         at the file's free under their makers' tolerance (friction and contact stiffness \
         ±20 %, masses ±3 %, each read as a uniform spread; searched from 1/(1 + 2 tol) \
         to 1 + 2 tol times the file's): how the model is judged on a run it was not \
         fitted to. The moves' probability, all together: p = {} (below {} the model does \
         not explain the data; one value beyond its tolerance does not reject it alone).",
        d.tolerated.len(),
        if p >= 0.1 {
            format!("{p:.2}")
        } else {
            format!("{p:.2e}")
        },
        super::key_diagnose::MOVED_P_MIN
    );
    let text = match d.tolerated_tempered {
        Some(c) => format!(
            "{text} The first such refit asked for more than the makers hold, with a score \
             that varied {c:.1} times what the noise says (the model's own error, which the \
             noise model reads as evidence): these values are those of the refit with the \
             runs' evidence weighted 1/{c:.1} (Holmes & Walker 2017, a likelihood's power \
             for a model that does not hold exactly)."
        ),
        None => text,
    };
    if html {
        format!("<p>{}</p>\n", escape(&text))
    } else {
        format!("{text}\n\n")
    }
}

/// Whether the refit moved a tolerated value beyond its tolerance (`factor` on the file's
/// value outside 1 ± tol).
pub fn beyond_tolerance(path: &str, factor: f64) -> bool {
    super::key_diagnose::tolerance_of(path, 1.0)
        .is_some_and(|tol| !(1.0 - tol - 1e-9..=1.0 + tol + 1e-9).contains(&factor))
}

/// A tolerated value's tolerance, and whether the refit moved it beyond.
fn tolerance_note(path: &str, factor: f64) -> String {
    match super::key_diagnose::tolerance_of(path, 1.0) {
        Some(tol) if beyond_tolerance(path, factor) => {
            format!("tolerance ±{:.0} %, beyond it", 100.0 * tol)
        }
        Some(tol) => format!("tolerance ±{:.0} %", 100.0 * tol),
        None => String::new(),
    }
}

/// Where a named effect's values and intervals come from: the refit on every run (with a
/// held-out run), else the fit on the fitted runs.
fn interval_source(d: &KeyDriveDiagnosis) -> String {
    if d.tolerated.is_empty() {
        "(values and 95 % intervals of the fit on the fitted runs)".to_string()
    } else {
        "(values of the refit on every run, the values the makers tolerate free within \
         their tolerance; each 95 % interval the hull of that refit's and the fit on the \
         fitted runs', which holds those values at the file's: neither alone admits the \
         model's error)"
            .to_string()
    }
}

/// The readable report.
pub fn markdown(d: &KeyDriveDiagnosis, dataset: &Path) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{}", generator_mark("report.md"));
    let _ = writeln!(s, "# Key-drive diagnosis of {}\n", dataset.display());
    let _ = writeln!(s, "**Decision: {}.** {}\n", d.decision, d.summary);
    let _ = writeln!(s, "*Outcomes.* {OUTCOMES}.\n");
    for e in &d.effects {
        let _ = write!(s, "Effect `{}`:", e.id);
        for (name, v) in &e.params {
            let ci = super::report::interval_text(e.ci95.get(name).copied());
            let _ = write!(s, " `{name}` = {v:.3e} ({ci});");
        }
        let _ = write!(s, " {}", interval_source(d));
        s.push_str("\n\n");
    }
    if let Some(x) = &d.separating_experiment {
        let _ = writeln!(
            s,
            "Cannot be told apart from {}. To separate them: {x}.\n",
            d.ambiguous_with.join(", ")
        );
    }
    if !d.at_bound.is_empty() {
        let _ = writeln!(
            s,
            "**Warning:** in {}, {} ended at the edge of its search range.\n",
            model_of(d),
            d.at_bound.join(", ")
        );
    }
    let _ = writeln!(
        s,
        "Noise floor {} µm per coordinate (AR(1) ρ = {:.2}). RMS gap per coordinate, fitted \
         runs: {} → {} µm; held-out: {} → {} µm. Flagged: the **{}** phase, worst on \
         `{}`; {}.\n",
        um(d.noise_floor_m),
        d.data.rho,
        um(d.before_rms_m),
        um(d.after_rms_m),
        opt_um(d.heldout_before_rms_m),
        opt_um(d.heldout_after_rms_m),
        d.flagged_phase,
        d.flagged_marker,
        onset_text(d)
    );
    if let Some((b, a)) = post_check_gap(d) {
        let _ = writeln!(
            s,
            "Gap after the check's catch (fitted runs, every marker): {} → {} µm ({:.1}×).\n",
            um(b),
            um(a),
            b / a.max(1e-300)
        );
    }
    s.push_str("## Gap per phase and marker (µm, before → after)\n\n| run | phase | from (ms) | to (ms) | marker | before | after |\n|---|---|---|---|---|---|---|\n");
    for p in &d.phases {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.1} | {} | {} | {} |",
            p.run,
            p.phase,
            p.t0_s * 1e3,
            p.t1_s * 1e3,
            p.marker,
            um(p.before_rms_m),
            um(p.after_rms_m)
        );
    }
    s.push('\n');
    s.push_str(&noise_check_section(
        d.best_candidate.as_deref(),
        d.noise_check.as_ref(),
        &d.baseline_noise_check,
        noise_check_markdown,
    ));
    s.push_str("\n## Candidates\n\n| effect | ΔBIC (whitened) | fit (µm) | held-out (µm) | parameters | kept | why | compute (core-s: screening + refit) |\n|---|---|---|---|---|---|---|---|\n");
    for c in &d.candidates {
        let params: Vec<String> = c
            .params
            .iter()
            .map(|(k, v)| format!("{k} = {v:.3e}"))
            .collect();
        let _ = writeln!(
            s,
            "| `{}` | {:.1} | {} | {} | {} | {} | {} | {:.1} + {:.1} |",
            c.id,
            c.delta_bic,
            um(c.fit_rms_m),
            opt_um(c.heldout_rms_m),
            params.join(", "),
            if c.kept { "yes" } else { "no" },
            c.why,
            c.screen_s,
            c.refit_s
        );
    }
    s.push_str("\n## Calibrated\n\n");
    s.push_str(&tolerated_text(d, false));
    for (k, v) in &d.calibrated {
        let _ = writeln!(s, "- `{k}` = {v:.6e}");
    }
    for (k, v) in &d.tolerated {
        let _ = writeln!(s, "- `{k}` ×{v:.3} ({})", tolerance_note(k, *v));
    }
    let _ = writeln!(
        s,
        "\nThe baseline calibration frees {}.\n\n## Where the time went\n",
        d.calibration_frees.join(", ")
    );
    s.push_str(&throughput_markdown(&d.throughput));
    s
}

fn thin(t: &[f64], v: impl Iterator<Item = f64>, step: usize) -> Vec<(f64, f64)> {
    t.iter()
        .copied()
        .zip(v)
        .step_by(step.max(1))
        .filter(|(_, y)| y.is_finite())
        .collect()
}

/// The charts: per marker of the first fitted run, its gap to the baseline and to the
/// corrected model against the noise floor; then the gap per phase.
pub fn charts(d: &KeyDriveDiagnosis) -> Vec<Chart> {
    let mut out = Vec::new();
    let sigma_um = d.noise_floor_m * 1e6;
    let Some(first) = d.data.runs.iter().find(|r| r.role == "fit") else {
        return out;
    };
    for tr in d.traces.iter().filter(|t| t.run == first.id) {
        let end = tr.t.last().copied().unwrap_or(0.3);
        let step = (tr.t.len() / 900).max(1);
        let dist = |model: &[[f64; 2]]| -> Vec<f64> {
            tr.measured
                .iter()
                .zip(model)
                .map(|(m, p)| 1e6 * (m[0] - p[0]).hypot(m[1] - p[1]))
                .collect()
        };
        let before = dist(&tr.baseline);
        let after = tr.corrected.as_deref().map(dist);
        let top = before
            .iter()
            .chain(after.iter().flatten())
            .filter(|v| v.is_finite())
            .fold(4.0 * sigma_um, |a, v| a.max(*v));
        let mut series = vec![
            Series {
                label: "noise floor (2D, 2σ)".into(),
                color: "#b9d3ea",
                points: vec![(0.0, 0.0), (end, 0.0)],
                mark: Mark::Band {
                    upper: vec![(0.0, 2.0 * sigma_um), (end, 2.0 * sigma_um)],
                },
            },
            Series {
                label: "baseline".into(),
                color: "#c0392b",
                points: thin(&tr.t, before.into_iter(), step),
                mark: Mark::Line { dashed: false },
            },
        ];
        if let Some(after) = after {
            series.push(Series {
                label: if d.decision == "partly_explained" {
                    "best candidate (not named)".into()
                } else {
                    "corrected".into()
                },
                // Purple for a candidate shown but not added, as in the replay.
                color: if d.decision == "partly_explained" {
                    "#8e44ad"
                } else {
                    "#1f77b4"
                },
                points: thin(&tr.t, after.into_iter(), step),
                mark: Mark::Line { dashed: false },
            });
        }
        out.push(Chart {
            title: format!("{}: gap at {}", tr.run, tr.marker),
            x: Axis::linear(0.0, end, "time (s)"),
            y: Axis::linear(0.0, 1.15 * top, "|measured − model| (µm)"),
            series,
            legend: Corner::TopRight,
        });
    }
    out
}

/// The self-contained HTML page.
pub fn html(d: &KeyDriveDiagnosis, dataset: &Path) -> String {
    let mut s = String::new();
    let title = format!("Key-drive diagnosis of {}", dataset.display());
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         {}\n<title>{}</title>\n\
         <style>{PAGE_STYLE}.decision{{font-size:17px;padding:8px 12px;background:#f4f8fc;border-left:4px solid #1f77b4}}\
         #replay{{width:100%;max-width:980px;height:560px;border:1px solid #ccc;display:block}}\
         .controls{{margin:6px 0}} .controls *{{margin-right:8px}} tr.beyond td{{color:#b00}}</style>\n\
         </head>\n<body>\n<h1>{}</h1>\n<p class=\"decision\"><b>Decision: {}.</b> {}</p>\n<p><i>Outcomes.</i> {}.</p>\n",
        generator_mark("report.html"),
        escape(&title),
        escape(&title),
        escape(&d.decision),
        escape(&d.summary),
        escape(OUTCOMES)
    );
    for e in &d.effects {
        let _ = write!(s, "<p>Effect <code>{}</code>: ", escape(&e.id));
        for (name, v) in &e.params {
            let ci = super::report::interval_text(e.ci95.get(name).copied());
            let _ = write!(s, "<code>{}</code> = {v:.3e} ({ci}) ", escape(name));
        }
        let _ = write!(s, "<i>{}</i>", escape(&interval_source(d)));
        s.push_str("</p>\n");
    }
    if let Some(x) = &d.separating_experiment {
        let _ = writeln!(
            s,
            "<p>Cannot be told apart from {}. To separate them: {}.</p>",
            escape(&d.ambiguous_with.join(", ")),
            escape(x)
        );
    }
    if !d.at_bound.is_empty() {
        let _ = writeln!(
            s,
            "<p><b>Warning:</b> in {}, {} ended at the edge of the search range.</p>",
            escape(&model_of(d)),
            escape(&d.at_bound.join(", "))
        );
    }
    let _ = writeln!(
        s,
        "<p>Noise floor {} µm per coordinate (AR(1) ρ = {:.2}, from the frames). RMS gap per \
         coordinate, fitted runs: {} → {} µm; held-out: {} → {} µm. Flagged: the <b>{}</b> \
         phase, worst on <code>{}</code>; {}.{}</p>",
        um(d.noise_floor_m),
        d.data.rho,
        um(d.before_rms_m),
        um(d.after_rms_m),
        opt_um(d.heldout_before_rms_m),
        opt_um(d.heldout_after_rms_m),
        escape(&d.flagged_phase),
        escape(&d.flagged_marker),
        escape(&onset_text(d)),
        post_check_gap(d).map_or(String::new(), |(b, a)| format!(
            " Gap after the check's catch: {} → {} µm ({:.1}×).",
            um(b),
            um(a),
            b / a.max(1e-300)
        ))
    );
    if let Some(replay) = &d.replay {
        s.push_str(
            "<h2>Replay</h2>\n<p>The action as the baseline (grey) and the corrected model \
             (blue; purple: the best candidate when it explains only part of the gap) move it; crosses: the models' markers; red dots: the measured markers, \
             their gap to each model magnified.</p>\n<div class=\"controls\"><select \
             id=\"replay-run\"></select><select id=\"replay-zoom\"></select><select \
             id=\"replay-gain\"></select><button id=\"replay-play\">play</button><input \
             id=\"replay-frame\" type=\"range\" min=\"0\" value=\"0\" style=\"width:360px\"><span \
             id=\"replay-time\"></span></div>\n<canvas id=\"replay\"></canvas>\n<script>\nconst \
             REPLAY = ",
        );
        s.push_str(&replay.to_string());
        s.push_str(";\n");
        s.push_str(REPLAY_JS);
        s.push_str("</script>\n");
    }
    s.push_str("<h2>Each marker's gap</h2>\n<div class=\"charts\">\n");
    for c in charts(d) {
        s.push_str(&c.svg());
        s.push('\n');
    }
    s.push_str("</div>\n<h2>Gap per phase and marker</h2>\n<table><thead><tr><th>run</th><th>phase</th><th>from (ms)</th><th>to (ms)</th><th>marker</th><th>before (µm)</th><th>after (µm)</th></tr></thead><tbody>\n");
    for p in &d.phases {
        let flagged = p.phase == d.flagged_phase && p.marker == d.flagged_marker;
        let _ = writeln!(
            s,
            "<tr{}><td>{}</td><td>{}</td><td class=\"num\">{:.1}</td><td class=\"num\">{:.1}</td><td>{}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            if flagged {
                " style=\"font-weight:bold\""
            } else {
                ""
            },
            escape(&p.run),
            escape(&p.phase),
            p.t0_s * 1e3,
            p.t1_s * 1e3,
            escape(&p.marker),
            um(p.before_rms_m),
            um(p.after_rms_m)
        );
    }
    s.push_str("</tbody></table>\n");
    s.push_str(&noise_check_section(
        d.best_candidate.as_deref(),
        d.noise_check.as_ref(),
        &d.baseline_noise_check,
        noise_check_html,
    ));
    s.push_str("<h2>Candidates</h2>\n<table><thead><tr><th>effect</th><th>ΔBIC (whitened)</th><th>fit (µm)</th><th>held-out (µm)</th><th>parameters</th><th>kept</th><th>why</th><th>compute (core-s: screening + refit)</th></tr></thead><tbody>\n");
    for c in &d.candidates {
        let params: Vec<String> = c
            .params
            .iter()
            .map(|(k, v)| format!("{k} = {v:.3e}"))
            .collect();
        let _ = writeln!(
            s,
            "<tr><td><code>{}</code></td><td class=\"num\">{:.1}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td>{}</td><td>{}</td><td>{}</td><td class=\"num\">{:.1} + {:.1}</td></tr>",
            escape(&c.id),
            c.delta_bic,
            um(c.fit_rms_m),
            opt_um(c.heldout_rms_m),
            escape(&params.join(", ")),
            if c.kept { "yes" } else { "no" },
            escape(&c.why),
            c.screen_s,
            c.refit_s
        );
    }
    s.push_str("</tbody></table>\n<h2>Calibrated</h2>\n");
    s.push_str(&tolerated_text(d, true));
    s.push_str(&calibrated_table(&d.calibrated));
    if !d.tolerated.is_empty() {
        s.push_str(
            "<p>Held at the file's, moved by the refit (factor on the file's value, and \
             the makers' tolerance):</p>\n<table><tbody>\n",
        );
        for (k, v) in &d.tolerated {
            let note = tolerance_note(k, *v);
            let _ = writeln!(
                s,
                "<tr{}><td><code>{}</code></td><td class=\"num\">×{v:.3}</td><td>{}</td></tr>",
                if beyond_tolerance(k, *v) {
                    " class=\"beyond\""
                } else {
                    ""
                },
                escape(k),
                escape(&note)
            );
        }
        s.push_str("</tbody></table>\n");
    }
    s.push_str("<p>On the rise alone:</p>\n");
    s.push_str(&calibrated_table(&d.rise_calibrated));
    s.push_str("<h2>Data and time</h2>\n<ul>\n");
    s.push_str(&data_items(&d.data));
    s.push_str("</ul>\n");
    s.push_str(&throughput_html(&d.throughput));
    s.push_str("</body>\n</html>\n");
    s
}
