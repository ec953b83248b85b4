//! Noise floor and outliers of tracked-marker data, read from the data itself.
//!
//! A high-speed camera's marker positions carry AR(1)-correlated noise
//! (`e_k = ρ e_{k−1} + √(1−ρ²) σ ξ_k`), a few gross tracking errors and a few lost frames.
//! This module finds the gross errors ([`detect_outliers`], a leave-one-out local
//! polynomial), measures the noise ([`estimate_ar1`], from differences of the data, so no
//! model is needed), whitens residuals and Jacobians under the AR(1) model ([`whiten`],
//! [`whiten_columns`]) and tests whiteness ([`ljung_box`]).
//!
//! The scale that makes this work: at 3000 fps a marker moving at 1.5 m/s steps 500 µm per
//! frame, far above a 30 µm noise, while its third difference is ~1e-8 m, far below it. So a
//! cubic through a dozen frames follows the motion and leaves the noise, and a third difference
//! removes the motion and keeps the noise.
//!
//! ```
//! use mbs_identify::noise::{detect_outliers, estimate_ar1, whiten, OutlierOptions};
//!
//! // A marker gliding at 1 m/s (333 µm per frame), a little wobble, one tracking error.
//! let t: Vec<f64> = (0..600).map(|k| k as f64 / 3000.0).collect();
//! let wobble = |k: usize| 3e-5 * ((k as f64 * 1.3).sin() + (k as f64 * 2.9).cos());
//! let mut x: Vec<Option<f64>> = t.iter().enumerate().map(|(k, &t)| Some(t + wobble(k))).collect();
//! x[300] = x[300].map(|v| v + 3e-4);
//! x[450] = None; // a lost frame
//! let flags = detect_outliers(&t, &[&x], &OutlierOptions::default());
//! assert!(flags[300] && flags.iter().filter(|&&f| f).count() == 1);
//!
//! let noise = estimate_ar1(&[&x], &flags).unwrap();
//! let r: Vec<f64> = x.iter().flatten().map(|v| v / noise.sigma).collect();
//! let w = whiten(&r, &[true], noise.rho);
//! assert_eq!(w.len(), r.len());
//! ```

use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};

/// Options of the outlier detector ([`detect_outliers`]).
///
/// ```
/// let o = mbs_identify::noise::OutlierOptions { threshold: 8.0, ..Default::default() };
/// assert_eq!((o.half_window, o.degree, o.max_passes), (6, 3, 6));
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct OutlierOptions {
    /// Frames on each side of the tested frame that feed its local polynomial (default 6).
    pub half_window: usize,
    /// Degree of the local polynomial (default 3).
    pub degree: usize,
    /// Flagging threshold, in robust standard deviations of the leave-one-out residual
    /// (default 6).
    pub threshold: f64,
    /// Largest number of passes; each pass flags at most one frame per window (default 6).
    pub max_passes: usize,
}

impl Default for OutlierOptions {
    fn default() -> Self {
        Self {
            half_window: 6,
            degree: 3,
            threshold: 6.0,
            max_passes: 6,
        }
    }
}

