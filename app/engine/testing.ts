/**
 * Test helpers (Node-RED style: load a tiny flow, feed it, look at what comes out; Timeflux style:
 * set a block's input, call it, check its output). Used by block tests and integration tests.
 */
import {
  portMetaProblem,
  type AnyBlockDefinition,
  type BlockContext,
  type BlockInstance,
  type InputInfo,
  type OutputPort,
  type PortMeta,
  type Resources,
  type TimerHandle,
} from "./block";
import type { Catalog } from "./catalog";
import type { IoBridges } from "./io";
import { VirtualClock } from "./clock";
import { formatDiagnostic, type Diagnostic } from "./diagnostics";
import { Frame, FramePool, type Shape } from "./frame";
import { loadPipeline } from "./pipeline/loader";
import { MemoryLogSink } from "./runtime/logsink";
import { Runtime, type Telemetry } from "./runtime/runtime";
import type { CatchUp, TickCallback } from "./runtime/scheduler";
import { runVirtual } from "./runtime/virtual";

export interface Recorded {
  t: number[];
  v: number[][];
  /** Sizes of the frames as emitted. */
  frames: number[];
}

function record(into: Recorded, f: Frame): void {
  into.frames.push(f.n);
  for (let i = 0; i < f.n; i++) {
    into.t.push(f.t[i]!);
    into.v.push(Array.from(f.v.subarray(i * f.stride, (i + 1) * f.stride)));
  }
}

export const noResources: Resources = {
  resolve: (p) => p,
  readText: (p) => Promise.reject(new Error(`no file access in this test (asked for '${p}')`)),
  writeText: (p) =>
    Promise.reject(new Error(`no file access in this test (asked to write '${p}')`)),
};

export interface VirtualRunOptions {
  catalog: Catalog;
  /** Virtual seconds to run. */
  duration: number;
  file?: string;
  resources?: Resources;
  /** Virtual clock start (UNIX seconds). */
  start?: number;
  /** Blocks whose default output is recorded (default: all). */
  record?: string[];
  /** Called after start, before running (e.g. to invoke actions). */
  beforeRun?: (rt: Runtime) => void;
}

export interface VirtualRun {
  outputs: Map<string, Recorded>;
  telemetry: Telemetry;
  logs: MemoryLogSink;
  runtime: Runtime;
  diagnostics: Diagnostic[];
}

/** Loads `yaml`, runs it under the virtual clock and records every block's output. Throws on load errors. */
export async function runVirtualPipeline(
  yaml: string,
  opts: VirtualRunOptions,
): Promise<VirtualRun> {
  const file = opts.file ?? "test.yaml";
  const loaded = loadPipeline(yaml, file, opts.catalog);
  if (!loaded.spec) throw new Error(loaded.diagnostics.map(formatDiagnostic).join("\n"));
  const clock = new VirtualClock(opts.start ?? 0);
  const logs = new MemoryLogSink();
  const created = await Runtime.create({
    spec: loaded.spec,
    catalog: opts.catalog,
    clock,
    virtual: true,
    resources: opts.resources ?? noResources,
    logs,
    ignorePlacement: true,
  });
  if (!created.runtime) throw new Error(created.diagnostics.map(formatDiagnostic).join("\n"));
  const rt = created.runtime;
  const outputs = new Map<string, Recorded>();
  for (const n of rt.nodes) {
    if (opts.record && !opts.record.includes(n.name)) continue;
    if (n.ports.length === 0) continue;
    const r: Recorded = { t: [], v: [], frames: [] };
    outputs.set(n.name, r);
    rt.tap(n.name, undefined, (f) => record(r, f));
  }
  rt.start();
  opts.beforeRun?.(rt);
  runVirtual(rt, clock, clock.t + opts.duration);
  const telemetry = rt.telemetry();
  rt.dispose();
  return {
    outputs,
    telemetry,
    logs,
    runtime: rt,
    diagnostics: [...loaded.diagnostics, ...created.diagnostics],
  };
}

