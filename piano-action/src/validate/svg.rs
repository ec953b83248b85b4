//! Small SVG charts written by hand for the validation page: axes with round ticks
//! (linear or logarithmic), lines, markers, shaded bands and error bars, and a legend. Text
//! stays text (the browser's sans-serif), so no font file is needed.

use std::fmt::Write as _;

/// One axis: its range, whether it is logarithmic, its label.
#[derive(Clone, Debug)]
pub struct Axis {
    /// Lowest value shown.
    pub lo: f64,
    /// Highest value shown.
    pub hi: f64,
    /// Logarithmic (both ends positive).
    pub log: bool,
    /// Label with unit.
    pub label: String,
}

impl Axis {
    /// A linear axis.
    pub fn linear(lo: f64, hi: f64, label: &str) -> Self {
        Axis {
            lo,
            hi,
            log: false,
            label: label.into(),
        }
    }

    /// A logarithmic axis.
    pub fn log(lo: f64, hi: f64, label: &str) -> Self {
        Axis {
            lo,
            hi,
            log: true,
            label: label.into(),
        }
    }

    /// Position of `v` along the axis, 0 at `lo` and 1 at `hi`.
    fn frac(&self, v: f64) -> f64 {
        if self.log {
            (v.ln() - self.lo.ln()) / (self.hi.ln() - self.lo.ln())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }

    /// Tick values: 1-2-5 steps (about six ticks) on a linear axis; 1, 2, 5 per decade
    /// on a log axis.
    fn ticks(&self) -> Vec<f64> {
        if self.log {
            let mut out = Vec::new();
            let mut decade = 10f64.powf(self.lo.log10().floor());
            while decade <= self.hi {
                for m in [1.0, 2.0, 5.0] {
                    let v = m * decade;
                    if v >= self.lo * (1.0 - 1e-9) && v <= self.hi * (1.0 + 1e-9) {
                        out.push(v);
                    }
                }
                decade *= 10.0;
            }
            out
        } else {
            let raw = (self.hi - self.lo) / 6.0;
            let mag = 10f64.powf(raw.log10().floor());
            let step = [1.0, 2.0, 5.0, 10.0]
                .iter()
                .map(|m| m * mag)
                .find(|s| *s >= raw)
                .unwrap_or(10.0 * mag);
            let first = (self.lo / step).ceil() as i64;
            let last = (self.hi / step + 1e-9).floor() as i64;
            (first..=last).map(|k| k as f64 * step).collect()
        }
    }
}

/// Formats a tick value without trailing zeros.
fn tick_text(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// What a series draws.
#[derive(Clone, Debug)]
pub enum Mark {
    /// A line through the points.
    Line {
        /// Dashed.
        dashed: bool,
    },
    /// A marker at each point: a filled circle, or an open one.
    Dots {
        /// Filled.
        filled: bool,
    },
    /// A shaded band between `lower` (the points) and the upper curve.
    Band {
        /// The upper edge, at the same x as the points.
        upper: Vec<(f64, f64)>,
    },
    /// A marker with a vertical error bar from `lo` to `hi` at each point.
    ErrorBars {
        /// (lo, hi) per point.
        bars: Vec<(f64, f64)>,
    },
}

/// A labelled series of points.
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// CSS colour.
    pub color: &'static str,
    /// (x, y) points.
    pub points: Vec<(f64, f64)>,
    /// How they are drawn.
    pub mark: Mark,
}

/// Where the legend goes inside the plot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Corner {
    /// Top right.
    TopRight,
    /// Bottom left.
    BottomLeft,
}

/// A chart: title, axes and series.
#[derive(Clone, Debug)]
pub struct Chart {
    /// Title above the plot.
    pub title: String,
    /// Horizontal axis.
    pub x: Axis,
    /// Vertical axis.
    pub y: Axis,
    /// What is drawn, first at the back.
    pub series: Vec<Series>,
    /// Where the legend goes.
    pub legend: Corner,
}

const WIDTH: f64 = 620.0;
const HEIGHT: f64 = 400.0;
const LEFT: f64 = 62.0;
const RIGHT: f64 = 16.0;
const TOP: f64 = 34.0;
const BOTTOM: f64 = 50.0;

/// Escapes text for SVG and HTML.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

impl Chart {
    /// Pixel position of a data point (not clamped).
    fn px(&self, (x, y): (f64, f64)) -> (f64, f64) {
        let w = WIDTH - LEFT - RIGHT;
        let h = HEIGHT - TOP - BOTTOM;
        (LEFT + self.x.frac(x) * w, TOP + (1.0 - self.y.frac(y)) * h)
    }

    /// Whether a point can be drawn (finite, positive on a log axis).
    fn drawable(&self, (x, y): (f64, f64)) -> bool {
        x.is_finite() && y.is_finite() && (!self.x.log || x > 0.0) && (!self.y.log || y > 0.0)
    }

