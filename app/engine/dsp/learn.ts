/**
 * TypeScript face of the Rust learning core (`core-wasm/learn`, crate mosaic-learn): ridge
 * regression, random Fourier features and LDA, batch and incremental, for the BatchPredictor and
 * IncrementalPredictor blocks. Call `initDsp` first (the learning kernels live in the same module).
 *
 * Math (details in the Rust docs, `cargo doc -p mosaic-learn`): ŷ = Wᵀx + b with W solving the
 * ridge normal equations (paper eqs. 5–6); the intercept b is not penalised (the data are centred,
 * as scikit-learn's `Ridge`), or absent with `intercept: false` (the paper's eq. 6 as written, and
 * MOSAIC 1). Incremental learning updates a Cholesky factor of the normal equations by one
 * rank-one update per sample (exact, O(p²)); `forgetting` β < 1 weighs sample i of n by β^(n−1−i).
 * RFF maps x to z = √(2/D)·cos(Ωx + b), Ω ~ N(0, 2γ) (scikit-learn's `RBFSampler`), then ridge.
 * LDA (kind `lda`) is linear discriminant analysis learnt per sample: the classes are the distinct
 * target vectors, their means and the pooled within-class covariance are updated per sample
 * (scikit-learn's `LinearDiscriminantAnalysis`, solver lsqr), and a prediction is the targets
 * weighted by the class probabilities (`ldaOutput: scores`) or the most probable class's target.
 *
 * Buffers are row-major: `nEvents` inputs are `nEvents × inputs` values, predictions
 * `nEvents × outputs`. Nothing is allocated per call in steady state.
 */

import { WasmLearner } from "../../../core-wasm/pkg/mosaic_core.js";
import {
  asError,
  checkCall,
  disposed,
  failed,
  grownCapacity,
  INITIAL_CAPACITY,
  requireReady,
  Scratch,
} from "./memory";

export type ModelKindName = "ridge" | "rff" | "lda";

export interface LearningModelOptions {
  kind: ModelKindName;
  /** d, values per input sample (1 … 2048 for ridge). */
  inputs: number;
  /** M, values per target and prediction (1 … 4096). */
  outputs: number;
  /** λ from 1e-50 to 1e50 (default 1). */
  lambda?: number;
  /** β ∈ (0, 1] (default 1: no forgetting). */
  forgetting?: number;
  /** Fit an unpenalised intercept (default true). */
  intercept?: boolean;
  /** Standardise the inputs (default false; see the Rust `Model`). */
  normalize?: boolean;
  /** RFF with normalize: training samples before the statistics freeze (default 200). */
  normalizeSamples?: number;
  /** RFF: D, the number of random features (default 300, MOSAIC's). */
  features?: number;
  /** RFF: γ of the kernel exp(−γ‖x − x′‖²) (default 0.5: Ω ~ N(0, I), MOSAIC's σ = 1). */
  gamma?: number;
  /** RFF: seed of Ω and b, an integer from 0 to 2^53 − 1 (default 0). */
  seed?: number;
  /** LDA: shrinkage α in [0, 1] of the pooled covariance (default 0). */
  shrinkage?: number;
  /** LDA: most classes (distinct targets) kept, 1 … 1024 (default 32). */
  maxClasses?: number;
  /** LDA: `scores` (targets weighted by the class probabilities, default) or `class`. */
  ldaOutput?: "scores" | "class";
}

/** Defaults of the optional options (the same as the Rust crate's). */
export const LEARNING_DEFAULTS = {
  lambda: 1,
  forgetting: 1,
  intercept: true,
  normalize: false,
  normalizeSamples: 200,
  features: 300,
  gamma: 0.5,
  seed: 0,
  shrinkage: 0,
  maxClasses: 32,
  ldaOutput: "scores",
} as const;

export type ResolvedLearningOptions = Required<LearningModelOptions>;

/** One named part of a model's flat state (see the Rust `Model::state_sections`). */
export interface StateSection {
  name: string;
  length: number;
}

