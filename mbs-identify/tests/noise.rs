//! Noise floor and outliers: AR(1) estimation, outlier detection, whitening, Ljung–Box, on
//! synthetic camera data (3000 fps, σ = 30 µm, a fast swinging marker and a stuck one).

use mbs_identify::noise::{
    Ar1, OutlierOptions, ar1_difference_autocovariance, detect_outliers, estimate_ar1, ljung_box,
    whiten, whiten_columns,
};
use nalgebra::DMatrix;

const FPS: f64 = 3000.0;
const SIGMA: f64 = 30e-6;
const FRAMES: usize = 12_000;

/// SplitMix64 with Box–Muller normals: a seeded generator, no crate needed.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in (0, 1].
    fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) + 1) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
}

/// Stationary AR(1): e_k = ρ e_{k−1} + √(1−ρ²) σ ξ_k, e_0 = σ ξ_0.
fn ar1_noise(rng: &mut Rng, n: usize, sigma: f64, rho: f64) -> Vec<f64> {
    let innovation = (1.0 - rho * rho).sqrt() * sigma;
    let mut e = Vec::with_capacity(n);
    let mut prev = sigma * rng.normal();
    for k in 0..n {
        if k > 0 {
            prev = rho * prev + innovation * rng.normal();
        }
        e.push(prev);
    }
    e
}

fn frame_times(n: usize) -> Vec<f64> {
    (0..n).map(|k| k as f64 / FPS).collect()
}

/// A marker 0.12 m from a pivot: θ(t) = 1.2 cos(8.8 t) e^(−0.3 t), up to 10.6 rad/s
/// (1.3 m/s, 420 µm per frame).
fn swinging_marker(t: f64) -> [f64; 2] {
    let theta = 1.2 * (8.8 * t).cos() * (-0.3 * t).exp();
    [0.12 * theta.cos(), 0.12 * theta.sin()]
}

/// A marker that does not move.
fn stuck_marker(_: f64) -> [f64; 2] {
    [0.031, -0.087]
}

/// x and y of a marker plus independent AR(1) noise on each.
fn noisy_marker(
    rng: &mut Rng,
    motion: fn(f64) -> [f64; 2],
    n: usize,
    rho: f64,
) -> [Vec<Option<f64>>; 2] {
    let t = frame_times(n);
    std::array::from_fn(|axis| {
        let e = ar1_noise(rng, n, SIGMA, rho);
        t.iter()
            .zip(e)
            .map(|(&t, e)| Some(motion(t)[axis] + e))
            .collect()
    })
}

/// Gross tracking errors of ±10σ on x, y or both, at `fraction` of the frames (distinct,
/// random). Returns the spoilt frames.
fn add_outliers(rng: &mut Rng, xy: &mut [Vec<Option<f64>>; 2], fraction: f64) -> Vec<usize> {
    let n = xy[0].len();
    let mut frames: Vec<usize> = Vec::new();
    while (frames.len() as f64) < fraction * n as f64 {
        let k = rng.below(n);
        if frames.contains(&k) || xy[0][k].is_none() {
            continue;
        }
        let which = rng.below(3); // 0: x, 1: y, 2: both
        for (axis, channel) in xy.iter_mut().enumerate() {
            if which == axis || which == 2 {
                let sign = if rng.below(2) == 0 { 1.0 } else { -1.0 };
                channel[k] = channel[k].map(|v| v + sign * 10.0 * SIGMA);
            }
        }
        frames.push(k);
    }
    frames.sort_unstable();
    frames
}

fn refs(channels: &[Vec<Option<f64>>]) -> Vec<&[Option<f64>]> {
    channels.iter().map(|c| c.as_slice()).collect()
}

fn assert_close(est: Ar1, rho: f64, sigma_tol: f64, rho_tol: f64, what: &str) {
    let sigma_err = est.sigma / SIGMA - 1.0;
    let rho_err = est.rho - rho;
    println!(
        "{what}: σ̂ = {:.2} µm ({:+.2} %), ρ̂ = {:.4} ({:+.4})",
        est.sigma * 1e6,
        100.0 * sigma_err,
        est.rho,
        rho_err
    );
    assert!(
        sigma_err.abs() < sigma_tol,
        "{what}: σ̂ = {} vs {SIGMA}",
        est.sigma
    );
    assert!(rho_err.abs() < rho_tol, "{what}: ρ̂ = {} vs {rho}", est.rho);
}

