use crate::lda::{Lda, LdaOutput, LdaParams};
use crate::ridge::{check_pairs, usable};
use crate::state::{Reader, Writer};
use crate::{
    check_rows, LearnError, PredictingMachine, RandomFourierFeatures, RffParams, Ridge, RidgeParams,
};

/// Which machine a [`Model`] holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ModelKind {
    /// Linear ridge regression ([`Ridge`]).
    Ridge,
    /// Ridge regression on random Fourier features ([`RandomFourierFeatures`]).
    Rff(RffParams),
    /// Incremental linear discriminant analysis ([`Lda`]): classes are the distinct targets.
    Lda(LdaParams),
}

/// Everything that defines a [`Model`]; built with a small builder.
///
/// ```
/// use mosaic_learn::{ModelConfig, ModelKind};
///
/// let cfg = ModelConfig::rff(8, 12).features(64).gamma(0.1).lambda(0.5).normalize(true);
/// assert!(matches!(cfg.kind, ModelKind::Rff(p) if p.features == 64 && p.gamma == 0.1));
/// let model = cfg.build()?;
/// assert_eq!(model.dim(), 64);
/// # Ok::<(), mosaic_learn::LearnError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ModelConfig {
    /// The machine and, for RFF, its feature map.
    pub kind: ModelKind,
    /// d, values per input sample.
    pub inputs: usize,
    /// M, values per target / prediction.
    pub outputs: usize,
    /// λ, forgetting, intercept.
    pub ridge: RidgeParams,
    /// Standardise every input (see [`Model`]).
    pub normalize: bool,
    /// RFF with `normalize`: the input statistics are learnt from this many
    /// training samples, then frozen (see [`Model`]); at least 2.
    pub normalize_samples: usize,
}

impl ModelConfig {
    /// A ridge regression with the default hyper-parameters.
    pub fn ridge(inputs: usize, outputs: usize) -> Self {
        ModelConfig {
            kind: ModelKind::Ridge,
            inputs,
            outputs,
            ridge: RidgeParams::default(),
            normalize: false,
            normalize_samples: 200,
        }
    }

    /// Ridge on random Fourier features with the default D, γ and seed.
    pub fn rff(inputs: usize, outputs: usize) -> Self {
        ModelConfig {
            kind: ModelKind::Rff(RffParams::default()),
            ..Self::ridge(inputs, outputs)
        }
    }

    /// Incremental LDA with the default [`LdaParams`] (λ, forgetting and intercept do not
    /// apply; `normalize` is refused: LDA does not depend on the inputs' scales).
    pub fn lda(inputs: usize, outputs: usize) -> Self {
        ModelConfig {
            kind: ModelKind::Lda(LdaParams::default()),
            ..Self::ridge(inputs, outputs)
        }
    }

    /// Sets the LDA shrinkage α (LDA only).
    pub fn shrinkage(mut self, alpha: f64) -> Self {
        if let ModelKind::Lda(p) = &mut self.kind {
            p.shrinkage = alpha;
        }
        self
    }

    /// Sets the most classes an LDA keeps (LDA only).
    pub fn max_classes(mut self, k: usize) -> Self {
        if let ModelKind::Lda(p) = &mut self.kind {
            p.max_classes = k;
        }
        self
    }

    /// Sets what an LDA predicts (LDA only).
    pub fn lda_output(mut self, output: LdaOutput) -> Self {
        if let ModelKind::Lda(p) = &mut self.kind {
            p.output = output;
        }
        self
    }

    /// Sets λ.
    pub fn lambda(mut self, lambda: f64) -> Self {
        self.ridge.lambda = lambda;
        self
    }

    /// Sets the forgetting factor β.
    pub fn forgetting(mut self, beta: f64) -> Self {
        self.ridge.forgetting = beta;
        self
    }

    /// Fits an unpenalised intercept (default) or none.
    pub fn intercept(mut self, on: bool) -> Self {
        self.ridge.intercept = on;
        self
    }

