/**
 * Shared machinery of the feature blocks (MeanAbsoluteValue, RMS, …, FeatureSet): the `Window` /
 * `Hop` params, the two input forms (window matrices [L, C] from SlidingWindow, or a plain stream
 * [1, C] that the block windows itself) and the hot path over the wasm kernels.
 */
import { z } from "zod";
import {
  BlockConfigError,
  errorMessage,
  formatShape,
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type OutputPort,
} from "../../engine";
import { FeatureKernel, WindowedFeatureKernel, type FeatureRequest } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";

/** Most samples per window / between windows (a bound that keeps the ring allocatable). */
export const MAX_WINDOW = 1 << 20;
/** Most values (samples × channels) a window may hold. */
export const MAX_WINDOW_VALUES = 1 << 23;

/** `Window` and `Hop`: only for a plain stream input. */
export const windowParams = {
  Window: z
    .number()
    .int()
    .min(2)
    .max(MAX_WINDOW)
    .optional()
    .describe(
      "Samples per window when the input is a plain stream [1, C]: the block then windows it " +
        "itself (leave out for window matrices [L, C] from SlidingWindow)",
    ),
  Hop: z
    .number()
    .int()
    .min(1)
    .max(MAX_WINDOW)
    .optional()
    .describe(
      "Samples between two windows of a plain stream (default: Window, no overlap); the output " +
        "rate is the input rate / Hop",
    ),
};

/** `Threshold` of ZC, SSC and WAMP (live). */
export const thresholdParam = (what: string) =>
  z.number().default(0).describe(`Threshold T of ${what} (signal units; default 0)`);

export interface WindowingParams {
  Window?: number | undefined;
  Hop?: number | undefined;
}

/** Sentence shared by the help texts. */
export const INPUT_HELP =
  "Input: window matrices [L, C] (rows = samples, oldest first, e.g. from SlidingWindow; L ≥ 2) " +
  "give one output [1, C] per window with the window's timestamp; or a plain stream [1, C] with " +
  "`Window` (and `Hop`, default `Window`): the block keeps the last `Window` samples and emits " +
  "every `Hop` samples, stamped with the newest sample's time, at the input rate / `Hop`.";

/** Text of the references, shared by the help texts. */
export const REFERENCES =
  "References: B. Hudgins, P. Parker, R. N. Scott, *A new strategy for multifunction myoelectric " +
  "control*, IEEE Trans. Biomed. Eng. 40(1), 1993; A. Phinyomark, P. Phukpattaranont, " +
  "C. Limsakul, *Feature reduction and selection for EMG signal classification*, Expert Systems " +
  "with Applications 39(8), 2012; LibEMG (Eddy et al., IEEE Access 2023).";

/**
 * Creates the instance of a feature block: `requests(params)` lists the features; the output is
 * `[1, features × C]` (feature-major). Thresholds are live: `setParam` recomputes the requests.
 */
export function createFeatureBlock<P extends WindowingParams>(
  ctx: BlockContext,
  params: P,
  requests: (p: P) => FeatureRequest[],
): BlockInstance {
  requireDsp(ctx.type);
  const sig = signalInput(ctx, 0);
  const { rows, cols } = sig.shape;
  const current: P = { ...params };
  const reqs = requests(current);
  const width = reqs.length * cols;
  const out = ctx.output(vectorShape(width));

  if (rows >= 2) {
    checkNoWindowing(sig, params);
    return new WindowMatrixRun(rows, cols, current, requests, out).instance();
  }

  const length = streamWindow(ctx, sig, params);
  const hop = params.Hop ?? length;
  checkWindowValues(length, cols);
  if (ctx.declaredRate === undefined && sig.info.rate > 0) ctx.setDesiredRate(sig.info.rate / hop);
  const kernel = windowedKernel(reqs, length, hop, cols);
  return new StreamRun(kernel, current, requests, out).instance();
}

/** Window matrices come windowed already: Window and Hop must be left out. */
function checkNoWindowing(sig: SignalInput, params: WindowingParams): void {
  if (params.Window !== undefined || params.Hop !== undefined) {
    throw new BlockConfigError(
      `input ${inputName(sig.info)} already carries windows ${formatShape(sig.shape)}; Window ` +
        "and Hop are only for a plain stream [1, C], remove them",
      params.Window !== undefined ? "Window" : "Hop",
    );
  }
}

