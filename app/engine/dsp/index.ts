/**
 * TypeScript face of the Rust DSP core (core-wasm/, built by `npm run build:wasm`).
 *
 * Runs anywhere the engine runs (Node worker_threads, browser Web Workers): no `node:` imports,
 * no DOM, no console. Call `initDsp(bytes)` once per thread with the bytes of
 * `core-wasm/pkg/mosaic_core_bg.wasm` (or a compiled `WebAssembly.Module`), then create kernels.
 *
 * Buffers are row-major interleaved: event `e`, channel `c` is at index `e * channels + c`; a
 * window `[L, C]` (SlidingWindow's event) is `L` such rows, oldest first.
 * Arrays may be longer than `nEvents * channels` (frames have a capacity); only the first
 * `nEvents * channels` values are read or written.
 *
 * Hot path: every kernel owns scratch buffers inside the wasm memory. `process` copies the input
 * into the input scratch through a cached `Float64Array` view of the memory, runs the kernel and
 * copies the output scratch out. Nothing is allocated per call in steady state; capacity grows
 * (doubling) only when a call brings more events than ever before. The view is re-created when
 * the wasm memory grows (its old buffer is then detached and reads as length 0).
 */

import {
  initSync,
  set_simd_enabled,
  version,
  wasm_memory,
  WasmAdaptiveFilter,
  WasmArtifactRejector,
  WasmEmgSynth,
  WasmFeatureKernel,
  WasmFilterBank,
  WasmFunctionKernel,
  WasmSlidingWindow,
  WasmWindowedFeatures,
} from "../../../core-wasm/pkg/mosaic_core.js";
import {
  asError,
  checkCall,
  checkChannels,
  disposed,
  errorMessage,
  failed,
  grownCapacity,
  HeapBlocks,
  INITIAL_CAPACITY,
  memoryReady,
  requireReady,
  Scratch,
  setMemory,
  type WasmMemoryLike,
} from "./memory";

export * from "./learn";

/**
 * A compiled `WebAssembly.Module`. Typed opaquely because the engine layer is type-checked
 * without the DOM and webworker libraries, which are the ones that declare `WebAssembly`.
 */
export type WasmModuleLike = object;

/** What `initDsp` accepts: the `.wasm` bytes (`BufferSource`) or a compiled module. */
export type DspWasmSource = ArrayBuffer | ArrayBufferView | WasmModuleLike;

/**
 * Instantiates the DSP module synchronously (the `--target web` glue's `initSync`). Call once per
 * thread before creating any kernel; later calls do nothing.
 */
export function initDsp(wasmBytes: DspWasmSource): void {
  if (memoryReady()) return;
  try {
    initSync({ module: wasmBytes });
  } catch (e) {
    throw new Error(
      `initDsp: cannot instantiate the DSP module (${errorMessage(e)}); pass the bytes of ` +
        "core-wasm/pkg/mosaic_core_bg.wasm or a compiled WebAssembly.Module, and rebuild it " +
        "with `npm run build:wasm` if it is missing or stale",
      { cause: e },
    );
  }
  setMemory(wasm_memory() as WasmMemoryLike);
}

/** `true` once `initDsp` has succeeded in this thread. */
export function dspReady(): boolean {
  return memoryReady();
}

/**
 * Chooses the kernels' SIMD128 paths (`true`, the default) or their scalar code (`false`) from
 * now on; the two give the same bits (for tests that check it). Returns whether the module has
 * SIMD paths at all (`scripts/build-wasm.sh` builds it with `+simd128`).
 */
export function setSimdEnabled(enabled: boolean): boolean {
  requireReady("setSimdEnabled()");
  return set_simd_enabled(enabled);
}

/** Version of the Rust core (`mosaic-core-wasm` crate). */
export function dspVersion(): string {
  requireReady("dspVersion()");
  return version();
}

/**
 * The MOSAIC Filter block's kernel: the difference equation (paper eq. 1) applied to every
 * channel independently, in direct form I. Coefficients are divided by `denominator[0]` (as
 * `scipy.signal.lfilter`); `denominator = [1]` gives an FIR filter. Initial state is zero.
 */
export class FilterBank {
  readonly channels: number;
  private inner: WasmFilterBank | null;
  private capacity = 0;
  private readonly input = new Scratch();
  private readonly output = new Scratch();

  constructor(numerator: readonly number[], denominator: readonly number[], channels: number) {
    requireReady("FilterBank");
    checkChannels("FilterBank", channels);
    try {
      this.inner = new WasmFilterBank(
        Float64Array.from(numerator),
        Float64Array.from(denominator),
        channels,
        INITIAL_CAPACITY,
      );
    } catch (e) {
      throw asError(e);
    }
    this.channels = channels;
    this.locate();
  }

