//! The validation pages: `validation.md` (the table in Markdown) and `validation.html`, a
//! self-contained page (no network) with the table and plots of the model's curves over
//! the published points and bands: Goebl's travel-time law, the reference contact
//! durations and rebounds, the check band, the key-bottom timing of Askenfelt & Jansson,
//! the free flight band.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::svg::{Axis, Chart, Corner, Mark, Series, escape};
use super::touches::{
    Blow, CONTACT_REFERENCE, DYNAMICS, KEY_BOTTOM_REFERENCE, Touch, goebl_travel_time_s,
};
use super::{Row, Validation};
use crate::error::{PianoError, Result};

/// The generator mark of both pages: a file without it is never replaced.
pub const GENERATOR: &str = "piano validate";

/// The files `--out DIR` writes.
pub const FILES: [&str; 2] = ["validation.md", "validation.html"];

/// Checks `dir` before the validation runs: not a file; the pages it would write absent,
/// or (with `force`) pages an earlier `piano validate` wrote. Anything else named like
/// them is never replaced.
pub fn check_out_dir(dir: &Path, force: bool) -> Result<()> {
    check_pages(dir, &FILES, GENERATOR, &generator_mark, force)
}

/// Checks folder `dir` before `command` writes its pages `files` there: not a file; each
/// page absent, or (with `force`) one `command` wrote earlier (it holds `mark(name)`).
/// Anything else named like them is never replaced.
pub(crate) fn check_pages(
    dir: &Path,
    files: &[&str],
    command: &str,
    mark: &dyn Fn(&str) -> String,
    force: bool,
) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        return Err(PianoError::option(
            "--out",
            format!("{} is a file; name a folder", dir.display()),
        ));
    }
    for name in files {
        let path = dir.join(name);
        if !path.exists() {
            continue;
        }
        let ours = std::fs::read_to_string(&path)
            .map(|t| t.contains(&mark(name)))
            .unwrap_or(false);
        if !ours {
            return Err(PianoError::file(
                &path,
                format!("exists and was not written by {command}; choose another --out"),
            ));
        }
        if !force {
            return Err(PianoError::file(
                &path,
                "exists; choose another --out, or pass --force to replace it",
            ));
        }
    }
    Ok(())
}

