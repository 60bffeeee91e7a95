import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  LegacyParamsError,
  vectorShape,
  type Frame,
} from "../../engine";
import type { LearningModel, ResolvedLearningOptions } from "../../engine/dsp";
import { requireDsp } from "../shared/dsp";
import { inputName, signalInput } from "../shared/inputs";
import { formatCount, formatVector, plural, TextThrottle } from "../shared/text";
import {
  createModel,
  describeOptions,
  formatR2,
  isMissingFile,
  legacyMachine,
  listR2,
  loadModel,
  loadModelAction,
  MODEL_HELP,
  modelFileArg,
  modelParams,
  ModelFileError,
  optionsFromParams,
  saveModelFile,
  type ModelFileHost,
} from "./model-file";
import { predictorMeta } from "./output-names";

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
    const feat = signalInput(ctx, 0, "Inputs");
    const tgt = ctx.inputs.length > 1 ? signalInput(ctx, 1, "Outputs") : null;
    const d = feat.size;
    if (p.Inputs !== undefined && p.Inputs !== d) {
      throw new BlockConfigError(
        `Inputs is ${p.Inputs} but the features input ${inputName(feat.info)} carries ${d} values ` +
          "per event",
        "Inputs",
      );
    }
    if (tgt && p.Outputs !== undefined && p.Outputs !== tgt.size) {
      throw new BlockConfigError(
        `Outputs is ${p.Outputs} but the target input ${inputName(tgt.info)} carries ${tgt.size} ` +
          "values per event",
        "Outputs",
      );
    }
    if (p.Model === "lda" && p.AutoSave) {
      throw new BlockConfigError(
        "AutoSave: LDA models cannot be saved to a model file yet (ridge and rff can)",
        "AutoSave",
      );
    }
    let m: number | null = tgt?.size ?? p.Outputs ?? null;
    const defaultFile = p.File ?? `${ctx.name}.model.json`;

    // A File that exists is the model.
    let loaded: { model: LearningModel; state: Float64Array } | null = null;
    let note = "";
    if (p.File !== undefined) {
      let text: string | null = null;
      try {
        text = await ctx.resources.readText(p.File);
      } catch (e) {
        if (!isMissingFile(e)) {
          throw new BlockConfigError(
            `cannot read model file '${p.File}': ${errorMessage(e)}`,
            "File",
          );
        }
        note = ` (no ${p.File} yet)`;
      }
      if (text !== null) {
        try {
          const r = loadModel(text, p.File, {
            inputs: d,
            outputs: m,
            inputName: feat.info.source,
            targetName: tgt?.info.source ?? null,
          });
          loaded = { model: r.model, state: r.file.state };
          m = r.file.options.outputs;
          note = ` (loaded ${p.File})`;
        } catch (e) {
          if (e instanceof ModelFileError) throw new BlockConfigError(e.message, "File");
          throw e;
        }
      }
    }
    if (m === null) {
      throw new BlockConfigError(
        "IncrementalPredictor needs a target input (its second input), Outputs, or an existing " +
          "File to know how many values it predicts",
        "Outputs",
      );
    }
    const M = m;
    const created: ResolvedLearningOptions = loaded
      ? loaded.model.options
      : optionsFromParams(p, d, M);
    let model: LearningModel = loaded ? loaded.model : createModel(created);
    const initialState = loaded?.state ?? null;

    // The outputs are named after the target's columns when it names them (a Stimulus's gestures).
    const names = predictorMeta(tgt?.size === M ? tgt.info.meta?.labels : undefined, M);
    const out = ctx.output(vectorShape(M), "prediction", names?.prediction);
    const fitOut = ctx.output(vectorShape(1 + M), "fit", names?.fit);

    // [prediction…, target…] per feature event, for the panel's Training view (when read).
    const versusOut = ctx.output(vectorShape(2 * M), "versus");

    const target = new Float64Array(M);
    let hasTarget = false;
    let paused = false;
    let disposed = false;
    /** The model was replaced by the load action (reset goes back to the created one). */
    let replaced = false;
    let learntSinceSave = 0;
    let lastSaved = "";
    const xrow = new Float64Array(d);
    const prow = new Float64Array(M);
    const before = new Float64Array(M);
    const r2 = new Float64Array(M);
    const throttle = new TextThrottle();

    const progress = (): string => {
      const n = model.samplesSeen();
      if (n === 0) return "untrained";
      model.r2(r2);
      return `trained on ${plural(n, "sample")}, ${formatR2(r2)}`;
    };
    const describe = (): void => {
      let s: string;
      if (paused) s = `paused: ${progress()}`;
      else if (hasTarget) s = `learning ${formatVector(target, 6)}: ${progress()}`;
      else if (model.samplesSeen() === 0) s = `untrained${tgt ? " (waiting for a target)" : ""}`;
      else s = progress();
      const rejected = model.rejected();
      if (rejected > 0) s += `; ${formatCount(rejected)} refused (NaN or huge)`;
      ctx.setText(s + (lastSaved !== "" ? ` (${lastSaved})` : note));
    };
    describe();

    const files: ModelFileHost = {
      ctx,
      model: () => model,
      expect: {
        inputs: d,
        outputs: M,
        inputName: feat.info.source,
        targetName: tgt?.info.source ?? null,
      },
      inputSource: feat.info.source,
      ...(tgt ? { targetSource: tgt.info.source } : {}),
      alive: () => !disposed,
      onSaved(message) {
        lastSaved = message;
        describe();
      },
      onLoaded(loaded, message) {
        model.dispose();
        model = loaded;
        replaced = true;
        learntSinceSave = 0;
        lastSaved = message;
        describe();
      },
    };

    const save = (file: string): string => {
      const n = model.samplesSeen();
      learntSinceSave = 0;
      saveModelFile(files, file);
      return `saving the model (${plural(n, "sample")}) to ${file}`;
    };

    /**
     * Target events: a vector starts (or switches) training, all NaN stops it. The status text
     * changes at once when training starts or stops; a target stream that changes every event
     * (a Stimulus's ramps) updates it at most every 0.25 s, like the predictions.
     */
    const onTarget = (f: Frame): void => {
      const v = f.v;
      const was = hasTarget;
      for (let e = 0; e < f.n; e++) {
        let nan = 0;
        for (let k = 0; k < M; k++) if (Number.isNaN(v[e * M + k]!)) nan++;
        if (nan === M) {
          if (hasTarget && p.AutoSave && learntSinceSave > 0) save(defaultFile);
          hasTarget = false;
        } else if (nan > 0) {
          ctx.warn(
            `ignored a target event with ${nan} NaN of ${M} values: a target must be all ` +
              "numbers, and a stop all NaN",
          );
        } else {
          for (let k = 0; k < M; k++) target[k] = v[e * M + k]!;
          hasTarget = true;
        }
      }
      if (hasTarget !== was) {
        throttle.reset();
        describe();
      } else if (throttle.due(f.t[f.n - 1]!)) describe();
    };

    /** [prediction…, NaN…] of every event, for the versus output while nothing is learnt. */
    const emitVersus = (o: Frame): void => {
      const vo = versusOut.frame(o.n);
      for (let e = 0; e < o.n; e++) {
        vo.t[e] = o.t[e]!;
        for (let i = 0; i < M; i++) {
          vo.v[e * 2 * M + i] = o.v[e * M + i]!;
          vo.v[e * 2 * M + M + i] = NaN;
        }
      }
      versusOut.emit(vo);
    };

    /**
     * One event at a time, to report the fit after every sample learnt and, when `versus` is
     * read, the prediction made before each sample is learnt.
     */
    const learnEach = (f: Frame, o: Frame): void => {
      const n = f.n;
      const ft = f.t;
      const fo = fitOut.frame(n);
      const vo = versusOut.idle ? null : versusOut.frame(n);
      const w = 1 + M;
      let k = 0;
      const fv = f.v;
      for (let e = 0; e < n; e++) {
        for (let i = 0; i < d; i++) xrow[i] = fv[e * d + i]!;
        if (vo) {
          model.predict(xrow, before, 1);
          vo.t[e] = ft[e]!;
          for (let i = 0; i < M; i++) {
            vo.v[e * 2 * M + i] = before[i]!;
            vo.v[e * 2 * M + M + i] = target[i]!;
          }
        }
        const used = model.trainPredict(xrow, target, prow, 1);
        for (let i = 0; i < M; i++) o.v[e * M + i] = prow[i]!;
        if (used > 0) {
          learntSinceSave++;
          model.r2(r2);
          fo.t[k] = ft[e]!;
          fo.v[k * w] = model.samplesSeen();
          for (let i = 0; i < M; i++) fo.v[k * w + 1 + i] = r2[i]!;
          k++;
        }
      }
      fo.n = k;
      fitOut.emit(fo);
      if (vo) versusOut.emit(vo);
    };

    const onFeatures = (f: Frame): void => {
      const n = f.n;
      const o = out.frame(n);
      const ft = f.t;
      for (let e = 0; e < n; e++) o.t[e] = ft[e]!;
      if (!hasTarget || paused) {
        model.predict(f.v, o.v, n);
        if (!versusOut.idle) emitVersus(o);
      } else if (fitOut.idle && versusOut.idle) {
        learntSinceSave += model.trainPredict(f.v, target, o.v, n);
      } else {
        learnEach(f, o);
      }
      out.emit(o);
      if (throttle.due(ft[n - 1]!)) describe();
    };

    const restore = (): void => {
      if (replaced) {
        model.dispose();
        model = createModel(created);
        replaced = false;
      }
      if (initialState) model.loadState(initialState);
      else model.reset();
    };

    return {
      process(f, port) {
        if (f.n === 0) return;
        if (port === 1) onTarget(f);
        else onFeatures(f);
      },
      reset() {
        restore();
        hasTarget = false;
        paused = false;
        learntSinceSave = 0;
        lastSaved = "";
        throttle.reset();
        describe();
      },
      dispose() {
        if (disposed) return;
        disposed = true;
        model.dispose();
      },
      actions: {
        train: {
          label: "Train",
          description: "Learn from target events again (after pause)",
          run() {
            paused = false;
            describe();
            return hasTarget
              ? `learning ${formatVector(target, 6)}`
              : "learning: waiting for a target event";
          },
        },
        pause: {
          label: "Pause",
          description: "Stop learning; predictions go on",
          run() {
            paused = true;
            describe();
            return `paused: ${progress()}`;
          },
        },
        reset: {
          label: "Reset model",
          description: "Forget everything learnt (an untrained model; Ω and b of rff are kept)",
          run() {
            const n = model.samplesSeen();
            model.reset();
            learntSinceSave = 0;
            describe();
            return `forgot ${plural(n, "sample")}`;
          },
        },
        save: {
          label: "Save model",
          description: `Write the model to a file (default ${defaultFile})`,
          run(arg) {
            return save(modelFileArg(arg, defaultFile));
          },
        },
        load: {
          label: "Load model",
          description: `Replace the model by one from a file (default ${defaultFile})`,
          run: (arg) => loadModelAction(files, arg, defaultFile),
        },
        inspect: {
          label: "Inspect",
          description: "Model, samples seen and R² of every output",
          run() {
            model.r2(r2);
            return (
              `${describeOptions(model.options)}: ${plural(model.samplesSeen(), "sample")} ` +
              `learnt, ${formatCount(model.rejected())} refused, λ in use ` +
              `${model.effectiveLambda()}; R² per output ${listR2(r2)}` +
              (paused ? "; paused" : "")
            );
          },
        },
      },
    };
  },
});
