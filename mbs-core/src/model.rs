//! The immutable [`Model`]: bodies in topological order, joints, placements and inertias.

use std::collections::BTreeMap;

use crate::error::{CoreError, Result};
use crate::layout::Layout;
use crate::spatial::{Force, Inertia, Motion, Transform};

/// Index of a body in a [`Model`]. Body 0 is the ground ([`BodyId::GROUND`]); moving bodies
/// are numbered from 1 in topological order (a parent always has a smaller index than its
/// children).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BodyId(pub(crate) usize);

impl BodyId {
    /// The ground (the fixed world body).
    pub const GROUND: BodyId = BodyId(0);

    /// The index of this body in per-body arrays of [`crate::Data`] and in `f_ext` slices.
    pub fn index(self) -> usize {
        self.0
    }
}

/// Index of a named frame in a [`Model`]: every body of the description has one, including
/// bodies merged into their parent by a fixed joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FrameId(pub(crate) usize);

/// The kind of a moving (one-degree-of-freedom) joint of a built model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointType {
    /// Rotation about z; the coordinate is the angle (rad).
    Revolute,
    /// Translation along a unit `axis` given in the joint frame; the coordinate is the
    /// displacement (m).
    Prismatic {
        /// Unit axis in the joint (child) frame.
        axis: [f64; 2],
    },
}

/// A named frame: a body-fixed frame with its placement in the joint frame of the body that
/// carries it (the ground for frames fixed to the world).
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// The frame's name (the name of the body it was given to in the description).
    pub name: String,
    /// The moving body (or the ground) that carries the frame.
    pub body: BodyId,
    /// Pose of the frame in the carrying body's joint frame.
    pub placement: Transform,
}

/// Per-body data used by the algorithms (hot loop): kept small and free of strings.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BodyModel {
    /// Parent body index (0 = ground; unused for the ground itself).
    pub parent: usize,
    /// Coordinate index of this body's joint in q, v, a, τ.
    pub idx_v: usize,
    /// Joint kind.
    pub joint: JointType,
    /// Pose of the joint frame in the parent's joint frame at q = 0.
    pub x_tree: Transform,
    /// Tree angle, for revolute joints: angle of x_tree.
    pub theta_tree: f64,
    /// For prismatic joints, the axis expressed in the parent frame: R_tree · axis.
    pub axis_parent: [f64; 2],
    /// Motion subspace S in the body frame.
    pub s: Motion,
    /// Rigid-body inertia (with merged fixed children) in the body's joint frame.
    pub inertia: Inertia,
}

impl BodyModel {
    /// Pose of this body's joint frame in its parent's, for coordinate value `q`.
    #[inline(always)]
    pub fn joint_transform(&self, q: f64) -> Transform {
        match self.joint {
            JointType::Revolute => {
                let (s, c) = (self.theta_tree + q).sin_cos();
                Transform {
                    c,
                    s,
                    x: self.x_tree.x,
                    y: self.x_tree.y,
                }
            }
            JointType::Prismatic { .. } => Transform {
                c: self.x_tree.c,
                s: self.x_tree.s,
                x: self.x_tree.x + q * self.axis_parent[0],
                y: self.x_tree.y + q * self.axis_parent[1],
            },
        }
    }

    /// `Sᵀ f`: the generalized force of a body-frame spatial force on this joint.
    ///
    /// The zero components of `S` still multiply their force components, as in the full
    /// product: a state so large that a force overflows (`v = 1e300` squares to infinity in
    /// the centripetal force, which a revolute joint does not feel) then gives a NaN
    /// generalized force that callers report, rather than a finite number from an
    /// overflowed computation.
    #[inline(always)]
    pub fn s_dot(&self, f: &Force) -> f64 {
        match self.joint {
            JointType::Revolute => f.n + 0.0 * f.fx + 0.0 * f.fy,
            JointType::Prismatic { .. } => 0.0 * f.n + self.s.vx * f.fx + self.s.vy * f.fy,
        }
    }

    /// `m + S k`: adds a joint rate (or acceleration) `k` to a body-frame motion.
    #[inline(always)]
    pub fn add_s(&self, m: Motion, k: f64) -> Motion {
        match self.joint {
            JointType::Revolute => Motion { w: m.w + k, ..m },
            JointType::Prismatic { .. } => Motion {
                w: m.w,
                vx: m.vx + self.s.vx * k,
                vy: m.vy + self.s.vy * k,
            },
        }
    }

