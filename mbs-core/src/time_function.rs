//! Functions of time: scalar loads ([`TimeFunction`]) and prescribed motions ([`Drive`]).

use crate::error::{CoreError, Result};

/// A scalar function of time, e.g. the magnitude of an applied force. Any
/// `Fn(f64) -> f64 + Send + Sync` closure is one.
pub trait TimeFunction: Send + Sync {
    /// The value at time `t` (s).
    fn value(&self, t: f64) -> f64;
}

impl<F: Fn(f64) -> f64 + Send + Sync> TimeFunction for F {
    fn value(&self, t: f64) -> f64 {
        self(t)
    }
}

/// A constant value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constant(pub f64);

impl TimeFunction for Constant {
    fn value(&self, _t: f64) -> f64 {
        self.0
    }
}

/// A piecewise-linear function through `(time, value)` points, held constant before the first
/// and after the last point: constants, ramps, releases and measured tables alike.
#[derive(Clone, Debug, PartialEq)]
pub struct PiecewiseLinear {
    points: Vec<(f64, f64)>,
}

impl PiecewiseLinear {
    /// Validates the points: at least one, all finite, times strictly increasing.
    pub fn new(points: Vec<(f64, f64)>) -> Result<Self> {
        if points.is_empty() {
            return Err(CoreError::InvalidParameter {
                item: "piecewise-linear function".into(),
                message: "needs at least one (time, value) point".into(),
            });
        }
        for (k, &(t, v)) in points.iter().enumerate() {
            if !t.is_finite() || !v.is_finite() {
                return Err(CoreError::InvalidParameter {
                    item: format!("piecewise-linear function, point {k}"),
                    message: format!("time and value must be finite, got ({t}, {v})"),
                });
            }
            if k > 0 && t <= points[k - 1].0 {
                return Err(CoreError::InvalidParameter {
                    item: format!("piecewise-linear function, point {k}"),
                    message: format!(
                        "times must increase strictly, got {t} after {}",
                        points[k - 1].0
                    ),
                });
            }
        }
        Ok(Self { points })
    }

    /// A linear ramp from `v0` at `t0` to `v1` at `t1` (`t1 > t0`), constant outside.
    pub fn ramp(t0: f64, v0: f64, t1: f64, v1: f64) -> Result<Self> {
        Self::new(vec![(t0, v0), (t1, v1)])
    }

    /// The points.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }
}

impl TimeFunction for PiecewiseLinear {
    fn value(&self, t: f64) -> f64 {
        let p = &self.points;
        let k = p.partition_point(|&(tk, _)| tk <= t);
        if k == 0 {
            p[0].1
        } else if k == p.len() {
            p[k - 1].1
        } else {
            let (t0, v0) = p[k - 1];
            let (t1, v1) = p[k];
            v0 + (v1 - v0) * (t - t0) / (t1 - t0)
        }
    }
}

/// Position, velocity and acceleration of a prescribed coordinate at one instant.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DriveState {
    /// Coordinate value.
    pub q: f64,
    /// Its rate.
    pub v: f64,
    /// Its second derivative.
    pub a: f64,
}

/// A prescribed motion `q(t), q̇(t), q̈(t)` of one coordinate; the three must be consistent
/// (derivatives of one another). Any `Fn(f64) -> DriveState + Send + Sync` closure is one.
pub trait Drive: Send + Sync {
    /// The motion at time `t`.
    fn eval(&self, t: f64) -> DriveState;
}

impl<F: Fn(f64) -> DriveState + Send + Sync> Drive for F {
    fn eval(&self, t: f64) -> DriveState {
        self(t)
    }
}

/// A smooth move from `q0` at `t0` to `q1` at `t1` along the quintic
/// `s(τ) = 10τ³ − 15τ⁴ + 6τ⁵`, with zero velocity and acceleration at both ends; at rest
/// outside `[t0, t1]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothMove {
    t0: f64,
    t1: f64,
    q0: f64,
    q1: f64,
}

impl SmoothMove {
    /// Validates `t1 > t0` and finiteness.
    pub fn new(t0: f64, q0: f64, t1: f64, q1: f64) -> Result<Self> {
        if ![t0, t1, q0, q1].iter().all(|x| x.is_finite()) || t1 <= t0 {
            return Err(CoreError::InvalidParameter {
                item: "smooth move".into(),
                message: format!(
                    "needs finite values and t1 > t0, got t0 = {t0}, t1 = {t1}, q0 = {q0}, q1 = {q1}"
                ),
            });
        }
        Ok(Self { t0, t1, q0, q1 })
    }
}

impl Drive for SmoothMove {
    fn eval(&self, t: f64) -> DriveState {
        let d = self.t1 - self.t0;
        let tau = ((t - self.t0) / d).clamp(0.0, 1.0);
        let dq = self.q1 - self.q0;
        let (t2, t3) = (tau * tau, tau * tau * tau);
        let s = t3 * (10.0 - 15.0 * tau + 6.0 * t2);
        let ds = 30.0 * t2 * (1.0 - 2.0 * tau + t2);
        let dds = 60.0 * tau * (1.0 - 3.0 * tau + 2.0 * t2);
        DriveState {
            q: self.q0 + dq * s,
            v: dq * ds / d,
            a: dq * dds / (d * d),
        }
    }
}

/// A sinusoidal motion `q = offset + amplitude sin(ω t + phase)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sinusoid {
    /// Mean value.
    pub offset: f64,
    /// Amplitude.
    pub amplitude: f64,
    /// Angular frequency (rad/s).
    pub omega: f64,
    /// Phase (rad).
    pub phase: f64,
}

impl Drive for Sinusoid {
    fn eval(&self, t: f64) -> DriveState {
        let (s, c) = (self.omega * t + self.phase).sin_cos();
        DriveState {
            q: self.offset + self.amplitude * s,
            v: self.amplitude * self.omega * c,
            a: -self.amplitude * self.omega * self.omega * s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piecewise_linear_interpolates_and_holds() {
        let f = PiecewiseLinear::new(vec![(0.0, 1.0), (1.0, 3.0), (2.0, 0.0)]).unwrap();
        assert_eq!(f.value(-1.0), 1.0);
        assert!((f.value(0.5) - 2.0).abs() < 1e-15);
        assert!((f.value(1.5) - 1.5).abs() < 1e-15);
        assert_eq!(f.value(5.0), 0.0);
        assert!(PiecewiseLinear::new(vec![]).is_err());
        assert!(PiecewiseLinear::new(vec![(1.0, 0.0), (1.0, 2.0)]).is_err());
        assert!(PiecewiseLinear::new(vec![(0.0, f64::NAN)]).is_err());
    }

    #[test]
    fn smooth_move_derivatives_are_consistent() {
        let m = SmoothMove::new(0.1, 0.2, 0.6, -0.3).unwrap();
        let h = 1e-6;
        for &t in &[0.0, 0.15, 0.3, 0.45, 0.59, 0.7] {
            let s = m.eval(t);
            let (p, n) = (m.eval(t + h), m.eval(t - h));
            assert!((s.v - (p.q - n.q) / (2.0 * h)).abs() < 1e-6, "v at {t}");
            assert!((s.a - (p.v - n.v) / (2.0 * h)).abs() < 1e-5, "a at {t}");
        }
        assert_eq!(m.eval(0.0).q, 0.2);
        assert!((m.eval(1.0).q + 0.3).abs() < 1e-15);
        assert!(SmoothMove::new(1.0, 0.0, 1.0, 1.0).is_err());
    }
}
