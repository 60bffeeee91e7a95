/**
 * The block API. A block type is one `defineBlock({...})` call: its zod params schema is the single
 * source of truth for the TypeScript type, the JSON Schema, the control-panel form and the docs.
 *
 * Life cycle: `create(ctx, params)` (at load: allocate state, declare outputs, no I/O besides
 * reading files it needs to know its output shape) → `start()` (the pipeline runs: open devices,
 * timers begin) → `process(frame, port)` for every input frame → `stop()` → `dispose()`.
 */
import type { z } from "zod";
import type { Frame, Shape } from "./frame";
import type { IoBridges } from "./io";
import type { LogChannel } from "./runtime/logsink";
import type { CatchUp, TickCallback } from "./runtime/scheduler";

export type BlockCategory =
  | "Timing"
  | "Sources"
  | "Signal processing"
  | "Features"
  | "Kinematics"
  | "Flow control"
  | "Learning"
  | "Control"
  | "Communication"
  | "Devices"
  | "Recording"
  | "Testing";

/**
 * Control-panel views a block offers (drawn by the UI): "training" is a predictor's feedback
 * (prediction versus target, R², gestures; its model file), "player" a file player's transport.
 */
export type BlockView =
  "scope" | "spider" | "heatmap" | "label" | "stimulus" | "training" | "player";

export interface InputSpec {
  /** Fewest inputs the block accepts. */
  min: number;
  /** Most inputs the block accepts (Infinity for any number). */
  max: number;
  /** Optional names of the input positions, for messages and the UI ("signal", "timer"). */
  labels?: readonly string[];
}

export interface InputInfo {
  /** Position of this input in the block's `Inputs` list. */
  readonly index: number;
  /** The reference as written, without the leading '-': "Block" or "Block.port". */
  readonly source: string;
  readonly block: string;
  readonly port: string;
  /** The source block's type (canonical name, e.g. "ControlAlgorithm"); undefined when unknown. */
  readonly type?: string;
  /** The source's output shape; null only inside a feedback cycle whose source is created later. */
  readonly shape: Shape | null;
  /** The source's desired rate in Hz; 0 when aperiodic or unknown. */
  readonly rate: number;
  /** True when the source is a timer (its events carry no values). */
  readonly isTimer: boolean;
  /** False for inputs written `-Name`: declared, subscribed only at run time. */
  readonly subscribed: boolean;
  /** What the source's channels are (names, unit, electrode grid), when it says. */
  readonly meta?: PortMeta;
}

/**
 * What an output's values are, for people and for recorders: channel names, unit, and where the
 * channels sit on an electrode grid. Shown by the panels (scope legend, heatmap layout), written
 * into recordings (XDF channel labels, EDF+ signal labels) and LSL stream descriptions.
 */
export interface PortMeta {
  /** One name per value (rows × cols, row-major), e.g. "sensor 3 (EMG)". */
  readonly labels?: readonly string[];
  /** Physical unit of every value ("V", "mV", "g"), when one holds for all. */
  readonly unit?: string;
  /** Where the values sit on an electrode grid (HD-EMG arrays): the heatmap's default layout. */
  readonly grid?: ElectrodeGrid;
}

export interface ElectrodeGrid {
  readonly rows: number;
  readonly cols: number;
  /** The value (0-based channel) shown in each cell, row-major; -1: no electrode there. */
  readonly cells: readonly number[];
  /** The array's name, e.g. "GR10MM0804". */
  readonly name?: string;
}

/** Why `meta` does not fit a port of `n` values; undefined when it does. */
export function portMetaProblem(meta: PortMeta, n: number): string | undefined {
  if (meta.labels !== undefined && meta.labels.length !== n) {
    return `${meta.labels.length} channel labels for ${n} values`;
  }
  const g = meta.grid;
  if (g === undefined) return undefined;
  if (!(Number.isInteger(g.rows) && Number.isInteger(g.cols) && g.rows > 0 && g.cols > 0)) {
    return `an electrode grid of ${g.rows} × ${g.cols}`;
  }
  if (g.cells.length !== g.rows * g.cols) {
    return `an electrode grid of ${g.rows} × ${g.cols} with ${g.cells.length} cells`;
  }
  const bad = g.cells.find((c) => !Number.isInteger(c) || c < -1 || c >= n);
  return bad === undefined ? undefined : `electrode grid cell ${bad} is not a channel of ${n}`;
}

