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
import type { BufferRows } from "../flow/buffer";
import { inputName, signalInput } from "../shared/inputs";
import { lookup } from "../shared/named";
import { formatCount, plural } from "../shared/text";
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

/** MOSAIC's batch learning machines (Learning.cs). */
const MACHINES = ["RidgeRegression", "RR_RFF"] as const;
/** Most values the row store may hold (1 GiB of doubles). */
const MAX_VALUES = 2 ** 27;

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
    const feat = signalInput(ctx, 0, "Inputs");
    const d = feat.size;
    if (p.Inputs !== undefined && p.Inputs !== d) {
      throw new BlockConfigError(
        `Inputs is ${p.Inputs} but the features input ${inputName(feat.info)} carries ${d} values ` +
          "per event",
        "Inputs",
      );
    }
    const pairsIn = ctx.inputs.length > 1 ? signalInput(ctx, 1) : null;
    // MOSAIC's form: the Buffer named in Params is read when the model is built.
    const named = !pairsIn && p.Buffer !== undefined ? p.Buffer : undefined;
    if (named !== undefined && p.Outputs === undefined && p.File === undefined) {
      throw new BlockConfigError(
        `reading the Buffer '${named}' by name needs Outputs (the width of its targets)`,
        "Outputs",
      );
    }
    if (pairsIn && p.Buffer !== undefined && pairsIn.info.block !== p.Buffer) {
      ctx.warn(
        `Buffer is '${p.Buffer}' but the pairs input is ${inputName(pairsIn.info)}; using the input`,
      );
    }
    let m: number | null = null;
    if (pairsIn) {
      m = pairsIn.size - d;
      if (m < 1) {
        throw new BlockConfigError(
          `the pairs input ${inputName(pairsIn.info)} carries ${pairsIn.size} values per event; ` +
            `rows must be [target…, data…] with the ${d} data values of ` +
            `${inputName(feat.info)} and at least one target value`,
          "Outputs",
        );
      }
      if (p.Outputs !== undefined && p.Outputs !== m) {
        throw new BlockConfigError(
          `Outputs is ${p.Outputs} but the pairs input ${inputName(pairsIn.info)} carries ` +
            `${pairsIn.size} values per row, ${d} of them data: ${m} targets`,
          "Outputs",
        );
      }
    } else {
      m = p.Outputs ?? null;
    }
    const W = d + (m ?? 0);
    const defaultFile = p.File ?? `${ctx.name}.model.json`;

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
            targetName: null,
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
        "BatchPredictor needs a pairs input (its second input), Outputs, or an existing File to " +
          "know how many values it predicts",
        "Outputs",
      );
    }
    const M = m;
    const maxRows = p.MaxRows;
    if ((pairsIn || named !== undefined) && maxRows * W > MAX_VALUES) {
      throw new BlockConfigError(
        `MaxRows ${formatCount(maxRows)} rows of ${W} values would take up to ` +
          `${((maxRows * W * 8) / 2 ** 30).toFixed(1)} GiB; at most ${formatCount(MAX_VALUES)} ` +
          `values (1 GiB) are kept: set MaxRows to ${formatCount(Math.floor(MAX_VALUES / W))} or less`,
        "MaxRows",
      );
    }
    const created: ResolvedLearningOptions = loaded
      ? loaded.model.options
      : optionsFromParams(p, d, M);
    let model: LearningModel = loaded ? loaded.model : createModel(created);
    const initialState = loaded?.state ?? null;
    let replaced = false;

    // Named after the pairs' target columns when the Buffer names them (a Stimulus's gestures).
    const names = predictorMeta(pairsIn?.info.meta?.labels, M);
    const out = ctx.output(vectorShape(M), "prediction", names?.prediction);
    const fitOut = ctx.output(vectorShape(1 + M), "fit", names?.fit);

    let values = new Float64Array(Math.min(maxRows, 256) * W);
    let rows = 0;
    let dropped = 0;
    let fittedRows = -1; // rows of the last fit; -1: none since creation/reset/load
    let disposed = false;
    let lastSaved = "";
    const r2 = new Float64Array(M);

    const describe = (): void => {
      let s: string;
      if (fittedRows >= 0 && fittedRows === rows) {
        model.r2(r2);
        s = `fitted on ${plural(model.samplesSeen(), "row")}, ${formatR2(r2)}`;
      } else if (rows > 0) {
        s =
          `${plural(rows, "row")} kept` + (fittedRows >= 0 ? "; fitted before on other rows" : "");
        s += p.AutoTrain ? "" : " (press train)";
      } else if (named !== undefined && model.samplesSeen() === 0) {
        s =
          `untrained: reads the Buffer '${named}'` +
          (p.AutoTrain ? " when a cluster ends" : " (press train)");
      } else if (model.samplesSeen() > 0) {
        model.r2(r2);
        s = `trained on ${plural(model.samplesSeen(), "row")}, ${formatR2(r2)}; no rows kept`;
      } else {
        s = "untrained: no rows yet";
      }
      if (dropped > 0) s += `; ${formatCount(dropped)} rows dropped (MaxRows)`;
      ctx.setText(s + (lastSaved !== "" ? ` (${lastSaved})` : note));
    };
    describe();

    const grow = (need: number): void => {
      let cap = values.length / W;
      if (need <= cap) return;
      while (cap < need) cap *= 2;
      cap = Math.min(cap, maxRows);
      const v = new Float64Array(cap * W);
      v.set(values.subarray(0, rows * W));
      values = v;
    };

    const fit = (t: number): string => {
      if (rows === 0) return "no rows to fit";
      const used = model.fitPairs(values, rows);
      fittedRows = rows;
      model.r2(r2);
      const fo = fitOut.frame(1);
      fo.t[0] = t;
      fo.v[0] = used;
      for (let i = 0; i < M; i++) fo.v[1 + i] = r2[i]!;
      fitOut.emit(fo);
      describe();
      const refused = rows - used;
      return (
        `fitted ${describeOptions(model.options)} on ${plural(used, "row")}` +
        (refused > 0 ? ` (${formatCount(refused)} refused)` : "") +
        `, in-sample ${formatR2(r2)}`
      );
    };

    /** Replaces the rows by the named Buffer's and fits; a sentence saying what happened. */
    const fitFromBuffer = (t: number): string => {
      const b = lookup<BufferRows>(ctx, named!, "Buffer");
      if (typeof b === "string") throw new Error(`cannot read the Buffer: ${b}`);
      if (b.targetWidth !== M || b.dataWidth !== d) {
        throw new Error(
          `the Buffer '${named}' stores targets of ${b.targetWidth} and data of ${b.dataWidth} ` +
            `values; this model maps ${d} inputs to ${M} outputs`,
        );
      }
      const n = Math.min(b.rows(), maxRows);
      dropped = b.rows() - n;
      grow(n);
      values.set(b.values().subarray(0, n * W));
      rows = n;
      return fit(t);
    };

    let warnedFull = false;
    const onRows = (f: Frame): void => {
      const n = f.n;
      if (p.Dataset === "replace") {
        rows = 0;
        dropped = 0;
        warnedFull = false;
      }
      const take = Math.min(n, maxRows - rows);
      if (take < n) {
        dropped += n - take;
        if (!warnedFull) {
          warnedFull = true;
          ctx.warn(
            `more rows than MaxRows (${formatCount(maxRows)}): ${formatCount(n - take)} dropped`,
          );
        }
      }
      if (take > 0) {
        grow(rows + take);
        const v = f.v;
        const at = rows * W;
        for (let i = 0; i < take * W; i++) values[at + i] = v[i]!;
        rows += take;
      }
      if (p.AutoTrain) fit(f.t[n - 1]!);
      else describe();
    };

    const onFeatures = (f: Frame): void => {
      const n = f.n;
      const o = out.frame(n);
      const ft = f.t;
      for (let e = 0; e < n; e++) o.t[e] = ft[e]!;
      model.predict(f.v, o.v, n);
      out.emit(o);
    };

    const files: ModelFileHost = {
      ctx,
      model: () => model,
      expect: { inputs: d, outputs: M, inputName: feat.info.source, targetName: null },
      inputSource: feat.info.source,
      ...(pairsIn ? { targetSource: pairsIn.info.source } : {}),
      alive: () => !disposed,
      onSaved(message) {
        lastSaved = message;
        describe();
      },
      onLoaded(loaded, message) {
        model.dispose();
        model = loaded;
        replaced = true;
        fittedRows = -1;
        lastSaved = message;
        describe();
      },
    };

    let unlisten: (() => void) | undefined;
    return {
      start() {
        if (named === undefined || unlisten) return;
        const b = lookup<BufferRows>(ctx, named, "Buffer");
        if (typeof b === "string") {
          ctx.warn(`Buffer '${named}' (Params): ${b}; the model cannot be trained from it`);
          return;
        }
        // AutoTrain: fit whenever the Buffer closes a cluster (in this block's turn, not the
        // Buffer's); otherwise on the train action, MOSAIC's "Build model".
        if (p.AutoTrain) {
          unlisten = b.onClusterClosed(() =>
            ctx.at(ctx.now(), (t) => {
              try {
                fitFromBuffer(t);
              } catch (e) {
                ctx.warn(errorMessage(e));
              }
            }),
          );
        }
      },
      process(f, port) {
        if (f.n === 0) return;
        if (port === 1) onRows(f);
        else onFeatures(f);
      },
      reset() {
        if (replaced) {
          model.dispose();
          model = createModel(created);
          replaced = false;
        }
        if (initialState) model.loadState(initialState);
        else model.reset();
        rows = 0;
        dropped = 0;
        warnedFull = false;
        fittedRows = -1;
        lastSaved = "";
        describe();
      },
      dispose() {
        if (disposed) return;
        disposed = true;
        unlisten?.();
        model.dispose();
      },
      actions: {
        train: {
          label: "Train",
          description:
            named !== undefined
              ? `Fit the model on every row of the Buffer '${named}'`
              : "Fit the model on every row kept",
          run() {
            return named !== undefined ? fitFromBuffer(ctx.now()) : fit(ctx.now());
          },
        },
        clear: {
          label: "Clear rows",
          description: "Drop the rows kept (the model stays)",
          run() {
            const n = rows;
            rows = 0;
            dropped = 0;
            warnedFull = false;
            describe();
            return `dropped ${plural(n, "row")}`;
          },
        },
        reset: {
          label: "Reset model",
          description: "Forget the fitted model (predictions are 0 until the next fit)",
          run() {
            model.reset();
            fittedRows = -1;
            describe();
            return "the model is untrained";
          },
        },
        save: {
          label: "Save model",
          description: `Write the model to a file (default ${defaultFile})`,
          run(arg) {
            const file = modelFileArg(arg, defaultFile);
            saveModelFile(files, file);
            return `saving the model to ${file}`;
          },
        },
        load: {
          label: "Load model",
          description: `Replace the model by one from a file (default ${defaultFile})`,
          run: (arg) => loadModelAction(files, arg, defaultFile),
        },
        inspect: {
          label: "Inspect",
          description: "Model, rows kept and the R² of every output",
          run() {
            model.r2(r2);
            return (
              `${describeOptions(model.options)}: ${plural(rows, "row")} kept, fitted on ` +
              `${plural(model.samplesSeen(), "row")}; in-sample R² per output ${listR2(r2)}`
            );
          },
        },
      },
    };
  },
});
