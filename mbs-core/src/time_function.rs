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

/// A piecewise-linear motion whose corners are rounded by parabolic blends (C¹, finite
/// acceleration), constant before the first and after the last point.
///
/// The first and last points are corners too: a motion that leaves its first point on a
/// slope does not pass through it: it is off by slope × τ / 4 there. Start with a short
/// flat segment to start exactly at the first value.
#[derive(Clone, Debug)]
pub struct BlendedLinear {
    t: Vec<f64>,
    q: Vec<f64>,
    /// Half-width of the blend at each point (s).
    tau: Vec<f64>,
}

impl BlendedLinear {
    /// Builds the motion through `(t, q)` points, each corner rounded over `2 τ` with
    /// `τ = min(max_blend_s, a quarter of each side)`. Refused: no points, values that are
    /// not finite, times that do not increase, a negative or non-finite blend.
    pub fn new(points: &[(f64, f64)], max_blend_s: f64) -> Result<Self> {
        if points.is_empty() {
            return Err(CoreError::InvalidParameter {
                item: "blended linear motion.points".into(),
                message: "a motion needs at least one point".into(),
            });
        }
        if !(max_blend_s.is_finite() && max_blend_s >= 0.0) {
            return Err(CoreError::InvalidParameter {
                item: "blended linear motion.max_blend_s".into(),
                message: format!("must be a non-negative time, got {max_blend_s}"),
            });
        }
        for (i, p) in points.iter().enumerate() {
            if !(p.0.is_finite() && p.1.is_finite()) {
                return Err(CoreError::InvalidParameter {
                    item: format!("blended linear motion.points[{i}]"),
                    message: format!("must be finite, got ({}, {})", p.0, p.1),
                });
            }
            if i > 0 && p.0 <= points[i - 1].0 {
                return Err(CoreError::InvalidParameter {
                    item: format!("blended linear motion.points[{i}]"),
                    message: format!("times must increase: {} after {}", p.0, points[i - 1].0),
                });
            }
        }
        let t: Vec<f64> = points.iter().map(|p| p.0).collect();
        let q: Vec<f64> = points.iter().map(|p| p.1).collect();
        let n = t.len();
        let tau = (0..n)
            .map(|k| {
                let before = if k > 0 {
                    t[k] - t[k - 1]
                } else {
                    f64::INFINITY
                };
                let after = if k + 1 < n {
                    t[k + 1] - t[k]
                } else {
                    f64::INFINITY
                };
                max_blend_s.min(0.25 * before).min(0.25 * after)
            })
            .collect();
        Ok(BlendedLinear { t, q, tau })
    }

    /// Slope of segment `i` (between points `i` and `i + 1`); 0 outside the table.
    fn slope(&self, i: isize) -> f64 {
        if i < 0 || i as usize + 1 >= self.t.len() {
            0.0
        } else {
            let i = i as usize;
            (self.q[i + 1] - self.q[i]) / (self.t[i + 1] - self.t[i])
        }
    }
}

impl Drive for BlendedLinear {
    fn eval(&self, t: f64) -> DriveState {
        let n = self.t.len();
        // Inside a corner blend?
        for k in 0..n {
            let (tk, tau) = (self.t[k], self.tau[k]);
            if tau > 0.0 && (t - tk).abs() < tau {
                let (m0, m1) = (self.slope(k as isize - 1), self.slope(k as isize));
                let s = t - tk + tau;
                return DriveState {
                    q: self.q[k] + m0 * (t - tk) + (m1 - m0) * s * s / (4.0 * tau),
                    v: m0 + (m1 - m0) * s / (2.0 * tau),
                    a: (m1 - m0) / (2.0 * tau),
                };
            }
        }
        if t <= self.t[0] {
            return DriveState {
                q: self.q[0],
                v: 0.0,
                a: 0.0,
            };
        }
        if t >= self.t[n - 1] {
            return DriveState {
                q: self.q[n - 1],
                v: 0.0,
                a: 0.0,
            };
        }
        let i = self.t.partition_point(|&tk| tk <= t) - 1;
        let m = self.slope(i as isize);
        DriveState {
            q: self.q[i] + m * (t - self.t[i]),
            v: m,
            a: 0.0,
        }
    }
}
