//! The algorithms against closed forms, against each other, and against finite differences
//! of the Lagrangian (Pinocchio's `unittest/crba.cpp`, `aba.cpp`, `energy.cpp` in spirit).

use std::f64::consts::PI;

use mbs_core::benchmarks::{branching_tree, planar_chain};
use mbs_core::{
    BodySpec, Data, JointKind, Model, ModelBuilder, Placement, Prescribed, aba, crba,
    forward_dynamics_crba, forward_kinematics, forward_kinematics_acc, frame_jacobian,
    gravity_torque, hybrid_dynamics, kinetic_energy, mechanical_energy, nonlinear_effects,
    point_acceleration, point_jacobian, point_position, point_velocity, potential_energy, rnea,
    update_poses,
};
use nalgebra::{DMatrix, DVector};

/// A deterministic pseudo-random sequence (no RNG dependency, same numbers every run).
fn pseudo_random(seed: u64, n: usize, lo: f64, hi: f64) -> Vec<f64> {
    let mut s = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            lo + (hi - lo) * u
        })
        .collect()
}

fn models() -> Vec<(&'static str, Model)> {
    vec![
        ("planar5", planar_chain(5)),
        ("branching13", branching_tree()),
        ("planar12", planar_chain(12)),
    ]
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A rod pendulum on the ground: mass m, length l, com at l/2, inertia m l²/12 about it.
fn rod_pendulum(m: f64, l: f64, g: f64) -> Model {
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -g]).add_link(
        "rod",
        None,
        JointKind::Revolute,
        Placement::default(),
        BodySpec::rod(m, l),
    );
    b.build().unwrap()
}

#[test]
fn single_pendulum_mass_matrix_is_m_l2_over_3() {
    let (m, l) = (0.7, 1.3);
    let model = rod_pendulum(m, l, 9.81);
    let mut data = Data::new(&model);
    for q in [-2.0f64, 0.0, 0.4, 3.0] {
        let mm = crba(&model, &mut data, &[q]).unwrap();
        assert!((mm[(0, 0)] - m * l * l / 3.0).abs() < 1e-14);
        // g(q) = m g (l/2) cos q
        let g = gravity_torque(&model, &mut data, &[q]).unwrap();
        assert!((g[0] - m * 9.81 * 0.5 * l * q.cos()).abs() < 1e-13);
    }
}

/// Arithmetic–geometric mean.
fn agm(mut a: f64, mut b: f64) -> f64 {
    // Quadratic convergence: 40 iterations are far more than f64 needs.
    for _ in 0..40 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    a
}

/// Classic RK4 on `ẋ = f(x)` with a fixed step (kept in the test: the integrators crate
/// is separate).
fn rk4_step(f: &mut impl FnMut(&[f64], &mut [f64]), x: &mut [f64], h: f64) {
    let n = x.len();
    let (mut k1, mut k2, mut k3, mut k4) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut y = vec![0.0; n];
    f(x, &mut k1);
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k1[i];
    }
    f(&y, &mut k2);
    for i in 0..n {
        y[i] = x[i] + 0.5 * h * k2[i];
    }
    f(&y, &mut k3);
    for i in 0..n {
        y[i] = x[i] + h * k3[i];
    }
    f(&y, &mut k4);
    for i in 0..n {
        x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
    }
}

#[test]
fn pendulum_period_matches_the_exact_large_amplitude_formula() {
    // T = 2π sqrt(I_o / (m g d)) / AGM(1, cos(θ₀/2)), exact for any amplitude θ₀.
    let (m, l, g) = (0.4, 0.9, 9.81);
    let model = rod_pendulum(m, l, g);
    let mut data = Data::new(&model);
    let i_o = m * l * l / 3.0;
    let t0 = 2.0 * PI * (i_o / (m * g * 0.5 * l)).sqrt();
    for amp in [0.05f64, 1.0, 2.5] {
        let exact = t0 / agm(1.0, (0.5 * amp).cos());
        // Hanging straight down is q = −π/2; release at rest from −π/2 + amp.
        let mut x = vec![-PI / 2.0 + amp, 0.0];
        let h = 2e-4;
        let mut f = |x: &[f64], dx: &mut [f64]| {
            let a = aba(&model, &mut data, &x[..1], &x[1..], &[0.0]).unwrap()[0];
            dx[0] = x[1];
            dx[1] = a;
        };
        let crossings = upward_crossings(&mut f, &mut x, -PI / 2.0, h, 3);
        let period = crossings[2] - crossings[1];
        let rel = (period - exact).abs() / exact;
        assert!(
            rel < 1e-8,
            "amplitude {amp}: period {period}, exact {exact}, rel {rel:e}"
        );
    }
}

