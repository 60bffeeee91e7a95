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
} from "../../engine";
import { FeatureKernel, WindowedFeatureKernel, type FeatureRequest } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { inputName, signalInput } from "../shared/inputs";

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
    if (params.Window !== undefined || params.Hop !== undefined) {
      throw new BlockConfigError(
        `input ${inputName(sig.info)} already carries windows ${formatShape(sig.shape)}; Window ` +
          "and Hop are only for a plain stream [1, C], remove them",
        params.Window !== undefined ? "Window" : "Hop",
      );
    }
    const build = (q: P): FeatureKernel => {
      try {
        return new FeatureKernel(requests(q), rows, cols);
      } catch (e) {
        throw new BlockConfigError(`cannot create the feature kernel: ${errorMessage(e)}`);
      }
    };
    let kernel = build(current);
    return {
      process(f: Frame) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        const ft = f.t;
        for (let e = 0; e < n; e++) o.t[e] = ft[e]!;
        kernel.process(f.v, o.v, n);
        out.emit(o);
      },
      setParam(name, value) {
        const next = { ...current, [name]: value };
        const k = build(next);
        kernel.dispose();
        kernel = k;
        Object.assign(current, next);
      },
      dispose() {
        kernel.dispose();
      },
    };
  }

  if (params.Window === undefined) {
    throw new BlockConfigError(
      `input ${inputName(sig.info)} is a plain stream ${formatShape(sig.shape)}: set Window (and ` +
        `Hop) so that ${ctx.type} windows it, or feed it windows from a SlidingWindow block`,
      "Window",
    );
  }
  const length = params.Window;
  const hop = params.Hop ?? length;
  if (length * cols > MAX_WINDOW_VALUES) {
    throw new BlockConfigError(
      `a window of ${length} samples × ${cols} channels holds more than ${MAX_WINDOW_VALUES} ` +
        "values; use a shorter Window",
      "Window",
    );
  }
  if (ctx.declaredRate === undefined && sig.info.rate > 0) ctx.setDesiredRate(sig.info.rate / hop);
  let kernel: WindowedFeatureKernel;
  try {
    kernel = new WindowedFeatureKernel(reqs, length, hop, cols);
  } catch (e) {
    throw new BlockConfigError(`cannot create the feature kernel: ${errorMessage(e)}`, "Window");
  }
  return {
    process(f: Frame) {
      const n = f.n;
      if (n === 0) return;
      const k = kernel.push(f.v, n);
      if (k === 0) return;
      const o = out.frame(k);
      kernel.read(o.v, k);
      const ft = f.t;
      for (let i = 0; i < k; i++) o.t[i] = ft[kernel.end(i)]!;
      out.emit(o);
    },
    reset() {
      kernel.reset();
    },
    setParam(name, value) {
      Object.assign(current, { [name]: value });
      kernel.setThresholds(requests(current));
    },
    dispose() {
      kernel.dispose();
    },
  };
}
