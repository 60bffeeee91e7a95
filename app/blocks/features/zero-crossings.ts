import { z } from "zod";
import { defineBlock, legacyNumber, LegacyParamsError } from "../../engine";
import {
  createFeatureBlock,
  INPUT_HELP,
  REFERENCES,
  thresholdParam,
  windowParams,
} from "./feature-block";

export const ZeroCrossings = defineBlock({
  type: "ZeroCrossings",
  category: "Features",
  summary: "Counts the zero crossings of each channel over a window (with an amplitude threshold).",
  help:
    "Counts, for every channel of a window, the pairs of consecutive samples with opposite signs " +
    "whose difference reaches the threshold: ZC = #{i : x_i·x_{i+1} < 0 and |x_i − x_{i+1}| ≥ " +
    "Threshold} (Hudgins et al. 1993; paper Table 3); the threshold keeps low-level noise around " +
    "zero from counting. A sample that is exactly 0 never crosses. LibEMG's `ZC` has no threshold " +
    "and equals Threshold 0 here. A NaN sample never counts. The output is a count (a float). " +
    INPUT_HELP +
    " " +
    REFERENCES,
  params: z.strictObject({ Threshold: thresholdParam("|x_i − x_{i+1}|"), ...windowParams }),
  legacyParams(args) {
    const a = args.filter((s) => s.trim() !== "");
    if (a.length > 1) {
      throw new LegacyParamsError(`expected [threshold], got ${a.length} arguments`, "Threshold");
    }
    return a.length === 0 ? {} : { Threshold: legacyNumber(a[0]!, "threshold", "Threshold") };
  },
  legacyForm: "[threshold]: e.g. [0.02] (optional)",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["Threshold"],
  views: ["scope", "spider"],
  panel: "Scope and spider plot of the zero-crossing counts; threshold control.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, (q) => [{ feature: "ZC", threshold: q.Threshold }]);
  },
});
