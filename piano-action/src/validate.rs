//! Validation against the literature (`piano validate`): every experiment of
//! `literature.md` and `string_reference.md` that a model can reproduce, run on the model
//! and set beside the published value or band, one [`Row`] each.
//!
//! The experiments are in [`experiments`] (regulation, touchweight, lever ratio, slow
//! press, repetition, the 1 kg drop, the swing test), [`touches`] (touches from soft to
//! loud: velocity range, free flight, travel time, key bottom, hammer–string contact,
//! check) and `motions.rs` (prescribed key motions and their control); the Markdown and HTML pages, with the model's curves over the published
//! points, in [`page`]. A row whose model value lies outside its band is *out of band*; the
//! rows the reference action is known to miss, and why, are listed in
//! `piano-action/validation/known_deviations.toml` ([`KNOWN_DEVIATIONS_TOML`]), which
//! [`Validation::apply_known`] reads into [`Row::known_deviation`].
//!
//! ```no_run
//! use piano_action::validate::{validate, known_deviations};
//! use piano_action::{ActionParams, ModelKind};
//!
//! let mut v = validate(&ActionParams::reference(), ModelKind::Double)?;
//! v.apply_known(&known_deviations()?);
//! print!("{}", v.table());
//! # Ok::<(), piano_action::PianoError>(())
//! ```

pub mod experiments;
mod motions;
pub mod page;
pub(crate) mod svg;
pub mod touches;

use serde::Deserialize;
use serde_json::{Value, json};

use crate::action::ModelKind;
use crate::error::{PianoError, Result};
use crate::params::ActionParams;

pub use experiments::validate;
pub use touches::{Blow, Curves, Touch};

/// What the literature says a quantity should be.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Band {
    /// From `lo` to `hi`, both included.
    Range(f64, f64),
    /// At least this.
    AtLeast(f64),
    /// Exactly this (a count).
    Exactly(f64),
    /// Within `tolerance` (a fraction: 0.25 for ±25 %) of `reference`.
    Relative {
        /// The published value.
        reference: f64,
        /// Allowed relative deviation.
        tolerance: f64,
    },
}

impl Band {
    /// Whether `value` is in the band (a missing value never is).
    pub fn contains(&self, value: Option<f64>) -> bool {
        let Some(v) = value.filter(|v| v.is_finite()) else {
            return false;
        };
        match *self {
            Band::Range(lo, hi) => lo <= v && v <= hi,
            Band::AtLeast(lo) => v >= lo,
            Band::Exactly(x) => v == x,
            Band::Relative {
                reference,
                tolerance,
            } => (v - reference).abs() <= tolerance * reference.abs(),
        }
    }

    /// The band as the table writes it: `0.5-2`, `>= 1`, `0`, `2.54 +-25 %`.
    pub fn describe(&self) -> String {
        match *self {
            Band::Range(lo, hi) => format!("{}..{}", num(lo), num(hi)),
            Band::AtLeast(lo) => format!(">= {}", num(lo)),
            Band::Exactly(x) => num(x),
            Band::Relative {
                reference,
                tolerance,
            } => format!("{} +-{} %", num(reference), num(tolerance * 100.0)),
        }
    }
}

