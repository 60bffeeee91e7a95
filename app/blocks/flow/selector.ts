import { z } from "zod";
import { BlockConfigError, defineBlock, formatShape, matrixShape } from "../../engine";
import { checkIndices, inputName, signalInput } from "../shared/inputs";
import { index } from "../shared/params";
import { MAX_CHANNELS } from "../shared/limits";

export const Selector = defineBlock({
  type: "Selector",
  category: "Flow control",
  summary:
    "Forwards its input, or one row of a matrix (Row: -1 = newest sample of a window) and chosen columns.",
  help:
    "MOSAIC's Selector received a (label, vector) tuple, e.g. from a Stimulus, and forwarded the " +
    "vector (paper Table 3). Here blocks have typed output ports instead of tuples (a block that " +
    "sent a tuple offers the vector on a port of its own), so a Selector written for MOSAIC, " +
    "with one input and no params, simply forwards that input unchanged. It can also pick: " +
    "`Row` forwards one row of a matrix input as a vector [1, C] (0-based; negative counts from " +
    "the end, so -1 is the newest sample of a SlidingWindow and -2 the one before), and " +
    "`Columns` keeps only the listed 0-based columns, in the listed order (of every row, or of " +
    "the chosen row). Timestamps are copied.",
  params: z.strictObject({
    Row: z
      .number()
      .int()
      .optional()
      .describe(
        "Forward only this row of a matrix input, as a vector (0-based; -1 = the last row, i.e. " +
          "the newest sample of a window); default: every row. Can be changed while running " +
          "when set",
      ),
    Columns: z
      .array(index())
      .min(1)
      .max(MAX_CHANNELS)
      .optional()
      .describe("Keep only these 0-based columns, in this order (default: all)"),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: Selector, Inputs: [Stimulus] }` forwards the input",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["Row"],
  views: ["scope"],
  panel: "Scope of the forwarded values.",
  create(ctx, p) {
    const sig = signalInput(ctx, 0);
    const { rows, cols } = sig.shape;
    const size = sig.size;
    const what = `input ${inputName(sig.info)}`;
    if (p.Columns !== undefined) {
      checkIndices(p.Columns, cols, what, "Columns", rows === 1 ? "channel" : "column");
    }
    const rowIndex = (r: number): number => {
      if (r < -rows || r >= rows) {
        throw new BlockConfigError(
          `Row ${r} is out of range for ${what} with shape ${formatShape(sig.shape)} ` +
            `(valid: ${-rows} to ${rows - 1}; -1 is the last row)`,
          "Row",
        );
      }
      return r < 0 ? rows + r : r;
    };
    const map = Int32Array.from(p.Columns ?? Array.from({ length: cols }, (_, c) => c));
    const k = map.length;
    const single = p.Row !== undefined;
    let row = single ? rowIndex(p.Row!) : 0;
    const outRows = single ? 1 : rows;
    const out = ctx.output(matrixShape(outRows, k));
    const outStride = outRows * k;
    return {
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        const ov = o.v;
        const v = f.v;
        const ft = f.t;
        for (let e = 0; e < n; e++) {
          o.t[e] = ft[e]!;
          for (let r = 0; r < outRows; r++) {
            const src = e * size + (single ? row : r) * cols;
            const dst = e * outStride + r * k;
            for (let c = 0; c < k; c++) ov[dst + c] = v[src + map[c]!]!;
          }
        }
        out.emit(o);
      },
      setParam(name, value) {
        if (name !== "Row") return;
        if (!single || value === undefined) {
          throw new Error(
            "Row can be changed while running only when it was set at load (setting or removing " +
              "it would change the output shape)",
          );
        }
        row = rowIndex(value as number);
      },
    };
  },
});
