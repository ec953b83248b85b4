//! Planar spatial algebra (Featherstone, *Rigid Body Dynamics Algorithms*, ch. 2, planar case).
//!
//! In the plane a spatial vector has three components, angular first:
//!
//! - a motion vector `[w, vx, vy]`: angular velocity about z, and the velocity of the body-fixed
//!   point that is at the frame origin;
//! - a force vector `[n, fx, fy]`: moment about z at the frame origin, and the force.
//!
//! Their scalar product is power: `m · f = w n + vx fx + vy fy`.
//!
//! A [`Transform`] is the pose of a child frame C in a parent frame P, stored as
//! `(cos θ, sin θ, x, y)` (four numbers, never a 3×3 matrix). It maps motion vectors from
//! parent to child coordinates (Featherstone's `plnr(θ, r)`):
//!
//! ```text
//! X = [ 1              0   0 ]
//!     [ s·x − c·y      c   s ]      ω_C = ω_P,   v_C = Rᵀ (v_P + ω × r)
//!     [ c·x + s·y     −s   c ]
//! ```
//!
//! and forces from child to parent by `Xᵀ`.

use std::ops::{Add, AddAssign, Mul, Neg, Sub, SubAssign};

/// A planar spatial motion vector `[w, vx, vy]` (angular velocity about z, then the linear
/// velocity of the body point at the frame origin), expressed in some frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Angular component (rad/s or rad/s²), about z.
    pub w: f64,
    /// Linear component along the frame's x axis.
    pub vx: f64,
    /// Linear component along the frame's y axis.
    pub vy: f64,
}

/// A planar spatial force vector `[n, fx, fy]` (moment about z at the frame origin, then the
/// force), expressed in some frame.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Force {
    /// Moment about z at the frame origin (N·m).
    pub n: f64,
    /// Force along the frame's x axis (N).
    pub fx: f64,
    /// Force along the frame's y axis (N).
    pub fy: f64,
}

impl Motion {
    /// The zero motion.
    pub const ZERO: Motion = Motion {
        w: 0.0,
        vx: 0.0,
        vy: 0.0,
    };

    /// A motion vector from its components.
    pub const fn new(w: f64, vx: f64, vy: f64) -> Self {
        Self { w, vx, vy }
    }

    /// Motion cross product `self ×ₘ m` (Featherstone's `crm(self) · m`):
    /// `[0, vy·m_w − w·m_vy, −vx·m_w + w·m_vx]`.
    #[inline(always)]
    pub fn cross_motion(&self, m: &Motion) -> Motion {
        Motion {
            w: 0.0,
            vx: self.vy * m.w - self.w * m.vy,
            vy: -self.vx * m.w + self.w * m.vx,
        }
    }

    /// Force cross product `self ×f f` (Featherstone's `crf(self) · f`):
    /// `[vx·fy − vy·fx, −w·fy, w·fx]`.
    #[inline(always)]
    pub fn cross_force(&self, f: &Force) -> Force {
        Force {
            n: self.vx * f.fy - self.vy * f.fx,
            fx: -self.w * f.fy,
            fy: self.w * f.fx,
        }
    }

    /// Power of a force on this motion: `w n + vx fx + vy fy`.
    #[inline(always)]
    pub fn dot(&self, f: &Force) -> f64 {
        self.w * f.n + self.vx * f.fx + self.vy * f.fy
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.w.is_finite() && self.vx.is_finite() && self.vy.is_finite()
    }
}

impl Force {
    /// The zero force.
    pub const ZERO: Force = Force {
        n: 0.0,
        fx: 0.0,
        fy: 0.0,
    };

    /// A force vector from its components.
    pub const fn new(n: f64, fx: f64, fy: f64) -> Self {
        Self { n, fx, fy }
    }

    /// The spatial force, about the origin of the frame its point is expressed in, of a force
    /// `f` applied at point `p`: `[p × f, fx, fy]`.
    #[inline]
    pub fn at_point(p: [f64; 2], f: [f64; 2]) -> Self {
        Self {
            n: p[0] * f[1] - p[1] * f[0],
            fx: f[0],
            fy: f[1],
        }
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.n.is_finite() && self.fx.is_finite() && self.fy.is_finite()
    }
}

