import { z } from "zod";
import { defineBlock } from "../../engine";
import { createFeatureBlock, INPUT_HELP, REFERENCES, windowParams } from "./feature-block";

export const Variance = defineBlock({
  type: "Variance",
  category: "Features",
  summary: "EMG variance of each channel over a window: VAR = Σx_i² / (N − 1), no mean removal.",
  help:
    "Computes the variance of EMG as defined in the EMG literature, VAR = (1/(N−1)) " +
    "Σ_{i=1..N} x_i² (Phinyomark et al. 2012): the mean of surface EMG is taken to be zero, so it " +
    "is not removed (a power estimate). This differs from LibEMG's `VAR`, which is NumPy's " +
    "`np.var` (mean removed, divided by N); high-pass filter the signal first if it has an " +
    "offset. " +
    INPUT_HELP +
    " A NaN sample makes that channel's value NaN. " +
    REFERENCES,
  params: z.strictObject({ ...windowParams }),
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the VAR of every channel.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, () => [{ feature: "VAR" }]);
  },
});
