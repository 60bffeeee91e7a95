//! Thin wasm-bindgen wrappers around `mosaic-dsp` for the TypeScript engine
//! (`app/engine/dsp/`). No DSP logic lives here.
//!
//! Hot-path protocol (no allocation, no copies through wasm-bindgen): every
//! wrapper owns an input and an output scratch buffer sized for
//! `capacity()` events. JavaScript writes the input through a
//! `Float64Array` view of `wasm_memory().buffer` at `input_ptr()`, calls
//! `process(n_events)` and reads the result at `output_ptr()`.
//! `ensure_capacity` may move the buffers (and grow the memory), so the
//! pointers and views must be fetched again after it.
//!
//! The names of the exports are a contract with `app/engine/dsp/index.ts`
//! (and `app/engine/dsp/learn.ts` for [`WasmLearner`], in `learn.rs`).
#![warn(missing_docs)]

mod learn;
pub use learn::WasmLearner;

use mosaic_dsp::{
    AdaptiveFilter, AdaptiveFilterConfig, ArtifactConfig, ArtifactRejector, DerivativeOrder,
    EmgSynth, EmgSynthConfig, Feature, FeatureKernel, FeatureSpec, FilterBank, FunctionKernel,
    FunctionOp, SlidingWindow, WindowFunction, WindowedFeatures, ARTIFACT_COUNTERS,
};
use wasm_bindgen::prelude::*;

/// The module's linear memory (a `WebAssembly.Memory`).
///
/// Named `wasm_memory`, not `memory`: wasm-bindgen exports a function under
/// its JS name, and the module already exports its memory as `memory`, so a
/// function of that name makes the module invalid ("Duplicate export name
/// 'memory'", wasm-bindgen issue #1116).
#[wasm_bindgen]
pub fn wasm_memory() -> JsValue {
    wasm_bindgen::memory()
}

/// Chooses the SIMD128 kernels (`true`, the default) or the scalar code
/// (`false`) from now on, for tests that compare the two; returns whether
/// this build has SIMD kernels at all (see `mosaic_dsp::set_simd_enabled`).
#[wasm_bindgen]
pub fn set_simd_enabled(enabled: bool) -> bool {
    mosaic_dsp::set_simd_enabled(enabled)
}

/// The version of this crate.
#[wasm_bindgen]
pub fn version() -> String {
    env!("CARGO_PKG_VERSION").to_string()
}

/// Input and output scratch buffers of `capacity` events × `channels` values
/// (a generator has no input buffer).
struct Scratch {
    channels: usize,
    capacity: usize,
    has_input: bool,
    input: Vec<f64>,
    output: Vec<f64>,
}

impl Scratch {
    fn new(channels: usize, capacity: usize, has_input: bool) -> Self {
        let mut s = Scratch {
            channels,
            capacity: 0,
            has_input,
            input: Vec::new(),
            output: Vec::new(),
        };
        s.ensure(capacity.max(1));
        s
    }

    fn ensure(&mut self, events: usize) {
        if events > self.capacity {
            self.capacity = events;
            let n = events * self.channels;
            if self.has_input {
                self.input = vec![0.0; n];
            }
            self.output = vec![0.0; n];
        }
    }

    /// Number of values for `n_events` events, or `None` beyond the capacity.
    fn len(&self, n_events: usize) -> Option<usize> {
        (n_events <= self.capacity).then(|| n_events * self.channels)
    }
}

fn js_err(e: mosaic_dsp::DspError) -> JsError {
    JsError::new(&e.to_string())
}

/// [`FilterBank`] with scratch buffers.
#[wasm_bindgen]
pub struct WasmFilterBank {
    bank: FilterBank,
    scratch: Scratch,
}

#[wasm_bindgen]
impl WasmFilterBank {
    /// See [`FilterBank::new`]; `capacity_events` sizes the scratch buffers.
    #[wasm_bindgen(constructor)]
    pub fn new(
        num: &[f64],
        den: &[f64],
        channels: usize,
        capacity_events: usize,
    ) -> Result<WasmFilterBank, JsError> {
        let bank = FilterBank::new(num, den, channels).map_err(js_err)?;
        Ok(WasmFilterBank {
            bank,
            scratch: Scratch::new(channels, capacity_events, true),
        })
    }

