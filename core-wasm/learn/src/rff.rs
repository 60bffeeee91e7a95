use crate::ridge::{check_pairs, usable};
use crate::state::{Reader, Writer};
use crate::{check_rows, LearnError, PredictingMachine, Ridge, RidgeParams};
use mosaic_dsp::rng::Rng;

/// Most values of Ω (features × inputs): 32 MiB.
const MAX_OMEGA: usize = 1 << 22;

/// Hyper-parameters of the random Fourier feature map.
///
/// ```
/// use mosaic_learn::RffParams;
///
/// let p = RffParams::default();
/// assert_eq!((p.features, p.gamma, p.seed), (300, 0.5, 0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RffParams {
    /// D, the number of random features (MOSAIC's default 300).
    pub features: usize,
    /// γ of the RBF kernel k(x, x′) = exp(−γ‖x − x′‖²) that the features
    /// approximate (scikit-learn's `RBFSampler(gamma)`). The default 0.5
    /// draws ω ~ N(0, I), MOSAIC 1's σ = 1.
    pub gamma: f64,
    /// Seed of the generator that draws ω and b.
    pub seed: u64,
}

impl Default for RffParams {
    fn default() -> Self {
        RffParams {
            features: 300,
            gamma: 0.5,
            seed: 0,
        }
    }
}

/// Ridge regression on random Fourier features (Rahimi & Recht, *Random
/// features for large-scale kernel machines*, NIPS 2007): the nonlinear
/// model of the paper's III-G, batch and incremental.
///
/// Each input x (d values) is mapped to D features
///
/// > z(x) = √(2/D) · cos(Ωx + b),  Ω ∈ ℝ^{D×d} with entries ~ N(0, 2γ),  b ~ U(0, 2π),
///
/// so that z(x)ᵀz(x′) ≈ exp(−γ‖x − x′‖²) — exactly scikit-learn's
/// `RBFSampler(gamma)` transform (its `random_weights_` is Ωᵀ and
/// `random_offset_` is b). A [`Ridge`] is then fitted on z (with its
/// unpenalised intercept by default). Ω and b are drawn once, from
/// [`RffParams::seed`] (xoshiro256++ seeded by splitmix64; Gaussian deviates
/// by the Marsaglia polar method; Ω row by row, then b), or given with
/// [`with_weights`](RandomFourierFeatures::with_weights).
///
/// MOSAIC 1 drew Ω ~ N(0, σ²) and used cos(Ωx + b) without the √(2/D)
/// factor: its (λ, σ) is this model's (λ·2/D, γ = σ²/2), with no intercept.
///
/// ```
/// use mosaic_learn::{PredictingMachine, RandomFourierFeatures, RffParams, RidgeParams};
///
/// // Learn y = sin(x) on [0, 3] from 200 samples, one at a time.
/// let rff = RffParams { features: 100, gamma: 1.0, seed: 7 };
/// let ridge = RidgeParams { lambda: 1e-3, ..RidgeParams::default() };
/// let mut m = RandomFourierFeatures::new(1, 1, rff, ridge)?;
/// for i in 0..200 {
///     let x = 3.0 * i as f64 / 199.0;
///     m.partial_fit(&[x], &[x.sin()])?;
/// }
/// let mut y = [0.0];
/// m.predict(&[1.5], &mut y)?;
/// assert!((y[0] - 1.5f64.sin()).abs() < 0.01);
/// # Ok::<(), mosaic_learn::LearnError>(())
/// ```
#[derive(Debug, Clone)]
pub struct RandomFourierFeatures {
    d: usize,
    gamma: f64,
    seed: u64,
    /// Ω, row-major D × d.
    omega: Vec<f64>,
    /// b, D values.
    offset: Vec<f64>,
    scale: f64,
    ridge: Ridge,
    z: Vec<f64>,
}

fn check_rff(inputs: usize, features: usize, gamma: f64) -> Result<(), LearnError> {
    if !(gamma > 0.0 && gamma.is_finite()) {
        return Err(LearnError::InvalidParameter {
            name: "Gamma",
            value: gamma,
            expected: "a finite number > 0 (the RBF kernel exp(−γ‖x − x′‖²); about 1 / (inputs × variance of an input) is a good start)",
        });
    }
    if inputs == 0 || inputs > MAX_OMEGA {
        return Err(LearnError::Size {
            name: "Inputs",
            value: inputs,
            expected: "at least 1",
        });
    }
    if features.saturating_mul(inputs) > MAX_OMEGA {
        return Err(LearnError::Size {
            name: "Features",
            value: features,
            expected:
                "at most 4,194,304 / Inputs (the projection Ω holds Features × Inputs values)",
        });
    }
    Ok(())
}

