//! Constitutive laws: the normal force as a function of penetration (and its rate and
//! history), and the tangential (friction) force.

use crate::error::{ContactError, Result};

/// A normal contact law: the compressive force between two bodies as a function of the
/// penetration `δ` (m, positive when the surfaces overlap), its rate `δ̇` (m/s, positive
/// when approaching) and, for hereditary laws, internal states integrated with the system.
///
/// Laws never pull: the force is ≥ 0, and 0 whenever `δ ≤ 0`.
pub trait NormalLaw: Send + Sync + std::fmt::Debug {
    /// Number of internal states (0 for memoryless laws).
    fn state_count(&self) -> usize {
        0
    }

    /// The normal force (N, ≥ 0). `states` are the law's internal states; their rates are
    /// written into `rates` (same length), also when out of contact (memory relaxes).
    fn force(&self, delta: f64, delta_dot: f64, states: &[f64], rates: &mut [f64]) -> f64;

    /// The tangent stiffness `∂F/∂δ` (N/m) at fixed `delta_dot` and states, when the law
    /// knows it in closed form; `None` (the default) when it does not, and callers that
    /// need it (the series felt–string spring of [`crate::StringContact`]) then take a
    /// finite difference of [`NormalLaw::force`].
    fn tangent_stiffness(&self, _delta: f64, _delta_dot: f64, _states: &[f64]) -> Option<f64> {
        None
    }

    /// The rate derivative `∂F/∂δ̇` (N·s/m) at fixed `delta` and states, when the law knows
    /// it in closed form; `None` (the default) when it does not, and callers that need it
    /// (a contact's Jacobian, [`crate::Contact`]) then take a central difference.
    fn rate_derivative(&self, _delta: f64, _delta_dot: f64, _states: &[f64]) -> Option<f64> {
        None
    }

    /// Whether the law ignores `delta_dot` altogether: neither the force nor the rates of
    /// its internal states depend on it (a purely elastic law such as [`Hertz`]). `false`
    /// by default: the law may depend on the rate. [`crate::StringContact`] relies on it to
    /// leave the string's modes out of an implicit integrator's Jacobian.
    fn rate_independent(&self) -> bool {
        false
    }
}

/// A tangential (friction) law: the friction force opposing the slip velocity, given the
/// normal force.
pub trait TangentialLaw: Send + Sync + std::fmt::Debug {
    /// Friction force along the tangent (N), opposing `slip` (m/s), for normal force
    /// `normal` (N, ≥ 0).
    fn force(&self, normal: f64, slip: f64) -> f64;
}

/// Checks a parameter is finite (and positive or non-negative), naming it.
pub(crate) fn check(law: &str, field: &str, value: f64, positive: bool) -> Result<f64> {
    use mbs_core::check::{Bound, check_value};
    let bound = if positive {
        Bound::Positive
    } else {
        Bound::NonNegative
    };
    check_value(value, bound).map_err(|message| ContactError::InvalidParameter {
        item: format!("{law}.{field}"),
        message,
    })
}

/// Checks a parameter lies in `[0, 1)` (or `(0, 1]` when `restitution`), naming it.
fn check_fraction(law: &str, field: &str, value: f64, restitution: bool) -> Result<f64> {
    let ok = if restitution {
        value > 0.0 && value <= 1.0
    } else {
        (0.0..1.0).contains(&value)
    };
    if ok {
        Ok(value)
    } else {
        Err(ContactError::InvalidParameter {
            item: format!("{law}.{field}"),
            message: format!(
                "must lie in {}, got {value}",
                if restitution { "(0, 1]" } else { "[0, 1)" }
            ),
        })
    }
}

/// `δ^n` for `δ > 0` (callers handle `δ ≤ 0`), with the common Hertz exponent fast.
#[inline]
fn power(delta: f64, n: f64) -> f64 {
    if n == 1.5 {
        delta * delta.sqrt()
    } else {
        delta.powf(n)
    }
}

impl<L: NormalLaw + ?Sized> NormalLaw for Box<L> {
    fn state_count(&self) -> usize {
        (**self).state_count()
    }

    fn force(&self, delta: f64, delta_dot: f64, states: &[f64], rates: &mut [f64]) -> f64 {
        (**self).force(delta, delta_dot, states, rates)
    }

    fn tangent_stiffness(&self, delta: f64, delta_dot: f64, states: &[f64]) -> Option<f64> {
        (**self).tangent_stiffness(delta, delta_dot, states)
    }

    fn rate_derivative(&self, delta: f64, delta_dot: f64, states: &[f64]) -> Option<f64> {
        (**self).rate_derivative(delta, delta_dot, states)
    }

    fn rate_independent(&self) -> bool {
        (**self).rate_independent()
    }
}

impl<L: NormalLaw + ?Sized> NormalLaw for std::sync::Arc<L> {
    fn state_count(&self) -> usize {
        (**self).state_count()
    }

    fn force(&self, delta: f64, delta_dot: f64, states: &[f64], rates: &mut [f64]) -> f64 {
        (**self).force(delta, delta_dot, states, rates)
    }

