//! Material presets: a normal law and friction coefficients for the materials of the piano
//! action (hammer felt, action felt, cloth, buckskin, wood, metal), each with its source and
//! whether its values are estimates.
//!
//! The numbers come from `literature.md` §4 of the project reference (tags there: **\[V\]**
//! read in a source, **\[S\]** secondhand, **\[M\]** recalled and approximate, **\[D\]** derived).
//! A preset's normal law is a lumped law for a typical piano contact patch: the stiffness
//! of a real contact depends on its geometry (radius, felt thickness), so identify it per
//! interface where measurements exist. Friction coefficients are against wood (the usual
//! counterpart in the action) unless the preset says otherwise; they are all **\[M\]**.
//!
//! ```
//! use mbs_contact::laws::{NormalLaw, TangentialLaw};
//! use mbs_contact::materials::Material;
//! let felt = Material::action_felt();
//! let normal = felt.normal_law();
//! let friction = felt.tangential_law(1e-3).unwrap();
//! let f = normal.force(0.5e-3, 0.0, &[], &mut []);
//! assert!(f > 10.0 && f < 50.0); // N at 0.5 mm, literature.md §4.2
//! assert!(friction.force(f, 0.1) < 0.0);
//! ```

use crate::error::{ContactError, Result};
use crate::laws::{
    Hertz, HuntCrossley, HystereticFelt, KelvinVoigt, LankaraniNikravesh, NormalLaw,
    RegularizedCoulomb, Stribeck, StulovFelt, TangentialLaw,
};

/// The normal law of a material: one of the laws of [`crate::laws`], with its parameters.
/// It is itself a [`NormalLaw`] (dispatching without allocation), so it can be handed to a
/// contact directly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialLaw {
    /// Linear spring and dashpot.
    KelvinVoigt(KelvinVoigt),
    /// Elastic power law.
    Hertz(Hertz),
    /// Power law with Hunt–Crossley damping.
    HuntCrossley(HuntCrossley),
    /// Power law with Lankarani–Nikravesh damping.
    LankaraniNikravesh(LankaraniNikravesh),
    /// Power-law felt with rate-sign hysteresis.
    HystereticFelt(HystereticFelt),
    /// Stulov's hereditary felt (one internal state).
    StulovFelt(StulovFelt),
}

impl MaterialLaw {
    /// The law as a boxed trait object.
    pub fn boxed(&self) -> Box<dyn NormalLaw> {
        match *self {
            MaterialLaw::KelvinVoigt(l) => Box::new(l),
            MaterialLaw::Hertz(l) => Box::new(l),
            MaterialLaw::HuntCrossley(l) => Box::new(l),
            MaterialLaw::LankaraniNikravesh(l) => Box::new(l),
            MaterialLaw::HystereticFelt(l) => Box::new(l),
            MaterialLaw::StulovFelt(l) => Box::new(l),
        }
    }

    /// The law as a `&dyn NormalLaw`.
    fn as_dyn(&self) -> &dyn NormalLaw {
        match self {
            MaterialLaw::KelvinVoigt(l) => l,
            MaterialLaw::Hertz(l) => l,
            MaterialLaw::HuntCrossley(l) => l,
            MaterialLaw::LankaraniNikravesh(l) => l,
            MaterialLaw::HystereticFelt(l) => l,
            MaterialLaw::StulovFelt(l) => l,
        }
    }
}

impl NormalLaw for MaterialLaw {
    fn state_count(&self) -> usize {
        self.as_dyn().state_count()
    }

    fn force(&self, delta: f64, delta_dot: f64, states: &[f64], rates: &mut [f64]) -> f64 {
        self.as_dyn().force(delta, delta_dot, states, rates)
    }

    fn tangent_stiffness(&self, delta: f64, delta_dot: f64, states: &[f64]) -> Option<f64> {
        self.as_dyn().tangent_stiffness(delta, delta_dot, states)
    }

    fn rate_independent(&self) -> bool {
        self.as_dyn().rate_independent()
    }
}

macro_rules! material_law_from {
    ($($law:ident),*) => {$(
        impl From<$law> for MaterialLaw {
            fn from(law: $law) -> Self {
                MaterialLaw::$law(law)
            }
        }
    )*};
}
material_law_from!(
    KelvinVoigt,
    Hertz,
    HuntCrossley,
    LankaraniNikravesh,
    HystereticFelt,
    StulovFelt
);

