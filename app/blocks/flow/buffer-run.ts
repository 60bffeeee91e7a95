/**
 * One Buffer's run (buffer.ts): the trigger events that start and stop clusters, the data rows
 * recorded into the store (buffer-store.ts), the `pairs` output, the rows offered by name to
 * BatchPredictor and PythonNetLearning, the status text and the actions.
 */
import {
  BlockConfigError,
  errorMessage,
  vectorShape,
  type BlockAction,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type OutputPort,
} from "../../engine";
import { indexArg, vectorArg } from "../shared/args";
import { signalInput, vectorInput } from "../shared/inputs";
import { publish } from "../shared/named";
import { formatCount, formatVector, plural, TextThrottle } from "../shared/text";
import type { BufferRows } from "./buffer";
import { BufferStore } from "./buffer-store";

/** Most values the store may hold (1 GiB of doubles). */
const MAX_VALUES = 2 ** 27;

export interface BufferOptions {
  Stream: boolean;
  MaxRows: number;
}

/** MaxRows rows of T + D values must fit in MAX_VALUES. */
function checkMaxRows(maxRows: number, T: number, D: number): void {
  const W = T + D;
  if (maxRows * W <= MAX_VALUES) return;
  throw new BlockConfigError(
    `MaxRows ${formatCount(maxRows)} rows of ${T} + ${D} values would take up to ` +
      `${((maxRows * W * 8) / 2 ** 30).toFixed(1)} GiB; the Buffer keeps at most ` +
      `${formatCount(MAX_VALUES)} values (1 GiB): set MaxRows to ` +
      `${formatCount(Math.floor(MAX_VALUES / W))} or less`,
    "MaxRows",
  );
}

/** The `start` action's target: a list of T numbers, or a label index ([k] when T = 1, else e_k). */
function targetArg(arg: unknown, T: number): Float64Array {
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
}

export class BufferRun {
  private readonly store: BufferStore;
  private readonly out: OutputPort;
  private readonly withdraw: () => void;
  private readonly closedListeners = new Set<() => void>();
  private readonly throttle = new TextThrottle();
  /** A `-Data` input (MOSAIC's form) is subscribed while recording, as MOSAIC's Buffer did. */
  private readonly subscribeWhileRecording: boolean;
  private stream: boolean;
  private warnedFull = false;
  /** "saved N rows to FILE" after a save, until the rows change. */
  private lastSaved = "";

  constructor(
    private readonly ctx: BlockContext,
    p: BufferOptions,
  ) {
    const trig = vectorInput(ctx, 0);
    const data = signalInput(ctx, 1);
    const T = trig.size;
    const D = data.size;
    // Aperiodic: it emits on request (MOSAIC set its rate to 0).
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    // Rows [target…, data…] are named after both inputs' values when both name them.
    const tl = trig.info.meta?.labels;
    const dl = data.info.meta?.labels;
    this.out = ctx.output(
      vectorShape(T + D),
      "pairs",
      tl?.length === T && dl?.length === D ? { labels: [...tl, ...dl] } : undefined,
    );
    checkMaxRows(p.MaxRows, T, D);
    this.stream = p.Stream;
    this.store = new BufferStore(T, D, p.MaxRows);
    this.subscribeWhileRecording = !data.info.subscribed;
    this.describe();
    this.withdraw = this.publishRows();
  }

  instance(): BlockInstance {
    return {
      process: (f, port) => {
        if (f.n === 0) return;
        if (port === 0) this.onTriggers(f);
        else this.onData(f);
      },
      reset: () => this.reset(),
      setParam: (name, value) => {
        if (name === "Stream") this.stream = value as boolean;
      },
      dispose: () => {
        this.withdraw();
        this.closedListeners.clear();
      },
      actions: this.actions(),
    };
  }

  /** Offers the rows by the block's name (kind "Buffer"); returns the withdrawal. */
  private publishRows(): () => void {
    const store = this.store;
    return publish(this.ctx, "Buffer", {
      targetWidth: store.T,
      dataWidth: store.D,
      rows: () => store.rows,
      values: () => store.rowValues(),
      onClusterClosed: (fn: () => void) => {
        this.closedListeners.add(fn);
        return () => this.closedListeners.delete(fn);
      },
    } satisfies BufferRows);
  }

  // -------------------------------------------------------------------------------------------
  // Recording

  /** Trigger events: a target starts (or switches) recording, all NaN stops it. */
  private onTriggers(f: Frame): void {
    const T = this.store.T;
    const v = f.v;
    for (let e = 0; e < f.n; e++) {
      let nan = 0;
      for (let k = 0; k < T; k++) if (Number.isNaN(v[e * T + k]!)) nan++;
      if (nan === T) this.stop();
      else if (nan > 0) {
        this.ctx.warn(
          `ignored a trigger event with ${nan} NaN of ${T} values: a target must be all ` +
            "numbers, and a stop all NaN",
        );
      } else this.start(v.subarray(e * T, (e + 1) * T));
    }
    this.describe();
  }

  /** Data events: stored as rows while recording, ignored otherwise. */
  private onData(f: Frame): void {
    if (this.store.current === null) return;
    this.record(f);
    if (this.throttle.due(f.t[f.n - 1]!)) this.describe();
  }