    fn tangent_stiffness(&self, delta: f64, delta_dot: f64, states: &[f64]) -> Option<f64> {
        (**self).tangent_stiffness(delta, delta_dot, states)
    }

    fn rate_derivative(&self, delta: f64, delta_dot: f64, states: &[f64]) -> Option<f64> {
        (**self).rate_derivative(delta, delta_dot, states)
    }

    fn rate_independent(&self) -> bool {
        (**self).rate_independent()
    }
}

impl<L: TangentialLaw + ?Sized> TangentialLaw for Box<L> {
    fn force(&self, normal: f64, slip: f64) -> f64 {
        (**self).force(normal, slip)
    }
}

impl<L: TangentialLaw + ?Sized> TangentialLaw for std::sync::Arc<L> {
    fn force(&self, normal: f64, slip: f64) -> f64 {
        (**self).force(normal, slip)
    }
}

// ---------------------------------------------------------------------------------------
// Normal laws
// ---------------------------------------------------------------------------------------

/// Linear spring and dashpot in parallel (Kelvin–Voigt):
///
/// `F = max(0, k δ + c δ̇)` for `δ > 0`, `F = 0` otherwise.
///
/// The clip keeps the dashpot from pulling the surfaces together while they separate
/// (the classic defect of the unclipped law, which also makes the force jump to `c v₀` at
/// first touch). Simple and cheap; for felt prefer a power law with Hunt–Crossley damping
/// (Hunt & Crossley, J. Appl. Mech. 42:440, 1975, discuss this defect).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KelvinVoigt {
    stiffness: f64,
    damping: f64,
}

impl KelvinVoigt {
    /// A Kelvin–Voigt law with stiffness `k` (N/m, > 0) and damping `c` (N·s/m, ≥ 0).
    /// Errors name `kelvin_voigt.stiffness` or `kelvin_voigt.damping`.
    pub fn new(stiffness: f64, damping: f64) -> Result<Self> {
        Ok(Self {
            stiffness: check("kelvin_voigt", "stiffness", stiffness, true)?,
            damping: check("kelvin_voigt", "damping", damping, false)?,
        })
    }

    /// Stiffness `k` (N/m).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Damping `c` (N·s/m).
    pub fn damping(&self) -> f64 {
        self.damping
    }
}

impl NormalLaw for KelvinVoigt {
    fn force(&self, delta: f64, delta_dot: f64, _states: &[f64], _rates: &mut [f64]) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        (self.stiffness * delta + self.damping * delta_dot).max(0.0)
    }

    fn tangent_stiffness(&self, delta: f64, delta_dot: f64, _states: &[f64]) -> Option<f64> {
        // ∂F/∂δ = k where the force is positive.
        let active = delta > 0.0 && self.stiffness * delta + self.damping * delta_dot > 0.0;
        Some(if active { self.stiffness } else { 0.0 })
    }

    fn rate_derivative(&self, delta: f64, delta_dot: f64, _states: &[f64]) -> Option<f64> {
        // ∂F/∂δ̇ = c where the force is positive.
        let active = delta > 0.0 && self.stiffness * delta + self.damping * delta_dot > 0.0;
        Some(if active { self.damping } else { 0.0 })
    }
}

/// Elastic power law (Hertz): `F = k δⁿ` for `δ > 0`.
///
/// With `n = 3/2` this is Hertz's law for two elastic bodies with curved surfaces,
/// `k = (4/3) E* √R` (K. L. Johnson, *Contact Mechanics*, CUP 1985, §4.2; see
/// [`Hertz::from_moduli`]). Other exponents give the pure power-law felt of
/// Chaigne & Askenfelt (JASA 95(2):1112, 1994; hammer C4: `p = 2.5`, `K = 4.5e9 N/m^2.5`).
/// Conservative: no energy is lost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hertz {
    stiffness: f64,
    exponent: f64,
}

impl Hertz {
    /// Hertz's exponent for curved elastic surfaces.
    pub const DEFAULT_EXPONENT: f64 = 1.5;

    /// `F = k δⁿ` with `k` (N/mⁿ, > 0) and `n` (> 0). Errors name `hertz.stiffness` or
    /// `hertz.exponent`.
    pub fn new(stiffness: f64, exponent: f64) -> Result<Self> {
        Ok(Self {
            stiffness: check("hertz", "stiffness", stiffness, true)?,
            exponent: check("hertz", "exponent", exponent, true)?,
        })
    }

    /// `F = k δ^{3/2}` (the Hertz exponent [`Hertz::DEFAULT_EXPONENT`]).
    pub fn with_stiffness(stiffness: f64) -> Result<Self> {
        Self::new(stiffness, Self::DEFAULT_EXPONENT)
    }

