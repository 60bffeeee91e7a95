/**
 * The model shared by the BatchPredictor and IncrementalPredictor blocks: its params (zod), MOSAIC's
 * positional forms, and its file format (`docs/model-format.md`): one JSON document, a flat header
 * a person can read (kind, sizes, hyper-parameters, samples seen, R², date) followed by the arrays
 * (weights, Ω and b for RFF, the normal equations for incremental learning), matrices one row per
 * line. Loading validates everything and throws a `ModelFileError` that names the file and what is
 * wrong with it; the Rust core then checks the numbers (symmetric, positive definite, weights that
 * match the normal equations).
 */
import { z } from "zod";
import {
  BlockConfigError,
  errorMessage,
  LegacyParamsError,
  legacyInteger,
  legacyNumber,
  type BlockContext,
} from "../../engine";
import {
  LEARNING_DEFAULTS,
  LearningModel,
  type ModelKindName,
  type ResolvedLearningOptions,
  type StateSection,
} from "../../engine/dsp";

export const MODEL_FORMAT = "mosaic-model";
export const MODEL_VERSION = 1;

/** Largest input width of a ridge model and largest D of an RFF model (p × p matrices). */
export const MAX_DIM = 2048;
export const MAX_OUTPUTS = 4096;

// ---------------------------------------------------------------------------------------------
// Params

/** The model params both predictor blocks take (fields of their zod object). */
export const modelParams = {
  Model: z
    .enum(["ridge", "rff", "lda"])
    .default("ridge")
    .describe(
      "ridge: linear ridge regression (paper eqs. 5–6); rff: ridge on random Fourier features " +
        "(nonlinear, an RBF-kernel approximation); lda: linear discriminant analysis, a " +
        "classifier whose classes are the distinct target vectors. MOSAIC's names " +
        "(IncrementalRidgeRegression, IncrementalRFF, IncrementalLDA, RidgeRegression, RR_RFF) " +
        "load through the positional form",
    ),
  Shrinkage: z
    .number()
    .min(0)
    .max(1)
    .default(0)
    .describe(
      "lda: α in [0, 1], the covariance used is (1 − α)Σ + α·(tr Σ/d)·I (scikit-learn's " +
        "shrinkage; helps with few samples per input)",
    ),
  MaxClasses: z
    .number()
    .int()
    .min(1)
    .max(1024)
    .default(32)
    .describe("lda: most classes (distinct targets) kept; samples of further classes are refused"),
  LdaOutput: z
    .enum(["scores", "class"])
    .default("scores")
    .describe(
      "lda: scores = the class targets weighted by their posterior probabilities (with one-hot " +
        "targets, the class probabilities); class = the most probable class's target (one-hot)",
    ),
  Lambda: z
    .number()
    .min(1e-50)
    .max(1e50)
    .default(1)
    .describe(
      "λ from 1e-50 to 1e50, the ridge penalty (larger: smoother, less fitted; MOSAIC's default 1)",
    ),
  Gamma: z
    .number()
    .gt(0)
    .default(0.5)
    .describe(
      "rff: γ of the RBF kernel exp(−γ‖x − x′‖²) (scikit-learn's RBFSampler gamma); the default " +
        "0.5 is MOSAIC's σ = 1. With Normalize, about 1 / Inputs is a good start",
    ),
  Features: z
    .number()
    .int()
    .min(1)
    .max(MAX_DIM)
    .default(300)
    .describe("rff: D, the number of random features (MOSAIC's default 300)"),
  Seed: z
    .number()
    .int()
    .min(0)
    .default(0)
    .describe("rff: seed of the random features Ω and b (same seed, same model)"),
  Forgetting: z
    .number()
    .gt(0)
    .max(1)
    .default(1)
    .describe(
      "β in (0, 1]: a sample learnt k samples ago weighs β^k (1 = remember everything; 0.999 " +
        "halves a sample's weight after 693 samples)",
    ),
  Intercept: z
    .boolean()
    .default(true)
    .describe(
      "Fit an intercept (not penalised, as scikit-learn's Ridge); false: ŷ = Wᵀx exactly as " +
        "the paper's eq. 6 and MOSAIC 1",
    ),
  Normalize: z
    .boolean()
    .default(false)
    .describe(
      "Standardise every input with the statistics of the training samples (see the help: " +
        "exact for ridge; for rff the statistics freeze after NormalizeSamples samples)",
    ),
  NormalizeSamples: z
    .number()
    .int()
    .min(2)
    .max(100_000)
    .default(200)
    .describe("rff with Normalize: training samples whose statistics are used, then frozen"),
  Inputs: z
    .number()
    .int()
    .min(1)
    .optional()
    .describe("Expected values per feature event (checked against the features input)"),
  Outputs: z
    .number()
    .int()
    .min(1)
    .max(MAX_OUTPUTS)
    .optional()
    .describe(
      "Expected values per target and prediction (checked against the target input; needed " +
        "when there is none and no File)",
    ),
  File: z
    .string()
    .min(1)
    .optional()
    .describe(
      "Model file (relative to the pipeline file): loaded at start if it exists, and the default " +
        "file of the save and load actions",
    ),
};

