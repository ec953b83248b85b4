//! The diagnosis's pages: `report.json` (the contract), `report.md` and a self-contained
//! `report.html` with the overlays, the residuals against the noise band, the gap per
//! phase and the candidate table.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use mbs_identify::explain::{CellCheck, NoiseCheck};
use mbs_identify::work::StageWork;

use super::diagnose::Diagnosis;
use crate::error::{PianoError, Result};
use crate::validate::page::PAGE_STYLE;
use crate::validate::svg::{Axis, Chart, Corner, Mark, Series, escape};

/// The files `piano diagnose --out DIR` writes.
pub const FILES: [&str; 3] = ["report.json", "report.md", "report.html"];

/// How each page marks that `piano diagnose` wrote it.
const GENERATOR: &str = "piano diagnose";

/// Checks `dir` before a diagnosis: not a file; its pages absent, or (with `force`)
/// pages an earlier `piano diagnose` wrote. Nothing else is ever replaced.
pub fn check_out_dir(dir: &Path, force: bool) -> Result<()> {
    crate::validate::page::check_pages(dir, &FILES, GENERATOR, &generator_mark, force)
}

/// How page `name` marks that `piano diagnose` wrote it.
pub(super) fn generator_mark(name: &str) -> String {
    if name.ends_with(".json") {
        format!("\"generator\": \"{GENERATOR}\"")
    } else if name.ends_with(".html") {
        format!("<meta name=\"generator\" content=\"{GENERATOR}\">")
    } else {
        format!("<!-- generator: {GENERATOR} -->")
    }
}