    /// Hertz contact of two elastic bodies (Young's moduli `e1`, `e2` in Pa, Poisson's
    /// ratios `nu1`, `nu2` in `[0, 0.5)`) with effective radius `radius` (m,
    /// `1/R = 1/R₁ + 1/R₂`): `k = (4/3) E* √R`, `1/E* = (1−ν₁²)/E₁ + (1−ν₂²)/E₂`
    /// (Johnson 1985, eqs. 4.22–4.23). This is the sphere–sphere stiffness, commonly used for
    /// planar cylinder contacts too as a lumped estimate. Errors name `hertz.young1`,
    /// `hertz.poisson1`, ..., `hertz.radius`.
    pub fn from_moduli(e1: f64, nu1: f64, e2: f64, nu2: f64, radius: f64) -> Result<Self> {
        let e1 = check("hertz", "young1", e1, true)?;
        let e2 = check("hertz", "young2", e2, true)?;
        let r = check("hertz", "radius", radius, true)?;
        let poisson = |field: &str, nu: f64| {
            if nu.is_finite() && (0.0..0.5).contains(&nu) {
                Ok(nu)
            } else {
                Err(ContactError::InvalidParameter {
                    item: format!("hertz.{field}"),
                    message: format!("must lie in [0, 0.5), got {nu}"),
                })
            }
        };
        let nu1 = poisson("poisson1", nu1)?;
        let nu2 = poisson("poisson2", nu2)?;
        let e_star = 1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2);
        Self::new(4.0 / 3.0 * e_star * r.sqrt(), Self::DEFAULT_EXPONENT)
    }

    /// Stiffness `k` (N/mⁿ).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Exponent `n`.
    pub fn exponent(&self) -> f64 {
        self.exponent
    }
}

impl NormalLaw for Hertz {
    fn force(&self, delta: f64, _delta_dot: f64, _states: &[f64], _rates: &mut [f64]) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        self.stiffness * power(delta, self.exponent)
    }

    fn tangent_stiffness(&self, delta: f64, _delta_dot: f64, _states: &[f64]) -> Option<f64> {
        // ∂F/∂δ = n k δⁿ⁻¹
        if delta <= 0.0 {
            return Some(0.0);
        }
        Some(self.exponent * self.stiffness * power(delta, self.exponent) / delta)
    }

    fn rate_derivative(&self, _delta: f64, _delta_dot: f64, _states: &[f64]) -> Option<f64> {
        Some(0.0)
    }

    fn rate_independent(&self) -> bool {
        true
    }
}

/// Hunt–Crossley: a power-law spring with a damping proportional to the elastic force,
///
/// `F = k δⁿ + λ δⁿ δ̇ = k δⁿ (1 + (3/2) α δ̇)`, clipped to `F ≥ 0`, `F = 0` for `δ ≤ 0`,
///
/// with `λ = (3/2) α k` (Hunt & Crossley, "Coefficient of restitution interpreted as
/// damping in vibroimpact", J. Appl. Mech. 42:440–445, 1975). Hunt and Crossley relate the
/// material constant `α` (s/m) to the restitution by `e ≈ 1 − α v₀` for an impact at speed
/// `v₀` (first order in `α v₀`), so `e` falls with impact speed; given a target `e` at a
/// reference speed, `α = (1 − e)/v₀`, i.e. `λ = 3k(1 − e)/(2 v₀)`
/// ([`HuntCrossley::from_restitution`]). The force starts and ends at zero, so there is no
/// jump at first touch and no pull at separation (the clip never acts in a free impact).
///
/// **Exact restitution.** For a mass on this law, `m δ̇ dδ̇/ds = −k (1 + c δ̇)` with
/// `s = δⁿ⁺¹/(n+1)` and `c = (3/2) α`, independent of `n`; integrating over the impact gives
/// the restitution `e = b/a` at impact speed `v₀` through
/// `a − ln(1 + a) = −b − ln(1 − b)`, `a = c v₀`, `b = c v_out`
/// (cf. Carvalho & Martins, Mech. Mach. Theory 139:174, 2019).
/// [`HuntCrossley::restitution_at`] evaluates it and
/// [`HuntCrossley::from_restitution_exact`] inverts it. The first-order relation
/// under-dissipates: targets 0.95, 0.9, 0.8, 0.5 give 0.9524, 0.9090, 0.8329, 0.6630
/// (computed, and confirmed by simulation in the crate tests).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HuntCrossley {
    stiffness: f64,
    exponent: f64,
    alpha: f64,
}

impl HuntCrossley {
    /// `F = k δⁿ (1 + (3/2) α δ̇)` with `k` (N/mⁿ, > 0), `n` (> 0) and the damping factor
    /// `α` (s/m, ≥ 0). Errors name `hunt_crossley.stiffness`, `.exponent` or `.alpha`.
    pub fn new(stiffness: f64, exponent: f64, alpha: f64) -> Result<Self> {
        Ok(Self {
            stiffness: check("hunt_crossley", "stiffness", stiffness, true)?,
            exponent: check("hunt_crossley", "exponent", exponent, true)?,
            alpha: check("hunt_crossley", "alpha", alpha, false)?,
        })
    }

