import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  formatShape,
  LegacyParamsError,
  legacyVector,
  matrixShape,
} from "../../engine";
import { inputName, signalInput } from "../shared/inputs";

const params = z.strictObject({
  Rows: z.number().int().min(1).max(256).describe("Electrode rows of the grid"),
  Columns: z.number().int().min(1).max(256).describe("Electrode columns of the grid"),
  Direction: z
    .enum(["rows", "columns"])
    .default("rows")
    .describe(
      "Along which grid axis the double difference is taken: rows (electrodes r−1, r, r+1 of a " +
        "column; (Rows − 2) × Columns outputs, the original's '8;4' → 24) or columns (c−1, c, c+1 " +
        "of a row; Rows × (Columns − 2) outputs). Put it along the muscle fibres",
    ),
  Layout: z
    .enum(["row-major", "column-major"])
    .default("row-major")
    .describe(
      "How the input's channels lie on the grid: row-major (channel k at row ⌊k / Columns⌋, " +
        "column k mod Columns) or column-major (row k mod Rows, column ⌊k / Rows⌋)",
    ),
});

type Params = z.output<typeof params>;

/**
 * Gather plan: output j = x[a_j] − 2·x[b_j] + x[c_j] (channel indices into the input's row), in
 * the output grid's row-major order.
 */
export function ddsPlan(p: Params): {
  a: Int32Array;
  b: Int32Array;
  c: Int32Array;
  rows: number;
  cols: number;
} {
  const R = p.Rows;
  const C = p.Columns;
  const ch = (r: number, c: number): number => (p.Layout === "row-major" ? r * C + c : c * R + r);
  const alongRows = p.Direction === "rows";
  const rows = alongRows ? R - 2 : R;
  const cols = alongRows ? C : C - 2;
  const n = rows * cols;
  const a = new Int32Array(n);
  const b = new Int32Array(n);
  const c = new Int32Array(n);
  let j = 0;
  for (let r = 0; r < rows; r++) {
    for (let k = 0; k < cols; k++) {
      if (alongRows) {
        a[j] = ch(r, k);
        b[j] = ch(r + 1, k);
        c[j] = ch(r + 2, k);
      } else {
        a[j] = ch(r, k);
        b[j] = ch(r, k + 1);
        c[j] = ch(r, k + 2);
      }
      j++;
    }
  }
  return { a, b, c, rows, cols };
}

export const DoubleDifferential = defineBlock({
  type: "ddS",
  category: "Signal processing",
  summary:
    "Spatial double-differential filter over an HD-EMG electrode grid: x[i−1] − 2·x[i] + x[i+1] along one axis.",
  help:
    "The double-differential (DD) spatial filter of high-density surface EMG (the name of the " +
    "original MOSAIC's older files; no public source of the original defines the block, so this " +
    "is the published filter). Along one axis of the electrode grid, every three consecutive " +
    "electrodes i−1, i, i+1 give one output x_{i−1} − 2·x_i + x_{i+1}: the difference of two " +
    "adjacent single-differential signals (Broman, Bilotto & De Luca, 'A note on the noninvasive " +
    "estimation of muscle fiber conduction velocity', IEEE Trans. Biomed. Eng. 32(5):341–344, " +
    "1985; as a spatial filter of electrode arrays, the longitudinal double-differential (LDD) " +
    "filter of Disselhorst-Klug, Silny & Rau, 'Improvement of spatial resolution in surface-EMG: " +
    "a theoretical and experimental comparison of different spatial filters', IEEE Trans. Biomed. " +
    "Eng. 44(7):567–574, 1997, whose mask has the opposite sign, which rectification removes). It " +
    "suppresses what the neighbouring electrodes share (crosstalk, common-mode signals) and keeps " +
    "sources under the middle electrode. The input carries Rows × Columns channels, numbered " +
    "by `Layout`; `Direction` rows gives (Rows − 2) × Columns outputs, columns Rows × (Columns − " +
    "2), in row-major order of the output grid. A matrix input (e.g. a window [n, channels]) is " +
    "filtered row by row. Tested against NumPy (app/blocks/signal/fixtures/gen_dds.py). MOSAIC's " +
    "positional form is `['rows;cols']`, e.g. `['8;4']`: 32 channels → 24.",
  params,
  legacyParams(args) {
    if (args.length !== 1) {
      throw new LegacyParamsError(
        `expected ['rows;cols'], e.g. ['8;4'], got ${args.length} argument${args.length === 1 ? "" : "s"}`,
        "Rows",
      );
    }
    const v = legacyVector(args[0]!, "the grid", "Rows");
    if (v.length !== 2) {
      throw new LegacyParamsError(`the grid '${args[0]}' is not 'rows;cols', e.g. '8;4'`, "Rows");
    }
    return { Rows: v[0], Columns: v[1] };
  },
  legacyForm: "['rows;cols'], e.g. ['8;4'] (the double difference along the rows)",
  inputs: { min: 1, max: 1, labels: ["grid"] },
  views: ["heatmap", "scope"],
  panel: "The filtered grid (heatmap) and its channels (scope).",
  create(ctx, p) {
    const R = p.Rows;
    const C = p.Columns;
    const need = R * C;
    if ((p.Direction === "rows" ? R : C) < 3) {
      throw new BlockConfigError(
        `a double difference needs 3 electrodes along ${p.Direction === "rows" ? "Rows" : "Columns"}; the grid is ${R} × ${C}`,
        p.Direction === "rows" ? "Rows" : "Columns",
      );
    }
    const input = signalInput(ctx, 0);
    if (input.shape.cols !== need) {
      throw new BlockConfigError(
        `input ${inputName(input.info)} has shape ${formatShape(input.shape)}: ${input.shape.cols} ` +
          `channels, but a ${R} × ${C} grid has ${need}`,
        "Rows",
      );
    }
    const plan = ddsPlan(p);
    const m = plan.a.length;
    const inRows = input.shape.rows;
    const out = ctx.output(matrixShape(inRows, m));
    const { a, b, c } = plan;
    return {
      process(f) {
        const n = f.n;
        if (n === 0) return;
        const o = out.frame(n);
        const v = f.v;
        const ov = o.v;
        const lines = n * inRows;
        for (let l = 0; l < lines; l++) {
          const src = l * need;
          const dst = l * m;
          for (let j = 0; j < m; j++) {
            ov[dst + j] = v[src + a[j]!]! - 2 * v[src + b[j]!]! + v[src + c[j]!]!;
          }
        }
        o.t.set(f.t.subarray(0, n));
        out.emit(o);
      },
    };
  },
});
