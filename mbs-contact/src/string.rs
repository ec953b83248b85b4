//! A taut, stiff string with rigid ends, struck by a body: [`TautString`] (the modal data of
//! one note, a unison of `n` strings taken as one string with the aggregate mass and
//! tension) and [`StringContact`] (a force element: a felt-covered striker against that
//! string).
//!
//! **Model** (Chaigne & Askenfelt, JASA 95(2):1112, 1994, modal form as in Suzuki, ICASSP
//! 1986; parameters and checks in `reference/string_reference.md` §1, §4 and §5). The
//! transverse displacement of the string is a sum of `N` modes `y(x, t) = Σ q_k(t)
//! sin(kπx/L)`; each obeys
//!
//! ```text
//! M_k q̈_k + M_k ω_k² q_k = φ_k F,   ω_k = k ω₁ √(1 + B k²),  φ_k = sin(kπa),  M_k = n μ L / 2
//! ```
//!
//! where `F` is the felt force at the strike point `x₀ = aL`. The modes cut off above `N`
//! still give the strike point a static compliance; it is kept as a massless spring in
//! series with the felt, `c_r = Σ_{k>N} φ_k²/(M_k ω_k²)` (for the ideal string
//! `c_r = x₀(L − x₀)/(T L) − Σ_{k≤N} φ_k²/(M_k ω_k²)`), which removes most of the
//! truncation error (`string_reference.md` §4.4 and §5.2, item 2).
//!
//! **States without ringing cost.** The modes are stored in variation-of-constants form,
//! `q_k = A_k cos ω_k t + B_k sin ω_k t`, `q̇_k = ω_k (−A_k sin ω_k t + B_k cos ω_k t)`, with
//!
//! ```text
//! dA_k/dt = −φ_k F sin(ω_k t)/(M_k ω_k),   dB_k/dt = φ_k F cos(ω_k t)/(M_k ω_k).
//! ```
//!
//! Out of contact the rates are exactly zero: the free vibration is exact and an adaptive
//! integrator is not held to microsecond steps by a ringing string between strikes.
//! **The string's losses** `σ_k = b₁ + b₃ ω_k²` are not in the integrated states: they
//! change the contact by less than 1 % (`string_reference.md` §1.4, §4.4). They are
//! applied when the motion is rendered as sound ([`TautString::decay_rate`],
//! [`BridgeForceRenderer`]).

use std::f64::consts::PI;
use std::sync::Arc;

use mbs_core::{BodyId, Crossing, ForceContext, ForceElement, LoadJacobian, Loads, Model};

use crate::element::{ContactOutput, ContactSide, ResolvedSide, resolve, velocity_at};
use crate::error::{ContactError, Result};
use crate::geometry::{Proximity, Shape, proximity};
use crate::laws::NormalLaw;

/// Highest mode frequency of the *flexible* string kept by default (Hz): `N = ceil(f_max /
/// f₁)` (12 kHz is enough for p to mf at C4, `string_reference.md` §5.2). Inharmonicity
/// raises the actual top mode: C4's 46th is at about 16 kHz.
pub const DEFAULT_MAX_FREQUENCY_HZ: f64 = 12_000.0;

/// The most modes a string may have (a C1 string to 20 kHz needs about 600).
pub const MAX_MODES: usize = 2_000;

/// How closely a given mass and tension must agree with `T = 4 L² f₁² μ` (relative).
const MASS_TENSION_AGREEMENT: f64 = 0.01;

/// The data of one note's string (or unison), as read in a source: what [`TautString::new`]
/// builds the modes from. Give the mass, the tension, or both (they must then agree with
/// the fundamental and length, `T = 4 L f₁² M_s`, within 1 %; the model then uses the
/// tension the mass implies, so that its modes add up to the string's static compliance).
#[derive(Clone, Debug, PartialEq)]
pub struct StringSpec {
    /// Speaking length `L` (m): agraffe to bridge.
    pub length_m: f64,
    /// Fundamental `f₁` (Hz) of the ideal (flexible) string, `c = 2 L f₁`.
    pub fundamental_hz: f64,
    /// Mass `M_s` of one string's speaking length (kg), or `None` to derive it from the
    /// tension.
    pub mass_kg: Option<f64>,
    /// Tension `T` of one string (N), or `None` to derive it from the mass.
    pub tension_n: Option<f64>,
    /// Inharmonicity `B` (≥ 0): `ω_k = k ω₁ √(1 + B k²)`; 0 for an ideal string.
    pub inharmonicity: f64,
    /// Striking ratio `a = x₀ / L`, in (0, 1).
    pub striking_ratio: f64,
    /// Strings in the unison `n` (≥ 1), struck in phase: one string with `n μ` and `n T`.
    pub strings: usize,
    /// Frequency-independent loss `b₁` (1/s, ≥ 0): `σ_k = b₁ + b₃ ω_k²` (sound only).
    pub loss_b1: f64,
    /// Frequency-dependent loss `b₃` (s, ≥ 0).
    pub loss_b3: f64,
    /// Number of modes `N`, or `None` for `ceil(`[`DEFAULT_MAX_FREQUENCY_HZ`]` / f₁)`.
    pub modes: Option<usize>,
    /// Whether the cut modes' static compliance is kept as a series spring.
    pub residual_compliance: bool,
}

