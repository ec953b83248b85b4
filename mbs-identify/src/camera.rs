//! The measurement model of a camera: what a frame records of a moving marker.
//!
//! A frame stamped `t` holds the marker's position averaged over the exposure
//! `[t + τ, t + τ + exposure]`, where `τ` is the unknown offset between the camera's clock
//! and the experiment's. Leaving the averaging or the offset out of the comparison makes
//! a fit "discover" drag that is not there (`identification.md` §0, item 3: 10 of 10
//! negative controls).

/// Gauss–Legendre nodes and weights on [−1, 1], 5 points: exact for polynomials up to
/// degree 9, so an exposure a tenth of a swing period is averaged to 1e-12.
const NODES: [f64; 5] = [
    0.0,
    -0.538_469_310_105_683_1,
    0.538_469_310_105_683_1,
    -0.906_179_845_938_664,
    0.906_179_845_938_664,
];
const WEIGHTS: [f64; 5] = [
    0.568_888_888_888_888_9,
    0.478_628_670_499_366_47,
    0.478_628_670_499_366_47,
    0.236_926_885_056_189_08,
    0.236_926_885_056_189_08,
];

/// A camera: its exposure and clock offset.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Exposure of one frame (s, ≥ 0; 0 is an instantaneous frame).
    pub exposure_s: f64,
    /// Offset `τ` of the camera's clock (s): a frame stamped `t` starts at `t + τ`.
    pub offset_s: f64,
}

impl Camera {
    /// The times in experiment time at which the frame stamped `t` samples the motion,
    /// with their weights (summing to 1).
    pub fn samples(&self, t: f64) -> impl Iterator<Item = (f64, f64)> + '_ {
        let start = t + self.offset_s;
        let half = 0.5 * self.exposure_s;
        let n = if self.exposure_s > 0.0 {
            NODES.len()
        } else {
            1
        };
        NODES.iter().zip(WEIGHTS).take(n).map(move |(x, w)| {
            if n == 1 {
                (start, 1.0)
            } else {
                (start + half * (1.0 + x), 0.5 * w)
            }
        })
    }

    /// What the frame stamped `t` records of the motion `position(time)`: its average over
    /// the exposure. `None` when `position` has no value at a sample time (the motion is
    /// not known there).
    pub fn frame(
        &self,
        t: f64,
        mut position: impl FnMut(f64) -> Option<[f64; 2]>,
    ) -> Option<[f64; 2]> {
        let mut sum = [0.0; 2];
        for (time, w) in self.samples(t) {
            let p = position(time)?;
            sum[0] += w * p[0];
            sum[1] += w * p[1];
        }
        Some(sum)
    }
}