#[test]
fn the_difference_autocovariance_matches_a_simulated_differenced_ar1() {
    // γ_j of the third difference against sample autocovariances of 400 000 frames.
    let c = [1.0, -3.0, 3.0, -1.0];
    let mut rng = Rng(11);
    for rho in [0.0, 0.5, 0.8] {
        let e = ar1_noise(&mut rng, 400_000, 1.0, rho);
        let z: Vec<f64> = (3..e.len())
            .map(|k| e[k] - 3.0 * e[k - 1] + 3.0 * e[k - 2] - e[k - 3])
            .collect();
        let g0 = ar1_difference_autocovariance(&c, 0, rho);
        for lag in 0..4 {
            let sample =
                z.iter().zip(&z[lag..]).map(|(a, b)| a * b).sum::<f64>() / (z.len() - lag) as f64;
            let exact = ar1_difference_autocovariance(&c, lag, rho);
            assert!(
                (sample - exact).abs() < 0.02 * g0,
                "ρ {rho} lag {lag}: {sample} vs {exact}"
            );
        }
    }
    // Why lags 0 and 1 alone cannot give ρ: their ratio hardly moves between 0.5 and 0.95.
    let ratio =
        |rho| ar1_difference_autocovariance(&c, 1, rho) / ar1_difference_autocovariance(&c, 0, rho);
    assert!((ratio(0.0) + 0.75).abs() < 1e-12);
    assert!((ratio(0.5) - ratio(0.95)).abs() < 0.02);
}

#[test]
fn ar1_is_estimated_from_pure_noise() {
    // 12 000 frames, 4 channels, σ = 30 µm; ρ = 0, 0.8, 0.95; several seeds each.
    for rho in [0.0, 0.8, 0.95] {
        for seed in 1..=3 {
            let mut rng = Rng(1000 * seed + (100.0 * rho) as u64);
            let channels: Vec<Vec<Option<f64>>> = (0..4)
                .map(|_| {
                    ar1_noise(&mut rng, FRAMES, SIGMA, rho)
                        .into_iter()
                        .map(Some)
                        .collect()
                })
                .collect();
            let est = estimate_ar1(&refs(&channels), &[]).unwrap();
            assert_close(est, rho, 0.05, 0.03, &format!("noise ρ {rho} seed {seed}"));
        }
    }
}

#[test]
fn fast_or_stuck_motion_does_not_bias_the_noise_estimate() {
    for (name, motion) in [
        ("swinging", swinging_marker as fn(f64) -> [f64; 2]),
        ("stuck", stuck_marker),
    ] {
        for rho in [0.0, 0.8] {
            for seed in 1..=3 {
                let mut rng = Rng(7000 + seed + (100.0 * rho) as u64);
                // Two markers' worth of channels: 4 series.
                let [x1, y1] = noisy_marker(&mut rng, motion, FRAMES, rho);
                let [x2, y2] = noisy_marker(&mut rng, motion, FRAMES, rho);
                let est = estimate_ar1(&refs(&[x1, y1, x2, y2]), &[]).unwrap();
                assert_close(est, rho, 0.05, 0.03, &format!("{name} ρ {rho} seed {seed}"));
            }
        }
    }
}

/// Per-channel median-filter detector with the same threshold and local-maximum logic:
/// r_k = y_k − median(y_{k−2..=k+2}), scale 1.4826 MAD (or `known_scale`), one pass.
fn median_filter_flags(
    channels: &[&[Option<f64>]],
    threshold: f64,
    half_window: usize,
    known_scale: Option<f64>,
) -> Vec<bool> {
    let n = channels[0].len();
    let mut flags = vec![false; n];
    for ch in channels {
        let r: Vec<f64> = (0..n)
            .map(|k| {
                let Some(y) = ch[k] else { return f64::NAN };
                let mut w: Vec<f64> = (k.saturating_sub(2)..(k + 3).min(n))
                    .filter_map(|j| ch[j])
                    .collect();
                w.sort_by(f64::total_cmp);
                y - w[w.len() / 2]
            })
            .collect();
        let mut v: Vec<f64> = r.iter().copied().filter(|x| x.is_finite()).collect();
        v.sort_by(f64::total_cmp);
        let med = v[v.len() / 2];
        let mut dev: Vec<f64> = v.iter().map(|x| (x - med).abs()).collect();
        dev.sort_by(f64::total_cmp);
        // The same floor as the detector's (1e-12 of the magnitude): on a fast swing more than
        // half the residuals are exactly 0 and the MAD collapses.
        let size = ch.iter().flatten().fold(0.0_f64, |m, v| m.max(v.abs()));
        let scale = known_scale.unwrap_or((1.4826 * dev[dev.len() / 2]).max(1e-12 * size));
        for k in 0..n {
            let z = r[k].abs() / scale;
            let (lo, hi) = (k.saturating_sub(half_window), (k + half_window).min(n - 1));
            if z > threshold
                && (lo..=hi).all(|j| j == k || r[j].is_nan() || r[j].abs() / scale <= z)
            {
                flags[k] = true;
            }
        }
    }
    flags
}

