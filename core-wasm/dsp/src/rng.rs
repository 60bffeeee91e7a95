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
        xoshiro_next(&mut self.s)
    }

    /// Uniform in [0, 1) with 53 random bits.
    pub fn uniform(&mut self) -> f64 {
        unit(self.next_u64())
    }

    /// Standard normal deviate (Marsaglia polar method; the second deviate of
    /// each pair is kept for the next call).
    pub fn gaussian(&mut self) -> f64 {
        if let Some(z) = self.spare.take() {
            return z;
        }
        let (a, b) = polar_pair(&mut self.s);
        self.spare = Some(b);
        a
    }

    /// The xoshiro256++ state (the EMG synthesiser keeps its channels'
    /// states side by side); only valid while no Gaussian deviate is spare.
    pub(crate) fn state(&self) -> [u64; 4] {
        debug_assert!(self.spare.is_none());
        self.s
    }
}

/// One step of xoshiro256++ on the state `s`: the next 64 random bits.
#[inline(always)]
pub(crate) fn xoshiro_next(s: &mut [u64; 4]) -> u64 {
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

/// 64 random bits to a uniform double in [0, 1) (the top 53 bits).
#[inline(always)]
pub(crate) fn unit(x: u64) -> f64 {
    (x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

/// A pair of independent standard normal deviates by the Marsaglia polar
/// method: uniform points `(u, v)` of the square until one falls inside the
/// unit circle (`0 < s = u² + v² < 1`), then `(u·m, v·m)` with
/// `m = sqrt(−2·ln(s)/s)`.
#[inline(always)]
pub(crate) fn polar_pair(state: &mut [u64; 4]) -> (f64, f64) {
    loop {
        let u = 2.0 * unit(xoshiro_next(state)) - 1.0;
        let v = 2.0 * unit(xoshiro_next(state)) - 1.0;
        let s = u * u + v * v;
        if s > 0.0 && s < 1.0 {
            let m = (-2.0 * s.ln() / s).sqrt();
            return (u * m, v * m);
        }
    }
}

/// [`polar_pair`] for two generators at once (SIMD128), first half: the
/// point `(u, v, s = u² + v²)` inside the unit circle; `state[i]` holds word
/// `i` of both states. Each lane draws exactly the numbers that [`polar_pair`]
/// would and keeps the first point inside the circle, so with
/// [`polar_scale_x2`] the deviates are bit-identical ([`ln_x2`] is the scalar
/// `ln`, `f64x2.sqrt` is correctly rounded as `f64::sqrt`).
///
/// Two candidate points per lane are drawn without a branch (both fall outside
/// in 4.6 % of the draws per lane): a loop whose exit depended on every single
/// draw would mispredict once in three pairs. Drawing the points of many
/// samples first and scaling them afterwards in a short loop lets the long
/// chains of the logarithm, the division and the square root of several
/// samples overlap.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
pub(crate) fn polar_point_x2(
    state: &mut [core::arch::wasm32::v128; 4],
) -> (
    core::arch::wasm32::v128,
    core::arch::wasm32::v128,
    core::arch::wasm32::v128,
) {
    use core::arch::wasm32::*;
    let mut after_one = *state;
    let (u1, v1, s1, in1) = candidate_x2(&mut after_one);
    let mut after_two = after_one;
    let (u2, v2, s2, in2) = candidate_x2(&mut after_two);
    // Lanes with a first point inside have drawn two numbers, the others four.
    for (w, (a, b)) in state.iter_mut().zip(after_one.into_iter().zip(after_two)) {
        *w = v128_bitselect(a, b, in1);
    }
    let mut u = v128_bitselect(u1, u2, in1);
    let mut v = v128_bitselect(v1, v2, in1);
    let mut s = v128_bitselect(s1, s2, in1);
    let mut done = v128_or(in1, in2);
    while !i64x2_all_true(done) {
        // Rare: one lane (or both) needs more points; the lanes done keep theirs.
        let mut next = *state;
        let (un, vn, sn, inside) = candidate_x2(&mut next);
        for (w, n) in state.iter_mut().zip(next) {
            *w = v128_bitselect(*w, n, done);
        }
        let take = v128_andnot(inside, done);
        u = v128_bitselect(un, u, take);
        v = v128_bitselect(vn, v, take);
        s = v128_bitselect(sn, s, take);
        done = v128_or(done, inside);
    }
    (u, v, s)
}

/// `(u·m, v·m)` with `m = sqrt(−2·ln(s)/s)`: the deviates of a point of
/// [`polar_point_x2`].
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
pub(crate) fn polar_scale_x2(
    u: core::arch::wasm32::v128,
    v: core::arch::wasm32::v128,
    s: core::arch::wasm32::v128,
) -> (core::arch::wasm32::v128, core::arch::wasm32::v128) {
    use core::arch::wasm32::*;
    let m = f64x2_sqrt(f64x2_div(f64x2_mul(f64x2_splat(-2.0), ln_x2(s)), s));
    (f64x2_mul(u, m), f64x2_mul(v, m))
}

/// One candidate point of the polar method per lane: `(u, v, s, inside)`.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
fn candidate_x2(
    state: &mut [core::arch::wasm32::v128; 4],
) -> (
    core::arch::wasm32::v128,
    core::arch::wasm32::v128,
    core::arch::wasm32::v128,
    core::arch::wasm32::v128,
) {
    use core::arch::wasm32::*;
    let u = signed_unit_x2(xoshiro_next_x2(state));
    let v = signed_unit_x2(xoshiro_next_x2(state));
    let one = f64x2_splat(1.0);
    let s = f64x2_add(f64x2_mul(u, u), f64x2_mul(v, v));
    let inside = v128_and(f64x2_gt(s, f64x2_splat(0.0)), f64x2_lt(s, one));
    (u, v, s, inside)
}

/// [`xoshiro_next`] on two states at once.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
fn xoshiro_next_x2(s: &mut [core::arch::wasm32::v128; 4]) -> core::arch::wasm32::v128 {
    use core::arch::wasm32::*;
    let rotl = |x: v128, k: u32| v128_or(i64x2_shl(x, k), u64x2_shr(x, 64 - k));
    let result = i64x2_add(rotl(i64x2_add(s[0], s[3]), 23), s[0]);
    let t = i64x2_shl(s[1], 17);
    s[2] = v128_xor(s[2], s[0]);
    s[3] = v128_xor(s[3], s[1]);
    s[1] = v128_xor(s[1], s[2]);
    s[0] = v128_xor(s[0], s[3]);
    s[2] = v128_xor(s[2], t);
    s[3] = rotl(s[3], 45);
    result
}

/// `2·unit(x) − 1` on two lanes, as the scalar code computes it: with
/// `m = x >> 11` (53 bits) that is exactly `m·2⁻⁵² − 1` (every step is exact).
/// Here `m·2⁻⁵² − 1` is assembled exactly from its even part (`x >> 12` as
/// the mantissa of a double in [2, 4), minus 3) and its last bit (0 or 2⁻⁵²),
/// so the bits are the same.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
fn signed_unit_x2(x: core::arch::wasm32::v128) -> core::arch::wasm32::v128 {
    use core::arch::wasm32::*;
    const TWO: u64 = 0x4000_0000_0000_0000;
    const ONE: u64 = 0x3ff0_0000_0000_0000;
    let even = f64x2_sub(
        v128_or(u64x2_shr(x, 12), u64x2_splat(TWO)),
        f64x2_splat(3.0),
    );
    let last = v128_or(v128_and(u64x2_shr(x, 11), u64x2_splat(1)), u64x2_splat(ONE));
    f64x2_add(even, f64x2_sub(last, f64x2_splat(1.0)))
}

/// The natural logarithm of two positive normal doubles below 2, the same
/// algorithm and the same operations as the `log` of the wasm build's math
/// library (Rust's `libm`, a port of musl/FreeBSD `e_log.c`), so it gives the
/// same bits as `f64::ln` there (checked over millions of values by
/// `app/engine/dsp/simd.test.ts`). Zero, negative, subnormal, infinite and NaN
/// inputs are not handled (the polar method never passes them).
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
pub(crate) fn ln_x2(x: core::arch::wasm32::v128) -> core::arch::wasm32::v128 {
    use core::arch::wasm32::*;
    // The constants of e_log.c, by their bits.
    let ln2_hi = f64::from_bits(0x3fe6_2e42_fee0_0000);
    let ln2_lo = f64::from_bits(0x3dea_39ef_3579_3c76);
    let lg1 = f64::from_bits(0x3fe5_5555_5555_5593);
    let lg2 = f64::from_bits(0x3fd9_9999_9997_fa04);
    let lg3 = f64::from_bits(0x3fd2_4924_9422_9359);
    let lg4 = f64::from_bits(0x3fcc_71c5_1d8e_78af);
    let lg5 = f64::from_bits(0x3fc7_4664_96cb_03de);
    let lg6 = f64::from_bits(0x3fc3_9a09_d078_c69f);
    let lg7 = f64::from_bits(0x3fc2_f112_df3e_5244);
    let sp = f64x2_splat;
    // Reduce x into [sqrt(2)/2, sqrt(2)]: x = 2^k · (1 + f).
    let hx = i64x2_add(u64x2_shr(x, 32), i64x2_splat(0x3ff0_0000 - 0x3fe6_a09e));
    let k = i64x2_sub(u64x2_shr(hx, 20), i64x2_splat(0x3ff));
    let hx = i64x2_add(
        v128_and(hx, i64x2_splat(0x000f_ffff)),
        i64x2_splat(0x3fe6_a09e),
    );
    let x = v128_or(i64x2_shl(hx, 32), v128_and(x, i64x2_splat(0xffff_ffff)));
    let f = f64x2_sub(x, sp(1.0));
    let hfsq = f64x2_mul(f64x2_mul(sp(0.5), f), f);
    let s = f64x2_div(f, f64x2_add(sp(2.0), f));
    let z = f64x2_mul(s, s);
    let w = f64x2_mul(z, z);
    let t1 = f64x2_mul(
        w,
        f64x2_add(
            sp(lg2),
            f64x2_mul(w, f64x2_add(sp(lg4), f64x2_mul(w, sp(lg6)))),
        ),
    );
    let t2 = f64x2_mul(
        z,
        f64x2_add(
            sp(lg1),
            f64x2_mul(
                w,
                f64x2_add(
                    sp(lg3),
                    f64x2_mul(w, f64x2_add(sp(lg5), f64x2_mul(w, sp(lg7)))),
                ),
            ),
        ),
    );
    let r = f64x2_add(t2, t1);
    // k fits in 32 bits: gather the low halves of the two lanes and convert.
    let dk = f64x2_convert_low_i32x4(i32x4_shuffle::<0, 2, 0, 2>(k, k));
    // s·(hfsq + R) + dk·ln2_lo − hfsq + f + dk·ln2_hi, left to right.
    let y = f64x2_add(f64x2_mul(s, f64x2_add(hfsq, r)), f64x2_mul(dk, sp(ln2_lo)));
    let y = f64x2_add(f64x2_sub(y, hfsq), f);
    f64x2_add(y, f64x2_mul(dk, sp(ln2_hi)))
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
