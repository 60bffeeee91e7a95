import { z } from "zod";
import { defineBlock } from "../../engine";
import { createFeatureBlock, INPUT_HELP, REFERENCES, windowParams } from "./feature-block";

export const IntegratedAbsoluteValue = defineBlock({
  type: "IntegratedAbsoluteValue",
  category: "Features",
  summary: "Integrated absolute value of each channel over a window: IAV = Σ|x_i|.",
  help:
    "Computes the integrated absolute value IAV = Σ_{i=1..N} |x_i| of every channel of a window " +
    "of N samples (Phinyomark et al. 2012; also called IEMG): N times the mean absolute value; " +
    "identical to LibEMG's `IAV`. " +
    INPUT_HELP +
    " A NaN sample makes that channel's value NaN. " +
    REFERENCES,
  params: z.strictObject({ ...windowParams }),
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the IAV of every channel.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, () => [{ feature: "IAV" }]);
  },
});