macro_rules! impl_vector_ops {
    ($t:ty, $a:ident, $b:ident, $c:ident) => {
        impl Add for $t {
            type Output = $t;
            #[inline(always)]
            fn add(self, o: $t) -> $t {
                Self {
                    $a: self.$a + o.$a,
                    $b: self.$b + o.$b,
                    $c: self.$c + o.$c,
                }
            }
        }
        impl Sub for $t {
            type Output = $t;
            #[inline(always)]
            fn sub(self, o: $t) -> $t {
                Self {
                    $a: self.$a - o.$a,
                    $b: self.$b - o.$b,
                    $c: self.$c - o.$c,
                }
            }
        }
        impl AddAssign for $t {
            #[inline(always)]
            fn add_assign(&mut self, o: $t) {
                self.$a += o.$a;
                self.$b += o.$b;
                self.$c += o.$c;
            }
        }
        impl SubAssign for $t {
            #[inline(always)]
            fn sub_assign(&mut self, o: $t) {
                self.$a -= o.$a;
                self.$b -= o.$b;
                self.$c -= o.$c;
            }
        }
        impl Mul<f64> for $t {
            type Output = $t;
            #[inline(always)]
            fn mul(self, k: f64) -> $t {
                Self {
                    $a: self.$a * k,
                    $b: self.$b * k,
                    $c: self.$c * k,
                }
            }
        }
        impl Neg for $t {
            type Output = $t;
            #[inline(always)]
            fn neg(self) -> $t {
                Self {
                    $a: -self.$a,
                    $b: -self.$b,
                    $c: -self.$c,
                }
            }
        }
    };
}
impl_vector_ops!(Motion, w, vx, vy);
impl_vector_ops!(Force, n, fx, fy);

/// The pose of a child frame C in a parent frame P: rotation angle θ (stored as cos, sin) and
/// the position `(x, y)` of C's origin in P coordinates. Used both as a pose and as the
/// Plücker transform between the two frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// cos θ.
    pub c: f64,
    /// sin θ.
    pub s: f64,
    /// x of the child origin in parent coordinates.
    pub x: f64,
    /// y of the child origin in parent coordinates.
    pub y: f64,
}

impl Default for Transform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Transform {
    /// The identity pose.
    pub const IDENTITY: Transform = Transform {
        c: 1.0,
        s: 0.0,
        x: 0.0,
        y: 0.0,
    };

    /// The pose rotated by `angle` (rad, counter-clockwise) with origin at `(x, y)`.
    pub fn new(angle: f64, x: f64, y: f64) -> Self {
        let (s, c) = angle.sin_cos();
        Self { c, s, x, y }
    }

    /// The rotation angle θ in (−π, π].
    pub fn angle(&self) -> f64 {
        self.s.atan2(self.c)
    }

    /// The origin of the child frame in parent coordinates.
    pub fn translation(&self) -> [f64; 2] {
        [self.x, self.y]
    }

    /// Composition `self ∘ other`: if `self` is the pose of B in A and `other` the pose of C in
    /// B, the result is the pose of C in A.
    #[inline(always)]
    pub fn compose(&self, other: &Transform) -> Transform {
        Transform {
            c: self.c * other.c - self.s * other.s,
            s: self.s * other.c + self.c * other.s,
            x: self.x + self.c * other.x - self.s * other.y,
            y: self.y + self.s * other.x + self.c * other.y,
        }
    }

    /// The inverse pose (the pose of P in C).
    pub fn inverse(&self) -> Transform {
        Transform {
            c: self.c,
            s: -self.s,
            x: -(self.c * self.x + self.s * self.y),
            y: self.s * self.x - self.c * self.y,
        }
    }