export interface HarnessOptions {
  inputs?: {
    shape: Shape | null;
    rate?: number;
    isTimer?: boolean;
    subscribed?: boolean;
    /** The source block's type (as `InputInfo.type`). */
    type?: string;
  }[];
  desiredRate?: number;
  now?: number;
  resources?: Resources;
  io?: IoBridges;
  virtual?: boolean;
  /** What `ctx.batching` reports (s, default 0). */
  batchingS?: number;
}

/**
 * One block outside any pipeline: feed frames with `push`, fire its timers with `tick`, read what
 * it emitted from `out`. Params are validated (defaults applied) as the loader would.
 */
export class BlockHarness {
  readonly out = new Map<string, Recorded>();
  readonly ports: OutputPort[] = [];
  /** The PortMeta each output declared, by port name. */
  readonly metas = new Map<string, PortMeta>();
  instance!: BlockInstance;
  readonly timers: {
    hz: number;
    tick: TickCallback;
    running: boolean;
    catchUp: CatchUp;
  }[] = [];
  oneShot: { t: number; fn: (t: number) => void } | null = null;
  text = "";
  warnings: string[] = [];
  /** What the block reported through `ctx.error` (message, and detail when given). */
  errors: string[] = [];
  /** The last count the block gave `ctx.setAwaiting`. */
  awaiting = 0;
  /** What the block reported through `ctx.reportCompute`. */
  computeReports: { ms: number; budgetMs?: number }[] = [];
  readonly logs = new MemoryLogSink();
  /** Subscription state the block asked for through `ctx.setSubscribed` (by input index). */
  readonly subscribed: Record<number, boolean> = {};
  finished = false;
  clock: number;
  desiredRate: number;
  params: unknown;

  private constructor(
    readonly def: AnyBlockDefinition,
    readonly opts: HarnessOptions,
  ) {
    this.clock = opts.now ?? 0;
    this.desiredRate = opts.desiredRate ?? opts.inputs?.find((i) => (i.rate ?? 0) > 0)?.rate ?? 0;
  }

  static async create(
    def: AnyBlockDefinition,
    rawParams: unknown,
    opts: HarnessOptions = {},
  ): Promise<BlockHarness> {
    const h = new BlockHarness(def, opts);
    const parsed = def.params.safeParse(rawParams ?? {});
    if (!parsed.success)
      throw new Error(
        `invalid params: ${parsed.error.issues.map((i: { path: PropertyKey[]; message: string }) => `${i.path.map(String).join(".")}: ${i.message}`).join("; ")}`,
      );
    h.params = parsed.data;
    h.instance = await def.create(h.context(), parsed.data);
    return h;
  }

  /** The BlockContext the block is created with: its inputs, clock, outputs, timers and reports. */
  private context(): BlockContext {
    const h = this;
    const inputs = harnessInputs(this.opts);
    return {
      name: "block",
      type: this.def.type,
      inputs,
      declaredRate: this.opts.desiredRate,
      get desiredRate() {
        return h.desiredRate;
      },
      setDesiredRate(hz: number) {
        h.desiredRate = hz;
      },
      now: () => h.clock,
      startTime: this.opts.now ?? 0,
      virtual: this.opts.virtual ?? true,
      resources: this.opts.resources ?? noResources,
      io: this.opts.io ?? {},
      output(shape: Shape, port?: string, meta?: PortMeta): OutputPort {
        return harnessOutput(h, shape, port, meta);
      },
      batching: this.opts.batchingS ?? 0,
      every(hz: number, tick: TickCallback, options?: { catchUp?: CatchUp }): TimerHandle {
        return harnessTimer(h, hz, tick, options);
      },
      ...harnessReports(h, inputs),
    };
  }

  start(): void {
    this.instance.start?.();
  }

  /** Delivers a frame to input `port`. */
  push(frame: Frame, port = 0): void {
    this.instance.process?.(frame, port);
    // Each push is a step of its own: blocks holding events for the step's end release them.
    this.instance.flush?.();
  }

  /** Fires every running timer once at time t. */
  tick(t: number): void {
    this.ticks([t]);
  }

  /** Fires every running timer with one batch of ticks at these times (the clock ends at the last). */
  ticks(times: readonly number[]): void {
    if (times.length === 0) return;
    this.clock = times[times.length - 1]!;
    const batch = Float64Array.from(times);
    for (const e of this.timers) if (e.running) e.tick(batch, batch.length);
  }

