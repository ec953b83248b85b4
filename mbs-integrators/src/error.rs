//! The error type of the crate.

use thiserror::Error;

/// An error raised by the system being integrated (its derivative, Jacobian or switching
/// functions), carried as text so any system can report one.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{0}")]
pub struct SystemError(pub String);

impl SystemError {
    /// An error from anything displayable.
    pub fn new(message: impl std::fmt::Display) -> Self {
        Self(message.to_string())
    }
}

/// Why an integration could not go on. Every variant says when (`t`) and why: the solver
/// never returns a silently wrong answer.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum IntegratorError {
    /// An option is invalid.
    #[error("option '{option}': {message}")]
    InvalidOption {
        /// The option's name.
        option: &'static str,
        /// What is wrong.
        message: String,
    },
    /// The initial state or time is invalid.
    #[error("initial condition: {0}")]
    InvalidInitialCondition(String),
    /// The step size fell below the minimum while trying to meet the tolerance.
    #[error("at t = {t}: step size {h:e} fell below the minimum {h_min:e} ({reason})")]
    StepSizeTooSmall {
        /// Time reached.
        t: f64,
        /// The step size that was needed.
        h: f64,
        /// The minimum step size.
        h_min: f64,
        /// What kept shrinking the step.
        reason: &'static str,
    },
    /// The state became NaN or infinite.
    #[error("at t = {t}: state component {index} became non-finite ({value})")]
    NonFiniteState {
        /// Time reached.
        t: f64,
        /// First non-finite component.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// Newton's method did not converge in the implicit method, even with a fresh
    /// Jacobian and the minimum step.
    #[error("at t = {t}: Newton iteration failed to converge with step {h:e}")]
    NewtonFailure {
        /// Time reached.
        t: f64,
        /// Step size of the last attempt.
        h: f64,
    },
    /// The iteration matrix `I − h γ J` is singular.
    #[error("at t = {t}: iteration matrix is singular (step {h:e})")]
    SingularMatrix {
        /// Time reached.
        t: f64,
        /// Step size.
        h: f64,
    },
    /// The maximum number of steps was taken before the end time.
    #[error("at t = {t}: maximum number of steps ({max_steps}) reached before t_end")]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// The limit.
        max_steps: usize,
    },
    /// The check of [`crate::with_interrupt_check`] asked to stop.
    #[error("at t = {t}: interrupted")]
    Interrupted {
        /// Time reached.
        t: f64,
    },
    /// The system reported an error.
    #[error("at t = {t}: the system failed: {source}")]
    System {
        /// Time of the failing evaluation.
        t: f64,
        /// What the system said.
        source: SystemError,
    },
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, IntegratorError>;