    /// Rotates a child-frame vector into parent coordinates: `R v`.
    #[inline(always)]
    pub fn rotate(&self, v: [f64; 2]) -> [f64; 2] {
        [self.c * v[0] - self.s * v[1], self.s * v[0] + self.c * v[1]]
    }

    /// Rotates a parent-frame vector into child coordinates: `Rᵀ v`.
    #[inline(always)]
    pub fn rotate_inv(&self, v: [f64; 2]) -> [f64; 2] {
        [
            self.c * v[0] + self.s * v[1],
            -self.s * v[0] + self.c * v[1],
        ]
    }

    /// Maps a point from child to parent coordinates: `r + R p`.
    #[inline(always)]
    pub fn transform_point(&self, p: [f64; 2]) -> [f64; 2] {
        let r = self.rotate(p);
        [self.x + r[0], self.y + r[1]]
    }

    /// Maps a point from parent to child coordinates: `Rᵀ (p − r)`.
    #[inline(always)]
    pub fn inverse_transform_point(&self, p: [f64; 2]) -> [f64; 2] {
        self.rotate_inv([p[0] - self.x, p[1] - self.y])
    }

    /// Motion from parent to child coordinates, `X m`: `ω_C = ω`, `v_C = Rᵀ (v + ω × r)`.
    #[inline(always)]
    pub fn apply_motion(&self, m: &Motion) -> Motion {
        // v + ω × r, with ω × r = (−ω y, ω x)
        let ux = m.vx - m.w * self.y;
        let uy = m.vy + m.w * self.x;
        Motion {
            w: m.w,
            vx: self.c * ux + self.s * uy,
            vy: -self.s * ux + self.c * uy,
        }
    }

    /// Motion from child to parent coordinates, `X⁻¹ m`: `v_P = R v − ω × r`.
    #[inline(always)]
    pub fn apply_motion_inv(&self, m: &Motion) -> Motion {
        let r = self.rotate([m.vx, m.vy]);
        Motion {
            w: m.w,
            vx: r[0] + m.w * self.y,
            vy: r[1] - m.w * self.x,
        }
    }

    /// Force from child to parent coordinates, `Xᵀ f`: `F_P = R F`, `n_P = n + r × F_P`.
    #[inline(always)]
    pub fn apply_force_transpose(&self, f: &Force) -> Force {
        let fx = self.c * f.fx - self.s * f.fy;
        let fy = self.s * f.fx + self.c * f.fy;
        Force {
            n: f.n + self.x * fy - self.y * fx,
            fx,
            fy,
        }
    }

    /// Force from parent to child coordinates, `X⁻ᵀ f`: `F_C = Rᵀ F`, `n_C = n − r × F`.
    #[inline(always)]
    pub fn apply_force(&self, f: &Force) -> Force {
        Force {
            n: f.n - (self.x * f.fy - self.y * f.fx),
            fx: self.c * f.fx + self.s * f.fy,
            fy: -self.s * f.fx + self.c * f.fy,
        }
    }
}

/// The rigid-body inertia of a body, about the origin of the frame it is expressed in:
/// mass `m`, first moment `h = m c` (c the centre of mass), and `i_o = I_c + m |c|²` the
/// rotational inertia about the frame origin. As a 3×3 matrix (Featherstone's `mcI`):
///
/// ```text
/// [ i_o  −hy   hx ]
/// [ −hy   m    0  ]
/// [  hx   0    m  ]
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Inertia {
    /// Mass (kg).
    pub m: f64,
    /// First moment of mass along x, `m · cx` (kg·m).
    pub hx: f64,
    /// First moment of mass along y, `m · cy` (kg·m).
    pub hy: f64,
    /// Rotational inertia about the frame origin (kg·m²).
    pub i_o: f64,
}

impl Inertia {
    /// The zero inertia.
    pub const ZERO: Inertia = Inertia {
        m: 0.0,
        hx: 0.0,
        hy: 0.0,
        i_o: 0.0,
    };