  /** Starts recording a cluster with `target`, unless it is the one being recorded. */
  private start(target: ArrayLike<number>): void {
    if (this.store.recording(target)) return;
    this.closeCluster();
    this.store.open(target);
    if (this.subscribeWhileRecording) this.ctx.setSubscribed(1, true);
  }

  private stop(): void {
    this.closeCluster();
    if (this.subscribeWhileRecording) this.ctx.setSubscribed(1, false);
  }

  /** Closes the current cluster; blocks reading the rows by name hear of it if it had rows. */
  private closeCluster(): void {
    if (this.store.close()) for (const fn of this.closedListeners) fn();
  }

  /** Stores a data frame's events as rows (warns once when the buffer is full); streams them. */
  private record(f: Frame): void {
    const store = this.store;
    const first = store.rows;
    const taken = store.append(f.t, f.v, f.n);
    if (taken < f.n && !this.warnedFull) {
      this.warnedFull = true;
      this.ctx.warn(
        `the buffer is full (${plural(store.maxRows, "row")}, MaxRows): new rows are dropped; ` +
          "save, emit or clear it",
      );
    }
    if (taken > 0 && this.stream && !this.out.idle) this.emitRows(first, store.rows);
  }

  /** Sends rows [from, to) as one frame on `pairs`. */
  private emitRows(from: number, to: number): void {
    const o = this.out.frame(to - from);
    o.t.set(this.store.rowTimes(from, to));
    o.v.set(this.store.rowValues(from, to));
    this.out.emit(o);
  }

  private clear(): void {
    this.store.clear();
    this.warnedFull = false;
    this.lastSaved = "";
  }

  private reset(): void {
    this.store.reset();
    this.warnedFull = false;
    this.lastSaved = "";
    this.throttle.reset();
    this.describe();
  }

  // -------------------------------------------------------------------------------------------
  // Status text and actions

  private describe(): void {
    this.ctx.setText(this.statusText());
  }

  private statusText(): string {
    const { rows, maxRows, current, dropped } = this.store;
    if (rows >= maxRows && (current !== null || dropped > 0)) {
      return (
        `full: ${plural(rows, "row")} (MaxRows)` +
        (dropped > 0 ? `, ${formatCount(dropped)} dropped` : "") +
        "; save, emit or clear to record more"
      );
    }
    if (current)
      return `recording ${formatVector(current.target)} (${plural(current.rows, "row")})`;
    const s = this.store.summary();
    return this.lastSaved !== "" ? `${s} (${this.lastSaved})` : s;
  }

  /** Writes every row as CSV to `arg` (default `<block>.csv`); the status says when it is saved. */
  private save(arg: unknown): string {
    const file = typeof arg === "string" && arg.trim() !== "" ? arg.trim() : `${this.ctx.name}.csv`;
    const n = this.store.rows;
    if (n === 0) return "the buffer is empty: nothing saved";
    this.ctx.resources.writeText(file, this.store.csv()).then(
      () => {
        this.lastSaved = `saved ${plural(n, "row")} to ${file}`;
        this.describe();
      },
      (e: unknown) => this.ctx.warn(`cannot save the buffer to ${file}: ${errorMessage(e)}`),
    );
    return `saving ${plural(n, "row")} to ${file}`;
  }

  /** Sends every stored row at once. */
  private emitAll(): string {
    const { rows, T, D } = this.store;
    if (rows === 0) return "the buffer is empty: nothing emitted";
    this.emitRows(0, rows);
    return `emitted ${plural(rows, "row")} of ${T} + ${D} values`;
  }

  /** Clusters and rows per target. */
  private inspect(): string {
    const { current, dropped } = this.store;
    const rec = current ? `; recording ${formatVector(current.target)}` : "";
    const full = dropped > 0 ? `; ${formatCount(dropped)} rows dropped (full)` : "";
    const detail = this.store.perTarget();
    return `${this.store.summary()}${rec}${full}${detail !== "" ? ` — ${detail}` : ""}`;
  }

  private actions(): Record<string, BlockAction> {
    return {
      start: {
        label: "Start recording",
        description:
          "Start (or switch to) a cluster with this target: a list of T numbers, or a label index",
        run: (arg) => {
          const t = targetArg(arg, this.store.T);
          this.start(t);
          this.describe();
          return `recording ${formatVector(t)}`;
        },
      },
      stop: {
        label: "Stop recording",
        description: "Close the current cluster",
        run: () => {
          this.stop();
          this.describe();
          return `stopped: ${this.store.summary()}`;
        },
      },
      clear: {
        label: "Clear",
        description: "Drop every stored row (recording, if on, goes on into an empty buffer)",
        run: () => {
          const n = this.store.rows;
          this.clear();
          this.describe();
          return `cleared ${plural(n, "row")}`;
        },
      },
      save: {
        label: "Save",
        description: "Write every row as a CSV line target…,data… to a file (default <block>.csv)",
        run: (arg) => this.save(arg),
      },
      emit: {
        label: "Emit",
        description: "Send every stored row at once on the pairs output (one frame)",
        run: () => this.emitAll(),
      },
      inspect: {
        label: "Inspect",
        description: "Clusters and rows per target",
        run: () => this.inspect(),
      },
    };
  }
}
