//! Incremental linear discriminant analysis.

use crate::linalg;
use crate::ridge::{usable, FitStats};
use crate::state::{Reader, Writer};
use crate::{LearnError, MAX_DIM, MAX_OUTPUTS};

/// What an [`Lda`] predicts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LdaOutput {
    /// Σₖ P(k | x)·tₖ: the class targets weighted by the posterior probabilities (with one-hot
    /// targets, the class probabilities themselves).
    Scores,
    /// The target tₖ of the most probable class (with one-hot targets, a one-hot prediction).
    Class,
}

/// Hyper-parameters of an [`Lda`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LdaParams {
    /// α in [0, 1]: the covariance used is (1 − α)Σ + α·(tr Σ / d)·I (scikit-learn's
    /// `shrinkage`); 0 by default.
    pub shrinkage: f64,
    /// Most classes (distinct target vectors) the model keeps; samples of further classes are
    /// refused and counted. 32 by default.
    pub max_classes: usize,
    /// Scores (default) or the most probable class's target.
    pub output: LdaOutput,
}

impl Default for LdaParams {
    fn default() -> Self {
        LdaParams {
            shrinkage: 0.0,
            max_classes: 32,
            output: LdaOutput::Scores,
        }
    }
}

/// Most classes an [`Lda`] may keep.
pub const MAX_CLASSES: usize = 1024;

/// Linear discriminant analysis learnt one sample at a time: the class means and the pooled
/// within-class covariance are updated per sample (Welford), so after n samples the model is
/// exactly the batch LDA of those n samples (scikit-learn's `LinearDiscriminantAnalysis` with
/// the `lsqr` solver, priors the class proportions).
///
/// **Classes** are the distinct target vectors (compared exactly): a one-hot target eₖ is class
/// k, but any vector works (MOSAIC's targets such as `power: 1;1;1;1;1;1;0;…`, or a rest of all
/// zeros). **Model**, with nₖ samples and mean μₖ in class k, n samples in all:
///
/// > Σ = Sᵥᵥ / n with Sᵥᵥ = Σₖ Σᵢ∈ₖ (xᵢ − μₖ)(xᵢ − μₖ)ᵀ,  Σₐ = (1 − α)Σ + α(tr Σ/d)·I,
/// > δₖ(x) = xᵀΣₐ⁻¹μₖ − ½ μₖᵀΣₐ⁻¹μₖ + ln(nₖ/n),  P(k | x) = softmax(δ(x))ₖ.
///
/// A sample of class k updates δ = x − μₖ, μₖ ← μₖ + δ/nₖ, Sᵥᵥ ← Sᵥᵥ + δ(x − μₖ)ᵀ (O(d²)). The
/// discriminants are solved again (Cholesky, O(d³ + K·d²)) at the first prediction after an
/// update. When Σₐ is singular (fewer samples than inputs, a constant input) a ridge of 10⁻¹⁰
/// of its mean diagonal (or 1 when it is 0: nearest class mean) is added and counted.
///
/// ```
/// use mosaic_learn::{LdaParams, Lda};
///
/// let mut lda = Lda::new(2, 2, LdaParams::default())?;
/// for i in 0..20 {
///     let t = i as f64 * 0.1;
///     lda.learn_one(&[t.sin() * 0.1, 1.0 + t.cos() * 0.1], &[1.0, 0.0]); // class [1, 0]
///     lda.learn_one(&[1.0 + t.cos() * 0.1, t.sin() * 0.1], &[0.0, 1.0]); // class [0, 1]
/// }
/// let mut p = [0.0; 2];
/// lda.predict_one(&[0.0, 1.0], &mut p);
/// assert!(p[0] > 0.99 && (p[0] + p[1] - 1.0).abs() < 1e-12);
/// # Ok::<(), mosaic_learn::LearnError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Lda {
    d: usize,
    m: usize,
    params: LdaParams,
    k: usize,
    samples: u64,
    rejected: u64,
    /// Targets of the classes, K × m.
    targets: Vec<f64>,
    counts: Vec<f64>,
    /// Class means, K × d.
    means: Vec<f64>,
    /// Pooled within-class scatter Sᵥᵥ, d × d (both triangles).
    scatter: Vec<f64>,
    stats: FitStats,
    // Derived (solved lazily).
    dirty: bool,
    regularized: u64,
    r: Vec<f64>,
    cov: Vec<f64>,
    ones: Vec<f64>,
    coef: Vec<f64>,
    intercept: Vec<f64>,
    scores: Vec<f64>,
    delta: Vec<f64>,
    pred: Vec<f64>,
    err: Vec<f64>,
}

