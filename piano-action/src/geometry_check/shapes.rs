//! The action's contact shapes in a pose, in plane geometry (mm), as `Action::build` makes
//! them: what the checks measure gaps with.

use super::COVER_TOL_MM;
use crate::params::ActionParams;

/// A point or vector in the plane (mm).
pub(super) type V = [f64; 2];

pub(super) fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1]]
}

pub(super) fn add(a: V, b: V) -> V {
    [a[0] + b[0], a[1] + b[1]]
}

pub(super) fn scale(a: V, k: f64) -> V {
    [a[0] * k, a[1] * k]
}

pub(super) fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// z of a × b.
pub(super) fn cross(a: V, b: V) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

pub(super) fn norm(a: V) -> f64 {
    a[0].hypot(a[1])
}

/// `v` turned by `angle` (rad) counter-clockwise.
pub(super) fn rot(v: V, angle: f64) -> V {
    let (s, c) = angle.sin_cos();
    [c * v[0] - s * v[1], s * v[0] + c * v[1]]
}

/// Point `p` turned by `angle` about `centre`.
pub(super) fn turn(p: V, centre: V, angle: f64) -> V {
    add(centre, rot(sub(p, centre), angle))
}

/// A flat face from `a` to `b`, solid on its right, facing left (as in mbs-contact).
#[derive(Clone, Copy, Debug)]
pub(super) struct Face {
    pub(super) a: V,
    pub(super) b: V,
}

impl Face {
    /// Signed gap (mm) to a round of centre `c` and radius `r`: along the normal inside the
    /// face's span, to the nearer end outside it.
    pub(super) fn gap(&self, c: V, r: f64) -> f64 {
        let d = sub(self.b, self.a);
        let len = norm(d);
        if len <= 0.0 {
            return norm(sub(c, self.a)) - r;
        }
        let u = scale(d, 1.0 / len);
        let s = dot(sub(c, self.a), u);
        if s < 0.0 {
            norm(sub(c, self.a)) - r
        } else if s > len {
            norm(sub(c, self.b)) - r
        } else {
            cross(u, sub(c, self.a)) - r
        }
    }

    /// Signed distance (mm) from the face's line, extended past its ends, to a round of
    /// centre `c` and radius `r`: how far the round must come along the normal to touch it.
    pub(super) fn line_gap(&self, c: V, r: f64) -> f64 {
        let d = sub(self.b, self.a);
        let len = norm(d);
        if len <= 0.0 {
            return norm(sub(c, self.a)) - r;
        }
        cross(scale(d, 1.0 / len), sub(c, self.a)) - r
    }

    /// The face turned by `angle` about `centre`.
    pub(super) fn turned(self, centre: V, angle: f64) -> Face {
        Face {
            a: turn(self.a, centre, angle),
            b: turn(self.b, centre, angle),
        }
    }
}

/// A horizontal fixed face at height `y` over `x`, facing up or down.
pub(super) fn ground(y: f64, x: [f64; 2], up: bool) -> Face {
    let (l, r) = ([x[0], y], [x[1], y]);
    if up {
        Face { a: l, b: r }
    } else {
        Face { a: r, b: l }
    }
}

/// Whether `x` lies in `[lo − tol, hi + tol]`.
pub(super) fn covers(range: [f64; 2], x: f64) -> bool {
    x >= range[0] - COVER_TOL_MM && x <= range[1] + COVER_TOL_MM
}

// The action's shapes in a pose.

/// Joint angles (rad) from the layout pose: key positive front down, wippen negative when
/// it rises, hammer positive head up. Jack and lever stay at rest on the wippen.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Pose {
    pub(super) key: f64,
    pub(super) wippen: f64,
    pub(super) hammer: f64,
}

/// The shapes of every contact in world coordinates (mm), as `Action::build` makes them.
pub(super) struct Shapes<'a> {
    p: &'a ActionParams,
    /// Jack axis, normalised.
    pub(super) n: V,
    /// Along the jack top toward the strings.
    pub(super) t: V,
}

impl<'a> Shapes<'a> {
    pub(super) fn new(p: &'a ActionParams) -> Self {
        let a = p.jack.axis;
        let l = norm(a);
        let n = if l > 0.0 {
            scale(a, 1.0 / l)
        } else {
            [0.0, 1.0]
        };
        Shapes {
            p,
            n,
            t: [n[1], -n[0]],
        }
    }

    pub(super) fn key(&self, q: Pose, x: V) -> V {
        turn(x, self.p.key.pivot_mm, q.key)
    }

    pub(super) fn wippen(&self, q: Pose, x: V) -> V {
        turn(x, self.p.wippen.pivot_mm, q.wippen)
    }

