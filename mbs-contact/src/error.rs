//! The error type of the crate.

use thiserror::Error;

/// Errors of `mbs-contact`: invalid shapes or law parameters, each naming what is wrong.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ContactError {
    /// A shape is degenerate (zero radius or length, empty arc, non-finite numbers).
    #[error("shape {shape}: {message}")]
    DegenerateShape {
        /// Which shape.
        shape: String,
        /// What is wrong.
        message: String,
    },
    /// A law or material parameter is invalid.
    #[error("{item}: {message}")]
    InvalidParameter {
        /// The law and field, e.g. `"hertz.stiffness"`.
        item: String,
        /// What is wrong.
        message: String,
    },
    /// Two shapes cannot be paired (e.g. two infinite lines).
    #[error("contact '{contact}': {message}")]
    UnsupportedPair {
        /// The contact's name.
        contact: String,
        /// Why.
        message: String,
    },
    /// An error from the multibody core (unknown frame...).
    #[error(transparent)]
    Core(#[from] mbs_core::CoreError),
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, ContactError>;