    /// The chart as an `<svg>` element.
    pub fn svg(&self) -> String {
        let mut s = String::new();
        let _ = write!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {WIDTH} {HEIGHT}" width="{WIDTH}" height="{HEIGHT}" font-family="sans-serif" font-size="12" role="img" aria-label="{}">"#,
            escape(&self.title)
        );
        let _ = write!(
            s,
            r#"<rect width="{WIDTH}" height="{HEIGHT}" fill="white"/><text x="{}" y="20" text-anchor="middle" font-size="15" font-weight="bold">{}</text>"#,
            WIDTH / 2.0,
            escape(&self.title)
        );
        let (x0, y0, x1, y1) = (LEFT, TOP, WIDTH - RIGHT, HEIGHT - BOTTOM);
        let _ = write!(
            s,
            r##"<defs><clipPath id="{id}"><rect x="{x0}" y="{y0}" width="{}" height="{}"/></clipPath></defs>"##,
            x1 - x0,
            y1 - y0,
            id = self.clip_id()
        );
        // Grid and ticks.
        for t in self.x.ticks() {
            let (px, _) = self.px((t, self.y.lo.max(f64::MIN_POSITIVE)));
            let _ = write!(
                s,
                r##"<line x1="{px:.1}" y1="{y0}" x2="{px:.1}" y2="{y1}" stroke="#e6e6e6"/><text x="{px:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
                y1 + 16.0,
                tick_text(t)
            );
        }
        for t in self.y.ticks() {
            let (_, py) = self.px((self.x.lo.max(f64::MIN_POSITIVE), t));
            let _ = write!(
                s,
                r##"<line x1="{x0}" y1="{py:.1}" x2="{x1}" y2="{py:.1}" stroke="#e6e6e6"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
                x0 - 6.0,
                py + 4.0,
                tick_text(t)
            );
        }
        let _ = write!(
            s,
            r##"<rect x="{x0}" y="{y0}" width="{}" height="{}" fill="none" stroke="#444"/>"##,
            x1 - x0,
            y1 - y0
        );
        let _ = write!(
            s,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            (x0 + x1) / 2.0,
            HEIGHT - 12.0,
            escape(&self.x.label)
        );
        let _ = write!(
            s,
            r#"<text transform="translate(16 {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
            (y0 + y1) / 2.0,
            escape(&self.y.label)
        );
        // Series, clipped to the plot.
        let _ = write!(s, r#"<g clip-path="url(#{})">"#, self.clip_id());
        for series in &self.series {
            self.draw_series(&mut s, series);
        }
        s.push_str("</g>");
        self.legend(&mut s);
        s.push_str("</svg>");
        s
    }

    /// An id for the clip path, unique per chart title on a page.
    fn clip_id(&self) -> String {
        let slug: String = self
            .title
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect();
        format!("clip-{slug}")
    }

    fn draw_series(&self, s: &mut String, series: &Series) {
        let c = series.color;
        let points: Vec<(f64, f64)> = series
            .points
            .iter()
            .copied()
            .filter(|p| self.drawable(*p))
            .collect();
        let path = |pts: &[(f64, f64)]| {
            pts.iter()
                .map(|p| {
                    let (x, y) = self.px(*p);
                    format!("{x:.1},{y:.1}")
                })
                .collect::<Vec<_>>()
                .join(" ")
        };
        match &series.mark {
            Mark::Line { dashed } => {
                if points.len() > 1 {
                    let dash = if *dashed {
                        r#" stroke-dasharray="6 4""#
                    } else {
                        ""
                    };
                    let _ = write!(
                        s,
                        r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="2"{dash}/>"#,
                        path(&points)
                    );
                }
            }
            Mark::Dots { filled } => {
                for p in &points {
                    let (x, y) = self.px(*p);
                    let fill = if *filled { c } else { "white" };
                    let _ = write!(
                        s,
                        r#"<circle cx="{x:.1}" cy="{y:.1}" r="4" fill="{fill}" stroke="{c}" stroke-width="1.5"/>"#
                    );
                }
            }
            Mark::Band { upper } => {
                let mut outline: Vec<(f64, f64)> = series.points.clone();
                outline.extend(upper.iter().rev().copied());
                let outline: Vec<(f64, f64)> =
                    outline.into_iter().filter(|p| self.drawable(*p)).collect();
                if outline.len() > 2 {
                    let _ = write!(
                        s,
                        r#"<polygon points="{}" fill="{c}" fill-opacity="0.18" stroke="none"/>"#,
                        path(&outline)
                    );
                }
            }
            Mark::ErrorBars { bars } => {
                for (p, (lo, hi)) in series.points.iter().zip(bars) {
                    if !(self.drawable(*p)
                        && self.drawable((p.0, *lo))
                        && self.drawable((p.0, *hi)))
                    {
                        continue;
                    }
                    let (x, y) = self.px(*p);
                    let (_, ylo) = self.px((p.0, *lo));
                    let (_, yhi) = self.px((p.0, *hi));
                    let _ = write!(
                        s,
                        r#"<line x1="{x:.1}" y1="{ylo:.1}" x2="{x:.1}" y2="{yhi:.1}" stroke="{c}" stroke-width="1.5"/><line x1="{:.1}" y1="{ylo:.1}" x2="{:.1}" y2="{ylo:.1}" stroke="{c}" stroke-width="1.5"/><line x1="{:.1}" y1="{yhi:.1}" x2="{:.1}" y2="{yhi:.1}" stroke="{c}" stroke-width="1.5"/><rect x="{:.1}" y="{:.1}" width="8" height="8" fill="{c}"/>"#,
                        x - 5.0,
                        x + 5.0,
                        x - 5.0,
                        x + 5.0,
                        x - 4.0,
                        y - 4.0
                    );
                }
            }
        }
    }