impl StringSpec {
    /// The C4 unison of Chaigne & Askenfelt (1994) as reproduced in public code
    /// (`string_reference.md` §1.1, all \[S\]): L = 0.62 m, f₁ = 262.2 Hz, M_s = 3.93 g,
    /// T = 670 N, B = 3.77e-4 \[D\], a = 0.12, three strings, b₁ = 0.5 1/s,
    /// b₃ = 6.25e-9 s, modes to 12 kHz, residual compliance on.
    pub fn chaigne_askenfelt_c4() -> Self {
        StringSpec {
            length_m: 0.62,
            fundamental_hz: 262.2,
            mass_kg: Some(3.93e-3),
            tension_n: Some(670.0),
            inharmonicity: 3.77e-4,
            striking_ratio: 0.12,
            strings: 3,
            loss_b1: 0.5,
            loss_b3: 6.25e-9,
            modes: None,
            residual_compliance: true,
        }
    }
}

/// A stiff string with rigid ends, reduced to its modes at the strike point (see the
/// module documentation). Built by [`TautString::new`] from a [`StringSpec`].
///
/// ```
/// use mbs_contact::{StringSpec, TautString};
/// let c4 = TautString::new(&StringSpec::chaigne_askenfelt_c4())?;
/// // Wave impedance of one string μc = 2 f₁ M_s ≈ 2.06 kg/s; the unison's ≈ 6.18 kg/s.
/// assert!((c4.wave_impedance() - 2.061).abs() < 1e-3);
/// assert!((c4.unison_impedance() - 6.18).abs() < 0.01);
/// // The agraffe round trip 2aL/c ≈ 0.458 ms, 46 modes below 12 kHz · (f₁ grid).
/// assert!((c4.agraffe_round_trip() - 0.458e-3).abs() < 1e-6);
/// assert_eq!(c4.modes(), 46);
/// # Ok::<(), mbs_contact::ContactError>(())
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct TautString {
    spec: StringSpec,
    /// Linear density of one string (kg/m).
    mu: f64,
    /// Tension of one string (N).
    tension: f64,
    /// ω_k (rad/s), k = 1..N.
    omega: Vec<f64>,
    /// φ_k = sin(kπa).
    phi: Vec<f64>,
    /// φ_k / (M_k ω_k): the factor of F in the rates of A_k and B_k.
    gain: Vec<f64>,
    /// T_total k π / L (−1)^(k+1): the bridge force per unit q_k.
    bridge: Vec<f64>,
    /// M_k = n μ L / 2 (kg).
    modal_mass: f64,
    /// √(Σ φ_k²), for a cheap bound on the strike-point displacement.
    phi_norm: f64,
    /// Residual compliance c_r (m/N), 0 when switched off.
    residual: f64,
}

fn invalid(field: &str, message: String) -> ContactError {
    ContactError::InvalidParameter {
        item: format!("string.{field}"),
        message,
    }
}

fn positive(field: &str, v: f64) -> Result<f64> {
    mbs_core::check::check_value(v, mbs_core::check::Bound::Positive)
        .map_err(|message| invalid(field, message))
}

fn non_negative(field: &str, v: f64) -> Result<f64> {
    mbs_core::check::check_value(v, mbs_core::check::Bound::NonNegative)
        .map_err(|message| invalid(field, message))
}

impl TautString {
    /// Builds the modes of `spec`, checking every field; an error names it
    /// (`string.length_m`, `string.tension_n`, ...).
    pub fn new(spec: &StringSpec) -> Result<Self> {
        let l = positive("length_m", spec.length_m)?;
        let f1 = positive("fundamental_hz", spec.fundamental_hz)?;
        let b = non_negative("inharmonicity", spec.inharmonicity)?;
        let a = spec.striking_ratio;
        if !(a.is_finite() && a > 0.0 && a < 1.0) {
            return Err(invalid(
                "striking_ratio",
                format!("must lie in (0, 1) (x0 / L), got {a}"),
            ));
        }
        if spec.strings == 0 {
            return Err(invalid("strings", "must be at least 1, got 0".into()));
        }
        non_negative("loss_b1", spec.loss_b1)?;
        non_negative("loss_b3", spec.loss_b3)?;
        // c = 2 L f₁ and T = μ c²: the mass gives the tension and the other way round.
        let c = 2.0 * l * f1;
        let (mu, tension) = match (spec.mass_kg, spec.tension_n) {
            (None, None) => {
                return Err(invalid(
                    "mass_kg",
                    "give the string's mass or its tension (or both)".into(),
                ));
            }
            (Some(m), None) => {
                let mu = positive("mass_kg", m)? / l;
                (mu, mu * c * c)
            }
            (None, Some(t)) => {
                let t = positive("tension_n", t)?;
                (t / (c * c), t)
            }
            (Some(m), Some(t)) => {
                let mu = positive("mass_kg", m)? / l;
                let t = positive("tension_n", t)?;
                let implied = mu * c * c;
                if ((t - implied) / implied).abs() > MASS_TENSION_AGREEMENT {
                    return Err(invalid(
                        "tension_n",
                        format!(
                            "{t} N disagrees with the {implied:.1} N that the length, \
                             fundamental and mass give (T = 4 L f1^2 Ms); give one of them, \
                             or make them agree within 1 %"
                        ),
                    ));
                }
                // The modes need T = μc² exactly (the residual is a small difference
                // of large sums): the given tension is only checked.
                (mu, implied)
            }
        };
        let n_modes = match spec.modes {
            Some(n) => n,
            None => (DEFAULT_MAX_FREQUENCY_HZ / f1).ceil().max(1.0) as usize,
        };
        if n_modes == 0 || n_modes > MAX_MODES {
            return Err(invalid(
                "modes",
                format!("must be 1 to {MAX_MODES}, got {n_modes}"),
            ));
        }
        let n = spec.strings as f64;
        let t_total = n * tension;
        let modal_mass = n * mu * l / 2.0;
        let w1 = 2.0 * PI * f1;
        let mut s = TautString {
            spec: spec.clone(),
            mu,
            tension,
            omega: Vec::with_capacity(n_modes),
            phi: Vec::with_capacity(n_modes),
            gain: Vec::with_capacity(n_modes),
            bridge: Vec::with_capacity(n_modes),
            modal_mass,
            phi_norm: 0.0,
            residual: 0.0,
        };
        for k in 1..=n_modes {
            let kf = k as f64;
            // ω_k = k ω₁ √(1 + B k²) ; φ_k = sin(kπa)
            let w = kf * w1 * (1.0 + b * kf * kf).sqrt();
            let phi = (kf * PI * a).sin();
            s.omega.push(w);
            s.phi.push(phi);
            s.gain.push(phi / (modal_mass * w));
            let sign = if k % 2 == 1 { 1.0 } else { -1.0 };
            s.bridge.push(t_total * kf * PI / l * sign);
        }
        s.phi_norm = s.phi.iter().map(|p| p * p).sum::<f64>().sqrt();
        if spec.residual_compliance {
            s.residual = s.cut_modes_compliance(w1, b);
        }
        Ok(s)
    }

