use crate::linalg;
use crate::state::{Reader, Writer};
use crate::{check_rows, LearnError, PredictingMachine, MAX_ABS, MAX_DIM, MAX_OUTPUTS};

/// Smallest λ (and penalty entry). With values within ±1e50 (MAX_ABS), the
/// solution stays finite: ‖(S + λP)⁻¹‖ ≤ 1/(λ_eff·min P) ≤ 2e100.
pub(crate) const MIN_LAMBDA: f64 = 1e-50;
/// Largest λ (and penalty entry).
pub(crate) const MAX_LAMBDA: f64 = 1e50;

/// Hyper-parameters of ridge regression (shared by [`Ridge`] and the ridge
/// stage of [`RandomFourierFeatures`](crate::RandomFourierFeatures)).
///
/// ```
/// use mosaic_learn::RidgeParams;
///
/// let p = RidgeParams::default();
/// assert_eq!((p.lambda, p.forgetting, p.intercept, p.refactor_every), (1.0, 1.0, true, 0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RidgeParams {
    /// λ > 0, the weight of the penalty λ‖W‖² (paper eq. 6; MOSAIC's default 1).
    pub lambda: f64,
    /// β ∈ (0, 1]: sample `i` of `n` has weight β^(n−1−i) (1 = no forgetting).
    pub forgetting: f64,
    /// `true`: fit an intercept that is **not** penalised (the data are
    /// centred, as scikit-learn's `Ridge(fit_intercept=True)`); `false`: no
    /// intercept, ŷ = Wᵀx exactly as the paper's eqs. 5–6 and MOSAIC 1.
    pub intercept: bool,
    /// Re-factorise `S + λI` from the stored scatter every this many updates
    /// (0: only when needed, see [`Ridge`]).
    pub refactor_every: usize,
}

impl Default for RidgeParams {
    fn default() -> Self {
        RidgeParams {
            lambda: 1.0,
            forgetting: 1.0,
            intercept: true,
            refactor_every: 0,
        }
    }
}

impl RidgeParams {
    pub(crate) fn validate(&self) -> Result<(), LearnError> {
        if !(MIN_LAMBDA..=MAX_LAMBDA).contains(&self.lambda) {
            return Err(LearnError::InvalidParameter {
                name: "Lambda",
                value: self.lambda,
                expected: "a number from 1e-50 to 1e50 (e.g. 1; smaller fits the training data more closely)",
            });
        }
        if !(self.forgetting > 0.0 && self.forgetting <= 1.0) {
            return Err(LearnError::InvalidParameter {
                name: "Forgetting",
                value: self.forgetting,
                expected: "a number in (0, 1]: 1 keeps every sample, 0.999 halves a sample's weight after 693 samples",
            });
        }
        Ok(())
    }
}

/// Running statistics behind the reported R²: weighted mean and scatter of
/// the targets and the weighted sum of squared residuals, per output.
#[derive(Debug, Clone)]
pub(crate) struct FitStats {
    pub(crate) weight: f64,
    pub(crate) mean: Vec<f64>,
    pub(crate) m2: Vec<f64>,
    pub(crate) sse: Vec<f64>,
}

impl FitStats {
    pub(crate) fn new(m: usize) -> Self {
        FitStats {
            weight: 0.0,
            mean: vec![0.0; m],
            m2: vec![0.0; m],
            sse: vec![0.0; m],
        }
    }

    pub(crate) fn clear(&mut self) {
        self.weight = 0.0;
        self.mean.fill(0.0);
        self.m2.fill(0.0);
        self.sse.fill(0.0);
    }

    /// One target `y` with residual `e`, sample weight `w`, older samples
    /// scaled by `beta`.
    pub(crate) fn add(&mut self, y: &[f64], e: &[f64], w: f64, beta: f64) {
        // Residuals of a hopeless model (conditioning beyond 1e100) could overflow e²: such a
        // sample is left out of the statistics, which are diagnostics only.
        if !e.iter().chain(y).all(|v| (v * v).is_finite()) {
            return;
        }
        let old = beta * self.weight;
        let new = old + w;
        for o in 0..y.len() {
            let d = y[o] - self.mean[o];
            self.mean[o] += d * (w / new);
            self.m2[o] = beta * self.m2[o] + (old * w / new) * d * d;
            self.sse[o] = beta * self.sse[o] + w * e[o] * e[o];
        }
        self.weight = new;
    }

    pub(crate) fn r2(&self, out: &mut [f64]) {
        for o in 0..out.len() {
            out[o] = if self.m2[o] > 0.0 {
                1.0 - self.sse[o] / self.m2[o]
            } else {
                f64::NAN
            };
        }
    }
}