    /// `v ×ₘ S k`: the velocity-product acceleration of a joint moving at rate `k` on a body
    /// moving at `v`. Its angular part is zero for both joint kinds.
    #[inline(always)]
    pub fn cross_s(&self, v: &Motion, k: f64) -> Motion {
        match self.joint {
            // [0, vy k, −vx k]
            JointType::Revolute => Motion::new(0.0, v.vy * k, -v.vx * k),
            // [0, −w ay k, w ax k]
            JointType::Prismatic { .. } => {
                Motion::new(0.0, -v.w * (self.s.vy * k), v.w * (self.s.vx * k))
            }
        }
    }
}

/// An immutable planar multibody model: a forest of bodies on the ground, each moving body
/// attached to its parent by a revolute or prismatic joint (fixed joints are merged into the
/// parent when the model is built). Build one with [`crate::ModelBuilder`] or from a
/// [`crate::ModelDescription`].
///
/// Bodies are in topological order (`parent < child`); coordinates are numbered in the order
/// the joints were declared, which need not be the body order.
#[derive(Clone, Debug)]
pub struct Model {
    pub(crate) gravity: [f64; 2],
    /// Index 0 is the ground placeholder.
    pub(crate) bodies: Vec<BodyModel>,
    pub(crate) body_names: Vec<String>,
    pub(crate) joint_names: Vec<String>,
    /// Body index of each coordinate.
    pub(crate) body_of_coordinate: Vec<usize>,
    pub(crate) frames: Vec<Frame>,
    pub(crate) frame_by_name: BTreeMap<String, usize>,
    /// Tables derived from `bodies` for the algorithms' hot loops.
    pub(crate) layout: Layout,
}

impl Model {
    /// A model from its parts, with the hot loops' tables derived from `bodies` (the one
    /// place a model is put together: [`crate::ModelBuilder`] calls it).
    pub(crate) fn from_parts(
        gravity: [f64; 2],
        bodies: Vec<BodyModel>,
        body_names: Vec<String>,
        joint_names: Vec<String>,
        body_of_coordinate: Vec<usize>,
        frames: Vec<Frame>,
        frame_by_name: BTreeMap<String, usize>,
    ) -> Model {
        Model {
            gravity,
            layout: Layout::new(&bodies),
            bodies,
            body_names,
            joint_names,
            body_of_coordinate,
            frames,
            frame_by_name,
        }
    }

    /// Gravity acceleration in world coordinates (m/s²).
    pub fn gravity(&self) -> [f64; 2] {
        self.gravity
    }

    /// A copy of this model with another gravity vector.
    pub fn with_gravity(&self, gravity: [f64; 2]) -> Result<Model> {
        for (k, g) in gravity.iter().enumerate() {
            if !g.is_finite() {
                return Err(CoreError::NonFinite {
                    item: "model".into(),
                    field: if k == 0 { "gravity[0]" } else { "gravity[1]" },
                    value: *g,
                });
            }
        }
        let mut m = self.clone();
        m.gravity = gravity;
        Ok(m)
    }

    /// Number of generalized coordinates (equal to the number of velocities: planar joints
    /// have plain angle or displacement coordinates).
    pub fn nv(&self) -> usize {
        self.body_of_coordinate.len()
    }

    /// Number of generalized coordinates (same as [`Model::nv`]).
    pub fn nq(&self) -> usize {
        self.nv()
    }

    /// Number of bodies **including the ground** (body 0): the length of per-body arrays
    /// such as external forces.
    pub fn nbodies(&self) -> usize {
        self.bodies.len()
    }

