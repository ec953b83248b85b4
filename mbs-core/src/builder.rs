//! [`ModelBuilder`]: declares bodies and joints, validates the topology with petgraph and
//! produces an immutable [`Model`] with bodies in topological order and fixed joints merged.

use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap};

use petgraph::Direction;
use petgraph::graph::{DiGraph, NodeIndex};
use petgraph::visit::EdgeRef;

use crate::error::{CoreError, Result};
use crate::model::{BodyModel, Frame, JointType, Model};
use crate::spatial::{Inertia, Motion, Transform};

/// Mass properties of a body: mass, centre of mass in the body's joint frame, rotational
/// inertia about the centre of mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodySpec {
    /// Mass (kg), positive.
    pub mass: f64,
    /// Centre of mass in the body's joint frame (m).
    pub com: [f64; 2],
    /// Rotational inertia about the centre of mass (kg·m²), positive.
    pub inertia: f64,
}

impl BodySpec {
    /// Mass properties from mass, centre of mass and inertia about the centre of mass.
    pub fn new(mass: f64, com: [f64; 2], inertia: f64) -> Self {
        Self { mass, com, inertia }
    }

    /// A uniform slender rod of mass `mass` and length `length` along the body's x axis from
    /// the joint: centre of mass at `(length / 2, 0)`, inertia `mass length² / 12`.
    pub fn rod(mass: f64, length: f64) -> Self {
        Self::new(mass, [0.5 * length, 0.0], mass * length * length / 12.0)
    }
}

/// Placement of a joint frame in its parent's joint frame: a rotation `angle` (rad, about z)
/// and an offset `(x, y)` expressed in the parent frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Placement {
    /// Rotation about z (rad).
    pub angle: f64,
    /// Offset along the parent's x axis (m).
    pub x: f64,
    /// Offset along the parent's y axis (m).
    pub y: f64,
}

impl Placement {
    /// A placement from its angle and offset.
    pub fn new(angle: f64, x: f64, y: f64) -> Self {
        Self { angle, x, y }
    }

    /// A pure offset.
    pub fn offset(x: f64, y: f64) -> Self {
        Self::new(0.0, x, y)
    }

    fn transform(&self) -> Transform {
        Transform::new(self.angle, self.x, self.y)
    }
}

/// Kind of a joint as declared.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum JointKind {
    /// Rotation about z.
    Revolute,
    /// Translation along `axis` (any non-zero in-plane vector in the joint frame; it is
    /// normalised).
    Prismatic {
        /// Direction of travel in the joint frame.
        axis: [f64; 2],
    },
    /// No relative motion: the child is merged into the parent when the model is built.
    Fixed,
}

#[derive(Clone, Debug)]
struct BodyDecl {
    name: String,
    spec: BodySpec,
}

#[derive(Clone, Debug)]
struct FrameDecl {
    name: String,
    parent: Option<String>,
    placement: Placement,
}

#[derive(Clone, Debug)]
struct JointDecl {
    name: String,
    kind: JointKind,
    parent: Option<String>,
    child: String,
    placement: Placement,
}

/// Declares bodies and the joints between them, then [`ModelBuilder::build`]s a validated
/// [`Model`]. Declarations may come in any order; errors are reported by `build`, each
/// naming the body or joint at fault.
///
/// ```
/// use mbs_core::{BodySpec, JointKind, ModelBuilder, Placement};
/// let mut b = ModelBuilder::new();
/// b.gravity([0.0, -9.81])
///     .add_body("arm", BodySpec::rod(1.0, 0.5))
///     .add_joint("shoulder", JointKind::Revolute, None, "arm", Placement::default());
/// let model = b.build().unwrap();
/// assert_eq!(model.nv(), 1);
/// ```
#[derive(Clone, Debug, Default)]
pub struct ModelBuilder {
    gravity: [f64; 2],
    bodies: Vec<BodyDecl>,
    joints: Vec<JointDecl>,
    frames: Vec<FrameDecl>,
}

impl ModelBuilder {
    /// An empty builder with zero gravity.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sets gravity (m/s², world coordinates).
    pub fn gravity(&mut self, gravity: [f64; 2]) -> &mut Self {
        self.gravity = gravity;
        self
    }

    /// Declares a body.
    pub fn add_body(&mut self, name: &str, spec: BodySpec) -> &mut Self {
        self.bodies.push(BodyDecl {
            name: name.to_string(),
            spec,
        });
        self
    }