export interface ModelParams {
  Model: ModelKindName;
  Lambda: number;
  Gamma: number;
  Features: number;
  Seed: number;
  Shrinkage: number;
  MaxClasses: number;
  LdaOutput: "scores" | "class";
  Forgetting: number;
  Intercept: boolean;
  Normalize: boolean;
  NormalizeSamples: number;
  Inputs?: number | undefined;
  Outputs?: number | undefined;
  File?: string | undefined;
}

export const MODEL_HELP =
  "Models (paper III-G): `ridge` fits ŷ = Wᵀx + b with W = (XᵀX + λI)⁻¹XᵀY on centred data, so " +
  "that the intercept b is not penalised (scikit-learn's `Ridge`; `Intercept: false` gives the " +
  "paper's eq. 6 as written, MOSAIC 1's model); `rff` first maps x to D random Fourier features " +
  "z = √(2/D)·cos(Ωx + b), Ω ~ N(0, 2γ), b ~ U(0, 2π) (Rahimi & Recht 2007; scikit-learn's " +
  "`RBFSampler`), then fits ridge on z. Learning is exact: incremental updates keep the Cholesky " +
  "factor of the normal equations (one rank-one update per sample), so after n samples the model " +
  "equals the batch fit of those n samples; `Forgetting` β < 1 weighs older samples less. " +
  "Samples with a NaN, an infinity or a value beyond ±1e50 are refused and counted. " +
  "`Normalize` standardises the inputs (mean 0, sd 1 over the training samples; a constant " +
  "input is only centred): for ridge exactly, as a penalty λ·sd² on each raw weight re-derived " +
  "whenever an sd moves by 10 % (the centring is the intercept's: without intercept the inputs " +
  "are only scaled); for rff the statistics freeze after `NormalizeSamples` training samples, " +
  "which are then learnt again (a one-off cost of that many updates). `lda` is linear " +
  "discriminant analysis learnt per sample: the classes are the distinct target vectors (a " +
  "one-hot eₖ, or MOSAIC's targets such as rest = all zeros), their means and the pooled " +
  "within-class covariance are updated per sample (exactly the batch LDA of the samples so far, " +
  "scikit-learn's LinearDiscriminantAnalysis with the lsqr solver and `Shrinkage`), and a " +
  "prediction is the targets weighted by the class probabilities (`LdaOutput: scores`) or the " +
  "most probable class's target (`class`); it has no λ, intercept, forgetting or normalisation, " +
  "and no model file yet. Model files: JSON, see " +
  "docs/model-format.md; a file that does not match the inputs is refused with a message naming " +
  "the file and the mismatch.";

/** The learning options of params, for `inputs` features and `outputs` targets. */
export function optionsFromParams(
  p: ModelParams,
  inputs: number,
  outputs: number,
): ResolvedLearningOptions {
  return {
    kind: p.Model,
    inputs,
    outputs,
    lambda: p.Lambda,
    forgetting: p.Forgetting,
    intercept: p.Intercept,
    normalize: p.Normalize,
    normalizeSamples: p.NormalizeSamples,
    features: p.Features,
    gamma: p.Gamma,
    seed: p.Seed,
    shrinkage: p.Shrinkage,
    maxClasses: p.MaxClasses,
    ldaOutput: p.LdaOutput,
  };
}

/** "rff (D 300, γ 0.5, λ 1)". */
export function describeOptions(o: ResolvedLearningOptions): string {
  if (o.kind === "lda") {
    return `lda (${o.ldaOutput}${o.shrinkage > 0 ? `, shrinkage ${o.shrinkage}` : ""})`;
  }
  const parts =
    o.kind === "rff" ? [`D ${o.features}`, `γ ${o.gamma}`, `λ ${o.lambda}`] : [`λ ${o.lambda}`];
  if (o.forgetting !== 1) parts.push(`β ${o.forgetting}`);
  if (!o.intercept) parts.push("no intercept");
  if (o.normalize) parts.push("normalized");
  return `${o.kind} (${parts.join(", ")})`;
}

/** Which params a Rust error is about (for BlockConfigError). */
function paramOf(message: string): string | undefined {
  const m =
    /^(Lambda|Gamma|Features|Forgetting|Inputs|Outputs|NormalizeSamples|Normalize|Shrinkage|MaxClasses)\b/.exec(
      message,
    );
  return m?.[1];
}

