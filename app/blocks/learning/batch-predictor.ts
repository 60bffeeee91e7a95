import { z } from "zod";
import { defineBlock, LegacyParamsError } from "../../engine";
import { requireDsp } from "../shared/dsp";
import { batchInstance, openBatch } from "./batch-predictor-run";
import { legacyMachine, MODEL_HELP, modelParams } from "./model-file";

/** MOSAIC's batch learning machines (Learning.cs). */
const MACHINES = ["RidgeRegression", "RR_RFF"] as const;

const params = z.strictObject({
  ...modelParams,
  Dataset: z
    .enum(["replace", "append"])
    .default("replace")
    .describe(
      "replace: every frame on the pairs input is a whole data set (the Buffer's emit sends all " +
        "its rows in one frame) and replaces the rows received before; append: rows accumulate " +
        "(a Buffer with Stream: true), until clear",
    ),
  AutoTrain: z
    .boolean()
    .default(true)
    .describe(
      "Fit as soon as rows arrive (each fit uses every row kept); false: fit on the train action",
    ),
  MaxRows: z
    .number()
    .int()
    .min(1)
    .max(10_000_000)
    .default(100_000)
    .describe("Most rows kept (rows beyond are dropped and counted)"),
  Buffer: z
    .string()
    .min(1)
    .optional()
    .describe(
      "MOSAIC's form: the Buffer whose rows train the model, read by name when the model is " +
        "built (train action, or with AutoTrain whenever the Buffer closes a cluster); with a " +
        "second input (the Buffer's pairs output), only checked against it",
    ),
});

export const BatchPredictor = defineBlock({
  type: "BatchPredictor",
  category: "Learning",
  summary: "Fits a regression model in one go on Buffer rows (target, data), then predicts.",
  help:
    "Batch learning (paper III-G): inputs are `[features, pairs]`. The pairs input carries rows " +
    "[target (M values), data (d values)] — the Buffer block's `pairs` output, whose `emit` " +
    "action sends every stored row in one frame; d is the width of the features input, and M " +
    "the rest. With `Dataset: replace` (default) each frame of rows is a whole data set and " +
    "replaces the previous one (so, unlike other inputs, it matters how rows are grouped in " +
    "frames); with `append` rows accumulate. With `AutoTrain` the model is fitted as soon as rows " +
    "arrive; otherwise on the `train` action. A fit forgets the previous model and solves the " +
    "normal equations of all rows at once. Every event of the features input gives a prediction " +
    "[1, M] (zeros before the first fit). The `fit` output carries, for every fit, [rows used, " +
    "R² of each output], the in-sample R² of the fitted rows. " +
    MODEL_HELP +
    " A `File` that exists is loaded when the pipeline is created and replaces the model the " +
    "params describe. Actions: `train` (fit on the rows kept), `clear` (drop the rows), `reset` " +
    "(forget the model), `save` and `load` (a file name, default File or <block>.model.json, or " +
    "a model file's text chosen in the page: the panel's Load model from file…) and " +
    "`inspect`. MOSAIC's `[buffer, RR_RFF, 8, 12, λ, σ, D]` loads as the same model (γ = σ²/2, " +
    "λ·2/D, no intercept) with one input: as in MOSAIC it reads the named Buffer's rows when the " +
    "model is built (the train action, MOSAIC's Build model; with AutoTrain also whenever the " +
    "Buffer closes a cluster). The Buffer must run on the same worker.",
  params,
  legacyParams: (args) => {
    if (args.length < 2) {
      throw new LegacyParamsError(
        "expected [buffer, machine, inputs, outputs, …], e.g. [cluster_storage, RidgeRegression, 8, 12]",
        "Buffer",
      );
    }
    return {
      Buffer: args[0]!.trim(),
      ...legacyMachine(args[1]!.trim(), args.slice(2, 4), args.slice(4), MACHINES),
    };
  },
  legacyForm:
    "[buffer, RidgeRegression, d, M, λ?] or [buffer, RR_RFF, d, M, λ?, σ?, D?] (MOSAIC's " +
    "Buffer name, machine, sizes and hyper-parameters)",
  inputs: { min: 1, max: 2, labels: ["features", "pairs"] },
  outputs: ["prediction", "fit"],
  views: ["training", "scope", "spider", "label"],
  panel:
    "Training: its status and the model file (save, a download in the browser build, or load " +
    "from a file); predictions (scope, spider), rows kept and the R² of the last fit; train, " +
    "clear, reset, save, load and inspect buttons.",
  async create(ctx, p) {
    requireDsp("BatchPredictor");
    return batchInstance(await openBatch(ctx, p));
  },
});
