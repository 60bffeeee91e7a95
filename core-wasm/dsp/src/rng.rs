//! Deterministic pseudo-random numbers: xoshiro256++ seeded by splitmix64
//! (both by Blackman & Vigna, <https://prng.di.unimi.it/>), and Gaussian
//! deviates by the Marsaglia polar method. Same seed, same draws, on every
//! platform (integer arithmetic, and `ln`/`sqrt` of the same doubles). Shared
//! by the EMG synthesiser and mosaic-learn's random Fourier features.

/// splitmix64: used only to expand a 64-bit seed into xoshiro state.
#[derive(Debug, Clone)]
pub(crate) struct SplitMix64(u64);

impl SplitMix64 {
    pub(crate) fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        mix64(self.0)
    }
}

/// The splitmix64 output function (a bijective 64-bit mixer).
pub(crate) fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// xoshiro256++ with a cached second Gaussian deviate.
#[derive(Debug, Clone)]
pub struct Rng {
    s: [u64; 4],
    spare: Option<f64>,
}

impl Rng {
    /// Seeds the generator for one stream (`stream` = channel index) of `seed`.
    pub fn new(seed: u64, stream: u64) -> Self {
        Rng::from_seed(seed ^ mix64(stream.wrapping_add(1)))
    }

    /// Seeds the generator with four consecutive splitmix64 outputs of `seed`.
    ///
    /// ```
    /// let mut a = mosaic_dsp::rng::Rng::from_seed(3);
    /// let mut b = mosaic_dsp::rng::Rng::from_seed(3);
    /// assert_eq!(a.next_u64(), b.next_u64());
    /// ```
    pub fn from_seed(seed: u64) -> Self {
        let mut sm = SplitMix64::new(seed);
        let s = [sm.next_u64(), sm.next_u64(), sm.next_u64(), sm.next_u64()];
        // splitmix64 is a bijection of its counter, so four consecutive outputs
        // are never all zero (the one state xoshiro must avoid).
        Rng { s, spare: None }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
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
    pub fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Standard normal deviate (Marsaglia polar method; the second deviate of
    /// each pair is kept for the next call).
    pub fn gaussian(&mut self) -> f64 {
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
    fn splitmix64_known_answer() {
        // Reference values of splitmix64 seeded with 0.
        let mut sm = SplitMix64::new(0);
        assert_eq!(sm.next_u64(), 0xE220_A839_7B1D_CDAF);
        assert_eq!(sm.next_u64(), 0x6E78_9E6A_A1B9_65F4);
    }

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
    fn from_seed_takes_the_splitmix64_outputs_of_the_seed() {
        let r = Rng::from_seed(0);
        assert_eq!(r.s[0], 0xE220_A839_7B1D_CDAF);
        assert_eq!(r.s[1], 0x6E78_9E6A_A1B9_65F4);
    }

    #[test]
    fn gaussian_moments() {
        let mut r = Rng::new(7, 0);
        let n = 200_000;
        let (mut s1, mut s2) = (0.0, 0.0);
        for _ in 0..n {
            let z = r.gaussian();
            s1 += z;
            s2 += z * z;
        }
        let mean = s1 / n as f64;
        let var = s2 / n as f64 - mean * mean;
        assert!(mean.abs() < 0.01, "mean {mean}");
        assert!((var - 1.0).abs() < 0.02, "var {var}");
    }
}
