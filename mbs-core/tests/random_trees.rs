//! Property tests on random planar trees (forests on the ground) of 1 to 12 links with
//! revolute, prismatic and fixed joints: the mass matrix, inverse, forward and hybrid
//! dynamics, energies and point Jacobians must agree with one another, and poses, energies
//! and velocities with an independent recursion over the declared links (which checks how
//! fixed joints are merged) and with finite differences.

use mbs_core::{
    BodyId, BodySpec, Data, JointKind, Model, ModelBuilder, Placement, Prescribed, Transform, aba,
    crba, forward_dynamics_crba, forward_kinematics, frame_pose, gravity_torque, hybrid_dynamics,
    kinetic_energy, nonlinear_effects, point_jacobian, point_position, point_velocity,
    potential_energy, rnea, update_poses,
};
use nalgebra::{Cholesky, DMatrix, DVector};
use proptest::prelude::*;
use std::f64::consts::PI;

/// Largest number of links (and so of coordinates).
const MAX_LINKS: usize = 12;

/// One random link, before it is tied to the tree.
#[derive(Clone, Debug)]
struct LinkParams {
    /// Picks the parent: `None` (the ground) or one of the earlier links.
    parent_pick: usize,
    /// 0 revolute, 1 prismatic, 2 fixed.
    kind: u8,
    /// Prismatic axis as polar angle and length (length in [0.2, 2], so never zero).
    axis_angle: f64,
    axis_len: f64,
    placement: (f64, f64, f64),
    mass: f64,
    com: [f64; 2],
    inertia: f64,
}

fn link_params() -> impl Strategy<Value = LinkParams> {
    (
        any::<usize>(),
        0u8..3,
        -PI..PI,
        0.2..2.0f64,
        (-PI..=PI, -1.0..=1.0f64, -1.0..=1.0f64),
        0.1..=5.0f64,
        [-0.5..=0.5f64, -0.5..=0.5f64],
        0.01..=1.0f64,
    )
        .prop_map(
            |(parent_pick, kind, axis_angle, axis_len, placement, mass, com, inertia)| LinkParams {
                parent_pick,
                kind,
                axis_angle,
                axis_len,
                placement,
                mass,
                com,
                inertia,
            },
        )
}

/// A random model (its links) and random inputs; vectors are cut to the model's nv.
#[derive(Clone, Debug)]
struct Case {
    links: Vec<LinkParams>,
    gravity: [f64; 2],
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
    mask: Vec<bool>,
    body_pick: usize,
    point: [f64; 2],
}

fn case() -> impl Strategy<Value = Case> {
    let vec12 = |r: f64| prop::collection::vec(-r..=r, MAX_LINKS);
    (
        prop::collection::vec(link_params(), 1..=MAX_LINKS),
        [-10.0..=10.0f64, -10.0..=10.0f64],
        vec12(PI),
        vec12(3.0),
        vec12(5.0),
        vec12(20.0),
        prop::collection::vec(any::<bool>(), MAX_LINKS),
        any::<usize>(),
        [-1.0..=1.0f64, -1.0..=1.0f64],
    )
        .prop_map(
            |(links, gravity, q, v, a, tau, mask, body_pick, point)| Case {
                links,
                gravity,
                q,
                v,
                a,
                tau,
                mask,
                body_pick,
                point,
            },
        )
}

fn link_name(i: usize) -> String {
    format!("link{i}")
}

/// Builds the model: link `i` hangs from the ground or from an earlier link; if every
/// joint came out fixed, the first one is made revolute.
fn build(c: &Case) -> Model {
    let mut b = ModelBuilder::new();
    b.gravity(c.gravity);
    for (i, l) in c.links.iter().enumerate() {
        let parent = parent_of(c, i).map(link_name);
        let (angle, x, y) = l.placement;
        b.add_link(
            &link_name(i),
            parent.as_deref(),
            kind_of(c, i),
            Placement::new(angle, x, y),
            BodySpec::new(l.mass, l.com, l.inertia),
        );
    }
    b.build().expect("a valid random tree")
}

