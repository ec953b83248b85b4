//! The error type of the crate.
//!
//! Every error about what a user wrote names what it is about (the parameter file, a
//! scenario, a CSV table, a run directory, a command-line option), the file, the line where
//! there is one, and the field path, then says what is wrong:
//!
//! ```text
//! scenario loud.toml, line 7, field `input.points[2][1]`: expected a number, found "x"
//! ```

use std::fmt;
use std::path::{Path, PathBuf};

use thiserror::Error;

/// What kind of input an [`InputError`] is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// The action's parameters (a parameter file, or values set in code).
    Parameters,
    /// A scenario (what `piano simulate` runs).
    Scenario,
    /// A table of points read from a CSV file (a key motion).
    PointsCsv,
    /// Measured data beside a run (`measured.csv`).
    Measured,
    /// A run directory written by `piano simulate`.
    RunDir,
    /// A command-line option or a value passed to a library function.
    Option,
}

impl InputKind {
    /// How a message names this kind of input.
    pub fn label(self) -> &'static str {
        match self {
            InputKind::Parameters => "parameters",
            InputKind::Scenario => "scenario",
            InputKind::PointsCsv => "CSV table",
            InputKind::Measured => "measured data",
            InputKind::RunDir => "run directory",
            InputKind::Option => "option",
        }
    }
}

/// A wrong value in an input: what it is about, where it is and why it is wrong.
#[derive(Debug, Clone, PartialEq)]
pub struct InputError {
    /// What kind of input.
    pub kind: InputKind,
    /// The file, when the input came from one.
    pub file: Option<PathBuf>,
    /// The line in that file (1-based), when known.
    pub line: Option<usize>,
    /// The field path (`hammer.mass_g`, `input.points[2][1]`, `--out`); empty when the
    /// problem is the whole input (a file that does not parse at all).
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for InputError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut head = match (&self.kind, &self.file) {
            (InputKind::Parameters, Some(p)) => format!("parameter file {}", p.display()),
            (InputKind::RunDir, Some(p)) => format!("run directory {}", p.display()),
            (kind, Some(p)) => format!("{} {}", kind.label(), p.display()),
            (kind, None) => kind.label().to_string(),
        };
        if let Some(line) = self.line {
            head.push_str(&format!(", line {line}"));
        }
        if !self.field.is_empty() {
            match self.kind {
                InputKind::Option => head = format!("option {}", self.field),
                InputKind::Measured | InputKind::PointsCsv => {
                    head.push_str(&format!(", column `{}`", self.field))
                }
                _ => head.push_str(&format!(", field `{}`", self.field)),
            }
        }
        write!(f, "{head}: {}", self.message)
    }
}

/// An I/O error kept as an error's cause: shared, so that [`PianoError`] stays `Clone`;
/// two are equal when they are of the same kind and say the same.
#[derive(Clone, Debug)]
pub struct IoCause(pub std::sync::Arc<std::io::Error>);

impl fmt::Display for IoCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for IoCause {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        Some(self.0.as_ref())
    }
}

impl PartialEq for IoCause {
    fn eq(&self, other: &Self) -> bool {
        self.0.kind() == other.0.kind() && self.0.to_string() == other.0.to_string()
    }
}