impl Lda {
    /// An LDA from `inputs` values to targets of `outputs` values (untrained: predicts 0).
    pub fn new(inputs: usize, outputs: usize, params: LdaParams) -> Result<Lda, LearnError> {
        if inputs == 0 || inputs > MAX_DIM {
            return Err(LearnError::Size {
                name: "Inputs",
                value: inputs,
                expected: "1 to 2048 inputs for LDA",
            });
        }
        if outputs == 0 || outputs > MAX_OUTPUTS {
            return Err(LearnError::Size {
                name: "Outputs",
                value: outputs,
                expected: "1 to 4096 outputs",
            });
        }
        if !(0.0..=1.0).contains(&params.shrinkage) {
            return Err(LearnError::InvalidParameter {
                name: "Shrinkage",
                value: params.shrinkage,
                expected: "a number from 0 to 1",
            });
        }
        if params.max_classes == 0 || params.max_classes > MAX_CLASSES {
            return Err(LearnError::Size {
                name: "MaxClasses",
                value: params.max_classes,
                expected: "1 to 1024 classes",
            });
        }
        let (d, m, kk) = (inputs, outputs, params.max_classes);
        Ok(Lda {
            d,
            m,
            params,
            k: 0,
            samples: 0,
            rejected: 0,
            targets: vec![0.0; kk * m],
            counts: vec![0.0; kk],
            means: vec![0.0; kk * d],
            scatter: vec![0.0; d * d],
            stats: FitStats::new(m),
            dirty: true,
            regularized: 0,
            r: vec![0.0; d * d],
            cov: vec![0.0; d * d],
            ones: vec![1.0; d],
            coef: vec![0.0; kk * d],
            intercept: vec![0.0; kk],
            scores: vec![0.0; kk],
            delta: vec![0.0; d],
            pred: vec![0.0; m],
            err: vec![0.0; m],
        })
    }

    /// d.
    pub fn inputs(&self) -> usize {
        self.d
    }

    /// M.
    pub fn outputs(&self) -> usize {
        self.m
    }

    /// The hyper-parameters.
    pub fn params(&self) -> LdaParams {
        self.params
    }

    /// Classes seen so far.
    pub fn classes(&self) -> usize {
        self.k
    }

    /// Samples learnt.
    pub fn samples_seen(&self) -> u64 {
        self.samples
    }

    /// Samples refused (a NaN, an infinity, a value beyond ±1e50, or a class beyond MaxClasses).
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Times the covariance had to be regularised to be solved.
    pub fn regularized(&self) -> u64 {
        self.regularized
    }

    /// Prequential R² per output: each sample from the second on is predicted before it is
    /// learnt (NaN while an output's target has not varied).
    pub fn r2(&self, out: &mut [f64]) {
        self.stats.r2(&mut out[..self.m]);
    }

    pub(crate) fn refuse(&mut self) {
        self.rejected += 1;
    }

    /// Forgets everything.
    pub fn reset(&mut self) {
        self.k = 0;
        self.samples = 0;
        self.rejected = 0;
        self.regularized = 0;
        self.targets.fill(0.0);
        self.counts.fill(0.0);
        self.means.fill(0.0);
        self.scatter.fill(0.0);
        self.stats.clear();
        self.dirty = true;
    }

    fn class_of(&self, y: &[f64]) -> Option<usize> {
        let m = self.m;
        (0..self.k).find(|&c| self.targets[c * m..(c + 1) * m] == *y)
    }

