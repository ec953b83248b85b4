//! Static figures of a run for papers (`piano plot RUN_DIR --format svg|png`): hammer angle,
//! hammer speed, key depth and the contact forces against time (those the run has: a
//! pendulum swing has only the hammer), with every strike, let-off, key bottom, check, drop,
//! jack reset and turning point marked by a line and named, without overlap, at the top of
//! the first panel. Drawn with plotters from the same data as the report.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;

use crate::error::{PianoError, Result};
use crate::report::data::RunData;

/// The file format of a figure.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics (text stays text).
    Svg,
    /// A 1600 × 1200 pixel PNG.
    Png,
}

impl Format {
    /// `"svg"` or `"png"`.
    pub fn parse(name: &str) -> Result<Format> {
        match name {
            "svg" => Ok(Format::Svg),
            "png" => Ok(Format::Png),
            other => Err(PianoError::option(
                "--format",
                format!("unknown format '{other}' (svg or png)"),
            )),
        }
    }
}

/// Where sans-serif fonts usually are (Debian, other Linux, macOS, Windows).
const FONT_PATHS: [&str; 6] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/Library/Fonts/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// Registers the text font once: `font` if given, else `PIANO_FONT`, else the first of
/// [`FONT_PATHS`] present. The figure needs one to measure and draw its labels.
fn register_font(font: Option<&Path>) -> Result<()> {
    static DONE: std::sync::OnceLock<std::result::Result<(), String>> = std::sync::OnceLock::new();
    let from_env = std::env::var_os("PIANO_FONT").map(std::path::PathBuf::from);
    let path = font.map(Path::to_path_buf).or(from_env).or_else(|| {
        FONT_PATHS
            .iter()
            .map(std::path::PathBuf::from)
            .find(|p| p.exists())
    });
    let outcome = DONE.get_or_init(|| {
        let path = path.ok_or_else(|| {
            "no font found for the figure's text: give one with --font FILE.ttf (or PIANO_FONT)"
                .to_string()
        })?;
        let bytes = std::fs::read(&path)
            .map_err(|e| format!("cannot read the font {}: {e}", path.display()))?;
        // plotters keeps fonts for the life of the program.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
            .map_err(|_| format!("{} is not a TrueType or OpenType font", path.display()))
    });
    outcome
        .clone()
        .map_err(|message| PianoError::option("--font", message))
}

/// Points of a line: time (ms) and value.
type Points = Vec<(f64, f64)>;

/// One panel: title and lines (label, colour, points).
struct Panel {
    title: String,
    lines: Vec<(String, RGBColor, Points)>,
}

const LINE_COLORS: [RGBColor; 8] = [
    RGBColor(31, 78, 156),
    RGBColor(192, 57, 43),
    RGBColor(46, 139, 87),
    RGBColor(142, 68, 173),
    RGBColor(211, 84, 0),
    RGBColor(22, 160, 133),
    RGBColor(52, 73, 94),
    RGBColor(183, 149, 11),
];

/// The run's output times (ms).
fn times_ms(run: &RunData) -> Vec<f64> {
    run.t.iter().map(|t| t * 1e3).collect()
}

/// The most series panels of a mechanism description's figure (the contact forces come
/// after them): a figure for a paper stays readable.
const MAX_MECHANISM_PANELS: usize = 5;