impl RandomFourierFeatures {
    /// Draws Ω and b from `rff.seed`; the model is untrained (predicts 0).
    pub fn new(
        inputs: usize,
        outputs: usize,
        rff: RffParams,
        ridge: RidgeParams,
    ) -> Result<RandomFourierFeatures, LearnError> {
        check_rff(inputs, rff.features, rff.gamma)?;
        let model = Ridge::new(rff.features, outputs, ridge).map_err(features_named)?;
        let d = inputs;
        let big_d = rff.features;
        let mut rng = Rng::from_seed(rff.seed);
        let sd = (2.0 * rff.gamma).sqrt();
        let omega = (0..big_d * d).map(|_| sd * rng.gaussian()).collect();
        let offset = (0..big_d)
            .map(|_| std::f64::consts::TAU * rng.uniform())
            .collect();
        Ok(Self::assemble(d, rff.gamma, rff.seed, omega, offset, model))
    }

    /// With a given Ω (row-major D × d, D = `offset.len()`) and b, e.g.
    /// scikit-learn's `RBFSampler.random_weights_.T` and `random_offset_`.
    /// `gamma` is recorded, not used.
    pub fn with_weights(
        inputs: usize,
        outputs: usize,
        gamma: f64,
        omega: &[f64],
        offset: &[f64],
        ridge: RidgeParams,
    ) -> Result<RandomFourierFeatures, LearnError> {
        let big_d = offset.len();
        check_rff(inputs, big_d, gamma)?;
        if omega.len() != big_d * inputs {
            return Err(LearnError::StateLength {
                section: "omega",
                len: omega.len(),
                expected: big_d * inputs,
            });
        }
        for (name, v) in [("omega", omega), ("offset", offset)] {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(LearnError::StateValue {
                    section: name,
                    index: i,
                    value: v[i],
                    expected: "a finite number",
                });
            }
        }
        let model = Ridge::new(big_d, outputs, ridge).map_err(features_named)?;
        Ok(Self::assemble(
            inputs,
            gamma,
            0,
            omega.to_vec(),
            offset.to_vec(),
            model,
        ))
    }

    fn assemble(
        d: usize,
        gamma: f64,
        seed: u64,
        omega: Vec<f64>,
        offset: Vec<f64>,
        ridge: Ridge,
    ) -> Self {
        let big_d = offset.len();
        RandomFourierFeatures {
            d,
            gamma,
            seed,
            omega,
            offset,
            scale: (2.0 / big_d as f64).sqrt(),
            ridge,
            z: vec![0.0; big_d],
        }
    }

    /// D, the number of features.
    pub fn features(&self) -> usize {
        self.offset.len()
    }

    /// γ of the approximated kernel.
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// The seed Ω and b were drawn from (0 for [`with_weights`](Self::with_weights)).
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Ω, row-major D × d.
    pub fn omega(&self) -> &[f64] {
        &self.omega
    }

    /// b, D values.
    pub fn offset(&self) -> &[f64] {
        &self.offset
    }

    /// The ridge regression on the features.
    pub fn ridge(&self) -> &Ridge {
        &self.ridge
    }

    pub(crate) fn ridge_mut(&mut self) -> &mut Ridge {
        &mut self.ridge
    }

    /// z(x) of `n` rows of `x` into `z` (n × D).
    pub fn transform(&self, x: &[f64], z: &mut [f64]) -> Result<(), LearnError> {
        let n = check_rows("x", x.len(), self.d)?;
        let big_d = self.features();
        let nz = check_rows("z", z.len(), big_d)?;
        if n != nz {
            return Err(LearnError::RowMismatch {
                a: "x",
                a_rows: n,
                b: "z",
                b_rows: nz,
            });
        }
        for i in 0..n {
            map(
                &self.omega,
                &self.offset,
                self.scale,
                &x[i * self.d..(i + 1) * self.d],
                &mut z[i * big_d..(i + 1) * big_d],
            );
        }
        Ok(())
    }

    pub(crate) fn learn_one(&mut self, x: &[f64], y: &[f64]) -> bool {
        if !usable(x) {
            self.ridge.refuse();
            return false;
        }
        map(&self.omega, &self.offset, self.scale, x, &mut self.z);
        self.ridge.learn_one(&self.z, y)
    }

    pub(crate) fn predict_one(&mut self, x: &[f64], out: &mut [f64]) {
        map(&self.omega, &self.offset, self.scale, x, &mut self.z);
        self.ridge.predict_one(&self.z, out);
    }

    /// Batch fit on rows produced by `row(i, out)` (d values each).
    pub(crate) fn fit_rows<F>(&mut self, n: usize, y: &[f64], mut row: F) -> usize
    where
        F: FnMut(usize, &mut [f64]) -> bool,
    {
        let d = self.d;
        let RandomFourierFeatures {
            omega,
            offset,
            scale,
            ridge,
            z,
            ..
        } = self;
        let mut x = std::mem::take(z);
        x.truncate(d);
        x.resize(d, 0.0);
        let used = ridge.fit_rows(n, y, |i, out| {
            let ok = row(i, &mut x) && usable(&x);
            map(omega, offset, *scale, &x, out);
            ok
        });
        x.resize(offset.len(), 0.0);
        *z = x;
        used
    }

    pub(crate) fn sections(&self, out: &mut Vec<(&'static str, usize)>) {
        out.push(("omega", self.omega.len()));
        out.push(("offset", self.offset.len()));
        self.ridge.sections(out);
    }

    pub(crate) fn state_len_inner(&self) -> usize {
        self.omega.len() + self.offset.len() + self.ridge.state_len_inner()
    }

    pub(crate) fn save(&self, w: &mut Writer<'_>) {
        w.put(&self.omega);
        w.put(&self.offset);
        self.ridge.save(w);
    }

    pub(crate) fn load(&mut self, rd: &mut Reader<'_>) -> Result<(), LearnError> {
        let omega = rd.section("omega", self.omega.len())?;
        let offset = rd.section("offset", self.offset.len())?;
        self.ridge.load(rd)?;
        self.omega.copy_from_slice(omega);
        self.offset.copy_from_slice(offset);
        Ok(())
    }
}

