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
    fill(model, data, body, p_b, out, true)
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
    fill(model, data, body, p_b, out, false)
}

/// Writes the Jacobian columns of the joints supporting `body`, with the angular row first
/// when `angular` is set.
fn fill(
    model: &Model,
    data: &Data,
    body: BodyId,
    p_b: [f64; 2],
    out: &mut DMatrix<f64>,
    angular: bool,
) -> Result<()> {
    let rows = if angular { 3 } else { 2 };
    data.check(model)?;
    check_shape(model, out, rows)?;
    out.fill(0.0);
    let p = data.x_world[body.0].transform_point(p_b);
    let r0 = rows - 2;
    for j in model.support(body) {
        let (w, lin) = column(model, data, j, p);
        let k = model.bodies[j.0].idx_v;
        if angular {
            out[(0, k)] = w;
        }
        out[(r0, k)] = lin[0];
        out[(r0 + 1, k)] = lin[1];
    }
    Ok(())
}

/// Angular and linear (at world point `p`) velocity per unit rate of body `j`'s joint.
#[inline]
pub(crate) fn column(model: &Model, data: &Data, j: BodyId, p: [f64; 2]) -> (f64, [f64; 2]) {
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
        return Err(CoreError::ShapeMismatch {
            what: "jacobian",
            expected: (rows, model.nv()),
            got: (out.nrows(), out.ncols()),
        });
    }
    Ok(())
}