/// A contact material: its normal law, friction coefficients and where the numbers come
/// from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Name of the material, e.g. `"action felt"`.
    pub name: &'static str,
    /// Normal law and its parameters.
    pub normal: MaterialLaw,
    /// Kinetic (sliding) friction coefficient `μ_k` (≥ 0).
    pub mu_kinetic: f64,
    /// Static friction coefficient `μ_s` (≥ `μ_k`).
    pub mu_static: f64,
    /// Stribeck velocity `v_s` (m/s) of the transition from static to kinetic friction.
    pub stribeck_velocity: f64,
    /// Where the values come from, with the tags of `literature.md` (\[V\], \[S\], \[M\], \[D\]).
    pub source: &'static str,
    /// Whether the normal law's parameters are estimates (not read in a source) to be
    /// identified before they become acceptance thresholds.
    pub estimate: bool,
    /// Whether the friction coefficients are estimates (all presets: **\[M\]**).
    pub friction_estimate: bool,
}

/// Default Stribeck velocity of the presets (m/s) \[M\]: felt and wood show their static
/// friction below about a millimetre per second.
pub const DEFAULT_STRIBECK_VELOCITY: f64 = 1e-3;

/// Effective radius of the reference contact behind the Hertz stiffness of the wood and
/// metal presets (m) \[M\]: a 5 mm radius (pin, rounded edge), i.e. `k = (4/3) E* √R`.
pub const REFERENCE_RADIUS: f64 = 5e-3;

impl Material {
    /// Hammer felt, C4: pure power law `F = K δᵖ`, `p = 2.5`, `K = 4.5e9 N/m^2.5` (Chaigne &
    /// Askenfelt, JASA 95(2):1112, 1994, \[S\]); `F(0.5 mm) ≈ 25 N`. Elastic (no loss), as in
    /// that model; see [`Material::hammer_felt_stulov`] for a hysteretic hammer. Friction on
    /// the steel string `μ_k = 0.2`, `μ_s = 0.25` \[M\].
    pub fn hammer_felt() -> Self {
        Self {
            name: "hammer felt",
            normal: Hertz::new(4.5e9, 2.5).expect("valid preset").into(),
            mu_kinetic: 0.2,
            mu_static: 0.25,
            stribeck_velocity: DEFAULT_STRIBECK_VELOCITY,
            source: "Chaigne & Askenfelt, JASA 95(2):1112 (1994), C4: p = 2.5, K = 4.5e9 N/m^2.5 \
                     [S] (literature.md §4.1); friction on steel string mu = 0.2-0.25 [M]",
            estimate: false,
            friction_estimate: true,
        }
    }

    /// Hammer felt, C4, as Stulov's hereditary felt: static stiffness from the keyboard fit
    /// `Q₀ = 183 e^{0.045 n}` N/mmᵖ, `p = 3.7 + 0.015 n` at key `n = 40` (J. O. Smith, PASP,
    /// "Nonlinear spring model", citing Stulov, \[V\]): `p = 4.3`, `Q₀ ≈ 8.8e15 N/m^4.3`
    /// (`F(0.5 mm) ≈ 56 N` at slow loading); `ε = 0.9`, `τ₀ = 3 µs` [M: typical ε ≈ 0.9–0.99,
    /// τ₀ ≈ 1–10 µs, to verify in Stulov 2005]. Estimate (the fit is read as the static
    /// stiffness `Q₀ = f₀(1 − ε)`). Friction as [`Material::hammer_felt`].
    pub fn hammer_felt_stulov() -> Self {
        let key: f64 = 40.0;
        let p = 3.7 + 0.015 * key;
        // N/mm^p → N/m^p: × 1000^p.
        let q0 = 183.0 * (0.045 * key).exp() * 1000f64.powf(p);
        Self {
            name: "hammer felt (Stulov)",
            normal: StulovFelt::from_static_stiffness(q0, p, 0.9, 3e-6)
                .expect("valid preset")
                .into(),
            mu_kinetic: 0.2,
            mu_static: 0.25,
            stribeck_velocity: DEFAULT_STRIBECK_VELOCITY,
            source: "Stulov hereditary model (JASA 97:2577, 1995); Q0 = 183 exp(0.045 n) N/mm^p, \
                     p = 3.7 + 0.015 n at n = 40 (Smith, PASP, citing Stulov) [V]; eps = 0.9, \
                     tau0 = 3 us [M] (literature.md §4.1); friction [M]",
            estimate: true,
            friction_estimate: true,
        }
    }

