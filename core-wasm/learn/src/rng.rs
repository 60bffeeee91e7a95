//! The seeded generator that draws the random Fourier features:
//! xoshiro256++ (Blackman & Vigna, <https://prng.di.unimi.it/>) seeded by
//! splitmix64, uniform deviates with 53 random bits and Gaussian deviates by
//! the Marsaglia polar method. Same seed, same draws, on every platform
//! (integer arithmetic, and `ln`/`sqrt` of the same doubles).

/// The splitmix64 output function (a bijective 64-bit mixer).
fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// xoshiro256++ with a cached second Gaussian deviate.
#[derive(Debug, Clone)]
pub(crate) struct Rng {
    s: [u64; 4],
    spare: Option<f64>,
}

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        let mut x = seed;
        let mut next = || {
            x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            mix64(x)
        };
        // splitmix64 is a bijection of its counter, so four consecutive
        // outputs are never all zero (the one state xoshiro must avoid).
        let s = [next(), next(), next(), next()];
        Rng { s, spare: None }
    }

    pub(crate) fn next_u64(&mut self) -> u64 {
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

    /// Uniform in [0, 1) with 53 random bits.
    pub(crate) fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal deviate.
    pub(crate) fn gaussian(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        loop {
            let u = 2.0 * self.uniform() - 1.0;
            let v = 2.0 * self.uniform() - 1.0;
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let m = (-2.0 * s.ln() / s).sqrt();
                self.spare = Some(v * m);
                return u * m;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xoshiro256pp_known_answer() {
        // State {1, 2, 3, 4}: first outputs of the reference C implementation.
        let mut r = Rng {
            s: [1, 2, 3, 4],
            spare: None,
        };
        assert_eq!(r.next_u64(), 41_943_041);
        assert_eq!(r.next_u64(), 58_720_359);
        assert_eq!(r.next_u64(), 3_588_806_011_781_223);
    }

    #[test]
    fn splitmix64_seeding_known_answer() {
        // splitmix64 seeded with 0 gives 0xE220A8397B1DCDAF first.
        let r = Rng::new(0);
        assert_eq!(r.s[0], 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.s[1], 0x6E78_9E6A_A1B9_65F4);
    }

    #[test]
    fn moments() {
        let mut r = Rng::new(7);
        let n = 200_000;
        let (mut g1, mut g2, mut u1) = (0.0, 0.0, 0.0);
        for _ in 0..n {
            let z = r.gaussian();
            g1 += z;
            g2 += z * z;
            u1 += r.uniform();
        }
        let n = n as f64;
        assert!((g1 / n).abs() < 0.01);
        assert!((g2 / n - 1.0).abs() < 0.02);
        assert!((u1 / n - 0.5).abs() < 0.005);
    }
}