/// Errors of `piano-action`, each naming what is wrong.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PianoError {
    /// A value in an input is wrong: a parameter file, a scenario, a CSV table, measured
    /// data, a run directory or a command-line option.
    #[error("{0}")]
    Input(Box<InputError>),
    /// A file or folder cannot be read or written, or writing it would overwrite the user's.
    #[error("{}: {message}", path.display())]
    File {
        /// The file or folder.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// A file or folder cannot be read, written, listed or removed: the operating system's
    /// error is kept as the cause (its kind tells a missing file from a refused one).
    #[error("{}: cannot {action}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// What was being done: `read`, `write`, `create the folder`, ...
        action: String,
        /// The operating system's error.
        #[source]
        source: IoCause,
    },
    /// A simulation could not be done (no string to sound, a fit that found nothing).
    #[error("simulation failed: {0}")]
    Simulation(String),
    /// The integration failed: the integrator's error, kept as the cause, says when and
    /// why.
    #[error("simulation failed: {0}")]
    Integrator(#[from] mbs_integrators::IntegratorError),
    /// The multibody core refused something.
    #[error(transparent)]
    Core(#[from] mbs_core::CoreError),
    /// A contact could not be built.
    #[error(transparent)]
    Contact(#[from] mbs_contact::ContactError),
    /// A mechanism description is wrong (the message names its file, line and field).
    #[error("mechanism description {0}")]
    Mechanism(#[from] mbs_mechanism::MechanismError),
    /// No parameter has this path (`piano params --list` prints them all).
    #[error(
        "no parameter '{path}'{}; `piano params --list` prints every path",
        suggestion.as_ref().map_or(String::new(), |s| format!(" (did you mean '{s}'?)"))
    )]
    UnknownParameter {
        /// The path asked for.
        path: String,
        /// The closest known path, if one is close.
        suggestion: Option<String>,
    },
}

impl PianoError {
    /// A wrong value of `kind` at `field`.
    pub fn input(kind: InputKind, field: impl Into<String>, message: impl Into<String>) -> Self {
        PianoError::Input(Box::new(InputError {
            kind,
            file: None,
            line: None,
            field: field.into(),
            message: message.into(),
        }))
    }

    /// A wrong parameter at `field` (a path such as `hammer.mass_g`).
    pub fn params(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::input(InputKind::Parameters, field, message)
    }

    /// A wrong scenario value at `field` (a path such as `input.force_n`).
    pub fn scenario(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::input(InputKind::Scenario, field, message)
    }

    /// A wrong command-line option or argument (`--out`, `--jobs`).
    pub fn option(flag: impl Into<String>, message: impl Into<String>) -> Self {
        Self::input(InputKind::Option, flag, message)
    }

    /// `action` (`"read"`, `"write"`, ...) on `path` failed with the operating system's
    /// `error`.
    pub fn io(path: &Path, action: impl Into<String>, error: std::io::Error) -> Self {
        PianoError::Io {
            path: path.to_path_buf(),
            action: action.into(),
            source: IoCause(std::sync::Arc::new(error)),
        }
    }

    /// A file or folder that cannot be used, for a reason of ours (it would overwrite the
    /// user's, it cannot be encoded); [`PianoError::io`] for the operating system's errors.
    pub fn file(path: &Path, message: impl Into<String>) -> Self {
        PianoError::File {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    /// The input error, if this is one.
    pub fn as_input(&self) -> Option<&InputError> {
        match self {
            PianoError::Input(e) => Some(e),
            _ => None,
        }
    }

    /// The field path of an input error (empty for other errors).
    pub fn field(&self) -> &str {
        self.as_input().map_or("", |e| e.field.as_str())
    }

    /// Names the file of an input error that does not name one yet.
    pub fn in_file(mut self, path: &Path) -> Self {
        if let PianoError::Input(e) = &mut self
            && e.file.is_none()
        {
            e.file = Some(path.to_path_buf());
        }
        self
    }

    /// Sets the line of an input error that has none yet.
    pub fn at_line(mut self, line: Option<usize>) -> Self {
        if let PianoError::Input(e) = &mut self
            && e.line.is_none()
        {
            e.line = line;
        }
        self
    }

    /// Finds the line of an input error's field in the TOML `text` it was read from.
    pub fn locate_in_toml(self, text: &str) -> Self {
        let line = match &self {
            PianoError::Input(e) if e.line.is_none() && !e.field.is_empty() => {
                crate::toml_lines::line_of(text, &e.field)
            }
            _ => None,
        };
        self.at_line(line)
    }
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, PianoError>;

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;

    /// A missing file keeps the operating system's error as the cause: its kind tells a
    /// missing file from a refused one, and the message still names the file.
    #[test]
    fn io_errors_keep_their_cause() {
        let path = Path::new("/nonexistent/piano/params.toml");
        let e = crate::ActionParams::load(path).expect_err("no such file");
        let PianoError::Io { source, .. } = &e else {
            panic!("an I/O error, got {e:?}");
        };
        assert_eq!(source.0.kind(), std::io::ErrorKind::NotFound);
        let text = e.to_string();
        assert!(
            text.starts_with("/nonexistent/piano/params.toml: cannot read"),
            "{text}"
        );
        let cause = e.source().expect("a cause");
        let io = cause
            .source()
            .and_then(|c| c.downcast_ref::<std::io::Error>())
            .expect("the io::Error under it");
        assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
        // Equal errors: the same place, kind and message.
        assert_eq!(e, crate::ActionParams::load(path).unwrap_err());
    }
}
