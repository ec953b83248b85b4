//! Forward kinematics: body poses, velocities and accelerations, and the position, velocity
//! and acceleration of body-fixed points.

use crate::data::{Data, parent_entry};
use crate::error::{Result, check_input};
use crate::layout::RevoluteJoint;
use crate::model::{BodyId, JointType, Model};
use crate::spatial::{Motion, Transform};
use crate::trig::sin_cos_lanes;

/// Joint angles whose sines and cosines are computed together in [`joint_transforms`] and
/// [`joint_sin_cos`]: four doubles fill two SSE2 registers or one AVX register. (Eight, one
/// pass for the 5-link chain, measured slower: 115 → 124 ns for its CRBA, 137 ns with
/// `target-cpu=native`; measured again with the block CRBA, still slower by 10 % on the chain
/// and 40 % on the tree with `target-cpu=native`.)
const TRIG_LANES: usize = 4;

/// Computes the world pose of every body for configuration `q`.
pub fn update_poses(model: &Model, data: &mut Data, q: &[f64]) -> Result<()> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    kinematics_pass(model, data, q, None);
    Ok(())
}

/// Computes world poses and body velocities for `(q, v)`.
pub fn forward_kinematics(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> Result<()> {
    data.check(model)?;
    check_input("q", q, model.nv())?;
    check_input("v", v, model.nv())?;
    kinematics_pass(model, data, q, Some(v));
    Ok(())
}

/// Computes world poses, body velocities and body accelerations (gravity excluded) for
/// `(q, v, a)`.
pub fn forward_kinematics_acc(
    model: &Model,
    data: &mut Data,
    q: &[f64],
    v: &[f64],
    a: &[f64],
) -> Result<()> {
    check_input("a", a, model.nv())?;
    forward_kinematics(model, data, q, v)?;
    data.a[0] = Motion::ZERO;
    for i in 1..model.bodies.len() {
        let b = &model.bodies[i];
        let iv = b.idx_v;
        let vj = b.s * v[iv];
        // a_i = X a_λ + S q̈ + v_i ×ₘ S q̇
        data.a[i] = data.x_up[i].apply_motion(&data.a[b.parent])
            + b.s * a[iv]
            + data.v[i].cross_motion(&vj);
    }
    Ok(())
}

/// Joint transforms, world poses and, when `v` is given, body velocities (inputs already
/// checked).
pub(crate) fn kinematics_pass(model: &Model, data: &mut Data, q: &[f64], v: Option<&[f64]>) {
    joint_transforms_and_poses(model, data, q);
    if let Some(v) = v {
        let bodies = model.bodies.as_slice();
        let nb = bodies.len();
        let x_up = &data.x_up[..nb];
        let vel = &mut data.v[..nb];
        vel[0] = Motion::ZERO;
        let mut v_prev = Motion::ZERO;
        for i in 1..nb {
            let b = &bodies[i];
            // v_i = X v_λ + S q̇
            let vi = b.add_s(
                x_up[i].apply_motion(&parent_entry(vel, v_prev, i, b.parent)),
                v[b.idx_v],
            );
            vel[i] = vi;
            v_prev = vi;
        }
    }
}

/// The joint transforms `data.x_up` and world poses `data.x_world` for configuration `q`
/// (inputs already checked): the first step of every algorithm but the CRBA, which needs
/// the joint transforms only ([`joint_transforms`]).
pub(crate) fn joint_transforms_and_poses(model: &Model, data: &mut Data, q: &[f64]) {
    joint_transforms(model, data, q);
    world_poses(model, data);
}

/// The joint transforms `data.x_up` for configuration `q` (inputs already checked): the
/// revolute joints [`TRIG_LANES`] at a time, their sines and cosines computed together
/// ([`sin_cos_lanes`], vectorized), the last few in one smaller group; then the prismatic
/// joints, which need no trigonometry. (The CRBA takes the sines and cosines by coordinate
/// instead, [`joint_sin_cos`], and reads them where it needs them.)
#[inline(always)]
pub(crate) fn joint_transforms(model: &Model, data: &mut Data, q: &[f64]) {
    let bodies = model.bodies.as_slice();
    let x_up = &mut data.x_up[..bodies.len()];
    let revolute = model.layout.revolute_joints.as_slice();
    let mut groups = revolute.chunks_exact(TRIG_LANES);
    for group in &mut groups {
        set_revolute_transforms::<TRIG_LANES>(group, x_up, q);
    }
    // The rest in a group of its own size (a pair fills one SSE2 register, as one angle does).
    let rest = groups.remainder();
    match rest.len() {
        0 => {}
        1 => set_revolute_transforms::<1>(rest, x_up, q),
        2 => set_revolute_transforms::<2>(rest, x_up, q),
        _ => set_revolute_transforms::<3>(rest, x_up, q),
    }
    for &i in &model.layout.prismatic_bodies {
        let b = &bodies[i];
        x_up[i] = b.joint_transform(q[b.idx_v]);
    }
}

/// The joint transforms of `N` revolute joints (`joints` of length `N`), with the sines and
/// cosines of their angles `θ = θ_tree + q` computed together.
#[inline(always)]
fn set_revolute_transforms<const N: usize>(
    joints: &[RevoluteJoint],
    x_up: &mut [Transform],
    q: &[f64],
) {
    let Ok(joints) = <&[RevoluteJoint; N]>::try_from(joints) else {
        unreachable!("a group of {N} joints")
    };
    let theta: [f64; N] = std::array::from_fn(|k| joints[k].theta_tree + q[joints[k].coordinate]);
    let (sin, cos) = sin_cos_lanes(&theta);
    for (k, j) in joints.iter().enumerate() {
        x_up[j.body] = Transform {
            c: cos[k],
            s: sin[k],
            x: j.x,
            y: j.y,
        };
    }
}

/// The joint transforms `data.x_up` from `data.sin_q`, `data.cos_q` (revolute joints) and
/// `q` (prismatic joints).
#[inline(always)]
pub(crate) fn transforms_from_sin_cos(model: &Model, data: &mut Data, q: &[f64]) {
    let bodies = model.bodies.as_slice();
    let nb = bodies.len();
    let x_up = &mut data.x_up[..nb];
    let (sin_q, cos_q) = (data.sin_q.as_slice(), data.cos_q.as_slice());
    for i in 1..nb {
        let b = &bodies[i];
        let k = b.idx_v;
        x_up[i] = match b.joint {
            JointType::Revolute => Transform {
                c: cos_q[k],
                s: sin_q[k],
                x: b.x_tree.x,
                y: b.x_tree.y,
            },
            JointType::Prismatic { .. } => b.joint_transform(q[k]),
        };
    }
}

/// The sines and cosines of the revolute joints' angles `θ = θ_tree + q` of configuration
/// `q`, by coordinate, into `data.sin_q` and `data.cos_q` (the prismatic coordinates' slots
/// are left alone): [`TRIG_LANES`] at a time ([`sin_cos_lanes`], vectorized), the few left
/// over in one smaller group. When every joint is revolute, a group is consecutive slots,
/// read and written in one go; otherwise its angles are gathered and its results scattered.
/// Groups run from the last coordinate back, so that the leaves' come first, which the
/// CRBA's backward pass needs first, and the left-over few, nearest the roots, last. Each
/// lane's result depends on its own angle only, so these are the numbers [`joint_transforms`]
/// puts in the transforms.
#[inline(always)]
pub(crate) fn joint_sin_cos(model: &Model, data: &mut Data, q: &[f64]) {
    let n = model.nv();
    let layout = &model.layout;
    let at_zero = &layout.angle_at_zero[..n];
    let (sin_q, cos_q) = (&mut data.sin_q[..n], &mut data.cos_q[..n]);
    let q = &q[..n];
    let revolute = layout.revolute_coordinates.as_slice();
    let rest = revolute.len() % TRIG_LANES;
    if revolute.len() == n {
        for k in (rest..n).step_by(TRIG_LANES).rev() {
            sin_cos_run::<TRIG_LANES>(k, at_zero, q, sin_q, cos_q);
        }
        match rest {
            0 => {}
            1 => sin_cos_run::<1>(0, at_zero, q, sin_q, cos_q),
            2 => sin_cos_run::<2>(0, at_zero, q, sin_q, cos_q),
            _ => sin_cos_run::<3>(0, at_zero, q, sin_q, cos_q),
        }
    } else {
        for group in revolute[rest..].chunks_exact(TRIG_LANES).rev() {
            sin_cos_gathered::<TRIG_LANES>(group, at_zero, q, sin_q, cos_q);
        }
        let group = &revolute[..rest];
        match rest {
            0 => {}
            1 => sin_cos_gathered::<1>(group, at_zero, q, sin_q, cos_q),
            2 => sin_cos_gathered::<2>(group, at_zero, q, sin_q, cos_q),
            _ => sin_cos_gathered::<3>(group, at_zero, q, sin_q, cos_q),
        }
    }
}

/// The sines and cosines of the `N` joint angles of the consecutive coordinates from `k` on
/// (a pair fills one SSE2 register, as one angle does).
#[inline(always)]
fn sin_cos_run<const N: usize>(
    k: usize,
    at_zero: &[f64],
    q: &[f64],
    sin_q: &mut [f64],
    cos_q: &mut [f64],
) {
    let lanes = k..k + N;
    let (at_zero, q) = (&at_zero[lanes.clone()], &q[lanes.clone()]);
    let theta: [f64; N] = std::array::from_fn(|j| at_zero[j] + q[j]);
    let (sin, cos) = sin_cos_lanes(&theta);
    sin_q[lanes.clone()].copy_from_slice(&sin);
    cos_q[lanes].copy_from_slice(&cos);
}

/// The sines and cosines of the joint angles of the `N` coordinates `group`.
#[inline(always)]
fn sin_cos_gathered<const N: usize>(
    group: &[usize],
    at_zero: &[f64],
    q: &[f64],
    sin_q: &mut [f64],
    cos_q: &mut [f64],
) {
    let Ok(group) = <&[usize; N]>::try_from(group) else {
        unreachable!("a group of {N} coordinates")
    };
    let theta: [f64; N] = std::array::from_fn(|j| at_zero[group[j]] + q[group[j]]);
    let (sin, cos) = sin_cos_lanes(&theta);
    for (j, &k) in group.iter().enumerate() {
        (sin_q[k], cos_q[k]) = (sin[j], cos[j]);
    }
}

/// The world poses `data.x_world`, composed down the tree from the joint transforms.
#[inline(always)]
pub(crate) fn world_poses(model: &Model, data: &mut Data) {
    let bodies = model.bodies.as_slice();
    let nb = bodies.len();
    let x_up = &data.x_up[..nb];
    let x_world = &mut data.x_world[..nb];
    x_world[0] = Transform::IDENTITY;
    let mut xw_prev = Transform::IDENTITY;
    for i in 1..nb {
        let xw = parent_entry(x_world, xw_prev, i, bodies[i].parent).compose(&x_up[i]);
        x_world[i] = xw;
        xw_prev = xw;
    }
}

/// World position of the point `p_b` fixed to `body` (coordinates in the body's joint frame).
/// Needs poses from [`forward_kinematics`] or [`update_poses`].
pub fn point_position(data: &Data, body: BodyId, p_b: [f64; 2]) -> [f64; 2] {
    data.x_world[body.0].transform_point(p_b)
}

/// World velocity of the point `p_b` fixed to `body`: `R (v + ω × p)`. Needs
/// [`forward_kinematics`].
pub fn point_velocity(data: &Data, body: BodyId, p_b: [f64; 2]) -> [f64; 2] {
    let v = &data.v[body.0];
    data.x_world[body.0].rotate([v.vx - v.w * p_b[1], v.vy + v.w * p_b[0]])
}

/// World (classical) acceleration of the point `p_b` fixed to `body`, gravity excluded:
/// `R (a + α × p + ω × (v + ω × p))`, with `(α, a)` the spatial acceleration. Needs
/// accelerations: [`forward_kinematics_acc`], or a dynamics call (see
/// [`Data::body_acceleration`]).
pub fn point_acceleration(data: &Data, body: BodyId, p_b: [f64; 2]) -> [f64; 2] {
    let v = &data.v[body.0];
    let a = &data.body_acceleration(body);
    let vp = [v.vx - v.w * p_b[1], v.vy + v.w * p_b[0]];
    let acc = [
        a.vx - a.w * p_b[1] - v.w * vp[1],
        a.vy + a.w * p_b[0] + v.w * vp[0],
    ];
    data.x_world[body.0].rotate(acc)
}

/// Angular velocity (rad/s) of a body. Needs [`forward_kinematics`].
pub fn angular_velocity(data: &Data, body: BodyId) -> f64 {
    data.v[body.0].w
}

/// World pose of a named frame. Needs poses.
pub fn frame_pose(model: &Model, data: &Data, frame: crate::FrameId) -> Transform {
    let f = model.frame(frame);
    data.x_world[f.body.0].compose(&f.placement)
}

/// The body carrying a named frame, and the point `p_f` (given in the frame) expressed in
/// that body's joint frame: the form every point query takes.
pub fn frame_point(model: &Model, frame: crate::FrameId, p_f: [f64; 2]) -> (BodyId, [f64; 2]) {
    let f = model.frame(frame);
    (f.body, f.placement.transform_point(p_f))
}