  private locate(): void {
    const k = this.inner as WasmFilterBank;
    this.capacity = k.capacity();
    const len = this.capacity * this.channels;
    this.input.place(k.input_ptr(), len);
    this.output.place(k.output_ptr(), len);
  }

  /**
   * Filters `nEvents` events of `input` into `output` (`nEvents * channels` values from index 0).
   * `output` may be the same array as `input`.
   */
  process(input: Float64Array, output: Float64Array, nEvents: number): void {
    const k = this.inner;
    if (k === null) throw disposed("FilterBank");
    const c = this.channels;
    checkCall("FilterBank.process", nEvents, c, input, output);
    if (nEvents > this.capacity) {
      k.ensure_capacity(grownCapacity(this.capacity, nEvents));
      this.locate();
    }
    const n = nEvents * c;
    this.input.write(input, n);
    if (!k.process(nEvents)) throw failed("FilterBank.process");
    this.output.read(output, n);
  }

  /** Clears the filter history (back to the zero initial state). */
  reset(): void {
    if (this.inner === null) throw disposed("FilterBank");
    this.inner.reset();
  }

  /** Frees the wasm memory of this bank. Further calls throw. Calling it twice is harmless. */
  dispose(): void {
    this.inner?.free();
    this.inner = null;
  }
}

/** The operations of the MOSAIC Function block (paper Table 1). */
export type FunctionOperation = "add" | "multiply" | "abs" | "power" | "clip";

export interface FunctionKernelOptions {
  /** add / multiply: 1 value (every channel) or one value per channel. */
  operand?: readonly number[];
  /** power: the exponent (integers up to ±64 are exact products; 0.5 is sqrt; else `pow`). */
  exponent?: number;
  /** clip: lower bound (default −∞). */
  min?: number;
  /** clip: upper bound (default +∞). */
  max?: number;
}

const OPERATIONS: readonly FunctionOperation[] = ["add", "multiply", "abs", "power", "clip"];

/**
 * The MOSAIC Function block's kernel: an element-wise operation. As in NumPy, a negative base
 * with a non-integer exponent gives NaN and NaN passes through `clip`.
 */
export class FunctionKernel {
  readonly channels: number;
  readonly op: FunctionOperation;
  private inner: WasmFunctionKernel | null;
  private readonly takesOperand: boolean;
  private capacity = 0;
  private readonly input = new Scratch();
  private readonly output = new Scratch();
  private readonly operand = new Scratch();

  constructor(op: FunctionOperation, options: FunctionKernelOptions, channels: number) {
    requireReady("FunctionKernel");
    checkChannels("FunctionKernel", channels);
    if (!OPERATIONS.includes(op)) {
      throw new Error(
        `FunctionKernel: unknown operation '${String(op)}'; expected one of ${OPERATIONS.join(", ")}`,
      );
    }
    if ((op === "add" || op === "multiply") && options.operand === undefined) {
      throw new Error(
        `FunctionKernel '${op}' needs options.operand (1 value, or one value per channel)`,
      );
    }
    if (op === "power" && options.exponent === undefined) {
      throw new Error("FunctionKernel 'power' needs options.exponent");
    }
    try {
      this.inner = new WasmFunctionKernel(
        op,
        Float64Array.from(options.operand ?? []),
        options.exponent ?? Number.NaN,
        options.min ?? -Infinity,
        options.max ?? Infinity,
        channels,
        INITIAL_CAPACITY,
      );
    } catch (e) {
      throw asError(e);
    }
    this.op = op;
    this.channels = channels;
    this.takesOperand = this.inner.takes_operand();
    this.locate();
  }

  private locate(): void {
    const k = this.inner as WasmFunctionKernel;
    this.capacity = k.capacity();
    const len = this.capacity * this.channels;
    this.input.place(k.input_ptr(), len);
    this.output.place(k.output_ptr(), len);
    this.operand.place(k.operand_ptr(), this.channels);
  }

  private prepare(
    what: string,
    nEvents: number,
    input: Float64Array,
    output: Float64Array,
  ): WasmFunctionKernel {
    const k = this.inner;
    if (k === null) throw disposed("FunctionKernel");
    checkCall(what, nEvents, this.channels, input, output);
    if (nEvents > this.capacity) {
      k.ensure_capacity(grownCapacity(this.capacity, nEvents));
      this.locate();
    }
    return k;
  }

  /** Applies the operation with its constant operand. `output` may be `input`. */
  process(input: Float64Array, output: Float64Array, nEvents: number): void {
    const k = this.prepare("FunctionKernel.process", nEvents, input, output);
    const n = nEvents * this.channels;
    this.input.write(input, n);
    if (!k.process(nEvents)) throw failed("FunctionKernel.process");
    this.output.read(output, n);
  }

