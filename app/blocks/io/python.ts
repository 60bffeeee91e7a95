import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  type BlockContext,
  type BlockInstance,
  type Shape,
} from "../../engine";
import { PythonRun, type PythonRunSettings } from "./python-run";

const params = z.strictObject({
  Module: z
    .string()
    .min(1)
    .describe(
      "A .py file (relative to the pipeline's folder) or an importable module name (numpy, mypackage.models)",
    ),
  Function: z
    .string()
    .min(1)
    .describe(
      "The function called for every input event: Function(x) or Function(x, state), x a float64 array [rows, cols]",
    ),
  Init: z
    .string()
    .min(1)
    .optional()
    .describe("A function called as init(Params) -> state at load and after reset (optional)"),
  Params: z
    .record(z.string(), z.unknown())
    .default({})
    .describe("Passed to Init as a dict (any YAML mapping)"),
  Budget: z
    .number()
    .positive()
    .max(3_600_000)
    .optional()
    .describe(
      "Milliseconds one call may take (default one period, 1000 / DesiredRate); longer calls are counted and mark the block stumbling",
    ),
  HardLimit: z
    .number()
    .positive()
    .max(86_400_000)
    .optional()
    .describe(
      "Milliseconds after which a call that has not returned is given up: reported as an error, the Python process killed and restarted with backoff (default 10 × Budget, at least 2000; 10000 when there is no Budget)",
    ),
  MemoryLimit: z
    .number()
    .min(0)
    .max(1_048_576)
    .default(4096)
    .describe(
      "Megabytes of memory the Python process may allocate (its data segment, RLIMIT_DATA, set before the module is imported); an allocation beyond it raises a MemoryError that is reported with this limit. 0: no limit",
    ),
  OnError: z
    .enum(["hold", "skip"])
    .default("hold")
    .describe(
      "When the function raises: hold (emit the last good output again) or skip (emit nothing)",
    ),
  MaxInFlight: z
    .number()
    .int()
    .min(1)
    .max(64)
    .default(1)
    .describe(
      "Calls sent to Python before an answer came back; beyond that the newest input waits and replaces an older waiting one",
    ),
  OutputShape: z
    .tuple([z.number().int().min(1).max(1_000_000), z.number().int().min(1).max(1_000_000)])
    .optional()
    .describe(
      "[rows, cols] the function returns (optional: found by a probe call at load, and checked when given; the browser build, which cannot run Python, uses it for downstream blocks)",
    ),
});

type Params = z.output<typeof params>;

/** Which param a load error points at. */
function paramOf(kind: string, p: Params): string {
  switch (kind) {
    case "missing-function":
    case "probe":
      return "Function";
    case "init":
      return p.Init !== undefined ? "Init" : "Function";
    case "shape":
      return p.OutputShape !== undefined ? "OutputShape" : "Function";
    case "memory":
      return "MemoryLimit";
    default:
      return "Module";
  }
}

/** The sidecar's own modules, which the Python-backed blocks (app/blocks/learning, …) load. */
const SHIPPED_MODULES = "mosaic_blocks.";

/**
 * A pipeline from a client of `mosaic serve` or the desktop app (confined resources) may run
 * only code in its allowed folders and the sidecar's own modules: an installed module by name
 * (`os` with Init `system`) would run anything on the host.
 */
function refuseInstalledModule(ctx: BlockContext, module: string): void {
  if (!ctx.resources.confined || looksLikeFile(module) || module.startsWith(SHIPPED_MODULES)) {
    return;
  }
  throw new BlockConfigError(
    `Module '${module}' is an installed module name; a pipeline loaded by a client of mosaic ` +
      "serve or the desktop app may run only Python files in its own folder or the data folder " +
      "(write it as a file name, e.g. Module: mymodel.py)",
    "Module",
  );
}

const looksLikeFile = (m: string): boolean =>
  m.endsWith(".py") || m.includes("/") || m.includes("\\");

/** The hard limit's default: this many budgets, at least HARD_MIN_MS (HARD_NO_BUDGET_MS without). */
const HARD_BUDGETS = 10;
const HARD_MIN_MS = 2000;
const HARD_NO_BUDGET_MS = 10_000;

/** The output shape the params give, if they give one. */
const declaredShape = (p: Params): Shape | undefined =>
  p.OutputShape ? { rows: p.OutputShape[0], cols: p.OutputShape[1] } : undefined;

