//! Kinetic and potential energy.

use crate::data::Data;
use crate::error::Result;
use crate::kinematics::forward_kinematics;
use crate::model::Model;

/// Kinetic energy `½ Σ vᵢ · Iᵢ vᵢ = ½ q̇ᵀ M q̇` (J). Runs forward kinematics.
pub fn kinetic_energy(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> Result<f64> {
    forward_kinematics(model, data, q, v)?;
    Ok(kinetic_energy_from_kinematics(model, data))
}

/// Kinetic energy from the velocities of the last kinematics call.
pub(crate) fn kinetic_energy_from_kinematics(model: &Model, data: &Data) -> f64 {
    let mut t = 0.0;
    for i in 1..model.bodies.len() {
        let vi = &data.v[i];
        t += vi.dot(&model.bodies[i].inertia.mul_motion(vi));
    }
    0.5 * t
}

/// Gravitational potential energy `−Σ mᵢ g · cᵢ` (J), zero with every centre of mass at the
/// world origin. Runs [`crate::update_poses`].
pub fn potential_energy(model: &Model, data: &mut Data, q: &[f64]) -> Result<f64> {
    crate::kinematics::update_poses(model, data, q)?;
    Ok(potential_energy_from_poses(model, data))
}

/// Potential energy from the poses of the last kinematics call.
pub(crate) fn potential_energy_from_poses(model: &Model, data: &Data) -> f64 {
    let g = model.gravity;
    let mut u = 0.0;
    for i in 1..model.bodies.len() {
        let inertia = &model.bodies[i].inertia;
        let c = data.x_world[i].transform_point(inertia.com());
        u -= inertia.m * (g[0] * c[0] + g[1] * c[1]);
    }
    u
}

/// Kinetic plus gravitational potential energy (J).
pub fn mechanical_energy(model: &Model, data: &mut Data, q: &[f64], v: &[f64]) -> Result<f64> {
    forward_kinematics(model, data, q, v)?;
    Ok(kinetic_energy_from_kinematics(model, data) + potential_energy_from_poses(model, data))
}