function checkSize(what: string, name: string, v: number, max: number): void {
  if (!Number.isInteger(v) || v < 1 || v > max) {
    throw new Error(`${what}: ${name} must be an integer from 1 to ${max}; got ${v}`);
  }
}

/**
 * A learning machine (ridge or RFF) in the wasm module. `trainPredict` is the IncrementalPredictor's
 * hot path (learn each event with the current target, then predict it, as MOSAIC did);
 * `fitPairs` the BatchPredictor's fit on Buffer rows `[target…, data…]`.
 */
export class LearningModel {
  readonly inputs: number;
  readonly outputs: number;
  readonly options: ResolvedLearningOptions;
  /** Dimension of the ridge stage: `inputs`, or `features` for RFF. */
  readonly dim: number;
  private inner: WasmLearner | null;
  private capacity = 0;
  private pairsCapacity = 0;
  private readonly x = new Scratch();
  private readonly out = new Scratch();
  private readonly target = new Scratch();
  private readonly pairs = new Scratch();
  private readonly r2s = new Scratch();
  private readonly state = new Scratch();
  private sections: StateSection[] | null = null;

  constructor(options: LearningModelOptions) {
    requireReady("LearningModel");
    const o: ResolvedLearningOptions = { ...LEARNING_DEFAULTS, ...options };
    if (o.kind !== "ridge" && o.kind !== "rff" && o.kind !== "lda") {
      throw new Error(
        `LearningModel: unknown kind '${String(o.kind)}'; expected ridge, rff or lda`,
      );
    }
    checkSize("LearningModel", "inputs", o.inputs, 1 << 22);
    checkSize("LearningModel", "outputs", o.outputs, 4096);
    if (!Number.isSafeInteger(o.seed) || o.seed < 0) {
      throw new Error(
        `LearningModel: seed must be an integer from 0 to 2^53 − 1; got ${String(o.seed)}`,
      );
    }
    const intOr0 = (v: number): number => (Number.isInteger(v) && v >= 0 && v < 2 ** 32 ? v : 0);
    try {
      this.inner = new WasmLearner(
        o.kind,
        o.inputs,
        o.outputs,
        o.lambda,
        o.forgetting,
        o.intercept,
        o.normalize,
        // Out-of-range counts reach Rust as 0, which it refuses with a message naming the param.
        intOr0(o.normalizeSamples),
        intOr0(o.features),
        o.gamma,
        Math.floor(o.seed / 2 ** 32),
        o.seed % 2 ** 32,
        o.shrinkage,
        intOr0(o.maxClasses),
        o.ldaOutput === "class",
        INITIAL_CAPACITY,
      );
    } catch (e) {
      throw asError(e);
    }
    this.options = o;
    this.inputs = o.inputs;
    this.outputs = o.outputs;
    this.dim = this.inner.dim();
    this.target.place(this.inner.target_ptr(), o.outputs);
    this.r2s.place(this.inner.r2_ptr(), o.outputs);
    this.state.place(this.inner.state_ptr(), this.inner.state_len());
    this.locate();
  }

  private live(): WasmLearner {
    if (this.inner === null) throw disposed("LearningModel");
    return this.inner;
  }

  private locate(): void {
    const k = this.inner as WasmLearner;
    this.capacity = k.capacity();
    this.x.place(k.x_ptr(), this.capacity * this.inputs);
    this.out.place(k.out_ptr(), this.capacity * this.outputs);
    // The other buffers never move, but the memory may have grown: refresh their views.
    this.target.place(k.target_ptr(), this.outputs);
    this.r2s.place(k.r2_ptr(), this.outputs);
    this.state.place(k.state_ptr(), k.state_len());
    this.pairsCapacity = k.pairs_capacity();
    this.pairs.place(k.pairs_ptr(), this.pairsCapacity * (this.inputs + this.outputs));
  }