/// (detected, missed, false flags) of `flags` against the spoilt frames.
fn score(flags: &[bool], spoilt: &[usize]) -> (usize, usize, usize) {
    let detected = spoilt.iter().filter(|&&k| flags[k]).count();
    let false_flags = flags.iter().filter(|&&f| f).count() - detected;
    (detected, spoilt.len() - detected, false_flags)
}

#[test]
fn outliers_on_a_fast_swing_are_found_where_a_median_filter_fails() {
    // 0.3 % of frames spoilt by ±10σ on x, y or both; AR(1) noise ρ = 0.8; 5 seeds.
    let t = frame_times(FRAMES);
    let options = OutlierOptions::default();
    let (mut ours, mut median, mut told_missed) = ((0, 0, 0), (0, 0, 0), 0);
    for seed in 1..=5 {
        let mut rng = Rng(31_000 + seed);
        let mut xy = noisy_marker(&mut rng, swinging_marker, FRAMES, 0.8);
        let spoilt = add_outliers(&mut rng, &mut xy, 0.003);
        let flags = detect_outliers(&t, &refs(&xy), &options);
        let (d, m, f) = score(&flags, &spoilt);
        let medf = median_filter_flags(&refs(&xy), options.threshold, options.half_window, None);
        let (md, mm, mf) = score(&medf, &spoilt);
        // Even told the noise's scale, the median filter misses errors on the fast parts,
        // where the median of five monotone samples is the spoilt sample itself.
        let told = Some(SIGMA);
        let medk = median_filter_flags(&refs(&xy), options.threshold, options.half_window, told);
        let (kd, km, kf) = score(&medk, &spoilt);
        println!(
            "seed {seed}: {} spoilt; local cubic: {d} found, {m} missed, {f} false; \
             median filter: {md} found, {mm} missed, {mf} false; \
             with scale σ: {kd} found, {km} missed, {kf} false",
            spoilt.len()
        );
        told_missed += km;
        assert!(f <= FRAMES / 1000, "seed {seed}: {f} false flags");
        ours = (ours.0 + d, ours.1 + m, ours.2 + f);
        median = (median.0 + md, median.1 + mm, median.2 + mf);
    }
    let rate = |(d, m, _): (usize, usize, usize)| d as f64 / (d + m) as f64;
    println!(
        "detection: local cubic {:.1} % ({} false), median filter {:.1} % ({} false)",
        100.0 * rate(ours),
        ours.2,
        100.0 * rate(median),
        median.2
    );
    assert!(rate(ours) >= 0.95);
    assert!(ours.2 <= 5 * FRAMES / 1000);
    // The median filter, on the same data with the same threshold logic, gets far more wrong:
    // its MAD collapses (hundreds of false flags), and given the right scale it misses the
    // errors on the fast parts of the swing.
    println!("median filter told σ: {told_missed} missed");
    assert!(told_missed >= (ours.0 + ours.1) / 10);
    let errors = |(_, m, f): (usize, usize, usize)| m + f;
    assert!(
        errors(median) > 10 * errors(ours).max(1),
        "median filter {median:?} vs ours {ours:?}"
    );
}

