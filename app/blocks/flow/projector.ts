import { z } from "zod";
import { defineBlock, LegacyParamsError, legacyVector, matrixShape } from "../../engine";
import { checkIndices, inputName, signalInput } from "../shared/inputs";
import { index } from "../shared/params";
import { MAX_CHANNELS } from "../shared/limits";

export const Projector = defineBlock({
  type: "Projector",
  category: "Flow control",
  summary: "Picks and reorders elements of a vector (or of every row of a matrix) by index.",
  help:
    "Extracts and forwards a subset of the elements of its input, reordered as listed (paper " +
    "Table 3): output element j is input element `Indices[j]` (0-based); an index may repeat. On " +
    "a matrix input (e.g. a window [rows, C]) it picks the same columns from every row, giving " +
    "[rows, k]. Timestamps are copied.",
  params: z.strictObject({
    Indices: z
      .array(index())
      .min(1)
      .max(MAX_CHANNELS)
      .describe(
        "0-based input indices, in output order (may repeat or reorder), e.g. [4, 5, 6, 0]",
      ),
  }),
  legacyParams(args) {
    if (args.length !== 1) {
      throw new LegacyParamsError(
        `expected one argument (indices a;b;c), got ${args.length}`,
        "Indices",
      );
    }
    return { Indices: legacyVector(args[0]!, "indices", "Indices") };
  },
  legacyForm: "['4;5;6;0;1;2']: 0-based indices in output order",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["scope"],
  panel: "Scope of the projected elements.",
  create(ctx, p) {
    const sig = signalInput(ctx, 0);
    const { rows, cols } = sig.shape;
    checkIndices(
      p.Indices,
      cols,
      `input ${inputName(sig.info)}`,
      "Indices",
      rows === 1 ? "channel" : "column",
    );
    const map = Int32Array.from(p.Indices);
    const k = map.length;
    const out = ctx.output(matrixShape(rows, k));
    const stride = sig.size;
    const outStride = rows * k;
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
          for (let r = 0; r < rows; r++) {
            const src = e * stride + r * cols;
            const dst = e * outStride + r * k;
            for (let c = 0; c < k; c++) ov[dst + c] = v[src + map[c]!]!;
          }
        }
        out.emit(o);
      },
    };
  },
});