/// Ridge regression (paper eqs. 5–6), batch and incremental, multi-output.
///
/// **Model.** ŷ = Wᵀx + b. With an intercept (the default) the intercept
/// is *not* regularised: the data are centred with their (weighted) means
/// x̄, ȳ and
///
/// > W = (S + λI)⁻¹ C,  b = ȳ − Wᵀx̄,  S = Σ wᵢ (xᵢ − x̄)(xᵢ − x̄)ᵀ,  C = Σ wᵢ (xᵢ − x̄)(yᵢ − ȳ)ᵀ,
///
/// which is scikit-learn's `Ridge(alpha=λ, fit_intercept=True)` with
/// `sample_weight = w`. Without an intercept x̄ = ȳ = 0 and this is
/// W = (XᵀX + λI)⁻¹XᵀY, eq. 6 as written (and MOSAIC 1). Sample `i` of `n`
/// has weight wᵢ = β^(n−1−i) (β = [`RidgeParams::forgetting`], 1 by
/// default). A diagonal [`penalty`](Ridge::set_penalty) P generalises λI to
/// λP (a [`Model`](crate::Model) uses it to standardise); it is I below.
///
/// **Incremental update** ([`partial_fit`](PredictingMachine::partial_fit)):
/// exact recursive update of the normal equations, O(p² + p·M) per sample
/// and no allocation. A new sample changes the means and adds the rank-one
/// term c·δδᵀ to S (δ = x − x̄ before the update, c = βW/(βW + 1) with W
/// the weight sum; c = 1 without intercept). The matrix A = S + λ_eff·I is
/// kept as its **Cholesky factor** R (A = RᵀR), updated by Givens rotations
/// (LINPACK's `dchud`, |c|, |s| ≤ 1): unlike Sherman–Morrison on A⁻¹, this
/// cannot lose positive definiteness or symmetry, and its diagonal only
/// grows, so it never divides by zero however ill-conditioned the inputs
/// (constant or duplicated channels, tiny λ). W follows by the exact gain identity
/// W ← W + A⁻¹(√c δ)(√c e)ᵀ, e = y − ŷ the a-priori error. S, C and the
/// means are also stored, for saving and for re-factorising.
///
/// **Forgetting** (β < 1): A ← βA + c·δδᵀ scales λI too, so the effective
/// regulariser decays as λ_eff = λβᵏ. Whenever λ_eff falls below λ/2 the
/// model re-factorises S + λI from the stored S (O(p³), every
/// ⌈ln 2 / −ln β⌉ samples, e.g. 693 for β = 0.999) and recomputes W = A⁻¹C
/// exactly. At every moment the model is therefore *exactly* the weighted
/// ridge solution above with λ replaced by
/// [`effective_lambda`](Ridge::effective_lambda) ∈ (λ/2, λ].
///
/// **Safeguards.** Samples with a NaN, an infinity or a value beyond ±1e50
/// are refused and counted ([`rejected`](Ridge::rejected)), and λ lies in
/// [1e-50, 1e50], so the state never holds a NaN or an infinity. When the
/// conditioning exceeds what doubles resolve (the factor's diagonal spans
/// more than 9 orders of magnitude: cond(A) > 1e18, e.g. duplicated inputs
/// in the millions with λ = 1e-12), rank-one updates would lose the smallest
/// directions, so every update then re-factorises the stored S (O(p³)) and
/// the model stays the batch solution. A re-factorisation that meets a
/// non-positive pivot (λ below the rounding of ‖S‖) retries with a larger
/// shift, which then becomes λ_eff.
///
/// **Batch** ([`fit`](PredictingMachine::fit)): forgets everything, forms
/// S and C from all rows (two passes, centred), factorises once. After
/// `fit` on n rows or `partial_fit` of the same n rows (β = 1) the models
/// agree to rounding.
///
/// ```
/// use mosaic_learn::{PredictingMachine, Ridge, RidgeParams};
///
/// // y = 2·x0 − x1 + 3, learnt one sample at a time.
/// let mut r = Ridge::new(2, 1, RidgeParams { lambda: 1e-9, ..RidgeParams::default() })?;
/// for i in 0..20 {
///     let x = [i as f64, (i * i % 7) as f64];
///     r.partial_fit(&x, &[2.0 * x[0] - x[1] + 3.0])?;
/// }
/// let mut y = [0.0];
/// r.predict(&[10.0, 1.0], &mut y)?;
/// assert!((y[0] - 22.0).abs() < 1e-6);
/// # Ok::<(), mosaic_learn::LearnError>(())
/// ```
#[derive(Debug, Clone)]
pub struct Ridge {
    p: usize,
    m: usize,
    params: RidgeParams,
    samples: u64,
    weight_sum: f64,
    lambda_eff: f64,
    x_mean: Vec<f64>,
    y_mean: Vec<f64>,
    /// Scatter S, p × p; the upper triangle is maintained, but for the
    /// `queued` updates not yet applied (see [`Ridge::flush_s`]).
    s: Vec<f64>,
    /// Updates of S not yet applied, oldest first: `(β, c)` of
    /// `S ← βS + c·δδᵀ`, with δ in `queue_delta`. Nothing but
    /// `refactor` and `save` reads S, and the factor R is updated directly,
    /// so S's update is deferred and done for up to `queue_len` samples in
    /// one pass (S is p² values: at p = 1024 one pass streams 8 MiB).
    queued: Vec<(f64, f64)>,
    /// The queued δ ([`linalg::queue_at`]).
    queue_delta: Vec<f64>,
    /// S may hold a −0 (only from a loaded state; see
    /// [`linalg::sym_update_queued`]).
    neg_zero: bool,
    /// Most updates queued before they are applied (0: S is updated with
    /// each sample, fused with R's update when β = 1).
    queue_len: usize,
    /// Cross scatter C, p × M.
    c: Vec<f64>,
    /// Diagonal of the penalty: A = S + λ_eff·diag(penalty) (all 1 but with
    /// normalisation).
    penalty: Vec<f64>,
    /// Upper Cholesky factor of A.
    r: Vec<f64>,
    /// Weights W, p × M.
    w: Vec<f64>,
    stats: FitStats,
    rejected: u64,
    since_refactor: usize,
    refactors: u64,
    // Scratch (no allocation after `new`).
    delta: Vec<f64>,
    u: Vec<f64>,
    k: Vec<f64>,
    dy: Vec<f64>,
    e: Vec<f64>,
    col: Vec<f64>,
}

