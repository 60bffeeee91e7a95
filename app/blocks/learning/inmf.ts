import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  Frame,
  legacyInteger,
  legacyNumber,
  LegacyParamsError,
  matrixShape,
  vectorShape,
  type BlockContext,
  type BlockInstance,
  type OutputPort,
  type Shape,
} from "../../engine";
import { createPythonModule, innerContext } from "../io/python-backed";
import { inputName, signalInput, type SignalInput } from "../shared/inputs";

const params = z
  .strictObject({
    Synergies: z
      .number()
      .int()
      .min(1)
      .max(64)
      .default(2)
      .describe("r, the number of synergies (the original's nComponents)"),
    Forgetting: z
      .number()
      .gt(0)
      .max(1)
      .default(0.85)
      .describe(
        "β in (0, 1]: the weight of the past per sample (the original's forgetFactor, 0.85; a " +
          "memory of about 1/(1 − β) samples)",
      ),
    Outputs: z
      .number()
      .int()
      .min(1)
      .max(4096)
      .optional()
      .describe(
        "Width of the output (the original's outputDim, e.g. 12 for a ControlAlgorithm): the " +
          "activations padded with zeros (default: Synergies)",
      ),
    Features: z
      .number()
      .int()
      .min(1)
      .max(4096)
      .optional()
      .describe("m, values per sample (the original's nFeatures): checked against the inputs"),
    Solver: z
      .enum(["bcd", "mu"])
      .default("bcd")
      .describe(
        "bcd: exact non-negative activations and block-coordinate descent on the synergies " +
          "(Mairal et al. 2010); mu: multiplicative updates (Lee & Seung 2001)",
      ),
    WIters: z
      .number()
      .int()
      .min(1)
      .max(1000)
      .default(1)
      .describe("Passes over the synergies per sample (the original's maxIterFit)"),
    HIters: z
      .number()
      .int()
      .min(1)
      .max(10_000)
      .default(30)
      .describe("mu only: updates of the activations per sample (the original's maxIterTransform)"),
    Update: z
      .boolean()
      .default(true)
      .describe(
        "Learn from the update input (the original's KeepUpdating, off until ticked there); " +
          "can be changed while running",
      ),
    Seed: z
      .number()
      .int()
      .min(0)
      .max(2 ** 31 - 1)
      .default(0)
      .describe("Seed of the initial synergies"),
  })
  .refine((p) => p.Outputs === undefined || p.Outputs >= p.Synergies, {
    message: "Outputs must be at least Synergies",
    path: ["Outputs"],
  });

type Params = z.output<typeof params>;

export const INmf = defineBlock({
  type: "iNMF",
  category: "Learning",
  summary:
    "Incremental non-negative matrix factorisation: muscle synergies learnt online, their activations out.",
  help:
    "MOSAIC's iNMF: muscle synergies learnt online from EMG envelopes and the activation of each " +
    "synergy emitted per sample, in the Python sidecar (native-bridges/python/mosaic_blocks/" +
    "inmf.py on the online NMF of pipelines/python/synergies.py: non-negative activations by " +
    "NNLS and the synergies by block-coordinate descent on forgetting-weighted sufficient " +
    "statistics, Mairal, Bach, Ponce & Sapiro, JMLR 11:19–60, 2010; `Solver: mu` the " +
    "multiplicative updates of Lee & Seung, NIPS 13, 2001). The original's Python model was not " +
    "published; this is the published algorithm, not a copy of it. With one input every sample " +
    "(a vector, or each row of a window) updates the model and its activations are emitted. With " +
    "two, MOSAIC's `[updates, samples]`: the rows of the first input's events (batches) update the " +
    "model (while `Update`), and every event of the second input gets its activations with the " +
    "synergies fixed. The output is [1, Outputs]: the Synergies activations, then zeros.",
  params,
  legacyParams(args) {
    if (args.length > 10) {
      throw new LegacyParamsError(`expected at most 10 numbers, got ${args.length}`);
    }
    const num = (i: number, what: string, param: string) =>
      args[i] === undefined ? undefined : legacyNumber(args[i], what, param);
    const int = (i: number, what: string, param: string) =>
      args[i] === undefined ? undefined : legacyInteger(args[i], what, param);
    for (const [i, what] of [
      [5, "synergyReg"],
      [6, "encodingReg"],
    ] as const) {
      const v = num(i, what, "Synergies");
      if (v !== undefined && v !== 0) {
        throw new LegacyParamsError(
          `${what} ${v}: regularisation is not supported by this iNMF (the original's model is not public); use 0`,
        );
      }
    }
    const out: Record<string, unknown> = {
      Outputs: int(0, "outputDim", "Outputs"),
      Forgetting: num(1, "forgetFactor", "Forgetting"),
      Synergies: int(2, "nComponents", "Synergies"),
      Features: int(3, "nFeatures", "Features"),
      WIters: int(8, "maxIterFit", "WIters"),
      HIters: int(9, "maxIterTransform", "HIters"),
    };
    for (const k of Object.keys(out)) if (out[k] === undefined) delete out[k];
    return out;
  },
  legacyForm:
    "[outputDim, forgetFactor, nComponents, nFeatures, batchSize, synergyReg, encodingReg, " +
    "epsilon, maxIterFit, maxIterTransform], all optional; batchSize is the update input's rows " +
    "and epsilon is not used here; the regularisations must be 0",
  inputs: { min: 1, max: 2, labels: ["updates", "samples"] },
  live: ["Update"],
  eventLoop: true,
  views: ["scope", "spider", "label"],
  panel: "The synergy activations; the sidecar's state and call times.",
  async create(ctx, p) {
    const { samples, m, R } = checkInputs(ctx, p);
    const k = p.Outputs ?? p.Synergies;
    const W = 1 + m;
    const out = ctx.output(vectorShape(k));
    const inner = await startModule(ctx, p, matrixShape(R, W), k, out);
    let update = p.Update;
    let x = new Frame(matrixShape(R, W), 8);
    return {
      ...inner,
      process(f, port) {
        const n = f.n;
        if (n === 0) return;
        const predict = samples !== null && port === 1;
        if (!predict && samples !== null && !update) return;
        if (x.capacity < n) x = new Frame(matrixShape(R, W), n);
        // One input: learn and emit (or only emit while Update is off); two: learn, or emit.
        const flag = predict ? 0 : samples === null ? (update ? 2 : 0) : 1;
        packRows(f, x, R, m, flag);
        inner.process?.(x, 0);
      },
      setParam(name, value) {
        if (name === "Update") update = value as boolean;
      },
    };
  },
});