/** Creates the model; every refusal becomes a BlockConfigError naming the param. */
export function createModel(o: ResolvedLearningOptions): LearningModel {
  try {
    return new LearningModel(o);
  } catch (e) {
    const msg = errorMessage(e);
    throw new BlockConfigError(`cannot create the ${o.kind} model: ${msg}`, paramOf(msg));
  }
}

/**
 * MOSAIC's learning machines by name (`Params: [IncrementalRFF, 8, 12, λ, σ, D]`), as named
 * params. MOSAIC 1 had no intercept and drew Ω ~ N(0, σ²) with features cos(Ωx + b) without the
 * √(2/D) factor: the same model here has γ = σ²/2 and λ·2/D.
 */
export function legacyMachine(
  name: string,
  dims: readonly string[],
  hyper: readonly string[],
  accepted: readonly string[],
): Record<string, unknown> {
  if (!accepted.includes(name)) {
    throw new LegacyParamsError(
      `unknown learning machine '${name}'; expected one of ${accepted.join(", ")}`,
      "Model",
    );
  }
  if (dims.length < 2) {
    throw new LegacyParamsError(
      `expected the input and output sizes after '${name}', e.g. [${name}, 8, 12]`,
      "Inputs",
    );
  }
  const inputs = legacyInteger(dims[0]!, "input size", "Inputs");
  const outputs = legacyInteger(dims[1]!, "output size", "Outputs");
  if (name.includes("LDA")) {
    // The original's IncrementalLDA took no hyper-parameters (it ignored any).
    if (hyper.length > 0) {
      throw new LegacyParamsError(
        `${name} takes no hyper-parameters (MOSAIC ignored them); got [${hyper.join(", ")}]`,
      );
    }
    return { Model: "lda", Inputs: inputs, Outputs: outputs };
  }
  const lambda = hyper[0] !== undefined ? legacyNumber(hyper[0], "lambda", "Lambda") : 1;
  const rff = name.includes("RFF");
  if (!rff) {
    if (hyper.length > 1) {
      throw new LegacyParamsError(
        `${name} takes one hyper-parameter (lambda); got ${hyper.length}`,
      );
    }
    return { Model: "ridge", Inputs: inputs, Outputs: outputs, Lambda: lambda, Intercept: false };
  }
  if (hyper.length > 3) {
    throw new LegacyParamsError(`${name} takes lambda, sigma and D; got ${hyper.length} values`);
  }
  const sigma = hyper[1] !== undefined ? legacyNumber(hyper[1], "sigma", "Gamma") : 1;
  const d = hyper[2] !== undefined ? legacyInteger(hyper[2], "D", "Features") : 300;
  if (!(d >= 1)) throw new LegacyParamsError(`D is ${d}; expected at least 1`, "Features");
  return {
    Model: "rff",
    Inputs: inputs,
    Outputs: outputs,
    Lambda: (lambda * 2) / d,
    Gamma: (sigma * sigma) / 2,
    Features: d,
    Intercept: false,
  };
}

// ---------------------------------------------------------------------------------------------
// Files

/** A model file that cannot be used: the message starts with the file name. */
export class ModelFileError extends Error {
  constructor(
    readonly file: string,
    problem: string,
  ) {
    super(`model file '${file}': ${problem}`);
    this.name = "ModelFileError";
  }
}

/** True for a read error that means "there is no such file" (then a File is simply not there yet). */
export function isMissingFile(e: unknown): boolean {
  const code = (e as { code?: unknown } | null)?.code;
  return code === "ENOENT" || /ENOENT|no such file|not found/i.test(errorMessage(e));
}

export interface ModelFileMeta {
  /** Block that wrote it. */
  block?: string;
  blockType?: string;
  /** ISO date of writing. */
  created: string;
  /** Where the inputs came from (the features input's source), for people reading the file. */
  inputSource?: string;
  targetSource?: string;
  featureNames?: readonly string[];
}

/** A read model file, ready to build the model from. */
export interface ModelFile {
  options: ResolvedLearningOptions;
  samplesSeen: number;
  created: string;
  block: string | null;
  /** The flat state in the model's section order (see `LearningModel.stateSections`). */
  state: Float64Array;
}

const num = (x: number): string => (Number.isFinite(x) ? String(x) : "null");

function vector(v: ArrayLike<number>, from = 0, to = v.length): string {
  const parts: string[] = [];
  for (let i = from; i < to; i++) parts.push(num(v[i]!));
  return `[${parts.join(", ")}]`;
}

function matrix(v: ArrayLike<number>, at: number, rows: number, cols: number, ind: string): string {
  const lines: string[] = [];
  for (let r = 0; r < rows; r++)
    lines.push(`${ind}  ${vector(v, at + r * cols, at + (r + 1) * cols)}`);
  return `[\n${lines.join(",\n")}\n${ind}]`;
}