    /// Declares a joint from `parent` (a body name, `None` for the ground) to `child`, its
    /// frame placed in the parent's joint frame by `placement`. Moving joints get their
    /// coordinate in declaration order.
    pub fn add_joint(
        &mut self,
        name: &str,
        kind: JointKind,
        parent: Option<&str>,
        child: &str,
        placement: Placement,
    ) -> &mut Self {
        self.joints.push(JointDecl {
            name: name.to_string(),
            kind,
            parent: parent.map(str::to_string),
            child: child.to_string(),
            placement,
        });
        self
    }

    /// Declares a body and the joint that carries it under one name, the way the JSON
    /// description does: `parent` is the name of the parent link (`None` for the ground).
    pub fn add_link(
        &mut self,
        name: &str,
        parent: Option<&str>,
        kind: JointKind,
        placement: Placement,
        spec: BodySpec,
    ) -> &mut Self {
        self.add_body(name, spec);
        self.add_joint(name, kind, parent, name, placement)
    }

    /// Declares a massless named frame fixed to `parent` (a body or an earlier frame; `None`
    /// for the ground), placed by `placement` in the parent's frame: a marker for contact
    /// points, screws, rails and sensors that does not change the dynamics.
    pub fn add_frame(
        &mut self,
        name: &str,
        parent: Option<&str>,
        placement: Placement,
    ) -> &mut Self {
        self.frames.push(FrameDecl {
            name: name.to_string(),
            parent: parent.map(str::to_string),
            placement,
        });
        self
    }

    /// Validates the declarations and builds the model.
    ///
    /// Errors, in the order they are checked: non-finite gravity; per body non-finite
    /// numbers, non-positive mass or inertia, duplicate names; per joint non-finite
    /// placement, bad prismatic axis, duplicate names, unknown parent or child; a body with
    /// several parent joints; cycles; bodies not connected to the ground; an empty model;
    /// frames with non-finite placement, a name already used, or an unknown parent.
    pub fn build(&self) -> Result<Model> {
        self.validate_numbers()?;
        let (graph, nodes) = self.graph()?;
        let order = self.topological_order(&graph, &nodes)?;
        let mut model = self.assemble(&graph, &order);
        self.add_marker_frames(&mut model)?;
        Ok(model)
    }

    /// Appends the massless frames, each placed relative to a body or an earlier frame.
    fn add_marker_frames(&self, model: &mut Model) -> Result<()> {
        for f in &self.frames {
            let item = || format!("frame '{}'", f.name);
            finite(item(), "placement.angle", f.placement.angle)?;
            finite(item(), "placement.x", f.placement.x)?;
            finite(item(), "placement.y", f.placement.y)?;
            if model.frame_by_name.contains_key(&f.name) {
                return Err(CoreError::DuplicateName {
                    what: "frame",
                    name: f.name.clone(),
                });
            }
            let (body, base) = match &f.parent {
                None => (crate::BodyId::GROUND, Transform::IDENTITY),
                Some(p) => {
                    let id = model.frame_id(p).map_err(|_| CoreError::InvalidParameter {
                        item: item(),
                        message: format!("unknown parent '{p}' (not a body or an earlier frame)"),
                    })?;
                    let parent = model.frame(id);
                    (parent.body, parent.placement)
                }
            };
            model
                .frame_by_name
                .insert(f.name.clone(), model.frames.len());
            model.frames.push(Frame {
                name: f.name.clone(),
                body,
                placement: base.compose(&f.placement.transform()),
            });
        }
        Ok(())
    }

    fn validate_numbers(&self) -> Result<()> {
        for (k, g) in self.gravity.iter().enumerate() {
            finite("model".into(), ["gravity[0]", "gravity[1]"][k], *g)?;
        }
        let mut seen = BTreeMap::new();
        for b in &self.bodies {
            let item = || format!("body '{}'", b.name);
            finite(item(), "mass", b.spec.mass)?;
            finite(item(), "com[0]", b.spec.com[0])?;
            finite(item(), "com[1]", b.spec.com[1])?;
            finite(item(), "inertia", b.spec.inertia)?;
            if b.spec.mass <= 0.0 {
                return Err(CoreError::NonPositiveMass {
                    body: b.name.clone(),
                    mass: b.spec.mass,
                });
            }
            if b.spec.inertia <= 0.0 {
                return Err(CoreError::NonPositiveInertia {
                    body: b.name.clone(),
                    inertia: b.spec.inertia,
                });
            }
            if seen.insert(b.name.as_str(), ()).is_some() {
                return Err(CoreError::DuplicateName {
                    what: "body",
                    name: b.name.clone(),
                });
            }
        }
        let mut seen = BTreeMap::new();
        for j in &self.joints {
            let item = || format!("joint '{}'", j.name);
            finite(item(), "placement.angle", j.placement.angle)?;
            finite(item(), "placement.x", j.placement.x)?;
            finite(item(), "placement.y", j.placement.y)?;
            if let JointKind::Prismatic { axis } = j.kind {
                finite(item(), "axis[0]", axis[0])?;
                finite(item(), "axis[1]", axis[1])?;
                let norm = axis[0].hypot(axis[1]);
                if norm.is_nan() || norm <= 1e-12 {
                    return Err(CoreError::ZeroAxis {
                        joint: j.name.clone(),
                        axis,
                    });
                }
            }
            if seen.insert(j.name.as_str(), ()).is_some() {
                return Err(CoreError::DuplicateName {
                    what: "joint",
                    name: j.name.clone(),
                });
            }
        }
        Ok(())
    }