/// A number as short as it can be written exactly to 3 decimals: `2`, `0.5`, `-3`, `2.54`.
fn num(v: f64) -> String {
    let s = format!("{v:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// One line of the validation: a quantity the model gives beside what the literature says.
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// Stable name (`regulation.key_dip`, `contact.duration.2`): the key of the
    /// known-deviations file.
    pub id: String,
    /// What is compared, in words.
    pub quantity: String,
    /// The model's value; `None` when the experiment could not produce it ([`Row::note`]
    /// says why).
    pub model_value: Option<f64>,
    /// The literature's value or band.
    pub band: Band,
    /// The band as written in the table (usually [`Band::describe`]).
    pub literature: String,
    /// Unit of the value and the band.
    pub unit: &'static str,
    /// Where the band comes from, with its tag (\[V\] read, \[S\] secondhand, \[M\]
    /// recalled, \[D\] derived).
    pub source: String,
    /// Whether the value is in the band.
    pub in_band: bool,
    /// Why the row is out of band, when it is listed in the known-deviations file.
    pub known_deviation: Option<String>,
    /// How the value was obtained, or why there is none.
    pub note: Option<String>,
    /// Decimals shown in the tables.
    pub decimals: usize,
}

impl Row {
    /// A row with its value judged against its band.
    pub fn new(
        id: impl Into<String>,
        quantity: impl Into<String>,
        model_value: Option<f64>,
        band: Band,
        unit: &'static str,
        source: impl Into<String>,
    ) -> Self {
        let model_value = model_value.filter(|v| v.is_finite());
        Row {
            id: id.into(),
            quantity: quantity.into(),
            model_value,
            band,
            literature: band.describe(),
            unit,
            source: source.into(),
            in_band: band.contains(model_value),
            known_deviation: None,
            note: None,
            decimals: 2,
        }
    }

    /// Writes the band differently in the tables.
    pub fn literature(mut self, text: impl Into<String>) -> Self {
        self.literature = text.into();
        self
    }

    /// Adds a note (how the value was measured, why it is missing).
    pub fn note(mut self, text: impl Into<String>) -> Self {
        self.note = Some(text.into());
        self
    }

    /// Shows the value with `decimals` decimals.
    pub fn decimals(mut self, decimals: usize) -> Self {
        self.decimals = decimals;
        self
    }

    /// The value as the tables show it (`-` when missing).
    pub fn value_text(&self) -> String {
        self.model_value
            .map_or("-".into(), |v| format!("{v:.*}", self.decimals))
    }

    /// `in`, `OUT (known)` or `OUT`.
    pub fn status(&self) -> &'static str {
        match (self.in_band, &self.known_deviation) {
            (true, _) => "in",
            (false, Some(_)) => "OUT (known)",
            (false, None) => "OUT",
        }
    }
}

/// The validation of one model.
#[derive(Clone, Debug)]
pub struct Validation {
    /// Which model.
    pub model: ModelKind,
    /// The rows, grouped by experiment.
    pub rows: Vec<Row>,
    /// The touches from soft to loud behind the rows, for the page's plots.
    pub curves: Curves,
    /// Whether known deviations were applied and some are listed for this model.
    pub known_listed: bool,
}

/// One entry of the known-deviations file.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KnownDeviation {
    /// The row's id.
    pub id: String,
    /// Why the model is out of band: the physics cause as far as known, and the
    /// literature's own uncertainty.
    pub reason: String,
    /// The models it applies to (default: `["double"]`, the reference model).
    #[serde(default = "default_models")]
    pub models: Vec<String>,
}