  /**
   * add / multiply with an operand from another stream: `operand` holds `channels` values,
   * applied to every event of this call.
   */
  processWithOperand(
    input: Float64Array,
    operand: Float64Array,
    output: Float64Array,
    nEvents: number,
  ): void {
    if (!this.takesOperand) {
      throw new Error(
        `FunctionKernel: operation '${this.op}' takes no operand; only 'add' and 'multiply' do ` +
          "(call process instead)",
      );
    }
    const c = this.channels;
    if (operand.length < c) {
      throw new Error(
        `FunctionKernel.processWithOperand: operand has ${operand.length} values; expected ` +
          `${c} (one per channel)`,
      );
    }
    const k = this.prepare("FunctionKernel.processWithOperand", nEvents, input, output);
    const n = nEvents * c;
    this.input.write(input, n);
    this.operand.write(operand, c);
    if (!k.process_with_operand(nEvents)) throw failed("FunctionKernel.processWithOperand");
    this.output.read(output, n);
  }

  /** Does nothing (the operation has no state); present for a uniform kernel interface. */
  reset(): void {
    if (this.inner === null) throw disposed("FunctionKernel");
    this.inner.reset();
  }

  /** Frees the wasm memory of this kernel. Further calls throw. */
  dispose(): void {
    this.inner?.free();
    this.inner = null;
  }
}

/** Configuration of an `EmgSynth`; omitted fields take the values of `EMG_SYNTH_DEFAULTS`. */
export interface EmgSynthConfig {
  channels: number;
  /** Hz. */
  sampleRate: number;
  /** Integer from 0 to 2^53 − 1 (passed to Rust as a 64-bit seed). */
  seed: number;
  /** RMS of the EMG at full activation, mV. */
  amplitudeMv?: number;
  /** RMS of the white background noise, mV. */
  noiseFloorMv?: number;
  /** Amplitude of the powerline interference, mV. */
  humMv?: number;
  /** Powerline frequency, Hz. */
  humHz?: number;
  /** High-pass corner of the EMG band, Hz (0: none). */
  bandLowHz?: number;
  /** Low-pass corner of the EMG band, Hz (clamped to 0.45 × sampleRate). */
  bandHighHz?: number;
  /** Envelope time constant when the activation rises, ms. */
  attackMs?: number;
  /** Envelope time constant when the activation falls, ms. */
  releaseMs?: number;
  /** Relative depth of the slow 1–3 Hz amplitude fluctuation, 0..1. */
  modulation?: number;
}

/** Defaults of the optional `EmgSynthConfig` fields (same as Rust `EmgSynthConfig::new`). */
export const EMG_SYNTH_DEFAULTS = {
  amplitudeMv: 0.5,
  noiseFloorMv: 0.01,
  humMv: 0.02,
  humHz: 50,
  bandLowHz: 20,
  bandHighHz: 450,
  attackMs: 60,
  releaseMs: 150,
  modulation: 0.1,
} as const;

/**
 * Seeded multi-channel surface-EMG generator (the EmgSimulator block's kernel): band-limited
 * Gaussian noise shaped by an attack/release envelope that follows per-channel target
 * activations, plus a noise floor and powerline hum. Same seed, same output.
 */
export class EmgSynth {
  readonly channels: number;
  private inner: WasmEmgSynth | null;
  private capacity = 0;
  private readonly output = new Scratch();
  private readonly targets = new Scratch();

  constructor(config: EmgSynthConfig) {
    requireReady("EmgSynth");
    checkChannels("EmgSynth", config.channels);
    const seed = config.seed;
    if (!Number.isSafeInteger(seed) || seed < 0) {
      throw new Error(`EmgSynth: seed must be an integer from 0 to 2^53 - 1; got ${seed}`);
    }
    const c = { ...EMG_SYNTH_DEFAULTS, ...config };
    try {
      this.inner = new WasmEmgSynth(
        c.channels,
        c.sampleRate,
        Math.floor(seed / 0x1_0000_0000),
        seed % 0x1_0000_0000,
        c.amplitudeMv,
        c.noiseFloorMv,
        c.humMv,
        c.humHz,
        c.bandLowHz,
        c.bandHighHz,
        c.attackMs,
        c.releaseMs,
        c.modulation,
        INITIAL_CAPACITY,
      );
    } catch (e) {
      throw asError(e);
    }
    this.channels = config.channels;
    this.locate();
  }

  private locate(): void {
    const k = this.inner as WasmEmgSynth;
    this.capacity = k.capacity();
    this.output.place(k.output_ptr(), this.capacity * this.channels);
    this.targets.place(k.targets_ptr(), this.channels);
  }

