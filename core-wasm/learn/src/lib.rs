//! Pure-Rust learning kernels of MOSAIC (paper III-G): ridge regression
//! (eqs. 5–6) and its nonlinear extension on random Fourier features, each
//! in batch and incremental form, behind one [`PredictingMachine`] trait.
//!
//! This crate has no dependencies and no binding code; `mosaic-core-wasm`
//! wraps [`Model`] for WebAssembly. Everything is `f64`. Conventions:
//!
//! * buffers are **row-major**: `n` samples of `d` inputs are `n·d` values,
//!   `n` targets or predictions of `M` outputs are `n·M` values;
//! * `predict` and `partial_fit` never allocate and never panic (a buffer of
//!   the wrong length is a [`LearnError`]); `fit` and `partial_fit` refuse
//!   (and count) samples with a NaN, an infinity or a value beyond ±1e50, so
//!   that the model never holds a NaN;
//! * learning `n` samples in one call or in `n` calls gives bit-identical
//!   models; after `reset()` the same samples give bit-identical models;
//! * a model's whole state is a flat `f64` array with named sections
//!   ([`Model::state_sections`]), saved and loaded with validation.
//!
//! Machines:
//!
//! * [`Ridge`] — ridge regression with an unpenalised intercept (as
//!   scikit-learn's `Ridge`) or none (as the paper and MOSAIC 1); the
//!   incremental form updates a Cholesky factor of the normal equations by
//!   plane rotations, O(p²) per sample, with an optional forgetting factor.
//! * [`RandomFourierFeatures`] — z(x) = √(2/D)·cos(Ωx + b) (scikit-learn's
//!   `RBFSampler`), then [`Ridge`] on z.
//! * [`Lda`] — linear discriminant analysis learnt per sample (class means and a
//!   pooled covariance), predicting class scores or the most probable class's
//!   target (MOSAIC 1's IncrementalLDA, done properly).
//! * [`Model`] — any of them from a [`ModelConfig`], with an optional
//!   running standardisation of the inputs (ridge and RFF).
//!
//! ```
//! use mosaic_learn::{ModelConfig, PredictingMachine};
//!
//! // Two outputs from three inputs; learn incrementally, then predict.
//! let mut model = ModelConfig::ridge(3, 2).lambda(1e-6).build()?;
//! for i in 0..50 {
//!     let x = [i as f64, (i % 5) as f64, 1.0 / (1.0 + i as f64)];
//!     let y = [x[0] + x[1], 2.0 * x[2] - 1.0];
//!     model.partial_fit(&x, &y)?;
//! }
//! let mut y = [0.0; 2];
//! model.predict(&[3.0, 4.0, 0.25], &mut y)?;
//! assert!((y[0] - 7.0).abs() < 1e-6 && (y[1] + 0.5).abs() < 1e-6);
//! # Ok::<(), mosaic_learn::LearnError>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs)]
// Dense linear algebra reads best with explicit row and column indices.
#![allow(clippy::needless_range_loop)]

mod error;
mod lda;
mod linalg;
mod model;
mod rff;
mod ridge;
mod state;

pub use error::LearnError;
pub use lda::{Lda, LdaOutput, LdaParams, MAX_CLASSES};
pub use model::{Model, ModelConfig, ModelKind};
pub use rff::{RandomFourierFeatures, RffParams};
pub use ridge::{Ridge, RidgeParams};

/// Largest magnitude of an input or target value that is learnt; beyond it
/// (and for NaN and infinities) a sample is refused and counted.
pub const MAX_ABS: f64 = 1e50;
/// Largest dimension p of the normal equations (p × p matrices).
pub const MAX_DIM: usize = 2048;
/// Most outputs M.
pub const MAX_OUTPUTS: usize = 4096;

/// The common interface of MOSAIC's learning machines (the paper's
/// *PredictingMachine*, Fig. 4): predict, learn (sample by sample or in one
/// batch), reset, and save/load the whole state as a flat array.
///
/// ```
/// use mosaic_learn::{ModelConfig, PredictingMachine};
///
/// fn train(m: &mut dyn PredictingMachine, x: &[f64], y: &[f64]) -> usize {
///     m.partial_fit(x, y).unwrap()
/// }
/// let mut m = ModelConfig::rff(2, 1).features(16).build()?;
/// assert_eq!(train(&mut m, &[0.0, 1.0, 1.0, 0.0], &[1.0, 2.0]), 2);
/// assert_eq!((m.inputs(), m.outputs(), m.samples_seen()), (2, 1, 2));
///
/// // Save, reset, load: the same predictions.
/// let mut state = vec![0.0; m.state_len()];
/// m.save_state(&mut state)?;
/// let (mut before, mut after) = ([0.0], [0.0]);
/// m.predict(&[0.5, 0.5], &mut before)?;
/// m.reset();
/// m.load_state(&state)?;
/// m.predict(&[0.5, 0.5], &mut after)?;
/// assert!((before[0] - after[0]).abs() < 1e-12);
/// # Ok::<(), mosaic_learn::LearnError>(())
/// ```
pub trait PredictingMachine {
    /// d, values per input sample.
    fn inputs(&self) -> usize;
    /// M, values per target and prediction.
    fn outputs(&self) -> usize;
    /// Samples learnt since creation, `reset` or the last `fit`.
    fn samples_seen(&self) -> u64;
    /// Predicts `n` rows of `x` (n·d values) into `y` (n·M values). An
    /// untrained model predicts 0. `&mut self` only for scratch space.
    fn predict(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LearnError>;
    /// Learns `n` samples in order (rows of `x` and `y`); returns how many
    /// were used (the others were refused, see [`MAX_ABS`]).
    fn partial_fit(&mut self, x: &[f64], y: &[f64]) -> Result<usize, LearnError>;
    /// Forgets everything and fits these rows in one batch.
    fn fit(&mut self, x: &[f64], y: &[f64]) -> Result<usize, LearnError>;
    /// Back to the untrained model (hyper-parameters, Ω and b are kept).
    fn reset(&mut self);
    /// Number of values of the flat state.
    fn state_len(&self) -> usize;
    /// Writes the state into `out` (exactly `state_len()` values).
    fn save_state(&self, out: &mut [f64]) -> Result<(), LearnError>;
    /// Replaces the state by a saved one, after checking it (lengths,
    /// finiteness, symmetry, positive definiteness, and that the saved
    /// weights are what the saved normal equations give). On error the model
    /// is unchanged.
    fn load_state(&mut self, state: &[f64]) -> Result<(), LearnError>;
}

/// Checks that `len` values are whole rows of `width`; returns the rows.
#[inline]
pub(crate) fn check_rows(
    name: &'static str,
    len: usize,
    width: usize,
) -> Result<usize, LearnError> {
    if len % width == 0 {
        Ok(len / width)
    } else {
        Err(LearnError::NotWholeRows { name, len, width })
    }
}
