import { z } from "zod";
import { defineBlock } from "../../engine";
import { signalInput } from "../shared/inputs";
import { index } from "../shared/params";
import { MAX_CHANNELS } from "../shared/limits";
import { ChannelSelectorRun } from "./channel-selector-run";

const MODES = ["zero", "hold", "nan"] as const;
/** What an inactive channel outputs. */
export type Mode = (typeof MODES)[number];

export const ChannelSelector = defineBlock({
  type: "ChannelSelector",
  category: "Flow control",
  summary:
    "Activates, deactivates or zeroes channels while running; the output keeps the input's shape.",
  help:
    "Passes the active channels of its input unchanged and replaces the others (paper Table 3), " +
    "so that a bad electrode can be silenced without restarting the pipeline. A channel is a " +
    "column: an element of a vector, or the same column in every row of a matrix (a window). " +
    "`Active` lists the 0-based channels that pass (default: all); `Inactive` says what the " +
    "others output: `zero`, `hold` (the last value the channel had while it was active; 0 if it " +
    "never was) or `nan`. Both can be changed while running, and the actions `activate`, " +
    "`deactivate` and `toggle` (a channel index or a list such as [0, 3]), `all` and `none` change " +
    "the active set; `reset` returns to `Active`. The output always has the input's shape: " +
    "MOSAIC's option to delete inactive channels (a narrower output) is not offered, because " +
    "shapes are fixed when the pipeline loads — use a Projector for a fixed subset. Timestamps " +
    "are copied.",
  params: z.strictObject({
    Active: z
      .array(index())
      .max(MAX_CHANNELS)
      .optional()
      .describe(
        "0-based channels that pass (default: all; [] passes none); can be changed while running",
      ),
    Inactive: z
      .enum(MODES)
      .default("zero")
      .describe(
        "What an inactive channel outputs: zero; hold (its last value while active); nan. Can " +
          "be changed while running",
      ),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: ChannelSelector, Inputs: [Emg] }` (all channels active)",
  inputs: { min: 1, max: 1, labels: ["signal"] },
  live: ["Active", "Inactive"],
  views: ["scope"],
  panel: "A checkbox per channel, the inactive-channel mode, and a scope of the output.",
  create(ctx, p) {
    return new ChannelSelectorRun(ctx, signalInput(ctx, 0), p.Active, p.Inactive).instance();
  },
});
