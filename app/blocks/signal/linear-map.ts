import { z } from "zod";
import { BlockConfigError, defineBlock, vectorShape } from "../../engine";
import { inputName, vectorInput } from "../shared/inputs";
import { SeededRandom } from "../shared/random";
import { MAX_CHANNELS, MAX_ITEMS } from "../shared/limits";

export const LinearMap = defineBlock({
  type: "LinearMap",
  category: "Signal processing",
  summary: "A fixed linear map y = W·x + b per event (a placeholder decoder).",
  help:
    "Maps every input vector x (C values) to y = W·x + b (k values), where W is a k × C matrix " +
    "and b a k-vector. It stands in for a trained decoder until the learning blocks exist, so a " +
    "pipeline can drive a controller with something that depends on the signal. Without " +
    "`Weights`, W is random but reproducible: its entries, row by row, are standard normal " +
    "numbers (mulberry32 uniforms through the Box–Muller transform, seeded with `Seed`) divided " +
    "by √C, so that y has about the scale of x. Without `Bias`, b = 0. Each output is computed " +
    "as (W[j][0]·x[0] + … + W[j][C−1]·x[C−1]) + b[j] in that order.",
  params: z
    .strictObject({
      Outputs: z
        .number()
        .int()
        .min(1)
        .optional()
        .describe("Number of outputs k (default: the number of rows of Weights)"),
      Weights: z
        .array(z.array(z.number()).min(1).max(MAX_CHANNELS))
        .min(1)
        .max(MAX_ITEMS)
        .optional()
        .describe(
          "The k × C matrix W as a list of k rows of C numbers (C = input width); default: " +
            "seeded random entries N(0, 1)/√C",
        ),
      Bias: z
        .array(z.number())
        .min(1)
        .max(MAX_ITEMS)
        .optional()
        .describe("The k offsets b (default: zeros)"),
      Seed: z
        .number()
        .int()
        .default(42)
        .describe("Seed of the random weights (used only when Weights is omitted)"),
    })
    .refine((p) => p.Outputs !== undefined || p.Weights !== undefined, {
      message: "give Outputs (the number of outputs) or Weights (the k × C matrix)",
      path: ["Outputs"],
    })
    .refine(
      (p) => p.Outputs === undefined || p.Weights === undefined || p.Weights.length === p.Outputs,
      { message: "Weights must have one row per output (Outputs rows)", path: ["Weights"] },
    )
    .refine(
      (p) => p.Weights === undefined || p.Weights.every((r) => r.length === p.Weights![0]!.length),
      {
        message: "every row of Weights must have the same length",
        path: ["Weights"],
      },
    )
    .refine(
      (p) => p.Bias === undefined || p.Bias.length === (p.Outputs ?? p.Weights?.length ?? 0),
      { message: "Bias must have one value per output", path: ["Bias"] },
    ),
  inputs: { min: 1, max: 1, labels: ["features"] },
  views: ["scope", "spider"],
  panel: "Scope of the outputs.",
  create(ctx, p) {
    const sig = vectorInput(ctx, 0);
    const c = sig.size;
    const k = p.Outputs ?? p.Weights!.length;
    const w = new Float64Array(k * c);
    if (p.Weights !== undefined) {
      const cols = p.Weights[0]!.length;
      if (cols !== c) {
        throw new BlockConfigError(
          `Weights is ${k} × ${cols}, but input ${inputName(sig.info)} has ${c} channels; ` +
            `expected ${k} rows of ${c} numbers`,
          "Weights",
        );
      }
      p.Weights.forEach((row, j) => row.forEach((x, i) => (w[j * c + i] = x)));
    } else {
      const rng = new SeededRandom(p.Seed);
      const scale = 1 / Math.sqrt(c);
      for (let i = 0; i < k * c; i++) w[i] = rng.normal() * scale;
    }
    const b = new Float64Array(k);
    if (p.Bias !== undefined) b.set(p.Bias);
    const out = ctx.output(vectorShape(k));
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
          const xo = e * c;
          const yo = e * k;
          for (let j = 0; j < k; j++) {
            const wo = j * c;
            let acc = 0;
            for (let i = 0; i < c; i++) acc += w[wo + i]! * v[xo + i]!;
            ov[yo + j] = acc + b[j]!;
          }
        }
        out.emit(o);
      },
    };
  },
});