/** Writes a model as a model file (text). */
export function serializeModel(model: LearningModel, meta: ModelFileMeta): string {
  const o = model.options;
  if (o.kind === "lda") {
    throw new Error(
      "LDA models cannot be saved to a model file yet (the format, docs/model-format.md, holds ridge and rff models)",
    );
  }
  const p = model.dim;
  const w = new StateWriter(o, p, model.saveState(), model.stateSections());
  const r2 = new Float64Array(o.outputs);
  model.r2(r2);
  const lines = w.header(meta, r2);
  lines.push(w.model(), w.normalizer(), w.stats());
  return `{\n${lines.join(",\n")}\n}\n`;
}

/**
 * One line of the file's top-level object: `"key": value`, the value written as is (JSON text, a
 * number or a boolean).
 */
const field = (key: string, value: unknown): string =>
  `  ${JSON.stringify(key)}: ${value as string}`;

/** Indentation of the arrays inside the file's "model" and "state" objects. */
const IND = "    ";

/** Writes a model's flat state, section by section, as the file's header and arrays. */
class StateWriter {
  /** Offset of each section in the flat state. */
  private readonly at: Record<string, number> = {};
  private readonly d: number;
  private readonly m: number;
  private readonly rff: boolean;

  constructor(
    private readonly o: ResolvedLearningOptions,
    /** Columns of the normal equations: features for rff, else inputs (the model's `dim`). */
    private readonly p: number,
    private readonly state: Float64Array,
    sections: readonly StateSection[],
  ) {
    this.d = o.inputs;
    this.m = o.outputs;
    this.rff = o.kind === "rff";
    let k = 0;
    for (const s of sections) {
      this.at[s.name] = k;
      k += s.length;
    }
  }

  /** The flat header: format, options, samples seen, R² and where the model came from. */
  header(meta: ModelFileMeta, r2: Float64Array): string[] {
    const { o, rff, state } = this;
    const meta3 = this.of("meta");
    return [
      field("format", JSON.stringify(MODEL_FORMAT)),
      field("version", MODEL_VERSION),
      field("kind", JSON.stringify(o.kind)),
      field("inputs", this.d),
      field("outputs", this.m),
      field("lambda", num(o.lambda)),
      field("gamma", rff ? num(o.gamma) : "null"),
      field("D", rff ? o.features : "null"),
      field("seed", rff ? o.seed : "null"),
      field("forgetting", num(o.forgetting)),
      field("intercept", o.intercept),
      field("normalize", o.normalize),
      field("normalizeSamples", rff && o.normalize ? o.normalizeSamples : "null"),
      field("samplesSeen", state[meta3]!),
      field("lambdaEffective", num(state[meta3 + 2]!)),
      field("r2", vector(r2)),
      field("created", JSON.stringify(meta.created)),
      field("block", meta.block !== undefined ? JSON.stringify(meta.block) : "null"),
      field("blockType", meta.blockType !== undefined ? JSON.stringify(meta.blockType) : "null"),
      field(
        "inputSource",
        meta.inputSource !== undefined ? JSON.stringify(meta.inputSource) : "null",
      ),
      field(
        "targetSource",
        meta.targetSource !== undefined ? JSON.stringify(meta.targetSource) : "null",
      ),
      field("featureNames", meta.featureNames ? JSON.stringify(meta.featureNames) : "null"),
    ];
  }

  /** `"model"`: the weights, intercept and penalty, and for rff Ω and the offsets b. */
  model(): string {
    const { p, m, d } = this;
    const parts = [
      `${IND}"weights": ${this.matrix("weights", p, m)}`,
      `${IND}"intercept": ${this.vector("intercept", m)}`,
      `${IND}"penalty": ${this.vector("penalty", p)}`,
    ];
    if (this.rff) {
      parts.push(`${IND}"omega": ${this.matrix("omega", p, d)}`);
      parts.push(`${IND}"offset": ${this.vector("offset", p)}`);
    }
    return `  "model": {\n${parts.join(",\n")}\n  }`;
  }

  /** `"normalizer"`: the input normalizer's count, frozen flag, means and M2; null without one. */
  normalizer(): string {
    if (!this.o.normalize) return `  "normalizer": null`;
    const { d, state } = this;
    const n0 = this.of("normalizer");
    return (
      `  "normalizer": {"count": ${num(state[n0]!)}, "frozen": ${state[n0 + 1] === 1}, ` +
      `"mean": ${vector(state, n0 + 2, n0 + 2 + d)}, "m2": ${vector(state, n0 + 2 + d, n0 + 2 + 2 * d)}}`
    );
  }