#[test]
fn lost_frames_are_neither_flagged_nor_used() {
    // 0.1 % lost frames at random plus a run of 30, on the swing with outliers.
    let t = frame_times(FRAMES);
    for seed in 1..=3 {
        let mut rng = Rng(41_000 + seed);
        let mut xy = noisy_marker(&mut rng, swinging_marker, FRAMES, 0.8);
        let clean = xy.clone();
        let mut lost: Vec<usize> = (0..FRAMES / 1000).map(|_| rng.below(FRAMES)).collect();
        lost.extend(5_000..5_030);
        for &k in &lost {
            xy[0][k] = None;
            xy[1][k] = None;
        }
        let spoilt = add_outliers(&mut rng, &mut xy, 0.003);
        let flags = detect_outliers(&t, &refs(&xy), &OutlierOptions::default());
        assert!(
            lost.iter().all(|&k| !flags[k]),
            "seed {seed}: a lost frame flagged"
        );
        let (d, m, f) = score(&flags, &spoilt);
        println!("seed {seed}: {d} found, {m} missed, {f} false");
        assert!(
            m <= 1 && f <= FRAMES / 1000,
            "seed {seed}: {m} missed, {f} false"
        );

        // The noise estimate with lost and flagged frames left out matches the clean one.
        let with_gaps = estimate_ar1(&refs(&xy), &flags).unwrap();
        let without = estimate_ar1(&refs(&clean), &[]).unwrap();
        println!("  with gaps {with_gaps:?}, clean {without:?}");
        assert!((with_gaps.sigma / without.sigma - 1.0).abs() < 0.01);
        assert!((with_gaps.rho - without.rho).abs() < 0.005);
        assert_close(with_gaps, 0.8, 0.05, 0.03, &format!("gaps seed {seed}"));
    }
}

/// Plain mean square of the third difference over all channels (no trimming).
fn plain_third_difference_mean_square(channels: &[Vec<Option<f64>>]) -> f64 {
    let z: Vec<f64> = channels
        .iter()
        .flat_map(|y| {
            (3..y.len())
                .filter_map(move |k| Some(y[k]? - 3.0 * y[k - 1]? + 3.0 * y[k - 2]? - y[k - 3]?))
        })
        .collect();
    z.iter().map(|v| v * v).sum::<f64>() / z.len() as f64
}

#[test]
fn undetected_outliers_barely_move_the_noise_estimate() {
    // 0.3 % of frames spoilt by ±10σ and not excluded. A spoilt frame adds (1+9+9+1)·100σ²
    // to four third differences, against 20σ² (ρ = 0) or 2.7σ² (ρ = 0.8) of noise: the plain
    // mean square grows by ~20 % or more than doubles, while the trimmed mean squares keep σ̂
    // within 10 % (in practice ~2 %).
    for rho in [0.0, 0.8] {
        for seed in 1..=3 {
            let mut rng = Rng(51_000 + seed);
            let mut a = noisy_marker(&mut rng, swinging_marker, FRAMES, rho);
            let mut b = noisy_marker(&mut rng, stuck_marker, FRAMES, rho);
            let clean: Vec<Vec<Option<f64>>> = a.iter().chain(&b).cloned().collect();
            add_outliers(&mut rng, &mut a, 0.003);
            add_outliers(&mut rng, &mut b, 0.003);
            let spoilt: Vec<Vec<Option<f64>>> = a.into_iter().chain(b).collect();
            let inflation = plain_third_difference_mean_square(&spoilt)
                / plain_third_difference_mean_square(&clean);
            println!("ρ {rho} seed {seed}: plain third-difference mean square × {inflation:.2}");
            assert!(inflation > if rho > 0.5 { 2.0 } else { 1.1 });
            let est = estimate_ar1(&refs(&spoilt), &[]).unwrap();
            let reference = estimate_ar1(&refs(&clean), &[]).unwrap();
            assert!((est.sigma / reference.sigma - 1.0).abs() < 0.05);
            assert_close(
                est,
                rho,
                0.10,
                0.05,
                &format!("undetected outliers ρ {rho} seed {seed}"),
            );
        }
    }
}

