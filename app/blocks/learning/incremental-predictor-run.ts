/**
 * IncrementalPredictor: one predictor's running state and what changes it. Target events start,
 * switch and stop learning; every feature event is learnt (while a target is on and not paused)
 * and predicted. `openIncremental` checks the inputs and params and reads the model File;
 * `incrementalInstance` is the block instance (the runtime's calls and the panel's actions).
 */
import {
  BlockConfigError,
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type OutputPort,
} from "../../engine";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";
import { formatCount, formatVector, plural, TextThrottle } from "../shared/text";
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

/** The IncrementalPredictor's params (its zod schema's output). */
export interface IncrementalParams extends ModelParams {
  AutoSave: boolean;
}

/**
 * Checks the inputs against the params, reads the model File and creates the predictor: its
 * outputs and its first status text.
 */
export async function openIncremental(
  ctx: BlockContext,
  p: IncrementalParams,
): Promise<IncrementalRun> {
  const feat = signalInput(ctx, 0, "Inputs");
  const tgt = ctx.inputs.length > 1 ? signalInput(ctx, 1, "Outputs") : null;
  checkParams(p, feat, tgt);
  const outputs = tgt?.size ?? p.Outputs ?? null;
  const startup = await readStartupModel(ctx, p.File, {
    inputs: feat.size,
    outputs,
    inputName: feat.info.source,
    targetName: tgt?.info.source ?? null,
  });
  const M = startup.loaded?.outputs ?? outputs;
  if (M === null) {
    throw new BlockConfigError(
      "IncrementalPredictor needs a target input (its second input), Outputs, or an existing " +
        "File to know how many values it predicts",
      "Outputs",
    );
  }
  return new IncrementalRun(ctx, p, feat, tgt, M, startup);
}

/** Inputs and Outputs must match the inputs' widths; AutoSave needs a model that can be saved. */
function checkParams(p: IncrementalParams, feat: SignalInput, tgt: SignalInput | null): void {
  checkInputsParam(p.Inputs, feat);
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
}

/** A running IncrementalPredictor: its model, the current target and the learning state. */
export class IncrementalRun {
  /** The default file of the save and load actions (and of AutoSave). */
  readonly defaultFile: string;
  readonly slot: ModelSlot;
  private readonly autoSave: boolean;
  /** A target input is connected (else the block only predicts). */
  private readonly hasTargetInput: boolean;
  /** Values per feature event. */
  private readonly d: number;
  /** Values per prediction (and per target). */
  private readonly M: number;
  private readonly out: OutputPort;
  private readonly fitOut: OutputPort;
  /** [prediction…, target…] per feature event, for the panel's Training view (when read). */
  private readonly versusOut: OutputPort;
  private readonly target: Float64Array;
  private hasTarget = false;
  private paused = false;
  private learntSinceSave = 0;
  private readonly xrow: Float64Array;
  private readonly prow: Float64Array;
  private readonly before: Float64Array;
  private readonly r2: Float64Array;
  private readonly throttle = new TextThrottle();

  /** Creates the model, declares the outputs and shows the first status text. */
  constructor(
    private readonly ctx: BlockContext,
    p: IncrementalParams,
    feat: SignalInput,
    tgt: SignalInput | null,
    M: number,
    startup: StartupModel,
  ) {
    const d = feat.size;
    this.d = d;
    this.M = M;
    this.autoSave = p.AutoSave;
    this.hasTargetInput = tgt !== null;
    this.defaultFile = p.File ?? `${ctx.name}.model.json`;
    this.slot = new ModelSlot(
      ctx,
      startup,
      optionsFromParams(p, d, M),
      {
        expect: {
          inputs: d,
          outputs: M,
          inputName: feat.info.source,
          targetName: tgt?.info.source ?? null,
        },
        inputSource: feat.info.source,
        ...(tgt ? { targetSource: tgt.info.source } : {}),
      },
      {
        saved: () => this.describe(),
        loaded: () => {
          this.learntSinceSave = 0;
          this.describe();
        },
      },
    );
    // The outputs are named after the target's columns when it names them (a Stimulus's gestures).
    const names = predictorMeta(tgt?.size === M ? tgt.info.meta?.labels : undefined, M);
    this.out = ctx.output(vectorShape(M), "prediction", names?.prediction);
    this.fitOut = ctx.output(vectorShape(1 + M), "fit", names?.fit);
    this.versusOut = ctx.output(vectorShape(2 * M), "versus");
    this.target = new Float64Array(M);
    this.xrow = new Float64Array(d);
    this.prow = new Float64Array(M);
    this.before = new Float64Array(M);
    this.r2 = new Float64Array(M);
    this.describe();
  }

