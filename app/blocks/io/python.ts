import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  formatShape,
  shapeSize,
  type BlockContext,
  type Frame,
  type PythonCallError,
  type PythonSidecar,
  type Shape,
} from "../../engine";

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

/** p50 and p99 of the first `n` values of `ring` (a copy is sorted). */
function percentiles(ring: Float64Array, n: number, scratch: Float64Array): [number, number] {
  if (n === 0) return [NaN, NaN];
  const s = scratch.subarray(0, n);
  s.set(ring.subarray(0, n));
  s.sort();
  const at = (q: number): number => s[Math.min(n - 1, Math.ceil(q * n) - 1)]!;
  return [at(0.5), at(0.99)];
}

const ms = (x: number): string =>
  !(x === x)
    ? "–"
    : x < 1
      ? `${x.toFixed(2)} ms`
      : x < 100
        ? `${x.toFixed(1)} ms`
        : `${Math.round(x)} ms`;

/** A duration of a call still running: ms below 10 s, then s. */
const running = (x: number): string => (x < 10_000 ? ms(x) : `${(x / 1000).toFixed(1)} s`);

const TIMES = 256;
const WARN_EVERY_MS = 5000;
/** The hard limit's default: this many budgets, at least HARD_MIN_MS (HARD_NO_BUDGET_MS without). */
const HARD_BUDGETS = 10;
const HARD_MIN_MS = 2000;
const HARD_NO_BUDGET_MS = 10_000;

/** Events (timestamp + values) waiting, oldest first: a ring that grows when full. */
class EventQueue {
  private t: Float64Array;
  private v: Float64Array;
  private head = 0;
  n = 0;

  constructor(
    private readonly size: number,
    private cap = 4,
  ) {
    this.t = new Float64Array(cap);
    this.v = new Float64Array(cap * size);
  }

  push(values: Float64Array, t: number): void {
    if (this.n === this.cap) this.grow();
    this.put((this.head + this.n) % this.cap, values, t);
    this.n++;
  }

  /** Replaces the newest event (there must be one). */
  replaceNewest(values: Float64Array, t: number): void {
    this.put((this.head + this.n - 1) % this.cap, values, t);
  }

  get oldestT(): number {
    return this.t[this.head]!;
  }

  get oldest(): Float64Array {
    return this.v.subarray(this.head * this.size, (this.head + 1) * this.size);
  }

  shift(): void {
    this.head = (this.head + 1) % this.cap;
    this.n--;
  }

  clear(): void {
    this.head = 0;
    this.n = 0;
  }

  private put(k: number, values: Float64Array, t: number): void {
    this.t[k] = t;
    this.v.set(values, k * this.size);
  }

  private grow(): void {
    const cap = this.cap * 2;
    const t = new Float64Array(cap);
    const v = new Float64Array(cap * this.size);
    for (let i = 0; i < this.n; i++) {
      const k = (this.head + i) % this.cap;
      t[i] = this.t[k]!;
      v.set(this.v.subarray(k * this.size, (k + 1) * this.size), i * this.size);
    }
    this.t = t;
    this.v = v;
    this.cap = cap;
    this.head = 0;
  }
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
    const inShape: Shape = input.shape;
    const inSize = shapeSize(inShape);
    const budgetMs = p.Budget ?? (ctx.desiredRate > 0 ? 1000 / ctx.desiredRate : Infinity);
    const budget = budgetMs < Infinity ? budgetMs : undefined;
    const hardLimitMs =
      p.HardLimit ??
      (budget !== undefined ? Math.max(HARD_BUDGETS * budget, HARD_MIN_MS) : HARD_NO_BUDGET_MS);
    const bridge = ctx.io.python;
    const declared: Shape | undefined = p.OutputShape
      ? { rows: p.OutputShape[0], cols: p.OutputShape[1] }
      : undefined;

    if (!bridge) {
      // No Python here (the browser build): the block loads so that the rest runs.
      ctx.output(declared ?? inShape);
      const text =
        "Python is not available here (browser build): run the pipeline with mosaic run or the desktop app";
      ctx.setText(text);
      return {
        start() {
          ctx.setText(text);
        },
      };
    }

    // Calls sent, oldest first: input timestamps, send times, and whether the call was already
    // counted as over budget while it ran (results come back in order).
    const cap = p.MaxInFlight;
    const sentT = new Float64Array(cap);
    const sentAt = new Float64Array(cap);
    const counted = new Uint8Array(cap);
    let head = 0;
    let count = 0;
    // Inputs waiting for a call: in real time one (newer ones replace it); under the virtual
    // clock all of them (the engine waits for every call).
    const waiting = new EventQueue(inSize, ctx.virtual ? 16 : 1);
    // Results held for `flush` under the virtual clock (emitted in the engine's order).
    let held: EventQueue | undefined;
    // Last good output (OnError: hold).
    let lastGood: Float64Array | undefined;
    let haveGood = false;

