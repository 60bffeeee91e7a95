import { z } from "zod";
import { defineBlock } from "../../engine";
import { createFeatureBlock, INPUT_HELP, REFERENCES, windowParams } from "./feature-block";

export const Rms = defineBlock({
  type: "RMS",
  category: "Features",
  summary: "Root mean square of each channel over a sliding window (window and hop configurable).",
  help:
    "Computes the root mean square RMS = √((1/N) Σ_{i=1..N} x_i²) of every channel over a window " +
    "of N samples (paper Table 3; Phinyomark et al. 2012), an estimate of the signal's amplitude " +
    "(its power, for zero-mean EMG); identical to LibEMG's `RMS`. It is typically used standalone " +
    "on a plain stream with `Window` and `Hop` (e.g. 200 and 50 samples at 1 kHz: a 200 ms " +
    "window every 50 ms). " +
    INPUT_HELP +
    " A NaN sample makes that channel's value NaN. " +
    REFERENCES,
  params: z.strictObject({ ...windowParams }),
  inputs: { min: 1, max: 1, labels: ["signal"] },
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the RMS of every channel.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, () => [{ feature: "RMS" }]);
  },
});
