//! Small programs a newcomer runs first; see the `[[example]]` entries of this crate:
//!
//! ```text
//! cargo run --release --example double_pendulum
//! ```