    /// `Σ_{k>N} φ_k²/(M ω_k²)`: the ideal string's closed form `x₀(L − x₀)/(T L)` less the
    /// kept ideal modes, less the stiffness correction of the cut modes
    /// `Σ_{k>N} φ_k²/(M ω₁²) · B/(1 + Bk²)` (summed to 20 N or 4000 modes, then its
    /// integral with `φ² ≈ ½`).
    fn cut_modes_compliance(&self, w1: f64, b: f64) -> f64 {
        let n = self.omega.len();
        let m = self.modal_mass;
        let kept: f64 = (1..=n)
            .map(|k| {
                let kf = k as f64;
                self.phi[k - 1].powi(2) / (m * (kf * w1).powi(2))
            })
            .sum();
        let mut tail = self.static_compliance() - kept;
        if b > 0.0 {
            let a = self.spec.striking_ratio;
            let k_max = (20 * n).max(4000);
            let summed: f64 = (n + 1..=k_max)
                .map(|k| {
                    let kf = k as f64;
                    (kf * PI * a).sin().powi(2) * b / (1.0 + b * kf * kf)
                })
                .sum();
            let rest = 0.5 * b.sqrt() * (PI / 2.0 - (b.sqrt() * (k_max as f64 + 0.5)).atan());
            tail -= (summed + rest) / (m * w1 * w1);
        }
        tail.max(0.0)
    }

    /// The data it was built from.
    pub fn spec(&self) -> &StringSpec {
        &self.spec
    }

    /// Number of modes `N`.
    pub fn modes(&self) -> usize {
        self.omega.len()
    }

    /// Speaking length `L` (m).
    pub fn length(&self) -> f64 {
        self.spec.length_m
    }

    /// Strike point `x₀ = aL` (m from the agraffe).
    pub fn strike_point(&self) -> f64 {
        self.spec.striking_ratio * self.spec.length_m
    }

    /// Number of strings in the unison.
    pub fn strings(&self) -> usize {
        self.spec.strings
    }

    /// Linear density of one string `μ = M_s / L` (kg/m).
    pub fn linear_density(&self) -> f64 {
        self.mu
    }

    /// Tension of one string (N).
    pub fn tension(&self) -> f64 {
        self.tension
    }

    /// Tension of the unison `n T` (N).
    pub fn total_tension(&self) -> f64 {
        self.spec.strings as f64 * self.tension
    }

    /// Transverse wave speed `c = √(T/μ) = 2 L f₁` (m/s).
    pub fn wave_speed(&self) -> f64 {
        2.0 * self.spec.length_m * self.spec.fundamental_hz
    }

    /// Wave impedance of one string `Z = μ c` (kg/s).
    pub fn wave_impedance(&self) -> f64 {
        self.mu * self.wave_speed()
    }

    /// Wave impedance of the unison `n Z` (kg/s); the striker sees `2 n Z` until the
    /// first reflection returns.
    pub fn unison_impedance(&self) -> f64 {
        self.spec.strings as f64 * self.wave_impedance()
    }

    /// Time for a pulse from the strike point to return from the agraffe, `2 a L / c` (s).
    pub fn agraffe_round_trip(&self) -> f64 {
        2.0 * self.strike_point() / self.wave_speed()
    }

    /// Time for a pulse from the strike point to return from the bridge,
    /// `2 (1 − a) L / c` (s).
    pub fn bridge_round_trip(&self) -> f64 {
        2.0 * (self.spec.length_m - self.strike_point()) / self.wave_speed()
    }

    /// Static compliance of the ideal (flexible) unison at the strike point,
    /// `x₀ (L − x₀) / (n T L)` (m/N).
    pub fn static_compliance(&self) -> f64 {
        let (x0, l) = (self.strike_point(), self.spec.length_m);
        x0 * (l - x0) / (self.total_tension() * l)
    }

    /// Static stiffness of the ideal unison at the strike point, `n T L / (x₀ (L − x₀))`
    /// (N/m).
    pub fn static_stiffness(&self) -> f64 {
        1.0 / self.static_compliance()
    }

    /// Residual compliance `c_r` of the cut modes (m/N), in series with the felt; 0 when
    /// the spec switched it off.
    pub fn residual_compliance(&self) -> f64 {
        self.residual
    }

    /// Modal mass `M_k = n μ L / 2` (kg), the same for every mode.
    pub fn modal_mass(&self) -> f64 {
        self.modal_mass
    }

    /// Angular frequency `ω_k` (rad/s) of mode `k` (1-based); `None` beyond `N`.
    pub fn angular_frequency(&self, k: usize) -> Option<f64> {
        self.omega.get(k.checked_sub(1)?).copied()
    }

    /// Mode shape at the strike point `φ_k = sin(kπa)` (1-based); `None` beyond `N`.
    pub fn shape_at_strike(&self, k: usize) -> Option<f64> {
        self.phi.get(k.checked_sub(1)?).copied()
    }

