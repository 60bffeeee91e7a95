import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  errorMessage,
  LegacyParamsError,
  type BlockContext,
  type BlockInstance,
} from "../../engine";
import type { BufferRows } from "../flow/buffer";
import { createPythonModule } from "../io/python-backed";
import { inputName, vectorInput } from "../shared/inputs";
import { lookup } from "../shared/named";
import { plural } from "../shared/text";

const params = z.strictObject({
  Buffer: z
    .string()
    .min(1)
    .describe(
      "The Buffer whose rows [target…, data…] train the model (by name, on the same worker)",
    ),
  Method: z
    .enum(["pca", "ica", "lda-transform", "lda-predict"])
    .default("pca")
    .describe(
      "pca (sklearn PCA), ica (FastICA, unit-variance whitening), lda-transform (the " +
        "discriminant components of LinearDiscriminantAnalysis) or lda-predict (the predicted " +
        "class's target vector; with MOSAIC's one-number labels, the label), as MOSAIC's panel offered",
    ),
  Components: z
    .number()
    .int()
    .min(1)
    .max(1000)
    .default(2)
    .describe(
      "Outputs of pca, ica and lda-transform (lda-transform: at most classes − 1, the rest 0)",
    ),
  Targets: z
    .number()
    .int()
    .min(1)
    .max(4096)
    .default(1)
    .describe("Values per target in the Buffer (1 for MOSAIC's labels such as rest:1)"),
  Seed: z
    .number()
    .int()
    .min(0)
    .max(2 ** 31 - 1)
    .default(0)
    .describe("random_state of FastICA"),
  TrainingFile: z
    .string()
    .min(1)
    .optional()
    .describe(
      "Where the training rows are written for the sidecar (CSV, relative to the pipeline; " +
        "default <block>.training.csv); a file left by an earlier run trains the model at load",
    ),
  AutoTrain: z
    .boolean()
    .default(false)
    .describe(
      "Fit whenever the Buffer closes a cluster (otherwise: the train action, MOSAIC's Fit)",
    ),
});

export const PythonNetLearning = defineBlock({
  type: "PythonNetLearning",
  category: "Learning",
  summary:
    "PCA, ICA or LDA from scikit-learn, fitted on a Buffer's clusters and applied to every input vector (MOSAIC's Python.NET example).",
  help:
    "MOSAIC's PythonNetLearning: fits a scikit-learn model on the rows of the named Buffer when " +
    "asked (the `train` action, MOSAIC's Fit button; with AutoTrain whenever the Buffer closes a " +
    "cluster) and applies it to every input vector, in the Python sidecar " +
    "(native-bridges/python/mosaic_blocks/learning.py). The Buffer's rows are written to " +
    "`TrainingFile` and the sidecar is re-initialised on them; until the first training the " +
    "output is zeros (the original sent nothing). `Method` pca and ica reduce the input to " +
    "`Components` values; lda-transform projects it on the discriminant axes of the classes " +
    "(the distinct target vectors); lda-predict outputs the predicted class's target vector. " +
    "The Buffer must run on the same worker. MOSAIC's positional form is `[bufferBlock]` (the " +
    "method and components were chosen in its panel: here Method and Components, PCA with 2 by " +
    "default).",
  params,
  legacyParams(args) {
    if (args.length !== 1 || args[0]!.trim() === "") {
      throw new LegacyParamsError(
        "expected [bufferBlock], the Buffer that trains the model",
        "Buffer",
      );
    }
    return { Buffer: args[0]!.trim() };
  },
  legacyForm: "[bufferBlock], e.g. [cluster_storage]",
  inputs: { min: 1, max: 1, labels: ["features"] },
  eventLoop: true,
  views: ["scope", "label"],
  panel: "The model's output; the sidecar's state; a train button.",
  async create(ctx, p) {
    const input = vectorInput(ctx, 0);
    const d = input.size;
    checkComponents(p, d, inputName(input.info));
    const file = p.TrainingFile ?? `${ctx.name}.training.csv`;
    const inner = await openSidecar(ctx, p, d, file);
    return new LearningRun(ctx, p, d, file, inner).instance();
  },
});

type Params = z.output<typeof params>;