    let runningNow = false;
    let calls = 0;
    let errors = 0;
    let overBudget = 0;
    let skipped = 0;
    let crashes = 0;
    let state = "loading";
    /** The sidecar failed to restart: under the virtual clock, inputs are not waited for. */
    let down = false;
    let lastError = "";
    let lastWarnAt = -Infinity;
    let lastText = "";
    /** How long the oldest call has been running, when that is longer than the budget (ms). */
    let lateFor = 0;
    const rtt = new Float64Array(TIMES);
    const py = new Float64Array(TIMES);
    const scratch = new Float64Array(TIMES);
    let timesN = 0;
    let timesAt = 0;

    let sidecar: PythonSidecar | undefined;
    // eslint-disable-next-line prefer-const
    let out: ReturnType<typeof ctx.output>;

    let pctText = "";
    let lastPct = -Infinity;
    const refresh = (force = false): void => {
      const now = performance.now();
      // Percentiles at most every 100 ms (a sort of the last 256 call times); counters always.
      if (force || now - lastPct >= 100 || timesN < 8) {
        lastPct = now;
        const [p50, p99] = percentiles(rtt, timesN, scratch);
        const [py50] = percentiles(py, timesN, scratch);
        pctText = `p50 ${ms(p50)} p99 ${ms(p99)} (Python ${ms(py50)})`;
      }
      let text: string;
      if (state === "ready") {
        text = `pid ${sidecar?.pid ?? "?"}`;
        if (lateFor > 0) text += ` · call running for ${running(lateFor)}`;
        text += ` · ${pctText}`;
        text += ` · ${overBudget} over budget${budget !== undefined ? ` (${ms(budget)})` : ""}`;
      } else {
        text = state;
      }
      if (skipped > 0) text += ` · ${skipped} skipped`;
      if (crashes > 0) text += ` · ${crashes} restart${crashes > 1 ? "s" : ""}`;
      if (errors > 0) text += ` · ${errors} errors (last: ${lastError})`;
      if (text !== lastText) {
        lastText = text;
        ctx.setText(text);
      }
    };

    /** Under the virtual clock: how many results the engine must wait for. */
    const awaiting = (): void => {
      if (ctx.virtual) ctx.setAwaiting(runningNow ? count + waiting.n : 0);
    };

    const send = (values: Float64Array, t: number): boolean => {
      if (count >= cap || !sidecar?.ready) return false;
      const k = (head + count) % cap;
      sentT[k] = t;
      sentAt[k] = performance.now();
      counted[k] = 0;
      count++;
      if (sidecar.call(values) < 0) {
        count--;
        return false;
      }
      return true;
    };

    /**
     * Takes the oldest outstanding call: its input timestamp, its round-trip time (ms), and
     * whether it was counted over budget while it ran.
     */
    const take = (): [number, number, boolean] | undefined => {
      if (count === 0) return undefined;
      const t = sentT[head]!;
      const took = performance.now() - sentAt[head]!;
      const wasCounted = counted[head] === 1;
      head = (head + 1) % cap;
      count--;
      lateFor = 0;
      return [t, took, wasCounted];
    };

    const sendWaiting = (): void => {
      while (waiting.n > 0 && send(waiting.oldest, waiting.oldestT)) waiting.shift();
    };

    const emit = (t: number, values: Float64Array): void => {
      if (!runningNow) return;
      if (held) {
        held.push(values, t);
        return;
      }
      const f = out.frame(1);
      f.t[0] = t;
      f.v.set(values);
      out.emit(f);
    };

    const warnOutput = (message: string): void => {
      const now = performance.now();
      if (now - lastWarnAt < WARN_EVERY_MS) return;
      lastWarnAt = now;
      ctx.warn(message);
    };

    /**
     * An error: counted by the runtime like an exception in `process`; the status counts the
     * function's errors (a lost process shows as a restart).
     */
    const failed = (message: string, traceback = "", restart = false): void => {
      if (!restart) {
        errors++;
        lastError = message;
      }
      ctx.error(message, traceback.trimEnd() || undefined);
    };

    /** The oldest call, still running past the budget: counted now, and marks it stumbling. */
    const onLate = (_id: number, runningMs: number): void => {
      if (count === 0 || budget === undefined) return;
      if (counted[head] === 0) {
        counted[head] = 1;
        overBudget++;
      }
      lateFor = runningMs;
      ctx.reportCompute(runningMs, budget);
      refresh(true);
    };

    const onResult = (_id: number, values: Float64Array, computeUs: number): void => {
      const taken = take();
      if (!taken) return;
      const [t, took, wasCounted] = taken;
      calls++;
      rtt[timesAt] = took;
      py[timesAt] = computeUs / 1000;
      timesAt = (timesAt + 1) % TIMES;
      if (timesN < TIMES) timesN++;
      if (took > budgetMs && !wasCounted) overBudget++;
      // The call's duration is this block's compute: a call over budget marks it stumbling.
      ctx.reportCompute(took, budget);
      if (!lastGood) lastGood = new Float64Array(values.length);
      lastGood.set(values);
      haveGood = true;
      emit(t, values);
      sendWaiting();
      awaiting();
      refresh();
    };