    /// The Hunt–Crossley law whose first-order restitution at impact speed `v0` (m/s, > 0)
    /// is `e` (in `(0, 1]`): `α = (1 − e)/v₀`, i.e. `λ = 3k(1 − e)/(2 v₀)`. Errors name
    /// `hunt_crossley.restitution` or `hunt_crossley.impact_velocity`.
    pub fn from_restitution(stiffness: f64, exponent: f64, e: f64, v0: f64) -> Result<Self> {
        let e = check_fraction("hunt_crossley", "restitution", e, true)?;
        let v0 = check("hunt_crossley", "impact_velocity", v0, true)?;
        Self::new(stiffness, exponent, (1.0 - e) / v0)
    }

    /// Stiffness `k` (N/mⁿ).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Exponent `n`.
    pub fn exponent(&self) -> f64 {
        self.exponent
    }

    /// Damping factor `α` (s/m).
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// Hunt and Crossley's damping coefficient `λ = (3/2) α k` (N·s/m^{n+1}).
    pub fn lambda(&self) -> f64 {
        1.5 * self.alpha * self.stiffness
    }

    /// The Hunt–Crossley law whose *exact* restitution at impact speed `v0` (m/s, > 0) is
    /// `e` (in `(0, 1]`): solves `a − ln(1 + a) = −e a − ln(1 − e a)` for `a = (3/2) α v₀`
    /// (see the type's documentation). Errors as [`HuntCrossley::from_restitution`].
    pub fn from_restitution_exact(stiffness: f64, exponent: f64, e: f64, v0: f64) -> Result<Self> {
        let e = check_fraction("hunt_crossley", "restitution", e, true)?;
        let v0 = check("hunt_crossley", "impact_velocity", v0, true)?;
        Self::new(stiffness, exponent, hc_damping_for(e) / (1.5 * v0))
    }

    /// The exact restitution `v_out/v₀` of a free impact at speed `v0` (m/s) on this law
    /// (any mass, stiffness and exponent): `b/a` with `a − ln(1 + a) = −b − ln(1 − b)`,
    /// `a = (3/2) α v₀`. Tends to `1 − α v₀` as `α v₀ → 0`.
    pub fn restitution_at(&self, v0: f64) -> f64 {
        hc_restitution(1.5 * self.alpha * v0.abs())
    }
}

/// Exact restitution of the Hunt–Crossley form for `a = c v₀` (`c` the coefficient of `δ̇`
/// in `1 + c δ̇`): `b/a` where `−b − ln(1 − b) = a − ln(1 + a)`, `b ∈ (0, 1)`.
fn hc_restitution(a: f64) -> f64 {
    if a.is_nan() || a <= 0.0 {
        return 1.0;
    }
    if !a.is_finite() {
        return 0.0;
    }
    let target = a - a.ln_1p();
    // −b − ln(1 − b) rises from 0 (b = 0) to ∞ (b → 1): bisection.
    let (mut lo, mut hi) = (0.0f64, 1.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if -mid - (-mid).ln_1p() < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi) / a
}

/// The `a = c v₀` at which the Hunt–Crossley form has restitution `e ∈ (0, 1]`: the root
/// in `(0, 1/e)` of `g(a) = a − ln(1 + a) + e a + ln(1 − e a)`, positive below it and
/// negative above (g rises up to `a = (1 − e)/e`, then falls to −∞).
fn hc_damping_for(e: f64) -> f64 {
    if e >= 1.0 {
        return 0.0;
    }
    let g = |a: f64| a - a.ln_1p() + e * a + (-e * a).ln_1p();
    let (mut lo, mut hi) = (0.0f64, 1.0 / e);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if g(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

impl NormalLaw for HuntCrossley {
    fn force(&self, delta: f64, delta_dot: f64, _states: &[f64], _rates: &mut [f64]) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        (self.stiffness * power(delta, self.exponent) * (1.0 + 1.5 * self.alpha * delta_dot))
            .max(0.0)
    }

    fn tangent_stiffness(&self, delta: f64, delta_dot: f64, _states: &[f64]) -> Option<f64> {
        // ∂F/∂δ = n k δⁿ⁻¹ (1 + (3/2) α δ̇) where the force is positive.
        let damping = 1.0 + 1.5 * self.alpha * delta_dot;
        if delta <= 0.0 || damping <= 0.0 {
            return Some(0.0);
        }
        Some(self.exponent * self.stiffness * power(delta, self.exponent) / delta * damping)
    }

    fn rate_derivative(&self, delta: f64, delta_dot: f64, _states: &[f64]) -> Option<f64> {
        // ∂F/∂δ̇ = (3/2) α k δⁿ where the force is positive.
        let damping = 1.0 + 1.5 * self.alpha * delta_dot;
        if delta <= 0.0 || damping <= 0.0 {
            return Some(0.0);
        }
        Some(1.5 * self.alpha * self.stiffness * power(delta, self.exponent))
    }
}

/// Lankarani–Nikravesh: the Hunt–Crossley form with the damping chosen by an energy
/// balance over the impact,
///
/// `F = k δⁿ (1 + 3(1 − e²)/4 · δ̇/v₀)`, clipped to `F ≥ 0`, `F = 0` for `δ ≤ 0`,
///
/// i.e. `λ = 3k(1 − e²)/(4 v₀)` (Lankarani & Nikravesh, "A contact force model with
/// hysteresis damping for impact analysis of multibody systems", J. Mech. Des. 112:369–376,
/// 1990). The energy lost in the hysteresis loop, `ΔE ≈ (1 − e²) m v₀²/2`, is evaluated on
/// the undamped trajectory, so the law reaches the restitution `e` at the impact speed `v₀`
/// only for `e` near 1 and dissipates less than targeted below: targets 0.95, 0.9, 0.8, 0.5
/// give 0.9535, 0.9132, 0.8471, 0.7252 (exact relation of [`HuntCrossley`], whose form
/// this is with `(3/2) α = 3(1 − e²)/(4 v₀)`; see [`LankaraniNikravesh::restitution_at`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LankaraniNikravesh {
    stiffness: f64,
    exponent: f64,
    restitution: f64,
    impact_velocity: f64,
    /// `3(1 − e²)/(4 v₀)` (s/m), cached.
    factor: f64,
}