  /** Target activation per channel (`channels` values, clamped to 0..1; NaN is an error). */
  setTargets(targets: ArrayLike<number>): void {
    const k = this.inner;
    if (k === null) throw disposed("EmgSynth");
    const c = this.channels;
    if (targets.length !== c) {
      throw new Error(
        `EmgSynth.setTargets: got ${targets.length} values; expected ${c} (one per channel)`,
      );
    }
    this.targets.write(targets, c);
    try {
      k.apply_targets();
    } catch (e) {
      throw asError(e);
    }
  }

  /** Writes `nEvents` events (`nEvents * channels` values from index 0) into `output`. */
  generate(output: Float64Array, nEvents: number): void {
    const k = this.inner;
    if (k === null) throw disposed("EmgSynth");
    checkCall("EmgSynth.generate", nEvents, this.channels, output, null);
    if (nEvents > this.capacity) {
      k.ensure_capacity(grownCapacity(this.capacity, nEvents));
      this.locate();
    }
    if (!k.generate(nEvents)) throw failed("EmgSynth.generate");
    this.output.read(output, nEvents * this.channels);
  }

  /** Back to the initial state (time 0, same random streams); the targets are kept. */
  reset(): void {
    if (this.inner === null) throw disposed("EmgSynth");
    this.inner.reset();
  }

  /** Frees the wasm memory of this generator. Further calls throw. */
  dispose(): void {
    this.inner?.free();
    this.inner = null;
  }
}

// ------------------------------------------------------------------------------------------------
// Windows, features, adaptive filter, artifact rejection (issue 3)

/** Time-domain EMG features (LibEMG abbreviations); see `FeatureKernel`. */
export type FeatureName =
  "MAV" | "RMS" | "WL" | "ZC" | "SSC" | "SSC_MOSAIC" | "VAR" | "IAV" | "DASDV" | "WAMP";

export const FEATURE_NAMES: readonly FeatureName[] = [
  "MAV",
  "RMS",
  "WL",
  "ZC",
  "SSC",
  "SSC_MOSAIC",
  "VAR",
  "IAV",
  "DASDV",
  "WAMP",
];

/** A feature to compute; `threshold` is used by ZC, SSC, SSC_MOSAIC and WAMP (default 0). */
export interface FeatureRequest {
  feature: FeatureName;
  threshold?: number;
}

function featureArgs(what: string, features: readonly FeatureRequest[]): [string, Float64Array] {
  if (features.length === 0) throw new Error(`${what}: give at least one feature`);
  for (const f of features) {
    if (!FEATURE_NAMES.includes(f.feature)) {
      throw new Error(
        `${what}: unknown feature '${String(f.feature)}'; expected one of ${FEATURE_NAMES.join(", ")}`,
      );
    }
  }
  return [
    features.map((f) => f.feature).join(","),
    Float64Array.from(features, (f) => f.threshold ?? 0),
  ];
}

function checkWhole(what: string, name: string, v: number, min: number): void {
  if (!Number.isInteger(v) || v < min) {
    throw new Error(`${what}: ${name} must be an integer of at least ${min}; got ${v}`);
  }
}

/**
 * Time-domain EMG features of windows `[rows, channels]` (Hudgins et al. 1993; Phinyomark,
 * Phukpattaranont & Limsakul 2012), any subset computed in one pass over each window:
 * MAV = mean|x|, RMS = √mean(x²), WL = Σ|Δx|, ZC = #{x_i·x_{i+1} < 0 and |Δx| ≥ T},
 * SSC = #{(x_i − x_{i−1})(x_i − x_{i+1}) ≥ T}, SSC_MOSAIC (MOSAIC 1's rule: strict slope sign
 * change, both |Δx| ≥ T), VAR = Σx²/(N−1), IAV = Σ|x|, DASDV = √(Σ(Δx)²/(N−1)),
 * WAMP = #{|Δx| ≥ T}. The output of one window is `features × channels` values, feature-major.
 */
export class FeatureKernel {
  readonly rows: number;
  readonly channels: number;
  /** Values per output event: features × channels. */
  readonly width: number;
  private inner: WasmFeatureKernel | null;
  private capacity = 0;
  private readonly input = new Scratch();
  private readonly output = new Scratch();

  constructor(features: readonly FeatureRequest[], rows: number, channels: number) {
    requireReady("FeatureKernel");
    checkChannels("FeatureKernel", channels);
    checkWhole("FeatureKernel", "rows", rows, 2);
    const [names, thresholds] = featureArgs("FeatureKernel", features);
    try {
      this.inner = new WasmFeatureKernel(names, thresholds, rows, channels, 4);
    } catch (e) {
      throw asError(e);
    }
    this.rows = rows;
    this.channels = channels;
    this.width = this.inner.output_width();
    this.locate();
  }