    /// Decay rate `σ_k = b₁ + b₃ ω_k²` (1/s) of mode `k` (1-based); `None` beyond `N`.
    /// Used only when rendering sound, not in the integrated states.
    pub fn decay_rate(&self, k: usize) -> Option<f64> {
        let w = self.angular_frequency(k)?;
        Some(self.spec.loss_b1 + self.spec.loss_b3 * w * w)
    }

    /// Number of internal states of the string: `2 N` (`A_k` then `B_k`).
    pub fn state_count(&self) -> usize {
        2 * self.omega.len()
    }

    /// Modal displacements `q_k` and velocities `q̇_k` at time `t` from the states
    /// `[A_1..A_N, B_1..B_N]`, for each mode in order.
    pub fn modal_motion<'a>(
        &'a self,
        t: f64,
        states: &'a [f64],
    ) -> impl Iterator<Item = (f64, f64)> + 'a {
        let n = self.omega.len();
        self.omega.iter().enumerate().map(move |(k, &w)| {
            let (a, b) = (states[k], states[n + k]);
            let (s, c) = (w * t).sin_cos();
            (a * c + b * s, w * (b * c - a * s))
        })
    }

    /// `(sin ω_k t, cos ω_k t)` for every mode, into `out` (length [`TautString::modes`]).
    fn trig_at(&self, t: f64, out: &mut [(f64, f64)]) {
        for (o, w) in out.iter_mut().zip(&self.omega) {
            *o = (w * t).sin_cos();
        }
    }

    /// [`TautString::strike_point_motion`] with the trigonometry of its time given.
    fn strike_point_motion_from(&self, trig: &[(f64, f64)], states: &[f64]) -> (f64, f64) {
        let n = self.omega.len();
        let (mut u, mut v) = (0.0, 0.0);
        for k in 0..n {
            let (a, b) = (states[k], states[n + k]);
            let ((s, c), w, p) = (trig[k], self.omega[k], self.phi[k]);
            u += p * (a * c + b * s);
            v += p * (w * (b * c - a * s));
        }
        (u, v)
    }

    /// Displacement (m, positive away from the striker) and velocity of the string at the
    /// strike point from the modes alone (the residual spring is the contact's business).
    pub fn strike_point_motion(&self, t: f64, states: &[f64]) -> (f64, f64) {
        self.modal_motion(t, states)
            .zip(&self.phi)
            .fold((0.0, 0.0), |(u, v), ((q, qd), p)| (u + p * q, v + p * qd))
    }

    /// Force of the unison on the bridge from its modes,
    /// `F_b = n T Σ (kπ/L)(−1)^(k+1) q_k` (N; `string_reference.md` §6).
    pub fn bridge_force(&self, t: f64, states: &[f64]) -> f64 {
        self.modal_motion(t, states)
            .zip(&self.bridge)
            .map(|((q, _), g)| g * q)
            .sum()
    }

    /// Energy of the string's modes, `Σ ½ M_k ω_k² (A_k² + B_k²)` (J): kinetic plus
    /// elastic, constant out of contact (no losses in the states).
    pub fn modal_energy(&self, states: &[f64]) -> f64 {
        let n = self.omega.len();
        self.omega
            .iter()
            .enumerate()
            .map(|(k, w)| {
                0.5 * self.modal_mass * w * w * (states[k].powi(2) + states[n + k].powi(2))
            })
            .sum()
    }

    /// A bound on |Σ φ_k q_k| without trigonometry: `√(Σφ²) √(Σ A² + B²)`.
    fn displacement_bound(&self, states: &[f64]) -> f64 {
        let sq: f64 = states[..2 * self.omega.len()].iter().map(|x| x * x).sum();
        self.phi_norm * sq.sqrt()
    }
}

/// The solved felt–string interaction at one state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Interaction {
    /// Felt force (N).
    force: f64,
    /// Felt compression (m).
    felt: f64,
    /// Felt compression rate (m/s).
    felt_rate: f64,
    /// Stretch of the residual spring (m).
    residual: f64,
}

/// What [`StringContact::string_output`] tells about the string at one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StringOutput {
    /// Displacement of the string at the strike point (m), away from the striker: the
    /// modes plus the residual spring's stretch.
    pub displacement: f64,
    /// Velocity of the string at the strike point from its modes (m/s).
    pub velocity: f64,
    /// Force on the bridge (N), `n T Σ (kπ/L)(−1)^(k+1) q_k`.
    pub bridge_force: f64,
    /// Energy in the string: its modes plus the residual spring (J).
    pub energy: f64,
}

/// A felt-covered striker (shapes on a body) against a [`TautString`] that at rest is a
/// straight segment fixed to the ground. The string's displacement `u` at the strike point
/// moves the segment along its normal, away from the striker, so the felt compression is
/// `δ = d − u`, `d` the rigid penetration of the striker into the string at rest and
/// `u = Σ φ_k q_k + u_r` with `u_r` the stretch of the residual spring, solved each
/// evaluation from `F(d − Σφ_k q_k − u_r) = u_r / c_r` (monotone, Newton with a bracket).
///
/// The felt law is a [`NormalLaw`]; C&A's felt is [`crate::laws::Hertz`] `F = K δᵖ`, no
/// velocity damping: the string carries the losses. Its internal states are the string's
/// `2N` modal states (`A_k`, then `B_k`; see the module documentation) followed by the felt
/// law's. Its switching function is the felt gap `−(d − Σφ_k q_k)`, so contact onset and
/// release are events named after the element (`contact '<name>' #0`, as for
/// [`crate::Contact`]).
#[derive(Clone)]
pub struct StringContact {
    name: String,
    string: Arc<TautString>,
    /// The modes' trigonometry at the last time asked: the evaluations of one stage (Newton
    /// iterations, Jacobian columns) share their time.
    trig: TrigCache,
    /// The string at rest (a segment or a line, on the ground, world coordinates), facing
    /// the striker.
    at_rest: Shape,
    striker: ResolvedSide,
    felt: Arc<dyn NormalLaw>,
}

