//! One check of a parameter's value for every crate's constructors and file readers:
//! finite, and where asked zero or positive, or positive. It says what is wrong as a phrase
//! (`must be positive, got -1`); the caller puts it in its own error with the field's name,
//! so that every crate words the same mistake the same way.

/// What a value must be, beyond finite.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Bound {
    /// Any finite number.
    Finite,
    /// Zero or positive.
    NonNegative,
    /// Strictly positive.
    Positive,
}

/// `Ok(value)` when `value` is finite and within `bound`, else what is wrong.
///
/// ```
/// use mbs_core::check::{Bound, check_value};
/// assert_eq!(check_value(2.0, Bound::Positive), Ok(2.0));
/// assert_eq!(check_value(0.0, Bound::Positive).unwrap_err(), "must be positive, got 0");
/// assert_eq!(check_value(-1.0, Bound::NonNegative).unwrap_err(), "must be zero or positive, got -1");
/// assert_eq!(check_value(f64::NAN, Bound::Finite).unwrap_err(), "must be a finite number, got NaN");
/// ```
pub fn check_value(value: f64, bound: Bound) -> Result<f64, String> {
    if !value.is_finite() {
        return Err(format!("must be a finite number, got {value}"));
    }
    match bound {
        Bound::NonNegative if value < 0.0 => Err(format!("must be zero or positive, got {value}")),
        Bound::Positive if value <= 0.0 => Err(format!("must be positive, got {value}")),
        _ => Ok(value),
    }
}