  private locate(): void {
    const k = this.inner as WasmFeatureKernel;
    this.capacity = k.capacity();
    this.input.place(k.input_ptr(), this.capacity * this.rows * this.channels);
    this.output.place(k.output_ptr(), this.capacity * this.width);
  }

  /**
   * Features of `nWindows` windows: `windows` holds `nWindows × rows × channels` values from index
   * 0, `output` receives `nWindows × width`.
   */
  process(windows: Float64Array, output: Float64Array, nWindows: number): void {
    const k = this.inner;
    if (k === null) throw disposed("FeatureKernel");
    const size = this.rows * this.channels;
    if (!(Number.isInteger(nWindows) && nWindows >= 0)) {
      throw new Error(
        `FeatureKernel.process: nWindows must be a non-negative integer; got ${nWindows}`,
      );
    }
    if (windows.length < nWindows * size || output.length < nWindows * this.width) {
      throw new Error(
        `FeatureKernel.process: ${nWindows} windows need ${nWindows * size} input and ` +
          `${nWindows * this.width} output values; got ${windows.length} and ${output.length}`,
      );
    }
    if (nWindows > this.capacity) {
      k.ensure_capacity(grownCapacity(this.capacity, nWindows));
      this.locate();
    }
    this.input.write(windows, nWindows * size);
    if (!k.process(nWindows)) throw failed("FeatureKernel.process");
    this.output.read(output, nWindows * this.width);
  }

  /** Does nothing (stateless); present for a uniform kernel interface. */
  reset(): void {
    if (this.inner === null) throw disposed("FeatureKernel");
  }

  dispose(): void {
    this.inner?.free();
    this.inner = null;
  }
}

/** SlidingWindow's window functions (symmetric, as `scipy.signal.get_window(name, L, fftbins=False)`). */
export type WindowFunctionName = "none" | "hann" | "hamming" | "blackman";

/** Shared plumbing of the two windowing kernels: input, outputs per window, window ends. */
interface WindowingInner {
  input_ptr(): number;
  output_ptr(): number;
  ends_ptr(): number;
  /** Byte address of each produced event (f64), when they are not all in the output buffer. */
  starts_ptr?(): number;
  capacity(): number;
  max_windows(n: number): number;
  ensure_capacity(n: number): void;
  process(n: number): number;
  reset(): void;
  free(): void;
}

abstract class Windowing {
  readonly channels: number;
  /** Values per produced event. */
  readonly width: number;
  protected inner: WindowingInner | null;
  private capacity = 0;
  private readonly input = new Scratch();
  private readonly output = new Scratch();
  private readonly ends = new Scratch();
  /** Where each produced event lies, when the kernel says (`starts_ptr`); else in `output`. */
  private readonly starts: Scratch | null;
  private readonly blocks: HeapBlocks | null;
  private produced = 0;

  protected constructor(
    private readonly what: string,
    inner: WindowingInner,
    channels: number,
    width: number,
  ) {
    this.inner = inner;
    this.channels = channels;
    this.width = width;
    const located = inner.starts_ptr !== undefined;
    this.starts = located ? new Scratch() : null;
    this.blocks = located ? new HeapBlocks(width) : null;
    this.locate();
  }

  private locate(): void {
    const k = this.inner as WindowingInner;
    this.capacity = k.capacity();
    const most = k.max_windows(this.capacity);
    this.input.place(k.input_ptr(), this.capacity * this.channels);
    this.output.place(k.output_ptr(), most * this.width);
    this.ends.place(k.ends_ptr(), most);
    if (k.starts_ptr !== undefined) this.starts?.place(k.starts_ptr(), most);
  }

  /** The most events one call of `nEvents` input events can produce. */
  maxWindows(nEvents: number): number {
    const k = this.inner;
    if (k === null) throw disposed(this.what);
    return k.max_windows(nEvents);
  }

  /**
   * Feeds `nEvents` events of `input` (`nEvents × channels` values from index 0) and returns the
   * number of windows they completed; read them with `read` and `end` before the next call.
   */
  push(input: Float64Array, nEvents: number): number {
    const k = this.inner;
    if (k === null) throw disposed(this.what);
    checkCall(`${this.what}.push`, nEvents, this.channels, input, null);
    if (nEvents > this.capacity) {
      k.ensure_capacity(grownCapacity(this.capacity, nEvents));
      this.locate();
    }
    this.input.write(input, nEvents * this.channels);
    const n = k.process(nEvents);
    if (n < 0) throw failed(`${this.what}.push`);
    this.produced = n;
    return n;
  }