impl std::fmt::Debug for StringContact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StringContact")
            .field("name", &self.name)
            .field("modes", &self.string.modes())
            .field("felt", &self.felt)
            .finish_non_exhaustive()
    }
}

/// `(t, [(sin ω_k t, cos ω_k t)])` of the last time asked, behind a lock so that the
/// element stays `Sync`; a clone starts empty.
struct TrigCache(std::sync::Mutex<TrigEntry>);

/// The bits of the time, when set, and `(sin ω_k t, cos ω_k t)` per mode.
type TrigEntry = (Option<u64>, Vec<(f64, f64)>);

impl TrigCache {
    fn new(modes: usize) -> Self {
        TrigCache(std::sync::Mutex::new((None, vec![(0.0, 0.0); modes])))
    }

    /// `read` applied to the trigonometry of `string` at `t` (computed if not cached).
    fn with<T>(&self, string: &TautString, t: f64, read: impl FnOnce(&[(f64, f64)]) -> T) -> T {
        let mut guard = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let (time, trig) = &mut *guard;
        if *time != Some(t.to_bits()) {
            // Unkeyed while it is rewritten, so that an interrupted update is never read.
            *time = None;
            string.trig_at(t, trig);
            *time = Some(t.to_bits());
        }
        read(trig)
    }
}

impl Clone for TrigCache {
    fn clone(&self) -> Self {
        let modes = self
            .0
            .lock()
            .map_or_else(|e| e.into_inner().1.len(), |g| g.1.len());
        TrigCache::new(modes)
    }
}

/// Newton iterations of the series-spring solve (it converges in 3–6).
const SERIES_MAX_ITERATIONS: usize = 60;

impl StringContact {
    /// The striker `striker` (shapes on a body, e.g. the hammer crown) against `string`
    /// lying at rest along `at_rest` (a [`Shape::segment`] or [`Shape::line`] in world
    /// coordinates, its outward normal toward the striker), with the felt law `felt`.
    /// Fails on an unknown frame, a striker on the ground or without shapes, a string
    /// shape that is not a segment or a line, or a pair that cannot touch.
    pub fn new(
        model: &Model,
        name: &str,
        string: TautString,
        at_rest: Shape,
        striker: ContactSide,
        felt: impl NormalLaw + 'static,
    ) -> Result<Self> {
        let unsupported = |message: &str| ContactError::UnsupportedPair {
            contact: name.into(),
            message: message.into(),
        };
        if !matches!(at_rest, Shape::Segment(_) | Shape::Line(_)) {
            return Err(unsupported(
                "the string at rest must be a segment or a line",
            ));
        }
        let striker = resolve(model, name, &striker)?;
        if striker.body == BodyId::GROUND {
            return Err(unsupported("the striker is on the ground"));
        }
        for s in &striker.shapes {
            proximity(&at_rest, s).map_err(|e| unsupported(&e.to_string()))?;
        }
        Ok(Self {
            name: format!("contact '{name}'"),
            trig: TrigCache::new(string.modes()),
            string: Arc::new(string),
            at_rest,
            striker,
            felt: Arc::new(felt),
        })
    }

    /// The string.
    pub fn string(&self) -> &TautString {
        &self.string
    }

    /// The felt law.
    pub fn felt(&self) -> &dyn NormalLaw {
        self.felt.as_ref()
    }

    /// The string's sides as [`crate::Contact::sides`] gives them: the ground with the
    /// string at rest, then the striker's body and shapes in its joint frame.
    pub fn sides(&self) -> [(BodyId, &[Shape]); 2] {
        [
            (BodyId::GROUND, std::slice::from_ref(&self.at_rest)),
            (self.striker.body, &self.striker.shapes),
        ]
    }

    /// The element behind a force element of a `System` (`None` when it is not a
    /// [`StringContact`]).
    pub fn of(element: &dyn ForceElement) -> Option<&StringContact> {
        element.as_any()?.downcast_ref::<StringContact>()
    }

    /// The gap (m) between the striker and the string *at rest* at the state in `ctx`: the
    /// distance a technician measures to the string line (blow distance, check), free of
    /// the string's ringing. The felt's own gap is in [`StringContact::output`].
    pub fn rest_gap(&self, ctx: &ForceContext<'_>) -> f64 {
        self.rigid_proximity(ctx).gap
    }

    /// Proximity of the string at rest (A) and the striker (B), world coordinates.
    fn rigid_proximity(&self, ctx: &ForceContext<'_>) -> Proximity {
        let pose = ctx.body_pose(self.striker.body);
        let mut best: Option<Proximity> = None;
        for s in &self.striker.shapes {
            // Pairs were checked at construction.
            if let Ok(p) = proximity(&self.at_rest, &s.placed(&pose))
                && best.is_none_or(|b| p.gap < b.gap)
            {
                best = Some(p);
            }
        }
        best.unwrap_or(Proximity {
            gap: f64::INFINITY,
            normal: [0.0, 1.0],
            point_a: [0.0, 0.0],
            point_b: [0.0, 0.0],
        })
    }

    /// Felt force at compression `delta` (rates of the felt's states into `rates`).
    fn felt_force(&self, delta: f64, rate: f64, states: &[f64], rates: &mut [f64]) -> f64 {
        self.felt.force(delta, rate, states, rates).max(0.0)
    }

