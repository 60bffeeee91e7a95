import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  formatShape,
  shapeSize,
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
    default:
      return "Module";
  }
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

const TIMES = 256;
const WARN_EVERY_MS = 5000;

export const Python = defineBlock({
  type: "Python",
  category: "Learning",
  summary:
    "Calls a Python function (NumPy, SciPy, scikit-learn, ONNX Runtime) on every input event.",
  help:
    "Reuses Python code inside a pipeline (paper III-J, V-(c)) without letting it stall the " +
    "pipeline: the function runs in a separate Python process (the sidecar, one per block, " +
    "started with the pipeline from the uv environment in native-bridges/python), and the " +
    "engine never waits for it. Every input event `x` (a float64 NumPy array [rows, cols]) is " +
    "sent to `Function(x)` — or `Function(x, state)` when `Init` names a function " +
    "`init(Params) -> state`, called once at load and again on reset; `state` is any Python " +
    "object kept in the sidecar. The function returns an array-like of a fixed shape (found at " +
    "load by a probe call on zeros); its result is emitted with the input event's timestamp. " +
    "While a call is outstanding (`MaxInFlight`), newer inputs wait in one slot, each replacing " +
    "the one before (counted as skipped): a slow function lowers the block's rate, so the block " +
    "and everything downstream show as lagging, and every call longer than `Budget` is counted " +
    "and marks it stumbling, while branches that do not depend on it stay on time. The status " +
    "shows call-time p50/p99 (round trip) and the over-budget count. An exception in the " +
    "function is shown with its traceback and the block keeps running (`OnError`); a crashed " +
    "or killed sidecar is reported and restarted with backoff (0.5 s doubling to 10 s), its " +
    "state initialised again. A missing module, a syntax error (with file and line), a missing " +
    "function or a result that is not an array is an error when the pipeline loads. Needs " +
    "`mosaic run`, `mosaic serve` or the desktop app: the browser build has no Python and says " +
    "so in the block's status (the rest of the pipeline runs). See docs/protocols.md for the " +
    "wire format and pipelines/python/ for examples.",
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

    // Calls sent, oldest first: input timestamps and send times (results come back in order).
    const cap = p.MaxInFlight;
    const sentT = new Float64Array(cap);
    const sentAt = new Float64Array(cap);
    let head = 0;
    let count = 0;
    // The one waiting input (newer ones replace it).
    const waiting = new Float64Array(inSize);
    let waitingT = 0;
    let hasWaiting = false;
    // Last good output (OnError: hold).
    let lastGood: Float64Array | undefined;
    let haveGood = false;

    let running = false;
    let calls = 0;
    let errors = 0;
    let overBudget = 0;
    let skipped = 0;
    let crashes = 0;
    let state = "loading";
    let lastError = "";
    let lastWarnAt = -Infinity;
    let lastText = "";
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
        text = `pid ${sidecar?.pid ?? "?"} · ${pctText}`;
        text += ` · ${overBudget} over budget${budgetMs < Infinity ? ` (${ms(budgetMs)})` : ""}`;
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

    const send = (values: Float64Array, t: number): boolean => {
      if (count >= cap || !sidecar?.ready) return false;
      const k = (head + count) % cap;
      sentT[k] = t;
      sentAt[k] = performance.now();
      count++;
      if (sidecar.call(values) < 0) {
        count--;
        return false;
      }
      return true;
    };

    /** Takes the oldest outstanding call: its input timestamp and its round-trip time (ms). */
    const take = (): [number, number] | undefined => {
      if (count === 0) return undefined;
      const t = sentT[head]!;
      const took = performance.now() - sentAt[head]!;
      head = (head + 1) % cap;
      count--;
      return [t, took];
    };

    const sendWaiting = (): void => {
      if (hasWaiting && send(waiting, waitingT)) hasWaiting = false;
    };

    const emit = (t: number, values: Float64Array): void => {
      if (!running) return;
      const f = out.frame(1);
      f.t[0] = t;
      f.v.set(values);
      out.emit(f);
    };

    const warnError = (message: string): void => {
      const now = performance.now();
      if (now - lastWarnAt < WARN_EVERY_MS) return;
      lastWarnAt = now;
      ctx.warn(message);
    };

    const onResult = (_id: number, values: Float64Array, computeUs: number): void => {
      const taken = take();
      if (!taken) return;
      const [t, took] = taken;
      calls++;
      rtt[timesAt] = took;
      py[timesAt] = computeUs / 1000;
      timesAt = (timesAt + 1) % TIMES;
      if (timesN < TIMES) timesN++;
      if (took > budgetMs) overBudget++;
      // The call's duration is this block's compute: a call over budget marks it stumbling.
      ctx.reportCompute(took, budgetMs < Infinity ? budgetMs : undefined);
      if (!lastGood) lastGood = new Float64Array(values.length);
      lastGood.set(values);
      haveGood = true;
      emit(t, values);
      sendWaiting();
      refresh();
    };

    const onError = (id: number, e: PythonCallError): void => {
      if (id === 0) {
        // Not a call: init raised on reset.
        errors++;
        lastError = e.message;
        ctx.warn(`${e.message}${e.traceback ? `\n${e.traceback}` : ""}`);
        refresh(true);
        return;
      }
      const taken = take();
      if (e.kind !== "crash") {
        errors++;
        lastError = e.message;
        warnError(
          `${e.message}${e.traceback ? `\n${e.traceback.trimEnd()}` : ""}${errors > 1 ? ` (${errors} errors so far)` : ""}`,
        );
      }
      if (taken) {
        ctx.reportCompute(taken[1], budgetMs < Infinity ? budgetMs : undefined);
        if (p.OnError === "hold" && haveGood && lastGood) emit(taken[0], lastGood);
      }
      sendWaiting();
      refresh(true);
    };

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
        onResult,
        onError,
        onStatus(s, message) {
          if (!sidecar) return; // the load itself: its outcome is what `load` returns
          if (s === "restarting") {
            if (state === "ready") crashes++;
            state = message ?? "restarting";
            count = 0;
            head = 0;
            ctx.warn(message ?? "the Python sidecar stopped; restarting");
          } else if (s === "ready") {
            state = "ready";
            if (message) ctx.warn(`Python sidecar ${message}`);
            sendWaiting();
          } else if (s === "closed") {
            state = "closed";
          }
          refresh(true);
        },
        onOutput(line) {
          warnError(`python: ${line}`);
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
    refresh(true);

    return {
      start() {
        running = true;
        if (ctx.virtual) {
          // The virtual clock does not wait for the sidecar (no call blocks the engine).
          ctx.warn(
            "under the virtual clock Python calls are not awaited: results arrive in real time, inputs that come faster are skipped, and runs are not reproducible; use the real-time clock",
          );
        }
        refresh(true);
      },
      stop() {
        running = false;
      },
      process(frame: Frame) {
        const stride = frame.stride;
        for (let e = 0; e < frame.n; e++) {
          const v = frame.v.subarray(e * stride, e * stride + inSize);
          const t = frame.t[e]!;
          if (!hasWaiting && send(v, t)) continue;
          // Busy (or restarting): this input waits, replacing an older waiting one.
          if (hasWaiting) skipped++;
          waiting.set(v);
          waitingT = t;
          hasWaiting = true;
        }
        refresh();
      },
      reset() {
        hasWaiting = false;
        haveGood = false;
        sc.reset();
      },
      dispose() {
        running = false;
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