  /** Copies the `k` events produced by the last `push` into `output` (`k × width` values). */
  read(output: Float64Array, k: number): void {
    if (this.inner === null) throw disposed(this.what);
    if (k > this.produced || output.length < k * this.width) {
      throw new Error(
        `${this.what}.read: asked for ${k} of ${this.produced} events into ${output.length} values`,
      );
    }
    const blocks = this.blocks;
    if (blocks === null) {
      this.output.read(output, k * this.width);
      return;
    }
    // Each event where the kernel says it lies (e.g. a window in its ring).
    const starts = this.starts as Scratch;
    const width = this.width;
    for (let i = 0; i < k; i++) blocks.copy(starts.get(i), output, i * width);
  }

  /** Index (within the last `push`) of the newest input event of produced event `i`. */
  end(i: number): number {
    if (this.inner === null) throw disposed(this.what);
    return this.ends.get(i);
  }

  /** Forgets every event. */
  reset(): void {
    const k = this.inner;
    if (k === null) throw disposed(this.what);
    k.reset();
    this.produced = 0;
  }

  dispose(): void {
    this.inner?.free();
    this.inner = null;
  }
}

/** Events a windowing kernel's buffers hold before the first call that needs more. */
const WINDOWING_CAPACITY = 8;

/**
 * The SlidingWindow block's kernel: windows of `length` events (rows, oldest first) every `step`
 * events once `length` have arrived, multiplied by the window function. A double-written ring
 * keeps the latest events contiguous: nothing moves per event. Untapered windows are copied once,
 * from where they lie in the ring straight into the caller's array (the ring holds
 * `length + capacity − 1` events, so every window of a call is still whole after it); tapered
 * ones are written by the kernel, then copied.
 */
export class SlidingWindowKernel extends Windowing {
  readonly length: number;
  readonly step: number;

  constructor(length: number, step: number, channels: number, fn: WindowFunctionName = "none") {
    requireReady("SlidingWindowKernel");
    checkChannels("SlidingWindowKernel", channels);
    checkWhole("SlidingWindowKernel", "length", length, 1);
    checkWhole("SlidingWindowKernel", "step", step, 1);
    let inner: WasmSlidingWindow;
    try {
      inner = new WasmSlidingWindow(length, step, channels, fn, WINDOWING_CAPACITY);
    } catch (e) {
      throw asError(e);
    }
    super("SlidingWindowKernel", inner, channels, length * channels);
    this.length = length;
    this.step = step;
  }
}

/**
 * Features (as `FeatureKernel`) over a sliding window of a plain event stream: every `step`
 * events, over the last `length` events, read straight from the ring (no copy).
 */
export class WindowedFeatureKernel extends Windowing {
  readonly length: number;
  readonly step: number;
  private readonly features: readonly FeatureRequest["feature"][];

  constructor(features: readonly FeatureRequest[], length: number, step: number, channels: number) {
    requireReady("WindowedFeatureKernel");
    checkChannels("WindowedFeatureKernel", channels);
    checkWhole("WindowedFeatureKernel", "length", length, 2);
    checkWhole("WindowedFeatureKernel", "step", step, 1);
    const [names, thresholds] = featureArgs("WindowedFeatureKernel", features);
    let inner: WasmWindowedFeatures;
    try {
      inner = new WasmWindowedFeatures(
        names,
        thresholds,
        length,
        step,
        channels,
        WINDOWING_CAPACITY,
      );
    } catch (e) {
      throw asError(e);
    }
    super("WindowedFeatureKernel", inner, channels, inner.output_width());
    this.length = length;
    this.step = step;
    this.features = features.map((f) => f.feature);
  }

  /**
   * Replaces the thresholds; `features` must name the same features in the same order as at
   * construction. The window history is kept.
   */
  setThresholds(features: readonly FeatureRequest[]): void {
    const k = this.inner as WasmWindowedFeatures | null;
    if (k === null) throw disposed("WindowedFeatureKernel");
    if (
      features.length !== this.features.length ||
      features.some((f, i) => f.feature !== this.features[i])
    ) {
      throw new Error(
        `WindowedFeatureKernel.setThresholds: expected the features ${this.features.join(", ")}`,
      );
    }
    try {
      k.set_thresholds(Float64Array.from(features, (f) => f.threshold ?? 0));
    } catch (e) {
      throw asError(e);
    }
  }
}

/** Where eq. 4 of the AdaptiveFilter takes |·|: `paper` LP(|ẋ|), `mosaic` |LP(ẋ)| (MOSAIC 1's code). */
export type DerivativeOrderName = "paper" | "mosaic";