/// How each page marks that `piano validate` wrote it.
fn generator_mark(name: &str) -> String {
    if name.ends_with(".html") {
        format!(r#"<meta name="generator" content="{GENERATOR}">"#)
    } else {
        format!("<!-- generator: {GENERATOR} -->")
    }
}

/// Writes `validation.md` and `validation.html` of `v` into `dir` (created if missing),
/// after the same checks as [`check_out_dir`]; returns the files written.
pub fn write_pages(v: &Validation, dir: &Path, force: bool) -> Result<Vec<PathBuf>> {
    check_out_dir(dir, force)?;
    std::fs::create_dir_all(dir).map_err(|e| PianoError::io(dir, "create the folder", e))?;
    let mut written = Vec::new();
    for (name, text) in [(FILES[0], markdown(v)), (FILES[1], html(v))] {
        let path = dir.join(name);
        std::fs::write(&path, text).map_err(|e| PianoError::io(&path, "write", e))?;
        written.push(path);
    }
    Ok(written)
}

/// Escapes a Markdown table cell.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// The table in Markdown, with the notes and known deviations below it.
pub fn markdown(v: &Validation) -> String {
    let mut s = format!(
        "{}\n# Validation of the {} action against the literature\n\n\
         Written by `piano validate --out DIR`. Each row runs an experiment of \
         `literature.md` or `string_reference.md` on the model; the source column names the \
         section and its tag ([V] read, [S] secondhand, [M] recalled, [D] derived). The \
         known deviations and their reasons are in \
         `piano-action/validation/known_deviations.toml`.\n\n{}.\n\n",
        generator_mark("validation.md"),
        v.model.name(),
        v.summary()
    );
    s.push_str("| id | quantity | model | literature | unit | source | status |\n");
    s.push_str("|---|---|--:|---|---|---|---|\n");
    for r in &v.rows {
        let _ = writeln!(
            s,
            "| `{}` | {} | {} | {} | {} | {} | {} |",
            r.id,
            cell(&r.quantity),
            r.value_text(),
            cell(&r.literature),
            cell(r.unit),
            cell(&r.source),
            if r.in_band {
                "in".to_string()
            } else {
                format!("**{}**", r.status())
            }
        );
    }
    let known: Vec<&Row> = known_deviations(v).collect();
    if !known.is_empty() {
        s.push_str("\n## Known deviations\n\n");
        for r in known {
            let _ = writeln!(
                s,
                "- `{}`: {}",
                r.id,
                r.known_deviation.as_deref().unwrap_or("")
            );
        }
    }
    let noted: Vec<&Row> = v.rows.iter().filter(|r| r.note.is_some()).collect();
    if !noted.is_empty() {
        s.push_str("\n## Notes\n\n");
        for r in noted {
            let _ = writeln!(s, "- `{}`: {}", r.id, r.note.as_deref().unwrap_or(""));
        }
    }
    s
}

const STRUCK: &str = "#1f4e9c";
const PRESSED: &str = "#c0392b";
const LITERATURE: &str = "#2e8b57";
const BAND: &str = "#7f8c8d";

/// The touches of one kind with a hammer speed, sweep and matched together, by speed.
fn touches(v: &Validation, touch: Touch) -> Vec<&Blow> {
    let c = &v.curves;
    let sweep = if touch == Touch::Struck {
        &c.struck
    } else {
        &c.pressed
    };
    let mut out: Vec<&Blow> = sweep
        .iter()
        .chain(c.matched.iter().filter(|b| b.touch == touch))
        .filter(|b| b.hammer_speed_m_s.is_some())
        .collect();
    out.sort_by(|a, b| {
        let v = |x: &&Blow| x.hammer_speed_m_s.unwrap_or(0.0);
        v(a).total_cmp(&v(b))
    });
    out
}

/// (hammer speed, `f(blow)`) for the touches of `touch` where `f` gives a value.
fn curve(v: &Validation, touch: Touch, f: impl Fn(&Blow) -> Option<f64>) -> Vec<(f64, f64)> {
    touches(v, touch)
        .into_iter()
        .filter_map(|b| Some((b.hammer_speed_m_s?, f(b)?)))
        .collect()
}

/// The model's struck and pressed curves of `f` as lines with markers.
fn model_series(
    v: &Validation,
    f: impl Fn(&Blow) -> Option<f64> + Copy,
    pressed: bool,
) -> Vec<Series> {
    let mut out = Vec::new();
    let kinds: &[(Touch, &'static str)] = if pressed {
        &[(Touch::Struck, STRUCK), (Touch::Pressed, PRESSED)]
    } else {
        &[(Touch::Struck, STRUCK)]
    };
    for &(touch, color) in kinds {
        let points = curve(v, touch, f);
        out.push(Series {
            label: String::new(),
            color,
            points: points.clone(),
            mark: Mark::Line { dashed: false },
        });
        out.push(Series {
            label: format!("model, {} touches", touch.name()),
            color,
            points,
            mark: Mark::Dots {
                filled: touch == Touch::Struck,
            },
        });
    }
    out
}

/// A horizontal band from `lo` to `hi` across the speed axis.
fn flat_band(label: &str, lo: f64, hi: f64) -> Series {
    Series {
        label: label.into(),
        color: BAND,
        points: vec![(0.01, lo), (100.0, lo)],
        mark: Mark::Band {
            upper: vec![(0.01, hi), (100.0, hi)],
        },
    }
}

/// Hammer speed at the string, the x axis of every chart (m/s, log).
fn speed_axis() -> Axis {
    Axis::log(0.2, 8.0, "hammer speed at the string (m/s)")
}

/// The charts of the page.
pub fn charts(v: &Validation) -> Vec<Chart> {
    let law = |touch: Touch| -> Vec<(f64, f64)> {
        (0..=60)
            .map(|i| 0.2 * 40f64.powf(i as f64 / 60.0))
            .map(|x| (x, goebl_travel_time_s(x, touch) * 1e3))
            .filter(|p| p.1 > 0.0)
            .collect()
    };
    let scaled = |touch: Touch, k: f64| {
        law(touch)
            .iter()
            .map(|&(x, y)| (x, y * k))
            .collect::<Vec<_>>()
    };
    let mut travel = vec![
        Series {
            label: "Goebl struck: law - 20 ms +-25 % (row)".into(),
            color: LITERATURE,
            points: scaled(Touch::Struck, 0.75),
            mark: Mark::Band {
                upper: scaled(Touch::Struck, 1.25),
            },
        },
        Series {
            label: "Goebl struck: 89 ms v^-0.57 - 20 ms [M]/[S]".into(),
            color: LITERATURE,
            points: law(Touch::Struck),
            mark: Mark::Line { dashed: false },
        },
        Series {
            label: "Goebl pressed: 89 ms v^-0.57 [M]".into(),
            color: LITERATURE,
            points: law(Touch::Pressed),
            mark: Mark::Line { dashed: true },
        },
    ];
    travel.extend(model_series(v, |b| b.travel_time_s.map(|t| t * 1e3), true));

    let mut contact = vec![Series {
        label: "reference C4 (str. ref. §4.1) +-25 %".into(),
        color: LITERATURE,
        points: CONTACT_REFERENCE.iter().map(|c| (c.0, c.1)).collect(),
        mark: Mark::ErrorBars {
            bars: CONTACT_REFERENCE
                .iter()
                .map(|c| (0.75 * c.1, 1.25 * c.1))
                .collect(),
        },
    }];
    contact.extend(model_series(
        v,
        |b| b.contact_duration_s.map(|t| t * 1e3),
        false,
    ));

    let mut rebound = vec![Series {
        label: "reference C4 (str. ref. §4.1) +-25 %".into(),
        color: LITERATURE,
        points: CONTACT_REFERENCE.iter().map(|c| (c.0, c.2)).collect(),
        mark: Mark::ErrorBars {
            bars: CONTACT_REFERENCE
                .iter()
                .map(|c| (0.75 * c.2, 1.25 * c.2))
                .collect(),
        },
    }];
    rebound.extend(model_series(v, |b| b.rebound, false));

    let mut check = vec![flat_band("check 12-16 mm (Gillespie 2011)", 12.0, 16.0)];
    check.extend(model_series(v, |b| b.check_mm, true));

    let speed_of = |name: &str| DYNAMICS.iter().find(|d| d.0 == name).map_or(1.0, |d| d.1);
    let row_band = |v: &Validation, prefix: &str| -> Vec<((f64, f64), (f64, f64))> {
        ["pp", "mf", "ff"]
            .iter()
            .filter_map(|name| {
                let row = v
                    .rows
                    .iter()
                    .find(|r| r.id.starts_with(&format!("{prefix}.{name}")))?;
                match row.band {
                    super::Band::Range(lo, hi) => {
                        Some(((speed_of(name), 0.5 * (lo + hi)), (lo, hi)))
                    }
                    _ => None,
                }
            })
            .collect()
    };
    let bands = row_band(v, "key_bottom");
    let mut key_bottom = vec![
        Series {
            label: "bands of the rows (pp, mf, ff)".into(),
            color: BAND,
            points: bands.iter().map(|b| b.0).collect(),
            mark: Mark::ErrorBars {
                bars: bands.iter().map(|b| b.1).collect(),
            },
        },
        Series {
            label: "A&J, Goebl (lit. §3.1-3.2) [S]".into(),
            color: LITERATURE,
            points: KEY_BOTTOM_REFERENCE
                .iter()
                .map(|(name, ms)| (speed_of(name), *ms))
                .collect(),
            mark: Mark::Dots { filled: true },
        },
    ];
    key_bottom.extend(model_series(
        v,
        |b| b.key_bottom_minus_contact_s.map(|t| t * 1e3),
        true,
    ));

    let mut free_flight = vec![flat_band("free flight 0.5-2 mm (lit. §2)", 0.5, 2.0)];
    free_flight.extend(model_series(v, |b| b.free_flight_mm, true));

    vec![
        Chart {
            title: "Travel time (key start to string)".into(),
            x: speed_axis(),
            y: Axis::log(10.0, 500.0, "travel time (ms)"),
            series: travel,
            legend: Corner::BottomLeft,
        },
        Chart {
            title: "Hammer-string contact duration".into(),
            x: speed_axis(),
            y: Axis::linear(0.0, 4.0, "contact duration (ms)"),
            series: contact,
            legend: Corner::TopRight,
        },
        Chart {
            title: "Hammer rebound e = -v_out / v_in".into(),
            x: speed_axis(),
            y: Axis::linear(0.0, 1.2, "e"),
            series: rebound,
            legend: Corner::TopRight,
        },
        Chart {
            title: "Check distance, key held".into(),
            x: speed_axis(),
            y: Axis::linear(0.0, 30.0, "crown to string (mm)"),
            series: check,
            legend: Corner::TopRight,
        },
        Chart {
            title: "Key bottom minus string contact".into(),
            x: speed_axis(),
            y: Axis::linear(-10.0, 40.0, "key bottom - string contact (ms)"),
            series: key_bottom,
            legend: Corner::TopRight,
        },
        Chart {
            title: "Free flight after let-off".into(),
            x: speed_axis(),
            y: Axis::linear(0.0, 12.0, "crown to string at jack release (mm)"),
            series: free_flight,
            legend: Corner::TopRight,
        },
    ]
}

pub(crate) const PAGE_STYLE: &str = "body{font-family:sans-serif;margin:24px;color:#222;max-width:1400px}\
h1{font-size:22px}h2{font-size:18px;margin-top:28px}\
table{border-collapse:collapse;font-size:13px}\
th,td{border-bottom:1px solid #ddd;padding:4px 8px;text-align:left;vertical-align:top}\
th{background:#f4f4f4}td.num{text-align:right;font-variant-numeric:tabular-nums}\
td.nowrap{white-space:nowrap}td.in{color:#1e7b3c}td.known{color:#b9770e;font-weight:bold}td.out{color:#c0392b;font-weight:bold}\
.note{color:#777;font-size:11px}code{font-size:12px}\
.charts{display:flex;flex-wrap:wrap;gap:12px}.charts svg{border:1px solid #ddd;flex:1 1 520px;max-width:620px;height:auto}\
dl dt{font-weight:bold;margin-top:8px}dl dd{margin-left:16px}";

/// The self-contained HTML page: the table, the plots, the known deviations.
pub fn html(v: &Validation) -> String {
    let mut s = String::new();
    let title = format!(
        "Validation of the {} action against the literature",
        v.model.name()
    );
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         {}\n<title>{}</title>\n<style>{PAGE_STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>\n\
         <p>{}. Written by <code>piano validate --out DIR</code>. Each row runs an experiment \
         of <code>literature.md</code> or <code>string_reference.md</code> on the model; \
         the source column names the section and its tag ([V] read, [S] secondhand, [M] \
         recalled, [D] derived). Out-of-band rows listed in \
         <code>piano-action/validation/known_deviations.toml</code> are marked known.</p>\n",
        generator_mark("validation.html"),
        escape(&title),
        escape(&title),
        escape(&v.summary())
    );
    s.push_str("<h2>Plots</h2>\n<div class=\"charts\">\n");
    for chart in charts(v) {
        s.push_str(&chart.svg());
        s.push('\n');
    }
    s.push_str("</div>\n<h2>Table</h2>\n<table>\n<thead><tr><th>id</th><th>quantity</th><th>model</th><th>literature</th><th>unit</th><th>source</th><th>status</th></tr></thead>\n<tbody>\n");
    for r in &v.rows {
        let class = match (r.in_band, r.known_deviation.is_some()) {
            (true, _) => "in",
            (false, true) => "known",
            (false, false) => "out",
        };
        let note = r.note.as_deref().map_or(String::new(), |n| {
            format!("<div class=\"note\">{}</div>", escape(n))
        });
        let _ = writeln!(
            s,
            "<tr><td><code>{}</code></td><td>{}{note}</td><td class=\"num\">{}</td><td class=\"nowrap\">{}</td><td>{}</td><td>{}</td><td class=\"{class} nowrap\">{}</td></tr>",
            escape(&r.id),
            escape(&r.quantity),
            escape(&r.value_text()),
            escape(&r.literature),
            escape(r.unit),
            escape(&r.source),
            escape(r.status())
        );
    }
    s.push_str("</tbody>\n</table>\n");
    let known: Vec<&Row> = known_deviations(v).collect();
    if !known.is_empty() {
        s.push_str("<h2>Known deviations</h2>\n<dl>\n");
        for r in known {
            let _ = writeln!(
                s,
                "<dt><code>{}</code></dt><dd>{}</dd>",
                escape(&r.id),
                escape(r.known_deviation.as_deref().unwrap_or(""))
            );
        }
        s.push_str("</dl>\n");
    }
    s.push_str("</body>\n</html>\n");
    s
}

/// The rows out of band that are listed as known deviations.
fn known_deviations(v: &Validation) -> impl Iterator<Item = &Row> {
    v.rows.iter().filter(|r| r.known_deviation.is_some())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelKind;
    use crate::validate::{Band, Curves};

    fn small() -> Validation {
        let mut v = Validation {
            model: ModelKind::Double,
            rows: vec![
                Row::new(
                    "a.b",
                    "x | y",
                    Some(1.0),
                    Band::Range(0.0, 2.0),
                    "mm",
                    "s [V]",
                ),
                Row::new("c", "<z>", Some(3.0), Band::Range(0.0, 2.0), "mm", "s"),
            ],
            curves: Curves::default(),
            known_listed: true,
        };
        v.rows[1].known_deviation = Some("because".into());
        v
    }

    #[test]
    fn the_pages_carry_the_table_and_their_generator_mark() {
        let v = small();
        let md = markdown(&v);
        assert!(
            md.contains("| `a.b` | x \\| y | 1.00 | 0..2 | mm | s [V] | in |"),
            "{md}"
        );
        assert!(md.contains("**OUT (known)**") && md.contains("- `c`: because"));
        assert!(md.contains(&generator_mark("validation.md")));
        let page = html(&v);
        assert!(page.contains(&generator_mark("validation.html")));
        assert!(page.contains("&lt;z&gt;") && !page.contains("<z>"));
        assert_eq!(page.matches("<svg").count(), charts(&v).len());
        // Self-contained: nothing is fetched.
        assert!(!page.contains("src=\"http") && !page.contains("href=\"http"));
    }

    #[test]
    fn only_our_own_pages_are_replaced_and_only_with_force() {
        let dir = std::env::temp_dir().join(format!("piano-validate-page-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let v = small();
        write_pages(&v, &dir, false).unwrap();
        let e = write_pages(&v, &dir, false).unwrap_err();
        assert!(e.to_string().contains("--force"), "{e}");
        write_pages(&v, &dir, true).unwrap();
        std::fs::write(dir.join("validation.md"), "my notes").unwrap();
        let e = write_pages(&v, &dir, true).unwrap_err();
        assert!(
            e.to_string().contains("not written by piano validate"),
            "{e}"
        );
        assert_eq!(
            std::fs::read_to_string(dir.join("validation.md")).unwrap(),
            "my notes"
        );
        let file = dir.join("validation.md");
        let e = check_out_dir(&file, true).unwrap_err();
        assert!(e.to_string().contains("is a file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