    /// Action felt (key-bed and front-rail punchings, capstan/heel cushion, let-off and rest
    /// felts): power law with Hunt–Crossley damping, `k = 2.5e9 N/m^2.5`, `n = 2.5`
    /// (secant stiffness 2.8e4 N/m at 0.5 mm, 7.9e4 N/m at 1 mm; 14 N and 79 N), `α = 1 s/m`
    /// (restitution 0.83 at 0.2 m/s, 0.66 at 0.5 m/s, 0.49 at 1 m/s) [D/M: literature.md
    /// §4.2, no table found: p ≈ 2–3, secant 3e4–1e5 N/m at 0.5–1 mm]. Friction on wood
    /// `μ_k = 0.25`, `μ_s = 0.3` \[M\].
    pub fn action_felt() -> Self {
        Self {
            name: "action felt",
            normal: HuntCrossley::new(2.5e9, 2.5, 1.0)
                .expect("valid preset")
                .into(),
            mu_kinetic: 0.25,
            mu_static: 0.3,
            stribeck_velocity: DEFAULT_STRIBECK_VELOCITY,
            source: "estimate from key-bottom forces 20-50 N at 0.5-1 mm punching compression \
                     (secant 3e4-1e5 N/m), power law p = 2.5 with Hunt-Crossley damping [D/M] \
                     (literature.md §4.2); friction felt on wood mu = 0.1-0.4 [M]",
            estimate: true,
            friction_estimate: true,
        }
    }

    /// Cloth (key bushings, balance and front-rail cloth, thin woven wool): power law
    /// `n = 2`, `k = 1e8 N/m²` (secant 5e4 N/m at 0.5 mm), Hunt–Crossley `α = 1 s/m`
    /// (restitution 0.66 at 0.5 m/s) \[estimate, no source\]. Friction `μ_k = 0.2`,
    /// `μ_s = 0.25` \[M\].
    pub fn cloth() -> Self {
        Self {
            name: "cloth",
            normal: HuntCrossley::new(1e8, 2.0, 1.0)
                .expect("valid preset")
                .into(),
            mu_kinetic: 0.2,
            mu_static: 0.25,
            stribeck_velocity: DEFAULT_STRIBECK_VELOCITY,
            source: "estimate: thin woven wool, power law p = 2, secant 5e4 N/m at 0.5 mm, \
                     Hunt-Crossley damping (no table found, literature.md §4.2); friction [M]",
            estimate: true,
            friction_estimate: true,
        }
    }

    /// Buckskin (leather on the jack top, knuckle and back-check): power law `n = 2`,
    /// `k = 2e8 N/m²` (secant 1e5 N/m at 0.5 mm), Hunt–Crossley `α = 0.5 s/m`
    /// (restitution 0.80 at 0.5 m/s, 0.66 at 1 m/s) \[estimate\]. Friction on wood
    /// `μ_k = 0.15`, `μ_s = 0.2` \[M\] (graphited knuckle at the low end of 0.1–0.4).
    pub fn buckskin() -> Self {
        Self {
            name: "buckskin",
            normal: HuntCrossley::new(2e8, 2.0, 0.5)
                .expect("valid preset")
                .into(),
            mu_kinetic: 0.15,
            mu_static: 0.2,
            stribeck_velocity: DEFAULT_STRIBECK_VELOCITY,
            source: "estimate: leather over felt, power law p = 2, secant 1e5 N/m at 0.5 mm, \
                     Hunt-Crossley damping; friction buckskin on wood mu = 0.1-0.4, graphited \
                     at the low end [M] (literature.md §4.2)",
            estimate: true,
            friction_estimate: true,
        }
    }

    /// Wood on wood (hard maple/hornbeam across the grain): Hertz-type contact
    /// `k = (4/3) E* √R ≈ 5.2e7 N/m^1.5` for `E = 1 GPa`, `ν = 0.3` on both sides and
    /// `R = 5 mm`, with Hunt–Crossley damping for restitution 0.6 at 1 m/s (exact relation,
    /// [`HuntCrossley::from_restitution_exact`]; `α ≈ 0.57 s/m`) \[estimate\].
    /// Friction `μ_k = 0.3`, `μ_s = 0.4` \[M\].
    pub fn wood() -> Self {
        let k = Hertz::from_moduli(1e9, 0.3, 1e9, 0.3, REFERENCE_RADIUS)
            .expect("valid preset")
            .stiffness();
        Self {
            name: "wood",
            normal: HuntCrossley::from_restitution_exact(k, 1.5, 0.6, 1.0)
                .expect("valid preset")
                .into(),
            mu_kinetic: 0.3,
            mu_static: 0.4,
            stribeck_velocity: DEFAULT_STRIBECK_VELOCITY,
            source: "estimate: Hertz k = (4/3) E* sqrt(R), E = 1 GPa across the grain, nu = 0.3, \
                     R = 5 mm (Johnson, Contact Mechanics 1985), Hunt-Crossley e ~ 0.6 at 1 m/s \
                     [M]; friction wood on wood [M]",
            estimate: true,
            friction_estimate: true,
        }
    }

