/**
 * BatchPredictor: one predictor's running state and what changes it. Rows [target…, data…]
 * arrive on the pairs input (or are read from a Buffer named in the params) and are kept; a fit
 * solves the model on every row kept; every feature event is predicted. `openBatch` checks the
 * inputs and params and reads the model File; `batchInstance` is the block instance (the
 * runtime's calls and the panel's actions).
 */
import {
  BlockConfigError,
  errorMessage,
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type OutputPort,
} from "../../engine";
import type { BufferRows } from "../flow/buffer";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";
import { lookup } from "../shared/named";
import { formatCount, plural } from "../shared/text";
import {
  describeOptions,
  formatR2,
  listR2,
  optionsFromParams,
  saveModelFile,
  type ModelParams,
} from "./model-file";
import { predictorMeta } from "./output-names";
import {
  checkInputsParam,
  modelFileActions,
  ModelSlot,
  readStartupModel,
  timedFrame,
  type StartupModel,
} from "./predictor-model";

/** Most values the row store may hold (1 GiB of doubles). */
const MAX_VALUES = 2 ** 27;

/** The BatchPredictor's params (its zod schema's output). */
export interface BatchParams extends ModelParams {
  Dataset: "replace" | "append";
  AutoTrain: boolean;
  MaxRows: number;
  Buffer?: string | undefined;
}

/** Where a BatchPredictor's rows come from, and how wide they are. */
export interface RowSource {
  /** The pairs input (its second input), if connected. */
  pairsIn: SignalInput | null;
  /** MOSAIC's form: the Buffer named in the params, read when the model is built. */
  named: string | undefined;
  /** Values per row kept: d data values plus the M targets (from the pairs input, Outputs or the File). */
  width: number;
}

/**
 * Checks the inputs against the params, reads the model File and creates the predictor: its
 * outputs and its first status text.
 */
export async function openBatch(ctx: BlockContext, p: BatchParams): Promise<BatchRun> {
  const feat = signalInput(ctx, 0, "Inputs");
  checkInputsParam(p.Inputs, feat);
  const pairsIn = ctx.inputs.length > 1 ? signalInput(ctx, 1) : null;
  const named = namedBuffer(ctx, p, pairsIn);
  const outputs = pairsIn ? pairsOutputs(p, feat, pairsIn) : (p.Outputs ?? null);
  const startup = await readStartupModel(ctx, p.File, {
    inputs: feat.size,
    outputs,
    inputName: feat.info.source,
    targetName: null,
  });
  const M = startup.loaded?.outputs ?? outputs;
  if (M === null) {
    throw new BlockConfigError(
      "BatchPredictor needs a pairs input (its second input), Outputs, or an existing File to " +
        "know how many values it predicts",
      "Outputs",
    );
  }
  // A row is [target…, data…]: its width is known once the File has said how many targets.
  const rows: RowSource = { pairsIn, named, width: feat.size + M };
  if (pairsIn || named !== undefined) checkMaxRows(p.MaxRows, rows.width);
  return new BatchRun(ctx, p, feat, rows, M, startup);
}

/**
 * MOSAIC's form: the Buffer named in Params is read when the model is built (only without a
 * pairs input, which is used instead, with a warning when it is another block).
 */
function namedBuffer(
  ctx: BlockContext,
  p: BatchParams,
  pairsIn: SignalInput | null,
): string | undefined {
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
  return named;
}

/** The number of targets in the pairs input's rows: what is not data; it must match Outputs. */
function pairsOutputs(p: BatchParams, feat: SignalInput, pairsIn: SignalInput): number {
  const d = feat.size;
  const m = pairsIn.size - d;
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
  return m;
}