    /// `∂F/∂δ` of the felt: closed form when the law has one, else a forward difference.
    fn felt_stiffness(&self, delta: f64, rate: f64, states: &[f64], rates: &mut [f64]) -> f64 {
        if let Some(k) = self.felt.tangent_stiffness(delta, rate, states) {
            return k;
        }
        let h = 1e-7 * delta.abs().max(1e-9);
        (self.felt_force(delta + h, rate, states, rates)
            - self.felt_force(delta, rate, states, rates))
            / h
    }

    /// Solves the felt in series with the residual spring for a modal penetration `dm > 0`
    /// (`d − Σφ_k q_k`) and its rate: `F(dm − u_r) = u_r / c_r`. The residual `g(u) =
    /// F(dm − u) − u/c_r` falls from `F(dm) ≥ 0` at `u = 0` to `≤ 0` at `u = c_r F(dm)`:
    /// Newton inside that bracket, bisection when a step leaves it. The felt's compression
    /// rate is `ḋm / (1 + c_r k_f)` (the spring shares the motion by compliance).
    fn interact(&self, dm: f64, dm_rate: f64, states: &[f64], rates: &mut [f64]) -> Interaction {
        let cr = self.string.residual;
        let f_full = self.felt_force(dm, dm_rate, states, rates);
        if cr <= 0.0 || f_full <= 0.0 {
            return Interaction {
                force: f_full,
                felt: dm,
                felt_rate: dm_rate,
                residual: 0.0,
            };
        }
        let mut rate = dm_rate;
        let mut u = 0.0;
        // Two passes: the felt rate depends on the tangent stiffness at the solution.
        for _pass in 0..2 {
            let (mut lo, mut hi) = (0.0, cr * self.felt_force(dm, rate, states, rates));
            for _ in 0..SERIES_MAX_ITERATIONS {
                let delta = dm - u;
                let g = self.felt_force(delta, rate, states, rates) - u / cr;
                if g > 0.0 {
                    lo = u;
                } else {
                    hi = u;
                }
                let slope = -self.felt_stiffness(delta, rate, states, rates) - 1.0 / cr;
                let mut next = u - g / slope;
                if !(next > lo && next < hi) {
                    next = 0.5 * (lo + hi);
                }
                let step = (next - u).abs();
                u = next;
                if step <= 1e-15 * dm || hi - lo <= 1e-15 * dm {
                    break;
                }
            }
            let k = self.felt_stiffness(dm - u, rate, states, rates);
            rate = dm_rate / (1.0 + cr * k);
        }
        let felt = dm - u;
        let force = self.felt_force(felt, rate, states, rates);
        Interaction {
            force,
            felt,
            felt_rate: rate,
            residual: u,
        }
    }

    /// Everything at one state: the rigid proximity, the modal displacement and velocity
    /// at the strike point, the rigid penetration rate and the interaction. `rates` takes
    /// the felt law's state rates.
    fn evaluate(
        &self,
        ctx: &ForceContext<'_>,
        p: Proximity,
        law_rates: &mut [f64],
    ) -> (f64, f64, f64, Interaction) {
        let ns = self.string.state_count();
        let (modal, law_states) = ctx.states.split_at(ns);
        let (u, u_rate) = self.trig.with(&self.string, ctx.t, |trig| {
            self.string.strike_point_motion_from(trig, modal)
        });
        let point = [
            0.5 * (p.point_a[0] + p.point_b[0]),
            0.5 * (p.point_a[1] + p.point_b[1]),
        ];
        let v = velocity_at(ctx, self.striker.body, point);
        // ġ₀ = v_B · n (the string at rest does not move)
        let gap_rate = v[0] * p.normal[0] + v[1] * p.normal[1];
        let dm = -(p.gap + u);
        let dm_rate = -(gap_rate + u_rate);
        let inter = if dm > 0.0 && p.gap.is_finite() {
            self.interact(dm, dm_rate, law_states, law_rates)
        } else {
            // Apart: no force; a law with memory still relaxes.
            let f = self.felt_force(dm, dm_rate, law_states, law_rates);
            Interaction {
                force: f,
                felt: dm,
                felt_rate: dm_rate,
                residual: 0.0,
            }
        };
        (u, u_rate, gap_rate, inter)
    }

    /// Gap, force, point, normal and power at the state in `ctx`, in the form
    /// [`crate::Contact::output`] gives: `gap` is the felt's own gap (`−δ` in contact),
    /// `gap_rate` its rate, `power` the rate of work of the contact forces on striker and
    /// string (`F ġ`, negative while the felt is compressed), `point` midway between the
    /// felt surface and the displaced string.
    pub fn output(&self, ctx: &ForceContext<'_>) -> ContactOutput {
        let mut rates = vec![0.0; self.felt.state_count()];
        let p = self.rigid_proximity(ctx);
        let (u, _, _, inter) = self.evaluate(ctx, p, &mut rates);
        let shift = u + inter.residual;
        let on_string = [
            p.point_a[0] - shift * p.normal[0],
            p.point_a[1] - shift * p.normal[1],
        ];
        let t = p.tangent();
        let v = velocity_at(ctx, self.striker.body, p.point_b);
        ContactOutput {
            active: inter.force > 0.0,
            gap: -inter.felt,
            gap_rate: -inter.felt_rate,
            slip: v[0] * t[0] + v[1] * t[1],
            normal_force: inter.force,
            tangential_force: 0.0,
            power: -inter.force * inter.felt_rate,
            point: [
                0.5 * (on_string[0] + p.point_b[0]),
                0.5 * (on_string[1] + p.point_b[1]),
            ],
            normal: p.normal,
        }
    }