    /// Sets [`RidgeParams::refactor_every`].
    pub fn refactor_every(mut self, n: usize) -> Self {
        self.ridge.refactor_every = n;
        self
    }

    /// Standardises the inputs.
    pub fn normalize(mut self, on: bool) -> Self {
        self.normalize = on;
        self
    }

    /// Sets [`ModelConfig::normalize_samples`].
    pub fn normalize_samples(mut self, n: usize) -> Self {
        self.normalize_samples = n;
        self
    }

    /// Sets D (RFF only; ignored for ridge).
    pub fn features(mut self, d: usize) -> Self {
        if let ModelKind::Rff(p) = &mut self.kind {
            p.features = d;
        }
        self
    }

    /// Sets γ (RFF only).
    pub fn gamma(mut self, gamma: f64) -> Self {
        if let ModelKind::Rff(p) = &mut self.kind {
            p.gamma = gamma;
        }
        self
    }

    /// Sets the seed of Ω and b (RFF only).
    pub fn seed(mut self, seed: u64) -> Self {
        if let ModelKind::Rff(p) = &mut self.kind {
            p.seed = seed;
        }
        self
    }

    /// Creates the (untrained) model.
    pub fn build(&self) -> Result<Model, LearnError> {
        Model::new(self.clone())
    }
}

/// With `normalize`, the penalty of a ridge model is re-derived from the
/// running standard deviations when one of them has moved by more than this
/// factor since the last time.
const DRIFT: f64 = 1.1;

/// Most warm-up samples of an RFF model with `normalize`.
const MAX_WARMUP: usize = 100_000;

/// Statistics of the inputs (Welford): mean and population sd; for RFF, the
/// warm-up samples that are learnt again once the statistics freeze.
#[derive(Debug, Clone)]
struct Standardizer {
    count: f64,
    frozen: bool,
    mean: Vec<f64>,
    m2: Vec<f64>,
    inv: Vec<f64>,
    /// Samples after which the statistics freeze (0: never, for ridge).
    warmup: usize,
    buf_x: Vec<f64>,
    buf_y: Vec<f64>,
    /// Warm-up samples held in the buffers (all of them since the last
    /// reset, unless a state was loaded mid-warm-up).
    buffered: usize,
}

impl Standardizer {
    fn new(d: usize, m: usize, warmup: usize) -> Self {
        Standardizer {
            count: 0.0,
            frozen: false,
            mean: vec![0.0; d],
            m2: vec![0.0; d],
            inv: vec![1.0; d],
            warmup,
            buf_x: vec![0.0; warmup * d],
            buf_y: vec![0.0; warmup * m],
            buffered: 0,
        }
    }

    fn clear(&mut self) {
        self.count = 0.0;
        self.frozen = false;
        self.mean.fill(0.0);
        self.m2.fill(0.0);
        self.inv.fill(1.0);
        self.buffered = 0;
    }

    fn observe(&mut self, x: &[f64]) {
        self.count += 1.0;
        for i in 0..x.len() {
            let d = x[i] - self.mean[i];
            self.mean[i] += d / self.count;
            self.m2[i] += d * (x[i] - self.mean[i]);
        }
        self.scales();
    }

    /// The scale of input i: its sd, or 1 for a channel without spread (a
    /// constant channel is only centred, as scikit-learn's StandardScaler does).
    ///
    /// Scales stay within 1e-25..1e25 (a penalty sd² within the ridge's range):
    /// a smaller sd counts as no spread, a larger one is clamped.
    fn scale(&self, i: usize) -> f64 {
        let sd = (self.m2[i] / self.count).sqrt();
        if self.count >= 2.0 && sd >= 1e-25 && sd > 1e-12 * self.mean[i].abs() {
            sd.min(1e25)
        } else {
            1.0
        }
    }

    fn scales(&mut self) {
        for i in 0..self.mean.len() {
            self.inv[i] = 1.0 / self.scale(i);
        }
    }