/** MaxRows rows of `width` values must fit in MAX_VALUES. */
function checkMaxRows(maxRows: number, width: number): void {
  if (maxRows * width <= MAX_VALUES) return;
  throw new BlockConfigError(
    `MaxRows ${formatCount(maxRows)} rows of ${width} values would take up to ` +
      `${((maxRows * width * 8) / 2 ** 30).toFixed(1)} GiB; at most ${formatCount(MAX_VALUES)} ` +
      `values (1 GiB) are kept: set MaxRows to ${formatCount(Math.floor(MAX_VALUES / width))} or less`,
    "MaxRows",
  );
}

/** A running BatchPredictor: its model and the rows kept to fit it. */
export class BatchRun {
  /** The default file of the save and load actions. */
  readonly defaultFile: string;
  readonly slot: ModelSlot;
  /** The Buffer named in the params, read when the model is built (no pairs input). */
  readonly named: string | undefined;
  private readonly autoTrain: boolean;
  /** Dataset: replace (each frame of rows is a whole data set) or append. */
  private readonly replaceRows: boolean;
  private readonly maxRows: number;
  /** Values per feature event. */
  private readonly d: number;
  /** Values per prediction. */
  private readonly M: number;
  /** Values per row kept. */
  private readonly W: number;
  private readonly out: OutputPort;
  private readonly fitOut: OutputPort;
  /** The rows kept, W values each. */
  private values: Float64Array;
  private rows = 0;
  private dropped = 0;
  private warnedFull = false;
  /** Rows of the last fit; -1: none since creation, reset or load. */
  private fittedRows = -1;
  private readonly r2: Float64Array;
  private unlisten: (() => void) | undefined;

  /** Creates the model, declares the outputs and shows the first status text. */
  constructor(
    private readonly ctx: BlockContext,
    p: BatchParams,
    feat: SignalInput,
    source: RowSource,
    M: number,
    startup: StartupModel,
  ) {
    const d = feat.size;
    this.d = d;
    this.M = M;
    this.W = source.width;
    this.named = source.named;
    this.autoTrain = p.AutoTrain;
    this.replaceRows = p.Dataset === "replace";
    this.maxRows = p.MaxRows;
    this.defaultFile = p.File ?? `${ctx.name}.model.json`;
    const pairsIn = source.pairsIn;
    this.slot = new ModelSlot(
      ctx,
      startup,
      optionsFromParams(p, d, M),
      {
        expect: { inputs: d, outputs: M, inputName: feat.info.source, targetName: null },
        inputSource: feat.info.source,
        ...(pairsIn ? { targetSource: pairsIn.info.source } : {}),
      },
      {
        saved: () => this.describe(),
        loaded: () => {
          this.fittedRows = -1;
          this.describe();
        },
      },
    );
    // Named after the pairs' target columns when the Buffer names them (a Stimulus's gestures).
    const names = predictorMeta(pairsIn?.info.meta?.labels, M);
    this.out = ctx.output(vectorShape(M), "prediction", names?.prediction);
    this.fitOut = ctx.output(vectorShape(1 + M), "fit", names?.fit);
    this.values = new Float64Array(Math.min(this.maxRows, 256) * this.W);
    this.r2 = new Float64Array(M);
    this.describe();
  }

  // ---- status text ------------------------------------------------------------------------

  private describe(): void {
    let s = this.fitState();
    if (this.dropped > 0) s += `; ${formatCount(this.dropped)} rows dropped (MaxRows)`;
    this.ctx.setText(this.slot.withFileNote(s));
  }

  /** Fitted on the rows kept, rows waiting for a fit, or the model without rows. */
  private fitState(): string {
    const model = this.slot.model;
    const rows = this.rows;
    if (this.fittedRows >= 0 && this.fittedRows === rows) {
      model.r2(this.r2);
      return `fitted on ${plural(model.samplesSeen(), "row")}, ${formatR2(this.r2)}`;
    }
    if (rows > 0) {
      return (
        `${plural(rows, "row")} kept` +
        (this.fittedRows >= 0 ? "; fitted before on other rows" : "") +
        (this.autoTrain ? "" : " (press train)")
      );
    }
    if (this.named !== undefined && model.samplesSeen() === 0) {
      return (
        `untrained: reads the Buffer '${this.named}'` +
        (this.autoTrain ? " when a cluster ends" : " (press train)")
      );
    }
    if (model.samplesSeen() > 0) {
      model.r2(this.r2);
      return `trained on ${plural(model.samplesSeen(), "row")}, ${formatR2(this.r2)}; no rows kept`;
    }
    return "untrained: no rows yet";
  }

