/**
 * Named presets of the Function block (paper Table 5 names the Myo and Delsys pipelines' stages
 * "Amplification" and "Rectification"; MOSAIC's own files wrote them as `Function` blocks with
 * `[multiply:5]` and `[abs:0]`, so these types have no positional form). Both run the Function
 * block itself — its definition, validation and wasm kernel — with translated params.
 */
import { z } from "zod";
import { BlockConfigError, defineBlock, formatShape, type Shape } from "../../engine";
import { inputName, signalInput } from "../shared/inputs";
import { FunctionBlock } from "./function";
import { MAX_CHANNELS } from "../shared/limits";

/** Widths a Function operand accepts for an input shape: 1, one per column, or one per element. */
const gainFits = (g: number | readonly number[], shape: Shape): boolean => {
  const len = typeof g === "number" ? 1 : g.length;
  return len === 1 || len === shape.cols || len === shape.rows * shape.cols;
};

const gainSchema = z.union([z.number(), z.array(z.number()).min(1).max(MAX_CHANNELS)]);

export const Amplification = defineBlock({
  type: "Amplification",
  category: "Signal processing",
  summary: "Multiplies every value by Gain (one number, or one per channel): a Function multiply.",
  help:
    "The amplification stage of an EMG pipeline (paper Table 5): every input value is " +
    "multiplied by `Gain`, one number for all channels or one per channel (for a matrix, one per " +
    "column or one per element). It is the Function block with `Operation: multiply` and " +
    "`Value: Gain`, running the same kernel; the output has the input's shape and timestamps. " +
    "Gain can be changed while running, e.g. from the control panel while watching the scope. " +
    "MOSAIC had no block of this type: its files wrote `{ Type: Function, Params: [multiply:5] }`, " +
    "which still loads as a Function.",
  params: z.strictObject({
    Gain: gainSchema
      .default(1)
      .describe(
        "Factor: one number for every value, or one per channel (the input width); can be " +
          "changed while running",
      ),
  }),
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["Gain"],
  views: ["scope"],
  panel: "Gain and a scope of the amplified signal.",
  async create(ctx, p) {
    const sig = signalInput(ctx, 0);
    const check = (g: number | number[]): void => {
      if (!gainFits(g, sig.shape)) {
        const len = typeof g === "number" ? 1 : g.length;
        throw new BlockConfigError(
          `Gain has ${len} numbers, but input ${inputName(sig.info)} has shape ` +
            `${formatShape(sig.shape)}; expected 1 or ${sig.shape.cols}` +
            (sig.shape.rows > 1 ? ` (one per column) or ${sig.size} (one per element)` : ""),
          "Gain",
        );
      }
    };
    check(p.Gain);
    const inner = await FunctionBlock.create(
      ctx,
      FunctionBlock.params.parse({ Operation: "multiply", Value: p.Gain }),
    );
    return {
      process: (f, port) => inner.process!(f, port),
      reset: () => inner.reset?.(),
      dispose: () => inner.dispose?.(),
      setParam(name, value) {
        if (name !== "Gain") return;
        check(value as number | number[]);
        inner.setParam!("Value", value);
      },
    };
  },
});

export const Rectification = defineBlock({
  type: "Rectification",
  category: "Signal processing",
  summary: "Absolute value of every input value (full-wave rectification): a Function abs.",
  help:
    "The rectification stage of an EMG pipeline (paper Table 5): full-wave rectification, " +
    "|x| for every input value, before a low-pass filter turns it into an envelope (ARV). It is " +
    "the Function block with `Operation: abs`, running the same kernel; the output has the " +
    "input's shape and timestamps, and NaN stays NaN. MOSAIC had no block of this type: its " +
    "files wrote `{ Type: Function, Params: [abs:0] }`, which still loads as a Function.",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["scope"],
  panel: "Scope of the rectified signal.",
  create(ctx) {
    return FunctionBlock.create(ctx, FunctionBlock.params.parse({ Operation: "abs" }));
  },
});