    /// Byte address of the input scratch buffer.
    pub fn input_ptr(&self) -> usize {
        self.scratch.input.as_ptr() as usize
    }

    /// Byte address of the output scratch buffer.
    pub fn output_ptr(&self) -> usize {
        self.scratch.output.as_ptr() as usize
    }

    /// Capacity of the scratch buffers, in events.
    pub fn capacity(&self) -> usize {
        self.scratch.capacity
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.bank.channels()
    }

    /// Grows the scratch buffers to hold at least `events` events (moves them).
    pub fn ensure_capacity(&mut self, events: usize) {
        self.scratch.ensure(events);
    }

    /// Filters the first `n_events` events of the input scratch into the
    /// output scratch. Returns `false` (and does nothing) when `n_events`
    /// exceeds `capacity()`. (A `bool` rather than a `Result`: wasm-bindgen
    /// returns a `Result` through a fresh JS array, an allocation per call.)
    pub fn process(&mut self, n_events: usize) -> bool {
        let Some(n) = self.scratch.len(n_events) else {
            return false;
        };
        self.bank
            .process(&self.scratch.input[..n], &mut self.scratch.output[..n])
            .is_ok()
    }

    /// Clears the filter history.
    pub fn reset(&mut self) {
        self.bank.reset();
    }
}

/// [`FunctionKernel`] with scratch buffers and an operand buffer of `channels` values.
#[wasm_bindgen]
pub struct WasmFunctionKernel {
    kernel: FunctionKernel,
    scratch: Scratch,
    operand: Vec<f64>,
}

#[wasm_bindgen]
impl WasmFunctionKernel {
    /// `op` is one of `add`, `multiply`, `abs`, `power`, `clip`; `operand` is
    /// used by add/multiply, `p` by power, `min`/`max` by clip.
    #[wasm_bindgen(constructor)]
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        op: &str,
        operand: &[f64],
        p: f64,
        min: f64,
        max: f64,
        channels: usize,
        capacity_events: usize,
    ) -> Result<WasmFunctionKernel, JsError> {
        let op = match op {
            "add" => FunctionOp::Add(operand.to_vec()),
            "multiply" => FunctionOp::Multiply(operand.to_vec()),
            "abs" => FunctionOp::Abs,
            "power" => FunctionOp::Power(p),
            "clip" => FunctionOp::Clip { min, max },
            other => {
                return Err(JsError::new(&format!(
                    "unknown operation '{other}'; expected one of add, multiply, abs, power, clip"
                )))
            }
        };
        let kernel = FunctionKernel::new(op, channels).map_err(js_err)?;
        Ok(WasmFunctionKernel {
            kernel,
            scratch: Scratch::new(channels, capacity_events, true),
            operand: vec![0.0; channels],
        })
    }

    /// Byte address of the input scratch buffer.
    pub fn input_ptr(&self) -> usize {
        self.scratch.input.as_ptr() as usize
    }

    /// Byte address of the output scratch buffer.
    pub fn output_ptr(&self) -> usize {
        self.scratch.output.as_ptr() as usize
    }

    /// Byte address of the operand buffer (`channels` values).
    pub fn operand_ptr(&self) -> usize {
        self.operand.as_ptr() as usize
    }

    /// Capacity of the scratch buffers, in events.
    pub fn capacity(&self) -> usize {
        self.scratch.capacity
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.kernel.channels()
    }

    /// Grows the scratch buffers to hold at least `events` events (moves them).
    pub fn ensure_capacity(&mut self, events: usize) {
        self.scratch.ensure(events);
    }

    /// Applies the operation with its constant operand to `n_events` events.
    /// Returns `false` (and does nothing) when `n_events` exceeds `capacity()`.
    pub fn process(&mut self, n_events: usize) -> bool {
        let Some(n) = self.scratch.len(n_events) else {
            return false;
        };
        self.kernel
            .process(&self.scratch.input[..n], &mut self.scratch.output[..n])
            .is_ok()
    }

    /// Applies add/multiply with the operand buffer (same vector for every
    /// event). Returns `false` (and does nothing) when `n_events` exceeds
    /// `capacity()` or the operation takes no operand (abs, power, clip).
    pub fn process_with_operand(&mut self, n_events: usize) -> bool {
        let Some(n) = self.scratch.len(n_events) else {
            return false;
        };
        self.kernel
            .process_with_operand(
                &self.scratch.input[..n],
                &self.operand,
                &mut self.scratch.output[..n],
            )
            .is_ok()
    }

    /// `true` when the operation combines the input with an operand (add, multiply).
    pub fn takes_operand(&self) -> bool {
        matches!(
            self.kernel.op(),
            FunctionOp::Add(_) | FunctionOp::Multiply(_)
        )
    }

    /// Does nothing (stateless); kept for a uniform interface.
    pub fn reset(&mut self) {
        self.kernel.reset();
    }
}

