import { z } from "zod";
import { defineBlock } from "../../engine";
import { createFeatureBlock, INPUT_HELP, REFERENCES, windowParams } from "./feature-block";

export const WaveformLength = defineBlock({
  type: "WaveformLength",
  category: "Features",
  summary: "Waveform length of each channel over a window: WL = Σ|x_{i+1} − x_i|.",
  help:
    "Computes the waveform length WL = Σ_{i=1..N−1} |x_{i+1} − x_i| of every channel of a window " +
    "of N samples (Hudgins et al. 1993; paper Table 3): the cumulative length of the waveform, " +
    "which grows with both amplitude and frequency; identical to LibEMG's `WL`. " +
    INPUT_HELP +
    " A NaN sample makes that channel's value NaN. " +
    REFERENCES,
  params: z.strictObject({ ...windowParams }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: WaveformLength, Inputs: [Window] }`",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the WL of every channel.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, () => [{ feature: "WL" }]);
  },
});