impl LankaraniNikravesh {
    /// A Lankarani–Nikravesh law with stiffness `k` (N/mⁿ, > 0), exponent `n` (> 0),
    /// restitution `e` (in `(0, 1]`) at the impact speed `v0` (m/s, > 0). Errors name
    /// `lankarani_nikravesh.stiffness`, `.exponent`, `.restitution` or `.impact_velocity`.
    pub fn new(stiffness: f64, exponent: f64, e: f64, v0: f64) -> Result<Self> {
        const LAW: &str = "lankarani_nikravesh";
        let stiffness = check(LAW, "stiffness", stiffness, true)?;
        let exponent = check(LAW, "exponent", exponent, true)?;
        let e = check_fraction(LAW, "restitution", e, true)?;
        let v0 = check(LAW, "impact_velocity", v0, true)?;
        Ok(Self {
            stiffness,
            exponent,
            restitution: e,
            impact_velocity: v0,
            factor: 0.75 * (1.0 - e * e) / v0,
        })
    }

    /// Stiffness `k` (N/mⁿ).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Exponent `n`.
    pub fn exponent(&self) -> f64 {
        self.exponent
    }

    /// Target restitution `e`.
    pub fn restitution(&self) -> f64 {
        self.restitution
    }

    /// Reference impact speed `v₀` (m/s).
    pub fn impact_velocity(&self) -> f64 {
        self.impact_velocity
    }

    /// The damping coefficient `λ = 3k(1 − e²)/(4 v₀)` (N·s/m^{n+1}).
    pub fn lambda(&self) -> f64 {
        self.stiffness * self.factor
    }

    /// The exact restitution `v_out/v` of a free impact at speed `v` (m/s) on this law (the
    /// Hunt–Crossley relation with `a = 3(1 − e²)/(4 v₀) · v`); at `v = v₀` it exceeds the
    /// target `e` (see the type's documentation).
    pub fn restitution_at(&self, v: f64) -> f64 {
        hc_restitution(self.factor * v.abs())
    }
}

impl NormalLaw for LankaraniNikravesh {
    fn force(&self, delta: f64, delta_dot: f64, _states: &[f64], _rates: &mut [f64]) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        (self.stiffness * power(delta, self.exponent) * (1.0 + self.factor * delta_dot)).max(0.0)
    }
}

/// Power-law felt with rate-sign hysteresis:
///
/// `F = K δᵖ (1 + a tanh(δ̇ / v_ε))` for `δ > 0`, `F = 0` otherwise.
///
/// Loading (`δ̇ > 0`) follows the stiffer branch `K(1 + a) δᵖ`, unloading the softer
/// `K(1 − a) δᵖ`; the `tanh` joins them smoothly over `|δ̇| ≲ v_ε` so the right-hand side
/// stays smooth for the integrators. Since `a tanh(δ̇/v_ε) δ̇ ≥ 0`, the power in excess of
/// the elastic `K δᵖ` is never negative: every loading–unloading cycle encloses positive
/// work, and the law never creates energy; with `a < 1`, `F ≥ 0`. This approximates the
/// hysteretic power-law felt measured by Boutillon (JASA 83(2):746, 1988: different
/// exponents on the loading and unloading branches) and used per interface by Hirschkorn,
/// McPhee & Birkett (J. Comput. Nonlinear Dyn. 1:47, 2006), with one exponent and a
/// constant branch ratio `(1 − a)/(1 + a)`; the dissipation is rate independent for
/// `|δ̇| ≫ v_ε`.
///
/// A felt whose loss also grows with the rate (a viscous share, as in Stulov's hereditary
/// felt at slow loading, whose `F ≈ Q₀[xᵖ + α d(xᵖ)/dt]`) takes a Hunt–Crossley term
/// ([`HystereticFelt::with_rate_damping`]):
///
/// `F = max(0, K δᵖ (1 + a tanh(δ̇ / v_ε) + (3/2) α δ̇))`,
///
/// which is [`HuntCrossley`] for `a = 0` and the rate-independent felt for `α = 0`; both
/// terms only take energy, and the clip (at the end of a fast unloading) only keeps the
/// felt from pulling.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HystereticFelt {
    stiffness: f64,
    exponent: f64,
    hysteresis: f64,
    v_eps: f64,
    alpha: f64,
}