    /// Iterator over the moving bodies, in topological order.
    pub fn moving_bodies(&self) -> impl Iterator<Item = BodyId> + '_ {
        (1..self.bodies.len()).map(BodyId)
    }

    /// The body with this name (a moving body; the name of a body merged by a fixed joint
    /// is a frame, see [`Model::frame_id`]).
    pub fn body_id(&self, name: &str) -> Result<BodyId> {
        // Index 0 is the ground's placeholder name: search the moving bodies only, so a
        // body the user named "ground" is still found.
        self.body_names[1..]
            .iter()
            .position(|n| n == name)
            .map(|i| BodyId(i + 1))
            .ok_or_else(|| CoreError::UnknownName {
                what: "moving body",
                name: name.to_string(),
            })
    }

    /// Name of a body (`"ground"` for the ground); `None` for an id that is not one of this
    /// model's bodies (an id taken from another model).
    pub fn body_name(&self, body: BodyId) -> Option<&str> {
        self.body_names.get(body.0).map(String::as_str)
    }

    /// Parent of a moving body (`None` for the ground, and for an id that is not one of
    /// this model's bodies).
    pub fn parent(&self, body: BodyId) -> Option<BodyId> {
        (body.0 > 0)
            .then(|| self.bodies.get(body.0).map(|b| BodyId(b.parent)))
            .flatten()
    }

    /// Joint connecting a moving body to its parent (`None` for the ground).
    /// `None` for the ground and for an id that is not one of this model's bodies.
    pub fn joint_type(&self, body: BodyId) -> Option<JointType> {
        (body.0 > 0)
            .then(|| self.bodies.get(body.0).map(|b| b.joint))
            .flatten()
    }

    /// Pose of a moving body's joint frame in its parent's joint frame at zero coordinate;
    /// `None` for an id that is not one of this model's bodies.
    pub fn joint_placement(&self, body: BodyId) -> Option<Transform> {
        self.bodies.get(body.0).map(|b| b.x_tree)
    }

    /// Rigid-body inertia of a moving body (including fixed children merged into it) in its
    /// joint frame; zero for the ground, `None` for an id that is not one of this model's
    /// bodies.
    pub fn inertia(&self, body: BodyId) -> Option<Inertia> {
        if body.0 == 0 {
            Some(Inertia::ZERO)
        } else {
            self.bodies.get(body.0).map(|b| b.inertia)
        }
    }

    /// Total mass of the moving bodies.
    pub fn total_mass(&self) -> f64 {
        self.bodies[1..].iter().map(|b| b.inertia.m).sum()
    }

    /// Coordinate index (into q, v, a, τ) of a moving body's joint; `None` for the ground.
    /// `None` also for an id that is not one of this model's bodies.
    pub fn coordinate_of(&self, body: BodyId) -> Option<usize> {
        (body.0 > 0)
            .then(|| self.bodies.get(body.0).map(|b| b.idx_v))
            .flatten()
    }

    /// Body moved by coordinate `k`.
    pub fn body_of_coordinate(&self, k: usize) -> Result<BodyId> {
        self.body_of_coordinate
            .get(k)
            .map(|&b| BodyId(b))
            .ok_or_else(|| CoreError::UnknownName {
                what: "coordinate index",
                name: format!("{k} (the model has {} coordinates)", self.nv()),
            })
    }

    /// Names of the coordinates (the joint names), in coordinate order.
    pub fn coordinate_names(&self) -> &[String] {
        &self.joint_names
    }

    /// Coordinate index of the joint with this name.
    pub fn coordinate_id(&self, joint: &str) -> Result<usize> {
        self.joint_names
            .iter()
            .position(|n| n == joint)
            .ok_or_else(|| CoreError::UnknownName {
                what: "moving joint",
                name: joint.to_string(),
            })
    }

    /// The frame with this name.
    pub fn frame_id(&self, name: &str) -> Result<FrameId> {
        self.frame_by_name
            .get(name)
            .map(|&i| FrameId(i))
            .ok_or_else(|| CoreError::UnknownName {
                what: "frame",
                name: name.to_string(),
            })
    }

    /// A frame of the model.
    pub fn frame(&self, frame: FrameId) -> &Frame {
        &self.frames[frame.0]
    }

    /// All named frames, in declaration order.
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }

    /// Ancestors of a body from itself up to (not including) the ground; empty for an id
    /// that is not one of this model's bodies.
    pub fn support(&self, body: BodyId) -> impl Iterator<Item = BodyId> + '_ {
        let mut i = if body.0 < self.bodies.len() {
            body.0
        } else {
            0
        };
        std::iter::from_fn(move || {
            if i == 0 {
                None
            } else {
                let b = BodyId(i);
                i = self.bodies[i].parent;
                Some(b)
            }
        })
    }
}
