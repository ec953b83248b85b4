//! The key as a lever: where the finger acts relative to the balance pivot, and from it the
//! key-front depth at a key angle, the angle for a depth, and the lever arm of a vertical
//! finger force. One type for the grand's parameters and for any description's key.

use crate::error::{PianoError, Result};
use crate::mechanism::{JointType, Mechanism};
use crate::params::KeyParams;

/// A key turning about its balance pivot (positive angle: the front goes down).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KeyGeometry {
    /// The finger point relative to the pivot (mm), in the key's frame.
    pub finger_mm: [f64; 2],
    /// The key frame's angle in the world at key angle 0 (rad): 0 for the grand.
    pub frame_angle: f64,
}

impl KeyGeometry {
    /// The grand's key of `key` (its layout is the frame at key angle 0).
    pub fn of(key: &KeyParams) -> Self {
        Self {
            finger_mm: [
                key.finger_mm[0] - key.pivot_mm[0],
                key.finger_mm[1] - key.pivot_mm[1],
            ],
            frame_angle: 0.0,
        }
    }

    /// The key of a description: the body that its input `input` acts on, which must turn
    /// about a revolute joint on the ground.
    pub fn from_mechanism(mechanism: &Mechanism, input: &str) -> Result<Self> {
        let at = &mechanism
            .inputs
            .iter()
            .find(|i| i.name == input)
            .ok_or_else(|| {
                PianoError::option(
                    "input",
                    format!(
                        "the description '{}' has no input '{input}'",
                        mechanism.name
                    ),
                )
            })?
            .at;
        let body = mechanism
            .bodies
            .iter()
            .find(|b| b.name == at.body)
            .ok_or_else(|| {
                PianoError::option("input", format!("no body '{}' for '{input}'", at.body))
            })?;
        if body.joint.kind != JointType::Revolute || body.joint.parent != "ground" {
            return Err(PianoError::option(
                "input",
                format!(
                    "'{input}' acts on '{}', which does not turn about a pivot on the ground",
                    body.name
                ),
            ));
        }
        Ok(Self {
            finger_mm: [at.point[0] * 1e3, at.point[1] * 1e3],
            frame_angle: body.joint.angle,
        })
    }

    /// The finger point relative to the pivot (m), in the key's frame.
    pub fn finger_m(&self) -> [f64; 2] {
        [self.finger_mm[0] * 1e-3, self.finger_mm[1] * 1e-3]
    }

    /// The finger point's height above the pivot (mm) at key angle `q`.
    pub fn height_mm(&self, q: f64) -> f64 {
        let [fx, fy] = self.finger_mm;
        let (s, c) = (self.frame_angle + q).sin_cos();
        fx * s + fy * c
    }

    /// Key-front depth (mm, down positive) at key angle `q`, from key angle 0.
    pub fn depth_mm(&self, q: f64) -> f64 {
        self.height_mm(0.0) - self.height_mm(q)
    }

    /// The key angle (rad) that puts the finger point `depth_mm` below where it is at key
    /// angle `q0` (Newton from the small-angle guess).
    pub fn angle_below(&self, q0: f64, depth_mm: f64) -> f64 {
        let [fx, fy] = self.finger_mm;
        let start = self.height_mm(q0);
        let mut q = q0 + depth_mm / (fx * fx + fy * fy).sqrt();
        for _ in 0..6 {
            let (s, c) = (self.frame_angle + q).sin_cos();
            let f = (start - self.height_mm(q)) - depth_mm;
            let df = -(fx * c - fy * s);
            q -= f / df;
        }
        q
    }

    /// The key angle (rad) that puts the finger point `depth_mm` below its place at key
    /// angle 0.
    pub fn angle_for_depth(&self, depth_mm: f64) -> f64 {
        self.angle_below(0.0, depth_mm)
    }

    /// The lever arm (m) of a vertical force at the finger point about the pivot, at key
    /// angle `q`: its horizontal distance (negative before the pivot).
    pub fn arm_m(&self, q: f64) -> f64 {
        let [fx, fy] = self.finger_mm;
        let (s, c) = (self.frame_angle + q).sin_cos();
        (fx * c - fy * s) * 1e-3
    }

    /// The finger point's distance from the pivot (mm).
    pub fn radius_mm(&self) -> f64 {
        self.finger_mm[0].hypot(self.finger_mm[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_angle_and_arm_agree() {
        let params = crate::ActionParams::reference();
        let key = KeyGeometry::of(&params.key);
        for depth in [0.5, 5.0, 10.5] {
            let q = key.angle_for_depth(depth);
            assert!((key.depth_mm(q) - depth).abs() < 1e-9, "{depth}");
            // A small turn moves the front down by the arm times the angle.
            let dq = 1e-7;
            let slope = (key.depth_mm(q + dq) - key.depth_mm(q - dq)) / (2.0 * dq);
            assert!((slope + key.arm_m(q) * 1e3).abs() < 1e-3, "{slope}");
        }
        // The same key turned in its frame: the same depths from a turned start.
        let turned = KeyGeometry {
            finger_mm: [
                key.finger_mm[0] * 0.3f64.cos() + key.finger_mm[1] * 0.3f64.sin(),
                -key.finger_mm[0] * 0.3f64.sin() + key.finger_mm[1] * 0.3f64.cos(),
            ],
            frame_angle: 0.3,
        };
        let q = key.angle_for_depth(7.0);
        assert!((turned.depth_mm(q) - 7.0).abs() < 1e-9);
        assert!((turned.angle_below(q, 2.0) - key.angle_for_depth(9.0)).abs() < 1e-12);
    }

    #[test]
    fn a_description_key_must_turn_on_the_ground() {
        let params = crate::ActionParams::reference();
        let m = crate::describe::grand_mechanism(&params, crate::ModelKind::Double, None)
            .expect("it describes");
        let key = KeyGeometry::from_mechanism(&m, "finger").expect("the finger acts on the key");
        let grand = KeyGeometry::of(&params.key);
        for i in 0..2 {
            assert!((key.finger_mm[i] - grand.finger_mm[i]).abs() < 1e-9);
        }
        assert!(KeyGeometry::from_mechanism(&m, "elbow").is_err());
    }
}