/**
 * Checks the inputs: the samples input (null with one input) and `Features` must match the
 * updates input's values per row. Returns m, the values per row, and R, the rows per event handed
 * to Python (the taller input's).
 */
function checkInputs(
  ctx: BlockContext,
  p: Params,
): { samples: SignalInput | null; m: number; R: number } {
  const up = signalInput(ctx, 0);
  const samples = ctx.inputs.length > 1 ? signalInput(ctx, 1) : null;
  const m = up.shape.cols;
  if (samples && samples.shape.cols !== m) {
    throw new BlockConfigError(
      `the samples input ${inputName(samples.info)} has ${samples.shape.cols} values per row, the ` +
        `updates input ${inputName(up.info)} ${m}: they must match`,
    );
  }
  if (p.Features !== undefined && p.Features !== m) {
    throw new BlockConfigError(
      `Features is ${p.Features}, but the inputs carry ${m} values per row`,
      "Features",
    );
  }
  return { samples, m, R: Math.max(up.shape.rows, samples?.shape.rows ?? 1) };
}

/**
 * Starts the sidecar's `mosaic_blocks.inmf`: its function sees `input`, [R, 1 + m] (a flag per
 * row), and returns [1, 1 + k] (emit?, h); the k activations of each result to emit go out.
 */
function startModule(
  ctx: BlockContext,
  p: Params,
  input: Shape,
  k: number,
  out: OutputPort,
): Promise<BlockInstance> {
  return createPythonModule(
    innerContext(ctx, input, (f) => {
      if (f.v[0] !== 1) return;
      const o = out.frame(1);
      o.t[0] = f.t[0]!;
      o.v.set(f.v.subarray(1, 1 + k));
      out.emit(o);
    }),
    {
      module: "mosaic_blocks.inmf",
      init: "init",
      function: "step",
      params: {
        n_synergies: p.Synergies,
        forgetting: p.Forgetting,
        outputs: k,
        solver: p.Solver,
        w_iters: p.WIters,
        h_iters: p.HIters,
        seed: p.Seed,
      },
      outputShape: [1, 1 + k],
      onError: "skip",
    },
  );
}

/**
 * Writes the events of `f` into `x` (R rows of 1 + m per event): each of the frame's rows as
 * [flag, its m values], the rows past them NaN.
 */
function packRows(f: Frame, x: Frame, R: number, m: number, flag: number): void {
  const n = f.n;
  const rows = f.rows;
  const W = 1 + m;
  x.n = n;
  const xv = x.v;
  for (let e = 0; e < n; e++) {
    x.t[e] = f.t[e]!;
    const base = e * R * W;
    for (let r = 0; r < R; r++) {
      const at = base + r * W;
      if (r < rows) {
        xv[at] = flag;
        xv.set(f.v.subarray((e * rows + r) * m, (e * rows + r + 1) * m), at + 1);
      } else {
        xv.fill(NaN, at, at + W);
      }
    }
  }
}