/// Parameters of an acrobot (double pendulum) with unequal links, angles from the x axis.
#[derive(Clone, Copy)]
struct Acrobot {
    m1: f64,
    m2: f64,
    l1: f64,
    lc1: f64,
    lc2: f64,
    i1: f64,
    i2: f64,
    g: f64,
}

const ACROBOT: Acrobot = Acrobot {
    m1: 1.1,
    m2: 0.8,
    l1: 1.2,
    lc1: 0.5,
    lc2: 0.7,
    i1: 0.09,
    i2: 0.13,
    g: 9.81,
};

impl Acrobot {
    fn model(&self) -> Model {
        let mut b = ModelBuilder::new();
        b.gravity([0.0, -self.g])
            .add_link(
                "upper",
                None,
                JointKind::Revolute,
                Placement::default(),
                BodySpec::new(self.m1, [self.lc1, 0.0], self.i1),
            )
            .add_link(
                "lower",
                Some("upper"),
                JointKind::Revolute,
                Placement::offset(self.l1, 0.0),
                BodySpec::new(self.m2, [self.lc2, 0.0], self.i2),
            );
        b.build().unwrap()
    }
}

/// Times of upward zero crossings of coordinate 0 (about `offset`) over a run with RK4,
/// each refined on the cubic Hermite interpolant of the step.
fn upward_crossings(
    f: &mut impl FnMut(&[f64], &mut [f64]),
    x: &mut [f64],
    offset: f64,
    h: f64,
    count: usize,
) -> Vec<f64> {
    let n = x.len() / 2;
    let mut crossings = Vec::new();
    let mut t = 0.0;
    while crossings.len() < count && t < 100.0 {
        let prev = x.to_vec();
        rk4_step(f, x, h);
        t += h;
        let (e0, e1) = (prev[0] - offset, x[0] - offset);
        if e0 < 0.0 && e1 >= 0.0 {
            let (d0, d1) = (h * prev[n], h * x[n]);
            let mut s = e0 / (e0 - e1);
            for _ in 0..50 {
                let p = (2.0 * s * s * s - 3.0 * s * s + 1.0) * e0
                    + (s * s * s - 2.0 * s * s + s) * d0
                    + (-2.0 * s * s * s + 3.0 * s * s) * e1
                    + (s * s * s - s * s) * d1;
                let dp = (6.0 * s * s - 6.0 * s) * e0
                    + (3.0 * s * s - 4.0 * s + 1.0) * d0
                    + (-6.0 * s * s + 6.0 * s) * e1
                    + (3.0 * s * s - 2.0 * s) * d1;
                s -= p / dp;
            }
            crossings.push(t - h + s * h);
        }
    }
    crossings
}