/// Flags gross outlier frames.
///
/// `channels` are several series over the same frames (a marker's x and y, or all markers of a
/// run), `t` the frame times (uniform or not; they place the samples for the local polynomial).
/// A frame is flagged when any channel is an outlier there. Lost samples (`None`, or a
/// non-finite value) are never flagged and never used. A channel shorter than `t` counts as
/// lost beyond its end; samples beyond `t.len()` are ignored. The result has `t.len()` entries.
///
/// **Method.** For each frame `k` and channel, a polynomial of `degree` in centred, scaled
/// time `s = (t_j − t_k)/max|t_j − t_k|` is fitted by least squares to the valid, not yet
/// flagged samples `j ≠ k` within `±half_window` frames, and predicts `ŷ_k`; the
/// leave-one-out residual is `d_k = y_k − ŷ_k`. A frame with fewer than `degree + 2` such
/// neighbours (the ends of a run of lost frames, say) is skipped. `d_k` is divided by
/// `√(1 + h_k)`, `h_k = [(XᵀX)⁻¹]₀₀` the prediction's variance factor for white noise: in the
/// interior of an unbroken uniform run `h_k` is one constant, so this only evens out the ends
/// of the record and the edges of gaps, where the polynomial extrapolates. The channel's scale
/// is the robust standard deviation `1.4826 × MAD` of these residuals. A frame is flagged when
/// its `|d|/scale` exceeds `threshold` *and* is the largest within `±half_window` in that
/// channel: an outlier spoils its neighbours' predictions, so only the local maximum is
/// trusted in a pass. Passes repeat, flagged frames excluded (and only the frames whose
/// window changed refitted), until a pass flags nothing or after `max_passes`.
///
/// A median filter would not do: a marker stepping 500 µm per frame is monotone over five
/// frames, so the median is the sample itself and a 300 µm error leaves no residual. The local
/// polynomial follows the motion (the cubic's misfit over ±2 ms is a few nm) and sees it.
///
/// Cost: linear in frames; one small normal-equation solve per frame and channel per pass.
pub fn detect_outliers(
    t: &[f64],
    channels: &[&[Option<f64>]],
    options: &OutlierOptions,
) -> Vec<bool> {
    let n = t.len();
    let h = options.half_window;
    let mut flagged = vec![false; n];
    if n == 0 || channels.is_empty() {
        return flagged;
    }
    let mut fit = LocalFit::new(options.degree);
    // u[c][k]: standardised leave-one-out residual, NaN where undefined.
    let mut u = vec![vec![f64::NAN; n]; channels.len()];
    // A floor on the scale so that a constant (or noise-free) channel flags nothing by
    // rounding error: 1e-12 of the channel's magnitude.
    let floors: Vec<f64> = channels
        .iter()
        .map(|ch| {
            let size = (0..n)
                .filter_map(|k| sample(ch, k))
                .fold(0.0_f64, |m, v| m.max(v.abs()));
            (1e-12 * size).max(f64::MIN_POSITIVE)
        })
        .collect();
    let mut stale = vec![true; n];
    let mut scratch = Vec::with_capacity(n);
    let mut newly = Vec::new();
    for _ in 0..options.max_passes {
        newly.clear();
        for ((ch, u), &floor) in channels.iter().zip(&mut u).zip(&floors) {
            for k in (0..n).filter(|&k| stale[k]) {
                u[k] = if flagged[k] {
                    f64::NAN
                } else {
                    fit.loo_residual(t, ch, &flagged, k, h)
                };
            }
            let scale = robust_sd(u, &mut scratch).max(floor);
            // Above the threshold (false for NaN) and the local maximum of |u| within ±h (ties
            // go to the earlier frame).
            let z = |k: usize| u[k].abs() / scale;
            for k in (0..n).filter(|&k| z(k) > options.threshold) {
                let (lo, hi) = (k.saturating_sub(h), (k + h).min(n - 1));
                let beaten = (lo..=hi).any(|j| j != k && (z(j) > z(k) || (z(j) == z(k) && j < k)));
                if !beaten {
                    newly.push(k);
                }
            }
        }
        stale.fill(false);
        if newly.is_empty() {
            break;
        }
        for &k in &newly {
            flagged[k] = true;
            stale[k.saturating_sub(h)..=(k + h).min(n - 1)].fill(true);
        }
    }
    flagged
}

/// A valid sample: present and finite.
fn sample(channel: &[Option<f64>], k: usize) -> Option<f64> {
    channel.get(k).copied().flatten().filter(|v| v.is_finite())
}

/// `1.4826 × median |u − median u|` over the finite entries of `u` (0 if none).
fn robust_sd(u: &[f64], scratch: &mut Vec<f64>) -> f64 {
    scratch.clear();
    scratch.extend(u.iter().copied().filter(|v| v.is_finite()));
    if scratch.is_empty() {
        return 0.0;
    }
    let med = median(scratch);
    for v in scratch.iter_mut() {
        *v = (*v - med).abs();
    }
    1.4826 * median(scratch)
}