    /// The inertia of a body of mass `mass` with centre of mass at `com` and rotational
    /// inertia `izz_com` about its centre of mass.
    pub fn from_com(mass: f64, com: [f64; 2], izz_com: f64) -> Self {
        Self {
            m: mass,
            hx: mass * com[0],
            hy: mass * com[1],
            i_o: izz_com + Self::parallel_axis(mass, com),
        }
    }

    /// The parallel-axis term `m |c|²`: what a mass `mass` at `com` adds to the rotational
    /// inertia about the origin over its inertia about its own centre of mass
    /// (`I_o = I_c + m |c|²`). The one place this theorem is written.
    #[inline]
    pub fn parallel_axis(mass: f64, com: [f64; 2]) -> f64 {
        mass * (com[0] * com[0] + com[1] * com[1])
    }

    /// Centre of mass in the frame's coordinates (the origin when the mass is zero).
    pub fn com(&self) -> [f64; 2] {
        if self.m > 0.0 {
            [self.hx / self.m, self.hy / self.m]
        } else {
            [0.0, 0.0]
        }
    }

    /// Rotational inertia about the centre of mass.
    pub fn izz_com(&self) -> f64 {
        let c = self.com();
        self.i_o - self.m * (c[0] * c[0] + c[1] * c[1])
    }

    /// Momentum `I m` of a motion (a force vector).
    #[inline(always)]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        Force {
            n: self.i_o * v.w - self.hy * v.vx + self.hx * v.vy,
            fx: -self.hy * v.w + self.m * v.vx,
            fy: self.hx * v.w + self.m * v.vy,
        }
    }

    /// The same inertia expressed in the parent frame of `x` (`x` the pose of this frame in
    /// the parent): `Xᵀ I X`, which stays a rigid-body inertia:
    /// `h_P = R h + m r`, `i_o,P = i_o + 2 r·(R h) + m |r|²`.
    #[inline(always)]
    pub fn to_parent(&self, x: &Transform) -> Inertia {
        let rh = x.rotate([self.hx, self.hy]);
        Inertia {
            m: self.m,
            hx: rh[0] + self.m * x.x,
            hy: rh[1] + self.m * x.y,
            i_o: self.i_o + 2.0 * (x.x * rh[0] + x.y * rh[1]) + self.m * (x.x * x.x + x.y * x.y),
        }
    }
}

impl Add for Inertia {
    type Output = Inertia;
    #[inline(always)]
    fn add(self, o: Inertia) -> Inertia {
        Inertia {
            m: self.m + o.m,
            hx: self.hx + o.hx,
            hy: self.hy + o.hy,
            i_o: self.i_o + o.i_o,
        }
    }
}

impl AddAssign for Inertia {
    #[inline(always)]
    fn add_assign(&mut self, o: Inertia) {
        *self = *self + o;
    }
}

/// A symmetric 3×3 matrix mapping motions to forces: the articulated-body inertia of the
/// articulated-body algorithm (which is no longer of rigid-body form). Stored as its six
/// unique entries.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ArticulatedInertia {
    /// Entry (0, 0): angular–angular.
    pub a00: f64,
    /// Entry (0, 1).
    pub a01: f64,
    /// Entry (0, 2).
    pub a02: f64,
    /// Entry (1, 1).
    pub a11: f64,
    /// Entry (1, 2).
    pub a12: f64,
    /// Entry (2, 2).
    pub a22: f64,
}

impl From<Inertia> for ArticulatedInertia {
    #[inline(always)]
    fn from(i: Inertia) -> Self {
        Self {
            a00: i.i_o,
            a01: -i.hy,
            a02: i.hx,
            a11: i.m,
            a12: 0.0,
            a22: i.m,
        }
    }
}

impl ArticulatedInertia {
    /// `IA m`.
    #[inline(always)]
    pub fn mul_motion(&self, v: &Motion) -> Force {
        Force {
            n: self.a00 * v.w + self.a01 * v.vx + self.a02 * v.vy,
            fx: self.a01 * v.w + self.a11 * v.vx + self.a12 * v.vy,
            fy: self.a02 * v.w + self.a12 * v.vx + self.a22 * v.vy,
        }
    }