#[test]
fn double_pendulum_normal_mode_periods_match_the_linearised_closed_form() {
    // Hanging at rest (q = (−π/2, 0)), small motions obey M₀ θ̈ + K θ = 0 with M₀ the acrobot
    // mass matrix at q₂ = 0 and K the Hessian of the potential:
    //   K11 = g (m1 lc1 + m2 (l1 + lc2)),  K12 = K22 = g m2 lc2.
    // det(K − λ M₀) = 0 gives ω² = λ; started along a mode shape, the motion has period 2π/ω.
    let Acrobot {
        m1,
        m2,
        l1,
        lc1,
        lc2,
        i1,
        i2,
        g,
    } = ACROBOT;
    let model = ACROBOT.model();
    let mut data = Data::new(&model);
    let m11 = i1 + i2 + m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2);
    let m12 = i2 + m2 * (lc2 * lc2 + l1 * lc2);
    let m22 = i2 + m2 * lc2 * lc2;
    let (k11, k12, k22) = (g * (m1 * lc1 + m2 * (l1 + lc2)), g * m2 * lc2, g * m2 * lc2);
    // (m11 m22 − m12²) λ² − (k11 m22 + k22 m11 − 2 k12 m12) λ + (k11 k22 − k12²) = 0
    let qa = m11 * m22 - m12 * m12;
    let qb = -(k11 * m22 + k22 * m11 - 2.0 * k12 * m12);
    let qc = k11 * k22 - k12 * k12;
    let disc = (qb * qb - 4.0 * qa * qc).sqrt();
    for lambda in [(-qb - disc) / (2.0 * qa), (-qb + disc) / (2.0 * qa)] {
        // Mode shape: (K − λ M₀) φ = 0 → φ = (−(k12 − λ m12), k11 − λ m11), signed so the
        // first joint starts above its rest angle and next crosses it going up.
        let mut phi = [-(k12 - lambda * m12), k11 - lambda * m11];
        if phi[0] < 0.0 {
            phi = [-phi[0], -phi[1]];
        }
        let scale = 1e-4 / phi[0].abs().max(phi[1].abs());
        let mut x = vec![-PI / 2.0 + scale * phi[0], scale * phi[1], 0.0, 0.0];
        let mut f = |x: &[f64], dx: &mut [f64]| {
            let a = aba(&model, &mut data, &x[..2], &x[2..], &[0.0, 0.0]).unwrap();
            dx[..2].copy_from_slice(&x[2..]);
            dx[2..].copy_from_slice(a.as_slice());
        };
        let c = upward_crossings(&mut f, &mut x, -PI / 2.0, 2e-4, 3);
        let period = c[2] - c[1];
        let exact = 2.0 * PI / lambda.sqrt();
        let rel = (period - exact).abs() / exact;
        assert!(
            rel < 1e-6,
            "mode ω² = {lambda}: period {period}, linear theory {exact}, rel {rel:e}"
        );
    }
}

#[test]
fn double_pendulum_matches_the_acrobot_closed_form() {
    // Acrobot (Drake multibody/benchmarks/acrobot) with angles from the x axis and gravity −y.
    let Acrobot {
        m1,
        m2,
        l1,
        lc1,
        lc2,
        i1,
        i2,
        g,
    } = ACROBOT;
    let model = ACROBOT.model();
    let mut data = Data::new(&model);
    for (q, v) in [
        ([0.3f64, -0.7], [1.2, -0.4]),
        ([-2.0, 2.5], [-0.3, 2.0]),
        ([1.0, 0.0], [0.0, 0.0]),
    ] {
        let c2 = q[1].cos();
        let s2 = q[1].sin();
        let m11 = i1 + i2 + m1 * lc1 * lc1 + m2 * (l1 * l1 + lc2 * lc2 + 2.0 * l1 * lc2 * c2);
        let m12 = i2 + m2 * (lc2 * lc2 + l1 * lc2 * c2);
        let m22 = i2 + m2 * lc2 * lc2;
        let mm = crba(&model, &mut data, &q).unwrap();
        assert!((mm[(0, 0)] - m11).abs() < 1e-13);
        assert!((mm[(0, 1)] - m12).abs() < 1e-13);
        assert!((mm[(1, 0)] - m12).abs() < 1e-13);
        assert!((mm[(1, 1)] - m22).abs() < 1e-13);
        let h = m2 * l1 * lc2 * s2;
        let g1 = m1 * g * lc1 * q[0].cos() + m2 * g * (l1 * q[0].cos() + lc2 * (q[0] + q[1]).cos());
        let g2 = m2 * g * lc2 * (q[0] + q[1]).cos();
        let c1 = -h * (2.0 * v[0] * v[1] + v[1] * v[1]);
        let c2v = h * v[0] * v[0];
        let nle = nonlinear_effects(&model, &mut data, &q, &v).unwrap();
        assert!(
            (nle[0] - (c1 + g1)).abs() < 1e-12,
            "{} vs {}",
            nle[0],
            c1 + g1
        );
        assert!((nle[1] - (c2v + g2)).abs() < 1e-12);
    }
}