/// The values of `v` are finite and within ±[`MAX_ABS`].
#[inline]
pub(crate) fn usable(v: &[f64]) -> bool {
    v.iter().all(|x| x.abs() <= MAX_ABS)
}

impl Ridge {
    /// A ridge regression from `inputs` to `outputs` values (untrained:
    /// predicts 0).
    pub fn new(inputs: usize, outputs: usize, params: RidgeParams) -> Result<Ridge, LearnError> {
        params.validate()?;
        check_dims("Inputs", inputs, outputs)?;
        let (p, m) = (inputs, outputs);
        let mut r = Ridge {
            p,
            m,
            params,
            samples: 0,
            weight_sum: 0.0,
            lambda_eff: params.lambda,
            x_mean: vec![0.0; p],
            y_mean: vec![0.0; m],
            s: vec![0.0; p * p],
            queued: Vec::with_capacity(linalg::SYM_QUEUE),
            queue_delta: vec![0.0; linalg::queue_size(p)],
            neg_zero: false,
            queue_len: linalg::SYM_QUEUE,
            c: vec![0.0; p * m],
            penalty: vec![1.0; p],
            r: vec![0.0; p * p],
            w: vec![0.0; p * m],
            stats: FitStats::new(m),
            rejected: 0,
            since_refactor: 0,
            refactors: 0,
            delta: vec![0.0; p],
            u: vec![0.0; p],
            k: vec![0.0; p],
            dy: vec![0.0; m],
            e: vec![0.0; m],
            col: vec![0.0; p],
        };
        r.reset();
        Ok(r)
    }

    /// The hyper-parameters.
    pub fn params(&self) -> &RidgeParams {
        &self.params
    }

    /// λ_eff: the regulariser the current solution uses (λ, or less with
    /// forgetting; see the type's documentation).
    pub fn effective_lambda(&self) -> f64 {
        self.lambda_eff
    }

    /// Σ wᵢ, the total weight of the samples learnt (n when β = 1).
    pub fn weight_sum(&self) -> f64 {
        self.weight_sum
    }

    /// Samples refused because of a NaN, an infinity or a value beyond ±1e50.
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Re-factorisations done since creation or `reset`.
    pub fn refactors(&self) -> u64 {
        self.refactors
    }

    /// W, row-major p × M (weight of input i for output o at `i·M + o`).
    pub fn weights(&self) -> &[f64] {
        &self.w
    }

    /// b = ȳ − Wᵀx̄ into `out` (M values; 0 without intercept).
    pub fn intercept(&self, out: &mut [f64]) {
        intercept_of(&self.w, &self.x_mean, &self.y_mean, self.p, self.m, out);
    }

    /// R² per output (M values into `out`; NaN while undefined).
    ///
    /// After incremental learning it is *prequential*: every training
    /// sample from the second on is predicted by the model **before** it
    /// learns it, and R² = 1 − Σwᵢeᵢ² / Σwᵢ(yᵢ − ȳ)² over those samples (a
    /// held-out estimate). After a batch [`fit`](PredictingMachine::fit) it is
    /// the in-sample R² of the fitted rows.
    pub fn r2(&self, out: &mut [f64]) {
        self.stats.r2(&mut out[..self.m]);
    }

    /// Solves again from the stored scatter: R = chol(S + λI), W = A⁻¹C.
    /// Restores λ_eff = λ after forgetting, and removes the rounding that
    /// rank-one updates accumulate (O(p³ + p²M)).
    pub fn refactor(&mut self) {
        self.flush_s();
        let p = self.p;
        let lambda = self.params.lambda;
        let scale = (0..p).map(|i| self.s[i * p + i]).fold(0.0, f64::max);
        let min_pen = self.penalty.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        // λ below the rounding of ‖S‖ can leave a pivot ≤ 0: shift a little more (λ_eff says
        // so), 4× more each time. The last shift makes S + shift·P diagonally dominant
        // (|Sᵢⱼ| ≤ max diag S), hence positive definite: the loop always ends with a factor.
        let mut shift = lambda;
        for tries in 1..=32 {
            if linalg::cholesky_upper(&self.s, shift, &self.penalty, &mut self.r, p) {
                break;
            }
            shift = if tries < 32 {
                lambda + scale / min_pen * 1e-15 * 4f64.powi(tries)
            } else {
                lambda + scale / min_pen * 2.0 * (p as f64 + 1.0)
            };
        }
        self.lambda_eff = shift;
        linalg::solve_columns(&self.r, &self.c, &mut self.w, &mut self.col, p, self.m);
        self.since_refactor = 0;
        self.refactors += 1;
    }