/// [`EmgSynth`] with an output scratch buffer and a targets buffer.
#[wasm_bindgen]
pub struct WasmEmgSynth {
    synth: EmgSynth,
    scratch: Scratch,
    targets: Vec<f64>,
}

#[wasm_bindgen]
impl WasmEmgSynth {
    /// See [`EmgSynthConfig`]; the 64-bit seed is `seed_hi · 2³² + seed_lo`.
    #[wasm_bindgen(constructor)]
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        channels: usize,
        sample_rate: f64,
        seed_hi: u32,
        seed_lo: u32,
        amplitude_mv: f64,
        noise_floor_mv: f64,
        hum_mv: f64,
        hum_hz: f64,
        band_low_hz: f64,
        band_high_hz: f64,
        attack_ms: f64,
        release_ms: f64,
        modulation: f64,
        capacity_events: usize,
    ) -> Result<WasmEmgSynth, JsError> {
        let config = EmgSynthConfig {
            channels,
            sample_rate,
            seed: (u64::from(seed_hi) << 32) | u64::from(seed_lo),
            amplitude_mv,
            noise_floor_mv,
            hum_mv,
            hum_hz,
            band_low_hz,
            band_high_hz,
            attack_ms,
            release_ms,
            modulation,
        };
        let synth = EmgSynth::new(config).map_err(js_err)?;
        Ok(WasmEmgSynth {
            synth,
            scratch: Scratch::new(channels, capacity_events, false),
            targets: vec![0.0; channels],
        })
    }

    /// Byte address of the targets buffer (`channels` values).
    pub fn targets_ptr(&self) -> usize {
        self.targets.as_ptr() as usize
    }

    /// Applies the values in the targets buffer (clamped to 0..=1).
    pub fn apply_targets(&mut self) -> Result<(), JsError> {
        self.synth.set_targets(&self.targets).map_err(js_err)
    }

    /// Byte address of the output scratch buffer.
    pub fn output_ptr(&self) -> usize {
        self.scratch.output.as_ptr() as usize
    }

    /// Capacity of the output buffer, in events.
    pub fn capacity(&self) -> usize {
        self.scratch.capacity
    }

    /// Number of channels.
    pub fn channels(&self) -> usize {
        self.synth.channels()
    }

    /// Grows the output buffer to hold at least `events` events (moves it).
    pub fn ensure_capacity(&mut self, events: usize) {
        self.scratch.ensure(events);
    }

    /// Generates `n_events` events into the output buffer. Returns `false`
    /// (and does nothing) when `n_events` exceeds `capacity()`.
    pub fn generate(&mut self, n_events: usize) -> bool {
        let Some(n) = self.scratch.len(n_events) else {
            return false;
        };
        self.synth.generate(&mut self.scratch.output[..n]).is_ok()
    }

    /// Returns to the initial state (targets are kept).
    pub fn reset(&mut self) {
        self.synth.reset();
    }
}