    /// Squared scales into `out`; `true` when one differs from `reference` by
    /// more than the drift allowance.
    fn penalty(&self, reference: &[f64], out: &mut [f64]) -> bool {
        let (lo, hi) = (1.0 / (DRIFT * DRIFT), DRIFT * DRIFT);
        let mut drifted = false;
        for i in 0..out.len() {
            let s = self.scale(i);
            out[i] = s * s;
            let ratio = out[i] / reference[i];
            drifted |= !(lo..=hi).contains(&ratio);
        }
        drifted
    }

    fn transform(&self, x: &[f64], out: &mut [f64]) {
        for i in 0..x.len() {
            out[i] = (x[i] - self.mean[i]) * self.inv[i];
        }
    }

    fn save(&self, w: &mut Writer<'_>) {
        w.put(&[self.count, self.frozen as u8 as f64]);
        w.put(&self.mean);
        w.put(&self.m2);
    }

    fn load(&mut self, rd: &mut Reader<'_>) -> Result<(), LearnError> {
        let d = self.mean.len();
        let v = rd.section("normalizer", 2 + 2 * d)?;
        for (k, &x) in v.iter().enumerate() {
            if (k == 0 || k >= 2 + d) && x < 0.0 {
                return Err(rd.bad(k, x, "a count or sum of squares >= 0"));
            }
        }
        if v[1] != 0.0 && v[1] != 1.0 {
            return Err(rd.bad(1, v[1], "0 (learning the statistics) or 1 (frozen)"));
        }
        self.count = v[0];
        self.frozen = v[1] == 1.0;
        self.mean.copy_from_slice(&v[2..2 + d]);
        self.m2.copy_from_slice(&v[2 + d..]);
        self.scales();
        // The warm-up samples learnt before are not in the state: no replay.
        self.buffered = 0;
        Ok(())
    }
}

#[derive(Debug, Clone)]
enum Machine {
    Ridge(Ridge),
    Rff(RandomFourierFeatures),
    Lda(Lda),
}

fn refuse(machine: &mut Machine) {
    match machine {
        Machine::Ridge(r) => r.refuse(),
        Machine::Rff(f) => f.ridge_mut().refuse(),
        Machine::Lda(l) => l.refuse(),
    }
}

/// A batch fit of an LDA: its statistics are sufficient, so it is the rows learnt in order.
fn fit_lda(l: &mut Lda, x: &[f64], y: &[f64], d: usize, m: usize) -> usize {
    l.reset();
    let n = x.len() / d;
    let mut used = 0;
    for i in 0..n {
        used += l.learn_one(&x[i * d..(i + 1) * d], &y[i * m..(i + 1) * m]) as usize;
    }
    used
}

/// A learning machine built from a [`ModelConfig`]: ridge or RFF, with an
/// optional running standardisation of the inputs. This is what the
/// Batch/IncrementalPredictor blocks run (through the WebAssembly bindings).
///
/// **Normalisation** (`normalize`) standardises every input value,
/// x ↦ (x − mean)/sd, with the mean and population sd (Welford) of the
/// training inputs; a channel without spread is only centred (its scale is
/// 1, as in scikit-learn's `StandardScaler`). How depends on the machine:
///
/// * **ridge**: scaling input j by 1/sⱼ is the same as penalising its raw
///   weight by λsⱼ², and the centring is the intercept's job, so the model
///   keeps the raw normal equations and a diagonal penalty
///   ([`Ridge::set_penalty`]) — at every moment it is *exactly* the ridge
///   solution on inputs scaled by the sds recorded at the last
///   re-factorisation, which happens whenever a running sd has moved by more
///   than 10 % from them (often at first, rarely once the statistics
///   settle). Weights are reported for the raw inputs. Without intercept
///   the inputs are scaled, not centred.
/// * **RFF** (the feature map is nonlinear, so there is no such identity):
///   the statistics are learnt from the first
///   [`normalize_samples`](ModelConfig::normalize_samples) training samples
///   (default 200), which are kept; then they freeze and those samples are
///   learnt again with the frozen statistics (one O(k·D²) step). From then
///   on the model is *exactly* RFF ridge on inputs standardised with the
///   statistics of its first k training samples; before, each sample uses the
///   statistics of its time.
///
/// A batch [`fit`](PredictingMachine::fit) first computes the statistics of
/// all rows, then fits: scikit-learn's `StandardScaler` followed by the model
/// (exactly, with intercept).
///
/// ```
/// use mosaic_learn::{ModelConfig, PredictingMachine};
///
/// let mut m = ModelConfig::ridge(1, 1).lambda(1e-6).build()?;
/// // Train while predicting (MOSAIC's IncrementalPredictor: learn, then predict).
/// let x = [0.0, 1.0, 2.0, 3.0];
/// let mut y = [0.0; 4];
/// m.train_predict(&x, &[5.0], &mut y)?; // the same target for four samples
/// assert_eq!(m.samples_seen(), 4);
/// assert!((y[3] - 5.0).abs() < 1e-9);
/// # Ok::<(), mosaic_learn::LearnError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Model {
    config: ModelConfig,
    machine: Machine,
    norm: Option<Standardizer>,
    xs: Vec<f64>,
}

