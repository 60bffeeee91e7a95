import { z } from "zod";
import { BlockConfigError, defineBlock, errorMessage, vectorShape } from "../../engine";
import { indexArg, vectorArg } from "../shared/args";
import { signalInput, vectorInput } from "../shared/inputs";
import { publish } from "../shared/named";
import { formatCount, formatVector, plural, TextThrottle } from "../shared/text";

/**
 * What a Buffer offers by its name (shared/named.ts, kind "Buffer") to the blocks that MOSAIC let
 * read it by name (BatchPredictor, PythonNetLearning): its rows, read on request.
 */
export interface BufferRows {
  /** T, values per target. */
  readonly targetWidth: number;
  /** D, values per data row. */
  readonly dataWidth: number;
  /** Rows stored now. */
  rows(): number;
  /** The stored rows [target…, data…], rows × (T + D) values; read before the next event. */
  values(): Float64Array;
  /** Calls `fn` whenever a cluster with rows closes (recording stops or changes target). */
  onClusterClosed(fn: () => void): () => void;
}

/** Most values the store may hold (1 GiB of doubles). */
const MAX_VALUES = 2 ** 27;

/** One labelled cluster: rows [start, start + rows) of the store, all with this target. */
interface Cluster {
  target: Float64Array;
  start: number;
  rows: number;
}

const sameValues = (a: ArrayLike<number>, b: ArrayLike<number>): boolean => {
  if (a.length !== b.length) return false;
  for (let i = 0; i < a.length; i++) if (a[i] !== b[i]) return false;
  return true;
};