    /// The string at the state in `ctx`: displacement and velocity at the strike point,
    /// bridge force and energy (modes plus residual spring).
    pub fn string_output(&self, ctx: &ForceContext<'_>) -> StringOutput {
        let mut rates = vec![0.0; self.felt.state_count()];
        let p = self.rigid_proximity(ctx);
        let (u, u_rate, _, inter) = self.evaluate(ctx, p, &mut rates);
        let modal = &ctx.states[..self.string.state_count()];
        let cr = self.string.residual;
        let spring = if cr > 0.0 {
            0.5 * inter.residual * inter.residual / cr
        } else {
            0.0
        };
        StringOutput {
            displacement: u + inter.residual,
            velocity: u_rate,
            bridge_force: self.string.bridge_force(ctx.t, modal),
            energy: self.string.modal_energy(modal) + spring,
        }
    }

    /// Energy stored in the felt at compression `delta` for a memoryless law:
    /// `∫₀^δ F(s) ds` by 8-point Gauss–Legendre (0 for laws with states).
    fn felt_energy(&self, delta: f64) -> f64 {
        if delta <= 0.0 || self.felt.state_count() > 0 {
            return 0.0;
        }
        const X: [f64; 4] = [
            0.183_434_642_495_649_8,
            0.525_532_409_916_329,
            0.796_666_477_413_626_7,
            0.960_289_856_497_536_3,
        ];
        const W: [f64; 4] = [
            0.362_683_783_378_362,
            0.313_706_645_877_887_3,
            0.222_381_034_453_374_5,
            0.101_228_536_290_376_3,
        ];
        let half = 0.5 * delta;
        let mut sum = 0.0;
        for (x, w) in X.iter().zip(W) {
            for s in [-x, *x] {
                sum += w * self.felt_force(half * (1.0 + s), 0.0, &[], &mut []);
            }
        }
        half * sum
    }
}

impl ForceElement for StringContact {
    fn name(&self) -> &str {
        &self.name
    }

    fn check_model(&self, model: &Model) -> mbs_core::Result<()> {
        if self.striker.body.index() >= model.nbodies() {
            return Err(mbs_core::CoreError::InvalidParameter {
                item: self.name.clone(),
                message: "built for another model".into(),
            });
        }
        Ok(())
    }

    fn state_count(&self) -> usize {
        self.string.state_count() + self.felt.state_count()
    }

    /// The modal amplitudes, when the felt ignores its compression rate: their rates
    /// (`∝ F (−sin ω_k t, cos ω_k t)`) are orthogonal at a fixed time to the strike-point
    /// displacement they feed (`∝ (cos ω_k t, sin ω_k t)`), so moving them along their rates
    /// changes no force. The string then costs the implicit integrator no Jacobian column
    /// and no elimination (a dense LU of the whole modal block made a keystroke 8 × slower).
    /// A rate-dependent felt also sees the strike point's velocity, which the rates do move:
    /// its columns stay in.
    fn states_outside_jacobian(&self) -> std::ops::Range<usize> {
        if self.felt.rate_independent() {
            0..self.string.state_count()
        } else {
            0..0
        }
    }

    fn apply(&self, ctx: &ForceContext<'_>, loads: &mut Loads<'_>, rates: &mut [f64]) {
        let ns = self.string.state_count();
        let (modal_rates, law_rates) = rates.split_at_mut(ns);
        modal_rates.fill(0.0);
        let p = self.rigid_proximity(ctx);
        // Apart by more than the string can have moved: no force, rates zero (a
        // memoryless felt has nothing to relax).
        if self.felt.state_count() == 0
            && p.gap - self.string.displacement_bound(&ctx.states[..ns]) > 0.0
        {
            return;
        }
        let (_, _, _, inter) = self.evaluate(ctx, p, law_rates);
        if inter.force <= 0.0 {
            return;
        }
        let f = inter.force;
        let point = [
            0.5 * (p.point_a[0] + p.point_b[0]),
            0.5 * (p.point_a[1] + p.point_b[1]),
        ];
        // The felt pushes the striker along n, the string along −n (the ground takes
        // nothing: the string's motion is its modes).
        loads.add_force_at_point(self.striker.body, point, [f * p.normal[0], f * p.normal[1]]);
        // dA_k/dt = −φ_k F sin(ω_k t)/(M ω_k) ; dB_k/dt = φ_k F cos(ω_k t)/(M ω_k)
        let s = &self.string;
        let n = s.modes();
        let (da, db) = modal_rates.split_at_mut(n);
        self.trig.with(s, ctx.t, |trig| {
            for k in 0..n {
                let (sin, cos) = trig[k];
                let g = s.gain[k] * f;
                da[k] = -g * sin;
                db[k] = g * cos;
            }
        });
    }

    /// With a memoryless, rate-independent felt (the string's modes then stay out of the
    /// Jacobian, see [`ForceElement::states_outside_jacobian`]).
    fn has_load_derivatives(&self) -> bool {
        self.felt.state_count() == 0 && self.felt.rate_independent()
    }