  private prepare(what: string, nEvents: number, x: Float64Array, out: Float64Array): WasmLearner {
    const k = this.live();
    checkCall(what, nEvents, this.inputs, x, null);
    if (!(out.length >= nEvents * this.outputs)) {
      throw new Error(
        `${what}: output has ${out.length} values but ${nEvents} events × ${this.outputs} ` +
          `outputs need ${nEvents * this.outputs}`,
      );
    }
    if (nEvents > this.capacity) {
      k.ensure_capacity(grownCapacity(this.capacity, nEvents));
      this.locate();
    }
    this.x.write(x, nEvents * this.inputs);
    return k;
  }

  /** Predicts `nEvents` rows of `x` into `out`. An untrained model predicts 0. */
  predict(x: Float64Array, out: Float64Array, nEvents: number): void {
    const k = this.prepare("LearningModel.predict", nEvents, x, out);
    if (!k.predict(nEvents)) throw failed("LearningModel.predict");
    this.out.read(out, nEvents * this.outputs);
  }

  /**
   * For each of `nEvents` rows of `x`: learn it with `target` (`outputs` values), then predict
   * it into `out`. Returns the samples learnt (rows with a NaN, an infinity or a value beyond
   * ±1e50 are refused and counted by `rejected()`).
   */
  trainPredict(
    x: Float64Array,
    target: ArrayLike<number>,
    out: Float64Array,
    nEvents: number,
  ): number {
    if (target.length < this.outputs) {
      throw new Error(
        `LearningModel.trainPredict: target has ${target.length} values; expected ${this.outputs}`,
      );
    }
    const k = this.prepare("LearningModel.trainPredict", nEvents, x, out);
    this.target.write(target, this.outputs);
    const used = k.train_predict(nEvents);
    if (used < 0) throw failed("LearningModel.trainPredict");
    this.out.read(out, nEvents * this.outputs);
    return used;
  }

  /**
   * Forgets everything and fits `nRows` rows of `pairs` in one batch; each row is
   * `[target (outputs), input (inputs)]` (the Buffer block's `pairs` layout). Returns the rows
   * used.
   */
  fitPairs(pairs: Float64Array, nRows: number): number {
    const k = this.live();
    const width = this.inputs + this.outputs;
    checkCall("LearningModel.fitPairs", nRows, width, pairs, null);
    if (nRows > this.pairsCapacity) {
      k.ensure_pairs(grownCapacity(this.pairsCapacity, nRows));
      this.locate();
    }
    this.pairs.write(pairs, nRows * width);
    const used = k.fit_pairs(nRows);
    if (used < 0) throw failed("LearningModel.fitPairs");
    return used;
  }

  /** Samples learnt since creation, `reset` or the last fit. */
  samplesSeen(): number {
    return this.live().samples_seen();
  }

  /** Samples refused since then (NaN, infinity, beyond ±1e50). */
  rejected(): number {
    return this.live().rejected();
  }

  /** λ in use: λ, or between λ/2 and λ while forgetting (see the Rust `Ridge`). */
  effectiveLambda(): number {
    return this.live().effective_lambda();
  }

  /**
   * R² per output into `out` (`outputs` values; NaN while undefined). After incremental learning
   * it is prequential: each training sample from the second on is predicted before it is learnt,
   * R² = 1 − Σe²/Σ(y − ȳ)² over those samples (weighted by β^(n−1−i) with forgetting); after a
   * batch fit, the in-sample R² of the fitted rows.
   */
  r2(out: Float64Array): void {
    this.live().update_r2();
    this.r2s.read(out, this.outputs);
  }

  /** The named sections of the flat state, in order. */
  stateSections(): StateSection[] {
    const k = this.live();
    if (this.sections === null) {
      const names = k.state_names().split(",");
      const lens = k.state_lens();
      this.sections = names.map((name, i) => ({ name, length: lens[i] ?? 0 }));
    }
    return this.sections;
  }

  /** The whole state (a new array; not for the hot path). */
  saveState(): Float64Array {
    const k = this.live();
    if (!k.save_state()) throw failed("LearningModel.saveState");
    const out = new Float64Array(k.state_len());
    this.state.read(out, out.length);
    return out;
  }