impl HystereticFelt {
    /// Felt with stiffness `K` (N/mᵖ, > 0), exponent `p` (> 0), hysteresis `a` (in
    /// `[0, 1)`) and smoothing velocity `v_ε` (m/s, > 0). Errors name
    /// `hysteretic_felt.stiffness`, `.exponent`, `.hysteresis` or `.v_eps`.
    pub fn new(stiffness: f64, exponent: f64, hysteresis: f64, v_eps: f64) -> Result<Self> {
        const LAW: &str = "hysteretic_felt";
        Ok(Self {
            stiffness: check(LAW, "stiffness", stiffness, true)?,
            exponent: check(LAW, "exponent", exponent, true)?,
            hysteresis: check_fraction(LAW, "hysteresis", hysteresis, false)?,
            v_eps: check(LAW, "v_eps", v_eps, true)?,
            alpha: 0.0,
        })
    }

    /// The same felt with a Hunt–Crossley damping factor `α` (s/m, ≥ 0) on top of its
    /// rate-independent hysteresis (see the type's documentation). Errors name
    /// `hysteretic_felt.alpha`.
    pub fn with_rate_damping(mut self, alpha: f64) -> Result<Self> {
        self.alpha = check("hysteretic_felt", "alpha", alpha, false)?;
        Ok(self)
    }

    /// The Hunt–Crossley damping factor `α` (s/m), 0 for a rate-independent felt.
    pub fn rate_damping(&self) -> f64 {
        self.alpha
    }

    /// The felt whose restitution is `e` (in `(0, 1]`) at every impact speed well above
    /// `v_ε`: a mass loads it along `K(1 + a)δᵖ` and unloads along `K(1 − a)δᵖ`, so
    /// `e² = (1 − a)/(1 + a)`, i.e. `a = (1 − e²)/(1 + e²)`. No reference speed enters:
    /// unlike Hunt–Crossley, a slow impact loses the same fraction of its energy as a fast
    /// one. Errors name `hysteretic_felt.restitution` and the fields of
    /// [`HystereticFelt::new`].
    pub fn from_restitution(stiffness: f64, exponent: f64, e: f64, v_eps: f64) -> Result<Self> {
        let e = check_fraction("hysteretic_felt", "restitution", e, true)?;
        Self::new(stiffness, exponent, (1.0 - e * e) / (1.0 + e * e), v_eps)
    }

    /// The restitution of an impact much faster than `v_ε`: `√((1 − a)/(1 + a))`.
    pub fn restitution(&self) -> f64 {
        ((1.0 - self.hysteresis) / (1.0 + self.hysteresis)).sqrt()
    }

    /// Stiffness `K` (N/mᵖ).
    pub fn stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Exponent `p`.
    pub fn exponent(&self) -> f64 {
        self.exponent
    }

    /// Hysteresis `a`.
    pub fn hysteresis(&self) -> f64 {
        self.hysteresis
    }

    /// Smoothing velocity `v_ε` (m/s).
    pub fn v_eps(&self) -> f64 {
        self.v_eps
    }
}

impl HystereticFelt {
    /// The factor on `K δᵖ`: `1 + a tanh(δ̇/v_ε) + (3/2) α δ̇` (may be negative; the force
    /// clips it).
    fn factor(&self, delta_dot: f64) -> f64 {
        1.0 + self.hysteresis * (delta_dot / self.v_eps).tanh() + 1.5 * self.alpha * delta_dot
    }
}

impl NormalLaw for HystereticFelt {
    fn force(&self, delta: f64, delta_dot: f64, _states: &[f64], _rates: &mut [f64]) -> f64 {
        if delta <= 0.0 {
            return 0.0;
        }
        (self.stiffness * power(delta, self.exponent) * self.factor(delta_dot)).max(0.0)
    }

    fn tangent_stiffness(&self, delta: f64, delta_dot: f64, _states: &[f64]) -> Option<f64> {
        // ∂F/∂δ = p K δᵖ⁻¹ (1 + a tanh(δ̇/v_ε) + (3/2) α δ̇) where the force is positive.
        let factor = self.factor(delta_dot);
        if delta <= 0.0 || factor <= 0.0 {
            return Some(0.0);
        }
        Some(self.exponent * self.stiffness * power(delta, self.exponent) / delta * factor)
    }

    fn rate_derivative(&self, delta: f64, delta_dot: f64, _states: &[f64]) -> Option<f64> {
        // ∂F/∂δ̇ = K δᵖ (a (1 − tanh²(δ̇/v_ε)) / v_ε + (3/2) α) where the force is positive.
        if delta <= 0.0 || self.factor(delta_dot) <= 0.0 {
            return Some(0.0);
        }
        let th = (delta_dot / self.v_eps).tanh();
        Some(
            self.stiffness
                * power(delta, self.exponent)
                * (self.hysteresis * (1.0 - th * th) / self.v_eps + 1.5 * self.alpha),
        )
    }
}

