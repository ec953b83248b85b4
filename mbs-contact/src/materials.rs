//! Material presets (being written).
