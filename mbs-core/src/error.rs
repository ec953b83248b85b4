//! The error type of the crate.

use thiserror::Error;

/// Everything that can go wrong in `mbs-core`: a model that cannot be built, an input of the
/// wrong size or with non-finite numbers, a force element that produced a non-finite value.
/// Every variant names the body, joint, field or vector at fault.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CoreError {
    /// Two bodies, or two joints, share a name.
    #[error("duplicate {what} name '{name}'")]
    DuplicateName {
        /// `"body"` or `"joint"`.
        what: &'static str,
        /// The repeated name.
        name: String,
    },
    /// A body has zero or negative mass.
    #[error("body '{body}': mass must be positive, got {mass}")]
    NonPositiveMass {
        /// The body.
        body: String,
        /// The rejected mass (kg).
        mass: f64,
    },
    /// A body has a zero or negative rotational inertia about its centre of mass.
    #[error(
        "body '{body}': rotational inertia about the centre of mass must be positive, got {inertia}"
    )]
    NonPositiveInertia {
        /// The body.
        body: String,
        /// The rejected inertia (kg·m²).
        inertia: f64,
    },
    /// A number in the model description is NaN or infinite.
    #[error("{item}: field '{field}' must be finite, got {value}")]
    NonFinite {
        /// What holds the field, e.g. `"body 'hammer'"`, `"joint 'key'"`, `"model"`.
        item: String,
        /// The field, e.g. `"placement.x"`.
        field: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// A prismatic joint has a zero axis.
    #[error("joint '{joint}': prismatic axis must be a non-zero vector, got [{}, {}]", axis[0], axis[1])]
    ZeroAxis {
        /// The joint.
        joint: String,
        /// The rejected axis.
        axis: [f64; 2],
    },
    /// An axis was given on a joint that has none, or a prismatic joint lacks one.
    #[error("joint '{joint}': {message}")]
    BadAxis {
        /// The joint.
        joint: String,
        /// What is wrong.
        message: &'static str,
    },
    /// A joint names a parent or child body that does not exist.
    #[error("joint '{joint}': unknown {role} body '{body}'")]
    UnknownBody {
        /// The joint.
        joint: String,
        /// `"parent"` or `"child"`.
        role: &'static str,
        /// The unknown name.
        body: String,
    },
    /// A body is the child of more than one joint (a closed kinematic loop).
    #[error("body '{body}' is the child of several joints ({}): closed loops are not supported", joints.join(", "))]
    MultipleParents {
        /// The body.
        body: String,
        /// The joints that all claim it as their child.
        joints: Vec<String>,
    },
    /// The joints form a cycle (a body is its own ancestor).
    #[error("the joints {} form a cycle", joints.join(", "))]
    Cycle {
        /// The joints of the cycle, in name order.
        joints: Vec<String>,
    },
    /// A body has no joint connecting it to the ground.
    #[error("body '{body}' is not connected to the ground (no joint has it as child)")]
    NotConnected {
        /// The body.
        body: String,
    },
    /// The model has no moving body.
    #[error("the model has no moving body")]
    EmptyModel,
    /// A model description could not be parsed.
    #[error("model description: {0}")]
    Parse(String),
    /// A states file (the inspect tool's input) could not be read or holds a bad state.
    #[error("states file: {0}")]
    States(String),
    /// A name was looked up that the model does not have.
    #[error("unknown {what} '{name}'")]
    UnknownName {
        /// `"frame"`, `"joint"`, `"body"`, ...
        what: &'static str,
        /// The name.
        name: String,
    },
    /// A vector passed to an algorithm has the wrong length.
    #[error("{what}: expected length {expected}, got {got}")]
    DimensionMismatch {
        /// Which argument, e.g. `"q"`, `"tau"`, `"f_ext"`.
        what: &'static str,
        /// The length the model needs.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A `Data` or `Workspace` made for another model was passed.
    #[error("workspace made for a model of {got} bodies used with a model of {expected}")]
    WorkspaceMismatch {
        /// Bodies (with the ground) of the model given.
        expected: usize,
        /// Bodies the workspace was made for.
        got: usize,
    },
    /// A matrix argument has the wrong shape.
    #[error("{what}: expected a {}×{} matrix, got {}×{}", expected.0, expected.1, got.0, got.1)]
    ShapeMismatch {
        /// Which argument.
        what: &'static str,
        /// Rows and columns needed.
        expected: (usize, usize),
        /// Rows and columns given.
        got: (usize, usize),
    },
    /// An input to an algorithm holds NaN or an infinity.
    #[error("{what}[{index}] is not finite ({value})")]
    NonFiniteInput {
        /// Which argument.
        what: &'static str,
        /// The first bad index.
        index: usize,
        /// The bad value.
        value: f64,
    },
    /// A state vector given to a `System` holds NaN or an infinity.
    #[error("at t = {t}: state x[{index}] ({meaning}) is not finite ({value})")]
    NonFiniteState {
        /// Time of the evaluation.
        t: f64,
        /// Index in the state vector.
        index: usize,
        /// What the entry is, e.g. `"v of joint 'hammer'"`.
        meaning: String,
        /// The bad value.
        value: f64,
    },
    /// A force element (or a drive) produced a non-finite value.
    #[error("at t = {t}: {source_name} produced a non-finite {quantity}")]
    NonFiniteOutput {
        /// Time of the evaluation.
        t: f64,
        /// The element or drive at fault.
        source_name: String,
        /// What was non-finite.
        quantity: &'static str,
    },
    /// The mass matrix is not positive definite (only possible with extreme inputs).
    #[error("mass matrix is not positive definite at coordinate '{coordinate}'")]
    NotPositiveDefinite {
        /// The coordinate whose pivot failed.
        coordinate: String,
    },
    /// A parameter of a force element, drive or time function is invalid.
    #[error("{item}: {message}")]
    InvalidParameter {
        /// The element or function, with the offending field.
        item: String,
        /// What is wrong and what is expected.
        message: String,
    },
}

/// Result alias of the crate.
pub type Result<T> = std::result::Result<T, CoreError>;

/// Checks that `x` has length `n` and only finite entries.
#[inline]
pub(crate) fn check_input(what: &'static str, x: &[f64], n: usize) -> Result<()> {
    if x.len() != n {
        return Err(CoreError::DimensionMismatch {
            what,
            expected: n,
            got: x.len(),
        });
    }
    // Summing is branch-free; a NaN or ±inf anywhere makes the sum non-finite.
    let sum: f64 = x.iter().map(|v| v * 0.0).sum();
    if sum != 0.0
        && let Some((index, &value)) = x.iter().enumerate().find(|(_, v)| !v.is_finite())
    {
        return Err(CoreError::NonFiniteInput { what, index, value });
    }
    Ok(())
}
