import { z } from "zod";
import {
  BlockConfigError,
  closest,
  defineBlock,
  errorMessage,
  legacyInteger,
  LegacyParamsError,
  matrixShape,
} from "../../engine";
import { SlidingWindowKernel } from "../../engine/dsp";
import { MAX_WINDOW, MAX_WINDOW_VALUES } from "../features/feature-block";
import { requireDsp } from "../shared/dsp";
import { vectorInput } from "../shared/inputs";

const FUNCTIONS = ["none", "hann", "hamming", "blackman"] as const;

/** MOSAIC 1's window names (case-insensitive) → ours. */
const LEGACY_FUNCTIONS: Record<string, (typeof FUNCTIONS)[number]> = {
  rectangular: "none",
  none: "none",
  hann: "hann",
  hamming: "hamming",
  blackman: "blackman",
};

export const SlidingWindow = defineBlock({
  type: "SlidingWindow",
  category: "Flow control",
  summary: "Frames a stream into windows [Length, C] every Step samples, optionally tapered.",
  help:
    "Collects the samples of a vector stream [1, C] and, once `Length` samples have arrived, " +
    "emits every `Step` samples a window matrix [Length, C] of the latest `Length` samples (row = " +
    "sample, oldest first) for feature extraction, smoothing or framing (paper Table 3). `Step` " +
    "smaller than `Length` gives overlapping windows, equal gives contiguous ones, larger skips " +
    "the samples in between. With a `WindowFunction` every row is multiplied by the symmetric " +
    "window of `scipy.signal.get_window(name, Length, fftbins=False)`: Hann " +
    "0.5 − 0.5·cos(2πn/(L−1)), Hamming 0.54 − 0.46·cos(2πn/(L−1)), Blackman 0.42 − " +
    "0.5·cos(2πn/(L−1)) + 0.08·cos(4πn/(L−1)) (the same as MOSAIC 1's Hann and Hamming). A " +
    "window's timestamp is that of its newest sample; the desired rate is the input rate / Step. " +
    "The history is a ring buffer kept across frames (nothing is allocated per sample); `reset` " +
    "empties it.",
  params: z.strictObject({
    Length: z
      .number()
      .int()
      .min(1)
      .max(MAX_WINDOW)
      .describe("Samples per window (rows of the output matrix)"),
    Step: z
      .number()
      .int()
      .min(1)
      .max(MAX_WINDOW)
      .optional()
      .describe(
        "Samples between the starts of two windows (hop; default: Length, no overlap); larger " +
          "than Length skips samples",
      ),
    WindowFunction: z
      .enum(FUNCTIONS)
      .default("none")
      .describe(
        "Taper multiplied into every window: none, hann, hamming or blackman (symmetric, as " +
          "scipy.signal.get_window with fftbins=False)",
      ),
  }),
  legacyParams(args) {
    // An empty list means no params (the loader's convention); Length is then reported missing.
    if (args.length === 0) return {};
    if (args.length > 3) {
      throw new LegacyParamsError(
        `expected [length, stride, window function], got ${args.length} arguments`,
      );
    }
    const out: { Length: number; Step?: number; WindowFunction?: string } = {
      Length: legacyInteger(args[0]!, "window length", "Length"),
    };
    if (args[1] !== undefined && args[1].trim() !== "") {
      out.Step = legacyInteger(args[1], "stride", "Step");
    }
    if (args[2] !== undefined && args[2].trim() !== "") {
      const name = args[2].trim().toLowerCase();
      const fn = LEGACY_FUNCTIONS[name];
      if (fn === undefined) {
        const s = closest(name, Object.keys(LEGACY_FUNCTIONS));
        throw new LegacyParamsError(
          `unknown window function '${args[2]}' (expected Rectangular, Hamming or Hann)` +
            (s !== undefined ? `; did you mean '${s}'?` : ""),
          "WindowFunction",
        );
      }
      out.WindowFunction = fn;
    }
    return out;
  },
  legacyForm:
    "[length, stride, window]: e.g. ['128', '32', 'Hamming']; window Rectangular, Hamming or Hann",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["heatmap", "scope"],
  panel: "Heatmap of the latest window (rows = samples, columns = channels).",
  create(ctx, p) {
    requireDsp(ctx.type);
    const sig = vectorInput(ctx, 0);
    const channels = sig.shape.cols;
    const step = p.Step ?? p.Length;
    if (p.Length * channels > MAX_WINDOW_VALUES) {
      throw new BlockConfigError(
        `a window of ${p.Length} samples × ${channels} channels holds more than ` +
          `${MAX_WINDOW_VALUES} values; use a shorter Length`,
        "Length",
      );
    }
    if (ctx.declaredRate === undefined && sig.info.rate > 0) {
      ctx.setDesiredRate(sig.info.rate / step);
    }
    let kernel: SlidingWindowKernel;
    try {
      kernel = new SlidingWindowKernel(p.Length, step, channels, p.WindowFunction);
    } catch (e) {
      throw new BlockConfigError(`cannot create the window: ${errorMessage(e)}`, "Length");
    }
    const out = ctx.output(matrixShape(p.Length, channels));
    return {
      process(f) {
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
      dispose() {
        kernel.dispose();
      },
    };
  },
});