#[test]
fn crba_columns_equal_rnea_differences() {
    for (name, model) in models() {
        let n = model.nv();
        let mut data = Data::new(&model);
        let q = pseudo_random(1, n, -PI, PI);
        let zero = vec![0.0; n];
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let g = rnea(&model, &mut data, &q, &zero, &zero).unwrap().clone();
        for k in 0..n {
            let mut e = vec![0.0; n];
            e[k] = 1.0;
            let col = rnea(&model, &mut data, &q, &zero, &e).unwrap() - &g;
            let d = max_abs_diff(col.as_slice(), m.column(k).as_slice());
            assert!(d < 1e-12, "{name}: column {k} differs by {d:e}");
        }
        assert_eq!(m, m.transpose(), "{name}: M not exactly symmetric");
    }
}

#[test]
fn aba_undoes_rnea_and_equals_crba_cholesky() {
    for (name, model) in models() {
        let n = model.nv();
        let mut data = Data::new(&model);
        for seed in 0..5 {
            let q = pseudo_random(10 + seed, n, -PI, PI);
            let v = pseudo_random(20 + seed, n, -2.0, 2.0);
            let a = pseudo_random(30 + seed, n, -5.0, 5.0);
            let tau = rnea(&model, &mut data, &q, &v, &a).unwrap().clone();
            let qdd = aba(&model, &mut data, &q, &v, tau.as_slice())
                .unwrap()
                .clone();
            let d = max_abs_diff(qdd.as_slice(), &a);
            assert!(d < 1e-12, "{name}: ABA(RNEA(a)) − a = {d:e}");
            let qdd2 =
                forward_dynamics_crba(&model, &mut data, &q, &v, tau.as_slice(), None).unwrap();
            let d = max_abs_diff(qdd2.as_slice(), qdd.as_slice());
            assert!(d < 1e-12, "{name}: ABA − CRBA/Cholesky = {d:e}");
            // And against nalgebra's dense Cholesky of the same M.
            let m = crba(&model, &mut data, &q).unwrap().clone();
            let nle = nonlinear_effects(&model, &mut data, &q, &v)
                .unwrap()
                .clone();
            let dense = m.cholesky().unwrap().solve(&(tau - nle));
            let d = max_abs_diff(dense.as_slice(), qdd.as_slice());
            assert!(d < 1e-11, "{name}: ABA − dense Cholesky = {d:e}");
        }
    }
}

#[test]
fn rnea_equals_euler_lagrange_by_finite_differences() {
    // τ = d/dt(∂T/∂v) − ∂T/∂q + ∂V/∂q, with ∂T/∂v = M v and
    // d/dt(M v) = M a + (dM/dq · v) v, derivatives by central differences.
    for (name, model) in models() {
        let n = model.nv();
        let mut data = Data::new(&model);
        let q = pseudo_random(3, n, -PI, PI);
        let v = pseudo_random(4, n, -2.0, 2.0);
        let a = pseudo_random(5, n, -5.0, 5.0);
        let h = 1e-5;
        let shifted = |s: f64, dir: &[f64]| -> Vec<f64> {
            q.iter().zip(dir).map(|(x, d)| x + s * d).collect()
        };
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let mp = crba(&model, &mut data, &shifted(h, &v)).unwrap().clone();
        let mm = crba(&model, &mut data, &shifted(-h, &v)).unwrap().clone();
        let mdot = (mp - mm) / (2.0 * h);
        let vv = DVector::from_column_slice(&v);
        let mut lagrange = &m * DVector::from_column_slice(&a) + &mdot * &vv;
        for k in 0..n {
            let mut e = vec![0.0; n];
            e[k] = 1.0;
            let (qp, qm) = (shifted(h, &e), shifted(-h, &e));
            let dt = (kinetic_energy(&model, &mut data, &qp, &v).unwrap()
                - kinetic_energy(&model, &mut data, &qm, &v).unwrap())
                / (2.0 * h);
            let dv = (potential_energy(&model, &mut data, &qp).unwrap()
                - potential_energy(&model, &mut data, &qm).unwrap())
                / (2.0 * h);
            lagrange[k] += -dt + dv;
        }
        let tau = rnea(&model, &mut data, &q, &v, &a).unwrap();
        let scale = 1.0 + tau.amax();
        let d = max_abs_diff(tau.as_slice(), lagrange.as_slice());
        assert!(d < 1e-7 * scale, "{name}: RNEA − Euler–Lagrange = {d:e}");
    }
}

