//! A small seeded random generator for synthetic data: xoshiro256++ (Blackman & Vigna
//! 2019) seeded through SplitMix64, with Gaussian draws by the Marsaglia polar method.
//!
//! Written here rather than taken from `rand` so that a seed gives the same dataset on
//! every platform and in every future version: the synthetic tests and the datasets users
//! share depend on it.

/// The generator.
#[derive(Clone, Debug)]
pub struct Rng {
    s: [u64; 4],
    spare: Option<f64>,
}

impl Rng {
    /// A generator seeded with `seed` (any value, 0 included).
    pub fn new(seed: u64) -> Self {
        // SplitMix64 spreads the seed over the 256-bit state (never all zero).
        let mut z = seed;
        let mut next = || {
            z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut x = z;
            x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            x ^ (x >> 31)
        };
        Self {
            s: [next(), next(), next(), next()],
            spare: None,
        }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        // xoshiro256++: result = rotl(s0 + s3, 23) + s0.
        let s = &mut self.s;
        let result = s[0].wrapping_add(s[3]).rotate_left(23).wrapping_add(s[0]);
        let t = s[1] << 17;
        s[2] ^= s[0];
        s[3] ^= s[1];
        s[1] ^= s[2];
        s[0] ^= s[3];
        s[2] ^= t;
        s[3] = s[3].rotate_left(45);
        result
    }

    /// A uniform draw in [0, 1) (53 random bits).
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A uniform draw in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// A standard normal draw.
    pub fn normal(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        // Marsaglia polar: (u, v) uniform in the unit disc gives two independent normals.
        loop {
            let u = 2.0 * self.uniform() - 1.0;
            let v = 2.0 * self.uniform() - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let f = (-2.0 * s.ln() / s).sqrt();
                self.spare = Some(v * f);
                return u * f;
            }
        }
    }

    /// `n` samples of AR(1) noise with marginal standard deviation `sigma` and lag-one
    /// correlation `rho` (|rho| < 1), started in its stationary distribution:
    /// `e_k = ρ e_{k−1} + √(1 − ρ²) σ ξ_k`.
    pub fn ar1(&mut self, n: usize, sigma: f64, rho: f64) -> Vec<f64> {
        let innovation = (1.0 - rho * rho).max(0.0).sqrt() * sigma;
        let mut e = sigma * self.normal();
        (0..n)
            .map(|k| {
                if k > 0 {
                    e = rho * e + innovation * self.normal();
                }
                e
            })
            .collect()
    }
}
