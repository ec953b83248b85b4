//! Jacobians of body-fixed points.

use nalgebra::DMatrix;

use crate::data::Data;
use crate::error::{CoreError, Result};
use crate::model::{BodyId, JointType, Model};

/// The 3 × nv Jacobian of a body-fixed point, in world coordinates: row 0 maps q̇ to the
/// body's angular velocity, rows 1–2 to the world velocity of the point `p_b` (given in the
/// body's joint frame). Written into `out`, which must be 3 × nv. Needs poses from
/// [`crate::update_poses`] or [`crate::forward_kinematics`].
pub fn frame_jacobian(
    model: &Model,
    data: &Data,
    body: BodyId,
    p_b: [f64; 2],
    out: &mut DMatrix<f64>,
) -> Result<()> {
    check_shape(model, out, 3)?;
    out.fill(0.0);
    let p = data.x_world[body.0].transform_point(p_b);
    for j in model.support(body) {
        let (w, lin) = column(model, data, j, p);
        let k = model.bodies[j.0].idx_v;
        out[(0, k)] = w;
        out[(1, k)] = lin[0];
        out[(2, k)] = lin[1];
    }
    Ok(())
}

/// The 2 × nv Jacobian of the world velocity of the point `p_b` fixed to `body` (given in
/// the body's joint frame): `ṗ = J q̇`. Written into `out`, which must be 2 × nv. Needs
/// poses from [`crate::update_poses`] or [`crate::forward_kinematics`].
pub fn point_jacobian(
    model: &Model,
    data: &Data,
    body: BodyId,
    p_b: [f64; 2],
    out: &mut DMatrix<f64>,
) -> Result<()> {
    check_shape(model, out, 2)?;
    out.fill(0.0);
    let p = data.x_world[body.0].transform_point(p_b);
    for j in model.support(body) {
        let (_, lin) = column(model, data, j, p);
        let k = model.bodies[j.0].idx_v;
        out[(0, k)] = lin[0];
        out[(1, k)] = lin[1];
    }
    Ok(())
}

/// Angular and linear (at world point `p`) velocity per unit rate of body `j`'s joint.
#[inline]
fn column(model: &Model, data: &Data, j: BodyId, p: [f64; 2]) -> (f64, [f64; 2]) {
    let x = &data.x_world[j.0];
    match model.bodies[j.0].joint {
        // ω = 1 about the joint origin o: ṗ = ẑ × (p − o)
        JointType::Revolute => (1.0, [-(p[1] - x.y), p[0] - x.x]),
        // ṗ = R_wj axis
        JointType::Prismatic { axis } => (0.0, x.rotate(axis)),
    }
}

fn check_shape(model: &Model, out: &DMatrix<f64>, rows: usize) -> Result<()> {
    if out.nrows() != rows || out.ncols() != model.nv() {
        return Err(CoreError::DimensionMismatch {
            what: "jacobian (rows × cols)",
            expected: rows * model.nv(),
            got: out.nrows() * out.ncols(),
        });
    }
    Ok(())
}