/// Writes the three pages of `d` into `dir` (created if missing); returns their paths.
pub fn write_pages(d: &Diagnosis, dataset: &Path, dir: &Path, force: bool) -> Result<Vec<PathBuf>> {
    check_out_dir(dir, force)?;
    std::fs::create_dir_all(dir).map_err(|e| PianoError::io(dir, "create the folder", e))?;
    let mut json = serde_json::to_value(d)
        .map_err(|e| PianoError::file(dir, format!("cannot encode the report: {e}")))?;
    if let Some(map) = json.as_object_mut() {
        map.insert("generator".into(), GENERATOR.into());
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

/// Where the baseline's gap first leaves the noise, in words.
fn onset_text(onset_s: Option<f64>) -> String {
    match onset_s {
        None => "; the gap stays within twice the noise floor".into(),
        Some(t) if t < 0.05 => "; the gap exceeds twice the noise floor from the release".into(),
        Some(t) => format!("; the gap leaves the noise at {t:.3} s"),
    }
}

fn um(m: f64) -> String {
    format!("{:.1}", m * 1e6)
}

/// The readable report.
pub fn markdown(d: &Diagnosis, dataset: &Path) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{}", generator_mark("report.md"));
    let _ = writeln!(s, "# Diagnosis of {}\n", dataset.display());
    let _ = writeln!(s, "**Decision: {}.** {}\n", d.decision, d.summary);
    let _ = writeln!(s, "*Outcomes.* {OUTCOMES}.\n");
    if !d.at_bound.is_empty() {
        let _ = writeln!(
            s,
            "**Warning:** {} ended at the edge of the search range: check the data and the \
             parameter file.\n",
            d.at_bound.join(", ")
        );
    }
    for e in &d.effects {
        let _ = writeln!(
            s,
            "Effect `{}` at `{}` (95 % intervals: fit statistics, and for torques the \
             hammer's weighing tolerance):\n",
            e.id, e.location
        );
        for (name, v) in &e.params {
            let ci = interval_text(e.ci95.get(name).copied());
            let _ = writeln!(s, "- `{name}` = {v:.3e} ({ci})");
        }
        s.push('\n');
    }
    if !d.ambiguous_with.is_empty() {
        let _ = writeln!(
            s,
            "Cannot be told apart from: {}. To separate them: {}.\n",
            d.ambiguous_with.join(", "),
            d.separating_experiment.as_deref().unwrap_or("")
        );
    }
    let g = &d.gap;
    let _ = writeln!(
        s,
        "## Gap (RMS of measured − model, per marker coordinate)\n"
    );
    let _ = writeln!(
        s,
        "Noise floor {} µm (AR(1) ρ = {:.2}, from the frames). Fitted runs: {} → {} µm. \
         Held-out runs: {} → {} µm. Flagged phase: {}{}.\n",
        um(g.noise_floor_m),
        d.data.rho,
        um(g.before_rms_m),
        um(g.after_rms_m),
        um(g.heldout_before_rms_m),
        um(g.heldout_after_rms_m),
        g.flagged_phase,
        onset_text(g.onset_s)
    );
    let _ = writeln!(
        s,
        "| phase | from (s) | to (s) | before (µm) | after (µm) |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|");
    for p in &g.phases {
        let _ = writeln!(
            s,
            "| {} | {:.3} | {:.3} | {} | {} |",
            p.name,
            p.t0_s,
            p.t1_s,
            um(p.before_rms_m),
            um(p.after_rms_m)
        );
    }
    s.push_str(&noise_check_section(
        d.best_candidate.as_deref(),
        d.noise_check.as_ref(),
        &d.baseline_noise_check,
        noise_check_markdown,
    ));
    let _ = writeln!(s, "\n## Candidates\n");
    let _ = writeln!(
        s,
        "| effect | ΔBIC (whitened) | fit (µm) | held-out (µm) | kept | why |"
    );
    let _ = writeln!(s, "|---|---|---|---|---|---|");
    for c in &d.candidates {
        let _ = writeln!(
            s,
            "| `{}` | {:.1} | {} | {} | {} | {} |",
            c.id,
            c.delta_bic,
            um(c.fit_rms_m),
            um(c.heldout_rms_m),
            if c.kept { "yes" } else { "no" },
            c.why
        );
    }
    let _ = writeln!(s, "\n## Calibrated\n");
    for (path, v) in &d.calibrated {
        let _ = writeln!(s, "- `{path}` = {v:.6e}");
    }
    let _ = writeln!(s, "\n## Data\n");
    for r in &d.data.runs {
        let _ = writeln!(
            s,
            "- `{}` ({}): {} frames, {} with a marker lost, {} outliers left out",
            r.id, r.role, r.frames, r.lost_frames, r.outlier_frames
        );
    }
    let _ = writeln!(s, "\n## Where the time went\n");
    s.push_str(&throughput_markdown(&d.throughput));
    s
}

/// Every `step`-th point, so a chart stays light.
fn thin(t: &[f64], v: impl Iterator<Item = f64>, step: usize) -> Vec<(f64, f64)> {
    t.iter().copied().zip(v).step_by(step.max(1)).collect()
}

/// The charts: per run, the head's height and the residuals before and after against the
/// noise band; then the gap per phase.
pub fn charts(d: &Diagnosis) -> Vec<Chart> {
    let mut out = Vec::new();
    let sigma_um = d.gap.noise_floor_m * 1e6;
    for tr in &d.traces {
        let step = (tr.t.len() / 1500).max(1);
        let end = tr.t.last().copied().unwrap_or(1.0);
        let role = if tr.heldout { "held out" } else { "fitted" };
        let (lo, hi) = tr
            .measured
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let margin = 0.06 * (hi - lo).max(1e-3);
        let mut series = vec![
            Series {
                label: "measured".into(),
                color: "#999999",
                points: thin(&tr.t, tr.measured.iter().map(|v| v * 1e3), step),
                mark: Mark::Dots { filled: true },
            },
            Series {
                label: "baseline".into(),
                color: "#c0392b",
                points: thin(&tr.t, tr.baseline.iter().map(|v| v * 1e3), step),
                mark: Mark::Line { dashed: true },
            },
        ];
        if let Some(c) = &tr.corrected {
            series.push(Series {
                label: "corrected".into(),
                color: "#1f77b4",
                points: thin(&tr.t, c.iter().map(|v| v * 1e3), step),
                mark: Mark::Line { dashed: false },
            });
        }
        out.push(Chart {
            title: format!("{} ({role}): head marker height", tr.run),
            x: Axis::linear(0.0, end, "time (s)"),
            y: Axis::linear((lo - margin) * 1e3, (hi + 3.0 * margin) * 1e3, "y (mm)"),
            series,
            legend: Corner::TopRight,
        });
        let um = |v: &[f64]| v.iter().map(|x| x * 1e6).collect::<Vec<f64>>();
        let before = um(&tr.baseline_residual);
        let after = tr.corrected_residual.as_deref().map(um);
        let span = before
            .iter()
            .chain(after.iter().flatten())
            .fold(4.0 * sigma_um, |a, v| a.max(v.abs()));
        let mut series = vec![
            Series {
                label: "noise floor ±σ".into(),
                color: "#b9d3ea",
                points: vec![(0.0, -sigma_um), (end, -sigma_um)],
                mark: Mark::Band {
                    upper: vec![(0.0, sigma_um), (end, sigma_um)],
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
                label: "corrected".into(),
                color: "#1f77b4",
                points: thin(&tr.t, after.into_iter(), step),
                mark: Mark::Line { dashed: false },
            });
        }
        out.push(Chart {
            title: format!("{} ({role}): residual along the swing, head", tr.run),
            x: Axis::linear(0.0, end, "time (s)"),
            y: Axis::linear(-span, span, "measured − model (µm)"),
            series,
            legend: Corner::TopRight,
        });
    }
    let n = d.gap.phases.len() as f64;
    let top = d.gap.phases.iter().fold(2.0 * sigma_um, |a, p| {
        a.max(p.before_rms_m * 1e6).max(p.after_rms_m * 1e6)
    });
    let pts = |f: &dyn Fn(&super::diagnose::Phase) -> f64| {
        d.gap
            .phases
            .iter()
            .enumerate()
            .map(|(i, p)| (i as f64 + 1.0, f(p) * 1e6))
            .collect::<Vec<_>>()
    };
    out.push(Chart {
        title: "RMS gap per phase (numbered as in the table)".into(),
        x: Axis::linear(0.5, n + 0.5, "phase"),
        // Headroom above the points for the legend.
        y: Axis::log(0.5 * sigma_um.min(top), 20.0 * top, "RMS gap (µm)"),
        series: vec![
            Series {
                label: "noise floor".into(),
                color: "#999999",
                points: vec![(0.5, sigma_um), (n + 0.5, sigma_um)],
                mark: Mark::Line { dashed: true },
            },
            Series {
                label: "before".into(),
                color: "#c0392b",
                points: pts(&|p| p.before_rms_m),
                mark: Mark::Dots { filled: true },
            },
        ]
        .into_iter()
        .chain((!d.effects.is_empty()).then(|| Series {
            label: "after".into(),
            color: "#1f77b4",
            points: pts(&|p| p.after_rms_m),
            mark: Mark::Dots { filled: false },
        }))
        .collect(),
        legend: Corner::TopRight,
    });
    out
}

/// The self-contained HTML page.
pub fn html(d: &Diagnosis, dataset: &Path) -> String {
    let mut s = String::new();
    let title = format!("Diagnosis of {}", dataset.display());
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         {}\n<title>{}</title>\n\
         <style>{PAGE_STYLE}.decision{{font-size:17px;padding:8px 12px;background:#f4f8fc;border-left:4px solid #1f77b4}}</style>\n\
         </head>\n<body>\n<h1>{}</h1>\n<p class=\"decision\"><b>Decision: {}.</b> {}</p>\n<p><i>Outcomes.</i> {}.</p>\n",
        generator_mark("report.html"),
        escape(&title),
        escape(&title),
        escape(&d.decision),
        escape(&d.summary),
        escape(OUTCOMES)
    );
    if !d.at_bound.is_empty() {
        let _ = writeln!(
            s,
            "<p><b>Warning:</b> {} ended at the edge of the search range: check the data and \
             the parameter file.</p>",
            escape(&d.at_bound.join(", "))
        );
    }
    for e in &d.effects {
        let _ = write!(
            s,
            "<p>Effect <code>{}</code> at <code>{}</code>: ",
            escape(&e.id),
            escape(&e.location)
        );
        for (name, v) in &e.params {
            let ci = interval_text(e.ci95.get(name).copied());
            let _ = write!(s, "<code>{}</code> = {v:.3e} ({ci}) ", escape(name));
        }
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
    let g = &d.gap;
    let _ = writeln!(
        s,
        "<p>Noise floor {} µm per coordinate (AR(1) ρ = {:.2}, estimated from the frames). \
         RMS gap, fitted runs: {} → {} µm; held-out runs: {} → {} µm. Flagged phase: \
         <b>{}</b>{}.</p>",
        um(g.noise_floor_m),
        d.data.rho,
        um(g.before_rms_m),
        um(g.after_rms_m),
        um(g.heldout_before_rms_m),
        um(g.heldout_after_rms_m),
        escape(&g.flagged_phase),
        onset_text(g.onset_s)
    );
    s.push_str("<h2>Plots</h2>\n<div class=\"charts\">\n");
    for c in charts(d) {
        s.push_str(&c.svg());
        s.push('\n');
    }
    s.push_str("</div>\n<h2>Gap per phase</h2>\n<table><thead><tr><th>#</th><th>phase</th><th>from (s)</th><th>to (s)</th><th>before (µm)</th><th>after (µm)</th></tr></thead><tbody>\n");
    for (i, p) in g.phases.iter().enumerate() {
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td>{}</td><td class=\"num\">{:.3}</td><td class=\"num\">{:.3}</td><td class=\"num\">{}</td><td class=\"num\">{}</td></tr>",
            i + 1,
            escape(&p.name),
            p.t0_s,
            p.t1_s,
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
    s.push_str("<h2>Candidates</h2>\n<table><thead><tr><th>effect</th><th>ΔBIC (whitened)</th><th>fit (µm)</th><th>held-out (µm)</th><th>parameters</th><th>kept</th><th>why</th></tr></thead><tbody>\n");
    for c in &d.candidates {
        let params: Vec<String> = c
            .params
            .iter()
            .map(|(k, v)| format!("{k} = {v:.3e}"))
            .collect();
        let _ = writeln!(
            s,
            "<tr><td><code>{}</code></td><td class=\"num\">{:.1}</td><td class=\"num\">{}</td><td class=\"num\">{}</td><td>{}</td><td class=\"{}\">{}</td><td>{}</td></tr>",
            escape(&c.id),
            c.delta_bic,
            um(c.fit_rms_m),
            um(c.heldout_rms_m),
            escape(&params.join(", ")),
            if c.kept { "in" } else { "out" },
            if c.kept { "yes" } else { "no" },
            escape(&c.why)
        );
    }
    s.push_str("</tbody></table>\n<h2>Calibrated</h2>\n");
    s.push_str(&calibrated_table(&d.calibrated));
    s.push_str("<h2>Data and time</h2>\n<ul>\n");
    s.push_str(&data_items(&d.data));
    s.push_str("</ul>\n");
    s.push_str(&throughput_html(&d.throughput));
    s.push_str("</body>\n</html>\n");
    s
}

/// The work of each stage and its rates as a Markdown table.
/// What the decisions mean, for the pages (issue 33).
pub(super) const OUTCOMES: &str = "named: one effect passes the selection rules, its model \
    explains every run, fitted and held out, to the noise, and it shrinks the flagged gap at \
    least twice; ambiguous: several such effects the data cannot tell apart; \
    partly_explained: the best candidate passes the selection rules but leaves a phase \
    beyond the noise or residuals that are not white, or shrinks the flagged gap less than \
    twice, so nothing is named and nothing added; none: the calibrated model explains the \
    data to the noise already; unexplained: it does not, and no candidate passes the \
    selection rules";

/// The noise check of the best candidate's model when there is one, else the baseline's,
/// rendered by `render` ([`noise_check_markdown`] or [`noise_check_html`]).
pub(super) fn noise_check_section(
    best: Option<&str>,
    check: Option<&NoiseCheck>,
    baseline: &NoiseCheck,
    render: fn(&str, &NoiseCheck) -> String,
) -> String {
    match check {
        Some(c) => render(
            &format!(
                "Does {} explain the data to the noise?",
                best.unwrap_or("the best candidate")
            ),
            c,
        ),
        None => render(
            "Does the calibrated baseline explain the data to the noise?",
            baseline,
        ),
    }
}

/// The test a name must pass, in Markdown: whether the model (the best candidate's, or
/// the baseline's) explains every run to the noise, and the cells and whiteness tests that
/// fail.
pub(super) fn noise_check_markdown(title: &str, c: &NoiseCheck) -> String {
    let mut s = format!(
        "## {title}

Every phase and marker within {} noise floors (whitened RMS, \
         significant for the phase's size; phases under 10 ms judged with the next) and \
         white residuals (Ljung–Box after an AR(1) of their own): **{}**.\n\n",
        c.floors,
        c.summary()
    );
    let failing: Vec<&CellCheck> = c.cells.iter().filter(|x| x.fails).collect();
    if !failing.is_empty() {
        s.push_str("| run | phase | marker | from (ms) | to (ms) | plain (floors) | whitened | p |\n|---|---|---|---|---|---|---|---|\n");
        for x in failing {
            let _ = writeln!(
                s,
                "| {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.2} | {:.1e} |",
                x.run,
                x.phase,
                x.marker,
                x.t0_s * 1e3,
                x.t1_s.min(1e3) * 1e3,
                x.floors,
                x.whitened_rms,
                x.p_value
            );
        }
        s.push('\n');
    }
    for w in &c.not_white {
        let _ = writeln!(
            s,
            "- not white: `{}` in {} (Ljung–Box Q = {:.0} over {} lags, p = {:.1e})",
            w.marker, w.run, w.q, w.lags, w.p_value
        );
    }
    s
}

/// [`noise_check_markdown`] for the HTML page.
pub(super) fn noise_check_html(title: &str, c: &NoiseCheck) -> String {
    let mut s = format!(
        "<h2>{}</h2>\n<p>Every phase and marker within {} noise floors (whitened RMS, \
         significant for the phase's size; phases under 10 ms judged with the next) and \
         white residuals (Ljung–Box after an AR(1) of their own): <b>{}</b>.</p>\n",
        escape(title),
        c.floors,
        escape(&c.summary())
    );
    let failing: Vec<&CellCheck> = c.cells.iter().filter(|x| x.fails).collect();
    if !failing.is_empty() {
        s.push_str("<table><tr><th>run</th><th>phase</th><th>marker</th><th>from (ms)</th><th>to (ms)</th><th>plain (floors)</th><th>whitened</th><th>p</th></tr>\n");
        for x in failing {
            let _ = writeln!(
                s,
                "<tr><td>{}</td><td>{}</td><td>{}</td><td>{:.1}</td><td>{:.1}</td><td>{:.1}</td><td>{:.2}</td><td>{:.1e}</td></tr>",
                escape(&x.run),
                escape(&x.phase),
                escape(&x.marker),
                x.t0_s * 1e3,
                x.t1_s.min(1e3) * 1e3,
                x.floors,
                x.whitened_rms,
                x.p_value
            );
        }
        s.push_str("</table>\n");
    }
    for w in &c.not_white {
        let _ = writeln!(
            s,
            "<p>Not white: <code>{}</code> in {} (Ljung–Box Q = {:.0} over {} lags, p = {:.1e})</p>",
            escape(&w.marker),
            escape(&w.run),
            w.q,
            w.lags,
            w.p_value
        );
    }
    s
}

/// The throughput table of a diagnosis's stages, in Markdown.
pub(super) fn throughput_markdown(stages: &[StageWork]) -> String {
    let mut s = String::from(
        "| stage | wall (s) | fits | evaluations | simulations | fits/s | simulations/s |\n\
         |---|---:|---:|---:|---:|---:|---:|\n",
    );
    for w in stages {
        let _ = writeln!(s, "| {} |", throughput_cells(w, &w.stage).join(" | "));
    }
    s
}

/// A stage's row: its name as given, wall time, fits, evaluations, simulations and rates.
fn throughput_cells(w: &StageWork, stage: &str) -> [String; 7] {
    [
        stage.to_string(),
        format!("{:.1}", w.wall_s),
        w.fits.to_string(),
        w.evaluations.to_string(),
        w.simulations.to_string(),
        format!("{:.2}", w.fits_per_s),
        format!("{:.1}", w.simulations_per_s),
    ]
}

/// The work of each stage and its rates as an HTML table.
pub(super) fn throughput_html(stages: &[StageWork]) -> String {
    let mut s = String::from(
        "<table><thead><tr><th>stage</th><th>wall (s)</th><th>fits</th><th>evaluations</th>\
         <th>simulations</th><th>fits/s</th><th>simulations/s</th></tr></thead><tbody>\n",
    );
    for w in stages {
        let [stage, numbers @ ..] = throughput_cells(w, &escape(&w.stage));
        let _ = write!(s, "<tr><td>{stage}</td>");
        for n in numbers {
            let _ = write!(s, "<td class=\"num\">{n}</td>");
        }
        s.push_str("</tr>\n");
    }
    s.push_str("</tbody></table>\n");
    s
}

/// The stages that did fits, and the total, a line each, for a terminal (see
/// [`StageWork::line`]).
pub fn throughput_lines(stages: &[StageWork]) -> Vec<String> {
    stages
        .iter()
        .filter(|w| w.fits > 0 || w.stage == "total")
        .map(StageWork::line)
        .collect()
}

/// The calibrated values as an HTML table.
pub(super) fn calibrated_table(values: &std::collections::BTreeMap<String, f64>) -> String {
    let mut s = String::from("<table><tbody>\n");
    for (path, v) in values {
        let _ = writeln!(
            s,
            "<tr><td><code>{}</code></td><td class=\"num\">{v:.6e}</td></tr>",
            escape(path)
        );
    }
    s.push_str("</tbody></table>\n");
    s
}

/// The data check's runs as HTML list items.
pub(super) fn data_items(data: &super::data_check::DataCheck) -> String {
    let mut s = String::new();
    for r in &data.runs {
        let _ = writeln!(
            s,
            "<li><code>{}</code> ({}): {} frames, {} with a marker lost, {} outliers left out</li>",
            escape(&r.id),
            r.role,
            r.frames,
            r.lost_frames,
            r.outlier_frames
        );
    }
    s
}

/// A value's 95 % interval as the reports print it, or that it has none (a value set by
/// a fit that gives no covariance, such as the refit on every run, or a singular one)
/// rather than "NaN to NaN".
pub(super) fn interval_text(ci: Option<[f64; 2]>) -> String {
    match ci {
        Some([lo, hi]) if lo.is_finite() && hi.is_finite() => {
            format!("95 %: {lo:.3e} to {hi:.3e}")
        }
        _ => "no 95 % interval".to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::interval_text;

    /// A value without an interval says so; one with an interval prints both ends.
    #[test]
    fn a_missing_interval_is_said_not_printed_as_nan() {
        assert_eq!(
            interval_text(Some([1e-3, 2e-3])),
            "95 %: 1.000e-3 to 2.000e-3"
        );
        for missing in [None, Some([f64::NAN, f64::NAN]), Some([1.0, f64::NAN])] {
            assert_eq!(interval_text(missing), "no 95 % interval");
        }
    }
}