impl Model {
    /// See [`ModelConfig::build`].
    pub fn new(config: ModelConfig) -> Result<Model, LearnError> {
        let machine = match config.kind {
            ModelKind::Ridge => {
                Machine::Ridge(Ridge::new(config.inputs, config.outputs, config.ridge)?)
            }
            ModelKind::Rff(p) => Machine::Rff(RandomFourierFeatures::new(
                config.inputs,
                config.outputs,
                p,
                config.ridge,
            )?),
            ModelKind::Lda(p) => {
                if config.normalize {
                    return Err(LearnError::InvalidParameter {
                        name: "Normalize",
                        value: 1.0,
                        expected:
                            "false for LDA (its predictions do not depend on the inputs' scales)",
                    });
                }
                if config.ridge.forgetting != 1.0 {
                    return Err(LearnError::InvalidParameter {
                        name: "Forgetting",
                        value: config.ridge.forgetting,
                        expected: "1 for LDA (it keeps every sample's statistics)",
                    });
                }
                Machine::Lda(Lda::new(config.inputs, config.outputs, p)?)
            }
        };
        let d = config.inputs;
        let warmup = match config.kind {
            ModelKind::Ridge | ModelKind::Lda(_) => 0,
            ModelKind::Rff(_) => {
                let k = config.normalize_samples;
                if config.normalize && !(2..=MAX_WARMUP).contains(&k) {
                    return Err(LearnError::Size {
                        name: "NormalizeSamples",
                        value: k,
                        expected: "2 to 100,000 training samples",
                    });
                }
                k
            }
        };
        Ok(Model {
            norm: config
                .normalize
                .then(|| Standardizer::new(d, config.outputs, warmup)),
            xs: vec![0.0; if config.normalize { d } else { 0 }],
            config,
            machine,
        })
    }

    /// The configuration it was built from.
    pub fn config(&self) -> &ModelConfig {
        &self.config
    }

    /// The ridge stage (on the inputs, or on the random features); None for LDA.
    pub fn ridge(&self) -> Option<&Ridge> {
        match &self.machine {
            Machine::Ridge(r) => Some(r),
            Machine::Rff(f) => Some(f.ridge()),
            Machine::Lda(_) => None,
        }
    }

    /// The feature map, for an RFF model.
    pub fn rff(&self) -> Option<&RandomFourierFeatures> {
        match &self.machine {
            Machine::Rff(f) => Some(f),
            _ => None,
        }
    }

    /// The LDA, for an LDA model.
    pub fn lda(&self) -> Option<&Lda> {
        match &self.machine {
            Machine::Lda(l) => Some(l),
            _ => None,
        }
    }

    /// p, the dimension the ridge works in (d, or D for RFF; d for LDA).
    pub fn dim(&self) -> usize {
        match &self.machine {
            Machine::Ridge(r) => r.inputs(),
            Machine::Rff(f) => f.ridge().inputs(),
            Machine::Lda(l) => l.inputs(),
        }
    }