/// Median (upper median for an even count) of a non-empty slice, reordering it.
fn median(v: &mut [f64]) -> f64 {
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Workspace of the leave-one-out polynomial fit: `p = degree + 1` coefficients.
struct LocalFit {
    p: usize,
    /// Moments `m_q = Σ s^q`, `q = 0..2p−1`.
    moments: Vec<f64>,
    /// `b_q = Σ s^q (y_j − y_k)`.
    rhs: Vec<f64>,
    /// Cholesky factor of the normal matrix `A_ab = m_{a+b}`, row-major lower triangle.
    chol: Vec<f64>,
    /// `L⁻¹ e₀`.
    unit: Vec<f64>,
    /// `L⁻¹ b`.
    rhs_solved: Vec<f64>,
}

impl LocalFit {
    fn new(degree: usize) -> Self {
        let p = degree + 1;
        Self {
            p,
            moments: vec![0.0; 2 * p - 1],
            rhs: vec![0.0; p],
            chol: vec![0.0; p * p],
            unit: vec![0.0; p],
            rhs_solved: vec![0.0; p],
        }
    }

    /// `(y_k − ŷ_k)/√(1 + h_k)` from the valid, unflagged neighbours within ±h, or NaN.
    fn loo_residual(
        &mut self,
        t: &[f64],
        channel: &[Option<f64>],
        flagged: &[bool],
        k: usize,
        h: usize,
    ) -> f64 {
        let (Some(yk), tk) = (sample(channel, k), t[k]) else {
            return f64::NAN;
        };
        let p = self.p;
        let (lo, hi) = (k.saturating_sub(h), (k + h).min(t.len() - 1));
        let neighbours = || {
            (lo..=hi).filter_map(move |j| {
                let y = sample(channel, j)?;
                let dt = t[j] - tk;
                (j != k && !flagged[j] && dt.is_finite()).then_some((dt, y - yk))
            })
        };
        let (count, span) =
            neighbours().fold((0, 0.0_f64), |(c, s), (dt, _)| (c + 1, s.max(dt.abs())));
        if count < p + 1 || span <= 0.0 || !tk.is_finite() {
            return f64::NAN;
        }
        // Normal equations in s = (t_j − t_k)/span: A c = b, A_ab = Σ s^(a+b), b_a = Σ s^a y_j.
        self.moments.fill(0.0);
        self.rhs.fill(0.0);
        for (dt, dy) in neighbours() {
            let s = dt / span;
            let mut power = 1.0;
            for q in 0..2 * p - 1 {
                self.moments[q] += power;
                if q < p {
                    self.rhs[q] += power * dy;
                }
                power *= s;
            }
        }
        // A = L Lᵀ.
        let l = &mut self.chol;
        for i in 0..p {
            for j in 0..=i {
                let mut v = self.moments[i + j];
                for m in 0..j {
                    v -= l[i * p + m] * l[j * p + m];
                }
                if i == j {
                    if v.is_nan() || v <= 1e-12 * self.moments[0] {
                        return f64::NAN;
                    }
                    l[i * p + i] = v.sqrt();
                } else {
                    l[i * p + j] = v / l[j * p + j];
                }
            }
        }
        // ŷ_k − y_k = c₀ = e₀ᵀ A⁻¹ b = (L⁻¹e₀)·(L⁻¹b); h_k = e₀ᵀ A⁻¹ e₀ = |L⁻¹e₀|².
        let (v, g) = (&mut self.unit, &mut self.rhs_solved);
        let (mut c0, mut h00) = (0.0, 0.0);
        for i in 0..p {
            let (mut vi, mut gi) = (if i == 0 { 1.0 } else { 0.0 }, self.rhs[i]);
            for m in 0..i {
                vi -= l[i * p + m] * v[m];
                gi -= l[i * p + m] * g[m];
            }
            v[i] = vi / l[i * p + i];
            g[i] = gi / l[i * p + i];
            c0 += v[i] * g[i];
            h00 += v[i] * v[i];
        }
        -c0 / (1.0 + h00).sqrt()
    }
}

/// AR(1) noise: marginal standard deviation and lag-one correlation,
/// `e_k = ρ e_{k−1} + √(1−ρ²) σ ξ_k` with `ξ` white and of unit variance.
///
/// ```
/// let n = mbs_identify::noise::Ar1 { sigma: 30e-6, rho: 0.8 };
/// // The innovation (one-step prediction error) standard deviation:
/// assert!((n.sigma * (1.0 - n.rho * n.rho).sqrt() - 18e-6).abs() < 1e-12);
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ar1 {
    /// Marginal standard deviation σ (the units of the data).
    pub sigma: f64,
    /// Lag-one correlation ρ, in (−1, 1).
    pub rho: f64,
}

/// Autocovariance at `lag` of a filtered AR(1) with σ = 1:
/// `z_k = Σ_a c_a e_{k−a}`, `c = filter`, `Cov(e_i, e_j) = ρ^|i−j|`, gives
///
/// `γ_j = Cov(z_k, z_{k+j}) = Σ_a Σ_b c_a c_b Cov(e_{k−a}, e_{k+j−b}) = Σ_a Σ_b c_a c_b ρ^|a−b+j|`.
///
/// For the third difference `c = [1, −3, 3, −1]`: `γ₀ = 20 − 30ρ + 12ρ² − 2ρ³`,
/// `γ₁ = −15 + 26ρ − 16ρ² + 6ρ³ − ρ⁴`. Multiply by σ² for noise of standard deviation σ.
///
/// ```
/// use mbs_identify::noise::ar1_difference_autocovariance as gamma;
/// let c = [1.0, -3.0, 3.0, -1.0];
/// let rho: f64 = 0.8;
/// let g0 = 20.0 - 30.0 * rho + 12.0 * rho.powi(2) - 2.0 * rho.powi(3);
/// assert!((gamma(&c, 0, rho) - g0).abs() < 1e-12);
/// assert!((gamma(&c, 1, 0.0) + 15.0).abs() < 1e-12); // white noise: −Σ c_a c_{a+1}
/// ```
pub fn ar1_difference_autocovariance(filter: &[f64], lag: usize, rho: f64) -> f64 {
    let mut gamma = 0.0;
    for (a, ca) in filter.iter().enumerate() {
        for (b, cb) in filter.iter().enumerate() {
            let m = (a + lag).abs_diff(b);
            gamma += ca * cb * rho.powi(m as i32);
        }
    }
    gamma
}

/// Differences whose mean squares are matched, as (order, stride), by increasing span: third
/// differences up to stride 4, then orders rising with the stride so that a smooth motion's
/// part stays negligible (see [`estimate_ar1`]).
const DIFFERENCES: [(usize, usize); 12] = [
    (3, 1),
    (3, 2),
    (3, 3),
    (3, 4),
    (4, 6),
    (4, 8),
    (4, 12),
    (5, 16),
    (5, 24),
    (6, 32),
    (6, 48),
    (6, 64),
];
/// The first fit uses this many of them; the others are added one by one.
const FIRST_DIFFERENCES: usize = 4;
/// Largest rise of the weighted misfit (χ² with one degree of freedom under the model) that
/// one more, longer difference may bring; beyond it that difference and all longer ones are
/// taken as spoilt by the motion.
const MOTION_GUARD: f64 = 16.0;
/// Fewest stride-1 differences for an estimate; fewest for any other stride to be used.
const MIN_DIFFERENCES: usize = 50;
const MIN_STRIDE_DIFFERENCES: usize = 25;
/// Differences beyond this many robust standard deviations are left out of a mean square.
const CLIP: f64 = 3.5;

/// Estimates the camera noise from the data itself, not from model residuals.
///
/// `channels` are series over the same frames (uniform frame rate; a marker's x and y, or all
/// markers of a run), pooled into one estimate; `excluded` marks frames not to use (outliers
/// found by [`detect_outliers`], contact phases; shorter than a channel means "not excluded"
/// beyond its end). Lost (`None`, non-finite) samples are never used; a difference is used
/// only when all its frames are valid and not excluded. Returns `None` with fewer than 50
/// usable third differences (or a noise-free record).
///
/// **Differences.** The third difference `z_k = y_k − 3y_{k−1} + 3y_{k−2} − y_{k−3}` removes
/// the motion (a 12 rad/s swing's is ~1e-8 m, against 30 µm of noise) and keeps the noise, whose
/// autocovariance is known exactly for AR(1) noise ([`ar1_difference_autocovariance`],
/// `γ_j = σ² Σ_a Σ_b c_a c_b ρ^|a−b+j|`).
///
/// **Why not only lags 0 and 1.** Their ratio `γ₁/γ₀` is −0.75 at ρ = 0, −0.686 at ρ = 0.5,
/// −0.669 at ρ = 0.8 and −2/3 as ρ → 1: the third difference of a strongly correlated noise
/// looks like the second difference of a white one whatever ρ is. With 48 000 differences the
/// ratio's sampling spread (0.003) maps to a spread of 0.1 in ρ̂ near 0.8 (simulated), and σ̂,
/// read from `γ₀ = σ² γ₀(ρ)` with `d ln γ₀/dρ ≈ −5.3` there, to ~25 %. The information on
/// ρ lies at longer lags, where the stride-1 autocovariances are tiny
/// (`γ_j = −σ² ρ^(j−3) (1−ρ)⁶` for `j ≥ 3`).
///
/// **What is matched instead.** The difference of order `d` with stride `s`,
/// `z_k = Σ_a c_a y_{k−as}`, `c_a = (−1)^a C(d, a)`, is the same formula with the filter
/// dilated (`c` placed at `0, s, 2s, …`), so its lag-0 value is
///
/// `V = σ² F(ρ)`, `F(ρ) = Σ_a Σ_b c_a c_b ρ^(s|a−b|)` (`= 20 − 30ρ^s + 12ρ^2s − 2ρ^3s` for d = 3).
///
/// For `d = 3` it combines the stride-1 autocovariances at lags up to `3(s−1)`, since
/// `(1 − B^s)³ = (1 − B)³ (1 + B + … + B^(s−1))³`. `F` depends on `ρ^s`, so the strides where
/// `ρ^s` lies between ~0.1 and ~0.7 pin ρ down: strides 1 to 64 cover ρ up to ~0.97. The
/// robust mean squares `V̂` of `(d, s)` = (3, 1), (3, 2), (3, 3), (3, 4), (4, 6), (4, 8),
/// (4, 12), (5, 16), (5, 24), (6, 32), (6, 48), (6, 64) are fitted in logarithms,
/// `ln V̂ ≈ ln σ² + ln F(ρ)`: for a given ρ, `ln σ²` is the weighted mean of
/// `ln V̂ − ln F(ρ)`, and ρ minimises the weighted misfit (grid, then golden section, on
/// `[−0.99, 0.995]`). The weights are the inverse covariance of the `ln V̂` under the AR(1)
/// model at the previous ρ̂ (generalised least squares: the moments share data, and the long
/// strides are noisier), equal in the first pass. On 12 000 frames × 4 channels the spread of
/// σ̂ is about 0.4 % at ρ = 0, 0.65 % at ρ = 0.8, 1.0 % at ρ = 0.9 and 1.8 % at ρ = 0.95 —
/// about what an efficient estimator that knew the motion would give (0.3 %, 0.7 %, 1.0 %,
/// 1.4 %) — and that of ρ̂ about 0.005, 0.002, 0.002, 0.002.
///
/// **Motion.** The motion's part of a `(d, s)` difference is ~`x⁽ᵈ⁾·(s Δt)^d`; the order grows
/// with the stride to keep it small. For a marker 0.12 m from a pivot swinging at up to
/// 10.6 rad/s at 3000 fps it is below 0.4 % of the noise variance in every moment. For rougher
/// motion the differences are added by increasing span, the first four together, then one at a
/// time while the weighted misfit (χ² under the model) rises by less than 16; the first that
/// breaks this and all longer ones are dropped. A marker bouncing on a felt (velocity
/// reversals, jerk ~3000 m/s³) then still gives σ̂ about 1 % (ρ = 0) to 4 % (ρ = 0.8) high,
/// and ρ̂ 0.01–0.02 high; for more strongly
/// correlated noise on such motion σ̂ is not reliable (the noise's slow part overlaps the
/// motion's harmonics): estimate from static segments, or exclude the contact phases.
///
/// **Outliers.** Each mean square is a clipped one: `s²` such that the mean of `z²` over
/// `|z| < 3.5 s` equals `s²·E[Z² | |Z| < 3.5]` (iterated from the MAD; unbiased for Gaussian
/// `z`, efficiency ~97 %). An undetected gross error touches `d + 1` differences per stride,
/// scaled by the binomial coefficients; the large ones (and the differences that straddle an
/// impact) lie far beyond 3.5 s and are ignored however many they are, the rest bias σ̂ by a
/// per cent or two (0.3 % of frames at ±10σ: within 2 %, where a plain mean square of the
/// third difference grows by 20–150 %; see the tests).
///
/// ```
/// use mbs_identify::noise::estimate_ar1;
/// // Far too short:
/// assert!(estimate_ar1(&[&[Some(0.0); 20][..]], &[]).is_none());
/// ```
pub fn estimate_ar1(channels: &[&[Option<f64>]], excluded: &[bool]) -> Option<Ar1> {
    let usable = |ch: &[Option<f64>], k: usize| {
        sample(ch, k).filter(|_| !excluded.get(k).copied().unwrap_or(false))
    };
    let mut z = Vec::new();
    // Robust ln V̂ of the difference (order, stride), or None if too few differences.
    let mut log_mean_square = |order: usize, stride: usize| {
        let filter = binomial_difference(order);
        let span = order * stride;
        z.clear();
        for ch in channels {
            // z_k = Σ_a c_a y_{k−a·stride}, all taps usable.
            z.extend((span..ch.len()).filter_map(|k| {
                filter.iter().enumerate().try_fold(0.0, |acc, (a, c)| {
                    usable(ch, k - a * stride).map(|y| acc + c * y)
                })
            }));
        }
        let needed = if stride == 1 {
            MIN_DIFFERENCES
        } else {
            MIN_STRIDE_DIFFERENCES
        };
        let v = clipped_mean_square(&mut z, CLIP);
        (z.len() >= needed && v > 0.0 && v.is_finite()).then(|| Moment {
            filter,
            stride,
            count: z.len(),
            ln_mean_square: v.ln(),
        })
    };
    let mut moments: Vec<Moment> = Vec::new();
    for (order, stride) in DIFFERENCES {
        match log_mean_square(order, stride) {
            Some(m) => moments.push(m),
            None if stride == 1 => return None,
            None => {}
        }
    }
    if moments.len() < 2 {
        return None;
    }
    // Longer differences one at a time, while each stays consistent with the shorter ones.
    let mut used = FIRST_DIFFERENCES.min(moments.len());
    let (mut noise, mut misfit) = fit_ar1(&moments[..used]);
    while used < moments.len() {
        let (longer, longer_misfit) = fit_ar1(&moments[..=used]);
        if longer_misfit - misfit > MOTION_GUARD {
            break;
        }
        (noise, misfit, used) = (longer, longer_misfit, used + 1);
    }
    Some(noise)
}

/// The robust mean square of one dilated difference, `V̂ = mean z²`, `z_k = Σ_a c_a y_{k−a·s}`.
struct Moment {
    /// `c`.
    filter: Vec<f64>,
    /// `s`.
    stride: usize,
    /// Number of differences behind `V̂`.
    count: usize,
    /// `ln V̂`.
    ln_mean_square: f64,
}

impl Moment {
    /// `Cov(z_k, z'_{k+m})` for unit AR(1) noise, `z'` the difference of `other`:
    /// `Σ_a Σ_b c_a c'_b ρ^|m + a s − b s'|`, with `powers[i] = ρ^i`.
    fn cross_covariance(&self, other: &Moment, m: i64, powers: &[f64]) -> f64 {
        let mut sum = 0.0;
        for (a, ca) in self.filter.iter().enumerate() {
            for (b, cb) in other.filter.iter().enumerate() {
                let lag = m + (a * self.stride) as i64 - (b * other.stride) as i64;
                sum += ca * cb * powers[lag.unsigned_abs() as usize];
            }
        }
        sum
    }

    /// The span `order × stride` of the difference, in frames.
    fn span(&self) -> usize {
        (self.filter.len() - 1) * self.stride
    }
}

/// `c_a = (−1)^a C(order, a)`, `a = 0..=order`.
fn binomial_difference(order: usize) -> Vec<f64> {
    let mut c = vec![1.0];
    for a in 1..=order {
        let prev = c[a - 1];
        c.push(-prev * (order + 1 - a) as f64 / a as f64);
    }
    c
}

/// σ and ρ fitted to the moments, `ln V̂_i ≈ ln σ² + ln F_i(ρ)`,
/// `F_i(ρ) = Σ_a Σ_b c_a c_b ρ^(s|a−b|)`, by generalised least squares: the misfit
/// `r = ln V̂ − ln F(ρ) − ln σ²` is weighed by the inverse of the moments' covariance
/// (they share data, and the long strides are noisier), computed under the AR(1) model at the
/// previous ρ̂; the first pass weighs them equally. For a given ρ, `ln σ²` is the weighted mean
/// of `ln V̂ − ln F(ρ)`; ρ minimises `rᵀ W r`.
fn fit_ar1(moments: &[Moment]) -> (Ar1, f64) {
    let count = moments.len();
    // g_m = Σ_a c_a c_{a+m}: F_i(ρ) = g₀ + 2 Σ_{m≥1} g_m ρ^(s m).
    let g: Vec<Vec<f64>> = moments
        .iter()
        .map(|mo| {
            (0..mo.filter.len())
                .map(|m| ar1_difference_autocovariance(&mo.filter, m, 0.0))
                .collect()
        })
        .collect();
    let residuals = |rho: f64| -> DVector<f64> {
        DVector::from_fn(count, |i, _| {
            let r = rho.powi(moments[i].stride as i32);
            let (mut f, mut rm) = (g[i][0], 1.0);
            for gm in &g[i][1..] {
                rm *= r;
                f += 2.0 * gm * rm;
            }
            moments[i].ln_mean_square - f.ln()
        })
    };
    // (misfit, ln σ²) at ρ for the weights w.
    let fit = |rho: f64, w: &DMatrix<f64>| {
        let r = residuals(rho);
        let ones = DVector::from_element(count, 1.0);
        let w_ones = w * &ones;
        let ln_var = w_ones.dot(&r) / w_ones.dot(&ones);
        let misfit = r.add_scalar(-ln_var);
        ((w * &misfit).dot(&misfit), ln_var)
    };
    let mut w = DMatrix::identity(count, count);
    let mut rho = minimise_on_interval(|rho| fit(rho, &w).0, -0.99, 0.995);
    for _ in 0..2 {
        match moment_weights(moments, rho) {
            Some(weights) => w = weights,
            None => break,
        }
        rho = minimise_on_interval(|rho| fit(rho, &w).0, -0.99, 0.995);
    }
    let (misfit, ln_var) = fit(rho, &w);
    let sigma = (0.5 * ln_var).exp();
    (Ar1 { sigma, rho }, misfit)
}

/// Inverse covariance of the `ln V̂_i` under unit AR(1) noise of correlation ρ. For Gaussian
/// series, `Cov(mean z², mean z'²) ≈ (2/n) Σ_m Cov(z_k, z'_{k+m})²`; dividing by `V V'` gives
/// the covariance of the logarithms. Beyond the spans the cross-covariance decays as `ρ^|m|`,
/// so the tails are summed in closed form. `None` if the matrix is not positive definite.
fn moment_weights(moments: &[Moment], rho: f64) -> Option<DMatrix<f64>> {
    let count = moments.len();
    let longest = moments.iter().map(Moment::span).max().unwrap_or(0);
    let powers: Vec<f64> = (0..=2 * longest + 1).map(|i| rho.powi(i as i32)).collect();
    let tail = rho * rho / (1.0 - rho * rho);
    let variance: Vec<f64> = moments
        .iter()
        .map(|mo| mo.cross_covariance(mo, 0, &powers))
        .collect();
    let mut cov = DMatrix::zeros(count, count);
    for i in 0..count {
        for j in 0..=i {
            let (a, b) = (&moments[i], &moments[j]);
            let (lo, hi) = (-(a.span() as i64), b.span() as i64);
            let core: f64 = (lo..=hi)
                .map(|m| a.cross_covariance(b, m, &powers).powi(2))
                .sum();
            let ends = a.cross_covariance(b, lo, &powers).powi(2)
                + a.cross_covariance(b, hi, &powers).powi(2);
            let n = (a.count as f64 * b.count as f64).sqrt();
            let c = 2.0 * (core + tail * ends) / (n * variance[i] * variance[j]);
            cov[(i, j)] = c;
            cov[(j, i)] = c;
        }
    }
    cov.cholesky().map(|l| l.inverse())
}

/// Robust mean square of zero-mean `z`: `s²` such that `s² κ(c) = mean of z² over |z| < c s`,
/// `κ(c) = E[Z² | |Z| < c]` for a standard normal, found by fixed-point iteration from
/// `s = 1.4826 median |z|`. Unbiased for Gaussian `z`; values beyond `c s` are ignored however
/// many they are (under half). Reorders `z`; NaN if empty.
fn clipped_mean_square(z: &mut [f64], c: f64) -> f64 {
    if z.is_empty() {
        return f64::NAN;
    }
    for v in z.iter_mut() {
        *v = v.abs();
    }
    let mut s = 1.4826 * median(z);
    let kappa = gaussian_clipped_second_moment(c);
    for _ in 0..50 {
        let (sum, kept) = z
            .iter()
            .filter(|&&v| v < c * s)
            .fold((0.0, 0usize), |(sum, n), v| (sum + v * v, n + 1));
        if kept == 0 {
            break;
        }
        let next = (sum / kept as f64 / kappa).sqrt();
        let converged = (next - s).abs() <= 1e-9 * s;
        s = next;
        if converged {
            break;
        }
    }
    s * s
}

/// `κ(c) = E[Z² | |Z| < c] = (P − 2cφ(c))/P`, `P = P(|Z| < c)`, for a standard normal `Z`
/// (integrating `z²φ` by parts); `P = 2 ∫₀^c φ` by Simpson's rule (error < 1e-10 for c ≤ 8).
fn gaussian_clipped_second_moment(c: f64) -> f64 {
    let phi = |z: f64| (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let m = 200;
    let h = c / m as f64;
    let simpson: f64 = (0..=m)
        .map(|i| {
            let w = match i {
                0 => 1.0,
                _ if i == m => 1.0,
                _ if i % 2 == 1 => 4.0,
                _ => 2.0,
            };
            w * phi(i as f64 * h)
        })
        .sum();
    let p = 2.0 * simpson * h / 3.0;
    (p - 2.0 * c * phi(c)) / p
}

/// Minimiser of `f` on `[a, b]`: the best of 200 grid points, then golden section between its
/// neighbours.
fn minimise_on_interval(f: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let steps = 200;
    let at = |i: usize| a + (b - a) * i as f64 / steps as f64;
    let best = (0..=steps)
        .min_by(|&i, &j| f(at(i)).total_cmp(&f(at(j))))
        .unwrap_or(0);
    let (mut lo, mut hi) = (at(best.saturating_sub(1)), at((best + 1).min(steps)));
    let golden = 0.5 * (5.0_f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - golden * (hi - lo), lo + golden * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..60 {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - golden * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + golden * (hi - lo);
            f2 = f(x2);
        }
    }
    0.5 * (lo + hi)
}

/// AR(1) prewhitening of a standardised residual sequence:
/// `w_k = (r_k − ρ r_{k−1}) / √(1 − ρ²)`, except at the first sample of each segment
/// (`segment_start[k]` true, and always at `k = 0`) where `w_k = r_k`. A `segment_start`
/// shorter than `residuals` means "no start" beyond its end.
///
/// Under the AR(1) model the `w` are white with unit variance when `r` is standardised by σ
/// (the residual divided by [`Ar1::sigma`]): `r_k − ρ r_{k−1}` is the innovation, of variance
/// `1 − ρ²`, and the first sample of a segment already has unit variance. The transform is
/// linear and lower-triangular, so it can be applied to residuals and to Jacobian columns
/// ([`whiten_columns`]) alike, and `Σ w²` is the Gaussian AR(1) log-likelihood's quadratic form.
///
/// # Panics
/// If `|rho| ≥ 1` or `rho` is not a number.
///
/// ```
/// let w = mbs_identify::noise::whiten(&[1.0, 1.0, 2.0, 2.0], &[true, false, true, false], 0.6);
/// assert!((w[1] - 0.5).abs() < 1e-12 && w[2] == 2.0 && (w[3] - 1.0).abs() < 1e-12);
/// ```
pub fn whiten(residuals: &[f64], segment_start: &[bool], rho: f64) -> Vec<f64> {
    let mut w = residuals.to_vec();
    whiten_in_place(&mut w, segment_start, rho);
    w
}

/// [`whiten`] applied in place to every column of a Jacobian (rows = residuals, in the same
/// order and with the same `segment_start` as the residual vector). `nalgebra`'s `DMatrix` is
/// column-major, so each column is one contiguous sequence. Since whitening is linear, the
/// whitened Jacobian is the Jacobian of the whitened residuals.
///
/// # Panics
/// If `|rho| ≥ 1` or `rho` is not a number.
///
/// ```
/// use mbs_identify::noise::{whiten, whiten_columns};
/// let mut j = nalgebra::DMatrix::from_column_slice(3, 2, &[1.0, 2.0, 3.0, 0.0, 1.0, 0.0]);
/// whiten_columns(&mut j, &[], 0.5);
/// assert_eq!(j.column(1).as_slice(), whiten(&[0.0, 1.0, 0.0], &[], 0.5).as_slice());
/// ```
pub fn whiten_columns(jacobian: &mut DMatrix<f64>, segment_start: &[bool], rho: f64) {
    let rows = jacobian.nrows();
    if rows == 0 {
        return;
    }
    for column in jacobian.as_mut_slice().chunks_exact_mut(rows) {
        whiten_in_place(column, segment_start, rho);
    }
}

fn whiten_in_place(r: &mut [f64], segment_start: &[bool], rho: f64) {
    assert!(rho.abs() < 1.0, "AR(1) whitening needs |ρ| < 1, got {rho}");
    let gain = 1.0 / (1.0 - rho * rho).sqrt();
    // Backwards, so that r[k−1] is still the original when w_k is formed.
    for k in (1..r.len()).rev() {
        if !segment_start.get(k).copied().unwrap_or(false) {
            r[k] = (r[k] - rho * r[k - 1]) * gain;
        }
    }
}

/// Ljung–Box statistic of a white-noise test on `w` up to `lags`:
/// `Q = n (n+2) Σ_{k=1}^{h} ρ̂_k² / (n − k)`, `ρ̂_k` the sample autocorrelation (mean
/// removed), `h = min(lags, n − 1)`. Returns `(Q, h)`; under the white-noise hypothesis `Q` is
/// about χ² with `h` degrees of freedom (mean `h`, standard deviation `√(2h)`), less the
/// number of fitted parameters if `w` are residuals of a fitted ARMA. With fewer than two
/// samples or a constant `w` there is nothing to test: `(0, 0)`.
///
/// ```
/// let (q, h) = mbs_identify::noise::ljung_box(&[1.0, -1.0, 1.0, -1.0, 1.0, -1.0], 2);
/// assert_eq!(h, 2);
/// assert!(q > 5.0); // perfectly alternating: ρ̂₁ ≈ −1
/// ```
pub fn ljung_box(w: &[f64], lags: usize) -> (f64, usize) {
    let n = w.len();
    if n < 2 {
        return (0.0, 0);
    }
    let mean = w.iter().sum::<f64>() / n as f64;
    let c0: f64 = w.iter().map(|v| (v - mean).powi(2)).sum();
    if !c0.is_finite() || c0 <= 0.0 {
        return (0.0, 0);
    }
    let h = lags.min(n - 1);
    let q: f64 = (1..=h)
        .map(|k| {
            let ck: f64 = w
                .iter()
                .zip(&w[k..])
                .map(|(a, b)| (a - mean) * (b - mean))
                .sum();
            (ck / c0).powi(2) / (n - k) as f64
        })
        .sum();
    (n as f64 * (n as f64 + 2.0) * q, h)
}