export interface AdaptiveFilterOptions {
  channels: number;
  /** Nominal sampling rate (Hz): ΔT = 1 / sampleRate. */
  sampleRate: number;
  g1: number;
  g2: number;
  /** Cut-off (Hz) of the derivative's first-order low-pass. */
  b1: number;
  b2: number;
  order?: DerivativeOrderName;
}

/**
 * The AdaptiveFilter block's kernel (paper III-F, eqs. 2–4), per channel:
 * F_c = exp(G2·|x| + G1·LP(|ẋ|, B1) + B2), α = 2πF_cΔT/(1 + 2πF_cΔT), y = αx + (1 − α)y[n−1].
 */
export class AdaptiveFilterKernel {
  readonly channels: number;
  private inner: WasmAdaptiveFilter | null;
  private capacity = 0;
  private readonly input = new Scratch();
  private readonly output = new Scratch();
  private readonly times = new Scratch();
  private readonly cutoffs = new Scratch();

  constructor(o: AdaptiveFilterOptions) {
    requireReady("AdaptiveFilterKernel");
    checkChannels("AdaptiveFilterKernel", o.channels);
    try {
      this.inner = new WasmAdaptiveFilter(
        o.channels,
        o.sampleRate,
        o.g1,
        o.g2,
        o.b1,
        o.b2,
        o.order ?? "paper",
        INITIAL_CAPACITY,
      );
    } catch (e) {
      throw asError(e);
    }
    this.channels = o.channels;
    this.locate();
  }

  private locate(): void {
    const k = this.inner as WasmAdaptiveFilter;
    this.capacity = k.capacity();
    this.input.place(k.input_ptr(), this.capacity * this.channels);
    this.output.place(k.output_ptr(), this.capacity * this.channels);
    this.times.place(k.times_ptr(), this.capacity);
    this.cutoffs.place(k.cutoff_ptr(), this.channels);
  }

  private prepare(what: string, nEvents: number, input: Float64Array, output: Float64Array) {
    const k = this.inner;
    if (k === null) throw disposed("AdaptiveFilterKernel");
    checkCall(what, nEvents, this.channels, input, output);
    if (nEvents > this.capacity) {
      k.ensure_capacity(grownCapacity(this.capacity, nEvents));
      this.locate();
    }
    this.input.write(input, nEvents * this.channels);
    return k;
  }

  /** Filters `nEvents` events with the nominal ΔT. `output` may be `input`. */
  process(input: Float64Array, output: Float64Array, nEvents: number): void {
    const k = this.prepare("AdaptiveFilterKernel.process", nEvents, input, output);
    if (!k.process(nEvents)) throw failed("AdaptiveFilterKernel.process");
    this.output.read(output, nEvents * this.channels);
  }

  /**
   * Filters with ΔT = t[n] − t[n−1] from `times` (seconds, one per event); the first event and
   * repeated or decreasing timestamps use the nominal ΔT.
   */
  processTimed(
    input: Float64Array,
    times: Float64Array,
    output: Float64Array,
    nEvents: number,
  ): void {
    if (times.length < nEvents) {
      throw new Error(
        `AdaptiveFilterKernel.processTimed: ${nEvents} events need ${nEvents} timestamps; got ${times.length}`,
      );
    }
    const k = this.prepare("AdaptiveFilterKernel.processTimed", nEvents, input, output);
    this.times.write(times, nEvents);
    if (!k.process_timed(nEvents)) throw failed("AdaptiveFilterKernel.processTimed");
    this.output.read(output, nEvents * this.channels);
  }

  /** Changes G1, G2, B1 and B2 while running; the filter state is kept. */
  setGains(g1: number, g2: number, b1: number, b2: number): void {
    if (this.inner === null) throw disposed("AdaptiveFilterKernel");
    try {
      this.inner.set_gains(g1, g2, b1, b2);
    } catch (e) {
      throw asError(e);
    }
  }

  /** The cut-off frequency (Hz) of channel `c` at the last sample (0 before any). */
  cutoff(c: number): number {
    if (this.inner === null) throw disposed("AdaptiveFilterKernel");
    return this.cutoffs.get(c);
  }

  reset(): void {
    if (this.inner === null) throw disposed("AdaptiveFilterKernel");
    this.inner.reset();
  }

  dispose(): void {
    this.inner?.free();
    this.inner = null;
  }
}

/** Reasons of the artifact kernel, in flag-bit order (bit `1 << i`). */
export const ARTIFACT_REASONS = ["clipping", "flat", "jump", "drift", "nonfinite"] as const;
export type ArtifactReasonName = (typeof ARTIFACT_REASONS)[number];

