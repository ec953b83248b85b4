//! The pendulum (swing) test reduced to its one coordinate, fast enough to sit inside a
//! least-squares fit: the hammer alone on its flange pin, under gravity, **true Coulomb
//! friction that sticks** (no regularisation: a stuck hammer stays stuck, where a `tanh`
//! law would creep) and the flange effects of [`FlangeEffects`].
//!
//! With φ the shank's angle above horizontal, c the centre of mass in the hammer frame,
//! r = R(φ) c and I_O = I_G + m |c|²:
//!
//! `I_O φ̈ = −m g r_x − s (T_c + d_s e^{−(ω/ω_s)²} + μ_r |F_pin|) − c ω − c_d ω|ω|`,
//!
//! s = sign(ω), and `F_pin = m (a_G − g)` the pin's reaction, a_G = α ẑ × r − ω² r. At
//! each reversal (ω = 0, located inside the step) the hammer sticks if the gravity torque
//! is within the static friction `T_c + d_s + μ_r m g`, else it moves off the other way.
//!
//! Classical RK4 on a fixed step with the reversals located exactly; between steps the
//! motion is the quintic Hermite interpolant of angle, rate and acceleration, so a camera
//! frame can sample it anywhere (O(h⁶)). A test checks it against the multibody swing
//! ([`crate::pendulum::swing`]), which builds the same hammer in `mbs-core`.

use mbs_identify::Camera;

use super::effects::FlangeEffects;
use crate::params::ActionParams;

pub use crate::params::GRAVITY_M_S2;

/// The hammer on its pin, with its flange laws.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwingModel {
    /// Mass (kg).
    pub mass_kg: f64,
    /// Centre of mass in the hammer frame (m; origin at the pin, x along the shank).
    pub com_m: [f64; 2],
    /// Inertia about the centre of mass (kg·m²).
    pub inertia_com_kg_m2: f64,
    /// Coulomb friction of the flange (N·m).
    pub coulomb_n_m: f64,
    /// The effects on the flange.
    pub effects: FlangeEffects,
    /// Integration step (s).
    pub step_s: f64,
}

/// One step of the motion: its start time, length and the angle, rate and acceleration
/// at both ends (the accelerations with the step's own friction direction).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Step {
    t0: f64,
    h: f64,
    a: [f64; 3],
    b: [f64; 3],
}

/// A simulated swing: the angle at any time.
#[derive(Clone, Debug, PartialEq)]
pub struct SwingPath {
    release_rad: f64,
    steps: Vec<Step>,
    /// Where and when the hammer stuck for good, if it did.
    pub stuck: Option<(f64, f64)>,
    /// Reversal times (s) and angles (rad), the last one the stop if it stuck.
    pub reversals: Vec<(f64, f64)>,
    end_s: f64,
}

/// Default integration step (s) [D]: RK4's error at 4 kHz is below 1e-9 rad over a
/// 4 s swing of this hammer (ω ≈ 9 rad/s).
pub const DEFAULT_STEP_S: f64 = 2.5e-4;

impl SwingModel {
    /// The hammer of `params` with its flange friction and `effects`.
    pub fn from_params(params: &ActionParams, effects: FlangeEffects) -> Self {
        let h = &params.hammer;
        Self {
            mass_kg: h.mass_g * 1e-3,
            com_m: [h.com_body_mm[0] * 1e-3, h.com_body_mm[1] * 1e-3],
            inertia_com_kg_m2: h.inertia_com_kg_m2,
            coulomb_n_m: h.pivot_friction_n_m,
            effects,
            step_s: DEFAULT_STEP_S,
        }
    }

    /// Inertia about the pin (kg·m²).
    pub fn inertia_pin_kg_m2(&self) -> f64 {
        let [cx, cy] = self.com_m;
        self.inertia_com_kg_m2 + self.mass_kg * (cx * cx + cy * cy)
    }

    /// The centre of mass in the world at angle `phi`.
    fn com_world(&self, phi: f64) -> [f64; 2] {
        let (s, c) = phi.sin_cos();
        let [cx, cy] = self.com_m;
        [c * cx - s * cy, s * cx + c * cy]
    }

    /// Gravity's torque about the pin at angle `phi` (N·m).
    pub fn gravity_torque(&self, phi: f64) -> f64 {
        -self.mass_kg * GRAVITY_M_S2 * self.com_world(phi)[0]
    }