#[test]
fn found_outliers_excluded_give_the_clean_noise_estimate() {
    // End to end: detect, then estimate without the flagged frames.
    let t = frame_times(FRAMES);
    for seed in 1..=3 {
        let mut rng = Rng(61_000 + seed);
        let mut a = noisy_marker(&mut rng, swinging_marker, FRAMES, 0.8);
        let mut b = noisy_marker(&mut rng, stuck_marker, FRAMES, 0.8);
        add_outliers(&mut rng, &mut a, 0.003);
        add_outliers(&mut rng, &mut b, 0.003);
        let [ax, ay] = a;
        let [bx, by] = b;
        let channels = [ax, ay, bx, by];
        let flags = detect_outliers(&t, &refs(&channels), &OutlierOptions::default());
        let est = estimate_ar1(&refs(&channels), &flags).unwrap();
        assert_close(
            est,
            0.8,
            0.05,
            0.03,
            &format!("detect then estimate seed {seed}"),
        );
    }
}

#[test]
fn whitening_turns_ar1_noise_white() {
    // Three independent AR(1) segments, standardised by σ, whitened with their starts marked.
    let mut rng = Rng(71);
    let rho = 0.8;
    let lengths = [5_000, 3_000, 4_000];
    let mut r = Vec::new();
    let mut starts = Vec::new();
    for n in lengths {
        starts.push(r.len());
        r.extend(ar1_noise(&mut rng, n, SIGMA, rho).iter().map(|e| e / SIGMA));
    }
    let mut segment_start = vec![false; r.len()];
    for &k in &starts {
        segment_start[k] = true;
    }
    let w = whiten(&r, &segment_start, rho);
    let n = w.len() as f64;
    let variance = w.iter().map(|v| v * v).sum::<f64>() / n;
    let lag1 = w.iter().zip(&w[1..]).map(|(a, b)| a * b).sum::<f64>() / n / variance;
    let raw_lag1 = r.iter().zip(&r[1..]).map(|(a, b)| a * b).sum::<f64>()
        / r.iter().map(|v| v * v).sum::<f64>();
    println!("whitened: variance {variance:.4}, lag-1 {lag1:+.4} (raw {raw_lag1:.3})");
    assert!((variance - 1.0).abs() < 0.05);
    assert!(lag1.abs() < 0.03);
    // At a segment start the sample is kept; just after it, the usual formula.
    let g = 1.0 / (1.0 - rho * rho).sqrt();
    for &k in &starts {
        assert_eq!(w[k], r[k]);
        assert!((w[k + 1] - (r[k + 1] - rho * r[k]) * g).abs() < 1e-12);
    }
    // Without the starts, the boundary samples are (wrongly) differenced against the
    // previous segment.
    let unmarked = whiten(&r, &[], rho);
    assert_eq!(unmarked[0], r[0]);
    assert!((unmarked[starts[1]] - (r[starts[1]] - rho * r[starts[1] - 1]) * g).abs() < 1e-12);

    // The Jacobian's columns get the same linear map.
    let cols = 3;
    let mut jac = DMatrix::from_fn(r.len(), cols, |i, j| r[i] * (j + 1) as f64 + i as f64);
    let original = jac.clone();
    whiten_columns(&mut jac, &segment_start, rho);
    for j in 0..cols {
        let expected = whiten(original.column(j).as_slice(), &segment_start, rho);
        assert_eq!(jac.column(j).as_slice(), expected.as_slice());
    }
}

#[test]
fn ljung_box_tells_white_from_ar1() {
    // White noise: Q ≈ χ²(20), mean 20, SD 6.3; AR(1) ρ = 0.8: enormous; whitened: white again.
    let lags = 20;
    for seed in 1..=5 {
        let mut rng = Rng(81_000 + seed);
        let white: Vec<f64> = (0..FRAMES).map(|_| rng.normal()).collect();
        let (q, used) = ljung_box(&white, lags);
        assert_eq!(used, lags);
        let ar = ar1_noise(&mut rng, FRAMES, 1.0, 0.8);
        let (q_ar, _) = ljung_box(&ar, lags);
        let (q_w, _) = ljung_box(&whiten(&ar, &[], 0.8), lags);
        println!("seed {seed}: Q white {q:.1}, AR(1) {q_ar:.0}, whitened AR(1) {q_w:.1}");
        // χ²(20): 0.1 % and 99.9 % quantiles are 5.9 and 45.3.
        assert!((5.9..45.3).contains(&q) && (5.9..45.3).contains(&q_w));
        assert!(q_ar > 10_000.0);
    }
    // Fewer samples than lags: the lags are cut to n − 1.
    assert_eq!(ljung_box(&[1.0, 2.0, 0.5, 3.0], 20).1, 3);
}