export interface ArtifactOptions {
  /** Samples per window (L ≥ 3). */
  rows: number;
  channels: number;
  /** Fixed rails; undefined: auto (the running extreme of the channel). */
  railLow?: number;
  railHigh?: number;
  clipTolerance: number;
  clipFraction: number;
  flatThreshold: number;
  /** Infinity disables the jump test. */
  jumpFactor: number;
  /** Undefined disables the drift test. */
  driftThreshold?: number;
  /** Hard: rejected channels are zeroed in the clean windows; soft: windows pass unchanged. */
  hard: boolean;
}

/**
 * The ArtifactRejection block's kernel: per channel of every window, clipping, flat line,
 * impulsive jump, drift and non-finite checks; clean windows, masks, reason flags and
 * cumulative counters (see the Rust `ArtifactRejector` for the rules).
 */
export class ArtifactKernel {
  readonly rows: number;
  readonly channels: number;
  private inner: WasmArtifactRejector | null;
  private capacity = 0;
  private readonly perChannel: number;
  private readonly input = new Scratch();
  private readonly clean = new Scratch();
  private readonly masks = new Scratch();
  private readonly flagsOut = new Scratch();
  private readonly counts = new Scratch();

  constructor(o: ArtifactOptions) {
    requireReady("ArtifactKernel");
    checkChannels("ArtifactKernel", o.channels);
    checkWhole("ArtifactKernel", "rows", o.rows, 3);
    try {
      this.inner = new WasmArtifactRejector(
        o.rows,
        o.channels,
        o.railLow ?? Number.NaN,
        o.railHigh ?? Number.NaN,
        o.clipTolerance,
        o.clipFraction,
        o.flatThreshold,
        o.jumpFactor,
        o.driftThreshold ?? Number.NaN,
        o.hard,
        1,
      );
    } catch (e) {
      throw asError(e);
    }
    this.rows = o.rows;
    this.channels = o.channels;
    this.perChannel = this.inner.counters_per_channel();
    this.locate();
  }

  private locate(): void {
    const k = this.inner as WasmArtifactRejector;
    this.capacity = k.capacity();
    const size = this.rows * this.channels;
    this.input.place(k.input_ptr(), this.capacity * size);
    this.clean.place(k.clean_ptr(), this.capacity * size);
    this.masks.place(k.mask_ptr(), this.capacity * this.channels);
    this.flagsOut.place(k.flags_ptr(), this.capacity * this.channels);
    this.counts.place(k.counters_ptr(), this.channels * this.perChannel);
  }

  /**
   * Judges `nWindows` windows of `windows`; `clean` receives the clean windows, `mask` and `flags`
   * (when given) `nWindows × channels` values (mask 1 = good; flags: bit i = ARTIFACT_REASONS[i]).
   */
  process(
    windows: Float64Array,
    nWindows: number,
    clean: Float64Array,
    mask: Float64Array,
    flags: Float64Array | null = null,
  ): void {
    const k = this.inner;
    if (k === null) throw disposed("ArtifactKernel");
    const size = this.rows * this.channels;
    checkCall("ArtifactKernel.process", nWindows, size, windows, clean);
    if (
      mask.length < nWindows * this.channels ||
      (flags && flags.length < nWindows * this.channels)
    ) {
      throw new Error(
        `ArtifactKernel.process: mask and flags need ${nWindows * this.channels} values each`,
      );
    }
    if (nWindows > this.capacity) {
      k.ensure_capacity(grownCapacity(this.capacity, nWindows));
      this.locate();
    }
    this.input.write(windows, nWindows * size);
    if (!k.process(nWindows)) throw failed("ArtifactKernel.process");
    this.clean.read(clean, nWindows * size);
    this.masks.read(mask, nWindows * this.channels);
    if (flags) this.flagsOut.read(flags, nWindows * this.channels);
  }

  /** Windows judged since creation or the last `resetCounters`. */
  windows(): number {
    if (this.inner === null) throw disposed("ArtifactKernel");
    return this.inner.windows();
  }

  /** Windows of channel `c` flagged for `reason` (index in ARTIFACT_REASONS), or rejected (index 5). */
  counter(c: number, reason: number): number {
    if (this.inner === null) throw disposed("ArtifactKernel");
    return this.counts.get(c * this.perChannel + reason);
  }

  /** Zeroes the counters (learned auto rails are kept). */
  resetCounters(): void {
    if (this.inner === null) throw disposed("ArtifactKernel");
    this.inner.reset_counters();
  }

  /** Counters and auto rails back to the initial state. */
  reset(): void {
    if (this.inner === null) throw disposed("ArtifactKernel");
    this.inner.reset();
  }

  dispose(): void {
    this.inner?.free();
    this.inner = null;
  }
}
