//! Evaluating the dynamics allocates nothing: a counting global allocator (per thread, so
//! tests running in parallel do not disturb each other) must see zero allocations during
//! every algorithm and during `System::derivative` with every kind of force element.

use mbs_core::alloc_count::{Counting, allocations_in};

use mbs_core::benchmarks::{branching_tree, branching_tree_system, planar_chain};
use mbs_core::{
    Data, Force, Prescribed, aba, aba_with_forces, crba, forward_dynamics_crba,
    forward_kinematics_acc, frame_jacobian, gravity_torque, hybrid_dynamics, kinetic_energy,
    mechanical_energy, nonlinear_effects, point_jacobian, potential_energy, rnea, rnea_with_forces,
};
use nalgebra::DMatrix;

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn the_counter_sees_allocations() {
    // Guard against a counter that cannot fail.
    let n = allocations_in(|| {
        let v = std::hint::black_box(vec![1.0f64; 16]);
        drop(v);
    });
    assert!(n >= 1);
}

#[test]
fn algorithms_do_not_allocate() {
    for model in [planar_chain(5), branching_tree()] {
        let n = model.nv();
        let mut data = Data::new(&model);
        let q: Vec<f64> = (0..n).map(|i| 0.3 * i as f64 - 1.0).collect();
        let v: Vec<f64> = (0..n).map(|i| 0.1 * i as f64).collect();
        let a: Vec<f64> = (0..n).map(|i| 1.0 - 0.2 * i as f64).collect();
        let fext = vec![Force::new(0.1, -0.2, 0.3); model.nbodies()];
        let mask: Vec<bool> = (0..n).map(|i| i % 2 == 0).collect();
        let mut jac2 = DMatrix::zeros(2, n);
        let mut jac3 = DMatrix::zeros(3, n);
        let body = model.moving_bodies().last().unwrap();
        let count = allocations_in(|| {
            rnea(&model, &mut data, &q, &v, &a).unwrap();
            rnea_with_forces(&model, &mut data, &q, &v, &a, &fext).unwrap();
            nonlinear_effects(&model, &mut data, &q, &v).unwrap();
            gravity_torque(&model, &mut data, &q).unwrap();
            crba(&model, &mut data, &q).unwrap();
            aba(&model, &mut data, &q, &v, &a).unwrap();
            aba_with_forces(&model, &mut data, &q, &v, &a, &fext).unwrap();
            forward_dynamics_crba(&model, &mut data, &q, &v, &a, Some(&fext)).unwrap();
            hybrid_dynamics(
                &model,
                &mut data,
                &q,
                &v,
                &a,
                Prescribed {
                    mask: &mask,
                    qdd: &a,
                },
                Some(&fext),
            )
            .unwrap();
            kinetic_energy(&model, &mut data, &q, &v).unwrap();
            potential_energy(&model, &mut data, &q).unwrap();
            mechanical_energy(&model, &mut data, &q, &v).unwrap();
            forward_kinematics_acc(&model, &mut data, &q, &v, &a).unwrap();
            point_jacobian(&model, &data, body, [0.1, 0.2], &mut jac2).unwrap();
            frame_jacobian(&model, &data, body, [0.1, 0.2], &mut jac3).unwrap();
        });
        assert_eq!(count, 0, "the algorithms allocated {count} times");
    }
}

#[test]
fn system_derivative_does_not_allocate() {
    let system = branching_tree_system().unwrap();
    let model = system.model().clone();
    let mut ws = system.workspace();
    let x = system
        .initial_state(0.0, &vec![0.2; model.nv()], &vec![-0.1; model.nv()])
        .unwrap();
    let mut xdot = vec![0.0; system.state_len()];
    let mut s = vec![0.0; system.switch_len()];
    let count = allocations_in(|| {
        for k in 0..10 {
            let t = 0.03 * k as f64;
            system.derivative(&mut ws, t, &x, &mut xdot).unwrap();
            system.switching_functions(&mut ws, t, &x, &mut s).unwrap();
            system.energy(&mut ws, t, &x).unwrap();
        }
    });
    assert_eq!(count, 0, "System::derivative allocated {count} times");
    assert!(xdot.iter().all(|v| v.is_finite()));
}
