//! Finding the line of a field in a TOML text, so an error found after parsing (a mass that
//! must be positive) names the line as well as the field path.

use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// 1-based line of byte `offset` in `text`.
pub fn line_at(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// One step of a field path: a table key or an array index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step<'a> {
    /// A table key.
    Key(&'a str),
    /// An array index.
    Index(usize),
}

/// Splits `input.points[2][1]` into keys and indices; `None` for a path it cannot read.
pub fn steps(path: &str) -> Option<Vec<Step<'_>>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if !key.is_empty() {
            out.push(Step::Key(key));
        }
        while let Some(stripped) = rest.strip_prefix('[') {
            let close = stripped.find(']')?;
            out.push(Step::Index(stripped[..close].parse().ok()?));
            rest = &stripped[close + 1..];
        }
    }
    Some(out)
}

/// The line of the value at `path` (a field path such as `input.points[2][1]`) in the TOML
/// `text`, or of the deepest part of the path that exists there; `None` when the text does
/// not parse or not even the first key is in it.
pub fn line_of(text: &str, path: &str) -> Option<usize> {
    let root = DeTable::parse(text).ok()?;
    let steps = steps(path)?;
    let mut table: &DeTable = root.get_ref();
    let mut array: Option<&[Spanned<DeValue>]> = None;
    let mut found: Option<std::ops::Range<usize>> = None;
    for step in steps {
        let value: &Spanned<DeValue> = match (step, array) {
            (Step::Key(k), None) => match table.iter().find(|(key, _)| key.get_ref() == k) {
                Some((key, value)) => {
                    // A table header's span is the key; a value's is the value.
                    found = Some(key.span());
                    value
                }
                None => break,
            },
            (Step::Index(i), Some(items)) => match items.get(i) {
                Some(value) => value,
                None => break,
            },
            _ => break,
        };
        if !matches!(value.get_ref(), DeValue::Table(_)) {
            found = Some(value.span());
        }
        match value.get_ref() {
            DeValue::Table(t) => {
                table = t;
                array = None;
            }
            DeValue::Array(a) => array = Some(&a[..]),
            _ => array = None,
        }
    }
    found.map(|span| line_at(text, span.start))
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "model = \"double\"\nduration_s = 0.2\n\n[input]\nkind = \"motion\"\n\
                        points = [\n  [0.0, 0.0],\n  [0.01, 5.0],\n  [0.02, 9.0],\n]\n";

    #[test]
    fn fields_and_array_cells_are_found_on_their_lines() {
        assert_eq!(line_of(TEXT, "duration_s"), Some(2));
        assert_eq!(line_of(TEXT, "input"), Some(4));
        assert_eq!(line_of(TEXT, "input.kind"), Some(5));
        assert_eq!(line_of(TEXT, "input.points"), Some(6));
        assert_eq!(line_of(TEXT, "input.points[1]"), Some(8));
        assert_eq!(line_of(TEXT, "input.points[2][1]"), Some(9));
        // A missing field: the deepest part that exists.
        assert_eq!(line_of(TEXT, "input.force_n"), Some(4));
        assert_eq!(line_of(TEXT, "nothing"), None);
        assert_eq!(line_of("not = [toml", "not"), None);
    }

    #[test]
    fn dotted_and_inline_tables_are_found() {
        let text = "a.b = 1\n[c]\nd = { e = [1, 2,\n 3] }\n";
        assert_eq!(line_of(text, "a.b"), Some(1));
        assert_eq!(line_of(text, "c.d.e[2]"), Some(4));
    }

    #[test]
    fn arrays_of_tables_are_found() {
        let text = "name = \"m\"\n[[bodies]]\nname = \"a\"\n[[bodies]]\nname = \"b\"\nmass = -1\n";
        assert_eq!(line_of(text, "bodies[1].mass"), Some(6));
        assert_eq!(line_of(text, "bodies[0].name"), Some(3));
    }
}