/** pca, ica and lda-transform cannot give more components than the input has values. */
function checkComponents(p: Params, d: number, input: string): void {
  if (p.Method !== "lda-predict" && p.Components > d) {
    throw new BlockConfigError(
      `Components ${p.Components} is more than the ${d} values of input ${input}`,
      "Components",
    );
  }
}

/** Loads mosaic_blocks.learning in the sidecar, on the training file; k outputs. */
function openSidecar(
  ctx: BlockContext,
  p: Params,
  d: number,
  file: string,
): Promise<BlockInstance> {
  const T = p.Targets;
  const k = p.Method === "lda-predict" ? T : p.Components;
  return createPythonModule(ctx, {
    module: "mosaic_blocks.learning",
    init: "init",
    function: "apply",
    params: {
      method: p.Method,
      n_components: p.Components,
      targets: T,
      features: d,
      training: ctx.resources.resolve(file),
      seed: p.Seed,
    },
    outputShape: [1, k],
  });
}

/** The Buffer's n rows of W values, as CSV lines (one row a line, a newline at the end). */
function trainingCsv(v: Float64Array, n: number, W: number): string {
  const lines: string[] = [];
  for (let r = 0; r < n; r++) {
    const row: string[] = [];
    for (let c = 0; c < W; c++) row.push(String(v[r * W + c]));
    lines.push(row.join(","));
  }
  return lines.join("\n") + "\n";
}

/** The sidecar's instance with training: the train action, AutoTrain's listener, disposal. */
class LearningRun {
  private disposed = false;
  private unlisten: (() => void) | undefined;

  constructor(
    private readonly ctx: BlockContext,
    private readonly p: Params,
    private readonly d: number,
    private readonly file: string,
    private readonly inner: BlockInstance,
  ) {}

  /** The sidecar's instance, its start and dispose wrapped, a train action added. */
  instance(): BlockInstance {
    const inner = this.inner;
    return {
      ...inner,
      start: () => this.start(),
      dispose: () => this.dispose(),
      actions: {
        ...inner.actions,
        train: {
          label: "Train",
          description: `Fit the model on the rows of the Buffer '${this.p.Buffer}'`,
          run: () => this.train(),
        },
      },
    };
  }

  /** Writes the Buffer's rows for the sidecar, which is re-initialised on them once written. */
  private train(): string {
    const { ctx, p, d, file } = this;
    const T = p.Targets;
    const b = lookup<BufferRows>(ctx, p.Buffer, "Buffer");
    if (typeof b === "string") throw new Error(`cannot read the Buffer: ${b}`);
    if (b.dataWidth !== d || b.targetWidth !== T) {
      throw new Error(
        `the Buffer '${p.Buffer}' stores targets of ${b.targetWidth} and data of ${b.dataWidth} ` +
          `values; this block reads ${d} values and Targets is ${T}`,
      );
    }
    const n = b.rows();
    if (n === 0) return `the Buffer '${p.Buffer}' is empty: nothing to train on`;
    ctx.resources.writeText(file, trainingCsv(b.values(), n, T + d)).then(
      () => {
        if (!this.disposed) this.inner.reset?.();
      },
      (e: unknown) => ctx.warn(`cannot write ${file}: ${errorMessage(e)}`),
    );
    return `training ${p.Method} on ${plural(n, "row")} of '${p.Buffer}'`;
  }

  /** Starts the sidecar; with AutoTrain, listens (once) to the Buffer's closed clusters. */
  private start(): void {
    const { ctx, p } = this;
    this.inner.start?.();
    if (!p.AutoTrain || this.unlisten) return;
    const b = lookup<BufferRows>(ctx, p.Buffer, "Buffer");
    if (typeof b === "string") {
      ctx.warn(`Buffer '${p.Buffer}': ${b}; the model cannot be trained from it`);
      return;
    }
    this.unlisten = b.onClusterClosed(() =>
      ctx.at(ctx.now(), () => {
        try {
          this.train();
        } catch (e) {
          ctx.warn(errorMessage(e));
        }
      }),
    );
  }

  /** Stops listening to the Buffer and disposes of the sidecar. */
  private dispose(): void {
    this.disposed = true;
    this.unlisten?.();
    this.inner.dispose?.();
  }
}