/// Stulov's hereditary hammer felt (Stulov, JASA 97(4):2577, 1995; Acta Acustica 91, 2005;
/// form as in J. O. Smith, *Physical Audio Signal Processing*, "Including Hysteresis"):
///
/// `F(t) = f₀ [ xᵖ(t) − (ε/τ₀) ∫₀ᵗ xᵖ(ξ) e^{(ξ−t)/τ₀} dξ ]`, `x = max(δ, 0)`.
///
/// The memory integral is carried by one state `z = (1/τ₀) ∫₀ᵗ xᵖ(ξ) e^{(ξ−t)/τ₀} dξ`
/// (start it at 0 for virgin felt), which obeys `ż = (xᵖ − z)/τ₀`, so
///
/// `F = max(0, f₀ (xᵖ − ε z))`.
///
/// Fast loading (`t ≪ τ₀`) sees the instantaneous stiffness `f₀`; slow loading the relaxed
/// `Q₀ = f₀ (1 − ε)`, with `F ≈ Q₀ [xᵖ + α d(xᵖ)/dt]`, `α = ε τ₀/(1 − ε)`. The clip acts
/// at the end of unloading, where the remembered compression exceeds the current one and
/// the unclipped law would pull. The state rate is written also for `δ ≤ 0` (the memory
/// relaxes out of contact). Typical hammer values: `ε ≈ 0.9–0.99`, `τ₀ ≈ 1–10 µs`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StulovFelt {
    f0: f64,
    exponent: f64,
    epsilon: f64,
    tau0: f64,
}

impl StulovFelt {
    /// Stulov felt with instantaneous stiffness `f₀` (N/mᵖ, > 0), exponent `p` (> 0),
    /// hereditary amplitude `ε` (in `[0, 1)`) and relaxation time `τ₀` (s, > 0). Errors
    /// name `stulov_felt.f0`, `.exponent`, `.epsilon` or `.tau0`.
    pub fn new(f0: f64, exponent: f64, epsilon: f64, tau0: f64) -> Result<Self> {
        const LAW: &str = "stulov_felt";
        Ok(Self {
            f0: check(LAW, "f0", f0, true)?,
            exponent: check(LAW, "exponent", exponent, true)?,
            epsilon: check_fraction(LAW, "epsilon", epsilon, false)?,
            tau0: check(LAW, "tau0", tau0, true)?,
        })
    }

    /// The same felt given by its static (slow-loading) stiffness `Q₀ = f₀ (1 − ε)`, the
    /// form of published keyboard fits (e.g. Q₀ = 183 e^{0.045 n} N/mmᵖ, Smith, PASP,
    /// "Nonlinear spring model", after Stulov). Errors as [`StulovFelt::new`], and
    /// `stulov_felt.q0` for `Q₀`.
    pub fn from_static_stiffness(q0: f64, exponent: f64, epsilon: f64, tau0: f64) -> Result<Self> {
        let q0 = check("stulov_felt", "q0", q0, true)?;
        let epsilon = check_fraction("stulov_felt", "epsilon", epsilon, false)?;
        Self::new(q0 / (1.0 - epsilon), exponent, epsilon, tau0)
    }

    /// Instantaneous stiffness `f₀` (N/mᵖ).
    pub fn f0(&self) -> f64 {
        self.f0
    }

    /// Exponent `p`.
    pub fn exponent(&self) -> f64 {
        self.exponent
    }

    /// Hereditary amplitude `ε`.
    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }

    /// Relaxation time `τ₀` (s).
    pub fn tau0(&self) -> f64 {
        self.tau0
    }

    /// Static (slow-loading) stiffness `Q₀ = f₀ (1 − ε)` (N/mᵖ).
    pub fn static_stiffness(&self) -> f64 {
        self.f0 * (1.0 - self.epsilon)
    }

    /// Hysteresis time of the slow-loading form, `α = ε τ₀/(1 − ε)` (s).
    pub fn hysteresis_time(&self) -> f64 {
        self.epsilon * self.tau0 / (1.0 - self.epsilon)
    }
}

impl NormalLaw for StulovFelt {
    /// One state: the memory `z` (units of `xᵖ`, i.e. mᵖ).
    fn state_count(&self) -> usize {
        1
    }

    /// `states[0] = z`; writes `rates[0] = ż = (xᵖ − z)/τ₀`.
    fn force(&self, delta: f64, _delta_dot: f64, states: &[f64], rates: &mut [f64]) -> f64 {
        let z = states[0];
        let xp = if delta > 0.0 {
            power(delta, self.exponent)
        } else {
            0.0
        };
        rates[0] = (xp - z) / self.tau0;
        if delta <= 0.0 {
            return 0.0;
        }
        (self.f0 * (xp - self.epsilon * z)).max(0.0)
    }
}