fn default_models() -> Vec<String> {
    vec!["double".into()]
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DeviationFile {
    #[serde(default)]
    deviation: Vec<KnownDeviation>,
}

/// The known-deviations file of the reference action
/// (`piano-action/validation/known_deviations.toml`), embedded.
pub const KNOWN_DEVIATIONS_TOML: &str = include_str!("../validation/known_deviations.toml");

/// Parses a known-deviations file (`[[deviation]]` tables with `id`, `reason` and
/// optionally `models`); an error names the field and its line. An id listed twice for one
/// model is refused.
pub fn parse_known_deviations(text: &str) -> Result<Vec<KnownDeviation>> {
    let file_error = |line: Option<usize>, field: &str, message: &str| {
        let mut at = String::new();
        if let Some(l) = line {
            at.push_str(&format!("line {l}, "));
        }
        if !field.is_empty() {
            at.push_str(&format!("field `{field}`: "));
        }
        PianoError::file(
            std::path::Path::new(KNOWN_DEVIATIONS_PATH),
            format!("{at}{message}"),
        )
    };
    let file: DeviationFile = crate::toml_lines::from_toml(text, crate::InputKind::Option)
        .map_err(|e| match e.as_input() {
            Some(b) => file_error(b.line, &b.field, &b.message),
            None => e,
        })?;
    let mut seen = std::collections::BTreeSet::new();
    for (i, d) in file.deviation.iter().enumerate() {
        let line = |key: &str| crate::toml_lines::line_of(text, &format!("deviation[{i}].{key}"));
        for m in &d.models {
            if !ModelKind::ALL.iter().any(|k| k.name() == m) {
                return Err(file_error(
                    line("models"),
                    &format!("deviation[{i}].models"),
                    &format!("unknown model '{m}' (simplified, single or double)"),
                ));
            }
            if !seen.insert((m.clone(), d.id.clone())) {
                return Err(file_error(
                    line("id"),
                    &format!("deviation[{i}].id"),
                    &format!("'{}' is listed twice for {m}", d.id),
                ));
            }
        }
    }
    Ok(file.deviation)
}

/// Where the known-deviations file is in the repository.
pub const KNOWN_DEVIATIONS_PATH: &str = "piano-action/validation/known_deviations.toml";

/// The embedded known deviations of the reference action.
pub fn known_deviations() -> Result<Vec<KnownDeviation>> {
    parse_known_deviations(KNOWN_DEVIATIONS_TOML)
}

impl Validation {
    /// Fills [`Row::known_deviation`] of the out-of-band rows listed in `known` for this
    /// model (rows in band keep `None`: see [`Validation::stale`]).
    pub fn apply_known(&mut self, known: &[KnownDeviation]) {
        let name = self.model.name();
        self.known_listed = known.iter().any(|d| d.models.iter().any(|m| m == name));
        for row in &mut self.rows {
            row.known_deviation = if row.in_band {
                None
            } else {
                known
                    .iter()
                    .find(|d| d.id == row.id && d.models.iter().any(|m| m == name))
                    .map(|d| d.reason.clone())
            };
        }
    }

    /// The rows out of band that `known` does not list for this model.
    pub fn unlisted(&self, known: &[KnownDeviation]) -> Vec<&Row> {
        let name = self.model.name();
        self.rows
            .iter()
            .filter(|r| {
                !r.in_band
                    && !known
                        .iter()
                        .any(|d| d.id == r.id && d.models.iter().any(|m| m == name))
            })
            .collect()
    }

    /// The ids `known` lists for this model whose row is in band (or does not exist): stale
    /// entries to remove from the file.
    pub fn stale<'a>(&self, known: &'a [KnownDeviation]) -> Vec<&'a str> {
        let name = self.model.name();
        known
            .iter()
            .filter(|d| d.models.iter().any(|m| m == name))
            .filter(|d| !self.rows.iter().any(|r| r.id == d.id && !r.in_band))
            .map(|d| d.id.as_str())
            .collect()
    }

    /// Counts: (rows, in band, out of band and listed, out of band and not listed).
    pub fn counts(&self) -> (usize, usize, usize, usize) {
        let inside = self.rows.iter().filter(|r| r.in_band).count();
        let known = self
            .rows
            .iter()
            .filter(|r| !r.in_band && r.known_deviation.is_some())
            .count();
        let n = self.rows.len();
        (n, inside, known, n - inside - known)
    }

    /// The count line under the tables.
    pub fn summary(&self) -> String {
        let (n, inside, known, unlisted) = self.counts();
        let mut s = format!(
            "{n} rows: {inside} in band, {} out of band ({known} known deviations, {unlisted} not listed)",
            known + unlisted
        );
        if !self.known_listed {
            s.push_str(&format!(
                "; no known deviations are listed for the {} action",
                self.model.name()
            ));
        }
        s
    }

    /// The terminal table: aligned columns, then the notes and the count line.
    pub fn table(&self) -> String {
        let head = [
            "id",
            "quantity",
            "model",
            "literature",
            "unit",
            "source",
            "status",
        ];
        let cells: Vec<[String; 7]> = self
            .rows
            .iter()
            .map(|r| {
                [
                    r.id.clone(),
                    r.quantity.clone(),
                    r.value_text(),
                    r.literature.clone(),
                    r.unit.to_string(),
                    r.source.clone(),
                    r.status().to_string(),
                ]
            })
            .collect();
        let mut width = head.map(|h| h.chars().count());
        for row in &cells {
            for (w, c) in width.iter_mut().zip(row) {
                *w = (*w).max(c.chars().count());
            }
        }
        let line = |row: &[String; 7]| {
            let mut s = String::new();
            for (k, (cell, w)) in row.iter().zip(width).enumerate() {
                let pad = w - cell.chars().count();
                // Numbers right-aligned, text left-aligned.
                if k == 2 {
                    s.push_str(&" ".repeat(pad));
                    s.push_str(cell);
                } else {
                    s.push_str(cell);
                    if k + 1 < row.len() {
                        s.push_str(&" ".repeat(pad));
                    }
                }
                if k + 1 < row.len() {
                    s.push_str("  ");
                }
            }
            s.trim_end().to_string() + "\n"
        };
        let mut out = format!(
            "Validation of the {} action against the literature\n\n",
            self.model.name()
        );
        out.push_str(&line(&head.map(String::from)));
        out.push_str(&line(&width.map(|w| "-".repeat(w))));
        for row in &cells {
            out.push_str(&line(row));
        }
        let notes: Vec<String> = self
            .rows
            .iter()
            .filter(|r| r.model_value.is_none())
            .map(|r| format!("  {}: {}\n", r.id, r.note.as_deref().unwrap_or("no value")))
            .collect();
        if !notes.is_empty() {
            out.push_str("\nNo value:\n");
            out.extend(notes);
        }
        out.push('\n');
        out.push_str(&self.summary());
        out.push('\n');
        out
    }

    /// The JSON of `piano validate --json`: `{"model", "rows": [{"id", "quantity",
    /// "model_value", "literature", "unit", "source", "in_band", "known_deviation",
    /// "note"}]}`; `model_value` is `null` when the experiment gave none (the `note` says
    /// why), `known_deviation` `null` or the reason.
    pub fn to_json(&self) -> Value {
        json!({
            "model": self.model.name(),
            "rows": self.rows.iter().map(|r| json!({
                "id": r.id,
                "quantity": r.quantity,
                "model_value": r.model_value,
                "literature": r.literature,
                "unit": r.unit,
                "source": r.source,
                "in_band": r.in_band,
                "known_deviation": r.known_deviation,
                "note": r.note,
            })).collect::<Vec<_>>(),
        })
    }
}