    /// `∂F/∂d_m` of the felt in series with the residual spring (a central difference of
    /// the series solution), through the penetration `d_m = −(n·Δ + u)` at the contact
    /// point: the force on the striker, and the modal rates `∝ F`.
    fn load_derivatives(&self, ctx: &ForceContext<'_>, jac: &mut LoadJacobian<'_>) {
        let ns = self.string.state_count();
        let p = self.rigid_proximity(ctx);
        if !p.gap.is_finite() || p.gap - self.string.displacement_bound(&ctx.states[..ns]) > 0.0 {
            return;
        }
        let (_, _, _, inter) = self.evaluate(ctx, p, &mut []);
        if inter.force <= 0.0 {
            return;
        }
        // In series with the residual spring (F = u_r / c_r at the felt's compression
        // d_m − u_r): ∂F/∂d_m = k_f / (1 + c_r k_f), k_f the felt's tangent stiffness.
        let kf = self.felt_stiffness(inter.felt, inter.felt_rate, &[], &mut []);
        let kd = kf / (1.0 + self.string.residual.max(0.0) * kf);
        let n = p.normal;
        let dq = [
            [-kd * n[0] * n[0], -kd * n[0] * n[1]],
            [-kd * n[1] * n[0], -kd * n[1] * n[1]],
        ];
        let point = [
            0.5 * (p.point_a[0] + p.point_b[0]),
            0.5 * (p.point_a[1] + p.point_b[1]),
        ];
        jac.set_point(BodyId::GROUND, self.striker.body, point);
        jac.add_point_force(dq, [[0.0; 2]; 2]);
        // dA_k/dt = −g_k F sin(ω_k t), dB_k/dt = g_k F cos(ω_k t), with ∂F/∂Δ = −k_d n.
        let s = &self.string;
        let modes = s.modes();
        let dir = [kd * n[0], kd * n[1]];
        self.trig.with(s, ctx.t, |trig| {
            jac.add_rates_at_point(0..modes, dir, [0.0; 2], |k| s.gain[k] * trig[k].0);
            jac.add_rates_at_point(modes..2 * modes, dir, [0.0; 2], |k| {
                -s.gain[k - modes] * trig[k - modes].1
            });
        });
    }

    fn potential_energy(&self, ctx: &ForceContext<'_>) -> f64 {
        let mut rates = vec![0.0; self.felt.state_count()];
        let p = self.rigid_proximity(ctx);
        let modal = &ctx.states[..self.string.state_count()];
        if !p.gap.is_finite() {
            return self.string.modal_energy(modal);
        }
        let (_, _, _, inter) = self.evaluate(ctx, p, &mut rates);
        let cr = self.string.residual;
        let spring = if cr > 0.0 {
            0.5 * inter.residual * inter.residual / cr
        } else {
            0.0
        };
        self.string.modal_energy(modal) + spring + self.felt_energy(inter.felt)
    }

    fn switch_count(&self) -> usize {
        1
    }

    fn switching_functions(&self, ctx: &ForceContext<'_>, out: &mut [f64]) {
        let ns = self.string.state_count();
        let modal = &ctx.states[..ns];
        let p = self.rigid_proximity(ctx);
        // Far from the string a lower bound of the felt gap has the same (positive) sign.
        let lower = p.gap - self.string.displacement_bound(modal);
        out[0] = if lower > 0.0 {
            lower
        } else {
            p.gap
                + self
                    .trig
                    .with(&self.string, ctx.t, |trig| {
                        self.string.strike_point_motion_from(trig, modal)
                    })
                    .0
        };
    }

    fn switch_direction(&self, _k: usize) -> Crossing {
        Crossing::Both
    }

    fn as_any(&self) -> Option<&dyn std::any::Any> {
        Some(self)
    }
}

/// Renders the bridge force of a [`TautString`] as sound: the modes evolve analytically
/// between the samples with their losses `σ_k = b₁ + b₃ ω_k²`, and what the contact adds to
/// the (lossless) modal amplitudes between two samples is injected at the later sample
/// (exact in free vibration; the losses during a 2 ms contact, under 1 %, are applied from
/// the next sample on). Modes above `0.45 fs` are left out.
#[derive(Clone, Debug)]
pub struct BridgeForceRenderer<'a> {
    string: &'a TautString,
    /// Complex lossy amplitudes `r_k` with `q_k = Re(r_k e^{iω_k t})`: (re, im).
    amplitude: Vec<(f64, f64)>,
    /// The lossless `A_k − i B_k` of the previous sample.
    last: Vec<(f64, f64)>,
    /// Per-sample decay `e^{−σ_k Δt}`.
    decay: Vec<f64>,
    /// Modes kept (below 0.45 fs).
    kept: usize,
    dt: f64,
}

impl<'a> BridgeForceRenderer<'a> {
    /// A renderer at `sample_rate_hz` (> 0) for `string`, starting from a string at rest.
    pub fn new(string: &'a TautString, sample_rate_hz: f64) -> Result<Self> {
        let fs = positive("sample_rate_hz", sample_rate_hz)?;
        let dt = 1.0 / fs;
        let kept = string
            .omega
            .iter()
            .take_while(|w| **w < 0.45 * 2.0 * PI * fs)
            .count();
        let decay = (1..=kept)
            .map(|k| (-string.decay_rate(k).unwrap_or(0.0) * dt).exp())
            .collect();
        Ok(Self {
            string,
            amplitude: vec![(0.0, 0.0); kept],
            last: vec![(0.0, 0.0); kept],
            decay,
            kept,
            dt,
        })
    }

    /// Time between samples (s).
    pub fn sample_period(&self) -> f64 {
        self.dt
    }

    /// Advances by one sample to time `t` with the string's lossless states `states`
    /// (`[A_1..A_N, B_1..B_N]` at `t`) and returns the bridge force there (N).
    pub fn sample(&mut self, t: f64, states: &[f64]) -> f64 {
        let s = self.string;
        let n = s.modes();
        let mut force = 0.0;
        for k in 0..self.kept {
            // r ← r e^{−σΔt} + (c_now − c_last), c = A − iB
            let c = (states[k], -states[n + k]);
            let (lr, li) = self.last[k];
            let (r, i) = self.amplitude[k];
            let d = self.decay[k];
            let (r, i) = (r * d + c.0 - lr, i * d + c.1 - li);
            self.amplitude[k] = (r, i);
            self.last[k] = c;
            // q = Re(r e^{iωt}) = r_re cos ωt − r_im sin ωt
            let (sin, cos) = (s.omega[k] * t).sin_cos();
            force += s.bridge[k] * (r * cos - i * sin);
        }
        force
    }
}