    /// The legend inside the plot, in its corner: one line per labelled series.
    fn legend(&self, s: &mut String) {
        let labelled: Vec<&Series> = self.series.iter().filter(|x| !x.label.is_empty()).collect();
        if labelled.is_empty() {
            return;
        }
        let longest = labelled
            .iter()
            .map(|x| x.label.chars().count())
            .max()
            .unwrap_or(0) as f64;
        let w = 36.0 + 6.6 * longest;
        let h = 8.0 + 18.0 * labelled.len() as f64;
        let (x, y) = match self.legend {
            Corner::TopRight => (WIDTH - RIGHT - w - 8.0, TOP + 8.0),
            Corner::BottomLeft => (LEFT + 8.0, HEIGHT - BOTTOM - h - 8.0),
        };
        let _ = write!(
            s,
            r##"<rect x="{x:.1}" y="{y:.1}" width="{w:.1}" height="{h:.1}" fill="white" fill-opacity="0.9" stroke="#bbb"/>"##
        );
        for (k, series) in labelled.iter().enumerate() {
            let cy = y + 13.0 + 18.0 * k as f64;
            let c = series.color;
            let sample = match &series.mark {
                Mark::Line { dashed } => format!(
                    r#"<line x1="{:.1}" y1="{cy:.1}" x2="{:.1}" y2="{cy:.1}" stroke="{c}" stroke-width="2"{}/>"#,
                    x + 6.0,
                    x + 28.0,
                    if *dashed {
                        r#" stroke-dasharray="6 4""#
                    } else {
                        ""
                    }
                ),
                Mark::Dots { filled } => format!(
                    r#"<circle cx="{:.1}" cy="{cy:.1}" r="4" fill="{}" stroke="{c}" stroke-width="1.5"/>"#,
                    x + 17.0,
                    if *filled { c } else { "white" }
                ),
                Mark::Band { .. } => format!(
                    r#"<rect x="{:.1}" y="{:.1}" width="22" height="10" fill="{c}" fill-opacity="0.18"/>"#,
                    x + 6.0,
                    cy - 5.0
                ),
                Mark::ErrorBars { .. } => format!(
                    r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{c}" stroke-width="1.5"/><rect x="{:.1}" y="{:.1}" width="8" height="8" fill="{c}"/>"#,
                    x + 17.0,
                    cy - 7.0,
                    x + 17.0,
                    cy + 7.0,
                    x + 13.0,
                    cy - 4.0
                ),
            };
            s.push_str(&sample);
            let _ = write!(
                s,
                r#"<text x="{:.1}" y="{:.1}">{}</text>"#,
                x + 34.0,
                cy + 4.0,
                escape(&series.label)
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_numbers_inside_the_axis() {
        assert_eq!(
            Axis::linear(0.0, 250.0, "").ticks(),
            [0.0, 50.0, 100.0, 150.0, 200.0, 250.0]
        );
        assert_eq!(
            Axis::linear(-6.0, 6.0, "").ticks(),
            [-6.0, -4.0, -2.0, 0.0, 2.0, 4.0, 6.0]
        );
        assert_eq!(Axis::log(0.2, 8.0, "").ticks(), [0.2, 0.5, 1.0, 2.0, 5.0]);
    }

    #[test]
    fn a_chart_is_one_svg_element_with_its_text_escaped() {
        let c = Chart {
            title: "a < b".into(),
            x: Axis::linear(0.0, 1.0, "x"),
            y: Axis::log(1.0, 100.0, "y"),
            series: vec![Series {
                label: "model & law".into(),
                color: "#1f4e9c",
                points: vec![(0.0, 1.0), (0.5, 10.0), (1.0, -1.0)],
                mark: Mark::Line { dashed: false },
            }],
            legend: Corner::TopRight,
        };
        let svg = c.svg();
        assert!(svg.starts_with("<svg") && svg.ends_with("</svg>"));
        assert!(svg.contains("a &lt; b") && svg.contains("model &amp; law"));
        // The point with a negative value on the log axis is left out.
        assert_eq!(svg.matches("<polyline").count(), 1);
        assert!(!svg.contains("NaN") && !svg.contains("inf"));
    }
}
