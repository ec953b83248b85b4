//! The error type of the crate.

use thiserror::Error;

/// Errors of `piano-action`, each naming what is wrong.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PianoError {
    /// A parameter file or value is invalid.
    #[error("parameters: {}{message}", if field.is_empty() { String::new() } else { format!("field `{field}`: ") })]
    Params {
        /// The field path (empty when the file itself cannot be read).
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The integration failed (the integrator's message says when and why).
    #[error("simulation failed: {0}")]
    Simulation(String),
    /// The multibody core refused something.
    #[error(transparent)]
    Core(#[from] mbs_core::CoreError),
    /// A contact could not be built.
    #[error(transparent)]
    Contact(#[from] mbs_contact::ContactError),
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, PianoError>;