/// Parses `MAV,WL,...` with one threshold per name (ignored by the features
/// that take none).
fn feature_specs(names: &str, thresholds: &[f64]) -> Result<Vec<FeatureSpec>, JsError> {
    let names: Vec<&str> = names
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect();
    if names.len() != thresholds.len() {
        return Err(JsError::new(&format!(
            "{} feature names but {} thresholds; give one threshold per feature",
            names.len(),
            thresholds.len()
        )));
    }
    names
        .iter()
        .zip(thresholds)
        .map(|(n, &t)| match Feature::parse(n) {
            Some(f) => Ok(FeatureSpec::with_threshold(f, t)),
            None => Err(JsError::new(&format!(
                "unknown feature '{n}'; expected one of {}",
                Feature::ALL.map(Feature::name).join(", ")
            ))),
        })
        .collect()
}

/// Grows `v` to `len` values (moves it) when it is shorter.
fn grow(v: &mut Vec<f64>, len: usize) {
    if v.len() < len {
        *v = vec![0.0; len];
    }
}

/// [`FeatureKernel`]: windows `[rows, channels]` in, features out.
#[wasm_bindgen]
pub struct WasmFeatureKernel {
    kernel: FeatureKernel,
    capacity: usize,
    input: Vec<f64>,
    output: Vec<f64>,
}

#[wasm_bindgen]
impl WasmFeatureKernel {
    /// `features` is a comma-separated list of abbreviations (MAV, RMS, WL, ZC,
    /// SSC, SSC_MOSAIC, VAR, IAV, DASDV, WAMP), `thresholds` one per feature.
    #[wasm_bindgen(constructor)]
    pub fn new(
        features: &str,
        thresholds: &[f64],
        rows: usize,
        channels: usize,
        capacity_windows: usize,
    ) -> Result<WasmFeatureKernel, JsError> {
        let specs = feature_specs(features, thresholds)?;
        let kernel = FeatureKernel::new(&specs, rows, channels).map_err(js_err)?;
        let mut k = WasmFeatureKernel {
            kernel,
            capacity: 0,
            input: Vec::new(),
            output: Vec::new(),
        };
        k.ensure_capacity(capacity_windows.max(1));
        Ok(k)
    }

    /// Byte address of the input buffer (`capacity × rows × channels`).
    pub fn input_ptr(&self) -> usize {
        self.input.as_ptr() as usize
    }

    /// Byte address of the output buffer (`capacity × output_width`).
    pub fn output_ptr(&self) -> usize {
        self.output.as_ptr() as usize
    }

    /// Capacity of the buffers, in windows.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Values per output event (features × channels).
    pub fn output_width(&self) -> usize {
        self.kernel.output_width()
    }

    /// Grows the buffers to hold at least `windows` windows (moves them).
    pub fn ensure_capacity(&mut self, windows: usize) {
        if windows > self.capacity {
            self.capacity = windows;
            grow(
                &mut self.input,
                windows * self.kernel.rows() * self.kernel.channels(),
            );
            grow(&mut self.output, windows * self.kernel.output_width());
        }
    }

    /// Computes the features of `n` windows. `false` when `n > capacity()`.
    pub fn process(&mut self, n: usize) -> bool {
        if n > self.capacity {
            return false;
        }
        let size = self.kernel.rows() * self.kernel.channels();
        let width = self.kernel.output_width();
        self.kernel
            .process(&self.input[..n * size], &mut self.output[..n * width])
            .is_ok()
    }
}

/// Input, window output and window-end buffers shared by the windowing wrappers.
struct WindowScratch {
    channels: usize,
    /// Values per produced window.
    width: usize,
    capacity: usize,
    input: Vec<f64>,
    output: Vec<f64>,
    /// Index of the newest event of each window, as f64 (read through the f64 heap view).
    ends: Vec<f64>,
    ends_usize: Vec<usize>,
}

