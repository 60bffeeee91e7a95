import { z } from "zod";
import { defineBlock, legacyNumber, LegacyParamsError } from "../../engine";
import {
  createFeatureBlock,
  INPUT_HELP,
  REFERENCES,
  thresholdParam,
  windowParams,
} from "./feature-block";

export const SlopeSignChanges = defineBlock({
  type: "SlopeSignChanges",
  category: "Features",
  summary: "Counts the slope sign changes of each channel over a window (with a threshold).",
  help:
    "Counts, for every channel of a window, the samples where the slope changes sign: with " +
    "`Rule: product` (default; Phinyomark et al. 2012 and LibEMG's `SSC`, whose default threshold " +
    "is also 0) SSC = #{i = 2..N−1 : (x_i − x_{i−1})(x_i − x_{i+1}) ≥ Threshold}; note that with " +
    "Threshold 0 a flat stretch (a zero product) counts too, so a small positive threshold " +
    "(in squared signal units) is usual. `Rule: mosaic` is MOSAIC 1's rule: a strict change of " +
    "sign of the slope with both |x_i − x_{i−1}| and |x_{i+1} − x_i| ≥ Threshold (signal units); " +
    "MOSAIC files (`Params: [threshold]`) are converted to it so they behave as before. Hudgins " +
    "et al. 1993 introduced the feature. A NaN sample never counts; the output is a count (a " +
    "float). " +
    INPUT_HELP +
    " " +
    REFERENCES,
  params: z.strictObject({
    Threshold: thresholdParam("the slope test (see Rule)"),
    Rule: z
      .enum(["product", "mosaic"])
      .default("product")
      .describe(
        "product: (x_i − x_{i−1})(x_i − x_{i+1}) ≥ Threshold (Phinyomark 2012, LibEMG); mosaic: " +
          "strict sign change and both differences ≥ Threshold in magnitude (MOSAIC 1)",
      ),
    ...windowParams,
  }),
  legacyParams(args) {
    const a = args.filter((s) => s.trim() !== "");
    if (a.length > 1) {
      throw new LegacyParamsError(`expected [threshold], got ${a.length} arguments`, "Threshold");
    }
    return a.length === 0
      ? { Rule: "mosaic" }
      : { Threshold: legacyNumber(a[0]!, "threshold", "Threshold"), Rule: "mosaic" };
  },
  legacyForm: "[threshold]: e.g. [0.02] (optional); converted with Rule: mosaic (MOSAIC 1's rule)",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["Threshold"],
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the slope-sign-change counts; threshold control.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, (q) => [
      { feature: q.Rule === "mosaic" ? "SSC_MOSAIC" : "SSC", threshold: q.Threshold },
    ]);
  },
});
