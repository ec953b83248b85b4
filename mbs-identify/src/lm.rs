//! Levenberg–Marquardt (in progress).