#[test]
fn kinetic_energy_is_half_vt_m_v() {
    for (name, model) in models() {
        let n = model.nv();
        let mut data = Data::new(&model);
        let q = pseudo_random(7, n, -PI, PI);
        let v = pseudo_random(8, n, -2.0, 2.0);
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let vv = DVector::from_column_slice(&v);
        let t = 0.5 * vv.dot(&(&m * &vv));
        let k = kinetic_energy(&model, &mut data, &q, &v).unwrap();
        assert!((t - k).abs() < 1e-12 * (1.0 + t), "{name}: {t} vs {k}");
    }
}

#[test]
fn rk4_conserves_the_energy_of_a_conservative_chain() {
    let model = planar_chain(5);
    let n = model.nv();
    let mut data = Data::new(&model);
    let mut x: Vec<f64> = pseudo_random(11, n, -1.0, 1.0);
    x.extend(pseudo_random(12, n, -1.0, 1.0));
    let e0 = mechanical_energy(&model, &mut data, &x[..n], &x[n..]).unwrap();
    let zero = vec![0.0; n];
    let mut f = |x: &[f64], dx: &mut [f64]| {
        let qdd = aba(&model, &mut data, &x[..n], &x[n..], &zero).unwrap();
        dx[..n].copy_from_slice(&x[n..]);
        dx[n..].copy_from_slice(qdd.as_slice());
    };
    let mut drift: f64 = 0.0;
    let h = 1e-3;
    let mut e_data = Data::new(&model);
    for step in 1..=2000 {
        rk4_step(&mut f, &mut x, h);
        if step % 100 == 0 {
            let e = mechanical_energy(&model, &mut e_data, &x[..n], &x[n..]).unwrap();
            drift = drift.max((e - e0).abs());
        }
    }
    // The chain swings through ~10 J of kinetic/potential exchange; RK4 at 1 ms keeps the
    // total within a few µJ over 2 s.
    assert!(drift < 1e-5, "energy drift {drift:e} J (E0 = {e0})");
    assert!(
        drift > 0.0,
        "an RK4 run that conserves energy exactly is suspicious"
    );
}