    /// The directed graph ground → bodies, one edge per joint (edge weight = joint index).
    fn graph(&self) -> Result<(DiGraph<usize, usize>, Vec<NodeIndex>)> {
        let mut graph = DiGraph::<usize, usize>::new();
        let ground = graph.add_node(usize::MAX);
        let mut nodes = vec![ground];
        let mut by_name = BTreeMap::new();
        for (i, b) in self.bodies.iter().enumerate() {
            let n = graph.add_node(i);
            nodes.push(n);
            by_name.insert(b.name.as_str(), n);
        }
        let lookup = |joint: &JointDecl, role: &'static str, name: &str| {
            by_name
                .get(name)
                .copied()
                .ok_or_else(|| CoreError::UnknownBody {
                    joint: joint.name.clone(),
                    role,
                    body: name.to_string(),
                })
        };
        for (k, j) in self.joints.iter().enumerate() {
            let parent = match &j.parent {
                None => ground,
                Some(p) => lookup(j, "parent", p)?,
            };
            let child = lookup(j, "child", &j.child)?;
            graph.add_edge(parent, child, k);
        }
        // A body reached by several joints closes a loop.
        for (i, b) in self.bodies.iter().enumerate() {
            let incoming: Vec<String> = graph
                .edges_directed(nodes[i + 1], Direction::Incoming)
                .map(|e| self.joints[*e.weight()].name.clone())
                .collect();
            if incoming.len() > 1 {
                let mut joints = incoming;
                joints.sort();
                return Err(CoreError::MultipleParents {
                    body: b.name.clone(),
                    joints,
                });
            }
        }
        // With at most one parent per body, a cycle is a strongly connected component of
        // more than one body, or a body that is its own parent.
        for scc in petgraph::algo::tarjan_scc(&graph) {
            let is_cycle = scc.len() > 1 || graph.edges_connecting(scc[0], scc[0]).next().is_some();
            if is_cycle {
                let mut joints: Vec<String> = scc
                    .iter()
                    .flat_map(|&n| graph.edges_directed(n, Direction::Incoming))
                    .filter(|e| scc.contains(&e.source()))
                    .map(|e| self.joints[*e.weight()].name.clone())
                    .collect();
                joints.sort();
                return Err(CoreError::Cycle { joints });
            }
        }
        for (i, b) in self.bodies.iter().enumerate() {
            if graph
                .edges_directed(nodes[i + 1], Direction::Incoming)
                .next()
                .is_none()
            {
                return Err(CoreError::NotConnected {
                    body: b.name.clone(),
                });
            }
        }
        Ok((graph, nodes))
    }

    /// Kahn's algorithm, taking the earliest-declared ready body first so that a
    /// description already in topological order keeps its order.
    fn topological_order(
        &self,
        graph: &DiGraph<usize, usize>,
        nodes: &[NodeIndex],
    ) -> Result<Vec<usize>> {
        let mut ready: BinaryHeap<Reverse<usize>> = graph
            .neighbors_directed(nodes[0], Direction::Outgoing)
            .map(|n| Reverse(graph[n]))
            .collect();
        let mut order = Vec::with_capacity(self.bodies.len());
        while let Some(Reverse(b)) = ready.pop() {
            order.push(b);
            for n in graph.neighbors_directed(nodes[b + 1], Direction::Outgoing) {
                ready.push(Reverse(graph[n]));
            }
        }
        // Every body has one parent and there is no cycle, so all are reached; keep the
        // check so a logic error cannot produce a silently truncated model.
        if let Some(b) = (0..self.bodies.len()).find(|b| !order.contains(b)) {
            return Err(CoreError::NotConnected {
                body: self.bodies[b].name.clone(),
            });
        }
        if !self
            .joints
            .iter()
            .any(|j| !matches!(j.kind, JointKind::Fixed))
        {
            return Err(CoreError::EmptyModel);
        }
        Ok(order)
    }

    /// Merges fixed joints and lays the moving bodies out in topological order.
    fn assemble(&self, graph: &DiGraph<usize, usize>, order: &[usize]) -> Model {
        let nbody = self.bodies.len();
        // Parent joint of each declared body.
        let mut joint_of = vec![0usize; nbody];
        for e in graph.edge_indices() {
            let (_, child) = graph.edge_endpoints(e).expect("edge exists");
            joint_of[graph[child]] = graph[e];
        }
        let body_index: BTreeMap<&str, usize> = self
            .bodies
            .iter()
            .enumerate()
            .map(|(i, b)| (b.name.as_str(), i))
            .collect();
        // Coordinates in joint declaration order.
        let mut coord_of_joint = vec![usize::MAX; self.joints.len()];
        let mut joint_names = Vec::new();
        for (k, j) in self.joints.iter().enumerate() {
            if !matches!(j.kind, JointKind::Fixed) {
                coord_of_joint[k] = joint_names.len();
                joint_names.push(j.name.clone());
            }
        }

        let ground = BodyModel {
            parent: 0,
            idx_v: usize::MAX,
            joint: JointType::Revolute,
            x_tree: Transform::IDENTITY,
            theta_tree: 0.0,
            axis_parent: [0.0, 0.0],
            s: Motion::ZERO,
            inertia: Inertia::ZERO,
        };
        let mut bodies = vec![ground];
        let mut body_names = vec!["ground".to_string()];
        let mut body_of_coordinate = vec![0usize; joint_names.len()];
        // Host moving body (0 = ground) and placement in its joint frame, per declared body.
        let mut host = vec![0usize; nbody];
        let mut placement_in_host = vec![Transform::IDENTITY; nbody];
        let mut frames = Vec::with_capacity(nbody);
        for &b in order {
            let j = &self.joints[joint_of[b]];
            let (parent_host, parent_placement) = match &j.parent {
                None => (0, Transform::IDENTITY),
                Some(p) => {
                    let pi = body_index[p.as_str()];
                    (host[pi], placement_in_host[pi])
                }
            };
            let x_tree = parent_placement.compose(&j.placement.transform());
            let spec = self.bodies[b].spec;
            let inertia = Inertia::from_com(spec.mass, spec.com, spec.inertia);
            match j.kind {
                JointKind::Fixed => {
                    host[b] = parent_host;
                    placement_in_host[b] = x_tree;
                    if parent_host != 0 {
                        bodies[parent_host].inertia += inertia.to_parent(&x_tree);
                    }
                }
                kind => {
                    let k = bodies.len();
                    let (joint, s) = match kind {
                        JointKind::Prismatic { axis } => {
                            let n = axis[0].hypot(axis[1]);
                            let a = [axis[0] / n, axis[1] / n];
                            (
                                JointType::Prismatic { axis: a },
                                Motion::new(0.0, a[0], a[1]),
                            )
                        }
                        _ => (JointType::Revolute, Motion::new(1.0, 0.0, 0.0)),
                    };
                    let axis_parent = match joint {
                        JointType::Prismatic { axis } => x_tree.rotate(axis),
                        JointType::Revolute => [0.0, 0.0],
                    };
                    let idx_v = coord_of_joint[joint_of[b]];
                    body_of_coordinate[idx_v] = k;
                    bodies.push(BodyModel {
                        parent: parent_host,
                        idx_v,
                        joint,
                        x_tree,
                        theta_tree: x_tree.angle(),
                        axis_parent,
                        s,
                        inertia,
                    });
                    body_names.push(self.bodies[b].name.clone());
                    host[b] = k;
                    placement_in_host[b] = Transform::IDENTITY;
                }
            }
        }
        // Frames in declaration order.
        for (b, decl) in self.bodies.iter().enumerate() {
            frames.push(Frame {
                name: decl.name.clone(),
                body: crate::BodyId(host[b]),
                placement: placement_in_host[b],
            });
        }
        let frame_by_name = frames
            .iter()
            .enumerate()
            .map(|(i, f)| (f.name.clone(), i))
            .collect();
        Model::from_parts(
            self.gravity,
            bodies,
            body_names,
            joint_names,
            body_of_coordinate,
            frames,
            frame_by_name,
        )
    }
}

fn finite(item: String, field: &'static str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(CoreError::NonFinite { item, field, value })
    }
}