    const onError = (id: number, e: PythonCallError): void => {
      if (id === 0) {
        // Not a call: init raised on reset.
        failed(e.message, e.traceback);
        refresh(true);
        return;
      }
      const taken = take();
      // A call lost to a crash or a kill: the restart's report counts it (once per process).
      if (e.kind !== "crash" && e.kind !== "timeout") failed(e.message, e.traceback);
      if (taken) {
        if (taken[1] > budgetMs && !taken[2]) overBudget++;
        ctx.reportCompute(taken[1], budget);
        if (p.OnError === "hold" && haveGood && lastGood) emit(taken[0], lastGood);
      }
      sendWaiting();
      awaiting();
      refresh(true);
    };

    refuseInstalledModule(ctx, p.Module);
    let loadPromise: Promise<PythonSidecar>;
    try {
      loadPromise = bridge.load({
        module: looksLikeFile(p.Module) ? ctx.resources.resolve(p.Module) : p.Module,
        function: p.Function,
        ...(p.Init !== undefined ? { init: p.Init } : {}),
        params: p.Params,
        inputShape: inShape,
        ...(declared ? { outputShape: declared } : {}),
        cwd: ctx.resources.resolve("."),
        label: `block '${ctx.name}'`,
        hardLimitMs,
        ...(budget !== undefined ? { lateAfterMs: budget } : {}),
        memoryLimitMb: p.MemoryLimit,
        onResult,
        onLate,
        onError,
        onStatus(s, message) {
          if (!sidecar) return; // the load itself: its outcome is what `load` returns
          if (s === "restarting") {
            const text = message ?? "the Python sidecar stopped; restarting";
            if (state === "ready") {
              // The process died (or was killed): one error, whatever it had in flight.
              crashes++;
              failed(text, "", true);
            } else {
              // A restart failed: the same outage goes on.
              ctx.warn(text);
              down = true;
              if (ctx.virtual && waiting.n > 0) {
                skipped += waiting.n;
                waiting.clear();
              }
            }
            state = text;
            count = 0;
            head = 0;
            lateFor = 0;
          } else if (s === "ready") {
            state = "ready";
            down = false;
            if (message) ctx.warn(`Python sidecar ${message}`);
            sendWaiting();
          } else if (s === "closed") {
            state = "closed";
          }
          awaiting();
          refresh(true);
        },
        onOutput(line) {
          warnOutput(`python: ${line}`);
        },
      });
      sidecar = await loadPromise;
    } catch (e) {
      const kind = (e as { kind?: unknown }).kind;
      const message = e instanceof Error ? e.message : String(e);
      throw new BlockConfigError(
        `Python: ${message}`,
        paramOf(typeof kind === "string" ? kind : "", p),
      );
    }
    const sc: PythonSidecar = sidecar;
    state = "ready";
    out = ctx.output(sc.outputShape);
    if (declared && shapeSize(declared) !== shapeSize(sc.outputShape)) {
      sc.close();
      throw new BlockConfigError(
        `Python: the function returns ${formatShape(sc.outputShape)}, not ${formatShape(declared)}`,
        "OutputShape",
      );
    }
    if (ctx.virtual) held = new EventQueue(shapeSize(sc.outputShape), 16);
    refresh(true);

    return {
      start() {
        runningNow = true;
        refresh(true);
      },
      stop() {
        runningNow = false;
        awaiting();
      },
      process(frame: Frame) {
        const stride = frame.stride;
        for (let e = 0; e < frame.n; e++) {
          const v = frame.v.subarray(e * stride, e * stride + inSize);
          const t = frame.t[e]!;
          if (waiting.n === 0 && send(v, t)) continue;
          if (ctx.virtual) {
            // Every input gets its call (unless the sidecar cannot be restarted).
            if (down) skipped++;
            else waiting.push(v, t);
          } else if (waiting.n > 0) {
            // Busy (or restarting): this input waits, replacing an older waiting one.
            skipped++;
            waiting.replaceNewest(v, t);
          } else {
            waiting.push(v, t);
          }
        }
        awaiting();
        refresh();
      },
      // Under the virtual clock results are held until the engine has delivered everything it
      // had (it waits for them), then go out here, in the engine's order of blocks.
      ...(held
        ? {
            flush() {
              const h = held!;
              if (h.n === 0 || !runningNow) {
                h.clear();
                return;
              }
              const f = out.frame(h.n);
              for (let i = 0; i < f.n; i++) {
                f.t[i] = h.oldestT;
                f.v.set(h.oldest, i * f.stride);
                h.shift();
              }
              out.emit(f);
            },
          }
        : {}),
      reset() {
        waiting.clear();
        held?.clear();
        haveGood = false;
        awaiting();
        sc.reset();
      },
      dispose() {
        runningNow = false;
        sc.close();
      },
      actions: {
        info: {
          label: "Sidecar info",
          description: "Shows the Python process, its versions and counters",
          run: () =>
            `${p.Module}:${p.Function} in pid ${sc.pid ?? "?"} (${sc.version}); ` +
            `${formatShape(inShape)} → ${formatShape(sc.outputShape)}; ${calls} calls, ` +
            `${overBudget} over budget, ${errors} errors, ${skipped} skipped, ${crashes} restarts`,
        },
      },
    };
  },
});