/** What the params and the input decide before the sidecar starts. */
function settings(ctx: BlockContext, p: Params, inShape: Shape): PythonRunSettings {
  const budgetMs = p.Budget ?? (ctx.desiredRate > 0 ? 1000 / ctx.desiredRate : Infinity);
  const hardLimitMs =
    p.HardLimit ??
    (budgetMs < Infinity ? Math.max(HARD_BUDGETS * budgetMs, HARD_MIN_MS) : HARD_NO_BUDGET_MS);
  return {
    module: looksLikeFile(p.Module) ? ctx.resources.resolve(p.Module) : p.Module,
    function: p.Function,
    ...(p.Init !== undefined ? { init: p.Init } : {}),
    params: p.Params,
    onError: p.OnError,
    maxInFlight: p.MaxInFlight,
    memoryLimitMb: p.MemoryLimit,
    inShape,
    declared: declaredShape(p),
    budgetMs,
    hardLimitMs,
    paramOf: (kind) => paramOf(kind, p),
  };
}

/** No Python here (the browser build): the block loads so that the rest runs, and says why. */
function withoutPython(ctx: BlockContext, shape: Shape): BlockInstance {
  ctx.output(shape);
  const text =
    "Python is not available here (browser build): run the pipeline with mosaic run or the desktop app";
  ctx.setText(text);
  return {
    start() {
      ctx.setText(text);
    },
  };
}

export const Python = defineBlock({
  type: "Python",
  category: "Learning",
  summary:
    "Calls a Python function (NumPy, SciPy, scikit-learn, ONNX Runtime) on every input event.",
  help:
    "Reuses Python code inside a pipeline (paper III-J, V-(c)) without letting it stall the " +
    "pipeline: the function runs in a separate Python process (the sidecar, one per block, " +
    "started with the pipeline from the uv environment in native-bridges/python, at a lower " +
    "scheduling priority than the engine: nice + 10), and the engine never waits for it in " +
    "real time. Every input event `x` (a float64 NumPy array [rows, cols]) is " +
    "sent to `Function(x)` — or `Function(x, state)` when `Init` names a function " +
    "`init(Params) -> state`, called once at load and again on reset; `state` is any Python " +
    "object kept in the sidecar. The function returns an array-like of a fixed shape (found at " +
    "load by a probe call on zeros); its result is emitted with the input event's timestamp. " +
    "While a call is outstanding (`MaxInFlight`), newer inputs wait in one slot, each replacing " +
    "the one before (counted as skipped): a slow function lowers the block's rate, so the block " +
    "and everything downstream show as lagging, and every call longer than `Budget` is counted " +
    "(a call still running as soon as it passes `Budget`) and marks it stumbling, while " +
    "branches that do not depend on it stay on time. The status shows call-time p50/p99 (round " +
    "trip), the over-budget count and how long a late call has been running. A call still " +
    "running after `HardLimit` is given up: an error, the process is killed and restarted. An " +
    "exception in the function is an error (counted like any block error, so `mosaic run` exits " +
    "1) shown with its traceback, and the block keeps running (`OnError`); a crashed or killed " +
    "sidecar is an error too, reported and restarted with backoff (0.5 s doubling to 10 s), its " +
    "state initialised again. The process's memory is limited (`MemoryLimit`): an allocation " +
    "beyond it raises a MemoryError, reported with the limit. Under the virtual clock the " +
    "engine waits for every call (virtual time stands still meanwhile): no input is skipped " +
    "and a replay gives the same output. A missing module, a syntax error (with file and line), " +
    "a missing function or a result that is not an array is an error when the pipeline loads. " +
    "Needs `mosaic run`, `mosaic serve` or the desktop app: the browser build has no Python and " +
    "says so in the block's status (the rest of the pipeline runs). See docs/protocols.md for " +
    "the wire format and pipelines/python/ for examples.",
  params,
  inputs: { min: 1, max: 1, labels: ["x"] },
  eventLoop: true,
  views: ["scope", "label"],
  panel:
    "The function's output; the sidecar's state, call-time percentiles, over-budget calls, errors with their traceback.",
  async create(ctx, p) {
    const input = ctx.inputs[0]!;
    if (!input.shape) {
      throw new BlockConfigError(
        `the shape of its input ${input.source} is unknown (a feedback cycle): put the Python block after the cycle's first block`,
      );
    }
    const bridge = ctx.io.python;
    if (!bridge) return withoutPython(ctx, declaredShape(p) ?? input.shape);
    refuseInstalledModule(ctx, p.Module);
    const run = new PythonRun(ctx, settings(ctx, p, input.shape));
    await run.load(bridge, ctx.resources.resolve("."));
    return run.instance();
  },
});