#[test]
fn degenerate_inputs_do_not_panic() {
    let options = OutlierOptions::default();
    // Empty.
    assert!(detect_outliers(&[], &[], &options).is_empty());
    assert!(detect_outliers(&[], &[&[]], &options).is_empty());
    assert!(estimate_ar1(&[], &[]).is_none());
    assert!(estimate_ar1(&[&[]], &[]).is_none());
    assert!(whiten(&[], &[], 0.5).is_empty());
    let mut empty = DMatrix::<f64>::zeros(0, 3);
    whiten_columns(&mut empty, &[], 0.5);
    assert_eq!(ljung_box(&[], 10), (0.0, 0));
    assert_eq!(ljung_box(&[1.0], 10), (0.0, 0));

    // All lost.
    let t = frame_times(500);
    let lost = vec![None; 500];
    assert!(
        detect_outliers(&t, &[&lost, &lost], &options)
            .iter()
            .all(|f| !f)
    );
    assert!(estimate_ar1(&[&lost], &[]).is_none());

    // Fewer frames than the window: nothing to fit, nothing flagged.
    let few: Vec<Option<f64>> = vec![Some(1.0), Some(5.0), Some(1.0)];
    assert_eq!(detect_outliers(&t[..3], &[&few], &options), vec![false; 3]);
    assert!(estimate_ar1(&[&few], &[]).is_none());

    // Constant series: no flags, zero noise is not an estimate; constant residuals: Q = 0.
    let constant = vec![Some(0.25); 500];
    assert!(
        detect_outliers(&t, &[&constant], &options)
            .iter()
            .all(|f| !f)
    );
    assert!(estimate_ar1(&[&constant], &[]).is_none());
    assert_eq!(ljung_box(&[2.0; 50], 10), (0.0, 0));
    // …but one gross error on a constant series is found.
    let mut bumped = constant.clone();
    bumped[250] = Some(0.2501);
    let flags = detect_outliers(&t, &[&bumped], &options);
    assert!(flags[250] && flags.iter().filter(|&&f| f).count() == 1);

    // Channels of other lengths than t, NaN samples, degree above the window, no passes.
    let mut rng = Rng(91);
    let short: Vec<Option<f64>> = (0..200).map(|_| Some(rng.normal())).collect();
    let mut nan = short.clone();
    nan[10] = Some(f64::NAN);
    assert_eq!(detect_outliers(&t, &[&short, &nan], &options).len(), 500);
    assert!(!detect_outliers(&t, &[&nan], &options)[10]);
    let high = OutlierOptions {
        degree: 20,
        ..options
    };
    assert!(detect_outliers(&t, &[&short], &high).iter().all(|f| !f));
    let none = OutlierOptions {
        max_passes: 0,
        ..options
    };
    assert!(detect_outliers(&t, &[&bumped], &none).iter().all(|f| !f));
    // Repeated frame times: no polynomial, no flag.
    let same_time = vec![0.0; 500];
    assert!(
        detect_outliers(&same_time, &[&bumped], &options)
            .iter()
            .all(|f| !f)
    );
}

