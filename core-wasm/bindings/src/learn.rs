//! [`Model`] (mosaic-learn) with scratch buffers in the wasm memory: the
//! Batch/IncrementalPredictor blocks' kernel. Same protocol as the DSP
//! wrappers: JavaScript writes inputs through a view of the memory at the
//! `*_ptr()` addresses, calls a method that returns a `bool` or a count
//! (never a `Result`, which wasm-bindgen returns through a fresh array), and
//! reads the results. `ensure_*` may move the buffers.

use mosaic_learn::{LdaOutput, LearnError, Model, ModelConfig, PredictingMachine};
use wasm_bindgen::prelude::*;

fn js_err(e: LearnError) -> JsError {
    JsError::new(&e.to_string())
}

fn zeros(len: usize) -> Vec<f64> {
    vec![0.0; len]
}

/// A learning machine (ridge, RFF or LDA) with its buffers.
#[wasm_bindgen]
pub struct WasmLearner {
    model: Model,
    d: usize,
    m: usize,
    /// Events the input and output buffers hold.
    capacity: usize,
    x: Vec<f64>,
    out: Vec<f64>,
    target: Vec<f64>,
    /// Rows the pairs buffer holds.
    pairs_capacity: usize,
    pairs: Vec<f64>,
    fit_x: Vec<f64>,
    fit_y: Vec<f64>,
    state: Vec<f64>,
    r2: Vec<f64>,
}