// ---------------------------------------------------------------------------------------
// Tangential laws
// ---------------------------------------------------------------------------------------

/// Coulomb friction regularized by a `tanh`:
///
/// `F = −μ N tanh(v / v_ε)`.
///
/// Odd in the slip `v`, zero at `v = 0`, saturating at `μ N` for `|v| ≫ v_ε`; a smooth
/// stand-in for the set-valued Coulomb law, so ODE integrators can run through sticking
/// (it creeps at `|v| ≲ v_ε` instead of sticking exactly). Usual in multibody piano work
/// (literature.md §4.3). Negative normal forces count as 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RegularizedCoulomb {
    mu: f64,
    v_eps: f64,
}

impl RegularizedCoulomb {
    /// Coulomb friction with coefficient `μ` (≥ 0) regularized over `v_ε` (m/s, > 0).
    /// Errors name `regularized_coulomb.mu` or `regularized_coulomb.v_eps`.
    pub fn new(mu: f64, v_eps: f64) -> Result<Self> {
        Ok(Self {
            mu: check("regularized_coulomb", "mu", mu, false)?,
            v_eps: check("regularized_coulomb", "v_eps", v_eps, true)?,
        })
    }

    /// Friction coefficient `μ`.
    pub fn mu(&self) -> f64 {
        self.mu
    }

    /// Regularization velocity `v_ε` (m/s).
    pub fn v_eps(&self) -> f64 {
        self.v_eps
    }
}

impl TangentialLaw for RegularizedCoulomb {
    fn force(&self, normal: f64, slip: f64) -> f64 {
        -self.mu * normal.max(0.0) * (slip / self.v_eps).tanh()
    }
}

/// Stribeck friction (regularized), with viscous friction:
///
/// `F = −N (μ_k + (μ_s − μ_k) e^{−(v/v_s)²}) tanh(v / v_ε) − c_v v`.
///
/// The static coefficient `μ_s` acts at small slip (for `v_ε ≪ |v| ≪ v_s`), decaying to the
/// kinetic `μ_k` beyond the Stribeck velocity `v_s`; `c_v` (N·s/m) adds viscous friction.
/// The exponential (Gaussian) Stribeck curve is the common form of Armstrong-Hélouvry,
/// Dupont & Canudas de Wit (Automatica 30(7):1083, 1994); the `tanh` regularizes the sign.
/// Odd in `v` and zero at `v = 0`. Negative normal forces count as 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stribeck {
    mu_static: f64,
    mu_kinetic: f64,
    v_stribeck: f64,
    v_eps: f64,
    viscous: f64,
}

impl Stribeck {
    /// Stribeck friction with `μ_s ≥ μ_k ≥ 0`, Stribeck velocity `v_s` (m/s, > 0),
    /// regularization `v_ε` (m/s, > 0) and viscous coefficient `c_v` (N·s/m, ≥ 0). Errors
    /// name `stribeck.mu_static`, `.mu_kinetic`, `.v_stribeck`, `.v_eps` or `.viscous`
    /// (`stribeck.mu_static` also when `μ_s < μ_k`).
    pub fn new(
        mu_static: f64,
        mu_kinetic: f64,
        v_stribeck: f64,
        v_eps: f64,
        viscous: f64,
    ) -> Result<Self> {
        const LAW: &str = "stribeck";
        let mu_static = check(LAW, "mu_static", mu_static, false)?;
        let mu_kinetic = check(LAW, "mu_kinetic", mu_kinetic, false)?;
        if mu_static < mu_kinetic {
            return Err(ContactError::InvalidParameter {
                item: format!("{LAW}.mu_static"),
                message: format!("must be at least mu_kinetic ({mu_kinetic}), got {mu_static}"),
            });
        }
        Ok(Self {
            mu_static,
            mu_kinetic,
            v_stribeck: check(LAW, "v_stribeck", v_stribeck, true)?,
            v_eps: check(LAW, "v_eps", v_eps, true)?,
            viscous: check(LAW, "viscous", viscous, false)?,
        })
    }

    /// Static coefficient `μ_s`.
    pub fn mu_static(&self) -> f64 {
        self.mu_static
    }

    /// Kinetic coefficient `μ_k`.
    pub fn mu_kinetic(&self) -> f64 {
        self.mu_kinetic
    }

    /// Stribeck velocity `v_s` (m/s).
    pub fn v_stribeck(&self) -> f64 {
        self.v_stribeck
    }

    /// Regularization velocity `v_ε` (m/s).
    pub fn v_eps(&self) -> f64 {
        self.v_eps
    }

    /// Viscous coefficient `c_v` (N·s/m).
    pub fn viscous(&self) -> f64 {
        self.viscous
    }
}

impl TangentialLaw for Stribeck {
    fn force(&self, normal: f64, slip: f64) -> f64 {
        let mu = mbs_core::elements::stribeck_level(
            self.mu_kinetic,
            self.mu_static,
            self.v_stribeck,
            slip,
        );
        -normal.max(0.0) * mu * (slip / self.v_eps).tanh() - self.viscous * slip
    }
}
