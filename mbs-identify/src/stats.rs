//! The few distribution functions the diagnosis's tests need: the χ² survival function
//! (for the whiteness test and a phase's gap against the noise) through the regularized
//! incomplete gamma function.
//!
//! ```
//! use mbs_identify::stats::chi2_sf;
//! // The 95 % point of χ² with one degree of freedom is 3.841.
//! assert!((chi2_sf(3.841_458_820_694_124, 1.0) - 0.05).abs() < 1e-9);
//! // With two degrees of freedom the tail is exactly e^(−x/2).
//! assert!((chi2_sf(6.0, 2.0) - (-3.0f64).exp()).abs() < 1e-12);
//! ```

/// ln Γ(z) for z > 0: the recurrence Γ(z) = Γ(z + n)/(z (z+1) … (z+n−1)) up to z ≥ 10, then
/// Stirling's series to the z⁻⁹ term (Abramowitz & Stegun 6.1.41 [M]), good to about
/// 1e-14 there. NaN for z ≤ 0 or not a number.
pub fn ln_gamma(z: f64) -> f64 {
    if z.is_nan() || z <= 0.0 {
        return f64::NAN;
    }
    if z.is_infinite() {
        return f64::INFINITY;
    }
    let (mut z, mut shift) = (z, 0.0);
    while z < 10.0 {
        shift += z.ln();
        z += 1.0;
    }
    let inv = 1.0 / z;
    let inv2 = inv * inv;
    // ln Γ(z) ≈ (z − ½) ln z − z + ½ ln 2π + 1/(12z) − 1/(360z³) + 1/(1260z⁵) − 1/(1680z⁷)
    //           + 1/(1188z⁹)
    let series = inv
        * (1.0 / 12.0
            + inv2
                * (-1.0 / 360.0 + inv2 * (1.0 / 1260.0 + inv2 * (-1.0 / 1680.0 + inv2 / 1188.0))));
    (z - 0.5) * z.ln() - z + 0.5 * (2.0 * std::f64::consts::PI).ln() + series - shift
}

/// The regularized upper incomplete gamma function Q(a, x) = Γ(a, x)/Γ(a), a > 0, x ≥ 0:
/// by its power series for P = 1 − Q below x = a + 1, by its continued fraction (modified
/// Lentz) above (both A&S 6.5.29 and 6.5.31 [M]). NaN outside its domain.
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if a.is_nan() || x.is_nan() || a <= 0.0 || x < 0.0 {
        return f64::NAN;
    }
    if x == 0.0 {
        return 1.0;
    }
    if x.is_infinite() {
        return 0.0;
    }
    let prefactor = (a * x.ln() - x - ln_gamma(a)).exp();
    if x < a + 1.0 {
        // P(a, x) = x^a e^−x / Γ(a) Σ_n x^n / (a (a+1) … (a+n))
        let (mut term, mut sum, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..10_000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * f64::EPSILON {
                break;
            }
        }
        (1.0 - prefactor * sum).clamp(0.0, 1.0)
    } else {
        // Q(a, x) = x^a e^−x / Γ(a) · 1/(x + 1 − a − 1·(1−a)/(x + 3 − a − 2·(2−a)/(x + 5 − a − …)))
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..10_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let step = d * c;
            h *= step;
            if (step - 1.0).abs() < f64::EPSILON {
                break;
            }
        }
        (prefactor * h).clamp(0.0, 1.0)
    }
}

/// P(χ²_k > x): the probability that a χ² variable of `k` degrees of freedom exceeds `x`
/// (1 for x ≤ 0; NaN for k ≤ 0).
pub fn chi2_sf(x: f64, k: f64) -> f64 {
    if k.is_nan() || k <= 0.0 || x.is_nan() {
        return f64::NAN;
    }
    if x <= 0.0 {
        return 1.0;
    }
    gamma_q(0.5 * k, 0.5 * x)
}

