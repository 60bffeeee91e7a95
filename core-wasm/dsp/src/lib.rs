//! Pure-Rust DSP kernels of MOSAIC.
//!
//! This crate has no dependencies and no binding code; the `mosaic-core-wasm`
//! crate wraps it for WebAssembly. Every kernel follows the same conventions:
//!
//! * `new(params) -> Result<Self, DspError>` validates its parameters and
//!   reports what is wrong with a message that names the parameter;
//! * `process(&mut self, input, output)` works on **row-major interleaved**
//!   buffers of `n` events × `channels` values, never allocates, never panics
//!   (a buffer of the wrong length is reported as [`DspError`]) and gives
//!   bit-identical results whether `n` events come in one call or in `n` calls;
//! * `reset()` returns the kernel to its initial state, after which the same
//!   input produces bit-identical output again.
//!
//! Kernels:
//!
//! * [`FilterBank`] — the MOSAIC *Filter* block: the difference equation
//!   (paper eq. 1) applied independently to every channel.
//! * [`FunctionKernel`] — the MOSAIC *Function* block (paper Table 1):
//!   add, multiply, abs, power, clip, element-wise.
//! * [`EmgSynth`] — a seeded multi-channel surface-EMG generator for the
//!   *EmgSimulator* block.
//! * [`design`] — second-order Butterworth designs (bilinear transform).
//! * [`SlidingWindow`] — the MOSAIC *SlidingWindow* block: windows of `L`
//!   events every `S` events, optionally tapered (Hann, Hamming, Blackman).
//! * [`FeatureKernel`] — time-domain EMG features (MAV, RMS, WL, ZC, SSC,
//!   VAR, IAV, DASDV, WAMP) of windows `[L, C]`, any subset in one pass;
//!   [`WindowedFeatures`] computes them over a sliding window of a stream.
//! * [`AdaptiveFilter`] — the MOSAIC *AdaptiveFilter* block (paper eqs. 2–4).
//! * [`ArtifactRejector`] — the MOSAIC *ArtifactRejection* block: clipping,
//!   flat line, jumps, drift per channel of a window.
//!
//! In the wasm build (`simd128`) the feature kernel and the synthesiser have
//! SIMD paths, bit-identical to the scalar code ([`set_simd_enabled`]).
//!
//! ```
//! use mosaic_dsp::{FilterBank, FunctionKernel, FunctionOp};
//!
//! // Rectify and smooth two channels.
//! let mut rectify = FunctionKernel::new(FunctionOp::Abs, 2)?;
//! let mut smooth = FilterBank::new(&[0.5, 0.5], &[1.0], 2)?;
//! let mut signal = [1.0, -2.0, -3.0, 4.0]; // 2 events × 2 channels
//! rectify.process_in_place(&mut signal)?;
//! smooth.process_in_place(&mut signal)?;
//! assert_eq!(signal, [0.5, 1.0, 2.0, 3.0]);
//! # Ok::<(), mosaic_dsp::DspError>(())
//! ```
// `unsafe` only in `simd` (v128 loads and stores of bounds-checked slices).
#![deny(unsafe_code)]
#![warn(missing_docs)]

mod adaptive;
mod artifact;
pub mod design;
mod error;
mod features;
mod filter;
mod function;
pub mod rng;
mod simd;
mod synth;
mod window;

pub use adaptive::{AdaptiveFilter, AdaptiveFilterConfig, DerivativeOrder};
pub use artifact::{ArtifactConfig, ArtifactReason, ArtifactRejector, ARTIFACT_COUNTERS};
pub use error::DspError;
pub use features::{Feature, FeatureKernel, FeatureSpec};
pub use filter::FilterBank;
pub use function::{FunctionKernel, FunctionOp};
pub use simd::{set_simd_enabled, simd_enabled, SIMD_COMPILED};
pub use synth::{EmgSynth, EmgSynthConfig};
pub use window::{SlidingWindow, WindowFunction, WindowedFeatures};

/// Checks that `len` values are a whole number of events of `channels` values.
#[inline]
pub(crate) fn check_multiple(
    name: &'static str,
    len: usize,
    channels: usize,
) -> Result<usize, DspError> {
    if len % channels == 0 {
        Ok(len / channels)
    } else {
        Err(DspError::NotWholeEvents {
            name,
            len,
            channels,
        })
    }
}

/// Checks that input and output have the same length.
#[inline]
pub(crate) fn check_same_len(input: usize, output: usize) -> Result<(), DspError> {
    if input == output {
        Ok(())
    } else {
        Err(DspError::LengthMismatch { input, output })
    }
}
