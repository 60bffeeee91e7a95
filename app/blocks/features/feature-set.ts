import { z } from "zod";
import { defineBlock } from "../../engine";
import type { FeatureRequest } from "../../engine/dsp";
import { createFeatureBlock, INPUT_HELP, REFERENCES, windowParams } from "./feature-block";
import { MAX_ITEMS } from "../shared/limits";

const FEATURES = ["MAV", "RMS", "WL", "ZC", "SSC", "VAR", "IAV", "DASDV", "WAMP"] as const;

const params = z
  .strictObject({
    Features: z
      .array(z.enum(FEATURES))
      .min(1)
      .max(MAX_ITEMS)
      .default(["MAV", "ZC", "SSC", "WL"])
      .describe(
        "Features to compute, in output order (default [MAV, ZC, SSC, WL]: LibEMG's HTD set, " +
          "Hudgins' time-domain features); each as in its own block",
      ),
    ZCThreshold: z.number().default(0).describe("Threshold of ZC (see ZeroCrossings)"),
    SSCThreshold: z.number().default(0).describe("Threshold of SSC (see SlopeSignChanges)"),
    SSCRule: z
      .enum(["product", "mosaic"])
      .default("product")
      .describe("Rule of SSC: product (Phinyomark 2012, LibEMG) or mosaic (MOSAIC 1)"),
    WAMPThreshold: z.number().default(0).describe("Threshold of WAMP (see WillisonAmplitude)"),
    ...windowParams,
  })
  .refine((p) => new Set(p.Features).size === p.Features.length, {
    message: "each feature may be listed once",
    path: ["Features"],
  });

type Params = z.output<typeof params>;

function requests(p: Params): FeatureRequest[] {
  return p.Features.map((f) => {
    switch (f) {
      case "ZC":
        return { feature: "ZC", threshold: p.ZCThreshold };
      case "SSC":
        return {
          feature: p.SSCRule === "mosaic" ? "SSC_MOSAIC" : "SSC",
          threshold: p.SSCThreshold,
        };
      case "WAMP":
        return { feature: "WAMP", threshold: p.WAMPThreshold };
      default:
        return { feature: f };
    }
  });
}

export const FeatureSet = defineBlock({
  type: "FeatureSet",
  category: "Features",
  summary: "Several time-domain EMG features of the same window in one pass, concatenated.",
  help:
    "Computes several of the time-domain features MAV, RMS, WL, ZC, SSC, VAR, IAV, DASDV and WAMP " +
    "(definitions and thresholds as in their own blocks) of every channel of the same window, " +
    "reading the window once, and concatenates them feature-major: for `Features: [MAV, ZC, SSC, " +
    "WL]` and C channels the output [1, 4·C] holds the C MAVs, then the C ZCs, and so on (LibEMG's " +
    "order when it concatenates a feature group; the default is its HTD set, Hudgins' " +
    "time-domain features). One FeatureSet costs much less than one block per feature on many " +
    "channels (one pass, one frame). " +
    INPUT_HELP +
    " " +
    REFERENCES,
  params,
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["ZCThreshold", "SSCThreshold", "WAMPThreshold"],
  views: ["scope", "heatmap"],
  panel: "Heatmap of the feature vector (features × channels); threshold controls.",
  create(ctx, p) {
    return createFeatureBlock(ctx, p, requests);
  },
});