  // ---- rows and fits ----------------------------------------------------------------------

  /** Room for `need` rows (doubling, at most MaxRows), keeping the rows kept. */
  private grow(need: number): void {
    const W = this.W;
    let cap = this.values.length / W;
    if (need <= cap) return;
    while (cap < need) cap *= 2;
    cap = Math.min(cap, this.maxRows);
    const v = new Float64Array(cap * W);
    v.set(this.values.subarray(0, this.rows * W));
    this.values = v;
  }

  /** Rows from the pairs input: they replace or join the rows kept, then a fit with AutoTrain. */
  onRows(f: Frame): void {
    const n = f.n;
    if (this.replaceRows) this.dropRows();
    const take = Math.min(n, this.maxRows - this.rows);
    if (take < n) this.dropExtra(n - take);
    if (take > 0) {
      const W = this.W;
      this.grow(this.rows + take);
      const v = f.v;
      const values = this.values;
      const at = this.rows * W;
      for (let i = 0; i < take * W; i++) values[at + i] = v[i]!;
      this.rows += take;
    }
    if (this.autoTrain) this.fit(f.t[n - 1]!);
    else this.describe();
  }

  /** No rows kept, none dropped. */
  private dropRows(): void {
    this.rows = 0;
    this.dropped = 0;
    this.warnedFull = false;
  }

  /** `n` rows beyond MaxRows: counted, and a warning the first time. */
  private dropExtra(n: number): void {
    this.dropped += n;
    if (this.warnedFull) return;
    this.warnedFull = true;
    this.ctx.warn(
      `more rows than MaxRows (${formatCount(this.maxRows)}): ${formatCount(n)} dropped`,
    );
  }

  /** Fits the model on the rows kept and emits the fit at `t`; a sentence saying what happened. */
  fit(t: number): string {
    const rows = this.rows;
    if (rows === 0) return "no rows to fit";
    const model = this.slot.model;
    const used = model.fitPairs(this.values, rows);
    this.fittedRows = rows;
    model.r2(this.r2);
    this.emitFit(t, used);
    this.describe();
    const refused = rows - used;
    return (
      `fitted ${describeOptions(model.options)} on ${plural(used, "row")}` +
      (refused > 0 ? ` (${formatCount(refused)} refused)` : "") +
      `, in-sample ${formatR2(this.r2)}`
    );
  }

  /** [rows used, R² of each output] at `t` on the fit output. */
  private emitFit(t: number, used: number): void {
    const fo = this.fitOut.frame(1);
    fo.t[0] = t;
    fo.v[0] = used;
    for (let i = 0; i < this.M; i++) fo.v[1 + i] = this.r2[i]!;
    this.fitOut.emit(fo);
  }

  /** Replaces the rows by the named Buffer's and fits; a sentence saying what happened. */
  fitFromBuffer(t: number): string {
    const { d, M, W, named } = this;
    const b = lookup<BufferRows>(this.ctx, named!, "Buffer");
    if (typeof b === "string") throw new Error(`cannot read the Buffer: ${b}`);
    if (b.targetWidth !== M || b.dataWidth !== d) {
      throw new Error(
        `the Buffer '${named}' stores targets of ${b.targetWidth} and data of ${b.dataWidth} ` +
          `values; this model maps ${d} inputs to ${M} outputs`,
      );
    }
    const n = Math.min(b.rows(), this.maxRows);
    this.dropped = b.rows() - n;
    this.grow(n);
    this.values.set(b.values().subarray(0, n * W));
    this.rows = n;
    return this.fit(t);
  }