    /// The diagonal penalty: the model minimises Σwᵢ‖yᵢ − ŷᵢ‖² + λ Σⱼ penaltyⱼ‖Wⱼ‖²
    /// (all 1: plain ridge).
    pub fn penalty(&self) -> &[f64] {
        &self.penalty
    }

    /// Replaces the diagonal penalty (p values, each from 1e-50 to 1e50) and
    /// re-factorises; it is kept by `reset` and `fit` (a hyper-parameter). Penalising input j by s²ⱼ is the same as plain ridge on
    /// the scaled input xⱼ/sⱼ: this is how a [`Model`](crate::Model)
    /// standardises exactly.
    pub fn set_penalty(&mut self, penalty: &[f64]) -> Result<(), LearnError> {
        if penalty.len() != self.p {
            return Err(LearnError::Length {
                name: "penalty",
                len: penalty.len(),
                expected: self.p,
            });
        }
        if let Some(j) = penalty
            .iter()
            .position(|v| !(MIN_LAMBDA..=MAX_LAMBDA).contains(v))
        {
            return Err(LearnError::InvalidParameter {
                name: "penalty",
                value: penalty[j],
                expected: "numbers from 1e-50 to 1e50",
            });
        }
        self.penalty.copy_from_slice(penalty);
        self.refactor();
        Ok(())
    }

    /// Adds to the count of refused samples.
    pub(crate) fn add_rejected(&mut self, n: u64) {
        self.rejected += n;
    }

    /// Counts a sample refused before it reached this model.
    pub(crate) fn refuse(&mut self) {
        self.rejected += 1;
    }

    /// Applies the queued updates of S.
    fn flush_s(&mut self) {
        if !self.queued.is_empty() {
            linalg::sym_update_queued(
                &mut self.s,
                &self.queued,
                &self.queue_delta,
                self.p,
                self.neg_zero,
            );
            self.queued.clear();
        }
    }

    /// Element (i, j) of S, `i ≤ j`, with the queued updates.
    fn s_at(&self, i: usize, j: usize) -> f64 {
        let v = self.s[i * self.p + j];
        linalg::queued_element(v, &self.queued, &self.queue_delta, i, j)
    }

    /// Queues `S ← βS + c·δδᵀ` (δ: `self.delta`), applying the queue when full.
    fn queue_s(&mut self, beta: f64, c: f64) {
        if beta == 1.0 && c == 0.0 {
            return; // nothing to add (what sym_update does: every c·δ_i is 0)
        }
        let q = self.queued.len();
        for (j, &d) in self.delta.iter().enumerate() {
            self.queue_delta[linalg::queue_at(q, j)] = d;
        }
        self.queued.push((beta, c));
        if self.queued.len() >= self.queue_len {
            self.flush_s();
        }
    }

    /// True when the factor's diagonal spans more than 9 orders of magnitude:
    /// cond(A) ≥ (max rᵢᵢ / min rᵢᵢ)² > 1e18, beyond double precision, where
    /// rank-one updates lose the smallest directions.
    fn beyond_precision(&self) -> bool {
        let p = self.p;
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for i in 0..p {
            let d = self.r[i * p + i];
            lo = lo.min(d);
            hi = hi.max(d);
        }
        hi > 1e9 * lo
    }

