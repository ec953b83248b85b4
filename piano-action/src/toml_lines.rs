//! Reading TOML files so that an error names the field path and its line.
//!
//! `serde_path_to_error` gives the path of a value that does not deserialize; the spanned
//! parse of the same text gives that value's line. Validation errors found after parsing
//! (a mass that must be positive) are located the same way, from their field path.

use serde::de::DeserializeOwned;

use crate::error::{InputKind, PianoError, Result};

pub(crate) use mbs_mechanism::toml_lines::{Step, steps};
pub use mbs_mechanism::toml_lines::{line_at, line_of};

/// Parses `text` as a `T` of `kind`: a syntax error gives its line and the parser's
/// message; a value that does not fit gives the field path and its line.
pub fn from_toml<T: DeserializeOwned>(text: &str, kind: InputKind) -> Result<T> {
    let de = toml::Deserializer::parse(text).map_err(|e| {
        let line = e.span().map(|s| line_at(text, s.start));
        PianoError::input(kind, "", e.message().trim().to_string()).at_line(line)
    })?;
    serde_path_to_error::deserialize(de).map_err(|e| {
        let field = match e.path().to_string() {
            p if p == "." => String::new(),
            p => p,
        };
        let inner = e.inner();
        let span_line = inner.span().map(|s| line_at(text, s.start));
        let err = PianoError::input(kind, field, inner.message().trim().to_string());
        // The field's own line is the more precise one when both are known: a value inside
        // a tagged table is reported by the parser at the table's header.
        let err = err.locate_in_toml(text);
        err.at_line(span_line)
    })
}
