import { z } from "zod";
import { defineBlock } from "../../engine";
import { createFeatureBlock, INPUT_HELP, REFERENCES, windowParams } from "./feature-block";

export const MeanAbsoluteValue = defineBlock({
  type: "MeanAbsoluteValue",
  aliases: ["MeanAverageValue"],
  category: "Features",
  summary: "Mean absolute value of each channel over a window: MAV = 1/N Σ|x_i|.",
  help:
    "Computes the mean absolute value MAV = (1/N) Σ_{i=1..N} |x_i| of every channel of a window " +
    "of N samples (Hudgins et al. 1993; paper Table 3), the classic amplitude feature of surface " +
    "EMG; identical to LibEMG's `MAV`. " +
    INPUT_HELP +
    " A NaN sample makes that channel's value NaN. MOSAIC 1 called this block " +
    "`MeanAverageValue` (same definition, no params). " +
    REFERENCES,
  params: z.strictObject({ ...windowParams }),
  legacyParams: () => ({}),
  legacyForm:
    "no params: `{ Type: MeanAbsoluteValue, Inputs: [Window] }` (MOSAIC 1: MeanAverageValue)",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the MAV of every channel.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, () => [{ feature: "MAV" }]);
  },
});