/// The joint kind link `i` was given by [`build`].
fn kind_of(c: &Case, i: usize) -> JointKind {
    let l = &c.links[i];
    match l.kind {
        _ if i == 0 && c.links.iter().all(|l| l.kind == 2) => JointKind::Revolute,
        0 => JointKind::Revolute,
        1 => JointKind::Prismatic {
            axis: [
                l.axis_len * l.axis_angle.cos(),
                l.axis_len * l.axis_angle.sin(),
            ],
        },
        _ => JointKind::Fixed,
    }
}

/// Parent link of link `i` as chosen by [`build`] (`None` for the ground).
fn parent_of(c: &Case, i: usize) -> Option<usize> {
    let pick = c.links[i].parent_pick % (i + 1);
    pick.checked_sub(1)
}

/// World pose of every link's frame, by an independent recursion over the declarations:
/// `X_w,i = X_w,parent · placement_i · joint_i(q)`.
fn hand_poses(c: &Case, model: &Model, q: &[f64]) -> Vec<Transform> {
    let mut poses: Vec<Transform> = Vec::with_capacity(c.links.len());
    for i in 0..c.links.len() {
        let parent = parent_of(c, i).map_or(Transform::IDENTITY, |p| poses[p]);
        let (angle, x, y) = c.links[i].placement;
        let placed = parent.compose(&Transform::new(angle, x, y));
        let coord = || q[model.coordinate_id(&link_name(i)).unwrap()];
        let joint = match kind_of(c, i) {
            JointKind::Revolute => Transform::new(coord(), 0.0, 0.0),
            JointKind::Prismatic { axis } => {
                let n = axis[0].hypot(axis[1]);
                Transform::new(0.0, coord() * axis[0] / n, coord() * axis[1] / n)
            }
            JointKind::Fixed => Transform::IDENTITY,
        };
        poses.push(placed.compose(&joint));
    }
    poses
}

/// Fourth-order central difference of `f` along `t` at 0.
fn derivative<const N: usize>(h: f64, f: impl Fn(f64) -> [f64; N]) -> [f64; N] {
    let (p2, p1, m1, m2) = (f(2.0 * h), f(h), f(-h), f(-2.0 * h));
    std::array::from_fn(|k| (-p2[k] + 8.0 * p1[k] - 8.0 * m1[k] + m2[k]) / (12.0 * h))
}

/// `|got − want| ≤ tol (1 + |want|)` entry by entry.
fn check_close(what: &str, got: &[f64], want: &[f64], tol: f64) -> Result<(), TestCaseError> {
    prop_assert_eq!(got.len(), want.len(), "{}: length", what);
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        prop_assert!(
            (g - w).abs() <= tol * (1.0 + w.abs()),
            "{}[{}]: got {:e}, want {:e}, diff {:e}",
            what,
            k,
            g,
            w,
            (g - w).abs()
        );
    }
    Ok(())
}

const TOL: f64 = 1e-9;

struct Setup {
    model: Model,
    data: Data,
    q: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    tau: Vec<f64>,
    mask: Vec<bool>,
}