/// Validates `kind` built from `params` and marks the known deviations of the reference
/// action: what `piano validate` prints.
pub fn validate_with_known(params: &ActionParams, kind: ModelKind) -> Result<Validation> {
    let known = known_deviations()?;
    let mut v = validate(params, kind)?;
    v.apply_known(&known);
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_include_their_ends_and_refuse_a_missing_value() {
        let r = Band::Range(0.5, 2.0);
        assert!(r.contains(Some(0.5)) && r.contains(Some(2.0)) && r.contains(Some(1.0)));
        assert!(!r.contains(Some(0.49)) && !r.contains(Some(2.01)));
        assert!(!r.contains(None) && !r.contains(Some(f64::NAN)));
        let rel = Band::Relative {
            reference: 2.0,
            tolerance: 0.25,
        };
        assert!(rel.contains(Some(1.5)) && rel.contains(Some(2.5)));
        assert!(!rel.contains(Some(1.49)) && !rel.contains(Some(2.51)));
        assert!(Band::AtLeast(1.0).contains(Some(3.0)) && !Band::AtLeast(1.0).contains(Some(0.0)));
        assert!(Band::Exactly(1.0).contains(Some(1.0)) && !Band::Exactly(1.0).contains(Some(2.0)));
        assert_eq!(r.describe(), "0.5..2");
        assert_eq!(rel.describe(), "2 +-25 %");
        assert_eq!(Band::Range(-5.0, -3.0).describe(), "-5..-3");
        assert_eq!(Band::AtLeast(1.0).describe(), ">= 1");
    }

    fn rows() -> Validation {
        Validation {
            model: ModelKind::Double,
            rows: vec![
                Row::new("a", "in", Some(1.0), Band::Range(0.0, 2.0), "mm", "s"),
                Row::new("b", "out", Some(3.0), Band::Range(0.0, 2.0), "mm", "s"),
                Row::new("c", "none", None, Band::Range(0.0, 2.0), "mm", "s").note("why"),
            ],
            curves: Curves::default(),
            known_listed: false,
        }
    }

    #[test]
    fn known_deviations_mark_out_of_band_rows_and_stale_entries_are_found() {
        let known = parse_known_deviations(
            "[[deviation]]\nid = \"b\"\nreason = \"felt\"\n\n[[deviation]]\nid = \"a\"\nreason = \"old\"\n\n[[deviation]]\nid = \"c\"\nreason = \"x\"\nmodels = [\"single\"]\n",
        )
        .unwrap();
        let mut v = rows();
        v.apply_known(&known);
        assert_eq!(v.rows[0].known_deviation, None);
        assert_eq!(v.rows[1].known_deviation.as_deref(), Some("felt"));
        // Listed for another model only.
        assert_eq!(v.rows[2].known_deviation, None);
        let unlisted: Vec<&str> = v.unlisted(&known).iter().map(|r| r.id.as_str()).collect();
        assert_eq!(unlisted, ["c"]);
        assert_eq!(v.stale(&known), ["a"]);
        assert_eq!(v.counts(), (3, 1, 1, 1));
        assert_eq!(v.rows[1].status(), "OUT (known)");
        assert_eq!(v.rows[2].status(), "OUT");
    }

    #[test]
    fn a_bad_known_deviations_file_is_named() {
        let e = parse_known_deviations("[[deviation]]\nid = \"a\"\n").unwrap_err();
        assert!(e.to_string().contains("reason"), "{e}");
        let e = parse_known_deviations(
            "[[deviation]]\nid = \"a\"\nreason = \"r\"\nmodels = [\"upright\"]\n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("upright"), "{e}");
        let e = parse_known_deviations(
            "[[deviation]]\nid = \"a\"\nreason = \"r\"\n[[deviation]]\nid = \"a\"\nreason = \"s\"\n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("twice"), "{e}");
        // The embedded file parses.
        known_deviations().unwrap();
    }

    #[test]
    fn the_json_has_one_object_per_row_with_the_documented_fields() {
        let mut v = rows();
        v.rows[1].known_deviation = Some("felt".into());
        let j = v.to_json();
        assert_eq!(j["model"], "double");
        let keys: Vec<&str> = j.as_object().unwrap().keys().map(String::as_str).collect();
        assert_eq!(keys, ["model", "rows"]);
        let rows = j["rows"].as_array().unwrap();
        assert_eq!(rows.len(), 3);
        let mut fields: Vec<&str> = rows[0]
            .as_object()
            .unwrap()
            .keys()
            .map(String::as_str)
            .collect();
        fields.sort_unstable();
        assert_eq!(
            fields,
            [
                "id",
                "in_band",
                "known_deviation",
                "literature",
                "model_value",
                "note",
                "quantity",
                "source",
                "unit"
            ]
        );
        assert_eq!(rows[0]["model_value"], 1.0);
        assert_eq!(rows[0]["in_band"], true);
        assert_eq!(rows[0]["literature"], "0..2");
        assert!(rows[0]["known_deviation"].is_null());
        assert_eq!(rows[1]["known_deviation"], "felt");
        assert!(rows[2]["model_value"].is_null());
        assert_eq!(rows[2]["note"], "why");
        assert_eq!(rows[2]["in_band"], false);
    }

    #[test]
    fn the_table_aligns_its_columns_and_counts_the_rows() {
        let t = rows().table();
        let lines: Vec<&str> = t
            .lines()
            .filter(|l| l.starts_with(['a', 'b', 'c']))
            .collect();
        assert_eq!(lines.len(), 3, "{t}");
        let col = |l: &str| l.find("mm").unwrap();
        assert!(lines.iter().all(|l| col(l) == col(lines[0])), "{t}");
        assert!(t.contains("3 rows: 1 in band, 2 out of band"), "{t}");
        assert!(
            t.contains("no known deviations are listed for the double action"),
            "{t}"
        );
        assert!(t.contains("c: why"), "{t}");
    }
}
