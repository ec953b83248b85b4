//! Writing a description from a drawing: points read in world millimetres (as a layout
//! gives them, every body at rest) turned into a body's frame in metres.

/// A body's frame at rest in the world: its origin (mm) and angle (rad, counter-clockwise).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorldFrame {
    /// Origin in the world (mm).
    pub origin_mm: [f64; 2],
    /// Angle of its x axis from the world's (rad).
    pub angle: f64,
}

impl WorldFrame {
    /// The world itself.
    pub const WORLD: Self = Self {
        origin_mm: [0.0, 0.0],
        angle: 0.0,
    };

    /// An unturned frame at `origin_mm`.
    pub const fn at(origin_mm: [f64; 2]) -> Self {
        Self {
            origin_mm,
            angle: 0.0,
        }
    }

    /// A frame at `origin_mm` turned by `angle`.
    pub const fn turned(origin_mm: [f64; 2], angle: f64) -> Self {
        Self { origin_mm, angle }
    }

    /// The world point `p_mm` (mm) in this frame (m). An unturned frame only shifts it, so
    /// the result is exactly `(p − origin) / 1000`.
    pub fn local(&self, p_mm: [f64; 2]) -> [f64; 2] {
        let d = [p_mm[0] - self.origin_mm[0], p_mm[1] - self.origin_mm[1]];
        let d = if self.angle == 0.0 {
            d
        } else {
            let (s, c) = self.angle.sin_cos();
            [c * d[0] + s * d[1], -s * d[0] + c * d[1]]
        };
        [d[0] * 1e-3, d[1] * 1e-3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_comes_back_through_the_frame() {
        let f = WorldFrame::turned([10.0, 20.0], 0.4);
        let p = [35.0, -7.5];
        let l = f.local(p);
        // Back to the world: rotate by the angle, shift by the origin.
        let (s, c) = 0.4f64.sin_cos();
        let w = [
            10.0 + (c * l[0] - s * l[1]) * 1e3,
            20.0 + (s * l[0] + c * l[1]) * 1e3,
        ];
        assert!(
            (w[0] - p[0]).abs() < 1e-12 && (w[1] - p[1]).abs() < 1e-12,
            "{w:?}"
        );
        assert_eq!(WorldFrame::at([1.0, 2.0]).local([3.0, 5.0]), [2e-3, 3e-3]);
        assert_eq!(WorldFrame::WORLD.local([-4.0, 0.5]), [-4e-3, 0.5e-3]);
    }
}