  // ---- status text ------------------------------------------------------------------------

  /** "untrained", or the samples learnt and the running R². */
  private progress(): string {
    const model = this.slot.model;
    const n = model.samplesSeen();
    if (n === 0) return "untrained";
    model.r2(this.r2);
    return `trained on ${plural(n, "sample")}, ${formatR2(this.r2)}`;
  }

  private describe(): void {
    const model = this.slot.model;
    let s: string;
    if (this.paused) s = `paused: ${this.progress()}`;
    else if (this.hasTarget) s = `learning ${formatVector(this.target, 6)}: ${this.progress()}`;
    else if (model.samplesSeen() === 0) {
      s = `untrained${this.hasTargetInput ? " (waiting for a target)" : ""}`;
    } else s = this.progress();
    const rejected = model.rejected();
    if (rejected > 0) s += `; ${formatCount(rejected)} refused (NaN or huge)`;
    this.ctx.setText(this.slot.withFileNote(s));
  }

  // ---- targets ----------------------------------------------------------------------------

  /**
   * Target events: a vector starts (or switches) training, all NaN stops it. The status text
   * changes at once when training starts or stops; a target stream that changes every event
   * (a Stimulus's ramps) updates it at most every 0.25 s, like the predictions.
   */
  onTarget(f: Frame): void {
    const was = this.hasTarget;
    for (let e = 0; e < f.n; e++) this.targetEvent(f.v, e * this.M);
    if (this.hasTarget !== was) {
      this.throttle.reset();
      this.describe();
    } else if (this.throttle.due(f.t[f.n - 1]!)) this.describe();
  }

  /**
   * The target event at `at` in `v`: all NaN stops learning (saving first with AutoSave), all
   * numbers are the new target, some NaN is ignored with a warning.
   */
  private targetEvent(v: Float64Array, at: number): void {
    const M = this.M;
    let nan = 0;
    for (let k = 0; k < M; k++) if (Number.isNaN(v[at + k]!)) nan++;
    if (nan === M) {
      if (this.hasTarget && this.autoSave && this.learntSinceSave > 0) this.save(this.defaultFile);
      this.hasTarget = false;
    } else if (nan > 0) {
      this.ctx.warn(
        `ignored a target event with ${nan} NaN of ${M} values: a target must be all ` +
          "numbers, and a stop all NaN",
      );
    } else {
      for (let k = 0; k < M; k++) this.target[k] = v[at + k]!;
      this.hasTarget = true;
    }
  }

  // ---- features ---------------------------------------------------------------------------

  /**
   * Every feature event gives a prediction; while a target is on (and not paused) it is learnt
   * first. Event by event only when the fit or versus output is read.
   */
  onFeatures(f: Frame): void {
    const n = f.n;
    const model = this.slot.model;
    const o = timedFrame(this.out, f);
    if (!this.hasTarget || this.paused) {
      model.predict(f.v, o.v, n);
      if (!this.versusOut.idle) this.emitVersus(o);
    } else if (this.fitOut.idle && this.versusOut.idle) {
      this.learntSinceSave += model.trainPredict(f.v, this.target, o.v, n);
    } else {
      this.learnEach(f, o);
    }
    this.out.emit(o);
    if (this.throttle.due(f.t[n - 1]!)) this.describe();
  }

  /** [prediction…, NaN…] of every event, for the versus output while nothing is learnt. */
  private emitVersus(o: Frame): void {
    const M = this.M;
    const vo = this.versusOut.frame(o.n);
    for (let e = 0; e < o.n; e++) {
      vo.t[e] = o.t[e]!;
      for (let i = 0; i < M; i++) {
        vo.v[e * 2 * M + i] = o.v[e * M + i]!;
        vo.v[e * 2 * M + M + i] = NaN;
      }
    }
    this.versusOut.emit(vo);
  }