#[wasm_bindgen]
impl WasmLearner {
    /// `kind` is `ridge`, `rff` or `lda`; `features`, `gamma` and the seed
    /// (`seed_hi · 2³² + seed_lo`) are used by `rff` only;
    /// `normalize_samples` by `rff` with `normalize` only; `shrinkage`,
    /// `max_classes` and `lda_class` (predict the most probable class's
    /// target instead of the probability-weighted targets) by `lda` only.
    #[wasm_bindgen(constructor)]
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        kind: &str,
        inputs: usize,
        outputs: usize,
        lambda: f64,
        forgetting: f64,
        intercept: bool,
        normalize: bool,
        normalize_samples: usize,
        features: usize,
        gamma: f64,
        seed_hi: u32,
        seed_lo: u32,
        shrinkage: f64,
        max_classes: usize,
        lda_class: bool,
        capacity_events: usize,
    ) -> Result<WasmLearner, JsError> {
        let base = match kind {
            "ridge" => ModelConfig::ridge(inputs, outputs),
            "rff" => ModelConfig::rff(inputs, outputs)
                .features(features)
                .gamma(gamma)
                .seed((u64::from(seed_hi) << 32) | u64::from(seed_lo)),
            "lda" => ModelConfig::lda(inputs, outputs)
                .shrinkage(shrinkage)
                .max_classes(max_classes)
                .lda_output(if lda_class {
                    LdaOutput::Class
                } else {
                    LdaOutput::Scores
                }),
            other => {
                return Err(JsError::new(&format!(
                    "unknown model '{other}'; expected ridge, rff or lda"
                )))
            }
        };
        let model = base
            .lambda(lambda)
            .forgetting(forgetting)
            .intercept(intercept)
            .normalize(normalize)
            .normalize_samples(normalize_samples)
            .build()
            .map_err(js_err)?;
        let len = model.state_len();
        let mut w = WasmLearner {
            model,
            d: inputs,
            m: outputs,
            capacity: 0,
            x: Vec::new(),
            out: Vec::new(),
            target: zeros(outputs),
            pairs_capacity: 0,
            pairs: Vec::new(),
            fit_x: Vec::new(),
            fit_y: Vec::new(),
            state: zeros(len),
            r2: zeros(outputs),
        };
        w.ensure_capacity(capacity_events.max(1));
        Ok(w)
    }

    /// Byte address of the input buffer (`capacity() × inputs` values).
    pub fn x_ptr(&self) -> usize {
        self.x.as_ptr() as usize
    }

    /// Byte address of the prediction buffer (`capacity() × outputs` values).
    pub fn out_ptr(&self) -> usize {
        self.out.as_ptr() as usize
    }

    /// Byte address of the target buffer (`outputs` values).
    pub fn target_ptr(&self) -> usize {
        self.target.as_ptr() as usize
    }

    /// Events the input and prediction buffers hold.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Grows the input and prediction buffers to `events` events (moves them).
    pub fn ensure_capacity(&mut self, events: usize) {
        if events > self.capacity {
            self.capacity = events;
            self.x = zeros(events * self.d);
            self.out = zeros(events * self.m);
        }
    }

    /// Predicts `n` events of the input buffer into the prediction buffer.
    /// `false` when `n > capacity()`.
    pub fn predict(&mut self, n: usize) -> bool {
        if n > self.capacity {
            return false;
        }
        self.model
            .predict(&self.x[..n * self.d], &mut self.out[..n * self.m])
            .is_ok()
    }

    /// For each of `n` events: learn it with the target buffer, then predict
    /// it. Returns the samples learnt (refused ones are counted by
    /// `rejected()`), or −1 when `n > capacity()`.
    pub fn train_predict(&mut self, n: usize) -> i32 {
        if n > self.capacity {
            return -1;
        }
        match self.model.train_predict(
            &self.x[..n * self.d],
            &self.target,
            &mut self.out[..n * self.m],
        ) {
            Ok(k) => k as i32,
            Err(_) => -1,
        }
    }

    /// Byte address of the pairs buffer: rows `[target (outputs), input
    /// (inputs)]`, the Buffer block's layout.
    pub fn pairs_ptr(&self) -> usize {
        self.pairs.as_ptr() as usize
    }

    /// Rows the pairs buffer holds.
    pub fn pairs_capacity(&self) -> usize {
        self.pairs_capacity
    }

    /// Grows the pairs buffer to `rows` rows (moves it).
    pub fn ensure_pairs(&mut self, rows: usize) {
        if rows > self.pairs_capacity {
            self.pairs_capacity = rows;
            self.pairs = zeros(rows * (self.d + self.m));
            self.fit_x = zeros(rows * self.d);
            self.fit_y = zeros(rows * self.m);
        }
    }

    /// Forgets everything and fits the first `n` rows of the pairs buffer in
    /// one batch. Returns the rows used, or −1 when `n > pairs_capacity()`.
    pub fn fit_pairs(&mut self, n: usize) -> i32 {
        if n > self.pairs_capacity {
            return -1;
        }
        let (d, m) = (self.d, self.m);
        for (i, row) in self.pairs[..n * (d + m)].chunks_exact(d + m).enumerate() {
            self.fit_y[i * m..(i + 1) * m].copy_from_slice(&row[..m]);
            self.fit_x[i * d..(i + 1) * d].copy_from_slice(&row[m..]);
        }
        match self.model.fit(&self.fit_x[..n * d], &self.fit_y[..n * m]) {
            Ok(k) => k as i32,
            Err(_) => -1,
        }
    }

    /// Samples learnt (as a double: JavaScript numbers).
    pub fn samples_seen(&self) -> f64 {
        self.model.samples_seen() as f64
    }

    /// Samples refused (NaN, infinity, beyond ±1e50).
    pub fn rejected(&self) -> f64 {
        self.model.rejected() as f64
    }

    /// λ in use (λ, or less while forgetting).
    pub fn effective_lambda(&self) -> f64 {
        self.model.effective_lambda()
    }

    /// Dimension of the ridge stage (inputs, or features for RFF).
    pub fn dim(&self) -> usize {
        self.model.dim()
    }

    /// Computes R² per output into the R² buffer (NaN while undefined).
    pub fn update_r2(&mut self) {
        self.model.r2(&mut self.r2);
    }

    /// Byte address of the R² buffer (`outputs` values).
    pub fn r2_ptr(&self) -> usize {
        self.r2.as_ptr() as usize
    }

    /// Values of the flat state.
    pub fn state_len(&self) -> usize {
        self.state.len()
    }

    /// Byte address of the state buffer.
    pub fn state_ptr(&self) -> usize {
        self.state.as_ptr() as usize
    }

    /// Names of the state's sections, comma-separated, in order.
    pub fn state_names(&self) -> String {
        let names: Vec<&str> = self.model.state_sections().iter().map(|s| s.0).collect();
        names.join(",")
    }

    /// Lengths of the state's sections, in order.
    pub fn state_lens(&self) -> Vec<u32> {
        self.model
            .state_sections()
            .iter()
            .map(|s| s.1 as u32)
            .collect()
    }

    /// Writes the state into the state buffer.
    pub fn save_state(&mut self) -> bool {
        self.model.save_state(&mut self.state).is_ok()
    }

    /// Replaces the model's state by the one in the state buffer, after
    /// checking it; on error the model is unchanged and the message says
    /// what is wrong.
    pub fn load_state(&mut self) -> Result<(), JsError> {
        self.model.load_state(&self.state).map_err(js_err)
    }

    /// Back to the untrained model (Ω and b are kept).
    pub fn reset(&mut self) {
        self.model.reset();
    }

    /// Solves again from the stored normal equations (see mosaic-learn).
    pub fn refactor(&mut self) {
        self.model.refactor();
    }
}
