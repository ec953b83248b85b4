//! [`Data`]: the preallocated workspace of the algorithms.

use nalgebra::{DMatrix, DVector};

use crate::model::{BodyId, Model};
use crate::spatial::{ArticulatedInertia, Force, Inertia, Motion, Transform};

/// The mutable workspace of the algorithms for one [`Model`]: every buffer is allocated here
/// once, so evaluating the dynamics allocates nothing. Per-body arrays are indexed by
/// [`BodyId::index`] (0 = ground); joint-space vectors by coordinate.
///
/// Results stay in the workspace after a call (`data.tau()`, `data.qdd()`,
/// `data.mass_matrix()`, body poses and velocities) until the next call overwrites them.
#[derive(Clone, Debug)]
pub struct Data {
    /// Pose of each body's joint frame in its parent's joint frame.
    pub(crate) x_up: Vec<Transform>,
    /// Sine of each revolute joint's angle, by coordinate, from the last CRBA (the slots of
    /// prismatic coordinates are not used).
    pub(crate) sin_q: Vec<f64>,
    /// Cosine of each revolute joint's angle, by coordinate (see `sin_q`).
    pub(crate) cos_q: Vec<f64>,
    /// Pose of each body's joint frame in the world.
    pub(crate) x_world: Vec<Transform>,
    /// Spatial velocity of each body, in its own frame.
    pub(crate) v: Vec<Motion>,
    /// Spatial acceleration of each body, in its own frame.
    pub(crate) a: Vec<Motion>,
    /// Net spatial force transmitted by each joint (RNEA), in the body frame.
    pub(crate) f: Vec<Force>,
    /// Composite rigid-body inertias being summed (CRBA), for the bodies with children other
    /// than the next body (the others' sums ride in registers).
    pub(crate) ic: Vec<Inertia>,
    /// The forces `F_j = IC_j S_j` of the mass matrix's columns (CRBA), by the position of
    /// body `j` in the model's depth-first preorder, each in the frame of the body the
    /// backward pass is at.
    pub(crate) column_force: Vec<Force>,
    /// Articulated-body inertias (ABA).
    pub(crate) ia: Vec<ArticulatedInertia>,
    /// Articulated bias forces (ABA).
    pub(crate) pa: Vec<Force>,
    /// Velocity-product accelerations `v ×ₘ S q̇` (ABA).
    pub(crate) c: Vec<Motion>,
    /// `U = IA S` per body (ABA).
    pub(crate) u_col: Vec<Force>,
    /// `1 / (Sᵀ U)` per body (ABA).
    pub(crate) d_inv: Vec<f64>,
    /// `u = τ − Sᵀ pA` per body (ABA).
    pub(crate) u: Vec<f64>,
    pub(crate) tau: DVector<f64>,
    pub(crate) qdd: DVector<f64>,
    pub(crate) nle: DVector<f64>,
    pub(crate) gravity: DVector<f64>,
    pub(crate) mass_matrix: DMatrix<f64>,
    /// The [`crate::layout::Layout::id`] of the model whose zero pattern `mass_matrix` holds:
    /// the entries between bodies on different branches, which the CRBA never writes, are
    /// zero. Another model's CRBA zeroes the matrix first.
    pub(crate) mass_matrix_zeros_for: u64,
    /// Tree-sparse LᵀL factor of the mass matrix, in body order.
    pub(crate) factor: Vec<f64>,
    /// Right-hand side / solution in body order.
    pub(crate) rhs: Vec<f64>,
}

impl Data {
    /// A workspace sized for `model`.
    pub fn new(model: &Model) -> Self {
        let nb = model.nbodies();
        let nv = model.nv();
        Self {
            x_up: vec![Transform::IDENTITY; nb],
            sin_q: vec![0.0; nv],
            cos_q: vec![1.0; nv],
            x_world: vec![Transform::IDENTITY; nb],
            v: vec![Motion::ZERO; nb],
            a: vec![Motion::ZERO; nb],
            f: vec![Force::ZERO; nb],
            ic: vec![Inertia::ZERO; nb],
            column_force: vec![Force::ZERO; nv],
            ia: vec![ArticulatedInertia::default(); nb],
            pa: vec![Force::ZERO; nb],
            c: vec![Motion::ZERO; nb],
            u_col: vec![Force::ZERO; nb],
            d_inv: vec![0.0; nb],
            u: vec![0.0; nb],
            tau: DVector::zeros(nv),
            qdd: DVector::zeros(nv),
            nle: DVector::zeros(nv),
            gravity: DVector::zeros(nv),
            mass_matrix: DMatrix::zeros(nv, nv),
            mass_matrix_zeros_for: model.layout.id,
            factor: vec![0.0; nv * nv],
            rhs: vec![0.0; nv],
        }
    }

    /// Checks that this workspace was made for a model of `model`'s size.
    pub(crate) fn check(&self, model: &Model) -> crate::Result<()> {
        if self.x_up.len() != model.nbodies() || self.tau.len() != model.nv() {
            return Err(crate::CoreError::WorkspaceMismatch {
                expected: model.nbodies(),
                got: self.x_up.len(),
            });
        }
        Ok(())
    }

    /// Generalized forces from the last [`crate::rnea`] (or the driving forces and given
    /// forces of [`crate::hybrid_dynamics`]).
    pub fn tau(&self) -> &DVector<f64> {
        &self.tau
    }