    /// Learns one sample (`x`: p values, `y`: M values); `false` when refused.
    pub(crate) fn learn_one(&mut self, x: &[f64], y: &[f64]) -> bool {
        if !(usable(x) && usable(y)) {
            self.rejected += 1;
            return false;
        }
        let (p, m) = (self.p, self.m);
        let beta = self.params.forgetting;
        let icpt = self.params.intercept;
        // δ, δy and the a-priori error with the old model.
        for i in 0..p {
            self.delta[i] = if icpt { x[i] - self.x_mean[i] } else { x[i] };
        }
        for o in 0..m {
            self.dy[o] = if icpt { y[o] - self.y_mean[o] } else { y[o] };
        }
        self.e.copy_from_slice(&self.dy);
        for i in 0..p {
            let d = self.delta[i];
            if d == 0.0 {
                continue;
            }
            let row = &self.w[i * m..(i + 1) * m];
            for o in 0..m {
                self.e[o] -= row[o] * d;
            }
        }
        if self.samples > 0 {
            self.stats.add(y, &self.e, 1.0, beta);
        }
        let old = beta * self.weight_sum;
        let new = old + 1.0;
        let c = if icpt { old / new } else { 1.0 };
        if icpt {
            let f = 1.0 / new;
            for i in 0..p {
                self.x_mean[i] += self.delta[i] * f;
            }
            for o in 0..m {
                self.y_mean[o] += self.dy[o] * f;
            }
        }
        self.weight_sum = new;
        self.samples += 1;
        // Normal equations: S ← βS + c·δδᵀ, C ← βC + c·δ·δyᵀ, λ_eff ← βλ_eff.
        // S's update is queued; unqueued and without forgetting, it is done below with R's, in
        // one pass over both.
        let queue = self.queue_len > 0;
        let fused = !queue && beta == 1.0 && c > 0.0;
        if queue {
            self.queue_s(beta, c);
        } else if !fused {
            linalg::sym_update(&mut self.s, beta, c, &self.delta, p);
        }
        for i in 0..p {
            let cd = c * self.delta[i];
            let row = &mut self.c[i * m..(i + 1) * m];
            for o in 0..m {
                row[o] = beta * row[o] + cd * self.dy[o];
            }
        }
        if beta != 1.0 {
            let sb = beta.sqrt();
            for i in 0..p {
                for v in &mut self.r[i * p + i..(i + 1) * p] {
                    *v *= sb;
                }
            }
            self.lambda_eff *= beta;
        }
        if c > 0.0 {
            let sc = c.sqrt();
            for i in 0..p {
                self.u[i] = sc * self.delta[i];
            }
            // R'ᵀR' = RᵀR + uuᵀ; the gain k = A'⁻¹u = R'⁻¹z, with z = R'⁻ᵀu from the rotations.
            if fused {
                linalg::sym_and_cholesky_update(
                    &mut self.s,
                    c,
                    &self.delta,
                    &mut self.r,
                    &mut self.u,
                    &mut self.k,
                    p,
                );
            } else {
                linalg::cholesky_update(&mut self.r, &mut self.u, &mut self.k, p);
            }
            linalg::solve_r(&self.r, &mut self.k, p);
            for o in 0..m {
                self.e[o] *= sc;
            }
            let mut finite = true;
            for i in 0..p {
                let ki = self.k[i];
                let row = &mut self.w[i * m..(i + 1) * m];
                for o in 0..m {
                    row[o] += ki * self.e[o];
                    finite &= row[o].is_finite();
                }
            }
            if !finite {
                // Only with a conditioning near 1e200 (λ at its floor, duplicated inputs at
                // ±1e50): the gain step overflowed; the exact solve from S and C cannot.
                self.refactor();
            }
        }
        self.since_refactor += 1;
        let every = self.params.refactor_every;
        if (beta != 1.0 && self.lambda_eff < 0.5 * self.params.lambda)
            || (every > 0 && self.since_refactor >= every)
            || self.beyond_precision()
        {
            self.refactor();
        }
        true
    }

    /// Predicts one sample into `out` (M values).
    pub(crate) fn predict_one(&self, x: &[f64], out: &mut [f64]) {
        let m = self.m;
        out[..m].copy_from_slice(&self.y_mean);
        for i in 0..self.p {
            let d = x[i] - self.x_mean[i];
            let row = &self.w[i * m..(i + 1) * m];
            for o in 0..m {
                out[o] += row[o] * d;
            }
        }
    }

    /// Batch fit on `n` rows produced by `row(i, out)` (which writes the p
    /// values of row i and returns them usable or not) with targets `y`
    /// (n × M). Returns the number of rows used.
    pub(crate) fn fit_rows<F>(&mut self, n: usize, y: &[f64], mut row: F) -> usize
    where
        F: FnMut(usize, &mut [f64]) -> bool,
    {
        self.reset();
        let (p, m) = (self.p, self.m);
        let beta = self.params.forgetting;
        let icpt = self.params.intercept;
        let mut x = std::mem::take(&mut self.u);
        // Pass 1: which rows are usable, weights and means.
        let mut used = 0usize;
        for i in 0..n {
            let yi = &y[i * m..(i + 1) * m];
            if row(i, &mut x) && usable(&x) && usable(yi) {
                used += 1;
            } else {
                self.rejected += 1;
            }
        }
        let weight = |j: usize| {
            if beta == 1.0 {
                1.0
            } else {
                beta.powi((used - 1 - j) as i32)
            }
        };
        let mut j = 0usize;
        if icpt {
            let mut wsum = 0.0;
            for i in 0..n {
                let yi = &y[i * m..(i + 1) * m];
                if !(row(i, &mut x) && usable(&x) && usable(yi)) {
                    continue;
                }
                let w = weight(j);
                j += 1;
                wsum += w;
                let f = w / wsum;
                for k in 0..p {
                    self.x_mean[k] += (x[k] - self.x_mean[k]) * f;
                }
                for o in 0..m {
                    self.y_mean[o] += (yi[o] - self.y_mean[o]) * f;
                }
            }
        }
        // Pass 2: S and C from centred rows.
        j = 0;
        let mut wsum = 0.0;
        for i in 0..n {
            let yi = &y[i * m..(i + 1) * m];
            if !(row(i, &mut x) && usable(&x) && usable(yi)) {
                continue;
            }
            let w = weight(j);
            j += 1;
            wsum += w;
            for k in 0..p {
                self.delta[k] = x[k] - self.x_mean[k];
            }
            for o in 0..m {
                self.dy[o] = yi[o] - self.y_mean[o];
            }
            linalg::sym_update(&mut self.s, 1.0, w, &self.delta, p);
            for k in 0..p {
                let wd = w * self.delta[k];
                let crow = &mut self.c[k * m..(k + 1) * m];
                for o in 0..m {
                    crow[o] += wd * self.dy[o];
                }
            }
        }
        self.weight_sum = wsum;
        self.samples = used as u64;
        self.refactor();
        self.refactors = 0;
        // Pass 3: in-sample fit statistics.
        let mut e = std::mem::take(&mut self.e);
        j = 0;
        for i in 0..n {
            let yi = &y[i * m..(i + 1) * m];
            if !(row(i, &mut x) && usable(&x) && usable(yi)) {
                continue;
            }
            let w = weight(j);
            j += 1;
            self.predict_one(&x, &mut e);
            for o in 0..m {
                e[o] = yi[o] - e[o];
            }
            self.stats.add(yi, &e, w, 1.0);
        }
        self.u = x;
        self.e = e;
        used
    }