/// The panels that apply to the run: hammer angle, hammer speed and key depth where the run
/// has them, and the contact forces that carry load at some time (a pendulum has neither
/// key nor contacts).
fn panels(run: &RunData) -> Vec<Panel> {
    let t = times_ms(run);
    let mut out = Vec::new();
    // A mechanism description's run plots its own series (coordinates, marker speeds); the
    // grand action's, the hammer and the key.
    let ids: Vec<&str> = if run.summary["metrics"].is_array() {
        run.series
            .iter()
            .map(|s| s.id.as_str())
            .filter(|id| !id.ends_with("_mj"))
            .take(MAX_MECHANISM_PANELS)
            .collect()
    } else {
        vec!["hammer_angle_deg", "hammer_speed_m_s", "key_depth_mm"]
    };
    for id in ids {
        let Some(s) = run.series.iter().find(|s| s.id == id) else {
            continue;
        };
        let points: Points = t.iter().copied().zip(s.values.iter().copied()).collect();
        if points.is_empty() {
            continue;
        }
        // The report's label, as a title: "hammer angle (°)" → "Hammer angle (deg)".
        let label = s.label.replace("(°)", "(deg)");
        let mut title = label[..1].to_uppercase();
        title.push_str(&label[1..]);
        out.push(Panel {
            title,
            lines: vec![(String::new(), LINE_COLORS[0], points)],
        });
    }
    // Contact forces: those that carry load at some time, largest peak first.
    let mut forces: Vec<(String, Points, f64)> = run
        .contacts
        .iter()
        .map(|(name, c)| {
            let f: Points = t.iter().copied().zip(c.f.iter().copied()).collect();
            let peak = f.iter().map(|p| p.1).fold(0.0, f64::max);
            let label = run
                .contact_labels
                .get(name)
                .cloned()
                .unwrap_or_else(|| name.replace('_', " "));
            (label, f, peak)
        })
        .filter(|c| c.2 > 0.0)
        .collect();
    forces.sort_by(|a, b| b.2.total_cmp(&a.2));
    if !forces.is_empty() {
        out.push(Panel {
            title: "Contact forces (N)".into(),
            lines: forces
                .into_iter()
                .take(LINE_COLORS.len())
                .enumerate()
                .map(|(k, (name, f, _))| (name, LINE_COLORS[k], f))
                .collect(),
        });
    }
    out
}

/// A marked moment: a vertical line in every panel, named at the top of the first.
struct Mark {
    /// Time (ms).
    t: f64,
    label: String,
    color: RGBColor,
}

/// The moments marked on the figure: every strike (numbered, from the summary), and the
/// listed let-offs, key bottoms, checks, drops, jack resets and turning points (see
/// [`crate::report::listed_events`]), in time order.
fn marks(run: &RunData) -> Vec<Mark> {
    let mut out: Vec<Mark> = run.summary["strikes"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|s| s["time_s"].as_f64())
                .enumerate()
                .map(|(k, t)| Mark {
                    t: t * 1e3,
                    label: format!("strike {}", k + 1),
                    color: RGBColor(192, 57, 43),
                })
                .collect()
        })
        .unwrap_or_default();
    let described = run.summary["metrics"].is_array();
    for e in run.listed_events.as_array().into_iter().flatten() {
        if described {
            // A description's named events, each under its own name.
            if let (Some(name), Some(t)) = (e["name"].as_str(), e["time_s"].as_f64()) {
                out.push(Mark {
                    t: t * 1e3,
                    label: name.replace('_', " "),
                    color: RGBColor(52, 73, 94),
                });
            }
            continue;
        }
        let (label, color) = match e["name"].as_str() {
            Some("let_off") => ("let-off", RGBColor(22, 160, 133)),
            Some("key_bottom") => ("key bottom", RGBColor(211, 84, 0)),
            Some("check_catch") => ("check", RGBColor(183, 149, 11)),
            Some("drop") => ("drop", RGBColor(52, 73, 94)),
            Some("jack_reset") => ("jack reset", RGBColor(142, 68, 173)),
            Some("turn") => ("turn", RGBColor(176, 58, 146)),
            _ => continue,
        };
        if let Some(t) = e["time_s"].as_f64() {
            out.push(Mark {
                t: t * 1e3,
                label: label.into(),
                color,
            });
        }
    }
    out.sort_by(|a, b| a.t.total_cmp(&b.t));
    out
}

/// Places the marks' labels in rows from the top of a plot whose time axis runs over the
/// pixels `x` (left, right) from `t` (first, last, ms): each beside its line (right of it, or
/// left when it would leave the plot), in the first row where it meets no other. Returns
/// each label's left pixel and row.
fn place_marks(marks: &[Mark], widths: &[f64], x: (f64, f64), t: (f64, f64)) -> Vec<(f64, usize)> {
    const GAP: f64 = 4.0;
    let mut rows: Vec<Vec<(f64, f64)>> = Vec::new();
    marks
        .iter()
        .zip(widths)
        .map(|(m, &w)| {
            let px = x.0 + (m.t - t.0) / (t.1 - t.0) * (x.1 - x.0);
            let left = if px + GAP + w <= x.1 {
                px + GAP
            } else {
                px - GAP - w
            };
            let span = (left - GAP, left + w + GAP);
            let row = rows
                .iter()
                .position(|r| r.iter().all(|&(a, b)| span.1 <= a || b <= span.0))
                .unwrap_or(rows.len());
            if row == rows.len() {
                rows.push(Vec::new());
            }
            rows[row].push(span);
            (left, row)
        })
        .collect()
}