    /// Generalized accelerations from the last forward-dynamics call.
    pub fn qdd(&self) -> &DVector<f64> {
        &self.qdd
    }

    /// Joint-space mass matrix from the last [`crate::crba`] (full, symmetric).
    pub fn mass_matrix(&self) -> &DMatrix<f64> {
        &self.mass_matrix
    }

    /// Nonlinear effects `C(q, v) v + g(q)` from the last [`crate::nonlinear_effects`].
    pub fn nonlinear_effects(&self) -> &DVector<f64> {
        &self.nle
    }

    /// Gravity generalized forces `g(q)` from the last [`crate::gravity_torque`].
    pub fn gravity_torque(&self) -> &DVector<f64> {
        &self.gravity
    }

    /// World pose of a body's joint frame, for the configuration of the last call of any
    /// algorithm (kinematics, dynamics or energy) but [`crate::crba`], which needs only the
    /// joint transforms and leaves the poses as they were.
    pub fn body_pose(&self, body: BodyId) -> Transform {
        self.x_world[body.0]
    }

    /// Spatial velocity of a body in its own frame (after a kinematics or dynamics call).
    pub fn body_velocity(&self, body: BodyId) -> Motion {
        self.v[body.0]
    }

    /// Spatial acceleration of a body in its own frame, gravity excluded, from the last call
    /// that computes accelerations ([`crate::forward_kinematics_acc`], [`crate::rnea`],
    /// [`crate::aba`], [`crate::hybrid_dynamics`], `System::derivative`).
    ///
    /// The dynamics algorithms run with the base accelerating at −g (Featherstone's way of
    /// applying gravity), stored in `a[0]`; it is removed here.
    pub fn body_acceleration(&self, body: BodyId) -> Motion {
        let a0 = self.a[0];
        let g_b = self.x_world[body.0].rotate_inv([a0.vx, a0.vy]);
        let a = self.a[body.0];
        Motion::new(a.w, a.vx - g_b[0], a.vy - g_b[1])
    }

    /// The spatial force on `body`, in its frame (the form `f_ext` of [`crate::rnea_with_forces`]
    /// and [`crate::aba_with_forces`] takes), of a force `f_w` applied at the world point
    /// `p_w`, both in world coordinates. Uses the body's current pose.
    pub fn body_force_from_world(&self, body: BodyId, p_w: [f64; 2], f_w: [f64; 2]) -> Force {
        self.x_world[body.0].apply_force(&Force::at_point(p_w, f_w))
    }

    /// The spatial force each joint transmits from the parent to the body (the body
    /// frame's origin, body coordinates), from the last [`crate::rnea`]: joint reaction
    /// plus actuation. Its component along the joint's axis is the generalized force.
    pub fn joint_force(&self, body: BodyId) -> Force {
        self.f[body.0]
    }
}

/// The entry of body `i`'s parent `p` in a per-body array being filled in body order, with
/// `prev` the entry just computed for body `i − 1`. When the parent is the previous body
/// (always, along a chain) the value comes from `prev`, still in registers, rather than
/// from the store just made: a forward recursion then does not wait on memory at each body.
#[inline(always)]
pub(crate) fn parent_entry<T: Copy>(entries: &[T], prev: T, i: usize, p: usize) -> T {
    if p + 1 == i { prev } else { entries[p] }
}

/// Hands body `i`'s contribution `c` to its parent `p` in a backward (leaves-first) pass.
/// When the parent is the next body processed (`p = i − 1`, always along a chain), `c` is
/// returned to be added there from registers; otherwise it is added to `entries[p]` and zero
/// is returned. The caller adds what this returns to the next body's entry: each parent then
/// receives its children's contributions in the same order as with plain `entries[p] += c`,
/// so the sums are identical bit for bit.
#[inline(always)]
pub(crate) fn add_to_parent<T: Copy + Default + std::ops::AddAssign>(
    entries: &mut [T],
    c: T,
    i: usize,
    p: usize,
) -> T {
    if p + 1 == i {
        c
    } else {
        entries[p] += c;
        T::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parent_entry_reads_the_previous_body_from_registers_only_for_it() {
        let entries = [10.0, 11.0, 12.0];
        // Body 3's parent is body 2, just computed: `prev` is used, not the stale store.
        assert_eq!(parent_entry(&entries, 99.0, 3, 2), 99.0);
        assert_eq!(parent_entry(&entries, 99.0, 3, 1), 11.0);
    }

    #[test]
    fn add_to_parent_sums_in_the_order_of_plain_accumulation() {
        // Parent 1 with children 2, 3, 4 (processed 4, 3, 2); values chosen so that the
        // order of the additions shows in the last bit.
        let own: f64 = 1.0;
        let c: [f64; 5] = [0.0, 0.0, 1e-16, 3e-16, 1.0];
        let mut plain = [0.0, own, 0.0, 0.0, 0.0];
        for i in (2..=4).rev() {
            plain[1] += c[i];
        }
        let mut entries = [0.0, own, 0.0, 0.0, 0.0];
        let mut carry: f64 = 0.0;
        for i in (2..=4).rev() {
            entries[i] += carry;
            carry = add_to_parent(&mut entries, c[i], i, 1);
        }
        entries[1] += carry;
        assert_eq!(entries[1].to_bits(), plain[1].to_bits());
    }
}
