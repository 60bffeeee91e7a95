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
//! The names of the exports are a contract with `app/engine/dsp/index.ts`.
#![warn(missing_docs)]

use mosaic_dsp::{EmgSynth, EmgSynthConfig, FilterBank, FunctionKernel, FunctionOp};
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