  /** `"state"`: the normal equations and the fit statistics, to go on learning from. */
  stats(): string {
    const { p, m, state } = this;
    const meta3 = this.of("meta");
    const f0 = this.of("fit_stats");
    const parts = [
      `${IND}"weightSum": ${num(state[meta3 + 1]!)}`,
      `${IND}"xMean": ${this.vector("x_mean", p)}`,
      `${IND}"yMean": ${this.vector("y_mean", m)}`,
      `${IND}"scatter": ${this.matrix("scatter", p, p)}`,
      `${IND}"cross": ${this.matrix("cross", p, m)}`,
      `${IND}"fitStats": {"weight": ${num(state[f0]!)}, "mean": ${vector(state, f0 + 1, f0 + 1 + m)}, ` +
        `"m2": ${vector(state, f0 + 1 + m, f0 + 1 + 2 * m)}, "sse": ${vector(state, f0 + 1 + 2 * m, f0 + 1 + 3 * m)}}`,
    ];
    return `  "state": {\n${parts.join(",\n")}\n  }`;
  }

  /** Offset of section `name` in the flat state; an error when the model has none. */
  private of(name: string): number {
    const i = this.at[name];
    if (i === undefined) throw new Error(`model state has no section '${name}'`);
    return i;
  }

  /** The first `length` values of section `name`, as a JSON array. */
  private vector(name: string, length: number): string {
    const i = this.of(name);
    return vector(this.state, i, i + length);
  }

  /** Section `name` as a rows × cols JSON matrix, one row per line. */
  private matrix(name: string, rows: number, cols: number): string {
    return matrix(this.state, this.of(name), rows, cols, IND);
  }
}

type Json = unknown;

/** Validating accessors that name the path of what is wrong. */
class Check {
  constructor(readonly file: string) {}

  fail(problem: string): never {
    throw new ModelFileError(this.file, problem);
  }

  object(v: Json, path: string): Record<string, Json> {
    if (typeof v !== "object" || v === null || Array.isArray(v)) {
      this.fail(`${path} is ${describe(v)}; expected an object`);
    }
    return v as Record<string, Json>;
  }

  number(v: Json, path: string, ok: (x: number) => boolean, expected: string): number {
    if (typeof v !== "number" || !Number.isFinite(v) || !ok(v)) {
      this.fail(`${path} is ${describe(v)}; expected ${expected}`);
    }
    return v;
  }

  int(v: Json, path: string, min: number, max: number, expected: string): number {
    return this.number(v, path, (x) => Number.isInteger(x) && x >= min && x <= max, expected);
  }

  bool(v: Json, path: string): boolean {
    if (typeof v !== "boolean") this.fail(`${path} is ${describe(v)}; expected true or false`);
    return v;
  }

  /** `len` finite numbers into `out` at `at`. */
  vector(v: Json, path: string, len: number, what: string, out: Float64Array, at: number): void {
    if (!Array.isArray(v))
      this.fail(`${path} is ${describe(v)}; expected a list of ${len} numbers`);
    if (v.length !== len) this.fail(`${path} has ${v.length} values; expected ${len} (${what})`);
    for (let i = 0; i < len; i++) {
      const x: Json = v[i];
      if (typeof x !== "number" || !Number.isFinite(x)) {
        this.fail(`${path}[${i}] is ${describe(x)}; expected a finite number`);
      }
      out[at + i] = x;
    }
  }

  /** `rows` lists of `cols` finite numbers, row-major into `out` at `at`. */
  matrix(
    v: Json,
    path: string,
    rows: number,
    cols: number,
    rowWhat: string,
    colWhat: string,
    out: Float64Array,
    at: number,
  ): void {
    if (!Array.isArray(v)) {
      this.fail(`${path} is ${describe(v)}; expected ${rows} rows of ${cols} numbers`);
    }
    if (v.length !== rows) this.fail(`${path} has ${v.length} rows; expected ${rows} (${rowWhat})`);
    for (let r = 0; r < rows; r++) {
      this.vector(v[r], `${path}[${r}]`, cols, colWhat, out, at + r * cols);
    }
  }
}

function describe(v: Json): string {
  if (v === undefined) return "missing";
  if (v === null) return "null";
  if (typeof v === "string") return JSON.stringify(v.length > 30 ? v.slice(0, 30) + "…" : v);
  if (Array.isArray(v)) return `a list of ${v.length}`;
  if (typeof v === "object") return "an object";
  return String(v);
}

/**
 * Reads and checks a model file's text (structure, sizes, hyper-parameters, every array's shape
 * and values). The numbers themselves are checked again by the Rust core when the state is
 * loaded (`buildModel`).
 */
export function parseModelFile(text: string, file: string): ModelFile {
  const c = new Check(file);
  const top = c.object(parseJson(c, text), "the file");
  checkFormat(c, top);
  const options = readOptions(c, top);
  const samples = c.int(
    top.samplesSeen,
    "samplesSeen",
    0,
    Number.MAX_SAFE_INTEGER,
    "a whole number >= 0",
  );
  const lambdaEff = c.number(top.lambdaEffective, "lambdaEffective", (x) => x > 0, "a number > 0");
  const created = typeof top.created === "string" ? top.created : "";
  const block = typeof top.block === "string" ? top.block : null;
  const state = new StateReader(c, top, options, samples, lambdaEff).read();
  return { options, samplesSeen: samples, created, block, state };
}