    pub(super) fn hammer(&self, q: Pose, body: V) -> V {
        let h = &self.p.hammer;
        add(
            h.pivot_mm,
            rot(body, h.rest_angle_deg.to_radians() + q.hammer),
        )
    }

    pub(super) fn capstan(&self, q: Pose) -> (V, f64) {
        let k = &self.p.key;
        let c = [
            k.capstan_center_mm[0],
            k.capstan_center_mm[1] + self.p.regulation.capstan_raise_mm,
        ];
        (self.key(q, c), k.capstan_radius_mm)
    }

    pub(super) fn heel(&self, q: Pose) -> Face {
        let w = &self.p.wippen;
        let (h, l) = (w.heel_mm, w.heel_half_length_mm);
        Face {
            a: [h[0] + l, h[1]],
            b: [h[0] - l, h[1]],
        }
        .turned(w.pivot_mm, q.wippen)
    }

    pub(super) fn front_pad(&self, q: Pose) -> (V, f64) {
        let k = &self.p.key;
        (self.key(q, k.front_pad_mm), k.front_pad_radius_mm)
    }

    pub(super) fn back_pad(&self, q: Pose) -> (V, f64) {
        let k = &self.p.key;
        (self.key(q, k.back_pad_mm), k.back_pad_radius_mm)
    }

    /// A top face through `top` along `t`, `front` before and `back` after it.
    pub(super) fn top_face(&self, top: V, front: f64, back: f64) -> Face {
        Face {
            a: sub(top, scale(self.t, front)),
            b: add(top, scale(self.t, back)),
        }
    }

    pub(super) fn jack_top(&self, q: Pose) -> Face {
        let j = &self.p.jack;
        self.top_face(j.top_mm, j.top_front_edge_mm, j.top_back_edge_mm)
            .turned(self.p.wippen.pivot_mm, q.wippen)
    }

    pub(super) fn lever_top(&self, q: Pose) -> Face {
        let r = &self.p.repetition_lever;
        self.top_face(r.top_mm, r.top_front_edge_mm, r.top_back_edge_mm)
            .turned(self.p.wippen.pivot_mm, q.wippen)
    }

    pub(super) fn toe(&self, q: Pose) -> (V, f64) {
        let j = &self.p.jack;
        let c = [j.toe_mm[0], j.toe_mm[1] - j.toe_radius_mm];
        (self.wippen(q, c), j.toe_radius_mm)
    }

    pub(super) fn tip(&self, q: Pose) -> (V, f64) {
        let r = &self.p.repetition_lever;
        let c = [r.tip_mm[0], r.tip_mm[1] - r.tip_radius_mm];
        (self.wippen(q, c), r.tip_radius_mm)
    }

    pub(super) fn knuckle(&self, q: Pose) -> (V, f64) {
        let h = &self.p.hammer;
        (self.hammer(q, h.knuckle_body_mm), h.knuckle_radius_mm)
    }

    pub(super) fn crown(&self, q: Pose) -> (V, f64) {
        let h = &self.p.hammer;
        let c = [h.strike_body_mm[0], h.strike_body_mm[1] - h.crown_radius_mm];
        (self.hammer(q, c), h.crown_radius_mm)
    }

    pub(super) fn tail(&self, q: Pose) -> (V, f64) {
        let h = &self.p.hammer;
        (self.hammer(q, h.tail_body_mm), h.tail_radius_mm)
    }

    pub(super) fn shank(&self, q: Pose) -> (V, f64) {
        let h = &self.p.hammer;
        let c = [h.rest_body_mm[0], h.rest_body_mm[1] + 0.5];
        (self.hammer(q, c), 0.5)
    }

    /// The backcheck face on the key, facing the hammer tail at rest, moved along its
    /// normal by the regulation offset.
    pub(super) fn backcheck(&self, q: Pose) -> Face {
        let k = &self.p.key;
        let a = k.backcheck_face_angle_deg.to_radians();
        let mut d = [a.cos(), a.sin()];
        let (tail, _) = self.tail(Pose::default());
        if cross(d, sub(tail, k.backcheck_mm)) < 0.0 {
            d = scale(d, -1.0);
        }
        let normal = [-d[1], d[0]];
        let c = add(
            k.backcheck_mm,
            scale(normal, self.p.regulation.backcheck_offset_mm),
        );
        let l = k.backcheck_half_length_mm;
        Face {
            a: sub(c, scale(d, l)),
            b: add(c, scale(d, l)),
        }
        .turned(k.pivot_mm, q.key)
    }
}