#[test]
fn hybrid_dynamics_matches_the_hand_derived_cart_pendulum() {
    // A cart on a horizontal slider (mass mc) carrying a rod pendulum (mass m, com at lc,
    // inertia ic). With the cart's acceleration ẍ prescribed, Lagrange gives
    //   I_o θ̈ = τ_θ + m lc sin θ ẍ − m g lc cos θ,                 I_o = ic + m lc²
    //   F     = (mc + m) ẍ − m lc (sin θ θ̈ + cos θ θ̇²).
    let (mc, m, lc, ic, g) = (2.0, 0.5, 0.3, 0.02, 9.81);
    let mut b = ModelBuilder::new();
    b.gravity([0.0, -g])
        .add_link(
            "cart",
            None,
            JointKind::Prismatic { axis: [1.0, 0.0] },
            Placement::default(),
            BodySpec::new(mc, [0.0, 0.0], 0.1),
        )
        .add_link(
            "pole",
            Some("cart"),
            JointKind::Revolute,
            Placement::default(),
            BodySpec::new(m, [lc, 0.0], ic),
        );
    let model = b.build().unwrap();
    let mut data = Data::new(&model);
    let i_o = ic + m * lc * lc;
    for (th, thd, xdd, tau_th) in [
        (0.3f64, 1.0, 2.0, 0.0),
        (-1.2, -0.5, -3.0, 0.2),
        (2.5, 3.0, 0.0, -0.1),
    ] {
        let q = [0.7, th];
        let v = [-0.4, thd];
        hybrid_dynamics(
            &model,
            &mut data,
            &q,
            &v,
            &[f64::NAN, tau_th], // the cart's τ entry is ignored
            Prescribed {
                mask: &[true, false],
                qdd: &[xdd, f64::NAN],
            },
            None,
        )
        .unwrap();
        let thdd = (tau_th + m * lc * th.sin() * xdd - m * g * lc * th.cos()) / i_o;
        let f = (mc + m) * xdd - m * lc * (th.sin() * thdd + th.cos() * thd * thd);
        assert!((data.qdd()[0] - xdd).abs() < 1e-15);
        assert!(
            (data.qdd()[1] - thdd).abs() < 1e-12,
            "θ̈ {} vs {}",
            data.qdd()[1],
            thdd
        );
        assert!(
            (data.tau()[0] - f).abs() < 1e-12,
            "F {} vs {}",
            data.tau()[0],
            f
        );
        assert_eq!(data.tau()[1], tau_th);
    }
}

#[test]
fn point_kinematics_agree_with_finite_differences_and_jacobians() {
    for (name, model) in models() {
        let n = model.nv();
        let mut data = Data::new(&model);
        let q = pseudo_random(13, n, -PI, PI);
        let v = pseudo_random(14, n, -2.0, 2.0);
        let a = pseudo_random(15, n, -5.0, 5.0);
        let p_b = [0.31, -0.17];
        forward_kinematics_acc(&model, &mut data, &q, &v, &a).unwrap();
        let mut jac = DMatrix::zeros(2, n);
        let mut fjac = DMatrix::zeros(3, n);
        let h = 1e-6;
        let step = |s: f64, x: &[f64], d: &[f64]| -> Vec<f64> {
            x.iter().zip(d).map(|(x, d)| x + s * d).collect()
        };
        for body in model.moving_bodies() {
            forward_kinematics_acc(&model, &mut data, &q, &v, &a).unwrap();
            let vel = point_velocity(&data, body, p_b);
            let acc = point_acceleration(&data, body, p_b);
            let w = data.body_velocity(body).w;
            point_jacobian(&model, &data, body, p_b, &mut jac).unwrap();
            frame_jacobian(&model, &data, body, p_b, &mut fjac).unwrap();
            let jv = &jac * DVector::from_column_slice(&v);
            let fv = &fjac * DVector::from_column_slice(&v);
            assert!(
                (jv[0] - vel[0]).abs() < 1e-12 && (jv[1] - vel[1]).abs() < 1e-12,
                "{name}"
            );
            assert!(
                (fv[0] - w).abs() < 1e-12 && (fv[1] - vel[0]).abs() < 1e-12,
                "{name}"
            );
            // Velocity: d/dt p(q + v t).
            update_poses(&model, &mut data, &step(h, &q, &v)).unwrap();
            let pp = point_position(&data, body, p_b);
            update_poses(&model, &mut data, &step(-h, &q, &v)).unwrap();
            let pm = point_position(&data, body, p_b);
            for k in 0..2 {
                let fd = (pp[k] - pm[k]) / (2.0 * h);
                assert!(
                    (fd - vel[k]).abs() < 1e-7,
                    "{name}: velocity {fd} vs {}",
                    vel[k]
                );
            }
            // Acceleration: d/dt ṗ(q + v t + ½ a t², v + a t).
            let vel_at = |s: f64, data: &mut Data| {
                let qs: Vec<f64> = (0..n)
                    .map(|i| q[i] + s * v[i] + 0.5 * s * s * a[i])
                    .collect();
                let vs = step(s, &v, &a);
                forward_kinematics(&model, data, &qs, &vs).unwrap();
                point_velocity(data, body, p_b)
            };
            let (vp, vm) = (vel_at(h, &mut data), vel_at(-h, &mut data));
            for k in 0..2 {
                let fd = (vp[k] - vm[k]) / (2.0 * h);
                assert!(
                    (fd - acc[k]).abs() < 1e-6,
                    "{name}: acceleration {fd} vs {}",
                    acc[k]
                );
            }
        }
    }
}