function parseJson(c: Check, text: string): Json {
  try {
    return JSON.parse(text);
  } catch (e) {
    // Not JSON.parse's whole message: it quotes the text around the error (`"root:$6$ab"...`).
    const said = JSON.stringify(errorMessage(e).split(', "')[0]).slice(1, -1);
    c.fail(`not a MOSAIC model file: invalid JSON (${said})`);
  }
}

/** The format name and a version this MOSAIC reads. */
function checkFormat(c: Check, top: Record<string, Json>): void {
  if (top.format !== MODEL_FORMAT) {
    c.fail(
      `not a MOSAIC model file: "format" is ${describe(top.format)}; expected "${MODEL_FORMAT}"`,
    );
  }
  const version = c.int(top.version, "version", 1, Number.MAX_SAFE_INTEGER, "a whole number");
  if (version > MODEL_VERSION) {
    c.fail(
      `format version ${version} is newer than this MOSAIC reads (${MODEL_VERSION}); update MOSAIC`,
    );
  }
}

/** Kind, sizes and hyper-parameters (the rff ones only for rff). */
function readOptions(c: Check, top: Record<string, Json>): ResolvedLearningOptions {
  if (top.kind !== "ridge" && top.kind !== "rff") {
    c.fail(`kind is ${describe(top.kind)}; expected "ridge" or "rff"`);
  }
  const kind = top.kind as ModelKindName;
  const rff = kind === "rff";
  const d = c.int(top.inputs, "inputs", 1, rff ? 1 << 22 : MAX_DIM, "a whole number of inputs");
  const m = c.int(top.outputs, "outputs", 1, MAX_OUTPUTS, "a whole number of outputs (1–4096)");
  const options: ResolvedLearningOptions = {
    kind,
    inputs: d,
    outputs: m,
    lambda: c.number(
      top.lambda,
      "lambda",
      (x) => x >= 1e-50 && x <= 1e50,
      "a number from 1e-50 to 1e50",
    ),
    forgetting: c.number(
      top.forgetting,
      "forgetting",
      (x) => x > 0 && x <= 1,
      "a number in (0, 1]",
    ),
    intercept: c.bool(top.intercept, "intercept"),
    normalize: c.bool(top.normalize, "normalize"),
    normalizeSamples: LEARNING_DEFAULTS.normalizeSamples,
    features: LEARNING_DEFAULTS.features,
    gamma: LEARNING_DEFAULTS.gamma,
    seed: 0,
    shrinkage: LEARNING_DEFAULTS.shrinkage,
    maxClasses: LEARNING_DEFAULTS.maxClasses,
    ldaOutput: LEARNING_DEFAULTS.ldaOutput,
  };
  if (rff) readRffOptions(c, top, options);
  return options;
}

function readRffOptions(
  c: Check,
  top: Record<string, Json>,
  options: ResolvedLearningOptions,
): void {
  options.gamma = c.number(top.gamma, "gamma", (x) => x > 0, "a number > 0");
  options.features = c.int(top.D, "D", 1, MAX_DIM, "a whole number of features (1–2048)");
  options.seed = c.int(top.seed ?? 0, "seed", 0, Number.MAX_SAFE_INTEGER, "a whole number >= 0");
  if (options.normalize) {
    options.normalizeSamples = c.int(
      top.normalizeSamples,
      "normalizeSamples",
      2,
      100_000,
      "a whole number of samples (2–100000)",
    );
  }
}

/** The flat state's sections and lengths, in the Rust order (mosaic-learn `Model::state_sections`). */
function stateSections(o: ResolvedLearningOptions): [string, number][] {
  const rff = o.kind === "rff";
  const d = o.inputs;
  const m = o.outputs;
  const p = rff ? o.features : d;
  const sections: [string, number][] = [];
  if (o.normalize) sections.push(["normalizer", 2 + 2 * d]);
  if (rff) sections.push(["omega", p * d], ["offset", p]);
  sections.push(
    ["meta", 3],
    ["penalty", p],
    ["x_mean", p],
    ["y_mean", m],
    ["scatter", p * p],
    ["cross", p * m],
    ["weights", p * m],
    ["intercept", m],
    ["fit_stats", 1 + 3 * m],
  );
  return sections;
}

/** Checks the file's arrays and copies them, section by section, into the flat state. */
class StateReader {
  private readonly d: number;
  private readonly m: number;
  /** Columns of the normal equations: features for rff, else inputs. */
  private readonly p: number;
  /** What each of the `p` values is, for the messages. */
  private readonly inputs: string;
  private readonly model: Record<string, Json>;
  private readonly st: Record<string, Json>;
  private readonly fitStats: Record<string, Json>;
  private readonly norm: Record<string, Json> | null;
  private readonly sections: [string, number][];
  private readonly state: Float64Array;

