//! WebAssembly SIMD128 paths of the hot kernels.
//!
//! The wasm build (`scripts/build-wasm.sh`) compiles with
//! `-C target-feature=+simd128`; there the feature kernel ([`crate::FeatureKernel`],
//! with a one-pass path for MAV, WL, ZC and SSC) and the EMG synthesiser
//! ([`crate::EmgSynth`], with a two-lane logarithm) process two channels per
//! instruction (`f64x2`, `i64x2`). Every other build (the native
//! `cargo test`) has only the scalar code.
//!
//! The biquad of [`crate::FilterBank`] stays scalar: SIMD128 versions (row by
//! row over the channels, or strips of 2–8 channels running through a block
//! of events with their state in registers) ran 1.4–2× *slower* in V8 than
//! the scalar loop (about 1 ns per channel-sample), which is memory-bound
//! and a few per cent of a replay's time.
//!
//! The SIMD paths vectorise **across channels** only: every channel still
//! goes through the same IEEE operations in the same order as in the scalar
//! code (no fused multiply-add, no reassociation, sums in sample order), so
//! the two paths give bit-identical results. The scalar code stays compiled
//! into the wasm module too, and [`set_simd_enabled`] switches between them at
//! run time, so that a test of the wasm module can compare both paths
//! (`app/engine/dsp/simd.test.ts`).
//!
//! ```
//! // Native builds have no SIMD path: the switch reports that.
//! assert_eq!(mosaic_dsp::set_simd_enabled(true), mosaic_dsp::SIMD_COMPILED);
//! ```

use core::sync::atomic::{AtomicBool, Ordering};

/// `true` in builds that contain the SIMD128 paths (wasm32 with `simd128`).
pub const SIMD_COMPILED: bool = cfg!(all(target_arch = "wasm32", target_feature = "simd128"));

static ENABLED: AtomicBool = AtomicBool::new(true);

/// Chooses the SIMD paths (`true`, the default) or the scalar code (`false`)
/// for the kernels created or called from now on; for tests and comparisons.
/// Returns [`SIMD_COMPILED`]: without SIMD paths the switch changes nothing.
pub fn set_simd_enabled(enabled: bool) -> bool {
    ENABLED.store(enabled, Ordering::Relaxed);
    SIMD_COMPILED
}

/// Whether the kernels use their SIMD paths now.
#[inline(always)]
pub fn simd_enabled() -> bool {
    SIMD_COMPILED && ENABLED.load(Ordering::Relaxed)
}

/// Loads and stores of `v128` from and to slices, bounds-checked.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[allow(unsafe_code)]
pub(crate) mod v {
    pub(crate) use core::arch::wasm32::*;

    /// Values `i`, `i + 1` of `s`.
    #[inline(always)]
    pub(crate) fn ld(s: &[f64], i: usize) -> v128 {
        let p: &[f64; 2] = s[i..i + 2].try_into().expect("two values");
        // SAFETY: `p` is 16 readable bytes; v128.load has no alignment requirement.
        unsafe { v128_load(p.as_ptr().cast()) }
    }

    /// Stores `x` into values `i`, `i + 1` of `s`.
    #[inline(always)]
    pub(crate) fn st(s: &mut [f64], i: usize, x: v128) {
        let p: &mut [f64; 2] = (&mut s[i..i + 2]).try_into().expect("two values");
        // SAFETY: `p` is 16 writable bytes; v128.store has no alignment requirement.
        unsafe { v128_store(p.as_mut_ptr().cast(), x) }
    }

    /// Values `i`, `i + 1` of `s`.
    #[inline(always)]
    pub(crate) fn ld_u64(s: &[u64], i: usize) -> v128 {
        let p: &[u64; 2] = s[i..i + 2].try_into().expect("two values");
        // SAFETY: as `ld`.
        unsafe { v128_load(p.as_ptr().cast()) }
    }

    /// Stores `x` into values `i`, `i + 1` of `s`.
    #[inline(always)]
    pub(crate) fn st_u64(s: &mut [u64], i: usize, x: v128) {
        let p: &mut [u64; 2] = (&mut s[i..i + 2]).try_into().expect("two values");
        // SAFETY: as `st`.
        unsafe { v128_store(p.as_mut_ptr().cast(), x) }
    }
}
