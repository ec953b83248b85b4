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

    /// A file or folder that cannot be read or written.
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