fn setup(c: &Case) -> Setup {
    let model = build(c);
    let n = model.nv();
    Setup {
        data: Data::new(&model),
        q: c.q[..n].to_vec(),
        v: c.v[..n].to_vec(),
        a: c.a[..n].to_vec(),
        tau: c.tau[..n].to_vec(),
        mask: c.mask[..n].to_vec(),
        model,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn model_shape_matches_the_declarations(c in case()) {
        let model = build(&c);
        let moving = (0..c.links.len())
            .filter(|&i| kind_of(&c, i) != JointKind::Fixed)
            .count();
        prop_assert_eq!(model.nv(), moving);
        prop_assert_eq!(model.nbodies(), moving + 1);
        prop_assert_eq!(model.frames().len(), c.links.len());
        for b in model.moving_bodies() {
            prop_assert!(model.parent(b).unwrap() < b);
        }
        // Coordinates are numbered in declaration order.
        let names = model.coordinate_names();
        let idx: Vec<usize> = names.iter().map(|n| n[4..].parse().unwrap()).collect();
        prop_assert!(idx.windows(2).all(|w| w[0] < w[1]), "{:?}", names);
        // The moving mass is the total of the links not fixed (directly or not) to the ground.
        prop_assert!(model.total_mass() <= c.links.iter().map(|l| l.mass).sum::<f64>() + 1e-12);
    }

    #[test]
    fn mass_matrix_is_symmetric_positive_definite(c in case()) {
        let Setup { model, mut data, q, .. } = setup(&c);
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let n = model.nv();
        for i in 0..n {
            for j in 0..i {
                prop_assert!(
                    (m[(i, j)] - m[(j, i)]).abs() <= TOL * (1.0 + m[(j, i)].abs()),
                    "M[{},{}] = {} vs M[{},{}] = {}", i, j, m[(i, j)], j, i, m[(j, i)]
                );
            }
        }
        prop_assert!(Cholesky::new(m.clone()).is_some(), "Cholesky failed: {}", m);
        let eig = m.clone().symmetric_eigen();
        let min = eig.eigenvalues.min();
        prop_assert!(min > 0.0, "min eigenvalue {} of {}", min, m);
        // data keeps the result.
        prop_assert_eq!(data.mass_matrix(), &m);
    }

    #[test]
    fn crba_columns_are_unit_acceleration_rnea(c in case()) {
        let Setup { model, mut data, q, .. } = setup(&c);
        let n = model.nv();
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let zero = vec![0.0; n];
        let g = rnea(&model, &mut data, &q, &zero, &zero).unwrap().clone();
        let g2 = gravity_torque(&model, &mut data, &q).unwrap().clone();
        check_close("gravity_torque", g2.as_slice(), g.as_slice(), TOL)?;
        for k in 0..n {
            let mut e = zero.clone();
            e[k] = 1.0;
            let col = rnea(&model, &mut data, &q, &zero, &e).unwrap() - &g;
            let want: Vec<f64> = m.column(k).iter().copied().collect();
            check_close(&format!("M column {k}"), col.as_slice(), &want, TOL)?;
        }
    }

    #[test]
    fn aba_inverts_rnea(c in case()) {
        let Setup { model, mut data, q, v, a, .. } = setup(&c);
        let tau = rnea(&model, &mut data, &q, &v, &a).unwrap().clone();
        let qdd = aba(&model, &mut data, &q, &v, tau.as_slice()).unwrap().clone();
        check_close("aba(rnea(a))", qdd.as_slice(), &a, TOL)?;
        prop_assert_eq!(data.qdd(), &qdd);
    }

    #[test]
    fn aba_equals_crba_forward_dynamics(c in case()) {
        let Setup { model, mut data, q, v, tau, .. } = setup(&c);
        let qdd_aba = aba(&model, &mut data, &q, &v, &tau).unwrap().clone();
        let qdd_crba = forward_dynamics_crba(&model, &mut data, &q, &v, &tau, None)
            .unwrap()
            .clone();
        check_close("crba qdd", qdd_crba.as_slice(), qdd_aba.as_slice(), TOL)?;
        // And both solve M qdd = tau - nle.
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let nle = nonlinear_effects(&model, &mut data, &q, &v).unwrap().clone();
        let residual = &m * &qdd_aba + &nle;
        check_close("M qdd + nle", residual.as_slice(), &tau, TOL)?;
    }

    #[test]
    fn kinetic_energy_is_half_vt_m_v(c in case()) {
        let Setup { model, mut data, q, v, .. } = setup(&c);
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let vv = DVector::from_column_slice(&v);
        let want = 0.5 * vv.dot(&(&m * &vv));
        let got = kinetic_energy(&model, &mut data, &q, &v).unwrap();
        check_close("kinetic energy", &[got], &[want], TOL)?;
        prop_assert!(got >= 0.0);
    }

    #[test]
    fn rnea_is_m_a_plus_nonlinear_effects(c in case()) {
        let Setup { model, mut data, q, v, a, .. } = setup(&c);
        let tau = rnea(&model, &mut data, &q, &v, &a).unwrap().clone();
        let m = crba(&model, &mut data, &q).unwrap().clone();
        let nle = nonlinear_effects(&model, &mut data, &q, &v).unwrap().clone();
        let want = &m * DVector::from_column_slice(&a) + &nle;
        check_close("rnea", tau.as_slice(), want.as_slice(), TOL)?;
        prop_assert_eq!(data.nonlinear_effects(), &nle);
    }

    #[test]
    fn hybrid_dynamics_meets_prescription_and_rnea(c in case()) {
        let Setup { model, mut data, q, v, a, tau, mask } = setup(&c);
        // Prescribed entries of tau and free entries of qdd are ignored: poison them.
        let tau_in: Vec<f64> = tau.iter().zip(&mask)
            .map(|(&t, &m)| if m { f64::NAN } else { t })
            .collect();
        let qdd_in: Vec<f64> = a.iter().zip(&mask)
            .map(|(&x, &m)| if m { x } else { f64::NAN })
            .collect();
        hybrid_dynamics(
            &model,
            &mut data,
            &q,
            &v,
            &tau_in,
            Prescribed { mask: &mask, qdd: &qdd_in },
            None,
        )
        .unwrap();
        let qdd = data.qdd().clone();
        let tau_out = data.tau().clone();
        for k in 0..model.nv() {
            if mask[k] {
                prop_assert_eq!(qdd[k], a[k], "prescribed qdd[{}]", k);
            } else {
                prop_assert_eq!(tau_out[k], tau[k], "given tau[{}]", k);
            }
            prop_assert!(qdd[k].is_finite() && tau_out[k].is_finite());
        }
        let tau_rnea = rnea(&model, &mut data, &q, &v, qdd.as_slice()).unwrap().clone();
        check_close("rnea(hybrid qdd)", tau_rnea.as_slice(), tau_out.as_slice(), TOL)?;
    }

    #[test]
    fn point_jacobian_maps_v_to_point_velocity(c in case()) {
        let Setup { model, mut data, q, v, .. } = setup(&c);
        let body = model.moving_bodies().nth(c.body_pick % model.nv()).unwrap();
        forward_kinematics(&model, &mut data, &q, &v).unwrap();
        let mut j = DMatrix::zeros(2, model.nv());
        point_jacobian(&model, &data, body, c.point, &mut j).unwrap();
        let jv = &j * DVector::from_column_slice(&v);
        let pv = point_velocity(&data, body, c.point);
        check_close("J v", jv.as_slice(), &pv, TOL)?;
        // Only the body's ancestors contribute.
        let support: Vec<BodyId> = model.support(body).collect();
        for b in model.moving_bodies() {
            if !support.contains(&b) {
                let k = model.coordinate_of(b).unwrap();
                prop_assert_eq!(j[(0, k)], 0.0);
                prop_assert_eq!(j[(1, k)], 0.0);
            }
        }
    }

    #[test]
    fn frame_poses_match_a_hand_recursion(c in case()) {
        let Setup { model, mut data, q, .. } = setup(&c);
        update_poses(&model, &mut data, &q).unwrap();
        let want = hand_poses(&c, &model, &q);
        for (i, w) in want.iter().enumerate() {
            let frame = model.frame_id(&link_name(i)).unwrap();
            let got = frame_pose(&model, &data, frame);
            check_close(
                &format!("pose of link{i}"),
                &[got.c, got.s, got.x, got.y],
                &[w.c, w.s, w.x, w.y],
                TOL,
            )?;
        }
        // A moving link's body pose is its frame pose.
        for b in model.moving_bodies() {
            let i: usize = model.body_name(b).unwrap()[4..].parse().unwrap();
            let got = data.body_pose(b);
            let w = want[i];
            check_close("body pose", &[got.c, got.s, got.x, got.y], &[w.c, w.s, w.x, w.y], TOL)?;
        }
    }

    #[test]
    fn point_velocity_is_the_derivative_of_point_position(c in case()) {
        let Setup { model, mut data, q, v, .. } = setup(&c);
        let body = model.moving_bodies().nth(c.body_pick % model.nv()).unwrap();
        let at = |t: f64| -> [f64; 2] {
            let qt: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q + t * v).collect();
            let mut d = Data::new(&model);
            update_poses(&model, &mut d, &qt).unwrap();
            point_position(&d, body, c.point)
        };
        let fd = derivative(1e-3, at);
        forward_kinematics(&model, &mut data, &q, &v).unwrap();
        let pv = point_velocity(&data, body, c.point);
        check_close("point velocity vs finite difference", &pv, &fd, 1e-6)?;
    }

    #[test]
    fn gravity_torque_is_the_gradient_of_potential_energy(c in case()) {
        let Setup { model, mut data, q, .. } = setup(&c);
        let g = gravity_torque(&model, &mut data, &q).unwrap().clone();
        for k in 0..model.nv() {
            let fd = derivative(1e-3, |t| {
                let mut qt = q.clone();
                qt[k] += t;
                let mut d = Data::new(&model);
                [potential_energy(&model, &mut d, &qt).unwrap()]
            });
            check_close(&format!("dU/dq[{k}]"), &[g[k]], &fd, 1e-6)?;
        }
    }

    #[test]
    fn energies_match_a_hand_sum_over_links(c in case()) {
        // Sums over the declared links, fixed ones included, with poses from the hand
        // recursion: checks that fixed joints merge mass, centre of mass and inertia.
        let Setup { model, mut data, q, v, .. } = setup(&c);
        let n = c.links.len();
        // Links welded to the ground carry no energy.
        let mut grounded = vec![false; n];
        let mut omega = vec![0.0; n];
        for i in 0..n {
            let parent = parent_of(&c, i);
            let kind = kind_of(&c, i);
            grounded[i] = kind == JointKind::Fixed && parent.is_none_or(|p| grounded[p]);
            omega[i] = parent.map_or(0.0, |p| omega[p]);
            if kind == JointKind::Revolute {
                omega[i] += v[model.coordinate_id(&link_name(i)).unwrap()];
            }
        }
        let com_world = |t: f64| -> Vec<[f64; 2]> {
            let qt: Vec<f64> = q.iter().zip(&v).map(|(q, v)| q + t * v).collect();
            let poses = hand_poses(&c, &model, &qt);
            (0..n).map(|i| poses[i].transform_point(c.links[i].com)).collect()
        };
        let g = c.gravity;
        let coms = com_world(0.0);
        let (mut mass, mut u, mut t) = (0.0, 0.0, 0.0);
        for i in (0..n).filter(|&i| !grounded[i]) {
            let l = &c.links[i];
            mass += l.mass;
            u -= l.mass * (g[0] * coms[i][0] + g[1] * coms[i][1]);
            let cdot = derivative(1e-3, |t| com_world(t)[i]);
            t += 0.5 * (l.mass * (cdot[0] * cdot[0] + cdot[1] * cdot[1]) + l.inertia * omega[i] * omega[i]);
        }
        check_close("total mass", &[model.total_mass()], &[mass], TOL)?;
        let u_got = potential_energy(&model, &mut data, &q).unwrap();
        check_close("potential energy", &[u_got], &[u], TOL)?;
        let t_got = kinetic_energy(&model, &mut data, &q, &v).unwrap();
        check_close("kinetic energy", &[t_got], &[t], 1e-6)?;
    }
}
