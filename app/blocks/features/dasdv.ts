import { z } from "zod";
import { defineBlock } from "../../engine";
import { createFeatureBlock, INPUT_HELP, REFERENCES, windowParams } from "./feature-block";

export const Dasdv = defineBlock({
  type: "DASDV",
  category: "Features",
  summary: "Difference absolute standard deviation value: √(Σ(x_{i+1} − x_i)² / (N − 1)).",
  help:
    "Computes the difference absolute standard deviation value DASDV = √((1/(N−1)) " +
    "Σ_{i=1..N−1} (x_{i+1} − x_i)²) of every channel of a window of N samples (Phinyomark et al. " +
    "2012): the RMS of the first differences, sensitive to both amplitude and frequency; " +
    "identical to LibEMG's `DASDV`. " +
    INPUT_HELP +
    " A NaN sample makes that channel's value NaN. " +
    REFERENCES,
  params: z.strictObject({ ...windowParams }),
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the DASDV of every channel.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, () => [{ feature: "DASDV" }]);
  },
});
