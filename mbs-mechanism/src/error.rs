//! The error of reading, checking and building a description: it names the file, the line
//! and the field, and keeps the cause (a core or contact error, an I/O error).

use std::error::Error as StdError;
use std::sync::Arc;

/// What went wrong, where.
#[derive(Clone, Debug, thiserror::Error)]
#[error("{}", self.render())]
pub struct MechanismError {
    /// The file, when the description came from one.
    pub file: Option<String>,
    /// The 1-based line in that file, when known.
    pub line: Option<usize>,
    /// The field path (`bodies[2].mass`), empty for the whole file.
    pub field: String,
    /// What is wrong.
    pub message: String,
    /// The underlying error, if another crate raised it.
    #[source]
    pub cause: Option<Arc<dyn StdError + Send + Sync + 'static>>,
}

/// Two errors are equal when they say the same thing at the same place (the causes are
/// not compared).
impl PartialEq for MechanismError {
    fn eq(&self, other: &Self) -> bool {
        (&self.file, self.line, &self.field, &self.message)
            == (&other.file, other.line, &other.field, &other.message)
    }
}

/// Result with [`MechanismError`].
pub type Result<T> = std::result::Result<T, MechanismError>;

impl MechanismError {
    /// An error at `field`.
    pub fn field(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            file: None,
            line: None,
            field: field.into(),
            message: message.into(),
            cause: None,
        }
    }

    /// An error at `field` caused by `cause` (its message becomes this one's).
    pub fn caused(field: impl Into<String>, cause: impl StdError + Send + Sync + 'static) -> Self {
        Self {
            message: cause.to_string(),
            cause: Some(Arc::new(cause)),
            ..Self::field(field, "")
        }
    }

    /// The same error located in `file`, its line found from the field path in the TOML
    /// `text` when it has none yet (JSON text gives no line).
    pub fn in_file(mut self, file: &str, text: Option<&str>) -> Self {
        self.file = Some(file.to_string());
        if self.line.is_none()
            && let Some(text) = text
            && !self.field.is_empty()
        {
            self.line = crate::toml_lines::line_of(text, &self.field);
        }
        self
    }

    fn render(&self) -> String {
        let mut s = String::new();
        if let Some(f) = &self.file {
            s.push_str(f);
            if let Some(l) = self.line {
                s.push_str(&format!(":{l}"));
            }
            s.push_str(": ");
        } else if let Some(l) = self.line {
            s.push_str(&format!("line {l}: "));
        }
        if !self.field.is_empty() {
            s.push_str(&self.field);
            s.push_str(": ");
        }
        s.push_str(&self.message);
        s
    }
}