/** File access for blocks; paths are resolved against the pipeline file's folder. */
export interface Resources {
  resolve(path: string): string;
  readText(path: string): Promise<string>;
  /**
   * Writes a whole text file (creating its folder), e.g. a Buffer's dataset saved on request.
   * Not for streams: use `ctx.openLog` for data that keeps coming.
   */
  writeText(path: string, text: string): Promise<void>;
  /**
   * True when the pipeline came from a client of `mosaic serve` or the desktop app's window:
   * reads and writes are confined to allowed folders, and blocks must not reach code or files
   * outside them by other means (e.g. a Python block importing an installed module by name).
   */
  readonly confined?: boolean;
  /**
   * Opens a file to read in pieces, synchronously (a big recording read as it plays); where the
   * host has no such access (browsers) it is absent and blocks read the whole text. Throws with a
   * message saying what is wrong (not found, no permission, outside the allowed folders).
   */
  openRead?(path: string): FileReadHandle;
  /**
   * Creates a binary file to write in pieces, synchronously (a recorder's XDF or EDF+ file; its
   * folders are created). An existing file is an error unless `overwrite`. Absent where the host
   * cannot write files (browsers: recorders download instead). Throws with a message saying what
   * is wrong (exists, no permission, disk full, outside the allowed folders).
   */
  openWrite?(path: string, options?: { overwrite?: boolean }): FileWriteHandle;
}

/** A file created by `Resources.openWrite`; each call reaches the operating system at once. */
export interface FileWriteHandle {
  /** The full path, for messages. */
  readonly path: string;
  /** Bytes appended so far. */
  readonly size: number;
  /** Appends `bytes` at the end. */
  write(bytes: Uint8Array): void;
  /** Overwrites bytes already written, at byte `position` (a header's record count). */
  writeAt(bytes: Uint8Array, position: number): void;
  /** Asks the disk to keep what was written (fdatasync); costly: at most about once a second. */
  sync(): void;
  close(): void;
}

/** A file opened by `Resources.openRead`. */
export interface FileReadHandle {
  /** The full path, for messages. */
  readonly path: string;
  /** Its size in bytes when opened; NaN when it is not a regular file (a device, a pipe: not opened). */
  readonly size: number;
  /** Reads up to `into.length` bytes at byte `position` into `into`; returns how many (0: the end). */
  read(into: Uint8Array, position: number): number;
  close(): void;
}

export interface TimerHandle {
  start(): void;
  stop(): void;
  readonly running: boolean;
  /** Ticks delivered since creation. */
  readonly fired: number;
  /** Ticks skipped after a stall (only with `catchUp: "skip"`; otherwise every tick goes out). */
  readonly missed: number;
  setRate(hz: number): void;
}

export interface OutputPort {
  readonly name: string;
  readonly shape: Shape;
  /** A writable frame with room for `n` events and `frame.n === n`. */
  frame(n: number): Frame;
  /** Sends a frame obtained from `frame()`; the port takes it back once delivered. */
  emit(frame: Frame): void;
  /** True when nothing listens (no subscribed edge, no log): a block may skip work. */
  readonly idle: boolean;
}

export interface BlockContext {
  readonly name: string;
  readonly type: string;
  readonly inputs: readonly InputInfo[];
  /** The rate written as `DesiredRate`, if any. */
  readonly declaredRate: number | undefined;
  /** The resolved desired rate in Hz (declared, or inherited from the inputs); 0 = aperiodic. */
  readonly desiredRate: number;
  /** Overrides the resolved desired rate (e.g. a FilePlayer that learns it from the file). */
  setDesiredRate(hz: number): void;
  /** Current time on the pipeline clock, UNIX seconds (virtual time under the virtual clock). */
  now(): number;
  /** Clock time at which the pipeline started (valid from `start()` on). */
  readonly startTime: number;
  /** True under the virtual clock (as fast as possible, deterministic). */
  readonly virtual: boolean;
  readonly resources: Resources;
  /** Device and network I/O provided by the host (empty in the browser build). */
  readonly io: IoBridges;
  /**
   * Declares an output port (the first declared port is the default one). `meta` names its
   * channels (and unit, electrode grid); without it a port of the same shape as the block's first
   * value input inherits that input's meta (a filter keeps its input's channel names).
   */
  output(shape: Shape, port?: string, meta?: PortMeta): OutputPort;
  /**
   * The batching interval that applies to this block, s (DESIGN.md §3): its timers' ticks may
   * wait this long to go out together. Self-timed sources (`at`) may batch the same way.
   */
  readonly batching: number;
  /**
   * A periodic callback on the high-resolution scheduler, lossless: each call receives every
   * tick due since the previous one (`n` ≥ 1), their deadlines in `times[0 … n)` (base + k / hz;
   * read them during the call). With `catchUp: "skip"` a call after a stall gets only the newest
   * tick and the skipped ones are counted as missed.
   */
  every(hz: number, tick: TickCallback, options?: { catchUp?: CatchUp }): TimerHandle;
  /**
   * A one-shot callback at clock time `t`; a later call replaces a pending one. With `latest`
   * (> t), it may run anywhere from `t` to `latest`: when the worker wakes for something else in
   * between (as batched timer ticks do), else at `latest` — for a source whose events go out
   * together within a batching interval, so that they are delivered in the same steps as the
   * timers' ticks of the same times. The callback gets its due time `t`; `ctx.now()` is when it
   * really runs.
   */
  at(t: number, fn: (t: number) => void, latest?: number): void;
  /** One line of live status text ("waiting for device", "row 120/2000"). */
  setText(text: string): void;
  /** A warning shown in the block's status (and printed by the CLI), rate-limited. */
  warn(message: string): void;
  /**
   * Reports an error that happened outside `process` (a failed sidecar call, a crashed helper
   * process): counted like an exception thrown by `process` (the block's `errors`, `lastError`,
   * an error event, rate-limited; `mosaic run` exits 1). `detail` (a traceback) goes with the
   * event only.
   */
  error(message: string, detail?: string): void;
  /**
   * How many results this block still waits for from outside the engine (calls in flight in a
   * sidecar, inputs queued for them); 0 when none. Under the virtual clock, time does not advance
   * while any block waits, so a replay does not depend on how fast the outside answers; real time
   * ignores it.
   */
  setAwaiting(count: number): void;
  /**
   * Reports work done for this block outside `process`, e.g. a call in the Python sidecar that
   * `process` only handed over: `ms` joins the block's compute max (not its CPU total), and a call
   * longer than `budgetMs` (default one period, 1 / DesiredRate) marks the block stumbling, as a
   * measured `process` call that long would.
   */
  reportCompute(ms: number, budgetMs?: number): void;
  /** Declares that this (finite) source is exhausted; a run ends when all finite sources are. */
  finish(): void;
  /**
   * Subscribes or unsubscribes one of this block's own inputs at run time (MOSAIC's Buffer
   * subscribes its `-Data` input while it records). Returns false when `index` is not an input.
   */
  setSubscribed(index: number, subscribed: boolean): boolean;
  /**
   * Opens a log file in the same line format as `Path` (for the Logger block). `path` is a folder
   * or a file, like `Path`; `stream` names the file inside a folder (`<stream>.txt`). Returns null
   * when this runtime has no log sink (then say so in the block's status).
   */
  openLog(path: string, stream: string, shape: Shape): LogChannel | null;
}