    pub(crate) fn sections(&self, out: &mut Vec<(&'static str, usize)>) {
        let (p, m) = (self.p, self.m);
        out.extend_from_slice(&[
            ("meta", 3),
            ("penalty", p),
            ("x_mean", p),
            ("y_mean", m),
            ("scatter", p * p),
            ("cross", p * m),
            ("weights", p * m),
            ("intercept", m),
            ("fit_stats", 1 + 3 * m),
        ]);
    }

    pub(crate) fn state_len_inner(&self) -> usize {
        let (p, m) = (self.p, self.m);
        3 + 2 * p + m + p * p + 2 * p * m + m + 1 + 3 * m
    }

    pub(crate) fn save(&self, w: &mut Writer<'_>) {
        let p = self.p;
        w.put(&[self.samples as f64, self.weight_sum, self.lambda_eff]);
        w.put(&self.penalty);
        w.put(&self.x_mean);
        w.put(&self.y_mean);
        for i in 0..p {
            for j in 0..p {
                let v = if j >= i {
                    self.s_at(i, j)
                } else {
                    self.s_at(j, i)
                };
                w.put(&[v]);
            }
        }
        w.put(&self.c);
        w.put(&self.w);
        let b = w.take(self.m);
        self.intercept(b);
        w.put(&[self.stats.weight]);
        w.put(&self.stats.mean);
        w.put(&self.stats.m2);
        w.put(&self.stats.sse);
    }

    pub(crate) fn load(&mut self, rd: &mut Reader<'_>) -> Result<(), LearnError> {
        let (p, m) = (self.p, self.m);
        let meta = rd.section("meta", 3)?;
        let (samples, wsum, lam) = (meta[0], meta[1], meta[2]);
        if !((0.0..=9.007_199_254_740_992e15).contains(&samples) && samples.fract() == 0.0) {
            return Err(rd.bad(0, samples, "a whole number of samples >= 0"));
        }
        if !(wsum >= 0.0 && wsum.is_finite()) {
            return Err(rd.bad(1, wsum, "a weight sum >= 0"));
        }
        if !(lam >= 0.5 * MIN_LAMBDA && lam.is_finite()) {
            return Err(rd.bad(2, lam, "an effective lambda >= 5e-51"));
        }
        let pen = rd.section("penalty", p)?;
        if let Some(j) = pen
            .iter()
            .position(|v| !(MIN_LAMBDA..=MAX_LAMBDA).contains(v))
        {
            return Err(rd.bad(j, pen[j], "a penalty from 1e-50 to 1e50"));
        }
        let x_mean = rd.section("x_mean", p)?;
        let y_mean = rd.section("y_mean", m)?;
        let s = rd.section("scatter", p * p)?;
        for i in 0..p {
            if s[i * p + i] < 0.0 {
                return Err(rd.bad(i * p + i, s[i * p + i], "a diagonal >= 0"));
            }
        }
        for i in 0..p {
            for j in 0..i {
                let (a, b) = (s[i * p + j], s[j * p + i]);
                let tol = 1e-12 * (s[i * p + i] + s[j * p + j]);
                if (a - b).abs() > tol {
                    return Err(LearnError::NotSymmetric { row: i, col: j });
                }
            }
        }
        let c = rd.section("cross", p * m)?;
        let w = rd.section("weights", p * m)?;
        let b = rd.section("intercept", m)?;
        let st = rd.section("fit_stats", 1 + 3 * m)?;
        for k in (0..1).chain(1 + m..1 + 3 * m) {
            if st[k] < 0.0 {
                return Err(rd.bad(k, st[k], "a weight or sum of squares >= 0"));
            }
        }
        // Rebuild the factor and check the weights against the normal equations.
        let mut r = vec![0.0; p * p];
        if !linalg::cholesky_upper(s, lam, pen, &mut r, p) {
            return Err(LearnError::NotPositiveDefinite);
        }
        let mut wn = vec![0.0; p * m];
        let mut col = vec![0.0; p];
        linalg::solve_columns(&r, c, &mut wn, &mut col, p, m);
        let max = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let diff = |a: &[f64], b: &[f64]| {
            a.iter()
                .zip(b)
                .fold(0.0f64, |acc, (x, y)| acc.max((x - y).abs()))
        };
        let tol_w = 1e-6 * max(&wn).max(max(w)).max(1e-300);
        let dw = diff(&wn, w);
        if dw > tol_w || dw.is_nan() {
            return Err(LearnError::Inconsistent {
                section: "weights",
                difference: dw,
                tolerance: tol_w,
            });
        }
        let mut bn = vec![0.0; m];
        intercept_of(&wn, x_mean, y_mean, p, m, &mut bn);
        let tol_b = 1e-6 * max(&bn).max(max(b)).max(max(y_mean)).max(1e-300);
        let db = diff(&bn, b);
        if db > tol_b || db.is_nan() {
            return Err(LearnError::Inconsistent {
                section: "intercept",
                difference: db,
                tolerance: tol_b,
            });
        }
        // Commit.
        self.samples = samples as u64;
        self.weight_sum = wsum;
        self.lambda_eff = lam;
        self.penalty.copy_from_slice(pen);
        self.x_mean.copy_from_slice(x_mean);
        self.y_mean.copy_from_slice(y_mean);
        self.s.copy_from_slice(s);
        self.queued.clear();
        self.neg_zero = s.iter().any(|v| v.to_bits() == (-0.0f64).to_bits());
        self.c.copy_from_slice(c);
        self.r = r;
        // The saved weights themselves (they agree with the normal equations, checked above):
        // a loaded model predicts exactly what the saved one did, not within rounding.
        self.w.copy_from_slice(w);
        self.stats.weight = st[0];
        self.stats.mean.copy_from_slice(&st[1..1 + m]);
        self.stats.m2.copy_from_slice(&st[1 + m..1 + 2 * m]);
        self.stats.sse.copy_from_slice(&st[1 + 2 * m..1 + 3 * m]);
        self.since_refactor = 0;
        self.refactors = 0;
        self.rejected = 0;
        Ok(())
    }
}

/// b = ȳ − Wᵀx̄.
fn intercept_of(w: &[f64], x_mean: &[f64], y_mean: &[f64], p: usize, m: usize, out: &mut [f64]) {
    out[..m].copy_from_slice(y_mean);
    for i in 0..p {
        let xm = x_mean[i];
        if xm == 0.0 {
            continue;
        }
        let row = &w[i * m..(i + 1) * m];
        for o in 0..m {
            out[o] -= row[o] * xm;
        }
    }
}

/// Checks the sizes of a model: `dim` (the model's input dimension, p) and
/// `outputs` (M), against what can be allocated.
pub(crate) fn check_dims(name: &'static str, dim: usize, outputs: usize) -> Result<(), LearnError> {
    if dim == 0 || dim > MAX_DIM {
        return Err(LearnError::Size {
            name,
            value: dim,
            expected: "1 to 2048 (the model keeps p × p matrices)",
        });
    }
    if outputs == 0 || outputs > MAX_OUTPUTS {
        return Err(LearnError::Size {
            name: "Outputs",
            value: outputs,
            expected: "1 to 4096",
        });
    }
    Ok(())
}

impl PredictingMachine for Ridge {
    fn inputs(&self) -> usize {
        self.p
    }