/// Names the ridge's dimension "Features" (it is D here, not the inputs).
fn features_named(e: LearnError) -> LearnError {
    match e {
        LearnError::Size {
            name: "Inputs",
            value,
            ..
        } => LearnError::Size {
            name: "Features",
            value,
            expected: "1 to 2048 (the model keeps D × D matrices)",
        },
        other => other,
    }
}

/// z = scale · cos(Ωx + b).
#[inline]
fn map(omega: &[f64], offset: &[f64], scale: f64, x: &[f64], z: &mut [f64]) {
    let d = x.len();
    for (j, zj) in z.iter_mut().enumerate() {
        let row = &omega[j * d..(j + 1) * d];
        let mut s = offset[j];
        for i in 0..d {
            s += row[i] * x[i];
        }
        *zj = scale * s.cos();
    }
}

impl PredictingMachine for RandomFourierFeatures {
    fn inputs(&self) -> usize {
        self.d
    }

    fn outputs(&self) -> usize {
        self.ridge.outputs()
    }

    fn samples_seen(&self) -> u64 {
        self.ridge.samples_seen()
    }

    fn predict(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LearnError> {
        let (d, m) = (self.d, self.outputs());
        let n = check_rows("x", x.len(), d)?;
        let ny = check_rows("output", y.len(), m)?;
        if n != ny {
            return Err(LearnError::RowMismatch {
                a: "x",
                a_rows: n,
                b: "output",
                b_rows: ny,
            });
        }
        for i in 0..n {
            self.predict_one(&x[i * d..(i + 1) * d], &mut y[i * m..(i + 1) * m]);
        }
        Ok(())
    }

    fn partial_fit(&mut self, x: &[f64], y: &[f64]) -> Result<usize, LearnError> {
        let (d, m) = (self.d, self.outputs());
        let n = check_pairs(x.len(), d, y.len(), m)?;
        let mut used = 0;
        for i in 0..n {
            used += self.learn_one(&x[i * d..(i + 1) * d], &y[i * m..(i + 1) * m]) as usize;
        }
        Ok(used)
    }

    fn fit(&mut self, x: &[f64], y: &[f64]) -> Result<usize, LearnError> {
        let d = self.d;
        let n = check_pairs(x.len(), d, y.len(), self.outputs())?;
        Ok(self.fit_rows(n, y, |i, out| {
            out.copy_from_slice(&x[i * d..(i + 1) * d]);
            true
        }))
    }

    fn reset(&mut self) {
        self.ridge.reset();
    }

    fn state_len(&self) -> usize {
        self.state_len_inner()
    }

    fn save_state(&self, out: &mut [f64]) -> Result<(), LearnError> {
        let mut w = Writer::new(out, self.state_len_inner())?;
        self.save(&mut w);
        Ok(())
    }

    fn load_state(&mut self, state: &[f64]) -> Result<(), LearnError> {
        let mut rd = Reader::new(state, self.state_len_inner())?;
        self.load(&mut rd)
    }
}
