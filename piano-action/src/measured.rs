//! Measured data beside a run: `measured.csv`, a `time_s` column and any of the report's
//! plotted series by their ids (`hammer_angle_deg`, `hammer_speed_m_s`, `key_depth_mm`,
//! ...), overlaid on the report's plots as points.
//!
//! The file is read strictly, because a silently misread measurement is worse than none:
//! every row has exactly as many cells as the header (an empty cell is a gap), times are
//! finite, from 0 on and increasing, values are finite numbers, and every column is known
//! and named once. Errors name the file, the line and the column.

use std::path::Path;

use crate::error::{InputKind, PianoError, Result};

/// One measured series: its column id and its `(time_s, value)` points (gaps left out).
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// The column id (one of the known series).
    pub id: String,
    /// Times (s) of the points.
    pub t: Vec<f64>,
    /// Values of the points.
    pub v: Vec<f64>,
}

/// Parses the text of a `measured.csv` (`file` names it in errors) whose columns after
/// `time_s` must be among `known`.
pub fn parse_measured(text: &str, file: &Path, known: &[&str]) -> Result<Vec<Series>> {
    let bad = |line: usize, field: &str, message: String| {
        PianoError::input(InputKind::Measured, field, message)
            .in_file(file)
            .at_line((line > 0).then_some(line))
    };
    // A spreadsheet's UTF-8 byte-order mark is not part of the first header.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (header_line, header) = lines.next().ok_or_else(|| {
        bad(
            0,
            "",
            "the file is empty (expected a header: time_s,...)".into(),
        )
    })?;
    let header: Vec<&str> = header.split(',').map(str::trim).collect();
    if header.first() != Some(&"time_s") {
        return Err(bad(
            header_line + 1,
            "",
            format!(
                "the first column must be time_s, got '{}'",
                header.first().copied().unwrap_or("")
            ),
        ));
    }
    for (k, h) in header.iter().enumerate().skip(1) {
        if !known.contains(h) {
            return Err(bad(
                header_line + 1,
                h,
                format!("not a plotted quantity (known: {})", known.join(", ")),
            ));
        }
        if header[..k].contains(h) {
            return Err(bad(header_line + 1, h, "the column is named twice".into()));
        }
    }
    let mut series: Vec<Series> = header[1..]
        .iter()
        .map(|h| Series {
            id: h.to_string(),
            t: Vec::new(),
            v: Vec::new(),
        })
        .collect();
    let mut last_time: Option<f64> = None;
    for (i, line) in lines {
        let n = i + 1;
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != header.len() {
            return Err(bad(
                n,
                "",
                format!(
                    "{} cells, the header has {} (an empty cell is a gap: write ',,')",
                    cells.len(),
                    header.len()
                ),
            ));
        }
        let number = |c: &str, column: &str| -> Result<Option<f64>> {
            if c.is_empty() {
                return Ok(None);
            }
            match c.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(Some(v)),
                _ => Err(bad(n, column, format!("'{c}' is not a finite number"))),
            }
        };
        let t = number(cells[0], "time_s")?
            .ok_or_else(|| bad(n, "time_s", "no time: every row needs one".into()))?;
        if t < 0.0 {
            return Err(bad(
                n,
                "time_s",
                format!("{t} s is negative (times count from the run's start)"),
            ));
        }
        if let Some(prev) = last_time
            && t <= prev
        {
            return Err(bad(
                n,
                "time_s",
                format!("times must increase: {t} s comes after {prev} s"),
            ));
        }
        last_time = Some(t);
        for (s, cell) in series.iter_mut().zip(&cells[1..]) {
            if let Some(v) = number(cell, &s.id)? {
                s.t.push(t);
                s.v.push(v);
            }
        }
    }
    Ok(series)
}

#[cfg(test)]
mod tests {
    use super::*;

    const KNOWN: &[&str] = &["hammer_angle_deg", "key_depth_mm"];

    fn parse(text: &str) -> Result<Vec<Series>> {
        parse_measured(text, Path::new("run/measured.csv"), KNOWN)
    }

    fn message(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn gaps_are_left_out_and_columns_kept_in_order() {
        let s = parse("time_s,key_depth_mm,hammer_angle_deg\n0,0,\n0.001,0.5,1.0\n").unwrap();
        assert_eq!(s[0].id, "key_depth_mm");
        assert_eq!(s[0].t, vec![0.0, 0.001]);
        assert_eq!(s[1].t, vec![0.001]);
        assert_eq!(s[1].v, vec![1.0]);
    }

    #[test]
    fn a_byte_order_mark_is_not_part_of_the_header() {
        let s = parse("\u{feff}time_s,key_depth_mm\r\n0,0.5\r\n").unwrap();
        assert_eq!(s[0].v, vec![0.5]);
    }

    #[test]
    fn an_extra_cell_is_refused_at_its_line() {
        let m = message("time_s,key_depth_mm\n0,0\n0.001,0.5,7\n");
        assert!(
            m.contains("run/measured.csv") && m.contains("line 3") && m.contains("3 cells"),
            "{m}"
        );
    }

    #[test]
    fn times_out_of_order_or_negative_are_refused() {
        let m = message("time_s,key_depth_mm\n0.002,0\n0.001,0.5\n");
        assert!(m.contains("line 3") && m.contains("must increase"), "{m}");
        let m = message("time_s,key_depth_mm\n-0.001,0\n");
        assert!(m.contains("line 2") && m.contains("negative"), "{m}");
        let m = message("time_s,key_depth_mm\n0,0\n0,1\n");
        assert!(m.contains("line 3"), "{m}");
    }

    #[test]
    fn bad_cells_unknown_and_repeated_columns_are_named() {
        let m = message("time_s,key_depth_mm\n0,abc\n");
        assert!(m.contains("line 2") && m.contains("`key_depth_mm`"), "{m}");
        let m = message("time_s,key_depth_mm\n0,inf\n");
        assert!(m.contains("not a finite number"), "{m}");
        let m = message("time_s,speed\n0,1\n");
        assert!(
            m.contains("column `speed`") && m.contains("known: hammer"),
            "{m}"
        );
        let m = message("time_s,key_depth_mm,key_depth_mm\n");
        assert!(m.contains("named twice"), "{m}");
        let m = message("t,key_depth_mm\n");
        assert!(m.contains("line 1") && m.contains("time_s"), "{m}");
        assert!(message("\n\n").contains("empty"));
        let m = message("time_s,key_depth_mm\n,1\n");
        assert!(m.contains("no time"), "{m}");
    }
}