impl WindowScratch {
    fn new(channels: usize, width: usize) -> Self {
        WindowScratch {
            channels,
            width,
            capacity: 0,
            input: Vec::new(),
            output: Vec::new(),
            ends: Vec::new(),
            ends_usize: Vec::new(),
        }
    }

    fn ensure(&mut self, events: usize, max_windows: usize) {
        if events > self.capacity {
            self.capacity = events;
            grow(&mut self.input, events * self.channels);
            grow(&mut self.output, max_windows * self.width);
            if self.ends.len() < max_windows {
                self.ends = vec![0.0; max_windows];
                self.ends_usize = vec![0; max_windows];
            }
        }
    }

    /// Copies the first `k` window ends into the f64 buffer; returns `k` as i32.
    fn finish(&mut self, k: usize) -> i32 {
        for (d, &e) in self.ends.iter_mut().zip(&self.ends_usize[..k]) {
            *d = e as f64;
        }
        k as i32
    }
}

/// [`SlidingWindow`]: events in, windows out. Untapered windows are not
/// copied: they are read where they lie in the window's ring
/// ([`SlidingWindow::process_in_ring`], the ring holds the latest
/// `length + capacity − 1` events); tapered windows are written into the
/// output buffer. Either way `starts_ptr()` says where each window is.
#[wasm_bindgen]
pub struct WasmSlidingWindow {
    window: SlidingWindow,
    tapered: bool,
    scratch: WindowScratch,
    /// Byte address of each window, as f64 (read through the f64 heap view).
    starts: Vec<f64>,
    starts_usize: Vec<usize>,
}

#[wasm_bindgen]
impl WasmSlidingWindow {
    /// `function` is `none`, `hann`, `hamming` or `blackman`.
    #[wasm_bindgen(constructor)]
    pub fn new(
        length: usize,
        step: usize,
        channels: usize,
        function: &str,
        capacity_events: usize,
    ) -> Result<WasmSlidingWindow, JsError> {
        let f = WindowFunction::parse(function).ok_or_else(|| {
            JsError::new(&format!(
                "unknown window function '{function}'; expected none, hann, hamming or blackman"
            ))
        })?;
        let window = SlidingWindow::new(length, step, channels, f).map_err(js_err)?;
        let tapered = f != WindowFunction::None;
        // Only tapered windows need an output buffer.
        let width = if tapered { window.window_size() } else { 0 };
        let mut w = WasmSlidingWindow {
            window,
            tapered,
            scratch: WindowScratch::new(channels, width),
            starts: Vec::new(),
            starts_usize: Vec::new(),
        };
        w.ensure_capacity(capacity_events.max(1));
        Ok(w)
    }

    /// Byte address of the input buffer (`capacity × channels`).
    pub fn input_ptr(&self) -> usize {
        self.scratch.input.as_ptr() as usize
    }

    /// Byte address of the buffer of tapered windows (`max_windows(capacity)
    /// × length × channels`; empty without a window function).
    pub fn output_ptr(&self) -> usize {
        self.scratch.output.as_ptr() as usize
    }

    /// Byte address of the window ends (f64 event indices, one per window).
    pub fn ends_ptr(&self) -> usize {
        self.scratch.ends.as_ptr() as usize
    }

    /// Byte address of the window starts (f64 byte addresses of the first
    /// value of each window, one per window; valid until the next call).
    pub fn starts_ptr(&self) -> usize {
        self.starts.as_ptr() as usize
    }

    /// Capacity of the input buffer, in events.
    pub fn capacity(&self) -> usize {
        self.scratch.capacity
    }

    /// The most windows `n_events` events can produce.
    pub fn max_windows(&self, n_events: usize) -> usize {
        self.window.max_windows(n_events)
    }

    /// Grows the buffers to hold at least `events` input events (moves them).
    pub fn ensure_capacity(&mut self, events: usize) {
        let most = self.window.max_windows(events);
        self.scratch.ensure(events, most);
        if !self.tapered {
            self.window.reserve(events);
        }
        if self.starts.len() < most {
            self.starts = vec![0.0; most];
            self.starts_usize = vec![0; most];
        }
    }