  /** Fires the pending one-shot, if any, at its time. */
  fireOneShot(): boolean {
    const o = this.oneShot;
    if (!o) return false;
    this.oneShot = null;
    this.clock = o.t;
    o.fn(o.t);
    return true;
  }

  output(port = "out"): Recorded {
    const r = this.out.get(port);
    if (!r) throw new Error(`no output '${port}'`);
    return r;
  }

  clear(): void {
    for (const r of this.out.values()) {
      r.t.length = 0;
      r.v.length = 0;
      r.frames.length = 0;
    }
  }
}

/** The inputs a harnessed block is told about, from `HarnessOptions.inputs`. */
function harnessInputs(opts: HarnessOptions): InputInfo[] {
  return (opts.inputs ?? []).map((i, index) => ({
    index,
    source: `in${index}`,
    block: `in${index}`,
    port: "out",
    ...(i.type === undefined ? {} : { type: i.type }),
    shape: i.shape,
    rate: i.rate ?? 0,
    isTimer: i.isTimer ?? false,
    subscribed: i.subscribed ?? true,
  }));
}

/** `ctx.output` of a harnessed block: a port whose frames are recorded into `h.out`. */
function harnessOutput(h: BlockHarness, shape: Shape, port?: string, meta?: PortMeta): OutputPort {
  const name = port ?? "out";
  const problem = meta && portMetaProblem(meta, shape.rows * shape.cols);
  if (problem) throw new Error(`output '${name}': ${problem}`);
  if (meta) h.metas.set(name, meta);
  const pool = new FramePool(shape);
  const rec: Recorded = { t: [], v: [], frames: [] };
  h.out.set(name, rec);
  const p: OutputPort = {
    name,
    shape,
    idle: false,
    frame: (n: number) => pool.take(n),
    emit: (f: Frame) => {
      record(rec, f);
      pool.release(f);
    },
  };
  h.ports.push(p);
  return p;
}

/** `ctx.every` of a harnessed block: a timer in `h.timers`, fired by `tick` while running. */
function harnessTimer(
  h: BlockHarness,
  hz: number,
  tick: TickCallback,
  options?: { catchUp?: CatchUp },
): TimerHandle {
  const entry = {
    hz,
    tick,
    running: false,
    fired: 0,
    missed: 0,
    catchUp: options?.catchUp ?? "all",
  };
  h.timers.push(entry);
  return {
    start: () => {
      entry.running = true;
    },
    stop: () => {
      entry.running = false;
    },
    get running() {
      return entry.running;
    },
    get fired() {
      return entry.fired;
    },
    get missed() {
      return entry.missed;
    },
    setRate: (r: number) => {
      entry.hz = r;
    },
  };
}

/** The rest of a harnessed block's context: one-shots, and what it reports (kept in `h`). */
function harnessReports(
  h: BlockHarness,
  inputs: readonly InputInfo[],
): Pick<
  BlockContext,
  | "at"
  | "setText"
  | "warn"
  | "error"
  | "setAwaiting"
  | "reportCompute"
  | "finish"
  | "setSubscribed"
  | "openLog"
> {
  return {
    at(t: number, fn: (t: number) => void) {
      h.oneShot = { t, fn };
    },
    setText(text: string) {
      h.text = text;
    },
    warn(message: string) {
      h.warnings.push(message);
    },
    error(message: string, detail?: string) {
      h.errors.push(detail ? `${message}\n${detail}` : message);
    },
    setAwaiting(count: number) {
      h.awaiting = count;
    },
    reportCompute(ms: number, budgetMs?: number) {
      h.computeReports.push({ ms, ...(budgetMs === undefined ? {} : { budgetMs }) });
    },
    finish() {
      h.finished = true;
    },
    setSubscribed(index: number, subscribed: boolean) {
      const i = inputs[index];
      if (!i) return false;
      h.subscribed[index] = subscribed;
      return true;
    },
    openLog(path: string, stream: string) {
      return h.logs.open(stream, "out", true, path);
    },
  };
}
