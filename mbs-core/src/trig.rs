//! Sines and cosines of several angles at once, as straight-line code over fixed-size arrays
//! that the compiler turns into SIMD: the joint transforms need one `sin_cos` per revolute
//! joint, and the library's `f64::sin_cos` is called one angle at a time.
//!
//! The method is the textbook one (Cody & Waite, *Software Manual for the Elementary
//! Functions*, 1980; Muller, *Elementary Functions*, ch. 11):
//!
//! 1. reduce `x = k π/2 + r` with `|r| ≤ π/4`, subtracting `k π/2` in four parts
//!    ([`PI_2_HI`], [`PI_2_MID`], [`PI_2_LO`], [`PI_2_TAIL`]); the first two subtractions
//!    are exact, and the rounding error of the third is kept (Fast2Sum), so that `r` is
//!    known as a pair `r + r_lo` to about 2⁻¹²⁰ absolute;
//! 2. evaluate the Taylor series of `sin r` and `cos r` on `[−π/4, π/4]`;
//! 3. pick `±sin r` or `±cos r` by the quadrant `k mod 4`.
//!
//! Angles with `|x| > REDUCTION_LIMIT` (or not finite) take `f64::sin_cos`, so
//! NaN and infinity behave exactly as before. Within the limit the result is within 2 ulp of
//! `f64::sin_cos`: the tests (4 million points over `[−1e5, 1e5]`, and the doubles next to
//! every `k π/2` there) see at most 1 ulp.

/// Largest `|x|` reduced here: `k = round(x · 2/π) < 2¹⁶`, so `k` times the 37-bit constants
/// below is exact.
const REDUCTION_LIMIT: f64 = 1e5;

/// `π/2` rounded down to a multiple of 2⁻³⁶ (37 significant bits, `0x1.921fb5444p0`).
const PI_2_HI: f64 = f64::from_bits(0x3FF9_21FB_5444_0000);
/// The next bits of `π/2`, down to 2⁻⁵³ (`0x1.68cp-39`, 13 significant bits).
const PI_2_MID: f64 = f64::from_bits(0x3D86_8C00_0000_0000);
/// The next 37 bits of `π/2`, down to 2⁻⁹⁰ (`0x1.1a6263314p-54`).
const PI_2_LO: f64 = f64::from_bits(0x3C91_A626_3314_0000);
/// The rest of `π/2`, rounded to a double (`0x1.701b839a25205p-92`); `π/2` minus the four
/// parts is about `1.8e-44`.
const PI_2_TAIL: f64 = f64::from_bits(0x3A37_01B8_39A2_5205);
/// `1.5 · 2⁵²`: adding and subtracting it rounds a double of magnitude below 2⁵¹ to the
/// nearest integer, and leaves that integer in the low bits of the sum's mantissa.
const ROUNDER: f64 = 6_755_399_441_055_744.0;

/// Taylor coefficients `(−1)ⁿ / (2n+1)!` of `sin r = r + r³ (S1 + r² S2 + …)`, n = 1..8.
/// Truncated after `r¹⁷`, the series errs by at most `(π/4)¹⁹/19! ≈ 8e-20` relative on
/// `[−π/4, π/4]`, far below the 1.1e-16 of a rounding.
const SIN_TAYLOR: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];

/// Taylor coefficients `(−1)ⁿ / (2n)!` of `cos r = 1 − r²/2 + r⁴ (C2 + r² C3 + …)`,
/// n = 2..8. Truncated after `r¹⁶`, the series errs by at most `(π/4)¹⁸/18! ≈ 2e-18`.
const COS_TAYLOR: [f64; 7] = [
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
];

/// `(sin x, cos x)` for every lane of `x`, each within 2 ulp of `f64::sin_cos`. A lane with
/// `|x| > 1e5`, or not finite, takes `f64::sin_cos`; the others are unaffected, so a lane's
/// result never depends on the other lanes (the function is crate-private, so this is not run
/// as a doctest; the unit tests below check it):
///
/// ```text
/// let (s, c) = sin_cos_lanes(&[0.0, 1.0, -2.0, 1e300]);
/// assert_eq!(s[3], 1e300_f64.sin());
/// assert_eq!(s[1], sin_cos_lanes(&[1.0]).0[0]);
/// ```
#[inline(always)]
pub(crate) fn sin_cos_lanes<const N: usize>(x: &[f64; N]) -> ([f64; N], [f64; N]) {
    let mut s = [0.0; N];
    let mut c = [0.0; N];
    for i in 0..N {
        (s[i], c[i]) = sin_cos_reduced(x[i]);
    }
    // Lanes out of range (NaN compares false) take the library's values, one by one: each
    // lane's result depends on its own angle only, whatever the others hold.
    let in_range = |xi: f64| xi.abs() <= REDUCTION_LIMIT;
    if !x.iter().fold(true, |all, &xi| all & in_range(xi)) {
        for i in 0..N {
            if !in_range(x[i]) {
                (s[i], c[i]) = x[i].sin_cos();
            }
        }
    }
    (s, c)
}

