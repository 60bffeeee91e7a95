import { z } from "zod";
import { defineBlock } from "../../engine";
import {
  createFeatureBlock,
  INPUT_HELP,
  REFERENCES,
  thresholdParam,
  windowParams,
} from "./feature-block";

export const WillisonAmplitude = defineBlock({
  type: "WillisonAmplitude",
  category: "Features",
  summary: "Willison amplitude: counts the steps |x_i − x_{i+1}| ≥ Threshold of each channel.",
  help:
    "Counts, for every channel of a window of N samples, the consecutive differences that reach " +
    "the threshold: WAMP = Σ_{i=1..N−1} [|x_i − x_{i+1}| ≥ Threshold] (Willison's amplitude, as " +
    "defined by Phinyomark et al. 2012), an indicator of motor-unit firing. LibEMG's `WAMP` counts " +
    "strictly greater differences and defaults to a threshold of 0.002 (in the signal's units); " +
    "here the default is 0, so set it for your signal's scale (e.g. 0.01–0.05 mV for surface " +
    "EMG). A NaN sample never counts; the output is a count (a float). " +
    INPUT_HELP +
    " " +
    REFERENCES,
  params: z.strictObject({ Threshold: thresholdParam("|x_i − x_{i+1}|"), ...windowParams }),
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["Threshold"],
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the WAMP counts; threshold control.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, (q) => [{ feature: "WAMP", threshold: q.Threshold }]);
  },
});