export const BufferBlock = defineBlock({
  type: "Buffer",
  category: "Flow control",
  summary:
    "Records (target, data) pairs between start and stop triggers, as labelled clusters for batch learning.",
  help:
    "Segments a data stream into labelled clusters for batch machine learning (paper III-F, " +
    "III-G). Inputs are `[Trigger, Data]`. As in MOSAIC, a data input written `-Data` is " +
    "subscribed only while recording (nothing is delivered in between); written `Data`, it stays " +
    "subscribed and the Buffer ignores data outside recording. Trigger protocol: " +
    "a trigger event whose values are a target vector [1, T] starts recording a cluster " +
    "labelled with that target (a different target closes the current cluster and starts a new " +
    "one; the same target again continues it); an event whose values are all NaN stops " +
    "recording; an event with only some NaN values is ignored with a warning. While recording, " +
    "every data event (its D values, row by row for a matrix) is stored as one row `[target…, " +
    "data…]` with the event's timestamp; data outside recording is ignored, so the data input " +
    "may stay subscribed. Actions: `start` (a target as a list of T numbers, or a label index k: " +
    "[k] when T = 1, the one-hot vector e_k otherwise), `stop`, `clear`, `save` (a file name, " +
    "default `<block>.csv`, relative to the pipeline file: one CSV line `target…,data…` per row, " +
    "no header, as MOSAIC's save button wrote), `inspect` (clusters and rows per target) and " +
    "`emit`, which sends every stored row at once, as one frame of [1, T + D] events on the " +
    "`pairs` output (how a BatchPredictor is trained). With `Stream: true` rows are also sent on " +
    "`pairs` as they are recorded. Memory is bounded by `MaxRows`: when it is full, further rows " +
    "are dropped and counted, and the status says so until you save, emit or clear. Clusters " +
    "that received no rows are not kept. Blocks that MOSAIC let read a Buffer by its name " +
    "(a BatchPredictor or PythonNetLearning written `[bufferName, …]`) read its rows when they " +
    "build their model, on the same worker.",
  params: z.strictObject({
    Stream: z
      .boolean()
      .default(false)
      .describe(
        "Also send every row on the pairs output as it is recorded (can be changed while running)",
      ),
    MaxRows: z
      .number()
      .int()
      .min(1)
      .max(10_000_000)
      .default(100_000)
      .describe(
        "Most rows kept (bounded memory: rows × (T + D) × 8 bytes, at most 1 GiB); rows beyond " +
          "are dropped and counted",
      ),
  }),
  legacyParams: () => ({}),
  legacyForm: "no params: `{ Type: Buffer, Inputs: [Trigger, -Data] }`",
  inputs: { min: 2, max: 2, labels: ["trigger", "data"] },
  outputs: ["pairs"],
  live: ["Stream"],
  views: ["label"],
  panel: "Clusters and rows per target, with start, stop, clear, save, emit and inspect buttons.",
  create(ctx, p) {
    const trig = vectorInput(ctx, 0);
    const data = signalInput(ctx, 1);
    const T = trig.size;
    const D = data.size;
    const W = T + D;
    // Aperiodic: it emits on request (MOSAIC set its rate to 0).
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    // Rows [target…, data…] are named after both inputs' values when both name them.
    const tl = trig.info.meta?.labels;
    const dl = data.info.meta?.labels;
    const out = ctx.output(
      vectorShape(W),
      "pairs",
      tl?.length === T && dl?.length === D ? { labels: [...tl, ...dl] } : undefined,
    );
    const maxRows = p.MaxRows;
    if (maxRows * W > MAX_VALUES) {
      throw new BlockConfigError(
        `MaxRows ${formatCount(maxRows)} rows of ${T} + ${D} values would take up to ` +
          `${((maxRows * W * 8) / 2 ** 30).toFixed(1)} GiB; the Buffer keeps at most ` +
          `${formatCount(MAX_VALUES)} values (1 GiB): set MaxRows to ` +
          `${formatCount(Math.floor(MAX_VALUES / W))} or less`,
        "MaxRows",
      );
    }
    let stream = p.Stream;

    // Row store, grown by doubling up to MaxRows.
    let values = new Float64Array(Math.min(maxRows, 256) * W);
    let times = new Float64Array(Math.min(maxRows, 256));
    let rows = 0;
    let dropped = 0;
    const clusters: Cluster[] = [];
    let current: Cluster | null = null;
    const throttle = new TextThrottle();
    let lastSaved = "";
    // A `-Data` input (MOSAIC's form) is subscribed while recording, as MOSAIC's Buffer did.
    const subscribeWhileRecording = !data.info.subscribed;

    const summary = (): string => {
      const n = clusters.length + (current !== null && current.rows > 0 ? 1 : 0);
      if (n === 0) return "empty";
      return `${plural(n, "cluster")}, ${plural(rows, "row")}`;
    };
    const describe = (): void => {
      let s: string;
      if (rows >= maxRows && (current !== null || dropped > 0)) {
        s =
          `full: ${plural(rows, "row")} (MaxRows)` +
          (dropped > 0 ? `, ${formatCount(dropped)} dropped` : "") +
          "; save, emit or clear to record more";
      } else if (current) {
        s = `recording ${formatVector(current.target)} (${plural(current.rows, "row")})`;
      } else {
        s = summary();
        if (lastSaved !== "") s += ` (${lastSaved})`;
      }
      ctx.setText(s);
    };
    describe();

    const grow = (need: number): void => {
      let cap = times.length;
      if (need <= cap) return;
      while (cap < need) cap *= 2;
      cap = Math.min(cap, maxRows);
      const v = new Float64Array(cap * W);
      v.set(values.subarray(0, rows * W));
      const t = new Float64Array(cap);
      t.set(times.subarray(0, rows));
      values = v;
      times = t;
    };

    const closedListeners = new Set<() => void>();
    /** Closes the current cluster (kept only if it received rows). */
    const close = (): void => {
      const closed = current !== null && current.rows > 0;
      if (closed) clusters.push(current!);
      current = null;
      if (closed) for (const fn of closedListeners) fn();
    };
    const withdraw = publish(ctx, "Buffer", {
      targetWidth: T,
      dataWidth: D,
      rows: () => rows,
      values: () => values.subarray(0, rows * W),
      onClusterClosed(fn: () => void) {
        closedListeners.add(fn);
        return () => closedListeners.delete(fn);
      },
    } satisfies BufferRows);
    const start = (target: ArrayLike<number>): void => {
      if (current && sameValues(current.target, target)) return;
      close();
      current = { target: Float64Array.from(target), start: rows, rows: 0 };
      if (subscribeWhileRecording) ctx.setSubscribed(1, true);
    };
    const stop = (): void => {
      close();
      if (subscribeWhileRecording) ctx.setSubscribed(1, false);
    };

    let warnedFull = false;
    const record = (f: { t: Float64Array; v: Float64Array; n: number }): void => {
      const cur = current!;
      const n = f.n;
      const room = maxRows - rows;
      const take = n < room ? n : room;
      if (take < n) {
        dropped += n - take;
        if (!warnedFull) {
          warnedFull = true;
          ctx.warn(
            `the buffer is full (${plural(maxRows, "row")}, MaxRows): new rows are dropped; ` +
              "save, emit or clear it",
          );
        }
      }
      if (take === 0) return;
      grow(rows + take);
      const first = rows;
      const tg = cur.target;
      const v = f.v;
      for (let e = 0; e < take; e++) {
        const dst = (rows + e) * W;
        for (let k = 0; k < T; k++) values[dst + k] = tg[k]!;
        const src = e * D;
        for (let k = 0; k < D; k++) values[dst + T + k] = v[src + k]!;
        times[rows + e] = f.t[e]!;
      }
      rows += take;
      cur.rows += take;
      if (stream && !out.idle) {
        const o = out.frame(take);
        o.t.set(times.subarray(first, rows));
        o.v.set(values.subarray(first * W, rows * W));
        out.emit(o);
      }
    };

    const clear = (): void => {
      clusters.length = 0;
      rows = 0;
      dropped = 0;
      warnedFull = false;
      if (current) current = { target: current.target, start: 0, rows: 0 };
      lastSaved = "";
    };

    const targetOf = (arg: unknown): Float64Array => {
      if (typeof arg === "number" || (typeof arg === "string" && /^\s*\d+\s*$/.test(arg))) {
        if (T === 1) {
          const k = Number(arg);
          if (!Number.isFinite(k)) throw new Error(`expected a label index, got ${String(arg)}`);
          return Float64Array.of(k);
        }
        const k = indexArg(arg, T, `a label index (one-hot over the ${T} target values)`);
        const t = new Float64Array(T);
        t[k] = 1;
        return t;
      }
      return Float64Array.from(vectorArg(arg, `a target of ${T} values`, T));
    };

    const perTarget = (): string => {
      const groups: { target: Float64Array; clusters: number; rows: number }[] = [];
      const all = current && current.rows > 0 ? [...clusters, current] : clusters;
      for (const c of all) {
        const g = groups.find((x) => sameValues(x.target, c.target));
        if (g) {
          g.clusters++;
          g.rows += c.rows;
        } else groups.push({ target: c.target, clusters: 1, rows: c.rows });
      }
      return groups
        .map(
          (g) =>
            `${formatVector(g.target)}: ${plural(g.clusters, "cluster")}, ${plural(g.rows, "row")}`,
        )
        .join("; ");
    };

    const csv = (): string => {
      const lines: string[] = new Array<string>(rows);
      const parts: string[] = new Array<string>(W);
      for (let r = 0; r < rows; r++) {
        const off = r * W;
        for (let k = 0; k < W; k++) parts[k] = String(values[off + k]);
        lines[r] = parts.join(",");
      }
      return rows > 0 ? lines.join("\n") + "\n" : "";
    };

    return {
      process(f, port) {
        const n = f.n;
        if (n === 0) return;
        if (port === 0) {
          const v = f.v;
          for (let e = 0; e < n; e++) {
            let nan = 0;
            for (let k = 0; k < T; k++) if (Number.isNaN(v[e * T + k]!)) nan++;
            if (nan === T) stop();
            else if (nan > 0) {
              ctx.warn(
                `ignored a trigger event with ${nan} NaN of ${T} values: a target must be all ` +
                  "numbers, and a stop all NaN",
              );
            } else start(v.subarray(e * T, (e + 1) * T));
          }
          describe();
          return;
        }
        if (current === null) return;
        record(f);
        if (throttle.due(f.t[n - 1]!)) describe();
      },
      reset() {
        clusters.length = 0;
        current = null;
        rows = 0;
        dropped = 0;
        warnedFull = false;
        lastSaved = "";
        throttle.reset();
        describe();
      },
      setParam(name, value) {
        if (name === "Stream") stream = value as boolean;
      },
      dispose() {
        withdraw();
        closedListeners.clear();
      },
      actions: {
        start: {
          label: "Start recording",
          description:
            "Start (or switch to) a cluster with this target: a list of T numbers, or a label index",
          run(arg) {
            const t = targetOf(arg);
            start(t);
            describe();
            return `recording ${formatVector(t)}`;
          },
        },
        stop: {
          label: "Stop recording",
          description: "Close the current cluster",
          run() {
            stop();
            describe();
            return `stopped: ${summary()}`;
          },
        },
        clear: {
          label: "Clear",
          description: "Drop every stored row (recording, if on, goes on into an empty buffer)",
          run() {
            const n = rows;
            clear();
            describe();
            return `cleared ${plural(n, "row")}`;
          },
        },
        save: {
          label: "Save",
          description:
            "Write every row as a CSV line target…,data… to a file (default <block>.csv)",
          run(arg) {
            const file =
              typeof arg === "string" && arg.trim() !== "" ? arg.trim() : `${ctx.name}.csv`;
            if (rows === 0) return "the buffer is empty: nothing saved";
            const n = rows;
            const text = csv();
            ctx.resources.writeText(file, text).then(
              () => {
                lastSaved = `saved ${plural(n, "row")} to ${file}`;
                describe();
              },
              (e: unknown) => ctx.warn(`cannot save the buffer to ${file}: ${errorMessage(e)}`),
            );
            return `saving ${plural(n, "row")} to ${file}`;
          },
        },
        emit: {
          label: "Emit",
          description: "Send every stored row at once on the pairs output (one frame)",
          run() {
            if (rows === 0) return "the buffer is empty: nothing emitted";
            const o = out.frame(rows);
            o.t.set(times.subarray(0, rows));
            o.v.set(values.subarray(0, rows * W));
            out.emit(o);
            return `emitted ${plural(rows, "row")} of ${T} + ${D} values`;
          },
        },
        inspect: {
          label: "Inspect",
          description: "Clusters and rows per target",
          run() {
            const s = summary();
            const rec = current ? `; recording ${formatVector(current.target)}` : "";
            const full = dropped > 0 ? `; ${formatCount(dropped)} rows dropped (full)` : "";
            const detail = perTarget();
            return `${s}${rec}${full}${detail !== "" ? ` — ${detail}` : ""}`;
          },
        },
      },
    };
  },
});
