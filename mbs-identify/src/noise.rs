//! Noise floor and outliers (in progress).