#[test]
fn results_are_bit_identical_on_repeated_calls() {
    let model = branching_tree();
    let n = model.nv();
    let q = pseudo_random(16, n, -PI, PI);
    let v = pseudo_random(17, n, -2.0, 2.0);
    let tau = pseudo_random(18, n, -5.0, 5.0);
    let mut d1 = Data::new(&model);
    let mut d2 = Data::new(&model);
    let first = aba(&model, &mut d1, &q, &v, &tau).unwrap().clone();
    for _ in 0..3 {
        // Interleave another evaluation so stale workspace contents would show.
        rnea(&model, &mut d2, &v, &q, &tau).unwrap();
        let again = aba(&model, &mut d2, &q, &v, &tau).unwrap();
        assert_eq!(
            first.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            again.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
    }
}

#[test]
fn bad_inputs_give_named_errors() {
    let model = planar_chain(3);
    let mut data = Data::new(&model);
    let e = rnea(&model, &mut data, &[0.0; 2], &[0.0; 3], &[0.0; 3]).unwrap_err();
    assert!(e.to_string().contains("q: expected length 3, got 2"), "{e}");
    let e = aba(
        &model,
        &mut data,
        &[0.0; 3],
        &[0.0, f64::NAN, 0.0],
        &[0.0; 3],
    )
    .unwrap_err();
    assert!(e.to_string().contains("v[1] is not finite"), "{e}");
    let e = crba(&model, &mut data, &[f64::INFINITY, 0.0, 0.0]).unwrap_err();
    assert!(e.to_string().contains("q[0]"), "{e}");
    let mut jac = DMatrix::zeros(2, 2);
    update_poses(&model, &mut data, &[0.0; 3]).unwrap();
    let body = model.body_id("link2").unwrap();
    assert!(point_jacobian(&model, &data, body, [0.0, 0.0], &mut jac).is_err());
}

#[test]
fn external_forces_enter_as_minus_jacobian_transpose() {
    // RNEA with a world force F at a body point equals RNEA without it minus Jᵀ F; ABA with
    // it undoes that.
    for (name, model) in models() {
        let n = model.nv();
        let mut data = Data::new(&model);
        let q = pseudo_random(21, n, -PI, PI);
        let v = pseudo_random(22, n, -2.0, 2.0);
        let a = pseudo_random(23, n, -5.0, 5.0);
        let body = model.moving_bodies().nth(n / 2).unwrap();
        let (p_b, f_w) = ([0.2, -0.1], [3.0, -1.5]);
        update_poses(&model, &mut data, &q).unwrap();
        let p_w = point_position(&data, body, p_b);
        let mut fext = vec![mbs_core::Force::ZERO; model.nbodies()];
        fext[body.index()] = data.body_force_from_world(body, p_w, f_w);
        let mut jac = DMatrix::zeros(2, n);
        point_jacobian(&model, &data, body, p_b, &mut jac).unwrap();
        let jt_f = jac.transpose() * DVector::from_column_slice(&f_w);
        let plain = rnea(&model, &mut data, &q, &v, &a).unwrap().clone();
        let with = mbs_core::rnea_with_forces(&model, &mut data, &q, &v, &a, &fext)
            .unwrap()
            .clone();
        let d = max_abs_diff(with.as_slice(), (plain - &jt_f).as_slice());
        assert!(d < 1e-12, "{name}: {d:e}");
        let qdd =
            mbs_core::aba_with_forces(&model, &mut data, &q, &v, with.as_slice(), &fext).unwrap();
        assert!(max_abs_diff(qdd.as_slice(), &a) < 1e-12, "{name}");
    }
}
