//! Small programs a newcomer runs first; see the `[[example]]` entries of this crate:
//!
//! ```text
//! cargo run --release --example double_pendulum
//! cargo run --release --example glockenspiel
//! ```
//!
//! And mechanisms that are not the grand action, written as descriptions
//! (`examples/mechanisms/`): a keyboard glockenspiel note, [`glockenspiel`].

use piano_action::mechanism::{Mechanism, MechanismError};

/// The keyboard glockenspiel note of `examples/mechanisms/glockenspiel.toml`: a key throws
/// a felt hammer against a steel bar that rings at 1046.5 Hz (sources in the file).
pub const GLOCKENSPIEL_TOML: &str = include_str!("../mechanisms/glockenspiel.toml");

/// [`GLOCKENSPIEL_TOML`], read and checked.
pub fn glockenspiel() -> Result<Mechanism, MechanismError> {
    let m = Mechanism::from_toml_str(GLOCKENSPIEL_TOML).map_err(|e| {
        e.in_file(
            "examples/mechanisms/glockenspiel.toml",
            Some(GLOCKENSPIEL_TOML),
        )
    })?;
    m.validate().map_err(|e| {
        e.in_file(
            "examples/mechanisms/glockenspiel.toml",
            Some(GLOCKENSPIEL_TOML),
        )
    })?;
    Ok(m)
}