    /// R² per output (see [`Ridge::r2`], [`Lda::r2`]); NaN while undefined.
    pub fn r2(&self, out: &mut [f64]) {
        match &self.machine {
            Machine::Ridge(r) => r.r2(out),
            Machine::Rff(f) => f.ridge().r2(out),
            Machine::Lda(l) => l.r2(out),
        }
    }

    /// The regulariser in use (see [`Ridge::effective_lambda`]); an LDA's shrinkage.
    pub fn effective_lambda(&self) -> f64 {
        match &self.machine {
            Machine::Ridge(r) => r.effective_lambda(),
            Machine::Rff(f) => f.ridge().effective_lambda(),
            Machine::Lda(l) => l.params().shrinkage,
        }
    }

    /// Samples refused (NaN, infinity, beyond ±1e50; for LDA also classes beyond MaxClasses).
    pub fn rejected(&self) -> u64 {
        match &self.machine {
            Machine::Ridge(r) => r.rejected(),
            Machine::Rff(f) => f.ridge().rejected(),
            Machine::Lda(l) => l.rejected(),
        }
    }

    /// See [`Ridge::refactor`] (nothing to do for LDA, which solves lazily).
    pub fn refactor(&mut self) {
        match &mut self.machine {
            Machine::Ridge(r) => r.refactor(),
            Machine::Rff(f) => f.ridge_mut().refactor(),
            Machine::Lda(_) => {}
        }
    }

    /// For each row of `x`: learn it with `target` (M values), then predict
    /// it into the same row of `out` (M values per row), as MOSAIC's
    /// IncrementalPredictor did. Returns the number of samples learnt.
    pub fn train_predict(
        &mut self,
        x: &[f64],
        target: &[f64],
        out: &mut [f64],
    ) -> Result<usize, LearnError> {
        let (d, m) = (self.config.inputs, self.config.outputs);
        let n = check_rows("x", x.len(), d)?;
        if target.len() != m {
            return Err(LearnError::Length {
                name: "target",
                len: target.len(),
                expected: m,
            });
        }
        if out.len() != n * m {
            return Err(LearnError::Length {
                name: "output",
                len: out.len(),
                expected: n * m,
            });
        }
        let mut used = 0;
        for i in 0..n {
            let xi = &x[i * d..(i + 1) * d];
            used += self.learn_one(xi, target) as usize;
            self.predict_one(xi, &mut out[i * m..(i + 1) * m]);
        }
        Ok(used)
    }

    fn learn_one(&mut self, x: &[f64], y: &[f64]) -> bool {
        let Model {
            norm, machine, xs, ..
        } = self;
        let Some(s) = norm else {
            return match machine {
                Machine::Ridge(r) => r.learn_one(x, y),
                Machine::Rff(f) => f.learn_one(x, y),
                Machine::Lda(l) => l.learn_one(x, y),
            };
        };
        if !(usable(x) && usable(y)) {
            refuse(machine);
            return false;
        }
        match machine {
            Machine::Ridge(r) => {
                // Exact: scaling by the sds is a diagonal penalty; re-derive it
                // when the sds have drifted.
                s.observe(x);
                if s.penalty(r.penalty(), xs) && r.set_penalty(xs).is_err() {
                    return false;
                }
                r.learn_one(x, y)
            }
            Machine::Rff(f) => {
                if !s.frozen {
                    s.observe(x);
                    let (d, m) = (x.len(), y.len());
                    let k = s.buffered;
                    if k + 1 == s.count as usize && k < s.warmup {
                        s.buf_x[k * d..(k + 1) * d].copy_from_slice(x);
                        s.buf_y[k * m..(k + 1) * m].copy_from_slice(y);
                        s.buffered += 1;
                    }
                    if s.count as usize >= s.warmup {
                        s.frozen = true;
                        if s.buffered == s.count as usize {
                            // Learn the warm-up again with the frozen statistics.
                            let rejected = f.ridge().rejected();
                            f.reset();
                            f.ridge_mut().add_rejected(rejected);
                            for k in 0..s.buffered {
                                s.transform(&s.buf_x[k * d..(k + 1) * d], xs);
                                f.learn_one(xs, &s.buf_y[k * m..(k + 1) * m]);
                            }
                            s.buffered = 0;
                            return true;
                        }
                    }
                }
                s.transform(x, xs);
                f.learn_one(xs, y)
            }
            // Refused at construction: LDA is never normalised.
            Machine::Lda(l) => l.learn_one(x, y),
        }
    }

