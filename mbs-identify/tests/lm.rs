//! The bounded Levenberg–Marquardt solver: recovery and honest uncertainty on a noisy
//! exponential, a hard valley (Rosenbrock), bounds, log scale, failing residual
//! functions, and independence from the thread count.

use std::sync::atomic::{AtomicUsize, Ordering};

use mbs_identify::lm::{FitError, FreeParam, LmFit, LmOptions, Stop, levenberg_marquardt};

/// xorshift64* with Gaussian draws by Box–Muller: noise that a seed fixes.
struct Noise(u64);

impl Noise {
    fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let bits = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11;
        (bits as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn gaussian(&mut self) -> f64 {
        let (u1, u2) = (self.uniform(), self.uniform());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

const A_TRUE: f64 = 2.0;
const B_TRUE: f64 = 0.7;
const SIGMA: f64 = 0.05;

/// y = a e^{−b t} + σ ε at t = 0, 0.05, …, 9.95.
fn decay_data(seed: u64) -> Vec<(f64, f64)> {
    let mut noise = Noise::new(seed);
    (0..200)
        .map(|j| {
            let t = 0.05 * j as f64;
            (t, A_TRUE * (-B_TRUE * t).exp() + SIGMA * noise.gaussian())
        })
        .collect()
}

/// a linear, b on a log scale, both started well off.
fn decay_params() -> Vec<FreeParam> {
    vec![
        FreeParam::linear("a", 1.0, 0.0, 10.0, 1.0),
        FreeParam::log("b", 0.2, 1e-3, 100.0),
    ]
}

fn fit_decay(data: &[(f64, f64)], options: &LmOptions) -> LmFit {
    let model = |x: &[f64]| {
        Ok(data
            .iter()
            .map(|&(t, y)| (x[0] * (-x[1] * t).exp() - y) / SIGMA)
            .collect())
    };
    levenberg_marquardt(&decay_params(), model, options).unwrap()
}

#[test]
fn a_noisy_exponential_is_recovered_with_an_honest_standard_deviation() {
    let truth = [A_TRUE, B_TRUE];
    let seeds = 50;
    let mut estimates = vec![Vec::new(); 2];
    let mut reported_sd = [0.0; 2];
    let mut covered = [0; 2];
    let mut most_evaluations = 0;
    for seed in 0..seeds {
        let fit = fit_decay(&decay_data(seed), &LmOptions::default());
        assert!(fit.converged, "seed {seed}: {:?}", fit.stop);
        most_evaluations = most_evaluations.max(fit.evaluations);
        // Standardised residuals: s² ≈ 1 and the rss near N − k = 198.
        assert!((fit.rss - 198.0).abs() < 5.0 * (2.0 * 198.0_f64).sqrt());
        for i in 0..2 {
            let (v, sd) = (fit.values[i], fit.sd[i]);
            assert!((v - truth[i]).abs() < 4.0 * sd, "seed {seed}: {v} ± {sd}");
            estimates[i].push(v);
            reported_sd[i] += sd / seeds as f64;
            let [lo, hi] = fit.ci95[i];
            assert!(lo < v && v < hi);
            covered[i] += usize::from(lo <= truth[i] && truth[i] <= hi);
        }
        // b is on a log scale: its interval is positive and longer above than below.
        let [lo, hi] = fit.ci95[1];
        assert!(lo > 0.0 && hi - fit.values[1] > fit.values[1] - lo);
        assert!(!fit.at_bound[0] && !fit.at_bound[1]);
    }
    for i in 0..2 {
        let mean = estimates[i].iter().sum::<f64>() / seeds as f64;
        let var = estimates[i].iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (seeds - 1) as f64;
        let ratio = reported_sd[i] / var.sqrt();
        eprintln!(
            "param {i}: reported sd {:.3e}, sd over seeds {:.3e}, ratio {ratio:.3}, CI95 coverage {}/{seeds}",
            reported_sd[i],
            var.sqrt(),
            covered[i]
        );
        assert!((0.7..1.3).contains(&ratio), "param {i}: ratio {ratio}");
        let coverage = covered[i] as f64 / seeds as f64;
        assert!((0.85..=1.0).contains(&coverage), "param {i}: {coverage}");
    }
    // Frugal: a 2-parameter fit from a poor start in a handful of Jacobians.
    eprintln!("most evaluations over the seeds: {most_evaluations}");
    assert!(most_evaluations <= 40, "{most_evaluations}");
}

#[test]
fn central_differences_give_the_same_optimum_as_forward() {
    let data = decay_data(7);
    let forward = fit_decay(&data, &LmOptions::default());
    let central = fit_decay(
        &data,
        &LmOptions {
            central: true,
            ..LmOptions::default()
        },
    );
    assert!(central.converged);
    for i in 0..2 {
        assert!((forward.values[i] - central.values[i]).abs() < 1e-3 * forward.sd[i]);
        assert!((forward.sd[i] / central.sd[i] - 1.0).abs() < 1e-3);
    }
}

#[test]
fn rosenbrock_converges_to_its_minimum() {
    let params = [
        FreeParam::linear("x", -1.2, -5.0, 5.0, 1.0),
        FreeParam::linear("y", 1.0, -5.0, 5.0, 1.0),
    ];
    let rosenbrock = |p: &[f64]| Ok(vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]]);
    let fit = levenberg_marquardt(&params, rosenbrock, &LmOptions::default()).unwrap();
    eprintln!(
        "rosenbrock: {:?} after {} iterations, {} evaluations, {:?}",
        fit.values, fit.iterations, fit.evaluations, fit.stop
    );
    assert!(fit.converged);
    assert!((fit.values[0] - 1.0).abs() < 1e-6 && (fit.values[1] - 1.0).abs() < 1e-6);
    assert!(fit.rss < 1e-12);
    // Zero residual at the optimum: s² = 0/0 is not defined (N = k).
    assert!(fit.covariance.is_none() && fit.sd.iter().all(|v| v.is_nan()));
    // The step tolerance sets the accuracy.
    let tight = LmOptions {
        step_tolerance: 1e-10,
        ..LmOptions::default()
    };
    let fit = levenberg_marquardt(&params, rosenbrock, &tight).unwrap();
    assert!(fit.converged);
    assert!((fit.values[0] - 1.0).abs() < 1e-9 && (fit.values[1] - 1.0).abs() < 1e-9);
}

#[test]
fn a_parameter_whose_truth_is_below_its_bound_sits_on_it() {
    // y = 1 − 0.5 t, fitted with y = a + c t and c ≥ 0: c ends at 0, and a at the mean
    // of y, which is the best a can do with c = 0. Forward differences, and central ones
    // (one-sided 3-point at the bound).
    let ts: Vec<f64> = (0..50).map(|j| 0.1 * j as f64).collect();
    let ys: Vec<f64> = ts.iter().map(|t| 1.0 - 0.5 * t).collect();
    let mean = ys.iter().sum::<f64>() / ys.len() as f64;
    for central in [false, true] {
        let options = LmOptions {
            central,
            ..LmOptions::default()
        };
        let params = [
            FreeParam::linear("a", 0.0, -10.0, 10.0, 1.0),
            FreeParam::linear("c", 1.0, 0.0, 5.0, 1.0),
        ];
        let model = |x: &[f64]| {
            Ok(ts
                .iter()
                .zip(&ys)
                .map(|(t, y)| x[0] + x[1] * t - y)
                .collect())
        };
        let fit = levenberg_marquardt(&params, model, &options).unwrap();
        assert!(fit.converged, "{:?}", fit.stop);
        assert_eq!(fit.values[1], 0.0);
        assert!(fit.at_bound[1] && !fit.at_bound[0]);
        // To the cost tolerance: the misfit of the missing slope is large, and 1e-6 of it
        // is a small fraction of a's SD.
        let (a, sd_a) = (fit.values[0], fit.sd[0]);
        assert!((a - mean).abs() < 0.01 * sd_a, "{a} ± {sd_a} vs {mean}");
        // Its interval is clipped to the bound.
        assert_eq!(fit.ci95[1][0], 0.0);

        // The same with one parameter only, started at the bound: nothing to do.
        let single = [FreeParam::linear("c", 0.0, 0.0, 5.0, 1.0)];
        let line = |x: &[f64]| Ok(ts.iter().map(|t| x[0] * t + 0.5 * t).collect());
        let fit = levenberg_marquardt(&single, line, &options).unwrap();
        assert_eq!(fit.stop, Stop::Stationary);
        assert_eq!(fit.values[0], 0.0);
        assert!(fit.at_bound[0]);
        assert_eq!(fit.evaluations, if central { 3 } else { 2 });
    }
}

#[test]
fn a_parameter_without_effect_has_no_covariance_and_does_not_move() {
    // y = a t with a = 3; b is not in the model.
    let ts: Vec<f64> = (1..=20).map(f64::from).collect();
    let params = [
        FreeParam::linear("a", 1.0, -10.0, 10.0, 1.0),
        FreeParam::linear("b", 0.5, -10.0, 10.0, 1.0),
    ];
    let model = |x: &[f64]| Ok(ts.iter().map(|t| x[0] * t - 3.0 * t + 0.01).collect());
    let fit = levenberg_marquardt(&params, model, &LmOptions::default()).unwrap();
    assert!(fit.converged, "{:?}", fit.stop);
    // Least squares: a = 3 − 0.01 Σt / Σt², to the step tolerance (1e-6 × typical).
    assert!((fit.values[0] - (3.0 - 0.01 * 210.0 / 2870.0)).abs() < 1e-6);
    assert_eq!(fit.values[1], 0.5);
    assert!(fit.covariance.is_none() && fit.sd.iter().all(|v| v.is_nan()));
}

#[test]
fn a_rate_on_a_log_scale_crosses_two_decades() {
    let k_true = 1e-3;
    let ts: Vec<f64> = (0..100).map(|j| 20.0 * j as f64).collect();
    let params = [FreeParam::log("rate", 1e-1, 1e-6, 10.0)];
    let model = |x: &[f64]| {
        Ok(ts
            .iter()
            .map(|t| (-x[0] * t).exp() - (-k_true * t).exp())
            .collect())
    };
    let fit = levenberg_marquardt(&params, model, &LmOptions::default()).unwrap();
    eprintln!(
        "log rate: {:e} after {} iterations, {} evaluations",
        fit.values[0], fit.iterations, fit.evaluations
    );
    assert!(fit.converged);
    assert!(
        (fit.values[0] / k_true - 1.0).abs() < 1e-6,
        "{}",
        fit.values[0]
    );
}

#[test]
fn an_invalid_parameter_is_named() {
    let good = FreeParam::linear("good", 1.0, 0.0, 2.0, 1.0);
    let cases = [
        FreeParam::linear("swapped", 1.0, 2.0, 0.0, 1.0),
        FreeParam::linear("nan_start", f64::NAN, 0.0, 2.0, 1.0),
        FreeParam::log("log_at_zero", 1.0, 0.0, 2.0),
        FreeParam::linear("outside", 3.0, 0.0, 2.0, 1.0),
        FreeParam::linear("no_typical", 1.0, 0.0, 2.0, 0.0),
        FreeParam::linear("infinite", 1.0, 0.0, f64::INFINITY, 1.0),
    ];
    for bad in cases {
        let calls = AtomicUsize::new(0);
        let f = |_: &[f64]| {
            calls.fetch_add(1, Ordering::Relaxed);
            Ok(vec![0.0])
        };
        let params = [good.clone(), bad.clone()];
        match levenberg_marquardt(&params, f, &LmOptions::default()) {
            Err(e @ FitError::InvalidParam { .. }) => {
                let FitError::InvalidParam { name, .. } = &e else {
                    unreachable!()
                };
                assert_eq!(name, &bad.name);
                assert!(e.to_string().contains(&bad.name), "{e}");
            }
            other => panic!("{}: {other:?}", bad.name),
        }
        assert_eq!(calls.load(Ordering::Relaxed), 0);
    }
}

#[test]
fn a_residual_function_failing_past_two_is_stepped_around() {
    // r = eᡃ − e^1.5: the Gauss–Newton step from 0 lands at 3.5, where the model fails.
    let failures = AtomicUsize::new(0);
    let f = |x: &[f64]| {
        if x[0] > 2.0 {
            failures.fetch_add(1, Ordering::Relaxed);
            return Err(format!("no model at {}", x[0]));
        }
        Ok(vec![x[0].exp() - 1.5_f64.exp(), 0.5 * (x[0] - 1.5)])
    };
    // From 0 (trial steps fail), and from 2 exactly (the forward difference fails and
    // steps back).
    for start in [0.0, 2.0] {
        failures.store(0, Ordering::Relaxed);
        let params = [FreeParam::linear("x", start, -10.0, 10.0, 1.0)];
        let fit = levenberg_marquardt(&params, f, &LmOptions::default()).unwrap();
        assert!(fit.converged, "{start}: {:?}", fit.stop);
        assert!(
            (fit.values[0] - 1.5).abs() < 1e-6,
            "{start}: {}",
            fit.values[0]
        );
        assert!(failures.load(Ordering::Relaxed) > 0, "{start}");
    }
}

#[test]
fn failures_that_cannot_be_stepped_around_are_errors() {
    let params = [FreeParam::linear("x", 1.0, 0.0, 2.0, 1.0)];
    let options = LmOptions::default();
    // At the start.
    let e = levenberg_marquardt(&params, |_| Err("boom".into()), &options).unwrap_err();
    assert_eq!(e, FitError::Residuals("boom".into()));
    let e = levenberg_marquardt(&params, |_| Ok(vec![1.0, f64::NAN]), &options).unwrap_err();
    assert_eq!(e, FitError::NonFiniteStart { index: 1 });
    // On both sides of the Jacobian's point.
    let only_at_start = |x: &[f64]| {
        if x[0] == 1.0 {
            Ok(vec![1.0])
        } else {
            Err("off".into())
        }
    };
    let e = levenberg_marquardt(&params, only_at_start, &options).unwrap_err();
    assert!(
        matches!(&e, FitError::Jacobian { name, .. } if name == "x"),
        "{e:?}"
    );
    // The residual vector changes length.
    let grows = |x: &[f64]| Ok(vec![x[0]; if x[0] == 1.0 { 3 } else { 4 }]);
    let e = levenberg_marquardt(&params, grows, &options).unwrap_err();
    assert_eq!(
        e,
        FitError::SizeChanged {
            expected: 3,
            found: 4
        }
    );
}

#[test]
fn no_parameters_is_one_evaluation() {
    let fit = levenberg_marquardt(&[], |_| Ok(vec![3.0, 4.0]), &LmOptions::default()).unwrap();
    assert_eq!((fit.rss, fit.evaluations, fit.iterations), (25.0, 1, 0));
    assert!(fit.converged && fit.values.is_empty());
}

/// `evaluations` is the number of calls of the residual function, on any number of
/// threads, failed calls (and the Jacobian's retries on the other side) included.
#[test]
fn the_evaluation_count_is_the_calls_of_the_residual_function() {
    let data = decay_data(5);
    for threads in [1, 3] {
        let (calls, failures) = (AtomicUsize::new(0), AtomicUsize::new(0));
        // The model cannot be evaluated beyond a = 2.1 (the optimum is near 2).
        let model = |x: &[f64]| {
            calls.fetch_add(1, Ordering::Relaxed);
            if x[0] > 2.1 {
                failures.fetch_add(1, Ordering::Relaxed);
                return Err("a > 2.1".to_string());
            }
            Ok(data
                .iter()
                .map(|&(t, y)| (x[0] * (-x[1] * t).exp() - y) / SIGMA)
                .collect())
        };
        let params = [
            FreeParam::linear("a", 2.099, 0.0, 10.0, 1.0),
            FreeParam::log("b", 0.2, 1e-3, 100.0),
        ];
        let options = LmOptions {
            threads,
            fd_relative_step: 2e-3,
            ..LmOptions::default()
        };
        let fit = levenberg_marquardt(&params, model, &options).unwrap();
        assert_eq!(
            fit.evaluations,
            calls.load(Ordering::Relaxed),
            "{threads} threads"
        );
    }
}

#[test]
fn the_thread_count_does_not_change_the_result() {
    let data = decay_data(3);
    for central in [false, true] {
        let fits: Vec<LmFit> = [1, 2, 3, 8]
            .into_iter()
            .map(|threads| {
                let options = LmOptions {
                    central,
                    threads,
                    ..LmOptions::default()
                };
                fit_decay(&data, &options)
            })
            .collect();
        let bits = |fit: &LmFit| {
            let mut b: Vec<u64> = fit.values.iter().map(|v| v.to_bits()).collect();
            b.extend(fit.residuals.iter().map(|v| v.to_bits()));
            b.extend(fit.covariance.as_ref().unwrap().iter().map(|v| v.to_bits()));
            b.push(fit.rss.to_bits());
            b.push(fit.evaluations as u64);
            b.push(fit.iterations as u64);
            b
        };
        for fit in &fits[1..] {
            assert_eq!(bits(fit), bits(&fits[0]), "central {central}");
        }
    }
}

/// A fit without a covariance stops where the one with it does, with the same values, one
/// Jacobian (two evaluations here) cheaper at its step limit, and says it has none.
#[test]
fn a_fit_without_covariance_skips_only_the_last_jacobian() {
    let data = decay_data(7);
    let mut limited = 0;
    for max_iterations in [1, 2] {
        let with = fit_decay(
            &data,
            &LmOptions {
                max_iterations,
                ..LmOptions::default()
            },
        );
        let without = fit_decay(
            &data,
            &LmOptions {
                max_iterations,
                covariance: false,
                ..LmOptions::default()
            },
        );
        assert_eq!(with.values, without.values);
        assert_eq!(with.rss, without.rss);
        assert_eq!(with.iterations, without.iterations);
        if with.stop == Stop::MaxIterations {
            assert_eq!(without.evaluations + 2, with.evaluations);
            limited += 1;
        }
        assert!(with.covariance.is_some());
        assert!(without.covariance.is_none() && without.sd.iter().all(|v| v.is_nan()));
    }
    assert!(limited > 0, "no fit reached its step limit");
}

/// A line fitted through correlated errors it takes for independent ones (AR(1), ρ 0.95:
/// a structural error's stretches of one sign): `s² (JᵀJ)⁻¹` covers the slope about one
/// time in three, the batch-means sandwich about as often as it says.
#[test]
fn the_sandwich_holds_the_truth_where_the_errors_are_correlated() {
    let (a_true, b_true, rho) = (1.0, 2.0, 0.95);
    let n = 2000;
    let seeds = 200;
    let mut covered = [0usize; 2];
    let mut width = [0.0; 2];
    for seed in 0..seeds {
        let mut noise = Noise::new(1000 + seed);
        let mut e = noise.gaussian();
        let data: Vec<(f64, f64)> = (0..n)
            .map(|j| {
                let t = j as f64 / n as f64;
                e = rho * e + (1.0 - rho * rho).sqrt() * noise.gaussian();
                (t, a_true + b_true * t + e)
            })
            .collect();
        let params = vec![
            FreeParam::linear("a", 0.0, -10.0, 10.0, 1.0),
            FreeParam::linear("b", 0.0, -10.0, 10.0, 1.0),
        ];
        for (i, batches) in [0, 20].into_iter().enumerate() {
            let options = LmOptions {
                score_batches: batches,
                ..LmOptions::default()
            };
            let fit = levenberg_marquardt(
                &params,
                |x: &[f64]| Ok(data.iter().map(|&(t, y)| x[0] + x[1] * t - y).collect()),
                &options,
            )
            .unwrap();
            let [lo, hi] = fit.ci95[1];
            covered[i] += usize::from((lo..=hi).contains(&b_true));
            width[i] += (hi - lo) / seeds as f64;
        }
    }
    let rate = |c: usize| c as f64 / seeds as f64;
    // Independent errors would have the plain interval cover 95 %; these are 39 times
    // the variance it assumes (1 + ρ)/(1 − ρ), so it covers about 2Φ(1.96/√39) − 1 = 24 %.
    eprintln!(
        "coverage: plain {:.2}, sandwich {:.2}",
        rate(covered[0]),
        rate(covered[1])
    );
    assert!(
        rate(covered[0]) < 0.5,
        "plain covers {:.2}",
        rate(covered[0])
    );
    // 20 batches of 100 points, each ~5 correlation lengths: the sandwich's variance has
    // about 19 degrees of freedom, so ±1.96 SD covers about 93 %.
    assert!(
        (0.85..=0.99).contains(&rate(covered[1])),
        "sandwich covers {:.2} (plain {:.2}; widths {:.3} vs {:.3})",
        rate(covered[1]),
        rate(covered[0]),
        width[1],
        width[0]
    );
}

/// With independent errors the sandwich agrees with `s² (JᵀJ)⁻¹` (it is never narrower).
#[test]
fn with_independent_errors_the_sandwich_is_the_plain_interval() {
    let data = decay_data(7);
    let plain = fit_decay(&data, &LmOptions::default());
    let sandwich = fit_decay(
        &data,
        &LmOptions {
            score_batches: 20,
            ..LmOptions::default()
        },
    );
    for i in 0..2 {
        assert_eq!(plain.values[i], sandwich.values[i]);
        let ratio = sandwich.sd[i] / plain.sd[i];
        // Never narrower; wider by at most what 20 batches' sampling error allows.
        assert!(
            (1.0..1.6).contains(&ratio),
            "param {i}: sd ratio {ratio:.3}"
        );
    }
}

/// Six bumps of known centres and unknown heights and widths (12 parameters, widths on a
/// log scale), measured with noise, started a factor off.
fn bumps_fit(seed: u64, options: &LmOptions) -> LmFit {
    bumps_fit_from(seed, options, &[0.7, 0.45].repeat(6))
}

/// A plain fit of the bumps started at `values` and stopped before its first step: the
/// covariance of finite differences there.
fn refit_bumps_at(seed: u64, values: &[f64]) -> LmFit {
    let options = LmOptions {
        max_iterations: 0,
        ..LmOptions::default()
    };
    bumps_fit_from(seed, &options, values)
}

fn bumps_fit_from(seed: u64, options: &LmOptions, start: &[f64]) -> LmFit {
    let centres = [1.0, 2.5, 4.0, 5.5, 7.0, 8.5];
    let heights = [1.0, 0.6, 1.4, 0.8, 1.2, 0.5];
    let widths = [0.4, 0.6, 0.3, 0.5, 0.7, 0.35];
    let bump = |t: f64, c: f64, a: f64, w: f64| a * (-0.5 * ((t - c) / w).powi(2)).exp();
    let mut noise = Noise::new(seed);
    let data: Vec<(f64, f64)> = (0..400)
        .map(|j| {
            let t = 0.025 * j as f64;
            let y: f64 = (0..6)
                .map(|i| bump(t, centres[i], heights[i], widths[i]))
                .sum();
            (t, y + 0.02 * noise.gaussian())
        })
        .collect();
    let mut params = Vec::new();
    for i in 0..6 {
        params.push(FreeParam::linear(
            format!("a{i}"),
            start[2 * i],
            0.0,
            5.0,
            0.1,
        ));
        params.push(FreeParam::log(format!("w{i}"), start[2 * i + 1], 0.05, 2.0));
    }
    let model = |x: &[f64]| {
        Ok(data
            .iter()
            .map(|&(t, y)| {
                let m: f64 = (0..6)
                    .map(|i| bump(t, centres[i], x[2 * i], x[2 * i + 1]))
                    .sum();
                (m - y) / 0.02
            })
            .collect())
    };
    levenberg_marquardt(&params, model, options).unwrap()
}

/// The secant option (Broyden's update between Jacobians of finite differences) ends
/// where the plain method does, within a small part of the standard deviations, with the
/// same covariance (both stop on finite differences at their optimum), on fewer
/// Jacobians and evaluations.
#[test]
fn secant_updates_reach_the_same_optimum_on_fewer_evaluations() {
    let (mut plain_evaluations, mut secant_evaluations) = (0, 0);
    for seed in 0..5 {
        let plain = bumps_fit(seed, &LmOptions::default());
        let secant = bumps_fit(
            seed,
            &LmOptions {
                secant: true,
                ..LmOptions::default()
            },
        );
        assert!(plain.converged && secant.converged, "seed {seed}");
        for i in 0..12 {
            let moved = (plain.values[i] - secant.values[i]).abs() / plain.sd[i];
            assert!(moved < 0.05, "seed {seed}, param {i}: {moved} sd apart");
            assert!(
                (secant.sd[i] / plain.sd[i] - 1.0).abs() < 0.01,
                "seed {seed}"
            );
        }
        assert!((secant.rss - plain.rss).abs() < 1e-3 * plain.rss);
        // Its covariance is that of finite differences at its own optimum, to the bit's
        // noise: a plain fit started there and stopped at once reports the same.
        let there = refit_bumps_at(seed, &secant.values);
        for i in 0..12 {
            assert!(
                (secant.sd[i] / there.sd[i] - 1.0).abs() < 1e-9,
                "seed {seed}, param {i}: {} against {}",
                secant.sd[i],
                there.sd[i]
            );
        }
        eprintln!(
            "seed {seed}: plain {} evaluations, {} Jacobians; secant {}, {}",
            plain.evaluations, plain.jacobians, secant.evaluations, secant.jacobians
        );
        assert!(secant.jacobians < plain.jacobians, "seed {seed}");
        plain_evaluations += plain.evaluations;
        secant_evaluations += secant.evaluations;
    }
    assert!(
        (secant_evaluations as f64) < 0.8 * plain_evaluations as f64,
        "{secant_evaluations} for {plain_evaluations}"
    );
}

/// On a hard valley the secant method still converges, with the covariance or without it
/// (each rejected trial on an updated Jacobian takes finite differences again).
#[test]
fn secant_updates_still_converge_in_a_valley() {
    let params = [
        FreeParam::linear("x", -1.2, -5.0, 5.0, 1.0),
        FreeParam::linear("y", 1.0, -5.0, 5.0, 1.0),
    ];
    let rosenbrock = |p: &[f64]| Ok(vec![10.0 * (p[1] - p[0] * p[0]), 1.0 - p[0]]);
    for covariance in [true, false] {
        let options = LmOptions {
            secant: true,
            covariance,
            ..LmOptions::default()
        };
        let fit = levenberg_marquardt(&params, rosenbrock, &options).unwrap();
        eprintln!(
            "rosenbrock, secant: {:?} after {} iterations, {} evaluations, {} Jacobians",
            fit.values, fit.iterations, fit.evaluations, fit.jacobians
        );
        assert!(fit.converged, "{:?}", fit.stop);
        assert!((fit.values[0] - 1.0).abs() < 1e-6 && (fit.values[1] - 1.0).abs() < 1e-6);
    }
}

/// The score's inflation reads independent errors as themselves (about 1) and an AR(1)
/// error as the variance factor of its batches' sums: for ρ 0.95 over batches of 100,
/// `(L(1 + ρ)/(1 − ρ) − 2ρ(1 − ρᴸ)/(1 − ρ)²)/L` = 31.4 (the variance of a sum of an AR(1)
/// process), about 31 once the fitted line's share of each batch is taken from the meat
/// and its expectation alike.
#[test]
fn the_score_inflation_is_one_for_noise_and_the_correlations_factor_otherwise() {
    let options = LmOptions {
        score_batches: 20,
        ..LmOptions::default()
    };
    let seeds = 40;
    let independent: f64 = (0..seeds)
        .map(|seed| {
            let fit = fit_decay(&decay_data(seed), &options);
            fit.score_inflation.expect("an inflation")
        })
        .sum::<f64>()
        / seeds as f64;
    assert!(
        (0.8..=1.15).contains(&independent),
        "independent errors: {independent:.3}"
    );
    let (rho, n) = (0.95, 2000);
    let correlated: f64 = (0..seeds)
        .map(|seed| {
            let mut noise = Noise::new(5000 + seed);
            let mut e = noise.gaussian();
            let data: Vec<(f64, f64)> = (0..n)
                .map(|j| {
                    let t = j as f64 / n as f64;
                    e = rho * e + (1.0 - rho * rho).sqrt() * noise.gaussian();
                    (t, 1.0 + 2.0 * t + e)
                })
                .collect();
            let params = vec![
                FreeParam::linear("a", 0.0, -10.0, 10.0, 1.0),
                FreeParam::linear("b", 0.0, -10.0, 10.0, 1.0),
            ];
            let fit = levenberg_marquardt(
                &params,
                |x: &[f64]| Ok(data.iter().map(|&(t, y)| x[0] + x[1] * t - y).collect()),
                &options,
            )
            .expect("a line fits");
            fit.score_inflation.expect("an inflation")
        })
        .sum::<f64>()
        / seeds as f64;
    assert!(
        (22.0..=40.0).contains(&correlated),
        "AR(1) errors: {correlated:.1}"
    );
    eprintln!("score inflation: independent {independent:.3}, AR(1) {correlated:.1}");
    let plain = fit_decay(&decay_data(1), &LmOptions::default());
    assert_eq!(plain.score_inflation, None, "no batches, no inflation");
}

/// A prior's terms after the data (`score_rows`) stay out of the score's inflation, and a
/// prior's pull is not read as the data's error: where a prior holds a fit off the data's
/// optimum, the data's own noise still reads about 1 (over 40 seeds; without projecting
/// the residuals off the columns first, 2.1), a fit with the prior's row reads at that
/// point what the data alone read, and counting the prior's row changes it.
#[test]
fn a_priors_rows_stay_out_of_the_score_inflation() {
    let fit =
        |data: &[(f64, f64)], prior: bool, rows: usize, params: &[FreeParam], iterations: usize| {
            let model = |x: &[f64]| {
                let mut r: Vec<f64> = data
                    .iter()
                    .map(|&(t, y)| (x[0] * (-x[1] * t).exp() - y) / SIGMA)
                    .collect();
                if prior {
                    r.push((x[0] - 0.9 * A_TRUE) / (0.02 * A_TRUE));
                }
                Ok(r)
            };
            let options = LmOptions {
                score_batches: 20,
                score_rows: rows,
                max_iterations: iterations,
                ..LmOptions::default()
            };
            levenberg_marquardt(params, model, &options).expect("a fit")
        };
    let seeds = 40;
    let mut held_mean = 0.0;
    for seed in 0..seeds {
        let data = decay_data(100 + seed);
        let held = fit(&data, true, data.len(), &decay_params(), 40);
        held_mean += held.score_inflation.expect("an inflation") / seeds as f64;
    }
    assert!(
        (0.8..=1.2).contains(&held_mean),
        "the data's noise under a prior's pull: {held_mean:.2}"
    );
    let data = decay_data(3);
    let n = data.len();
    let held = fit(&data, true, n, &decay_params(), 40);
    // Stopped before a first step from the held optimum: the Jacobian there.
    let mut at = decay_params();
    for (p, v) in at.iter_mut().zip(&held.values) {
        p.start = *v;
    }
    let inflation = |prior: bool, rows: usize| {
        fit(&data, prior, rows, &at, 0)
            .score_inflation
            .expect("an inflation")
    };
    let data_alone = inflation(false, 0);
    let rows_left_out = inflation(true, n);
    let rows_counted = inflation(true, 0);
    eprintln!(
        "inflation: held {held_mean:.2}; data {data_alone:.2}, prior left out \
         {rows_left_out:.2}, counted {rows_counted:.2}"
    );
    assert!(
        (rows_left_out - data_alone).abs() <= 0.02 * data_alone,
        "{rows_left_out} for {data_alone}"
    );
    assert!(
        (rows_counted - data_alone).abs() > 0.15 * data_alone,
        "{rows_counted} for {data_alone}"
    );
}