/// The value a χ² variable of `k` degrees of freedom exceeds with probability `p`, the
/// inverse of [`chi2_sf`] (bisection, to a millionth of `k`); NaN unless 0 < p < 1 and
/// k > 0.
pub fn chi2_isf(p: f64, k: f64) -> f64 {
    if !(p > 0.0 && p < 1.0 && k > 0.0) {
        return f64::NAN;
    }
    let (mut lo, mut hi) = (0.0, k.max(1.0));
    while chi2_sf(hi, k) > p {
        lo = hi;
        hi *= 2.0;
    }
    while hi - lo > 1e-6 * k.max(1.0) {
        let mid = 0.5 * (lo + hi);
        if chi2_sf(mid, k) > p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// The standard deviation of component `i` of a Gaussian estimate with covariance `cov`
/// when the components `given` are held at their values: √(Σᵢᵢ − Σᵢₛ Σₛₛ⁻¹ Σₛᵢ) (the
/// Schur complement). How well a strength is known at a fitted place, where the place
/// and the strength trade along a ridge. `None` when an index is out of range, `i` is
/// among `given`, `Σₛₛ` is not positive definite or the result not a finite, non-negative
/// number.
pub fn conditional_sd(cov: &nalgebra::DMatrix<f64>, i: usize, given: &[usize]) -> Option<f64> {
    let n = cov.nrows();
    if cov.ncols() != n || i >= n || given.iter().any(|&g| g >= n || g == i) {
        return None;
    }
    let mut var = cov[(i, i)];
    if !given.is_empty() {
        let m = given.len();
        let ss = nalgebra::DMatrix::from_fn(m, m, |p, q| cov[(given[p], given[q])]);
        let si = nalgebra::DVector::from_fn(m, |p, _| cov[(given[p], i)]);
        let solved = ss.cholesky()?.solve(&si);
        var -= si.dot(&solved);
    }
    (var.is_finite() && var >= 0.0).then(|| var.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two components of correlation ρ: the first's SD given the second is σ √(1 − ρ²);
    /// given nothing, σ; a component given itself, or a singular block, is refused.
    #[test]
    fn a_component_held_leaves_the_schur_complement() {
        use nalgebra::DMatrix;
        let (s1, s2, rho) = (2.0, 0.5, 0.9);
        let cov = DMatrix::from_row_slice(
            3,
            3,
            &[
                s1 * s1,
                rho * s1 * s2,
                0.0,
                rho * s1 * s2,
                s2 * s2,
                0.0,
                0.0,
                0.0,
                1.0,
            ],
        );
        let given = conditional_sd(&cov, 0, &[1]).expect("defined");
        assert!((given - s1 * (1.0 - rho * rho).sqrt()).abs() < 1e-12);
        // An uncorrelated component held changes nothing.
        let alone = conditional_sd(&cov, 0, &[2]).expect("defined");
        assert!((alone - s1).abs() < 1e-12);
        assert!((conditional_sd(&cov, 0, &[]).expect("defined") - s1).abs() < 1e-12);
        assert_eq!(conditional_sd(&cov, 0, &[0]), None);
        assert_eq!(conditional_sd(&cov, 3, &[]), None);
        let singular = DMatrix::from_row_slice(2, 2, &[1.0, 0.0, 0.0, 0.0]);
        assert_eq!(conditional_sd(&singular, 0, &[1]), None);
    }

    #[test]
    fn ln_gamma_matches_factorials_and_half_integers() {
        let mut fact = 1.0f64;
        for n in 1..30 {
            // Γ(n) = (n − 1)!
            assert!((ln_gamma(n as f64) - fact.ln()).abs() < 1e-12, "n = {n}");
            fact *= n as f64;
        }
        // Γ(½) = √π
        let half = 0.5 * std::f64::consts::PI.ln();
        assert!((ln_gamma(0.5) - half).abs() < 1e-13);
        assert!(ln_gamma(0.0).is_nan() && ln_gamma(-1.0).is_nan());
    }

    /// The inverse against the tables [M]: 30.144 for 19 degrees of freedom at 5 %,
    /// 13.816 for 2 and 149.449 for 100 at one in a thousand; NaN outside (0, 1).
    #[test]
    fn chi2_upper_points_match_the_tables() {
        for (p, k, q) in [
            (0.05, 19.0, 30.144),
            (1e-3, 2.0, 13.816),
            (1e-3, 100.0, 149.449),
        ] {
            let x = chi2_isf(p, k);
            assert!((x - q).abs() < 2e-3, "χ²({k}) at {p}: {x}, tables {q}");
        }
        assert!(chi2_isf(0.0, 3.0).is_nan() && chi2_isf(0.5, 0.0).is_nan());
    }

    #[test]
    fn chi2_tails_match_published_quantiles() {
        // (x, k, tail) from the standard χ² tables [M]: the 95 % and 99.9 % points.
        let table = [
            (3.841_458_820_694_124, 1.0, 0.05),
            (10.827_566_170_662_733, 1.0, 0.001),
            (31.410_432_844_230_918, 20.0, 0.05),
            (45.314_746_618_125_67, 20.0, 0.001),
            (124.342_113_404_070_9, 100.0, 0.05),
        ];
        for (x, k, tail) in table {
            let p = chi2_sf(x, k);
            assert!(
                (p - tail).abs() < 1e-9 * tail.max(1e-3) * 1e3,
                "{x} {k}: {p}"
            );
        }
        // Both branches agree at the switch, and the tail falls with x.
        for k in [1.0, 3.0, 7.5, 40.0] {
            let a = 0.5 * k;
            let below = gamma_q(a, a + 1.0 - 1e-9);
            let above = gamma_q(a, a + 1.0 + 1e-9);
            assert!((below - above).abs() < 1e-8, "k = {k}");
            assert!(chi2_sf(k, k) > chi2_sf(2.0 * k, k));
        }
        assert_eq!(chi2_sf(0.0, 3.0), 1.0);
        assert_eq!(chi2_sf(f64::INFINITY, 3.0), 0.0);
        assert!(chi2_sf(1.0, 0.0).is_nan());
    }
}