    fn predict_one(&mut self, x: &[f64], out: &mut [f64]) {
        match &mut self.machine {
            Machine::Ridge(r) => r.predict_one(x, out),
            Machine::Lda(l) => l.predict_one(x, out),
            Machine::Rff(f) => match &self.norm {
                Some(s) => {
                    s.transform(x, &mut self.xs);
                    f.predict_one(&self.xs, out);
                }
                None => f.predict_one(x, out),
            },
        }
    }

    /// Names and lengths of the sections of the flat state
    /// ([`save_state`](PredictingMachine::save_state)), in order (p: the
    /// ridge dimension, d inputs, D features, M outputs):
    ///
    /// | section | values | content |
    /// |---|---|---|
    /// | `normalizer` | 2 + 2d | only with `normalize`: count, frozen (0/1), mean (d), Σ(x − mean)² (d) |
    /// | `omega` | D·d | only for RFF: Ω, row-major |
    /// | `offset` | D | only for RFF: b |
    /// | `meta` | 3 | samples seen, weight sum Σwᵢ, λ_eff |
    /// | `penalty` | p | diagonal P of the penalty λ_eff·P (all 1 unless normalising a ridge) |
    /// | `x_mean` | p | x̄ (0 without intercept) |
    /// | `y_mean` | M | ȳ (0 without intercept) |
    /// | `scatter` | p·p | S, row-major, symmetric |
    /// | `cross` | p·M | C, row-major |
    /// | `weights` | p·M | W = (S + λ_eff P)⁻¹C, row-major (checked on load) |
    /// | `intercept` | M | b = ȳ − Wᵀx̄ (checked on load) |
    /// | `fit_stats` | 1 + 3M | R² statistics: weight, mean of y (M), Σw(y − ȳ)² (M), Σw·e² (M) |
    ///
    /// ```
    /// use mosaic_learn::{ModelConfig, PredictingMachine};
    ///
    /// let m = ModelConfig::ridge(2, 1).build()?;
    /// let names: Vec<_> = m.state_sections().iter().map(|s| s.0).collect();
    /// assert_eq!(
    ///     names,
    ///     ["meta", "penalty", "x_mean", "y_mean", "scatter", "cross", "weights", "intercept", "fit_stats"]
    /// );
    /// assert_eq!(m.state_sections().iter().map(|s| s.1).sum::<usize>(), m.state_len());
    /// # Ok::<(), mosaic_learn::LearnError>(())
    /// ```
    pub fn state_sections(&self) -> Vec<(&'static str, usize)> {
        let mut v = Vec::new();
        if self.norm.is_some() {
            v.push(("normalizer", 2 + 2 * self.config.inputs));
        }
        match &self.machine {
            Machine::Ridge(r) => r.sections(&mut v),
            Machine::Rff(f) => f.sections(&mut v),
            Machine::Lda(l) => l.sections(&mut v),
        }
        v
    }
}

impl PredictingMachine for Model {
    fn inputs(&self) -> usize {
        self.config.inputs
    }

    fn outputs(&self) -> usize {
        self.config.outputs
    }

    fn samples_seen(&self) -> u64 {
        match &self.machine {
            Machine::Ridge(r) => r.samples_seen(),
            Machine::Rff(f) => f.ridge().samples_seen(),
            Machine::Lda(l) => l.samples_seen(),
        }
    }