/// Draws the figure on `root`.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &RunData,
) -> std::result::Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let title = run.title.as_str();
    let root = root.titled(title, ("sans-serif", 26)).map_err(err)?;
    let t = times_ms(run);
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last()
            .copied()
            .unwrap_or(1.0)
            .max(t.first().copied().unwrap_or(0.0) + 1e-6),
    );
    let marks = marks(run);
    let label_font: TextStyle = ("sans-serif", 14).into_font().into();
    let widths: Vec<f64> = marks
        .iter()
        .map(|m| {
            root.estimate_text_size(&m.label, &label_font)
                .map(|(w, _)| f64::from(w))
                .map_err(err)
        })
        .collect::<std::result::Result<_, _>>()?;
    let panels = panels(run);
    let cols = panels.len().clamp(1, 2);
    let rows = panels.len().div_ceil(2).max(1);
    for (k, (area, panel)) in root
        .split_evenly((rows, cols))
        .iter()
        .zip(panels)
        .enumerate()
    {
        let values = panel.lines.iter().flat_map(|l| l.2.iter().map(|p| p.1));
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let (lo, mut hi) = if lo.is_finite() && hi > lo {
            let pad = 0.06 * (hi - lo);
            (lo - pad, hi + pad)
        } else {
            (-1.0, 1.0)
        };
        // The first panel keeps room at its top for the marks' names.
        let named = k == 0 && !marks.is_empty();
        if named {
            hi += 0.3 * (hi - lo);
        }
        let mut chart = ChartBuilder::on(area)
            .caption(&panel.title, ("sans-serif", 20))
            .margin(12)
            // Room on the right for the last time label, centred on the axis end.
            .margin_right(28)
            .x_label_area_size(36)
            .y_label_area_size(56)
            .build_cartesian_2d(t0..t1, lo..hi)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time (ms)")
            .label_style(("sans-serif", 14))
            .light_line_style(RGBColor(238, 238, 238))
            .draw()
            .map_err(err)?;
        for m in &marks {
            // Strikes stand out: the blows are what the figure is about.
            let width = if m.label.starts_with("strike") { 2 } else { 1 };
            chart
                .draw_series(LineSeries::new(
                    [(m.t, lo), (m.t, hi)],
                    m.color.mix(0.55).stroke_width(width),
                ))
                .map_err(err)?;
        }
        if named {
            let (x0, y0) = chart.backend_coord(&(t0, hi));
            let (x1, _) = chart.backend_coord(&(t1, hi));
            let base = area.get_base_pixel();
            let places = place_marks(&marks, &widths, (f64::from(x0), f64::from(x1)), (t0, t1));
            for (m, (left, row)) in marks.iter().zip(places) {
                let at = (
                    left.round() as i32 - base.0,
                    y0 + 4 + 18 * row as i32 - base.1,
                );
                area.draw(&Text::new(m.label.clone(), at, label_font.color(&m.color)))
                    .map_err(err)?;
            }
        }
        let labelled = panel.lines.iter().any(|l| !l.0.is_empty());
        for (label, color, points) in &panel.lines {
            let s = chart
                .draw_series(LineSeries::new(
                    points.iter().copied(),
                    color.stroke_width(2),
                ))
                .map_err(err)?;
            if labelled {
                let c = *color;
                s.label(label.as_str()).legend(move |(x, y)| {
                    PathElement::new([(x, y), (x + 18, y)], c.stroke_width(2))
                });
            }
        }
        if labelled {
            chart
                .configure_series_labels()
                .label_font(("sans-serif", 13))
                .background_style(WHITE.mix(0.85))
                .border_style(RGBColor(200, 200, 200))
                .position(SeriesLabelPosition::UpperRight)
                .draw()
                .map_err(err)?;
        }
    }
    root.present().map_err(err)?;
    Ok(())
}

/// Writes the figure of the run in `dir` to `out` in `format`; `font` is the TrueType
/// font for the text (found on the system when `None`).
pub fn plot_run(dir: &Path, format: Format, out: &Path, font: Option<&Path>) -> Result<()> {
    register_font(font)?;
    let run = crate::report::run_data(dir)?;
    let failed = |e: String| PianoError::file(out, format!("cannot draw: {e}"));
    match format {
        Format::Svg => draw(
            &SVGBackend::new(out, (1600, 1200)).into_drawing_area(),
            &run,
        ),
        Format::Png => draw(
            &BitMapBackend::new(out, (1600, 1200)).into_drawing_area(),
            &run,
        ),
    }
    .map_err(failed)
}