    /// Feeds `n_events` events; returns the number of windows produced, or
    /// −1 when `n_events > capacity()`.
    pub fn process(&mut self, n_events: usize) -> i32 {
        let s = &mut self.scratch;
        if n_events > s.capacity {
            return -1;
        }
        let input = &s.input[..n_events * s.channels];
        let size = self.window.window_size();
        let f64_bytes = std::mem::size_of::<f64>();
        if self.tapered {
            let Ok(k) = self.window.process(input, &mut s.output, &mut s.ends_usize) else {
                return -1;
            };
            let base = s.output.as_ptr() as usize;
            for (i, d) in self.starts.iter_mut().take(k).enumerate() {
                *d = (base + i * size * f64_bytes) as f64;
            }
            s.finish(k)
        } else {
            let Ok(k) =
                self.window
                    .process_in_ring(input, &mut self.starts_usize, &mut s.ends_usize)
            else {
                return -1;
            };
            let base = self.window.ring().as_ptr() as usize;
            for (d, &i) in self.starts.iter_mut().zip(&self.starts_usize[..k]) {
                *d = (base + i * f64_bytes) as f64;
            }
            s.finish(k)
        }
    }

    /// Forgets every event.
    pub fn reset(&mut self) {
        self.window.reset();
    }
}

/// [`WindowedFeatures`]: events in, features of every window out.
#[wasm_bindgen]
pub struct WasmWindowedFeatures {
    kernel: WindowedFeatures,
    scratch: WindowScratch,
}

#[wasm_bindgen]
impl WasmWindowedFeatures {
    /// Features (as [`WasmFeatureKernel::new`]) over windows of `length`
    /// events every `step` events.
    #[wasm_bindgen(constructor)]
    pub fn new(
        features: &str,
        thresholds: &[f64],
        length: usize,
        step: usize,
        channels: usize,
        capacity_events: usize,
    ) -> Result<WasmWindowedFeatures, JsError> {
        let specs = feature_specs(features, thresholds)?;
        let kernel = WindowedFeatures::new(&specs, length, step, channels).map_err(js_err)?;
        let width = kernel.output_width();
        let mut w = WasmWindowedFeatures {
            kernel,
            scratch: WindowScratch::new(channels, width),
        };
        w.ensure_capacity(capacity_events.max(1));
        Ok(w)
    }

    /// Byte address of the input buffer.
    pub fn input_ptr(&self) -> usize {
        self.scratch.input.as_ptr() as usize
    }

    /// Byte address of the feature buffer.
    pub fn output_ptr(&self) -> usize {
        self.scratch.output.as_ptr() as usize
    }

    /// Byte address of the window ends.
    pub fn ends_ptr(&self) -> usize {
        self.scratch.ends.as_ptr() as usize
    }

    /// Capacity of the input buffer, in events.
    pub fn capacity(&self) -> usize {
        self.scratch.capacity
    }

    /// Values per output event (features × channels).
    pub fn output_width(&self) -> usize {
        self.kernel.output_width()
    }

    /// The most windows `n_events` events can produce.
    pub fn max_windows(&self, n_events: usize) -> usize {
        self.kernel.max_windows(n_events)
    }

    /// Grows the buffers to hold at least `events` input events (moves them).
    pub fn ensure_capacity(&mut self, events: usize) {
        let most = self.kernel.max_windows(events);
        self.scratch.ensure(events, most);
    }

    /// Replaces the thresholds (one per feature, in order); the window
    /// history is kept.
    pub fn set_thresholds(&mut self, thresholds: &[f64]) -> Result<(), JsError> {
        self.kernel.set_thresholds(thresholds).map_err(js_err)
    }

    /// Feeds `n_events` events; returns the number of windows, or −1 when
    /// `n_events > capacity()`.
    pub fn process(&mut self, n_events: usize) -> i32 {
        let s = &mut self.scratch;
        if n_events > s.capacity {
            return -1;
        }
        match self.kernel.process(
            &s.input[..n_events * s.channels],
            &mut s.output,
            &mut s.ends_usize,
        ) {
            Ok(k) => s.finish(k),
            Err(_) => -1,
        }
    }