    /// The largest torque the flange holds at rest (N·m).
    pub fn static_friction_n_m(&self) -> f64 {
        self.coulomb_n_m
            + self.effects.stribeck_n_m
            + self.effects.load_friction_m * self.mass_kg * GRAVITY_M_S2
    }

    /// The pin's reaction (N) at angle `phi`, rate `omega`, acceleration `alpha`.
    fn pin_force(&self, phi: f64, omega: f64, alpha: f64) -> f64 {
        let r = self.com_world(phi);
        let w2 = omega * omega;
        let fx = self.mass_kg * (-alpha * r[1] - w2 * r[0]);
        let fy = self.mass_kg * (alpha * r[0] - w2 * r[1] + GRAVITY_M_S2);
        fx.hypot(fy)
    }

    /// Angular acceleration moving in direction `dir` (±1).
    fn acceleration(&self, phi: f64, omega: f64, dir: f64, inertia: f64) -> f64 {
        let e = &self.effects;
        let base = self.gravity_torque(phi) + e.damping_torque(omega)
            - dir * (self.coulomb_n_m + e.friction_level(omega, 0.0));
        let mut alpha = base / inertia;
        if e.needs_pin_force() {
            // The load friction depends on the reaction, which depends on α: a fixed
            // point, contracting since μ_r m |r| ≪ I_O.
            for _ in 0..3 {
                let f = self.pin_force(phi, omega, alpha);
                alpha = (base - dir * e.load_friction_m * f) / inertia;
            }
        }
        alpha
    }

    /// Simulates the release from rest at shank angle `release_rad` (rad above horizontal)
    /// at t = 0, for `duration_s`.
    pub fn simulate(&self, release_rad: f64, duration_s: f64) -> SwingPath {
        let inertia = self.inertia_pin_kg_m2();
        let acc = |phi: f64, omega: f64, dir: f64| self.acceleration(phi, omega, dir, inertia);
        let rk4 = |phi: f64, omega: f64, dir: f64, h: f64| {
            let k1 = (omega, acc(phi, omega, dir));
            let k2 = (
                omega + 0.5 * h * k1.1,
                acc(phi + 0.5 * h * k1.0, omega + 0.5 * h * k1.1, dir),
            );
            let k3 = (
                omega + 0.5 * h * k2.1,
                acc(phi + 0.5 * h * k2.0, omega + 0.5 * h * k2.1, dir),
            );
            let k4 = (omega + h * k3.1, acc(phi + h * k3.0, omega + h * k3.1, dir));
            (
                phi + h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
                omega + h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
            )
        };
        let mut path = SwingPath {
            release_rad,
            steps: Vec::with_capacity((duration_s / self.step_s) as usize + 16),
            stuck: None,
            reversals: Vec::new(),
            end_s: duration_s,
        };
        let (mut t, mut phi, mut omega) = (0.0, release_rad, 0.0);
        let mut dir = 0.0;
        // Reversals are bounded: each costs the swing at least 2 T_c/k of amplitude.
        let mut events_left = 100_000usize;
        while t < duration_s {
            if omega == 0.0 {
                let tg = self.gravity_torque(phi);
                if tg.abs() <= self.static_friction_n_m() || events_left == 0 {
                    path.stuck = Some((t, phi));
                    break;
                }
                dir = tg.signum();
                events_left -= 1;
            }
            let h = self.step_s.min(duration_s - t);
            let a0 = acc(phi, omega, dir);
            let (p1, w1) = rk4(phi, omega, dir, h);
            if w1 * dir > 0.0 {
                let a1 = acc(p1, w1, dir);
                path.steps.push(Step {
                    t0: t,
                    h,
                    a: [phi, omega, a0],
                    b: [p1, w1, a1],
                });
                (t, phi, omega) = (t + h, p1, w1);
                continue;
            }
            // The rate reverses inside the step: find where on the cubic Hermite of ω
            // (bisection; ω is monotone there), step exactly to it and stop.
            let a1 = acc(p1, w1, dir);
            let hermite_w = |s: f64| {
                let s2 = s * s;
                let s3 = s2 * s;
                (2.0 * s3 - 3.0 * s2 + 1.0) * omega
                    + (s3 - 2.0 * s2 + s) * h * a0
                    + (-2.0 * s3 + 3.0 * s2) * w1
                    + (s3 - s2) * h * a1
            };
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if hermite_w(mid) * dir > 0.0 {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let hs = (0.5 * (lo + hi) * h).max(1e-12);
            let (ps, _) = rk4(phi, omega, dir, hs);
            let stop_acc = acc(ps, 0.0, dir);
            path.steps.push(Step {
                t0: t,
                h: hs,
                a: [phi, omega, a0],
                b: [ps, 0.0, stop_acc],
            });
            (t, phi, omega) = (t + hs, ps, 0.0);
            path.reversals.push((t, phi));
        }
        path
    }
}

impl SwingPath {
    /// The shank angle (rad) at time `t` (s): the release angle before 0, the stuck angle
    /// after the stop, the last value past the end.
    pub fn angle(&self, t: f64) -> f64 {
        self.angle_near(t, &mut 0)
    }

