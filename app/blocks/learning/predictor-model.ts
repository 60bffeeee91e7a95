/**
 * What the IncrementalPredictor and BatchPredictor blocks share: the Inputs check, the model File
 * read when the pipeline is created, the model in use (created from the params or the File,
 * replaced by the load action, restored by reset) with the host its save and load actions use,
 * and the save and load actions themselves.
 */
import {
  BlockConfigError,
  errorMessage,
  type BlockAction,
  type BlockContext,
  type Frame,
  type OutputPort,
} from "../../engine";
import type { LearningModel, ResolvedLearningOptions } from "../../engine/dsp";
import { inputName, type SignalInput } from "../shared/inputs";
import {
  createModel,
  isMissingFile,
  loadModel,
  loadModelAction,
  ModelFileError,
  modelFileArg,
  type ModelFileHost,
} from "./model-file";

/** Sizes and input names a model file must match (`outputs` null: any). */
export type ModelExpect = ModelFileHost["expect"];

/** The `Inputs` param, when given, must be the width of the features input. */
export function checkInputsParam(inputs: number | undefined, feat: SignalInput): void {
  if (inputs !== undefined && inputs !== feat.size) {
    throw new BlockConfigError(
      `Inputs is ${inputs} but the features input ${inputName(feat.info)} carries ${feat.size} ` +
        "values per event",
      "Inputs",
    );
  }
}

/** The model `File` as read when the pipeline is created. */
export interface StartupModel {
  /** The File's model, its state and its number of outputs, when the File exists. */
  loaded: { model: LearningModel; state: Float64Array; outputs: number } | null;
  /** What the status text says about the File: " (loaded F)", " (no F yet)" or "". */
  note: string;
}

/**
 * Reads the model `file` (none: no File param): a File that exists is the model. A file that
 * cannot be read, or that does not match `expect`, is a BlockConfigError on `File`.
 */
export async function readStartupModel(
  ctx: BlockContext,
  file: string | undefined,
  expect: ModelExpect,
): Promise<StartupModel> {
  if (file === undefined) return { loaded: null, note: "" };
  let text: string;
  try {
    text = await ctx.resources.readText(file);
  } catch (e) {
    if (!isMissingFile(e)) {
      throw new BlockConfigError(`cannot read model file '${file}': ${errorMessage(e)}`, "File");
    }
    return { loaded: null, note: ` (no ${file} yet)` };
  }
  try {
    const r = loadModel(text, file, expect);
    return {
      loaded: { model: r.model, state: r.file.state, outputs: r.file.options.outputs },
      note: ` (loaded ${file})`,
    };
  } catch (e) {
    if (e instanceof ModelFileError) throw new BlockConfigError(e.message, "File");
    throw e;
  }
}

/** What a ModelSlot tells its block. */
export interface ModelEvents {
  /** A save finished. */
  saved(): void;
  /** The load action replaced the model. */
  loaded(): void;
}

/**
 * A predictor block's model: the one its params or its File describe, until the load action
 * replaces it; reset goes back to it (its File's state, or untrained).
 */
export class ModelSlot {
  /** The model in use. */
  model: LearningModel;
  /** The last save's or load's message (`saved to F`); "" since creation or reset. */
  lastSaved = "";
  /** The host of the save and load actions. */
  readonly files: ModelFileHost;
  private disposedFlag = false;
  /** The model was replaced by the load action (reset goes back to the created one). */
  private replaced = false;
  private readonly created: ResolvedLearningOptions;
  private readonly initialState: Float64Array | null;
  private readonly note: string;

  /**
   * Creates the model (`fromParams` unless the File was loaded); `io` is what a loaded file must
   * match and the sources a saved file records.
   */
  constructor(
    ctx: BlockContext,
    startup: StartupModel,
    fromParams: ResolvedLearningOptions,
    io: Pick<ModelFileHost, "expect" | "inputSource" | "targetSource">,
    events: ModelEvents,
  ) {
    const loaded = startup.loaded;
    this.created = loaded ? loaded.model.options : fromParams;
    this.model = loaded ? loaded.model : createModel(this.created);
    this.initialState = loaded?.state ?? null;
    this.note = startup.note;
    this.files = {
      ctx,
      model: () => this.model,
      ...io,
      alive: () => !this.disposedFlag,
      onSaved: (message) => {
        this.lastSaved = message;
        events.saved();
      },
      onLoaded: (model, message) => {
        this.model.dispose();
        this.model = model;
        this.replaced = true;
        this.lastSaved = message;
        events.loaded();
      },
    };
  }

  get disposed(): boolean {
    return this.disposedFlag;
  }

  /** A status text followed by the last save's or load's message, else the File's note. */
  withFileNote(s: string): string {
    return s + (this.lastSaved !== "" ? ` (${this.lastSaved})` : this.note);
  }

  /** Back to the model as created: the File's state, or untrained; forgets the last save. */
  restore(): void {
    if (this.replaced) {
      this.model.dispose();
      this.model = createModel(this.created);
      this.replaced = false;
    }
    if (this.initialState) this.model.loadState(this.initialState);
    else this.model.reset();
    this.lastSaved = "";
  }

  dispose(): void {
    if (this.disposedFlag) return;
    this.disposedFlag = true;
    this.model.dispose();
  }
}

/** A frame of `out` for the events of `f`, with their times (the values are to be written). */
export function timedFrame(out: OutputPort, f: Frame): Frame {
  const n = f.n;
  const o = out.frame(n);
  const ft = f.t;
  for (let e = 0; e < n; e++) o.t[e] = ft[e]!;
  return o;
}

/**
 * The `save` and `load` actions of a predictor block: `save` writes the model with `save(file)`
 * (which says what it does), `load` replaces it by a file's.
 */
export function modelFileActions(
  files: ModelFileHost,
  defaultFile: string,
  save: (file: string) => string,
): { save: BlockAction; load: BlockAction } {
  return {
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
  };
}
