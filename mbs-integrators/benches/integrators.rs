//! Integrator benchmarks. Run with `cargo bench -p mbs-integrators`; the work counts of each
//! case (steps, evaluations) are printed once before it is timed.
//!
//! - the 5-link planar chain of `mbs-core` integrated for 1 s with DOPRI5 at 1e-8;
//! - Robertson's stiff kinetics to t = 40 with TR-BDF2 at rtol 1e-6 (and DOPRI5 for
//!   comparison);
//! - Van der Pol, ε = 1e-6, to t = 2 with TR-BDF2.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use mbs_core::System;
use mbs_core::benchmarks::planar_chain;
use mbs_integrators::problems::{Robertson, VanDerPol};
use mbs_integrators::{Method, MultibodyOde, OdeSystem, Options, solve};

fn report(
    name: &str,
    sys: &mut dyn OdeSystem,
    method: Method,
    y0: &[f64],
    t_end: f64,
    opts: &Options,
) {
    match solve(sys, method, 0.0, y0, t_end, opts) {
        Ok(sol) => eprintln!("{name}: {:?}", sol.stats),
        Err(e) => eprintln!("{name}: failed: {e}"),
    }
}

fn integrators(c: &mut Criterion) {
    let chain = System::new(planar_chain(5));
    let x0 = chain
        .initial_state(
            0.0,
            &[0.3, -0.2, 0.5, 0.1, -0.4],
            &[0.0, 1.0, -0.5, 0.2, 0.0],
        )
        .unwrap();
    let tight = Options::with_tolerances(1e-8, 1e-8);
    report(
        "planar5 DOPRI5 1 s 1e-8",
        &mut MultibodyOde::new(&chain),
        Method::DormandPrince54,
        &x0,
        1.0,
        &tight,
    );
    c.bench_function("planar5_dopri5_1s_tol1e-8", |b| {
        b.iter(|| {
            let mut ode = MultibodyOde::new(&chain);
            solve(
                &mut ode,
                Method::DormandPrince54,
                0.0,
                black_box(&x0),
                1.0,
                &tight,
            )
            .unwrap()
            .y_final[0]
        })
    });

    let stiff = Options::with_tolerances(1e-6, 1e-10);
    let y0 = Robertson::Y0;
    report(
        "robertson t=40 TR-BDF2",
        &mut Robertson::default(),
        Method::TrBdf2,
        &y0,
        40.0,
        &stiff,
    );
    report(
        "robertson t=40 DOPRI5",
        &mut Robertson::default(),
        Method::DormandPrince54,
        &y0,
        40.0,
        &stiff,
    );
    c.bench_function("robertson_trbdf2_t40", |b| {
        b.iter(|| {
            solve(
                &mut Robertson::default(),
                Method::TrBdf2,
                0.0,
                black_box(&y0),
                40.0,
                &stiff,
            )
            .unwrap()
            .y_final[0]
        })
    });
    c.bench_function("robertson_dopri5_t40", |b| {
        b.iter(|| {
            solve(
                &mut Robertson::default(),
                Method::DormandPrince54,
                0.0,
                black_box(&y0),
                40.0,
                &stiff,
            )
            .unwrap()
            .y_final[0]
        })
    });

    let vdp = Options::with_tolerances(1e-6, 1e-6);
    let mut sys = VanDerPol {
        eps: 1e-6,
        analytic_jacobian: false,
    };
    report(
        "van der Pol eps=1e-6 t=2 TR-BDF2",
        &mut sys,
        Method::TrBdf2,
        &[2.0, 0.0],
        2.0,
        &vdp,
    );
    c.bench_function("vanderpol_eps1e-6_trbdf2_t2", |b| {
        b.iter(|| {
            solve(
                &mut sys,
                Method::TrBdf2,
                0.0,
                black_box(&[2.0, 0.0]),
                2.0,
                &vdp,
            )
            .unwrap()
            .y_final[0]
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = integrators
}
criterion_main!(benches);