    /// Learns one sample (d values) of the class with target `y` (M values); false when refused.
    pub fn learn_one(&mut self, x: &[f64], y: &[f64]) -> bool {
        if !(usable(x) && usable(y)) {
            self.refuse();
            return false;
        }
        let (d, m) = (self.d, self.m);
        let known = self.class_of(y);
        if known.is_none() && self.k == self.params.max_classes {
            self.refuse();
            return false;
        }
        // Prequential statistics: predicted by the model of the samples before this one.
        if self.samples > 0 {
            let mut pred = std::mem::take(&mut self.pred);
            self.predict_one(x, &mut pred);
            for o in 0..m {
                self.err[o] = y[o] - pred[o];
            }
            self.stats.add(y, &self.err, 1.0, 1.0);
            self.pred = pred;
        }
        let c = match known {
            Some(c) => c,
            None => {
                let c = self.k;
                self.targets[c * m..(c + 1) * m].copy_from_slice(y);
                self.counts[c] = 0.0;
                self.means[c * d..(c + 1) * d].fill(0.0);
                self.k += 1;
                c
            }
        };
        self.counts[c] += 1.0;
        let n = self.counts[c];
        let mean = &mut self.means[c * d..(c + 1) * d];
        for i in 0..d {
            self.delta[i] = x[i] - mean[i];
            mean[i] += self.delta[i] / n;
        }
        // Sᵥᵥ += δ (x − μ_new)ᵀ = (n − 1)/n · δδᵀ: symmetric, rank one.
        let f = (n - 1.0) / n;
        for i in 0..d {
            let a = f * self.delta[i];
            if a == 0.0 {
                continue;
            }
            let row = &mut self.scatter[i * d..(i + 1) * d];
            for j in 0..d {
                row[j] += a * self.delta[j];
            }
        }
        self.samples += 1;
        self.dirty = true;
        true
    }

    /// Solves the discriminants from the statistics.
    fn prepare(&mut self) {
        if !self.dirty {
            return;
        }
        self.dirty = false;
        let (d, k) = (self.d, self.k);
        if k == 0 {
            return;
        }
        let n: f64 = self.counts[..k].iter().sum();
        let alpha = self.params.shrinkage;
        let mut trace = 0.0;
        for i in 0..d {
            trace += self.scatter[i * d + i] / n;
        }
        let mu = trace / d as f64;
        for i in 0..d {
            for j in 0..d {
                let s = (1.0 - alpha) * (self.scatter[i * d + j] / n);
                self.cov[i * d + j] = if i == j { s + alpha * mu } else { s };
            }
        }
        let ones = &self.ones;
        if !linalg::cholesky_upper(&self.cov, 0.0, ones, &mut self.r, d) {
            self.regularized += 1;
            let mean_diag = (0..d).map(|i| self.cov[i * d + i]).sum::<f64>() / d as f64;
            let mut shift = if mean_diag > 0.0 && mean_diag.is_finite() {
                1e-10 * mean_diag
            } else {
                1.0
            };
            while !linalg::cholesky_upper(&self.cov, shift, ones, &mut self.r, d) {
                shift *= 10.0;
                if !shift.is_finite() {
                    break;
                }
            }
        }
        for c in 0..k {
            let w = &mut self.coef[c * d..(c + 1) * d];
            w.copy_from_slice(&self.means[c * d..(c + 1) * d]);
            linalg::solve(&self.r, w, d);
            let quad: f64 = (0..d).map(|i| self.means[c * d + i] * w[i]).sum();
            self.intercept[c] = -0.5 * quad + (self.counts[c] / n).ln();
        }
    }

    /// The posterior probabilities of the classes for `x` into `p` (`classes()` values).
    pub fn probabilities(&mut self, x: &[f64], p: &mut [f64]) {
        self.prepare();
        let (d, k) = (self.d, self.k);
        let mut max = f64::NEG_INFINITY;
        for c in 0..k {
            let w = &self.coef[c * d..(c + 1) * d];
            let s = self.intercept[c] + (0..d).map(|i| x[i] * w[i]).sum::<f64>();
            p[c] = s;
            if s > max {
                max = s;
            }
        }
        let mut sum = 0.0;
        for v in p[..k].iter_mut() {
            *v = (*v - max).exp();
            sum += *v;
        }
        for v in p[..k].iter_mut() {
            *v /= sum;
        }
    }

    /// Predicts `x` (d values) into `out` (M values): see [`LdaOutput`]; 0 while untrained.
    pub fn predict_one(&mut self, x: &[f64], out: &mut [f64]) {
        let (m, k) = (self.m, self.k);
        out[..m].fill(0.0);
        if k == 0 {
            return;
        }
        let mut p = std::mem::take(&mut self.scores);
        self.probabilities(x, &mut p);
        match self.params.output {
            LdaOutput::Scores => {
                for c in 0..k {
                    let t = &self.targets[c * m..(c + 1) * m];
                    for o in 0..m {
                        out[o] += p[c] * t[o];
                    }
                }
            }
            LdaOutput::Class => {
                let mut best = 0;
                for c in 1..k {
                    if p[c] > p[best] {
                        best = c;
                    }
                }
                out[..m].copy_from_slice(&self.targets[best * m..(best + 1) * m]);
            }
        }
        self.scores = p;
    }