    fn outputs(&self) -> usize {
        self.m
    }

    fn samples_seen(&self) -> u64 {
        self.samples
    }

    fn predict(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LearnError> {
        let n = check_rows("x", x.len(), self.p)?;
        let ny = check_rows("output", y.len(), self.m)?;
        if n != ny {
            return Err(LearnError::RowMismatch {
                a: "x",
                a_rows: n,
                b: "output",
                b_rows: ny,
            });
        }
        for i in 0..n {
            self.predict_one(
                &x[i * self.p..(i + 1) * self.p],
                &mut y[i * self.m..(i + 1) * self.m],
            );
        }
        Ok(())
    }

    fn partial_fit(&mut self, x: &[f64], y: &[f64]) -> Result<usize, LearnError> {
        let n = check_pairs(x.len(), self.p, y.len(), self.m)?;
        let mut used = 0;
        for i in 0..n {
            used += self.learn_one(
                &x[i * self.p..(i + 1) * self.p],
                &y[i * self.m..(i + 1) * self.m],
            ) as usize;
        }
        Ok(used)
    }

    fn fit(&mut self, x: &[f64], y: &[f64]) -> Result<usize, LearnError> {
        let n = check_pairs(x.len(), self.p, y.len(), self.m)?;
        let p = self.p;
        Ok(self.fit_rows(n, y, |i, out| {
            out.copy_from_slice(&x[i * p..(i + 1) * p]);
            true
        }))
    }

    fn reset(&mut self) {
        let p = self.p;
        self.samples = 0;
        self.weight_sum = 0.0;
        self.lambda_eff = self.params.lambda;
        self.x_mean.fill(0.0);
        self.y_mean.fill(0.0);
        self.s.fill(0.0);
        self.queued.clear();
        self.neg_zero = false;
        self.c.fill(0.0);
        self.w.fill(0.0);
        self.r.fill(0.0);
        for i in 0..p {
            self.r[i * p + i] = (self.params.lambda * self.penalty[i]).sqrt();
        }
        self.stats.clear();
        self.rejected = 0;
        self.since_refactor = 0;
        self.refactors = 0;
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

/// Rows of `x` (width `p`) and `y` (width `m`): both whole and equal in number.
pub(crate) fn check_pairs(xl: usize, p: usize, yl: usize, m: usize) -> Result<usize, LearnError> {
    let n = check_rows("x", xl, p)?;
    let ny = check_rows("y", yl, m)?;
    if n != ny {
        return Err(LearnError::RowMismatch {
            a: "x",
            a_rows: n,
            b: "y",
            b_rows: ny,
        });
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// Queued updates of S give, bit for bit, what updating S with every sample gives: S, the
    /// weights, predictions, saved states (saved with updates still queued) and refactors.
    #[test]
    fn queued_scatter_updates_are_bit_identical() {
        for &(p, m) in &[(13usize, 2usize), (133, 3)] {
            for &beta in &[1.0, 0.97] {
                for &intercept in &[true, false] {
                    for &every in &[0usize, 7] {
                        let params = RidgeParams {
                            lambda: 0.5,
                            forgetting: beta,
                            intercept,
                            refactor_every: every,
                        };
                        let mut a = Ridge::new(p, m, params).unwrap();
                        let mut b = Ridge::new(p, m, params).unwrap();
                        a.queue_len = 0;
                        assert_eq!(b.queue_len, linalg::SYM_QUEUE);
                        let n = if p > 100 { 80 } else { 400 };
                        let mut seed = 0x9e37_79b9_7f4a_7c15u64 ^ p as u64;
                        let mut rnd = || {
                            seed ^= seed << 13;
                            seed ^= seed >> 7;
                            seed ^= seed << 17;
                            (seed % 20001) as f64 / 10000.0 - 1.0
                        };
                        let (mut ya, mut yb) = (vec![0.0; m], vec![0.0; m]);
                        let mut sa = vec![0.0; a.state_len()];
                        let mut sb = vec![0.0; b.state_len()];
                        for t in 0..n {
                            // Zeros (δ_i = 0 without intercept), a repeated sample, large values.
                            let x: Vec<f64> = (0..p)
                                .map(|i| match (t + i) % 11 {
                                    0 => 0.0,
                                    1 => 30.0 * rnd(),
                                    _ => rnd(),
                                })
                                .collect();
                            let y: Vec<f64> =
                                (0..m).map(|o| x[o] - 0.5 * x[p - 1 - o] + rnd()).collect();
                            for _ in 0..1 + (t % 17 == 3) as usize {
                                assert!(a.learn_one(&x, &y));
                                assert!(b.learn_one(&x, &y));
                            }
                            a.predict_one(&x, &mut ya);
                            b.predict_one(&x, &mut yb);
                            assert_eq!(bits(&ya), bits(&yb), "p {p} beta {beta} t {t}");
                            assert_eq!(bits(&a.w), bits(&b.w));
                            if t % 29 == 5 {
                                a.save_state(&mut sa).unwrap();
                                b.save_state(&mut sb).unwrap();
                                assert_eq!(bits(&sa), bits(&sb), "p {p} beta {beta} t {t}");
                            }
                        }
                        assert_eq!(a.refactors, b.refactors);
                        a.save_state(&mut sa).unwrap();
                        b.save_state(&mut sb).unwrap();
                        assert_eq!(bits(&sa), bits(&sb));
                        b.refactor();
                        a.refactor();
                        assert!(b.queued.is_empty());
                        assert_eq!(bits(&a.s), bits(&b.s));
                        assert_eq!(bits(&a.r), bits(&b.r));
                        assert_eq!(bits(&a.w), bits(&b.w));
                        // A loaded state drops what was queued before.
                        b.learn_one(&vec![1.0; p], &vec![1.0; m]);
                        b.load_state(&sa).unwrap();
                        a.load_state(&sa).unwrap();
                        assert!(b.queued.is_empty());
                        assert_eq!(bits(&a.s), bits(&b.s));
                    }
                }
            }
        }
    }

    /// A −0 in a loaded S stays −0 where the unqueued update skips its row (β = 1, δᵢ = 0).
    #[test]
    fn queued_updates_keep_a_loaded_negative_zero() {
        let (p, m) = (6, 1);
        let params = RidgeParams {
            intercept: false,
            ..RidgeParams::default()
        };
        let mut a = Ridge::new(p, m, params).unwrap();
        let mut b = Ridge::new(p, m, params).unwrap();
        a.queue_len = 0;
        let x = |t: usize| -> Vec<f64> {
            (0..p)
                .map(|i| {
                    if i == 2 {
                        0.0
                    } else {
                        (t * 7 + i) as f64 % 5.0 - 2.0
                    }
                })
                .collect()
        };
        for t in 0..5 {
            a.learn_one(&x(t), &[t as f64]);
        }
        let mut st = vec![0.0; a.state_len()];
        a.save_state(&mut st).unwrap();
        let s0 = 3 + 2 * p + m; // the scatter section
        assert_eq!(st[s0 + 2 * p + 2], 0.0);
        st[s0 + 2 * p + 2] = -0.0;
        a.load_state(&st).unwrap();
        b.load_state(&st).unwrap();
        assert!(b.neg_zero);
        for t in 5..30 {
            a.learn_one(&x(t), &[t as f64]);
            b.learn_one(&x(t), &[t as f64]);
        }
        b.flush_s();
        assert_eq!(bits(&a.s), bits(&b.s));
        assert_eq!(a.s[2 * p + 2].to_bits(), (-0.0f64).to_bits());
    }
}
