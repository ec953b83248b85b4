//! Static figures of a run for papers (`piano plot RUN_DIR --format svg|png`): hammer angle,
//! hammer speed, key depth and the contact forces against time, with the let-off, string
//! contact and key bottom marked. Drawn with plotters from the same data as the report.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use serde_json::Value;

use crate::error::{PianoError, Result};

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
fn times_ms(run: &Value) -> Vec<f64> {
    run["t"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(Value::as_f64)
                .map(|t| t * 1e3)
                .collect()
        })
        .unwrap_or_default()
}

fn panels(run: &Value) -> Vec<Panel> {
    let t = times_ms(run);
    let series = |id: &str| -> Vec<(f64, f64)> {
        run["series"]
            .as_array()
            .and_then(|all| all.iter().find(|s| s["id"] == id))
            .and_then(|s| s["values"].as_array())
            .map(|v| {
                t.iter()
                    .copied()
                    .zip(v.iter().filter_map(Value::as_f64))
                    .collect()
            })
            .unwrap_or_default()
    };
    let one = |title: &str, id: &str| Panel {
        title: title.into(),
        lines: vec![(String::new(), LINE_COLORS[0], series(id))],
    };
    // Contact forces: those that carry load at some time, largest peak first.
    let mut forces: Vec<(String, Points, f64)> = run["contacts"]
        .as_object()
        .map(|m| {
            m.iter()
                .map(|(name, c)| {
                    let f: Vec<(f64, f64)> = c["f"]
                        .as_array()
                        .map(|a| {
                            t.iter()
                                .copied()
                                .zip(a.iter().filter_map(Value::as_f64))
                                .collect()
                        })
                        .unwrap_or_default();
                    let peak = f.iter().map(|p| p.1).fold(0.0, f64::max);
                    (name.replace('_', " "), f, peak)
                })
                .filter(|c| c.2 > 0.0)
                .collect()
        })
        .unwrap_or_default();
    forces.sort_by(|a, b| b.2.total_cmp(&a.2));
    vec![
        one("Hammer angle (deg)", "hammer_angle_deg"),
        one("Hammer speed at the strike point (m/s)", "hammer_speed_m_s"),
        one("Key-front depth below rest (mm)", "key_depth_mm"),
        Panel {
            title: "Contact forces (N)".into(),
            lines: forces
                .into_iter()
                .take(LINE_COLORS.len())
                .enumerate()
                .map(|(k, (name, f, _))| (name, LINE_COLORS[k], f))
                .collect(),
        },
    ]
}

/// Draws the figure on `root`.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    run: &Value,
) -> std::result::Result<(), String> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(err)?;
    let title = run["title"].as_str().unwrap_or("run");
    let root = root.titled(title, ("sans-serif", 26)).map_err(err)?;
    let t = times_ms(run);
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last()
            .copied()
            .unwrap_or(1.0)
            .max(t.first().copied().unwrap_or(0.0) + 1e-6),
    );
    // Marked events: the first let-off, string contact and key bottom.
    let marks: Vec<(f64, &str)> = ["let_off", "string_contact_start", "key_bottom"]
        .into_iter()
        .filter_map(|name| {
            run["events"]
                .as_array()?
                .iter()
                .find(|e| e["name"] == name)
                .and_then(|e| e["time_s"].as_f64())
                .map(|t| (t * 1e3, name))
        })
        .collect();
    for (area, panel) in root.split_evenly((2, 2)).iter().zip(panels(run)) {
        let values = panel.lines.iter().flat_map(|l| l.2.iter().map(|p| p.1));
        let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let (lo, hi) = if lo.is_finite() && hi > lo {
            let pad = 0.06 * (hi - lo);
            (lo - pad, hi + pad)
        } else {
            (-1.0, 1.0)
        };
        let mut chart = ChartBuilder::on(area)
            .caption(&panel.title, ("sans-serif", 20))
            .margin(12)
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
        for &(tm, _) in &marks {
            chart
                .draw_series(LineSeries::new(
                    [(tm, lo), (tm, hi)],
                    RGBColor(230, 160, 150).stroke_width(1),
                ))
                .map_err(err)?;
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
