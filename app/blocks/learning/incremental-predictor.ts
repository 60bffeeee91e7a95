import { z } from "zod";
import { defineBlock, LegacyParamsError } from "../../engine";
import { requireDsp } from "../shared/dsp";
import { incrementalInstance, openIncremental } from "./incremental-predictor-run";
import { legacyMachine, MODEL_HELP, modelParams } from "./model-file";

/** MOSAIC's incremental learning machines (Learning.cs). */
const MACHINES = ["IncrementalRidgeRegression", "IncrementalRFF", "IncrementalLDA"] as const;

const params = z.strictObject({
  ...modelParams,
  AutoSave: z
    .boolean()
    .default(false)
    .describe(
      "Save the model to File (default <block>.model.json) whenever a training cluster ends " +
        "(an all-NaN target event), as MOSAIC saved after each acquisition",
    ),
});

export const IncrementalPredictor = defineBlock({
  type: "IncrementalPredictor",
  category: "Learning",
  summary:
    "Learns a regression model sample by sample while predicting: cued targets in, predictions out.",
  help:
    "Online learning with the participant in the loop (paper III-G, IV-A). Inputs are " +
    "`[features, target]`, MOSAIC's order. The target input carries target vectors [1, M] from a " +
    "Trigger or Stimulus while the participant is cued, and an all-NaN event when not (their " +
    "`trigger` protocol), or is a plain target stream: a target event makes every later feature " +
    "event a training sample with that target, until an all-NaN event stops training (an event " +
    "with only some NaN values is ignored with a warning). A target labels the feature events " +
    "that arrive after it: a target stream computed from the features themselves pairs each " +
    "feature event with the previous target. Every feature event gives a prediction " +
    "[1, M] on the `prediction` output, also while training (the sample is learnt first, then " +
    "predicted, as MOSAIC did). The `fit` output carries, for every sample learnt, [samples seen, " +
    "R² of each output]: a running, prequential R² over the training samples (each sample from " +
    "the second on is predicted before it is learnt; R² = 1 − Σe²/Σ(y − ȳ)², weighted like the " +
    "samples with Forgetting; NaN while an output's target has not varied). The `versus` output " +
    "(for the panel's Training view; computed only while something reads it) carries, for every " +
    "feature event, [prediction…, target…]: while learning, the prediction made before the " +
    "sample is learnt and the target it is learnt with, else the prediction and NaN. Without a target " +
    "input the block only predicts (give `Outputs` or a `File`). " +
    MODEL_HELP +
    " A `File` that exists is loaded when the pipeline is created and replaces the model the " +
    "params describe (its kind, sizes and hyper-parameters are the file's). Actions: `train` " +
    "(learn from targets again), `pause` (ignore targets, keep predicting), `reset` (forget " +
    "everything), `save` and `load` (a file name, default File or <block>.model.json, or a " +
    "model file's text chosen in the page: the panel's Load model from file…) and " +
    "`inspect`. MOSAIC's `[IncrementalRFF, 8, 12, λ, σ, D]` loads as the same model: γ = σ²/2, " +
    "λ·2/D, no intercept. MOSAIC's `[IncrementalLDA, 8, 12]` loads as `Model: lda`: MOSAIC's " +
    "own IncrementalLDA learnt one class only and predicted a d-value 'velocity', so this is " +
    "LDA as published (class means and a pooled covariance updated per sample), not its numbers.",
  params,
  legacyParams: (args) => {
    if (args.length === 0) {
      throw new LegacyParamsError(
        "expected [machine, inputs, outputs, …], e.g. [IncrementalRidgeRegression, 8, 12]",
        "Model",
      );
    }
    // The original's older files give only [d, M] (no machine; their blocks are named incr_RFF):
    // IncrementalRFF with its defaults.
    if (/^\s*[0-9]+\s*$/.test(args[0]!)) {
      if (args.length !== 2) {
        throw new LegacyParamsError(
          `expected [machine, inputs, outputs, …] or the older [inputs, outputs], got [${args.join(", ")}]`,
          "Model",
        );
      }
      return legacyMachine("IncrementalRFF", args, [], MACHINES);
    }
    return legacyMachine(args[0]!.trim(), args.slice(1, 3), args.slice(3), MACHINES);
  },
  legacyForm:
    "[IncrementalRidgeRegression, d, M, λ?], [IncrementalRFF, d, M, λ?, σ?, D?] or " +
    "[IncrementalLDA, d, M] (MOSAIC's machine, input and output sizes, hyper-parameters); the " +
    "older [d, M] loads as IncrementalRFF",
  inputs: { min: 1, max: 2, labels: ["features", "target"] },
  outputs: ["prediction", "fit", "versus"],
  views: ["training", "scope", "spider", "label"],
  panel:
    "Training: prediction versus target per output, R² per output over the recent samples and, " +
    "for gesture targets, per-gesture accuracy and a confusion matrix; save the model (a " +
    "download in the browser build) or load one from a file. Predictions (scope, spider) and " +
    "the fit output; train, pause, reset, save, load and inspect buttons.",
  async create(ctx, p) {
    requireDsp("IncrementalPredictor");
    return incrementalInstance(await openIncremental(ctx, p));
  },
});