export interface BlockAction {
  label: string;
  description?: string;
  run(arg?: unknown): string | void;
}

export interface BlockInstance {
  process?(frame: Frame, port: number): void;
  /**
   * Called when the worker has delivered everything queued in a step, for blocks that hold events
   * back while the same step may still deliver what they wait for (a Resampler's tick waits for
   * the signal events of its own time). Emit what is still held; do nothing when nothing is.
   */
  flush?(): void;
  start?(): void;
  stop?(): void;
  /** Clears internal state: after reset the block behaves as if just created. */
  reset?(): void;
  dispose?(): void;
  actions?: Record<string, BlockAction>;
  /** Applies a live-settable param (already validated against the schema). */
  setParam?(name: string, value: unknown): void;
}

export interface BlockDefinition<S extends z.ZodType = z.ZodType> {
  /** Never changes once released: saved pipelines depend on it. */
  type: string;
  /** Other names files may use for this type (MOSAIC's class names); loading one warns. */
  aliases?: readonly string[];
  category: BlockCategory;
  /** One line. */
  summary: string;
  /** One paragraph of help (Markdown), with references where the block implements a published definition. */
  help: string;
  params: S;
  /**
   * Converts MOSAIC's positional `Params` (a list of strings such as `[multiply:5]` or
   * `[b0;b1;b2, 1;a1;a2]`) into the named form, which is then validated by `params`.
   */
  legacyParams?: (args: readonly string[]) => unknown;
  /** The positional form, for docs: e.g. "[numerator, denominator] as a;b;c vectors". */
  legacyForm?: string;
  inputs: InputSpec;
  /** Output port names; the first is the default. A function when ports depend on params. */
  outputs?: readonly string[] | ((params: z.output<S>) => readonly string[]);
  /**
   * True for blocks fed by I/O callbacks (sockets, serial ports, child processes): the worker that
   * runs them then sleeps in its event loop between ticks, so that data wakes it at once.
   */
  eventLoop?: boolean;
  /** Timers drive pipelines: their ticks carry no values and `DesiredRate` is required. */
  timer?: boolean;
  /** True when the block needs `DesiredRate` written in the file. */
  requiresRate?: boolean;
  /** True when, with these params, the block is a finite source that calls `ctx.finish()`. */
  finite?: (params: z.output<S>) => boolean;
  /** Params that may be changed while running. */
  live?: readonly string[];
  /** Views its control panel offers. */
  views?: readonly BlockView[];
  /** What the control panel shows, in one sentence (drawn by the UI). */
  panel?: string;
  create(ctx: BlockContext, params: z.output<S>): BlockInstance | Promise<BlockInstance>;
}

/** Declares a block type; identity at run time, but infers the params type for `create`. */
export function defineBlock<S extends z.ZodType>(def: BlockDefinition<S>): BlockDefinition<S> {
  return def;
}

// eslint-disable-next-line @typescript-eslint/no-explicit-any
export type AnyBlockDefinition = BlockDefinition<any>;

export function outputNames(def: AnyBlockDefinition, params: unknown): readonly string[] {
  const o = def.outputs;
  if (o === undefined) return ["out"];
  return typeof o === "function" ? o(params) : o;
}