    fn predict(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LearnError> {
        let (d, m) = (self.config.inputs, self.config.outputs);
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
        let (d, m) = (self.config.inputs, self.config.outputs);
        let n = check_pairs(x.len(), d, y.len(), m)?;
        let mut used = 0;
        for i in 0..n {
            used += self.learn_one(&x[i * d..(i + 1) * d], &y[i * m..(i + 1) * m]) as usize;
        }
        Ok(used)
    }

    fn fit(&mut self, x: &[f64], y: &[f64]) -> Result<usize, LearnError> {
        let (d, m) = (self.config.inputs, self.config.outputs);
        let n = check_pairs(x.len(), d, y.len(), m)?;
        let row = |i: usize| &x[i * d..(i + 1) * d];
        let ok = |i: usize| usable(row(i)) && usable(&y[i * m..(i + 1) * m]);
        let Model {
            norm, machine, xs, ..
        } = self;
        let used = match norm {
            Some(s) => {
                s.clear();
                for i in 0..n {
                    if ok(i) {
                        s.observe(row(i));
                    }
                }
                match machine {
                    Machine::Ridge(r) => {
                        s.penalty(r.penalty(), xs);
                        r.set_penalty(xs)?;
                        r.fit_rows(n, y, |i, out| {
                            out.copy_from_slice(row(i));
                            true
                        })
                    }
                    Machine::Rff(r) => {
                        s.frozen = true;
                        let s = &*s;
                        r.fit_rows(n, y, |i, out| {
                            s.transform(row(i), out);
                            ok(i)
                        })
                    }
                    Machine::Lda(l) => fit_lda(l, x, y, d, m),
                }
            }
            None => {
                let f = |i: usize, out: &mut [f64]| {
                    out.copy_from_slice(row(i));
                    true
                };
                match machine {
                    Machine::Ridge(r) => r.fit_rows(n, y, f),
                    Machine::Rff(r) => r.fit_rows(n, y, f),
                    Machine::Lda(l) => fit_lda(l, x, y, d, m),
                }
            }
        };
        Ok(used)
    }

    fn reset(&mut self) {
        match &mut self.machine {
            Machine::Ridge(r) => {
                if let Some(s) = &mut self.norm {
                    s.clear();
                    self.xs.fill(1.0);
                    // Cannot fail: ones are valid penalties.
                    let _ = r.set_penalty(&self.xs);
                }
                r.reset();
            }
            Machine::Rff(f) => {
                if let Some(s) = &mut self.norm {
                    s.clear();
                }
                f.reset();
            }
            Machine::Lda(l) => l.reset(),
        }
    }

    fn state_len(&self) -> usize {
        let norm = if self.norm.is_some() {
            2 + 2 * self.config.inputs
        } else {
            0
        };
        norm + match &self.machine {
            Machine::Ridge(r) => r.state_len_inner(),
            Machine::Rff(f) => f.state_len_inner(),
            Machine::Lda(l) => l.state_len_inner(),
        }
    }

    fn save_state(&self, out: &mut [f64]) -> Result<(), LearnError> {
        let mut w = Writer::new(out, self.state_len())?;
        if let Some(s) = &self.norm {
            s.save(&mut w);
        }
        match &self.machine {
            Machine::Ridge(r) => r.save(&mut w),
            Machine::Rff(f) => f.save(&mut w),
            Machine::Lda(l) => l.save(&mut w),
        }
        Ok(())
    }

    fn load_state(&mut self, state: &[f64]) -> Result<(), LearnError> {
        let mut rd = Reader::new(state, self.state_len())?;
        let mut norm = self.norm.clone();
        if let Some(s) = &mut norm {
            s.load(&mut rd)?;
        }
        match &mut self.machine {
            Machine::Ridge(r) => r.load(&mut rd)?,
            Machine::Rff(f) => f.load(&mut rd)?,
            Machine::Lda(l) => l.load(&mut rd)?,
        }
        self.norm = norm;
        Ok(())
    }
}