  constructor(
    private readonly c: Check,
    top: Record<string, Json>,
    options: ResolvedLearningOptions,
    private readonly samples: number,
    private readonly lambdaEff: number,
  ) {
    const rff = options.kind === "rff";
    this.d = options.inputs;
    this.m = options.outputs;
    this.p = rff ? options.features : this.d;
    this.inputs = rff ? "one per feature" : "one per input";
    this.model = c.object(top.model, "model");
    this.st = c.object(top.state, "state");
    this.fitStats = c.object(this.st.fitStats, "state.fitStats");
    this.norm = options.normalize ? c.object(top.normalizer, "normalizer") : null;
    this.sections = stateSections(options);
    this.state = new Float64Array(this.sections.reduce((s, x) => s + x[1], 0));
  }

  read(): Float64Array {
    let at = 0;
    for (const [name, len] of this.sections) {
      this.section(name, at);
      at += len;
    }
    return this.state;
  }

  private section(name: string, at: number): void {
    const { c, model, st, state, p, m, inputs } = this;
    switch (name) {
      case "normalizer":
        this.normalizer(at);
        break;
      case "omega":
        c.matrix(
          model.omega,
          "model.omega",
          p,
          this.d,
          "one per feature",
          "one per input",
          state,
          at,
        );
        break;
      case "offset":
        c.vector(model.offset, "model.offset", p, "one per feature", state, at);
        break;
      case "meta":
        this.meta(at);
        break;
      case "penalty":
        c.vector(model.penalty, "model.penalty", p, inputs, state, at);
        break;
      case "x_mean":
        c.vector(st.xMean, "state.xMean", p, inputs, state, at);
        break;
      case "y_mean":
        c.vector(st.yMean, "state.yMean", m, "one per output", state, at);
        break;
      case "scatter":
        c.matrix(st.scatter, "state.scatter", p, p, inputs, inputs, state, at);
        break;
      case "cross":
        c.matrix(st.cross, "state.cross", p, m, inputs, "one per output", state, at);
        break;
      case "weights":
        c.matrix(model.weights, "model.weights", p, m, inputs, "one per output", state, at);
        break;
      case "intercept":
        c.vector(model.intercept, "model.intercept", m, "one per output", state, at);
        break;
      case "fit_stats":
        this.fitStatsSection(at);
        break;
    }
  }

  private normalizer(at: number): void {
    const { c, state, d } = this;
    const n = this.norm!;
    state[at] = c.number(n.count, "normalizer.count", (x) => x >= 0, "a count >= 0");
    state[at + 1] = c.bool(n.frozen, "normalizer.frozen") ? 1 : 0;
    c.vector(n.mean, "normalizer.mean", d, "one per input", state, at + 2);
    c.vector(n.m2, "normalizer.m2", d, "one per input", state, at + 2 + d);
  }

  private meta(at: number): void {
    const { c, state, st } = this;
    state[at] = this.samples;
    state[at + 1] = c.number(st.weightSum, "state.weightSum", (x) => x >= 0, "a number >= 0");
    state[at + 2] = this.lambdaEff;
  }

  private fitStatsSection(at: number): void {
    const { c, state, m } = this;
    const f = this.fitStats;
    state[at] = c.number(f.weight, "state.fitStats.weight", (x) => x >= 0, "a number >= 0");
    c.vector(f.mean, "state.fitStats.mean", m, "one per output", state, at + 1);
    c.vector(f.m2, "state.fitStats.m2", m, "one per output", state, at + 1 + m);
    c.vector(f.sse, "state.fitStats.sse", m, "one per output", state, at + 1 + 2 * m);
  }
}

/**
 * Creates the model a file describes and loads its state (the Rust core checks the numbers:
 * symmetric positive-definite scatter, weights that match the normal equations, …).
 */
export function buildModel(f: ModelFile, file: string): LearningModel {
  let model: LearningModel;
  try {
    model = new LearningModel(f.options);
  } catch (e) {
    throw new ModelFileError(file, `its hyper-parameters are refused: ${errorMessage(e)}`);
  }
  const names = model.stateSections().reduce((s, x) => s + x.length, 0);
  if (names !== f.state.length) {
    model.dispose();
    throw new ModelFileError(
      file,
      `its state has ${f.state.length} values; the model needs ${names}`,
    );
  }
  try {
    model.loadState(f.state);
  } catch (e) {
    model.dispose();
    throw new ModelFileError(file, errorMessage(e));
  }
  return model;
}