  /**
   * One event at a time, to report the fit after every sample learnt and, when `versus` is
   * read, the prediction made before each sample is learnt.
   */
  private learnEach(f: Frame, o: Frame): void {
    const { d, M, xrow, prow, target } = this;
    const model = this.slot.model;
    const n = f.n;
    const ft = f.t;
    const fv = f.v;
    const fo = this.fitOut.frame(n);
    const vo = this.versusOut.idle ? null : this.versusOut.frame(n);
    let k = 0;
    for (let e = 0; e < n; e++) {
      for (let i = 0; i < d; i++) xrow[i] = fv[e * d + i]!;
      if (vo) this.versusBeforeLearning(vo, e, ft[e]!);
      const used = model.trainPredict(xrow, target, prow, 1);
      for (let i = 0; i < M; i++) o.v[e * M + i] = prow[i]!;
      if (used > 0) {
        this.learntSinceSave++;
        this.writeFit(fo, k, ft[e]!);
        k++;
      }
    }
    fo.n = k;
    this.fitOut.emit(fo);
    if (vo) this.versusOut.emit(vo);
  }

  /** Event `e` of `vo`: the prediction for `xrow` before it is learnt, and the target. */
  private versusBeforeLearning(vo: Frame, e: number, t: number): void {
    const { M, before, target } = this;
    this.slot.model.predict(this.xrow, before, 1);
    vo.t[e] = t;
    for (let i = 0; i < M; i++) {
      vo.v[e * 2 * M + i] = before[i]!;
      vo.v[e * 2 * M + M + i] = target[i]!;
    }
  }

  /** Event `k` of the fit frame: [samples seen, R² of each output] at time `t`. */
  private writeFit(fo: Frame, k: number, t: number): void {
    const { M, r2 } = this;
    const model = this.slot.model;
    const w = 1 + M;
    model.r2(r2);
    fo.t[k] = t;
    fo.v[k * w] = model.samplesSeen();
    for (let i = 0; i < M; i++) fo.v[k * w + 1 + i] = r2[i]!;
  }

  // ---- lifecycle and actions ----------------------------------------------------------------

  reset(): void {
    this.slot.restore();
    this.hasTarget = false;
    this.paused = false;
    this.learntSinceSave = 0;
    this.throttle.reset();
    this.describe();
  }

  dispose(): void {
    this.slot.dispose();
  }

  /** Writes the model to `file` in the background; what it does, for the save action. */
  save(file: string): string {
    const n = this.slot.model.samplesSeen();
    this.learntSinceSave = 0;
    saveModelFile(this.slot.files, file);
    return `saving the model (${plural(n, "sample")}) to ${file}`;
  }

  train(): string {
    this.paused = false;
    this.describe();
    return this.hasTarget
      ? `learning ${formatVector(this.target, 6)}`
      : "learning: waiting for a target event";
  }

  pause(): string {
    this.paused = true;
    this.describe();
    return `paused: ${this.progress()}`;
  }

  /** The reset action: an untrained model (the targets and pause stay). */
  forget(): string {
    const model = this.slot.model;
    const n = model.samplesSeen();
    model.reset();
    this.learntSinceSave = 0;
    this.describe();
    return `forgot ${plural(n, "sample")}`;
  }

  inspect(): string {
    const model = this.slot.model;
    model.r2(this.r2);
    return (
      `${describeOptions(model.options)}: ${plural(model.samplesSeen(), "sample")} ` +
      `learnt, ${formatCount(model.rejected())} refused, λ in use ` +
      `${model.effectiveLambda()}; R² per output ${listR2(this.r2)}` +
      (this.paused ? "; paused" : "")
    );
  }
}

/** The block instance of a running predictor: the runtime's calls and the panel's actions. */
export function incrementalInstance(run: IncrementalRun): BlockInstance {
  return {
    process(f, port) {
      if (f.n === 0) return;
      if (port === 1) run.onTarget(f);
      else run.onFeatures(f);
    },
    reset: () => run.reset(),
    dispose: () => run.dispose(),
    actions: {
      train: {
        label: "Train",
        description: "Learn from target events again (after pause)",
        run: () => run.train(),
      },
      pause: {
        label: "Pause",
        description: "Stop learning; predictions go on",
        run: () => run.pause(),
      },
      reset: {
        label: "Reset model",
        description: "Forget everything learnt (an untrained model; Ω and b of rff are kept)",
        run: () => run.forget(),
      },
      ...modelFileActions(run.slot.files, run.defaultFile, (file) => run.save(file)),
      inspect: {
        label: "Inspect",
        description: "Model, samples seen and R² of every output",
        run: () => run.inspect(),
      },
    },
  };
}