/** The window length of a plain stream: Window, which such an input needs. */
function streamWindow(ctx: BlockContext, sig: SignalInput, params: WindowingParams): number {
  if (params.Window === undefined) {
    throw new BlockConfigError(
      `input ${inputName(sig.info)} is a plain stream ${formatShape(sig.shape)}: set Window (and ` +
        `Hop) so that ${ctx.type} windows it, or feed it windows from a SlidingWindow block`,
      "Window",
    );
  }
  return params.Window;
}

/** A window of `length` samples × `cols` channels must hold at most MAX_WINDOW_VALUES values. */
function checkWindowValues(length: number, cols: number): void {
  if (length * cols > MAX_WINDOW_VALUES) {
    throw new BlockConfigError(
      `a window of ${length} samples × ${cols} channels holds more than ${MAX_WINDOW_VALUES} ` +
        "values; use a shorter Window",
      "Window",
    );
  }
}

/** The kernel that windows a plain stream itself, its failure reported on Window. */
function windowedKernel(
  reqs: FeatureRequest[],
  length: number,
  hop: number,
  cols: number,
): WindowedFeatureKernel {
  try {
    return new WindowedFeatureKernel(reqs, length, hop, cols);
  } catch (e) {
    throw new BlockConfigError(`cannot create the feature kernel: ${errorMessage(e)}`, "Window");
  }
}

/** A feature block on window matrices [L, C]: one output per window, a new kernel on setParam. */
class WindowMatrixRun<P extends WindowingParams> {
  private kernel: FeatureKernel;

  constructor(
    private readonly rows: number,
    private readonly cols: number,
    private readonly current: P,
    private readonly requests: (p: P) => FeatureRequest[],
    private readonly out: OutputPort,
  ) {
    this.kernel = this.build(current);
  }

  /** The block instance the engine drives (no reset: it holds no history). */
  instance(): BlockInstance {
    return {
      process: (f) => this.process(f),
      setParam: (name, value) => this.setParam(name, value),
      dispose: () => this.kernel.dispose(),
    };
  }

  /** A kernel for the features of params `q`, its failure a config error. */
  private build(q: P): FeatureKernel {
    try {
      return new FeatureKernel(this.requests(q), this.rows, this.cols);
    } catch (e) {
      throw new BlockConfigError(`cannot create the feature kernel: ${errorMessage(e)}`);
    }
  }

  /** One output per window, stamped with the window's time. */
  private process(f: Frame): void {
    const n = f.n;
    if (n === 0) return;
    const o = this.out.frame(n);
    const ft = f.t;
    for (let e = 0; e < n; e++) o.t[e] = ft[e]!;
    this.kernel.process(f.v, o.v, n);
    this.out.emit(o);
  }

  /** Swaps in a kernel built for the new params; the params change only once it is built. */
  private setParam(name: string, value: unknown): void {
    const next = { ...this.current, [name]: value };
    const k = this.build(next);
    this.kernel.dispose();
    this.kernel = k;
    Object.assign(this.current, next);
  }
}

/** A feature block windowing a plain stream [1, C] itself: an output every Hop samples. */
class StreamRun<P extends WindowingParams> {
  constructor(
    private readonly kernel: WindowedFeatureKernel,
    private readonly current: P,
    private readonly requests: (p: P) => FeatureRequest[],
    private readonly out: OutputPort,
  ) {}

  /** The block instance the engine drives. */
  instance(): BlockInstance {
    return {
      process: (f) => this.process(f),
      reset: () => this.kernel.reset(),
      setParam: (name, value) => this.setParam(name, value),
      dispose: () => this.kernel.dispose(),
    };
  }

  /** Pushes the samples; emits each completed window, stamped with its newest sample's time. */
  private process(f: Frame): void {
    const n = f.n;
    if (n === 0) return;
    const kernel = this.kernel;
    const k = kernel.push(f.v, n);
    if (k === 0) return;
    const o = this.out.frame(k);
    kernel.read(o.v, k);
    const ft = f.t;
    for (let i = 0; i < k; i++) o.t[i] = ft[kernel.end(i)]!;
    this.out.emit(o);
  }

  /** Live thresholds: the kernel keeps its window history. */
  private setParam(name: string, value: unknown): void {
    Object.assign(this.current, { [name]: value });
    this.kernel.setThresholds(this.requests(this.current));
  }
}