    /// Forgets every event.
    pub fn reset(&mut self) {
        self.kernel.reset();
    }
}

/// [`AdaptiveFilter`] with input, output and timestamp buffers.
#[wasm_bindgen]
pub struct WasmAdaptiveFilter {
    filter: AdaptiveFilter,
    scratch: Scratch,
    times: Vec<f64>,
}

#[wasm_bindgen]
impl WasmAdaptiveFilter {
    /// See [`AdaptiveFilterConfig`]; `order` is `paper` (LP(|ẋ|)) or `mosaic` (|LP(ẋ)|).
    #[wasm_bindgen(constructor)]
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        channels: usize,
        sample_rate: f64,
        g1: f64,
        g2: f64,
        b1: f64,
        b2: f64,
        order: &str,
        capacity_events: usize,
    ) -> Result<WasmAdaptiveFilter, JsError> {
        let order = match order {
            "paper" => DerivativeOrder::LowpassOfAbs,
            "mosaic" => DerivativeOrder::AbsOfLowpass,
            other => {
                return Err(JsError::new(&format!(
                    "unknown derivative order '{other}'; expected paper or mosaic"
                )))
            }
        };
        let cfg = AdaptiveFilterConfig {
            channels,
            sample_rate,
            g1,
            g2,
            b1,
            b2,
            order,
        };
        let filter = AdaptiveFilter::new(cfg).map_err(js_err)?;
        let scratch = Scratch::new(channels, capacity_events, true);
        let times = vec![0.0; scratch.capacity];
        Ok(WasmAdaptiveFilter {
            filter,
            scratch,
            times,
        })
    }

    /// Byte address of the input scratch buffer.
    pub fn input_ptr(&self) -> usize {
        self.scratch.input.as_ptr() as usize
    }

    /// Byte address of the output scratch buffer.
    pub fn output_ptr(&self) -> usize {
        self.scratch.output.as_ptr() as usize
    }

    /// Byte address of the timestamp buffer (one per event).
    pub fn times_ptr(&self) -> usize {
        self.times.as_ptr() as usize
    }

    /// Byte address of the cut-off of each channel at the last sample.
    pub fn cutoff_ptr(&self) -> usize {
        self.filter.cutoff().as_ptr() as usize
    }

    /// Capacity of the scratch buffers, in events.
    pub fn capacity(&self) -> usize {
        self.scratch.capacity
    }

    /// Grows the scratch buffers to hold at least `events` events (moves them).
    pub fn ensure_capacity(&mut self, events: usize) {
        self.scratch.ensure(events);
        grow(&mut self.times, self.scratch.capacity);
    }

    /// Changes G1, G2, B1 and B2 (the state is kept).
    pub fn set_gains(&mut self, g1: f64, g2: f64, b1: f64, b2: f64) -> Result<(), JsError> {
        self.filter.set_gains(g1, g2, b1, b2).map_err(js_err)
    }

    /// Filters `n_events` events with the nominal step. `false` when
    /// `n_events > capacity()`.
    pub fn process(&mut self, n_events: usize) -> bool {
        let Some(n) = self.scratch.len(n_events) else {
            return false;
        };
        self.filter
            .process(&self.scratch.input[..n], &mut self.scratch.output[..n])
            .is_ok()
    }

    /// Filters `n_events` events with ΔT from the timestamp buffer.
    pub fn process_timed(&mut self, n_events: usize) -> bool {
        let Some(n) = self.scratch.len(n_events) else {
            return false;
        };
        self.filter
            .process_timed(
                &self.scratch.input[..n],
                &self.times[..n_events],
                &mut self.scratch.output[..n],
            )
            .is_ok()
    }

    /// Back to the zero initial state.
    pub fn reset(&mut self) {
        self.filter.reset();
    }
}