  /** Every feature event gives a prediction (zeros before the first fit). */
  onFeatures(f: Frame): void {
    const o = timedFrame(this.out, f);
    this.slot.model.predict(f.v, o.v, f.n);
    this.out.emit(o);
  }

  // ---- lifecycle and actions ----------------------------------------------------------------

  /**
   * With a named Buffer and AutoTrain: fit whenever the Buffer closes a cluster (in this block's
   * turn, not the Buffer's); otherwise on the train action, MOSAIC's "Build model".
   */
  start(): void {
    const named = this.named;
    if (named === undefined || this.unlisten) return;
    const b = lookup<BufferRows>(this.ctx, named, "Buffer");
    if (typeof b === "string") {
      this.ctx.warn(`Buffer '${named}' (Params): ${b}; the model cannot be trained from it`);
      return;
    }
    if (this.autoTrain) {
      const ctx = this.ctx;
      this.unlisten = b.onClusterClosed(() =>
        ctx.at(ctx.now(), (t) => {
          try {
            this.fitFromBuffer(t);
          } catch (e) {
            ctx.warn(errorMessage(e));
          }
        }),
      );
    }
  }

  reset(): void {
    this.slot.restore();
    this.dropRows();
    this.fittedRows = -1;
    this.describe();
  }

  dispose(): void {
    if (this.slot.disposed) return;
    this.unlisten?.();
    this.slot.dispose();
  }

  /** The train action: a fit on the named Buffer's rows, else on the rows kept. */
  train(): string {
    const now = this.ctx.now();
    return this.named !== undefined ? this.fitFromBuffer(now) : this.fit(now);
  }

  /** The clear action: drops the rows kept (the model stays). */
  clear(): string {
    const n = this.rows;
    this.dropRows();
    this.describe();
    return `dropped ${plural(n, "row")}`;
  }

  /** The reset action: an untrained model (the rows stay). */
  forget(): string {
    this.slot.model.reset();
    this.fittedRows = -1;
    this.describe();
    return "the model is untrained";
  }

  /** Writes the model to `file` in the background; what it does, for the save action. */
  save(file: string): string {
    saveModelFile(this.slot.files, file);
    return `saving the model to ${file}`;
  }

  inspect(): string {
    const model = this.slot.model;
    model.r2(this.r2);
    return (
      `${describeOptions(model.options)}: ${plural(this.rows, "row")} kept, fitted on ` +
      `${plural(model.samplesSeen(), "row")}; in-sample R² per output ${listR2(this.r2)}`
    );
  }
}

/** The block instance of a running predictor: the runtime's calls and the panel's actions. */
export function batchInstance(run: BatchRun): BlockInstance {
  const named = run.named;
  return {
    start: () => run.start(),
    process(f, port) {
      if (f.n === 0) return;
      if (port === 1) run.onRows(f);
      else run.onFeatures(f);
    },
    reset: () => run.reset(),
    dispose: () => run.dispose(),
    actions: {
      train: {
        label: "Train",
        description:
          named !== undefined
            ? `Fit the model on every row of the Buffer '${named}'`
            : "Fit the model on every row kept",
        run: () => run.train(),
      },
      clear: {
        label: "Clear rows",
        description: "Drop the rows kept (the model stays)",
        run: () => run.clear(),
      },
      reset: {
        label: "Reset model",
        description: "Forget the fitted model (predictions are 0 until the next fit)",
        run: () => run.forget(),
      },
      ...modelFileActions(run.slot.files, run.defaultFile, (file) => run.save(file)),
      inspect: {
        label: "Inspect",
        description: "Model, rows kept and the R² of every output",
        run: () => run.inspect(),
      },
    },
  };
}
