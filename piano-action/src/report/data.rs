//! The report page's data, typed: what `piano report` embeds as JSON and the page's script
//! reads (its JSDoc `ReportData` typedef in `player.js` mirrors these structs). The page
//! only draws: every name, colour, plot and headline comes from here, so the script knows
//! nothing of pianos.

use std::collections::BTreeMap;

use serde::Serialize;
use serde_json::Value;

/// Everything the page shows.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ReportData {
    /// The version of `piano` that wrote the page.
    pub version: String,
    /// The runs, each drawn in its own view and overlaid in the plots.
    pub runs: Vec<RunData>,
}

/// One run directory's data.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunData {
    /// The run's name (its folder).
    pub name: String,
    /// Its title: the mechanism and the input.
    pub title: String,
    /// The model (`double`, `pendulum`, a description's name).
    pub model: String,
    /// One line under the title: the first strike's speed, the metrics, the swing's period.
    pub headline: String,
    /// The drawing at rest: parts (outlines, the frame carrying them, thickness), contact
    /// shapes, frames (see `drawing::scene`).
    pub scene: Value,
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Each frame's motion from its rest place, per sample.
    pub carry: BTreeMap<String, Carry>,
    /// Each contact's force, point and normal, per sample.
    pub contacts: BTreeMap<String, ContactSeries>,
    /// How each contact is named for a reader.
    pub contact_labels: BTreeMap<String, String>,
    /// Each contact's colour (`#rrggbb`).
    pub contact_colors: BTreeMap<String, String>,
    /// Plotted quantities.
    pub series: Vec<Series>,
    /// The plots, in order; a series in none gets a plot of its own.
    pub plots: Vec<Plot>,
    /// Every event (`events.json`).
    pub events: Value,
    /// The events a reader should see (no releases, no chatter).
    pub listed_events: Value,
    /// What the events left out of the list are, for the page's note.
    pub minor_events: String,
    /// `summary.json`.
    pub summary: Value,
    /// Zoom presets of the 2D view (`{name: {center, half_width}}`).
    pub zoom: Value,
    /// Measured series to draw over the model's (`measured.csv`), by series id.
    pub measured: Option<BTreeMap<String, Measured>>,
}

/// A frame's motion: rotation (rad) and translation (mm) from its rest place, per sample.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Carry {
    /// Angle (rad).
    pub a: Vec<f64>,
    /// x (mm).
    pub x: Vec<f64>,
    /// y (mm).
    pub y: Vec<f64>,
}

/// A contact per sample: its normal force (N, 0 when open), the point (mm) and the unit
/// normal of the force on its second body (0 when open).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ContactSeries {
    /// Normal force (N).
    pub f: Vec<f64>,
    /// Contact point x (mm).
    pub px: Vec<f64>,
    /// Contact point y (mm).
    pub py: Vec<f64>,
    /// Normal x.
    pub nx: Vec<f64>,
    /// Normal y.
    pub ny: Vec<f64>,
}

/// A plotted quantity per sample.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Series {
    /// Its id (`hammer_speed_m_s`).
    pub id: String,
    /// Its label with the unit (`hammer speed at the strike point (m/s)`).
    pub label: String,
    /// Its values, one per sample.
    pub values: Vec<f64>,
}

impl Series {
    /// A series `id` labelled `label`.
    pub fn new(id: &str, label: &str, values: Vec<f64>) -> Self {
        Self {
            id: id.into(),
            label: label.into(),
            values,
        }
    }
}

/// A plot: lines of series (one per run each), or the contact forces.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Plot {
    /// Its id on the page (`plot-<id>`).
    pub id: String,
    /// Its title.
    pub title: String,
    /// Its lines; empty when it plots the contact forces.
    pub lines: Vec<PlotLine>,
    /// Plots every contact's force instead of series.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub contacts: bool,
}

/// A line of a plot: a series of each run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlotLine {
    /// The series' id.
    pub series: String,
    /// Words before the run's name in the legend (`kinetic`), if the plot has several.
    #[serde(skip_serializing_if = "String::is_empty")]
    pub prefix: String,
    /// Drawn dashed.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub dashed: bool,
}

impl Plot {
    /// A plot of the one series `series`, titled `title`.
    pub fn of(id: &str, title: &str, series: &str) -> Self {
        Self {
            id: id.into(),
            title: title.into(),
            lines: vec![PlotLine {
                series: series.into(),
                prefix: String::new(),
                dashed: false,
            }],
            contacts: false,
        }
    }

    /// The contact forces' plot.
    pub fn contact_forces() -> Self {
        Self {
            id: "contact-forces".into(),
            title: "Contact forces (N)".into(),
            lines: Vec::new(),
            contacts: true,
        }
    }

    /// The energies: kinetic (solid) and gravitational (dashed).
    pub fn energy(gravity_from: &str) -> Self {
        Self {
            id: "energy".into(),
            title: format!("Energy (mJ): kinetic (solid), gravity {gravity_from} (dashed)"),
            lines: vec![
                PlotLine {
                    series: "kinetic_mj".into(),
                    prefix: "kinetic".into(),
                    dashed: false,
                },
                PlotLine {
                    series: "gravity_mj".into(),
                    prefix: "gravity".into(),
                    dashed: true,
                },
            ],
            contacts: false,
        }
    }
}

/// A measured series.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Measured {
    /// Times (s).
    pub t: Vec<f64>,
    /// Values, in the series' unit.
    pub v: Vec<f64>,
}

/// `v` with `digits` significant digits, as JavaScript's `toPrecision` writes it in the
/// usual range (for headlines).
pub fn precision(v: f64, digits: i32) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let magnitude = v.abs().log10().floor() as i32;
    let decimals = (digits - 1 - magnitude).max(0) as usize;
    format!("{v:.decimals$}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn precision_counts_significant_digits() {
        assert_eq!(precision(3.66712, 4), "3.667");
        assert_eq!(precision(0.025713, 4), "0.02571");
        assert_eq!(precision(1046.72, 4), "1047");
        assert_eq!(precision(0.0, 4), "0");
    }

    #[test]
    fn flags_are_left_out_when_false() {
        let text = serde_json::to_string(&Plot::of("a", "A", "a_mm")).unwrap();
        assert!(
            !text.contains("contacts") && !text.contains("dashed"),
            "{text}"
        );
        let text = serde_json::to_string(&Plot::contact_forces()).unwrap();
        assert!(text.contains(r#""contacts":true"#), "{text}");
    }
}