/// The spread of the AR(1) estimate over 30 seeds (the figures quoted in
/// `estimate_ar1`'s documentation). `cargo test --release -- --ignored --nocapture`.
#[test]
#[ignore = "prints the spread over 30 seeds (figures for the docs); run with --ignored --nocapture"]
fn spread_of_the_ar1_estimate_over_30_seeds() {
    let mean_sd_max = |v: &[f64]| {
        let m = v.iter().sum::<f64>() / v.len() as f64;
        let sd = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
        (m, sd, v.iter().fold(0.0_f64, |a, x| a.max(x.abs())))
    };
    for rho in [0.0, 0.5, 0.8, 0.9, 0.95] {
        for (name, motion) in [
            ("stuck", stuck_marker as fn(f64) -> [f64; 2]),
            ("swinging", swinging_marker),
        ] {
            let (mut es, mut er) = (Vec::new(), Vec::new());
            for seed in 0..30 {
                let mut rng = Rng(99_000 + seed);
                let [x1, y1] = noisy_marker(&mut rng, motion, FRAMES, rho);
                let [x2, y2] = noisy_marker(&mut rng, motion, FRAMES, rho);
                let est = estimate_ar1(&refs(&[x1, y1, x2, y2]), &[]).unwrap();
                es.push(est.sigma / SIGMA - 1.0);
                er.push(est.rho - rho);
            }
            let (s, r) = (mean_sd_max(&es), mean_sd_max(&er));
            println!(
                "ρ {rho} {name}: σ̂ error mean {:+.2} % sd {:.2} % max {:.2} %; \
                 ρ̂ error mean {:+.4} sd {:.4} max {:.4}",
                100.0 * s.0,
                100.0 * s.1,
                100.0 * s.2,
                r.0,
                r.1,
                r.2
            );
        }
    }
    // The lag-1/lag-0 ratio of the stride-1 third difference alone: spread of ρ̂ at ρ = 0.8.
    let c = [1.0, -3.0, 3.0, -1.0];
    let ratio =
        |rho| ar1_difference_autocovariance(&c, 1, rho) / ar1_difference_autocovariance(&c, 0, rho);
    let slope = (ratio(0.81) - ratio(0.79)) / 0.02;
    let ratios: Vec<f64> = (0..30)
        .map(|seed| {
            let mut rng = Rng(5_000 + seed);
            let (mut s0, mut s1) = (0.0, 0.0);
            for _ in 0..4 {
                let e = ar1_noise(&mut rng, FRAMES, 1.0, 0.8);
                let z: Vec<f64> = (3..e.len())
                    .map(|k| e[k] - 3.0 * e[k - 1] + 3.0 * e[k - 2] - e[k - 3])
                    .collect();
                s0 += z.iter().map(|v| v * v).sum::<f64>();
                s1 += z.iter().zip(&z[1..]).map(|(a, b)| a * b).sum::<f64>();
            }
            s1 / s0
        })
        .collect();
    let (_, sd, _) = mean_sd_max(&ratios);
    println!(
        "lag ratio alone at ρ 0.8: ratio sd {sd:.4}, slope {slope:.4}, ρ̂ sd {:.3}",
        sd / slope
    );
}

#[test]
fn a_two_frame_tracking_error_is_found_in_two_passes() {
    // Two adjacent frames off by +10σ spoil each other's prediction; the passes peel them.
    let t = frame_times(3_000);
    let mut rng = Rng(111);
    let mut found = 0;
    for trial in 0..20 {
        let [mut x, y] = noisy_marker(&mut rng, swinging_marker, 3_000, 0.8);
        let k = 200 + 130 * trial;
        for j in [k, k + 1] {
            x[j] = x[j].map(|v| v + 10.0 * SIGMA);
        }
        let flags = detect_outliers(&t, &[&x, &y], &OutlierOptions::default());
        let n_flags = flags.iter().filter(|&&f| f).count();
        if flags[k] && flags[k + 1] && n_flags == 2 {
            found += 1;
        }
    }
    println!("two-frame errors found {found}/20");
    assert!(found >= 18);
}

/// A marker bouncing on a felt: 2 cm |sin| at 4 Hz, velocity reversing from −0.5 to 0.5 m/s
/// eight times a second, jerk up to ~3000 m/s³ between the reversals.
fn bouncing_marker(t: f64) -> [f64; 2] {
    let h = 0.02 * (2.0 * std::f64::consts::PI * 4.0 * t).sin().abs();
    [0.05, 0.1 + h]
}

#[test]
fn a_bouncing_marker_still_gives_the_noise_for_moderate_correlation() {
    // Rough motion: the differences straddling a reversal are clipped, the long strides that
    // the smooth part spoils are dropped by the misfit guard. (For ρ = 0.95 on this motion
    // σ̂ is off by 25–60 %: documented, not tested.)
    for rho in [0.0, 0.8] {
        for seed in 1..=5 {
            let mut rng = Rng(121_000 + seed);
            let [x1, y1] = noisy_marker(&mut rng, bouncing_marker, FRAMES, rho);
            let [x2, y2] = noisy_marker(&mut rng, bouncing_marker, FRAMES, rho);
            let est = estimate_ar1(&refs(&[x1, y1, x2, y2]), &[]).unwrap();
            assert_close(
                est,
                rho,
                0.07,
                0.03,
                &format!("bouncing ρ {rho} seed {seed}"),
            );
        }
    }
}