  /**
   * Replaces the state by a saved one. Throws an Error whose message says what is wrong (wrong
   * length, a NaN, an asymmetric or indefinite scatter matrix, weights that do not match the
   * normal equations); the model is then unchanged.
   */
  loadState(state: Float64Array): void {
    const k = this.live();
    const len = k.state_len();
    if (state.length !== len) {
      throw new Error(`the saved state has ${state.length} values; this model needs ${len}`);
    }
    this.state.write(state, len);
    try {
      k.load_state();
    } catch (e) {
      throw asError(e);
    }
  }

  /** Back to the untrained model (RFF keeps Ω and b). */
  reset(): void {
    this.live().reset();
  }

  /** Solves again from the stored normal equations (rarely needed; see the Rust docs). */
  refactor(): void {
    this.live().refactor();
  }

  /** Frees the wasm memory of this model. Further calls throw. Calling it twice is harmless. */
  dispose(): void {
    this.inner?.free();
    this.inner = null;
  }
}

export interface LearningBenchFigure {
  /** The bench times the regressions (an LDA update costs a ridge's plus its re-solve). */
  kind: "ridge" | "rff";
  /** Dimension of the normal equations: inputs for ridge, features for RFF. */
  dim: number;
  inputs: number;
  outputs: number;
  /** Mean time of one incremental update followed by its prediction (`trainPredict`), ns. */
  updateNs: number;
  /** Mean time of one prediction, ns. */
  predictNs: number;
}

/**
 * Bench hook (for `npm run bench`): ns per incremental update (learn + predict one event, the
 * IncrementalPredictor's training path) and per prediction, for ridge with `dims` inputs and for
 * RFF with `dims` features on 8 inputs, `outputs` outputs. `now` is a clock in milliseconds
 * (`performance.now`). Events go one per call, as in a pipeline; each figure is the mean over
 * `seconds` of running (amortising the rare O(p³) re-factorisations, of which there are none
 * without forgetting). Needs `initDsp`.
 *
 * ```ts
 * for (const f of benchLearning(() => performance.now())) console.log(f);
 * ```
 */
export function benchLearning(
  now: () => number,
  opts: { dims?: readonly number[]; outputs?: number; seconds?: number } = {},
): LearningBenchFigure[] {
  const dims = opts.dims ?? [8, 64, 256];
  const outputs = opts.outputs ?? 12;
  const budget = (opts.seconds ?? 0.3) * 1000;
  const figures: LearningBenchFigure[] = [];
  for (const kind of ["ridge", "rff"] as const) {
    for (const dim of dims) {
      const inputs = kind === "ridge" ? dim : 8;
      const model = new LearningModel({ kind, inputs, outputs, features: dim, gamma: 0.1 });
      const n = 64;
      const x = new Float64Array(n * inputs);
      for (let i = 0; i < x.length; i++) x[i] = Math.sin(0.37 * i) + 0.1 * Math.cos(1.3 * i);
      const target = new Float64Array(outputs).fill(0.5);
      const out = new Float64Array(outputs);
      const time = (step: (i: number) => void): number => {
        for (let i = 0; i < n; i++) step(i); // warm-up
        let calls = 0;
        const t0 = now();
        let t = t0;
        while (t - t0 < budget) {
          for (let i = 0; i < n; i++) step(i);
          calls += n;
          t = now();
        }
        return ((t - t0) * 1e6) / calls;
      };
      const row = (i: number): Float64Array => x.subarray(i * inputs, (i + 1) * inputs);
      const rows = Array.from({ length: n }, (_, i) => row(i));
      const updateNs = time((i) => model.trainPredict(rows[i]!, target, out, 1));
      const predictNs = time((i) => model.predict(rows[i]!, out, 1));
      figures.push({ kind, dim, inputs, outputs, updateNs, predictNs });
      model.dispose();
    }
  }
  return figures;
}
