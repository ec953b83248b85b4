//! Forward kinematics: body poses, velocities and accelerations, and the position, velocity
//! and acceleration of body-fixed points.

use crate::data::{Data, parent_entry};
use crate::error::{Result, check_input};
use crate::model::{BodyId, BodyModel, JointType, Model};
use crate::spatial::{Motion, Transform};
use crate::trig::sin_cos_lanes;

/// Joint angles whose sines and cosines are computed together in [`joint_transforms`]: four
/// doubles fill two SSE2 registers or one AVX register. (Eight, one pass for the 5-link
/// chain, measured slower: 115 → 124 ns for its CRBA, 137 ns with `target-cpu=native`.)
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
    joint_transforms(model, data, q);
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
/// (inputs already checked): the first step of every algorithm.
///
/// Two passes rather than one: the first computes the joint transforms, with the sines and
/// cosines of [`TRIG_LANES`] joint angles at a time ([`sin_cos_lanes`], vectorized) and the
/// remaining few one by one; the second composes the poses down the tree.
pub(crate) fn joint_transforms(model: &Model, data: &mut Data, q: &[f64]) {
    let bodies = model.bodies.as_slice();
    let nb = bodies.len();
    // Per-body arrays cut to the body count: indexing by the loop counter needs no check.
    let x_up = &mut data.x_up[..nb];
    let x_world = &mut data.x_world[..nb];
    let (moving, x_up_moving) = (&bodies[1..], &mut x_up[1..]);
    let full = moving.len() / TRIG_LANES * TRIG_LANES;
    for (chunk, x_up) in moving[..full]
        .chunks_exact(TRIG_LANES)
        .zip(x_up_moving[..full].chunks_exact_mut(TRIG_LANES))
    {
        set_joint_transforms::<TRIG_LANES>(chunk, x_up, q);
    }
    // The last few bodies one at a time (same arithmetic, same results, no padded lanes).
    for (b, x_up) in moving[full..].iter().zip(&mut x_up_moving[full..]) {
        set_joint_transforms::<1>(std::slice::from_ref(b), std::slice::from_mut(x_up), q);
    }
    x_world[0] = Transform::IDENTITY;
    let mut xw_prev = Transform::IDENTITY;
    for i in 1..nb {
        let xw = parent_entry(x_world, xw_prev, i, bodies[i].parent).compose(&x_up[i]);
        x_world[i] = xw;
        xw_prev = xw;
    }
}

/// The joint transforms of `N` bodies (`x_up` of the same length), with the sines and
/// cosines of their joint angles computed together.
#[inline(always)]
fn set_joint_transforms<const N: usize>(bodies: &[BodyModel], x_up: &mut [Transform], q: &[f64]) {
    // θ = θ_tree + q for revolute joints; prismatic lanes get 0 and are not used.
    let mut theta = [0.0; N];
    for (theta, b) in theta.iter_mut().zip(bodies) {
        if b.joint == JointType::Revolute {
            *theta = b.theta_tree + q[b.idx_v];
        }
    }
    let (sin, cos) = sin_cos_lanes(&theta);
    for (j, (x, b)) in x_up.iter_mut().zip(bodies).enumerate() {
        *x = match b.joint {
            JointType::Revolute => Transform {
                c: cos[j],
                s: sin[j],
                x: b.x_tree.x,
                y: b.x_tree.y,
            },
            JointType::Prismatic { .. } => b.joint_transform(q[b.idx_v]),
        };
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
