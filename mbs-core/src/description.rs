//! The serde model description (JSON): the file format the builder accepts.
//!
//! ```json
//! {"gravity": [0.0, -9.81],
//!  "joints": [{"name": "link1", "parent": null, "kind": "revolute",
//!              "placement": {"angle": 0.0, "x": 0.0, "y": 0.0},
//!              "body": {"mass": 1.0, "com": [0.5, 0.0], "inertia": 0.0833}}]}
//! ```
//!
//! Each joint carries the body it moves, under the joint's name; `parent` names the parent
//! joint (its body) or is `null` for the ground. The joint frame is placed in the parent's
//! joint frame by a rotation `angle` about z and an offset `(x, y)` in the parent frame.
//! Revolute joints turn about z; prismatic joints slide along `axis` (prismatic only) in the
//! joint frame; fixed joints merge their body into the parent. Coordinates are numbered in
//! file order. Unknown fields are rejected so that a misspelt field is not silently ignored.

use serde::{Deserialize, Serialize};

use crate::builder::{BodySpec, JointKind, ModelBuilder, Placement};
use crate::error::{CoreError, Result};
use crate::model::Model;

/// A whole model description.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelDescription {
    /// Gravity in world coordinates (m/s²).
    pub gravity: [f64; 2],
    /// Joints, each with the body it carries, in coordinate order.
    pub joints: Vec<JointDescription>,
}

/// The kind of a described joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKindName {
    /// Rotation about z.
    Revolute,
    /// Translation along `axis`.
    Prismatic,
    /// No relative motion (merged into the parent).
    Fixed,
}

/// Placement of a joint frame in its parent's joint frame.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlacementDescription {
    /// Rotation about z (rad).
    pub angle: f64,
    /// Offset along the parent's x axis (m).
    pub x: f64,
    /// Offset along the parent's y axis (m).
    pub y: f64,
}

/// Mass properties of the body a joint carries.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodyDescription {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the joint frame (m).
    pub com: [f64; 2],
    /// Rotational inertia about the centre of mass (kg·m²).
    pub inertia: f64,
}

/// One joint and the body it carries.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDescription {
    /// Name of the joint and of its body.
    pub name: String,
    /// Name of the parent joint, `None` (JSON `null`) for the ground.
    pub parent: Option<String>,
    /// Joint kind.
    pub kind: JointKindName,
    /// Prismatic axis in the joint frame (prismatic joints only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 2]>,
    /// Placement in the parent's joint frame.
    pub placement: PlacementDescription,
    /// Mass properties.
    pub body: BodyDescription,
}

impl ModelDescription {
    /// Parses a JSON description; the error names the field (as a path such as
    /// `joints[2].body.mass`), where it is (line, column) and what is wrong.
    pub fn from_json_str(text: &str) -> Result<Self> {
        let de = &mut serde_json::Deserializer::from_str(text);
        serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            if path.is_empty() || path == "." {
                CoreError::Parse(inner.to_string())
            } else {
                CoreError::Parse(format!("field `{path}`: {inner}"))
            }
        })
    }

    /// Serialises to pretty JSON.
    pub fn to_json_string(&self) -> String {
        // Serialising plain data with string keys cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }

    /// A builder holding this description's bodies and joints.
    pub fn to_builder(&self) -> Result<ModelBuilder> {
        let mut b = ModelBuilder::new();
        b.gravity(self.gravity);
        for j in &self.joints {
            let kind = match (j.kind, j.axis) {
                (JointKindName::Revolute, None) => JointKind::Revolute,
                (JointKindName::Fixed, None) => JointKind::Fixed,
                (JointKindName::Prismatic, Some(axis)) => JointKind::Prismatic { axis },
                (JointKindName::Prismatic, None) => {
                    return Err(CoreError::BadAxis {
                        joint: j.name.clone(),
                        message: "a prismatic joint needs an \"axis\": [ax, ay]",
                    });
                }
                (_, Some(_)) => {
                    return Err(CoreError::BadAxis {
                        joint: j.name.clone(),
                        message: "\"axis\" is only allowed on prismatic joints",
                    });
                }
            };
            b.add_link(
                &j.name,
                j.parent.as_deref(),
                kind,
                Placement::new(j.placement.angle, j.placement.x, j.placement.y),
                BodySpec::new(j.body.mass, j.body.com, j.body.inertia),
            );
        }
        Ok(b)
    }

    /// Builds the model.
    pub fn build(&self) -> Result<Model> {
        self.to_builder()?.build()
    }
}

impl Model {
    /// Parses and builds a model from its JSON description.
    pub fn from_json_str(text: &str) -> Result<Model> {
        ModelDescription::from_json_str(text)?.build()
    }
}
