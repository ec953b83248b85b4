//! Identification against measured motion, for the piano: the pendulum (swing) test's
//! model, its library of flange effects, synthetic datasets with hidden effects, and the
//! diagnosis that finds, names and adds a missing effect (issue 13; the generic parts are
//! in `mbs-identify`).

pub mod action_effects;
pub mod commands;
mod data_check;
pub mod diagnose;
pub mod effects;
pub mod key_diagnose;
pub mod key_drive;
pub mod key_report;
mod recent;
pub mod report;
pub mod swing_model;
pub mod synth;