    /// `self − k u uᵀ` for a force-like column `u`.
    #[inline(always)]
    pub fn sub_outer(&self, u: &Force, k: f64) -> Self {
        Self {
            a00: self.a00 - k * u.n * u.n,
            a01: self.a01 - k * u.n * u.fx,
            a02: self.a02 - k * u.n * u.fy,
            a11: self.a11 - k * u.fx * u.fx,
            a12: self.a12 - k * u.fx * u.fy,
            a22: self.a22 - k * u.fy * u.fy,
        }
    }

    /// The same matrix in the parent frame of `x`: `Xᵀ IA X`. With `X = [[1, 0], [d, E]]`,
    /// `E = Rᵀ`, `d = (s x − c y, c x + s y)` and `IA = [[a, bᵀ], [b, C]]`:
    /// `a' = a + 2 b·d + dᵀ C d`, `b' = R (b + C d)`, `C' = R C Rᵀ`.
    #[inline(always)]
    pub fn to_parent(&self, x: &Transform) -> Self {
        let (c, s) = (x.c, x.s);
        let dx = s * x.x - c * x.y;
        let dy = c * x.x + s * x.y;
        // C d
        let cdx = self.a11 * dx + self.a12 * dy;
        let cdy = self.a12 * dx + self.a22 * dy;
        let a = self.a00 + 2.0 * (self.a01 * dx + self.a02 * dy) + dx * cdx + dy * cdy;
        // R (b + C d)
        let bx = self.a01 + cdx;
        let by = self.a02 + cdy;
        let b1 = c * bx - s * by;
        let b2 = s * bx + c * by;
        // R C Rᵀ
        let m00 = c * self.a11 - s * self.a12;
        let m01 = c * self.a12 - s * self.a22;
        let m10 = s * self.a11 + c * self.a12;
        let m11 = s * self.a12 + c * self.a22;
        Self {
            a00: a,
            a01: b1,
            a02: b2,
            a11: m00 * c - m01 * s,
            a12: m00 * s + m01 * c,
            a22: m10 * s + m11 * c,
        }
    }
}

impl Add for ArticulatedInertia {
    type Output = ArticulatedInertia;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        Self {
            a00: self.a00 + o.a00,
            a01: self.a01 + o.a01,
            a02: self.a02 + o.a02,
            a11: self.a11 + o.a11,
            a12: self.a12 + o.a12,
            a22: self.a22 + o.a22,
        }
    }
}