/// `(sin x, cos x)` for `|x| ≤ REDUCTION_LIMIT`: no branches (selections are bit masks), so
/// that the loop over lanes in [`sin_cos_lanes`] vectorizes. For other `x` (NaN included)
/// the result is meaningless but harmless (no panic), and [`sin_cos_lanes`] replaces it.
#[inline(always)]
fn sin_cos_reduced(x: f64) -> (f64, f64) {
    // k = round(x · 2/π), and k mod 4 from the low mantissa bits of the rounded sum.
    let shifted = x * std::f64::consts::FRAC_2_PI + ROUNDER;
    let quadrant = shifted.to_bits();
    let k = shifted - ROUNDER;
    // r = x − k π/2. The products of k (|k| < 2¹⁶) with the first three parts are exact,
    // and so are the first two subtractions: for k ≠ 0, |x| > π/4, so x, k·PI_2_HI and
    // k·PI_2_MID are all multiples of 2⁻⁵³ and the difference (below 1) fits in 53 bits.
    // The third subtraction rounds; its error and the tail go to `r_lo` (Fast2Sum), off the
    // critical path.
    let d = (x - k * PI_2_HI) - k * PI_2_MID;
    let p = k * PI_2_LO;
    let r = d - p;
    let r_lo = ((d - r) - p) - k * PI_2_TAIL;

    // Polynomials in r² by Estrin's scheme (short dependency chains).
    let r2 = r * r;
    let r4 = r2 * r2;
    let r8 = r4 * r4;
    let [s1, s2, s3, s4, s5, s6, s7, s8] = SIN_TAYLOR;
    let sin_poly =
        ((s1 + r2 * s2) + r4 * (s3 + r2 * s4)) + r8 * ((s5 + r2 * s6) + r4 * (s7 + r2 * s8));
    let [c2, c3, c4, c5, c6, c7, c8] = COS_TAYLOR;
    let cos_poly = ((c2 + r2 * c3) + r4 * (c4 + r2 * c5)) + r8 * ((c6 + r2 * c7) + r4 * c8);
    // sin(r + r_lo) ≈ sin r + r_lo (1 − r²/2); cos(r + r_lo) ≈ cos r − r_lo r.
    let half_r2 = 0.5 * r2;
    let sin_r = (r + ((r * r2) * sin_poly + r_lo * (1.0 - half_r2))).to_bits();
    let cos_r = ((1.0 - half_r2) + (r4 * cos_poly - r_lo * r)).to_bits();

    // Quadrant k mod 4: (sin, cos) = (s, c), (c, −s), (−s, −c), (−c, s): swap for odd k,
    // then flip signs.
    let swap = (quadrant & 1).wrapping_neg();
    let sin_abs = (sin_r & !swap) | (cos_r & swap);
    let cos_abs = (cos_r & !swap) | (sin_r & swap);
    let sin_x = sin_abs ^ ((quadrant & 2) << 62);
    let cos_x = cos_abs ^ ((quadrant.wrapping_add(1) & 2) << 62);
    // sin(±0) = ±0 (the sums above give +0 for −0): keep x where it is zero.
    let zero = ((x == 0.0) as u64).wrapping_neg();
    let sin_x = (sin_x & !zero) | (x.to_bits() & zero);
    (f64::from_bits(sin_x), f64::from_bits(cos_x))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place between two finite doubles of the same sign, or
    /// across zero (counted through it).
    fn ulps(a: f64, b: f64) -> u64 {
        let key = |v: f64| {
            let bits = v.to_bits() as i64;
            if bits < 0 { i64::MIN - bits } else { bits }
        };
        key(a).abs_diff(key(b))
    }

    /// The largest ulp errors of `sin_cos_lanes` over `xs` against `f64::sin_cos`.
    fn max_ulps(xs: &[f64]) -> (u64, u64, f64, f64) {
        let (mut worst_s, mut worst_c, mut at_s, mut at_c) = (0, 0, 0.0, 0.0);
        for chunk in xs.chunks(4) {
            let mut lanes = [0.0; 4];
            lanes[..chunk.len()].copy_from_slice(chunk);
            let (s, c) = sin_cos_lanes(&lanes);
            for (i, &x) in chunk.iter().enumerate() {
                let (s_ref, c_ref) = x.sin_cos();
                let (es, ec) = (ulps(s[i], s_ref), ulps(c[i], c_ref));
                if es > worst_s {
                    (worst_s, at_s) = (es, x);
                }
                if ec > worst_c {
                    (worst_c, at_c) = (ec, x);
                }
            }
        }
        (worst_s, worst_c, at_s, at_c)
    }

    #[test]
    fn dense_sweep_within_two_ulp() {
        // 4 million points over [−1e5, 1e5], denser near zero, with an irrational step so that
        // they fall everywhere relative to the multiples of π/2.
        let mut xs = Vec::new();
        for i in 0..2_000_000 {
            let u = i as f64 * 0.618_033_988_749_894_8 % 1.0;
            xs.push(8.0 * (2.0 * u - 1.0));
            xs.push(1e5 * (2.0 * u - 1.0));
        }
        let (es, ec, at_s, at_c) = max_ulps(&xs);
        eprintln!("sweep: sin {es} ulp at {at_s:e}, cos {ec} ulp at {at_c:e}");
        assert!(
            es <= 2 && ec <= 2,
            "sin {es} ulp at {at_s}, cos {ec} ulp at {at_c}"
        );
    }

    #[test]
    fn near_multiples_of_half_pi() {
        // The doubles nearest to k π/2 and their neighbours, where r cancels most.
        let mut xs = Vec::new();
        for k in -63_600_i64..=63_600 {
            let x = k as f64 * std::f64::consts::FRAC_PI_2;
            let mut v = x;
            for _ in 0..3 {
                xs.push(v);
                v = v.next_up();
            }
            v = x;
            for _ in 0..3 {
                v = v.next_down();
                xs.push(v);
            }
        }
        let (es, ec, at_s, at_c) = max_ulps(&xs);
        eprintln!("k π/2: sin {es} ulp at {at_s:e}, cos {ec} ulp at {at_c:e}");
        assert!(
            es <= 2 && ec <= 2,
            "sin {es} ulp at {at_s}, cos {ec} ulp at {at_c}"
        );
    }

    #[test]
    fn edge_cases() {
        let edges = [
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            f64::MIN_POSITIVE,
            5e-324,
            1e-8,
            std::f64::consts::FRAC_PI_4,
            std::f64::consts::FRAC_PI_2,
            std::f64::consts::PI,
            -std::f64::consts::PI,
            1e5,
            -1e5,
            1e5_f64.next_up(),
            1e6,
            1e300,
            -1e300,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for &x in &edges {
            let (s, c) = sin_cos_lanes(&[x, 0.5, -0.5, 1.0]);
            let (s_ref, c_ref) = x.sin_cos();
            if x.is_nan() || x.is_infinite() {
                assert!(s[0].is_nan() && c[0].is_nan(), "{x}");
            } else {
                assert!(ulps(s[0], s_ref) <= 2 && ulps(c[0], c_ref) <= 2, "{x}");
                assert_eq!(s[0].is_sign_negative(), s_ref.is_sign_negative(), "{x}");
            }
            if x.abs() > REDUCTION_LIMIT || !x.is_finite() {
                assert_eq!(
                    (s[0].to_bits(), c[0].to_bits()),
                    (s_ref.to_bits(), c_ref.to_bits())
                );
            }
        }
        // A lane's result does not depend on its neighbours, in range or not.
        let alone: Vec<(u64, u64)> = [0.7, -2.5, 1e6, f64::NAN]
            .iter()
            .map(|&x| {
                let (s, c) = sin_cos_lanes(&[x]);
                (s[0].to_bits(), c[0].to_bits())
            })
            .collect();
        let (s, c) = sin_cos_lanes(&[0.7, -2.5, 1e6, f64::NAN]);
        for i in 0..3 {
            assert_eq!((s[i].to_bits(), c[i].to_bits()), alone[i], "lane {i}");
        }
        assert!(s[3].is_nan() && c[3].is_nan() && f64::from_bits(alone[3].0).is_nan());
        // Exact zeros and ones where the library gives them.
        assert_eq!(sin_cos_lanes(&[0.0]), ([0.0], [1.0]));
        assert!(sin_cos_lanes(&[-0.0]).0[0].is_sign_negative());
    }
}