    pub(crate) fn sections(&self, out: &mut Vec<(&'static str, usize)>) {
        let (d, m, kk) = (self.d, self.m, self.params.max_classes);
        out.extend_from_slice(&[
            ("meta", 3),
            ("targets", kk * m),
            ("counts", kk),
            ("means", kk * d),
            ("scatter", d * d),
            ("fit_stats", 1 + 3 * m),
        ]);
    }

    pub(crate) fn state_len_inner(&self) -> usize {
        let (d, m, kk) = (self.d, self.m, self.params.max_classes);
        3 + kk * m + kk + kk * d + d * d + 1 + 3 * m
    }

    pub(crate) fn save(&self, w: &mut Writer<'_>) {
        w.put(&[self.samples as f64, self.k as f64, self.rejected as f64]);
        w.put(&self.targets);
        w.put(&self.counts);
        w.put(&self.means);
        w.put(&self.scatter);
        w.put(&[self.stats.weight]);
        w.put(&self.stats.mean);
        w.put(&self.stats.m2);
        w.put(&self.stats.sse);
    }

    pub(crate) fn load(&mut self, rd: &mut Reader<'_>) -> Result<(), LearnError> {
        let (d, m, kk) = (self.d, self.m, self.params.max_classes);
        let whole = |v: f64, max: f64| (0.0..=max).contains(&v) && v.fract() == 0.0;
        let meta = rd.section("meta", 3)?;
        if !whole(meta[0], 9.007_199_254_740_992e15) {
            return Err(rd.bad(0, meta[0], "a whole number of samples >= 0"));
        }
        if !whole(meta[1], kk as f64) {
            return Err(rd.bad(1, meta[1], "a whole number of classes up to MaxClasses"));
        }
        if !whole(meta[2], 9.007_199_254_740_992e15) {
            return Err(rd.bad(2, meta[2], "a whole number of refused samples >= 0"));
        }
        let k = meta[1] as usize;
        let targets = rd.section("targets", kk * m)?;
        let counts = rd.section("counts", kk)?;
        for c in 0..kk {
            if !whole(counts[c], 9.007_199_254_740_992e15) || (c < k) != (counts[c] > 0.0) {
                return Err(rd.bad(
                    c,
                    counts[c],
                    "a whole number of samples > 0 for each class in use, 0 for the others",
                ));
            }
        }
        if counts[..k].iter().sum::<f64>() != meta[0] {
            return Err(rd.bad(0, meta[0], "the sum of the class counts"));
        }
        let means = rd.section("means", kk * d)?;
        let s = rd.section("scatter", d * d)?;
        for i in 0..d {
            if s[i * d + i] < 0.0 {
                return Err(rd.bad(i * d + i, s[i * d + i], "a diagonal >= 0"));
            }
            for j in 0..i {
                let (a, b) = (s[i * d + j], s[j * d + i]);
                if (a - b).abs() > 1e-12 * (s[i * d + i] + s[j * d + j]) {
                    return Err(LearnError::NotSymmetric { row: i, col: j });
                }
            }
        }
        let st = rd.section("fit_stats", 1 + 3 * m)?;
        for j in (0..1).chain(1 + m..1 + 3 * m) {
            if st[j] < 0.0 {
                return Err(rd.bad(j, st[j], "a weight or sum of squares >= 0"));
            }
        }
        self.samples = meta[0] as u64;
        self.k = k;
        self.rejected = meta[2] as u64;
        self.targets.copy_from_slice(targets);
        self.counts.copy_from_slice(counts);
        self.means.copy_from_slice(means);
        self.scatter.copy_from_slice(s);
        self.stats.weight = st[0];
        self.stats.mean.copy_from_slice(&st[1..1 + m]);
        self.stats.m2.copy_from_slice(&st[1 + m..1 + 2 * m]);
        self.stats.sse.copy_from_slice(&st[1 + 2 * m..1 + 3 * m]);
        self.dirty = true;
        Ok(())
    }
}