/** Reads, checks and builds a model file against the block's sizes. */
export function loadModel(
  text: string,
  file: string,
  expect: { inputs: number; outputs: number | null; inputName: string; targetName: string | null },
): { model: LearningModel; file: ModelFile } {
  const f = parseModelFile(text, file);
  const o = f.options;
  if (o.inputs !== expect.inputs) {
    throw new ModelFileError(
      file,
      `the model has ${o.inputs} inputs but input '${expect.inputName}' carries ${expect.inputs} ` +
        "values per event",
    );
  }
  if (expect.outputs !== null && o.outputs !== expect.outputs) {
    throw new ModelFileError(
      file,
      `the model has ${o.outputs} outputs but ` +
        (expect.targetName !== null
          ? `the target input '${expect.targetName}' carries ${expect.outputs} values per event`
          : `Outputs is ${expect.outputs}`),
    );
  }
  return { model: buildModel(f, file), file: f };
}

/** What a predictor block's `save` and `load` actions need from it. */
export interface ModelFileHost {
  ctx: BlockContext;
  /** The model as it is now (a load replaces it). */
  model(): LearningModel;
  /** Sizes and input names a loaded file must match. */
  expect: { inputs: number; outputs: number | null; inputName: string; targetName: string | null };
  /** Sources recorded in a saved file's header. */
  inputSource: string;
  targetSource?: string;
  /** False once the block is disposed: a late read or write then changes nothing. */
  alive(): boolean;
  /** A save finished (`saved to FILE`) or a load replaced the model (`loaded FILE: …`). */
  onSaved(message: string): void;
  onLoaded(model: LearningModel, message: string): void;
}

/** The action's file argument, or the block's default file. */
export function modelFileArg(arg: unknown, defaultFile: string): string {
  return typeof arg === "string" && arg.trim() !== "" ? arg.trim() : defaultFile;
}

/** Writes the model to `file` in the background; failures become the block's warnings. */
export function saveModelFile(h: ModelFileHost, file: string): void {
  const text = serializeModel(h.model(), {
    block: h.ctx.name,
    blockType: h.ctx.type,
    created: new Date(h.ctx.now() * 1000).toISOString(),
    inputSource: h.inputSource,
    ...(h.targetSource !== undefined ? { targetSource: h.targetSource } : {}),
  });
  h.ctx.resources.writeText(file, text).then(
    () => {
      if (h.alive()) h.onSaved(`saved to ${file}`);
    },
    (e: unknown) => h.ctx.warn(`cannot save the model to ${file}: ${errorMessage(e)}`),
  );
}

/** Reads `file` in the background and hands the checked model to `onLoaded`; else warns. */
export function loadModelFile(h: ModelFileHost, file: string): void {
  h.ctx.resources.readText(file).then(
    (text) => {
      if (!h.alive()) return;
      try {
        const r = loadModel(text, file, h.expect);
        h.onLoaded(r.model, `loaded ${file}: ${describeOptions(r.model.options)}`);
      } catch (e) {
        h.ctx.warn(`cannot load the model: ${errorMessage(e)}`);
      }
    },
    (e: unknown) => h.ctx.warn(`cannot load the model from ${file}: ${errorMessage(e)}`),
  );
}

/** A model file's own text, chosen in the page (the UI's "Load model from file…"). */
export interface ModelText {
  /** The chosen file's name, for messages. */
  name: string;
  text: string;
}

const isModelText = (arg: unknown): arg is ModelText =>
  arg !== null &&
  typeof arg === "object" &&
  typeof (arg as { name?: unknown }).name === "string" &&
  typeof (arg as { text?: unknown }).text === "string";

/**
 * The `load` action: a file name (default `defaultFile`) is read in the background (a failure
 * becomes a warning); a model file's text ({ name, text }, a file picked in the page, which the
 * engine may have no access to) is checked and replaces the model at once, or the action fails
 * with the reason.
 */
export function loadModelAction(h: ModelFileHost, arg: unknown, defaultFile: string): string {
  if (!isModelText(arg)) {
    const file = modelFileArg(arg, defaultFile);
    loadModelFile(h, file);
    return `loading ${file}`;
  }
  const name = arg.name.trim() || "the chosen file";
  const r = loadModel(arg.text, name, h.expect);
  const message = `loaded ${name}: ${describeOptions(r.model.options)}`;
  h.onLoaded(r.model, message);
  return message;
}

/** Mean of the defined R² values, for status texts: "R² 0.82", or "R² –". */
export function formatR2(r2: Float64Array): string {
  let s = 0;
  let n = 0;
  for (const v of r2) {
    if (Number.isFinite(v)) {
      s += v;
      n++;
    }
  }
  return n === 0 ? "R² –" : `R² ${(s / n).toFixed(2)}`;
}

/** Per-output R² as a list: "[0.91, 0.75, –]". */
export function listR2(r2: Float64Array): string {
  return `[${Array.from(r2, (v) => (Number.isFinite(v) ? v.toFixed(3) : "–")).join(", ")}]`;
}