    /// [`SwingPath::angle`] with a search hint: `cursor` is where the last call found its
    /// step, so monotone or nearby queries cost O(1).
    pub fn angle_near(&self, t: f64, cursor: &mut usize) -> f64 {
        let Some(first) = self.steps.first() else {
            return self.stuck.map_or(self.release_rad, |s| s.1);
        };
        if t <= first.t0 {
            return self.release_rad;
        }
        let last = self.steps[self.steps.len() - 1];
        if t >= last.t0 + last.h {
            return self.stuck.map_or(last.b[0], |s| s.1);
        }
        let mut i = (*cursor).min(self.steps.len() - 1);
        while t < self.steps[i].t0 {
            i -= 1;
        }
        while t > self.steps[i].t0 + self.steps[i].h {
            i += 1;
        }
        *cursor = i;
        let st = &self.steps[i];
        let s = ((t - st.t0) / st.h).clamp(0.0, 1.0);
        quintic_hermite(s, st.h, st.a, st.b)
    }

    /// The end of the simulated time (s).
    pub fn end_s(&self) -> f64 {
        self.end_s
    }

    /// What `camera` records of the marker at `local_m` (hammer frame) in the frames
    /// stamped `times`.
    pub fn frames(&self, camera: &Camera, times: &[f64], local_m: [f64; 2]) -> Vec<[f64; 2]> {
        let mut cursor = 0;
        times
            .iter()
            .map(|&t| {
                let mut sum = [0.0; 2];
                for (time, w) in camera.samples(t) {
                    let (s, c) = self.angle_near(time, &mut cursor).sin_cos();
                    sum[0] += w * (c * local_m[0] - s * local_m[1]);
                    sum[1] += w * (s * local_m[0] + c * local_m[1]);
                }
                sum
            })
            .collect()
    }
}

/// The quintic Hermite interpolant at `s` ∈ [0, 1] of a step of length `h` with
/// (position, rate, acceleration) `a` at its start and `b` at its end.
fn quintic_hermite(s: f64, h: f64, a: [f64; 3], b: [f64; 3]) -> f64 {
    let s2 = s * s;
    let s3 = s2 * s;
    let s4 = s3 * s;
    let s5 = s4 * s;
    let h0 = 1.0 - 10.0 * s3 + 15.0 * s4 - 6.0 * s5;
    let h1 = s - 6.0 * s3 + 8.0 * s4 - 3.0 * s5;
    let h2 = 0.5 * (s2 - 3.0 * s3 + 3.0 * s4 - s5);
    let h3 = 0.5 * (s3 - 2.0 * s4 + s5);
    let h4 = -4.0 * s3 + 7.0 * s4 - 3.0 * s5;
    let h5 = 10.0 * s3 - 15.0 * s4 + 6.0 * s5;
    h0 * a[0] + h * (h1 * a[1] + h4 * b[1]) + h * h * (h2 * a[2] + h3 * b[2]) + h5 * b[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quintic_hermite_reproduces_a_quintic() {
        let p =
            |t: f64| 1.0 - 2.0 * t + 0.5 * t * t + 3.0 * t.powi(3) - t.powi(4) + 0.7 * t.powi(5);
        let v = |t: f64| -2.0 + t + 9.0 * t * t - 4.0 * t.powi(3) + 3.5 * t.powi(4);
        let a = |t: f64| 1.0 + 18.0 * t - 12.0 * t * t + 14.0 * t.powi(3);
        let (t0, h) = (0.3, 0.7);
        for k in 0..=10 {
            let s = k as f64 / 10.0;
            let got = quintic_hermite(
                s,
                h,
                [p(t0), v(t0), a(t0)],
                [p(t0 + h), v(t0 + h), a(t0 + h)],
            );
            assert!((got - p(t0 + s * h)).abs() < 1e-12, "s = {s}");
        }
    }
}