/// [`ArtifactRejector`] with window, clean, mask and flag buffers.
#[wasm_bindgen]
pub struct WasmArtifactRejector {
    rejector: ArtifactRejector,
    capacity: usize,
    input: Vec<f64>,
    clean: Vec<f64>,
    mask: Vec<f64>,
    flags: Vec<f64>,
}

#[wasm_bindgen]
impl WasmArtifactRejector {
    /// See [`ArtifactConfig`]; a NaN rail means auto, a NaN drift threshold
    /// disables the drift test.
    #[wasm_bindgen(constructor)]
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        rows: usize,
        channels: usize,
        rail_low: f64,
        rail_high: f64,
        clip_tolerance: f64,
        clip_fraction: f64,
        flat_threshold: f64,
        jump_factor: f64,
        drift_threshold: f64,
        hard: bool,
        capacity_windows: usize,
    ) -> Result<WasmArtifactRejector, JsError> {
        let some = |v: f64| (!v.is_nan()).then_some(v);
        let cfg = ArtifactConfig {
            rows,
            channels,
            rail_low: some(rail_low),
            rail_high: some(rail_high),
            clip_tolerance,
            clip_fraction,
            flat_threshold,
            jump_factor,
            drift_threshold: some(drift_threshold),
            hard,
        };
        let rejector = ArtifactRejector::new(cfg).map_err(js_err)?;
        let mut r = WasmArtifactRejector {
            rejector,
            capacity: 0,
            input: Vec::new(),
            clean: Vec::new(),
            mask: Vec::new(),
            flags: Vec::new(),
        };
        r.ensure_capacity(capacity_windows.max(1));
        Ok(r)
    }

    /// Byte address of the window buffer (`capacity × rows × channels`).
    pub fn input_ptr(&self) -> usize {
        self.input.as_ptr() as usize
    }

    /// Byte address of the clean windows (same size as the input).
    pub fn clean_ptr(&self) -> usize {
        self.clean.as_ptr() as usize
    }

    /// Byte address of the masks (`capacity × channels`).
    pub fn mask_ptr(&self) -> usize {
        self.mask.as_ptr() as usize
    }

    /// Byte address of the reason flags (`capacity × channels`).
    pub fn flags_ptr(&self) -> usize {
        self.flags.as_ptr() as usize
    }

    /// Byte address of the counters (`channels × ARTIFACT_COUNTERS`).
    pub fn counters_ptr(&self) -> usize {
        self.rejector.counters().as_ptr() as usize
    }

    /// Counters per channel (one per reason, then the rejected total).
    pub fn counters_per_channel(&self) -> usize {
        ARTIFACT_COUNTERS
    }

    /// Windows judged since the counters were last reset.
    pub fn windows(&self) -> f64 {
        self.rejector.windows() as f64
    }

    /// Capacity of the buffers, in windows.
    pub fn capacity(&self) -> usize {
        self.capacity
    }

    /// Grows the buffers to hold at least `windows` windows (moves them).
    pub fn ensure_capacity(&mut self, windows: usize) {
        if windows > self.capacity {
            self.capacity = windows;
            let size = self.rejector.window_size();
            let c = self.rejector.channels();
            grow(&mut self.input, windows * size);
            grow(&mut self.clean, windows * size);
            grow(&mut self.mask, windows * c);
            grow(&mut self.flags, windows * c);
        }
    }

    /// Judges `n` windows. `false` when `n > capacity()`.
    pub fn process(&mut self, n: usize) -> bool {
        if n > self.capacity {
            return false;
        }
        let size = self.rejector.window_size();
        let c = self.rejector.channels();
        self.rejector
            .process(
                &self.input[..n * size],
                &mut self.clean[..n * size],
                &mut self.mask[..n * c],
                &mut self.flags[..n * c],
            )
            .is_ok()
    }

    /// Zeroes the counters (the auto rails are kept).
    pub fn reset_counters(&mut self) {
        self.rejector.reset_counters();
    }

    /// Back to the initial state (counters and auto rails).
    pub fn reset(&mut self) {
        self.rejector.reset();
    }
}
