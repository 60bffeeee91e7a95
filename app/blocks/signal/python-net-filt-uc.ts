import { z } from "zod";
import { BlockConfigError, defineBlock, LegacyParamsError, legacyInteger } from "../../engine";
import { signalInput } from "../shared/inputs";
import { createPythonModule } from "../io/python-backed";

const params = z.strictObject({
  Filter: z
    .enum(["lowpass", "notch"])
    .default("lowpass")
    .describe(
      "lowpass: scipy.signal.butter(Order, 2·Frequency/SampleRate, 'low'); notch: " +
        "scipy.signal.iirnotch(Frequency, Q, SampleRate)",
    ),
  Order: z.number().int().min(1).max(20).default(2).describe("Butterworth order (lowpass)"),
  Q: z.number().positive().max(1e6).default(30).describe("Quality factor of the notch"),
  Frequency: z
    .number()
    .positive()
    .describe("Cut-off frequency (lowpass) or the frequency removed (notch), Hz"),
  SampleRate: z
    .number()
    .positive()
    .max(1e7)
    .optional()
    .describe("Sample rate of the input, Hz (default: the input's rate)"),
  Initial: z
    .enum(["step", "zero"])
    .default("step")
    .describe(
      "Filter state at the start: step (scipy.signal.lfilter_zi(b, a) per channel, as if the " +
        "input had been 1 for ever: what MOSAIC did) or zero (at rest, lfilter's default)",
    ),
});

export const PythonNetFiltUC = defineBlock({
  type: "PythonNetFiltUC",
  category: "Signal processing",
  summary:
    "SciPy Butterworth low-pass or notch filter, run in the Python sidecar (MOSAIC's Python.NET example).",
  help:
    "MOSAIC's PythonNetFiltUC, its example of calling SciPy from a pipeline: designs a " +
    "Butterworth low-pass (`scipy.signal.butter(Order, 2·Frequency/SampleRate, 'low')`) or a " +
    "notch (`scipy.signal.iirnotch(Frequency, Q, SampleRate)`) and filters every channel with " +
    "`scipy.signal.lfilter`, keeping its state between events, in the Python sidecar " +
    "(native-bridges/python/mosaic_blocks/filt_uc.py; the Python block's process, restarts and " +
    "status). The output equals scipy filtering the whole signal at once, bit for bit. As the " +
    "original, each channel starts at `lfilter_zi(b, a)` (`Initial: step`: the steady state of a " +
    "constant input of 1, whatever the first sample is); `Initial: zero` starts at rest. For a " +
    "filter inside the engine (WASM, no process) use Filter with the same coefficients. MOSAIC's " +
    "positional form is `[type, order|Q, frequency, scriptPath, fs]` (type 0 low-pass, 1 notch; " +
    "the script path is ignored, as it was).",
  params,
  legacyParams(args) {
    if (args.length < 5) {
      throw new LegacyParamsError(
        `expected [type, order|Q, frequency, scriptPath, fs] (MOSAIC's PythonNetFiltUC needed 5), got ${args.length}`,
      );
    }
    const type = legacyInteger(args[0]!, "the filter type", "Filter");
    if (type !== 0 && type !== 1) {
      throw new LegacyParamsError(`filter type ${type}: 0 is low-pass, 1 notch`, "Filter");
    }
    // The original parsed order/Q, frequency and fs as whole numbers (Convert.ToInt32).
    const n = legacyInteger(args[1]!, type === 0 ? "the order" : "Q", type === 0 ? "Order" : "Q");
    return {
      Filter: type === 0 ? "lowpass" : "notch",
      ...(type === 0 ? { Order: n } : { Q: n }),
      Frequency: legacyInteger(args[2]!, "the frequency", "Frequency"),
      SampleRate: legacyInteger(args[4]!, "fs", "SampleRate"),
    };
  },
  legacyForm:
    "[type, order|Q, frequency, scriptPath, fs]: type 0 low-pass (order), 1 notch (Q), e.g. [1, 2, 3, 'x.py', 200]",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  eventLoop: true,
  views: ["scope", "label"],
  panel: "The filtered signal; the sidecar's state and call times.",
  async create(ctx, p) {
    const input = signalInput(ctx, 0);
    // A window's rate is not its samples' rate: with a matrix input SampleRate must be given.
    if (p.SampleRate === undefined && input.shape.rows > 1) {
      throw new BlockConfigError(
        `the input ${input.info.source} carries windows of ${input.shape.rows} samples, whose ` +
          "rate is not the samples' rate: give SampleRate",
        "SampleRate",
      );
    }
    const fs = p.SampleRate ?? ctx.inputs[0]!.rate;
    if (!(fs > 0)) {
      throw new BlockConfigError(
        `the input ${input.info.source} has no known rate: give SampleRate`,
        "SampleRate",
      );
    }
    if (!(p.Frequency < fs / 2)) {
      throw new BlockConfigError(
        `Frequency ${p.Frequency} Hz is not below the Nyquist frequency (${fs / 2} Hz at ${fs} Hz)`,
        "Frequency",
      );
    }
    return createPythonModule(ctx, {
      module: "mosaic_blocks.filt_uc",
      init: "init",
      function: "step",
      params: {
        kind: p.Filter,
        order: p.Order,
        q: p.Q,
        frequency: p.Frequency,
        fs,
        initial: p.Initial,
      },
      outputShape: [input.shape.rows, input.shape.cols],
    });
  },
});