impl AddAssign for ArticulatedInertia {
    #[inline(always)]
    fn add_assign(&mut self, o: Self) {
        *self = *self + o;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn matrix_of(x: &Transform) -> [[f64; 3]; 3] {
        let mut m = [[0.0; 3]; 3];
        for (j, e) in [
            Motion::new(1.0, 0.0, 0.0),
            Motion::new(0.0, 1.0, 0.0),
            Motion::new(0.0, 0.0, 1.0),
        ]
        .iter()
        .enumerate()
        {
            let col = x.apply_motion(e);
            m[0][j] = col.w;
            m[1][j] = col.vx;
            m[2][j] = col.vy;
        }
        m
    }

    #[test]
    fn transform_matches_featherstone_plnr() {
        let x = Transform::new(0.7, 0.3, -1.2);
        let m = matrix_of(&x);
        let (s, c) = 0.7f64.sin_cos();
        let expect = [
            [1.0, 0.0, 0.0],
            [s * 0.3 - c * -1.2, c, s],
            [c * 0.3 + s * -1.2, -s, c],
        ];
        for i in 0..3 {
            for j in 0..3 {
                assert_relative_eq!(m[i][j], expect[i][j], epsilon = 1e-15);
            }
        }
    }

    #[test]
    fn power_is_frame_invariant_and_inverses_hold() {
        let x = Transform::new(-2.1, 0.4, 0.9);
        let mp = Motion::new(0.3, -1.1, 2.0);
        let fc = Force::new(0.5, 1.5, -0.7);
        let mc = x.apply_motion(&mp);
        // (X m_P) · f_C = m_P · (Xᵀ f_C)
        assert_relative_eq!(
            mc.dot(&fc),
            mp.dot(&x.apply_force_transpose(&fc)),
            epsilon = 1e-14
        );
        let back = x.apply_motion_inv(&mc);
        assert_relative_eq!(back.vx, mp.vx, epsilon = 1e-14);
        assert_relative_eq!(back.vy, mp.vy, epsilon = 1e-14);
        let f = x.apply_force(&x.apply_force_transpose(&fc));
        assert_relative_eq!(f.n, fc.n, epsilon = 1e-14);
        assert_relative_eq!(f.fy, fc.fy, epsilon = 1e-14);
        let id = x.compose(&x.inverse());
        assert_relative_eq!(id.x, 0.0, epsilon = 1e-15);
        assert_relative_eq!(id.s, 0.0, epsilon = 1e-15);
        let p = [0.2, -0.3];
        let q = x.inverse_transform_point(x.transform_point(p));
        assert_relative_eq!(q[0], p[0], epsilon = 1e-15);
        assert_relative_eq!(q[1], p[1], epsilon = 1e-15);
    }

    #[test]
    fn inertia_and_articulated_inertia_transform_alike() {
        let x = Transform::new(1.3, -0.6, 0.25);
        let i = Inertia::from_com(2.0, [0.3, -0.1], 0.05);
        let a: ArticulatedInertia = i.into();
        let ip: ArticulatedInertia = i.to_parent(&x).into();
        let ap = a.to_parent(&x);
        assert_relative_eq!(ip.a00, ap.a00, epsilon = 1e-14);
        assert_relative_eq!(ip.a01, ap.a01, epsilon = 1e-14);
        assert_relative_eq!(ip.a02, ap.a02, epsilon = 1e-14);
        assert_relative_eq!(ip.a11, ap.a11, epsilon = 1e-14);
        assert_relative_eq!(ip.a12, ap.a12, epsilon = 1e-14);
        assert_relative_eq!(ip.a22, ap.a22, epsilon = 1e-14);
        // Xᵀ I X m_P = Xᵀ (I (X m_P)) for any m_P.
        let mp = Motion::new(0.7, 0.2, -0.4);
        let lhs = ap.mul_motion(&mp);
        let rhs = x.apply_force_transpose(&a.mul_motion(&x.apply_motion(&mp)));
        assert_relative_eq!(lhs.n, rhs.n, epsilon = 1e-14);
        assert_relative_eq!(lhs.fx, rhs.fx, epsilon = 1e-14);
        assert_relative_eq!(lhs.fy, rhs.fy, epsilon = 1e-14);
        // Centre of mass and central inertia survive the round trip.
        assert_relative_eq!(i.izz_com(), 0.05, epsilon = 1e-15);
        assert_relative_eq!(i.to_parent(&x).izz_com(), 0.05, epsilon = 1e-14);
    }

    #[test]
    fn cross_products_are_derivatives_of_transforms() {
        // d/dt (X(t) m) for a frame rotating at w about its origin equals −v ×ₘ m.
        let v = Motion::new(0.9, 0.0, 0.0);
        let m = Motion::new(0.3, 1.0, -2.0);
        let h = 1e-6;
        let x = Transform::new(v.w * h, 0.0, 0.0);
        let xm = x.apply_motion(&m);
        let d = (xm - m) * (1.0 / h);
        let expect = -v.cross_motion(&m);
        assert_relative_eq!(d.vx, expect.vx, epsilon = 1e-5);
        assert_relative_eq!(d.vy, expect.vy, epsilon = 1e-5);
        // crf = −crmᵀ: (v ×ₘ m) · f = −m · (v ×f f)
        let f = Force::new(0.4, -0.2, 1.1);
        let v = Motion::new(0.5, 0.7, -0.3);
        assert_relative_eq!(
            v.cross_motion(&m).dot(&f),
            -m.dot(&v.cross_force(&f)),
            epsilon = 1e-14
        );
    }
}