    /// Metal on metal (steel, brass: pins, screws, springs): Hertz-type contact
    /// `k = (4/3) E* √R ≈ 1.09e10 N/m^1.5` for steel (`E = 210 GPa`, `ν = 0.3`) and
    /// `R = 5 mm`, with Hunt–Crossley damping for restitution 0.9 at 1 m/s (exact relation;
    /// `α ≈ 0.11 s/m`) \[estimate\].
    /// Friction, lubricated: `μ_k = 0.15`, `μ_s = 0.2` \[M\].
    pub fn metal() -> Self {
        let k = Hertz::from_moduli(210e9, 0.3, 210e9, 0.3, REFERENCE_RADIUS)
            .expect("valid preset")
            .stiffness();
        Self {
            name: "metal",
            normal: HuntCrossley::from_restitution_exact(k, 1.5, 0.9, 1.0)
                .expect("valid preset")
                .into(),
            mu_kinetic: 0.15,
            mu_static: 0.2,
            stribeck_velocity: DEFAULT_STRIBECK_VELOCITY,
            source: "estimate: Hertz k = (4/3) E* sqrt(R), steel E = 210 GPa, nu = 0.3, R = 5 mm \
                     (Johnson, Contact Mechanics 1985), Hunt-Crossley e ~ 0.9 at 1 m/s [M]; \
                     friction lubricated metal on metal [M]",
            estimate: true,
            friction_estimate: true,
        }
    }

    /// Every preset.
    pub fn presets() -> Vec<Material> {
        vec![
            Self::hammer_felt(),
            Self::hammer_felt_stulov(),
            Self::action_felt(),
            Self::cloth(),
            Self::buckskin(),
            Self::wood(),
            Self::metal(),
        ]
    }

    /// The same material with another normal law (e.g. a stiffness identified for one
    /// interface).
    pub fn with_normal(self, normal: impl Into<MaterialLaw>) -> Self {
        Self {
            normal: normal.into(),
            ..self
        }
    }

    /// The same material with other friction coefficients. Errors name
    /// `<material>.mu_kinetic` or `<material>.mu_static` (also when `μ_s < μ_k`).
    pub fn with_friction(self, mu_kinetic: f64, mu_static: f64) -> Result<Self> {
        let m = Self {
            mu_kinetic,
            mu_static,
            ..self
        };
        m.validate()?;
        Ok(m)
    }

    /// Checks the friction parameters (the normal law was checked when built), naming the
    /// bad field as `<material>.<field>`.
    pub fn validate(&self) -> Result<()> {
        use mbs_core::check::{Bound, check_value};
        let bad = |field: &str, message: String| ContactError::InvalidParameter {
            item: format!("{}.{field}", self.name),
            message,
        };
        check_value(self.mu_kinetic, Bound::NonNegative).map_err(|m| bad("mu_kinetic", m))?;
        check_value(self.mu_static, Bound::NonNegative).map_err(|m| bad("mu_static", m))?;
        if self.mu_static < self.mu_kinetic {
            return Err(bad(
                "mu_static",
                format!(
                    "must be at least mu_kinetic ({}), got {}",
                    self.mu_kinetic, self.mu_static
                ),
            ));
        }
        check_value(self.stribeck_velocity, Bound::Positive)
            .map_err(|m| bad("stribeck_velocity", m))?;
        Ok(())
    }

    /// The normal law, boxed.
    pub fn normal_law(&self) -> Box<dyn NormalLaw> {
        self.normal.boxed()
    }

    /// Stribeck friction from `μ_s`, `μ_k` and the Stribeck velocity, regularized over
    /// `v_eps` (m/s), without viscous friction. Errors name the bad field.
    pub fn stribeck(&self, v_eps: f64) -> Result<Stribeck> {
        self.validate()?;
        Stribeck::new(
            self.mu_static,
            self.mu_kinetic,
            self.stribeck_velocity,
            v_eps,
            0.0,
        )
    }

    /// Regularized Coulomb friction with the kinetic coefficient, over `v_eps` (m/s).
    pub fn coulomb(&self, v_eps: f64) -> Result<RegularizedCoulomb> {
        self.validate()?;
        RegularizedCoulomb::new(self.mu_kinetic, v_eps)
    }

    /// The friction law, boxed: [`Stribeck`] when `μ_s > μ_k`, otherwise
    /// [`RegularizedCoulomb`]; regularized over `v_eps` (m/s).
    pub fn tangential_law(&self, v_eps: f64) -> Result<Box<dyn TangentialLaw>> {
        if self.mu_static > self.mu_kinetic {
            Ok(Box::new(self.stribeck(v_eps)?))
        } else {
            Ok(Box::new(self.coulomb(v_eps)?))
        }
    }
}
