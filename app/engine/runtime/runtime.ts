/**
 * The runtime of one worker: instantiates the blocks placed on it, delivers frames along edges,
 * fires timers, tracks status, answers control requests and produces telemetry.
 *
 * Delivery is breadth-first through one FIFO per worker: an emitted frame is queued on every
 * subscribed edge (bounded, with an overflow policy and a drop counter) and the consumer runs when
 * its turn comes. Blocks never re-enter, feedback cycles are fine, and the order of deliveries is
 * deterministic, which the virtual clock relies on for byte-identical logs.
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
} from "../block";
import type { Catalog } from "../catalog";
import { BlockConfigError, errorMessage, type Diagnostic } from "../diagnostics";
import { Frame, FramePool, formatShape, type Shape } from "../frame";
import type { BlockSpec, PipelineSpec, QueuePolicy, SourcePos } from "../pipeline/loader";
import type { Clock } from "../clock";
import type { IoBridges } from "../io";
import { Deque } from "./deque";
import type { LogChannel, LogSink } from "./logsink";
import type { SabRing } from "./sab-ring";
import { Scheduler, type CatchUp, type TickCallback, type TimerEntry } from "./scheduler";
import { StatusTracker, type Status } from "./status";

// ---------------------------------------------------------------------------------------------
// Telemetry types

export interface BlockTelemetry {
  name: string;
  type: string;
  worker: string;
  status: Status;
  lagging: boolean;
  stumbling: boolean;
  /** Actual rate over the last 100 outputs, Hz (0 when unknown). */
  rate: number;
  desiredRate: number;
  events: number;
  computeLastMs: number;
  computeMeanMs: number;
  computeMaxMs: number;
  /** Mean (emission time − event timestamp) since the previous telemetry, ms. */
  latencyMs: number;
  /**
   * Delivery delay: time of processing − timestamp of the oldest event of each batch the block
   * received (timers: of each batch of ticks they fired), ms; p50/p99/max since the start or the
   * last `resetTiming`, and the largest since the previous telemetry. Real time only (0 under the
   * virtual clock). `n` counts batches.
   */
  delay: {
    p50Ms: number;
    p99Ms: number;
    maxMs: number;
    windowMaxMs: number;
    n: number;
    /** A batch delayed longer than this is late: the block reads as lagging. */
    lateMs: number;
  };
  /** Events dropped on the edges into this block (all time). */
  dropsIn: number;
  text: string;
  errors: number;
  lastError: string;
  finished: boolean;
  /** Timers only. */
  timer?: {
    /** Ticks delivered. */
    fired: number;
    /** Ticks skipped (`CatchUp: skip` only; a lossless timer never misses one). */
    missed: number;
    catchUp: CatchUp;
    /** The timer's batching interval, ms. */
    batchingMs: number;
    latenessP50Us: number;
    latenessP99Us: number;
    latenessMaxUs: number;
    running: boolean;
  };
  /** ΔT between consecutive output events (timestamps), since start or the last `resetTiming`. */
  timing: { n: number; meanDt: number; stdDt: number; computeTotalMs: number; calls: number };
}

export interface EdgeTelemetry {
  id: number;
  from: string;
  fromPort: string;
  to: string;
  toIndex: number;
  subscribed: boolean;
  rate: number;
  delivered: number;
  dropped: number;
  pending: number;
}

export interface RuntimeEvent {
  t: number;
  level: "error" | "warning" | "info";
  block: string;
  message: string;
}

export interface Telemetry {
  t: number;
  worker: string;
  blocks: BlockTelemetry[];
  edges: EdgeTelemetry[];
  events: RuntimeEvent[];
  finished: boolean;
}

// ---------------------------------------------------------------------------------------------
// Plan: what every worker must know about every block (shapes and rates), computed once.

export interface PlanBlock {
  name: string;
  type: string;
  worker: string;
  desiredRate: number;
  isTimer: boolean;
  finite: boolean;
  outputs: { name: string; shape: Shape; meta?: PortMeta }[];
  inputs: { block: string; port: string }[];
  /** The block's declared input queue capacity (events), if any. */
  queueCapacity?: number;
}
export interface Plan {
  blocks: PlanBlock[];
}

// ---------------------------------------------------------------------------------------------

const DEFAULT_QUEUE_MIN = 64;
/**
 * The default batching interval (DESIGN.md §3): a worker wakes at most once per interval and
 * fires every tick due, as devices deliver packets. Chosen from `mosaic bench --only batching`
 * on the 2-core bench machine (bench/README.md, "Batching sweep"): a wake-up costs far more than
 * the work it triggers there, so CPU falls with the wake-up rate — the Delsys pipeline (1926 Hz)
 * wakes 1828 / 836 / 474 / 196 / 97 times a second at 0 / 1 / 2 / 5 / 10 ms, and the Myo
 * pipeline (200 Hz) only drops below one wake-up per sample from 5 ms (two samples a wake-up, as
 * the armband's notifications carry). 5 ms is the knee: both pipelines at about 60 % of their 2 ms
 * CPU, delivery delay p99 within 6 ms — below every device's own packet interval (Trigno 13.5 ms,
 * Myo 10 ms) and far below the ~100 ms a myoelectric control loop tolerates.
 */
export const DEFAULT_BATCHING_S = 0.005;
const WARN_INTERVAL_S = 2;

export interface RemoteSender {
  /** Copies the frame into the cross-worker ring; returns events dropped (ring full). */
  write(frame: Frame): number;
}

export interface RuntimeOptions {
  spec: PipelineSpec;
  catalog: Catalog;
  clock: Clock;
  virtual: boolean;
  resources: Resources;
  /** Device and network bridges (Node host); none in browsers. */
  io?: IoBridges;
  logs?: LogSink;
  /** Name of this worker ("main" by default); blocks placed elsewhere are not instantiated. */
  worker?: string;
  /** Shapes and rates from the planning worker, required when blocks live on other workers. */
  plan?: Plan;
  /** Run every block here regardless of its `Worker` key (the virtual clock does this). */
  ignorePlacement?: boolean;
  /**
   * The batching interval for blocks that do not set their own (`BatchingMs`), s: overrides the
   * pipeline's `Pipeline: { BatchingMs }` (the CLI's `--batching-ms`).
   */
  batchingS?: number;
}

class Edge {
  readonly queue = new Deque<Frame>(8);
  pendingEvents = 0;
  skip = 0;
  delivered = 0;
  dropped = 0;
  readonly times = new Float64Array(100);
  private ti = 0;
  private tn = 0;
  one: Frame | null = null;
  /** Consumer side of a cross-worker edge: the ring to drain, and frames to read into. */
  inbound: SabRing | null = null;
  inPool: FramePool | null = null;
  /** The source's output shape (known from the plan even when the source is on another worker). */
  srcShape: Shape | null = null;

  constructor(
    readonly id: number,
    readonly fromName: string,
    readonly fromPort: OutPort | null,
    readonly fromPortName: string,
    readonly to: Node,
    readonly toIndex: number,
    public subscribed: boolean,
    readonly policy: QueuePolicy,
    readonly capacity: number,
  ) {}

  noteTimes(f: Frame): void {
    const n = f.n;
    const s = n > 100 ? n - 100 : 0;
    for (let i = s; i < n; i++) {
      this.times[this.ti] = f.t[i]!;
      this.ti = (this.ti + 1) % 100;
    }
    this.tn = Math.min(100, this.tn + n - s);
  }

  rate(): number {
    if (this.tn < 2) return 0;
    const last = this.times[(this.ti - 1 + 100) % 100]!;
    const first = this.times[(this.ti - this.tn + 100) % 100]!;
    return last > first ? (this.tn - 1) / (last - first) : 0;
  }
}

class OutPort implements OutputPort {
  readonly pool: FramePool;
  /** Channel names, unit, electrode grid (declared or inherited). */
  meta: PortMeta | undefined;
  readonly edges: Edge[] = [];
  log: LogChannel | null = null;
  /** Observers of every emitted frame (tests, open control panels); they must copy what they keep. */
  taps: ((f: Frame) => void)[] = [];
  /** Producer side of cross-worker edges. */
  remotes: RemoteSender[] = [];

  constructor(
    readonly node: Node,
    readonly name: string,
    readonly shape: Shape,
  ) {
    this.pool = new FramePool(shape);
  }

  get idle(): boolean {
    if (this.log || this.taps.length > 0 || this.remotes.length > 0) return false;
    for (const e of this.edges) if (e.subscribed) return false;
    return true;
  }

  frame(n: number): Frame {
    return this.pool.take(n);
  }

  emit(frame: Frame): void {
    this.node.rt.emit(this, frame);
  }
}

class Node {
  instance: BlockInstance = {};
  readonly ports: OutPort[] = [];
  readonly inEdges: Edge[] = [];
  readonly status: StatusTracker;
  readonly timers: TimerEntry[] = [];
  oneShot: TimerEntry | null = null;
  text = "";
  errors = 0;
  lastError = "";
  lastWarnAt = -Infinity;
  /** Results this block waits for from outside the engine (`ctx.setAwaiting`). */
  awaiting = 0;
  finished = false;
  finite = false;
  readonly extraLogs: LogChannel[] = [];
  started = false;
  params: unknown;
  /** The batching interval of this block's timers, s. */
  readonly batchS: number;

  constructor(
    readonly rt: Runtime,
    readonly spec: BlockSpec,
    readonly def: AnyBlockDefinition,
    public desiredRate: number,
    readonly local: boolean,
  ) {
    this.batchS = spec.batchingMs !== undefined ? spec.batchingMs / 1000 : rt.batchS;
    this.status = new StatusTracker(desiredRate);
    this.status.batchS = rt.maxBatchS;
    this.params = spec.params;
    this.finite = def.finite?.(spec.params) ?? false;
  }

  get name(): string {
    return this.spec.name;
  }
}

/** The port metas of a planned block, by port name. */
function ghostMetas(p: PlanBlock): Map<string, PortMeta> {
  const m = new Map<string, PortMeta>();
  for (const o of p.outputs) if (o.meta !== undefined) m.set(o.name, o.meta);
  return m;
}

/**
 * The meta a port without its own inherits: that of the block's first value input (not a timer)
 * when it has the same shape (a filter, a gain, a rectifier keep their input's channels).
 */
function inheritedMeta(inputs: readonly InputInfo[], shape: Shape): PortMeta | undefined {
  const first = inputs.find((i) => !i.isTimer && i.shape !== null);
  if (!first?.meta || !first.shape) return undefined;
  if (first.shape.rows !== shape.rows || first.shape.cols !== shape.cols) return undefined;
  return first.meta;
}

/** A block placed on another worker: known only through the plan. */
interface Ghost {
  name: string;
  type: string;
  worker: string;
  desiredRate: number;
  isTimer: boolean;
  outputs: Map<string, Shape>;
  metas: Map<string, PortMeta>;
}

export interface CreateResult {
  runtime: Runtime | undefined;
  diagnostics: Diagnostic[];
  plan: Plan | undefined;
}

/**
 * Blocks in topological order: at every step the first block in file order whose inputs are all
 * placed, or, inside a feedback cycle, the first block in file order not placed yet. O((blocks +
 * inputs) · log blocks): a heap of the ready blocks by file position.
 */
function topoOrder(spec: PipelineSpec): BlockSpec[] {
  const blocks = spec.blocks;
  const index = new Map<string, number>();
  blocks.forEach((b, i) => index.set(b.name, i));
  const indeg = new Int32Array(blocks.length);
  const outs: number[][] = blocks.map(() => []);
  blocks.forEach((b, i) => {
    for (const inp of b.inputs) {
      const from = index.get(inp.block);
      if (from === undefined || from === i) continue;
      indeg[i]!++;
      outs[from]!.push(i);
    }
  });
  const ready = new MinHeap();
  for (let i = 0; i < blocks.length; i++) if (indeg[i] === 0) ready.push(i);
  const done = new Uint8Array(blocks.length);
  const order: BlockSpec[] = [];
  let firstLeft = 0;
  while (order.length < blocks.length) {
    let next = -1;
    while (ready.size > 0) {
      const i = ready.pop();
      if (!done[i]) {
        next = i;
        break;
      }
    }
    if (next < 0) {
      // Inside a feedback cycle: take the first remaining block in file order.
      while (done[firstLeft]) firstLeft++;
      next = firstLeft;
    }
    done[next] = 1;
    order.push(blocks[next]!);
    for (const o of outs[next]!) if (--indeg[o]! === 0) ready.push(o);
  }
  return order;
}

/** A binary min-heap of numbers. */
class MinHeap {
  private readonly a: number[] = [];
  get size(): number {
    return this.a.length;
  }
  push(v: number): void {
    const a = this.a;
    let i = a.length;
    a.push(v);
    while (i > 0) {
      const p = (i - 1) >> 1;
      if (a[p]! <= v) break;
      a[i] = a[p]!;
      i = p;
    }
    a[i] = v;
  }
  pop(): number {
    const a = this.a;
    const top = a[0]!;
    const last = a.pop()!;
    if (a.length > 0) {
      let i = 0;
      for (;;) {
        const l = 2 * i + 1;
        if (l >= a.length) break;
        const r = l + 1;
        const c = r < a.length && a[r]! < a[l]! ? r : l;
        if (a[c]! >= last) break;
        a[i] = a[c]!;
        i = c;
      }
      a[i] = last;
    }
    return top;
  }
}

/** What instantiating the blocks produced (see `Runtime.instantiate`). */
interface Instantiated {
  diagnostics: Diagnostic[];
  /** Blocks on other workers, instantiated only for planning (when no plan was given). */
  planning: Node[];
  planningByName: Map<string, Node>;
}

/** What this worker knows of a planned block: its shapes, metas and rate, by the plan. */
function ghostOf(p: PlanBlock): Ghost {
  return {
    name: p.name,
    type: p.type,
    worker: p.worker,
    desiredRate: p.desiredRate,
    isTimer: p.isTimer,
    outputs: new Map(p.outputs.map((o) => [o.name, o.shape])),
    metas: ghostMetas(p),
  };
}

/**
 * A block's desired rate before it is created: its declared one, or that of its first timer input
 * with a rate, or of its first input with a rate, or 0.
 */
function desiredRateOf(b: BlockSpec, inputs: readonly InputInfo[]): number {
  let desired = b.desiredRate ?? 0;
  if (b.desiredRate === undefined) {
    const timerIn = inputs.find((i) => i.isTimer && i.rate > 0);
    const anyIn = inputs.find((i) => i.rate > 0);
    desired = (timerIn ?? anyIn)?.rate ?? 0;
  }
  return desired;
}

/** A `block-config` error about block `b`, at `pos` of `file` (and naming `param` if given). */
function blockDiagnostic(
  file: string,
  b: BlockSpec,
  pos: SourcePos,
  message: string,
  param?: string,
): Diagnostic {
  return {
    severity: "error",
    code: "block-config",
    message: `block '${b.name}' (${b.type}): ${message}`,
    file,
    line: pos.line,
    col: pos.col,
    block: b.name,
    ...(param !== undefined ? { param } : {}),
  };
}

/**
 * The diagnostic for block `b` whose `create` threw `e`: at the param a `BlockConfigError` names
 * (else at the block's params, else at the block).
 */
function createFailure(file: string, b: BlockSpec, e: unknown): Diagnostic {
  const param = e instanceof BlockConfigError ? e.param : undefined;
  const pos = param !== undefined ? (b.paramPos[param.split(/[.[]/)[0]!] ?? b.paramsPos) : b.pos;
  return blockDiagnostic(file, b, pos, errorMessage(e), param);
}

export class Runtime {
  readonly worker: string;
  readonly clock: Clock;
  readonly virtual: boolean;
  readonly scheduler: Scheduler;
  readonly nodes: Node[] = [];
  readonly byName = new Map<string, Node>();
  readonly edges: Edge[] = [];
  private readonly fifo = new Deque<Edge>(256);
  private readonly events: RuntimeEvent[] = [];
  private readonly logs: LogSink | undefined;
  private readonly resources: Resources;
  private readonly io: IoBridges;
  startTime = NaN;
  running = false;
  private finiteCount = 0;
  private finishedCount = 0;
  /** Called after a block asks for a wake-up (new timer, one-shot) so the host can re-plan its wait. */
  onWake: (() => void) | null = null;
  /** The batching interval of blocks without their own `BatchingMs`, s. */
  readonly batchS: number;
  /** The largest batching interval any block of the pipeline uses, s (status allows for it). */
  readonly maxBatchS: number;

  private constructor(
    readonly spec: PipelineSpec,
    opts: RuntimeOptions,
  ) {
    this.batchS = opts.batchingS ?? batchingOf(spec);
    // A loop, not Math.max(...all): a spread of 100k blocks overflows the stack.
    let maxBatchS = this.batchS;
    for (const b of spec.blocks) {
      if (b.batchingMs !== undefined) maxBatchS = Math.max(maxBatchS, b.batchingMs / 1000);
    }
    this.maxBatchS = maxBatchS;
    this.worker = opts.worker ?? "main";
    this.clock = opts.clock;
    this.virtual = opts.virtual;
    this.scheduler = new Scheduler(opts.virtual);
    this.logs = opts.logs;
    this.resources = opts.resources;
    this.io = opts.io ?? {};
  }

  /**
   * Instantiates the pipeline's blocks for this worker in topological order, resolving every
   * input's shape and rate. Never throws: block errors come back as diagnostics.
   */
  static async create(opts: RuntimeOptions): Promise<CreateResult> {
    const rt = new Runtime(opts.spec, opts);
    const ghosts = new Map<string, Ghost>();
    if (opts.plan) for (const p of opts.plan.blocks) ghosts.set(p.name, ghostOf(p));
    const order = topoOrder(opts.spec);
    const { diagnostics, planning, planningByName } = await rt.instantiate(opts, order, ghosts);
    if (diagnostics.length > 0) {
      for (const n of [...rt.nodes, ...planning]) rt.safeDispose(n);
      return { runtime: undefined, diagnostics, plan: undefined };
    }
    // The plan, for workers that did not see the other blocks.
    const plan: Plan = opts.plan ?? rt.planOf(order, planningByName);
    for (const n of planning) rt.safeDispose(n);
    if (!opts.plan) {
      // Blocks placed on other workers are known from here on through the plan, like elsewhere.
      for (const p of plan.blocks) if (!rt.byName.has(p.name)) ghosts.set(p.name, ghostOf(p));
    }
    rt.connectEdges(ghosts);
    rt.openPathLogs();
    for (const n of rt.nodes) if (n.finite) rt.finiteCount++;
    return { runtime: rt, diagnostics, plan };
  }

  /**
   * Creates the blocks in `order`, one after the other: this worker's into `nodes`, and, when no
   * plan was given, the other workers' for planning only. A block that fails becomes a diagnostic.
   */
  private async instantiate(
    opts: RuntimeOptions,
    order: BlockSpec[],
    ghosts: Map<string, Ghost>,
  ): Promise<Instantiated> {
    const diagnostics: Diagnostic[] = [];
    const file = opts.spec.file;
    // Blocks on other workers are instantiated here only for planning (when no plan was given).
    const planning: Node[] = [];
    const planningByName = new Map<string, Node>();
    // Blocks that could not be created. A block fed by one cannot know its input's shape either:
    // its own error would only repeat the first one (and blame a feedback cycle), so it is not
    // reported (issue 17, defect 5).
    const failed = new Set<string>();
    for (const b of order) {
      const local = opts.ignorePlacement === true || b.worker === this.worker;
      if (!local && opts.plan) continue;
      const afterFailure = b.inputs.some((inp) => failed.has(inp.block));
      const inputs = this.inputInfos(b, planningByName, ghosts);
      const node = new Node(this, b, b.def, desiredRateOf(b, inputs), local);
      const ctx = this.makeContext(node, inputs);
      try {
        node.instance = await b.def.create(ctx, b.params);
      } catch (e) {
        failed.add(b.name);
        if (!afterFailure) diagnostics.push(createFailure(file, b, e));
        continue;
      }
      node.status.desiredRate = node.desiredRate;
      for (const out of b.outputs) {
        if (!node.ports.some((p) => p.name === out)) {
          const message = `internal error: the block did not declare its output '${out}'`;
          diagnostics.push(blockDiagnostic(file, b, b.pos, message));
        }
      }
      if (local) {
        this.nodes.push(node);
        this.byName.set(b.name, node);
      } else {
        planning.push(node);
        planningByName.set(b.name, node);
      }
    }
    return { diagnostics, planning, planningByName };
  }

  /**
   * What block `b` learns of its inputs: each source's type, shape, rate and meta, from the block
   * itself when it was created here (for this worker or for planning), else from the plan.
   */
  private inputInfos(
    b: BlockSpec,
    planningByName: Map<string, Node>,
    ghosts: Map<string, Ghost>,
  ): InputInfo[] {
    return b.inputs.map((inp, index) => {
      const src = this.byName.get(inp.block) ?? planningByName.get(inp.block);
      const ghost = ghosts.get(inp.block);
      const srcPort = src?.ports.find((p) => p.name === inp.port);
      const shape = src ? (srcPort?.shape ?? null) : (ghost?.outputs.get(inp.port) ?? null);
      const meta = src ? srcPort?.meta : ghost?.metas.get(inp.port);
      return {
        index,
        source: inp.source,
        block: inp.block,
        port: inp.port,
        ...((src?.def.type ?? ghost?.type) !== undefined
          ? { type: src?.def.type ?? ghost?.type }
          : {}),
        shape,
        rate: src ? src.desiredRate : (ghost?.desiredRate ?? 0),
        isTimer: src ? src.def.timer === true : (ghost?.isTimer ?? false),
        subscribed: inp.subscribed,
        ...(meta !== undefined ? { meta } : {}),
      };
    });
  }

  /** The plan of every block in `order` (all created, here or for planning: no plan was given). */
  private planOf(order: BlockSpec[], planningByName: Map<string, Node>): Plan {
    return {
      blocks: order.map((b) => {
        const n = this.byName.get(b.name) ?? planningByName.get(b.name)!;
        return {
          name: b.name,
          type: b.type,
          worker: b.worker,
          desiredRate: n.desiredRate,
          isTimer: b.def.timer === true,
          finite: n.finite,
          outputs: n.ports.map((p) => ({
            name: p.name,
            shape: p.shape,
            ...(p.meta !== undefined ? { meta: p.meta } : {}),
          })),
          inputs: b.inputs.map((i) => ({ block: i.block, port: i.port })),
          ...(b.queue.capacity !== undefined ? { queueCapacity: b.queue.capacity } : {}),
        };
      }),
    };
  }

  /**
   * Creates the edges into this worker's blocks, in file order of consumers (so delivery order is
   * stable); a source on another worker is known by its ghost (the ring is attached later).
   */
  private connectEdges(ghosts: Map<string, Ghost>): void {
    for (const b of this.spec.blocks) {
      const to = this.byName.get(b.name);
      if (!to) continue;
      b.inputs.forEach((inp, index) => {
        const from = this.byName.get(inp.block);
        const fromPort = from?.ports.find((p) => p.name === inp.port) ?? null;
        const srcShape = fromPort?.shape ?? ghosts.get(inp.block)?.outputs.get(inp.port);
        const srcRate = from?.desiredRate ?? ghosts.get(inp.block)?.desiredRate ?? 0;
        const cap = b.queue.capacity ?? Math.max(DEFAULT_QUEUE_MIN, Math.ceil(srcRate));
        const e = new Edge(
          this.edges.length,
          inp.block,
          fromPort,
          inp.port,
          to,
          index,
          inp.subscribed,
          b.queue.policy,
          cap,
        );
        e.srcShape = srcShape ?? null;
        if (srcShape && b.queue.policy === "latest") e.one = new Frame(srcShape, 1);
        this.edges.push(e);
        to.inEdges.push(e);
        fromPort?.edges.push(e);
      });
    }
  }

  /** Opens the path logs: one per output of every block with a `Path` (none without a log sink). */
  private openPathLogs(): void {
    const logs = this.logs;
    if (!logs) return;
    for (const n of this.nodes) {
      if (n.spec.path === undefined) continue;
      n.ports.forEach((p, i) => {
        p.log = logs.open(n.name, p.name, i === 0, n.spec.path!, p.shape);
      });
    }
  }

  private safeDispose(n: Node): void {
    try {
      n.instance.dispose?.();
    } catch {
      // disposal errors during a failed load are not the user's first problem
    }
  }

  /** The context `node`'s block is created with (its window on the runtime), see `BlockContext`. */
  private makeContext(node: Node, inputs: InputInfo[]): BlockContext {
    const rt = this;
    return {
      name: node.name,
      type: node.spec.type,
      inputs,
      declaredRate: node.spec.desiredRate,
      get desiredRate() {
        return node.desiredRate;
      },
      setDesiredRate(hz: number) {
        node.desiredRate = hz;
        node.status.desiredRate = hz;
      },
      now: () => rt.clock.now(),
      get startTime() {
        return rt.startTime;
      },
      virtual: this.virtual,
      resources: this.resources,
      io: this.io,
      output: (shape, port, meta) => rt.declareOutput(node, inputs, shape, port, meta),
      get batching() {
        return node.batchS;
      },
      every: (hz, tick, options) => rt.addTimer(node, hz, tick, options),
      at: (t, fn, latest) => rt.scheduleAt(node, t, fn, latest),
      setText(text: string) {
        node.text = text;
      },
      warn(message: string) {
        rt.warn(node, message);
      },
      error(message: string, detail?: string) {
        rt.fail(node, message, detail);
      },
      setAwaiting(count: number) {
        rt.setAwaiting(node, count);
      },
      reportCompute(ms: number, budgetMs?: number) {
        node.status.external(ms, rt.clock.now(), budgetMs);
      },
      setSubscribed: (index, subscribed) => rt.subscribeInput(node, index, subscribed),
      openLog: (path, stream, shape) => rt.openExtraLog(node, path, stream, shape),
      finish: () => rt.finishNode(node),
    };
  }

  /**
   * `ctx.output`: declares output `port` of `node` (by default its next name in the spec, else
   * "out"), with `meta` or, without, the meta it inherits from its inputs.
   */
  private declareOutput(
    node: Node,
    inputs: InputInfo[],
    shape: Shape,
    port?: string,
    meta?: PortMeta,
  ): OutPort {
    const name = port ?? node.spec.outputs[node.ports.length] ?? "out";
    if (node.ports.some((p) => p.name === name)) {
      throw new Error(`output '${name}' declared twice`);
    }
    if (!(
      shape.rows >= 1 &&
      shape.cols >= 0 &&
      Number.isInteger(shape.rows) &&
      Number.isInteger(shape.cols)
    )) {
      throw new Error(`invalid output shape ${formatShape(shape)}`);
    }
    const p = new OutPort(node, name, shape);
    p.meta = meta ?? inheritedMeta(inputs, shape);
    const problem = p.meta && portMetaProblem(p.meta, shape.rows * shape.cols);
    if (problem) throw new Error(`output '${name}': ${problem}`);
    node.ports.push(p);
    return p;
  }

  /** `ctx.every`: registers a periodic timer of `node` (idle until its handle's `start`). */
  private addTimer(
    node: Node,
    hz: number,
    tick: TickCallback,
    options?: { catchUp?: CatchUp },
  ): TimerHandle {
    const rt = this;
    const sched = this.scheduler;
    if (!(hz > 0)) throw new BlockConfigError(`a timer rate must be positive, got ${hz}`);
    const e = sched.addPeriodic(node.name, hz, tick, {
      batchS: node.batchS,
      ...(options?.catchUp !== undefined ? { catchUp: options.catchUp } : {}),
    });
    node.timers.push(e);
    return {
      start() {
        if (!e.running) {
          sched.start(e, rt.clock.now());
          rt.onWake?.();
        }
      },
      stop() {
        sched.stop(e);
      },
      get running() {
        return e.running;
      },
      get fired() {
        return e.fired;
      },
      get missed() {
        return e.missed;
      },
      setRate(h: number) {
        if (!(h > 0)) throw new Error(`a timer rate must be positive, got ${h}`);
        sched.setRate(e, h, rt.clock.now());
        rt.onWake?.();
      },
    };
  }

  /** `ctx.at`: (re)arms `node`'s one-shot timer (one per block) for `t`, with callback `fn`. */
  private scheduleAt(node: Node, t: number, fn: (t: number) => void, latest?: number): void {
    const sched = this.scheduler;
    if (!node.oneShot) {
      node.oneShot = sched.addOneShot(node.name, fn);
    }
    node.oneShot.cb = fn;
    sched.once(node.oneShot, t, latest);
    this.onWake?.();
  }

  /** `ctx.setSubscribed`: (un)subscribes `node`'s input `index`; false when it has none. */
  private subscribeInput(node: Node, index: number, subscribed: boolean): boolean {
    const e = node.inEdges.find((x) => x.toIndex === index);
    if (!e) return false;
    if (e.subscribed !== subscribed) {
      e.subscribed = subscribed;
      if (!subscribed) this.dropPending(e);
    }
    return true;
  }

  /** `ctx.openLog`: opens an extra log of `node` (closed on dispose); null without a log sink. */
  private openExtraLog(node: Node, path: string, stream: string, shape: Shape): LogChannel | null {
    if (!this.logs) return null;
    const ch = this.logs.open(stream, "out", true, path, shape);
    node.extraLogs.push(ch);
    return ch;
  }

  /** `ctx.finish`: marks `node` finished (counted once, if it is a finite source). */
  private finishNode(node: Node): void {
    if (!node.finished) {
      node.finished = true;
      if (node.finite) this.finishedCount++;
    }
  }

  // -------------------------------------------------------------------------------------------
  // Hot path

  emit(port: OutPort, f: Frame): void {
    if (f.n <= 0) {
      if (f.refs === 0) f.pool?.release(f);
      return;
    }
    // Emitted from an I/O callback (a datagram, serial bytes): wake the loop to deliver it now.
    if (!this.stepping && this.running) this.onWake?.();
    const now = this.clock.now();
    // Status follows the default (first) output; other ports emit in step with it.
    if (port === port.node.ports[0]) port.node.status.record(f, now);
    if (port.log) port.log.write(f);
    const taps = port.taps;
    for (let i = 0; i < taps.length; i++) taps[i]!(f);
    const edges = port.edges;
    for (let i = 0; i < edges.length; i++) {
      const e = edges[i]!;
      if (e.subscribed) this.push(e, f);
    }
    const remotes = port.remotes;
    for (let i = 0; i < remotes.length; i++) remotes[i]!.write(f);
    if (f.refs === 0) f.pool?.release(f);
  }

  /** Queues frame `f` on edge `e` (applying its policy). */
  push(e: Edge, f: Frame): void {
    e.noteTimes(f);
    const n = f.n;
    if (e.policy === "latest") {
      this.cancelPending(e, e.queue.length);
    } else if (e.pendingEvents + n > e.capacity) {
      if (e.policy === "drop-newest") {
        e.dropped += n;
        return;
      }
      while (e.queue.length > 0 && e.pendingEvents + n > e.capacity) this.cancelPending(e, 1);
    }
    e.delivered += n;
    f.refs++;
    e.queue.push(f);
    e.pendingEvents += n;
    this.fifo.push(e);
  }

  /** Drops every frame still queued on `e` (an input that was just unsubscribed). */
  dropPending(e: Edge): void {
    this.cancelPending(e, e.queue.length);
  }

  private cancelPending(e: Edge, count: number): void {
    for (let i = 0; i < count; i++) {
      const f = e.queue.shift();
      if (!f) return;
      e.pendingEvents -= f.n;
      e.dropped += f.n;
      e.delivered -= f.n;
      e.skip++;
      if (--f.refs === 0) f.pool?.release(f);
    }
  }

  /** Delivers queued frames until the FIFO is empty, then lets holding blocks flush (and so on). */
  dispatch(): void {
    do this.drainFifo();
    while (this.flushHolders());
  }

  /** Calls `flush` on the blocks that have one; true when that queued new deliveries. */
  private flushHolders(): boolean {
    const holders = this.holders;
    for (let i = 0; i < holders.length; i++) {
      const node = holders[i]!;
      if (!node.started) continue;
      try {
        node.instance.flush!();
      } catch (err) {
        this.fail(node, err);
      }
    }
    return this.fifo.length > 0;
  }

  private drainFifo(): void {
    const fifo = this.fifo;
    while (fifo.length > 0) {
      const e = fifo.shift()!;
      if (e.skip > 0) {
        e.skip--;
        continue;
      }
      const f = e.queue.shift()!;
      e.pendingEvents -= f.n;
      let g = f;
      if (e.policy === "latest" && f.n > 1 && e.one) {
        e.one.copyEvents(f, f.n - 1, 1, 0);
        e.one.n = 1;
        e.dropped += f.n - 1;
        g = e.one;
      }
      this.deliver(e.to, g, e.toIndex);
      if (--f.refs === 0) f.pool?.release(f);
    }
  }

  private deliver(node: Node, f: Frame, port: number): void {
    const proc = node.instance.process;
    if (!proc || !node.started) return;
    const t0 = performance.now();
    // A batch is as late as its oldest event.
    if (!this.virtual) node.status.delivered(f.t[0]!, this.clock.now());
    try {
      proc.call(node.instance, f, port);
    } catch (err) {
      this.fail(node, err);
    }
    const now = this.clock.now();
    node.status.compute(performance.now() - t0, now, f.n);
    // A block without outputs (a sink, a device output) is timed by what it consumes; one that
    // emits on request (no desired rate) is not idle while it consumes.
    if (node.ports.length === 0) node.status.record(f, now);
    else node.status.consumed(now);
  }

  private fireEntry = (e: TimerEntry, n: number): void => {
    const node = this.byName.get(e.owner);
    if (!node || !node.started) return;
    const t0 = performance.now();
    if (e.period > 0 && !this.virtual) node.status.delivered(e.times[0]!, this.clock.now());
    if (e.missed > 0) node.status.missed(e.missed, this.clock.now());
    try {
      if (e.period > 0) e.onTicks(e.times, n);
      else e.cb(e.times[0]!);
    } catch (err) {
      this.fail(node, err);
    }
    node.status.compute(performance.now() - t0, this.clock.now(), n);
  };

  /** Fires every timer due at `now` (then call `dispatch`). */
  fireDue(now: number): number {
    return this.scheduler.fireDue(now, this.fireEntry);
  }

  /** One step of the loop: take in frames from other workers, fire due timers, deliver. */
  step(now: number): void {
    this.stepping = true;
    try {
      if (this.inbound.length > 0) this.drainInbound();
      this.fireDue(now);
      this.dispatch();
    } finally {
      this.stepping = false;
    }
  }

  /** True while the loop runs a step (emits then are dispatched in that step). */
  private stepping = false;

  private readonly inbound: Edge[] = [];
  /** Blocks with a `flush` (called when a step has delivered everything). */
  private holders: Node[] = [];

  /** Sends what `block`'s output `port` emits into a cross-worker ring too. */
  attachRemoteOut(block: string, port: string, sender: RemoteSender): void {
    const node = this.byName.get(block);
    const p = node?.ports.find((x) => x.name === port);
    if (!p) throw new Error(`no output '${block}.${port}' on worker '${this.worker}'`);
    p.remotes.push(sender);
  }

  /** Feeds input `index` of `block` from a cross-worker ring (drained in `step`). */
  attachRemoteIn(block: string, index: number, ring: SabRing): void {
    const node = this.byName.get(block);
    const e = node?.inEdges.find((x) => x.toIndex === index);
    if (!e) throw new Error(`no input ${index} of '${block}' on worker '${this.worker}'`);
    e.inbound = ring;
    e.inPool = new FramePool(e.srcShape ?? { rows: 1, cols: ring.stride }, 64);
    this.inbound.push(e);
  }

  /** Moves events waiting in cross-worker rings onto their edges. */
  drainInbound(): void {
    for (const e of this.inbound) {
      const ring = e.inbound!;
      while (ring.available() > 0) {
        const f = e.inPool!.take(0);
        f.pool = e.inPool;
        ring.read(f);
        if (e.subscribed && f.n > 0) this.push(e, f);
        if (f.refs === 0) e.inPool!.release(f);
      }
    }
  }

  /** When the worker should wake next (the scheduler's batching applied). */
  nextDeadline(): number {
    return this.scheduler.nextWake();
  }

  get pending(): number {
    return this.fifo.length;
  }

  /** True when a block on this worker is fed by I/O callbacks (see `BlockDefinition.eventLoop`). */
  get needsEventLoop(): boolean {
    return this.nodes.some((n) => n.def.eventLoop === true);
  }

  /** True when every finite source has finished (never true without finite sources). */
  get finished(): boolean {
    return this.finiteCount > 0 && this.finishedCount >= this.finiteCount;
  }

  private fail(node: Node, err: unknown, detail?: string): void {
    node.errors++;
    node.lastError = errorMessage(err);
    const now = this.clock.now();
    if (now - node.lastWarnAt >= WARN_INTERVAL_S || node.errors === 1) {
      node.lastWarnAt = now;
      this.events.push({
        t: now,
        level: "error",
        block: node.name,
        message: `${node.lastError}${node.errors > 1 ? ` (${node.errors} errors so far)` : ""}${detail ? `\n${detail}` : ""}`,
      });
    }
  }

  /** Results all blocks of this worker wait for from outside the engine (`ctx.setAwaiting`). */
  awaiting = 0;

  private setAwaiting(node: Node, count: number): void {
    const n = count > 0 ? count : 0;
    if (n === node.awaiting) return;
    this.awaiting += n - node.awaiting;
    node.awaiting = n;
    // The last awaited result arrived from an I/O callback: the virtual driver goes on.
    if (this.awaiting === 0 && !this.stepping) this.onWake?.();
  }

  private warn(node: Node, message: string): void {
    const now = this.clock.now();
    if (now - node.lastWarnAt < WARN_INTERVAL_S && node.lastError === message) return;
    node.lastWarnAt = now;
    this.events.push({ t: now, level: "warning", block: node.name, message });
  }

  // -------------------------------------------------------------------------------------------
  // Life cycle

  start(): void {
    if (this.running) return;
    this.running = true;
    this.holders = this.nodes.filter((n) => typeof n.instance.flush === "function");
    this.startTime = this.clock.now();
    for (const n of this.nodes) n.started = true;
    for (const n of this.nodes) {
      try {
        n.instance.start?.();
      } catch (err) {
        this.fail(n, err);
      }
    }
  }

  stop(): void {
    if (!this.running) return;
    this.running = false;
    for (const n of this.nodes) {
      for (const t of n.timers) this.scheduler.stop(t);
      if (n.oneShot) this.scheduler.stop(n.oneShot);
      try {
        n.instance.stop?.();
      } catch (err) {
        this.fail(n, err);
      }
      n.started = false;
      n.awaiting = 0;
    }
    this.awaiting = 0;
  }

  dispose(): void {
    this.stop();
    for (const n of this.nodes) {
      this.safeDispose(n);
      for (const p of n.ports) p.log?.close();
      for (const l of n.extraLogs) l.close();
    }
  }

  // -------------------------------------------------------------------------------------------
  // Control

  node(name: string): Node | undefined {
    return this.byName.get(name);
  }

  /** Subscribes or unsubscribes a block's input at run time (the `-Name` inputs). */
  setSubscribed(block: string, input: string | number, subscribed: boolean): string {
    const node = this.byName.get(block);
    if (!node) throw new Error(`no block '${block}' on worker '${this.worker}'`);
    const edge =
      typeof input === "number"
        ? node.inEdges[input]
        : node.inEdges.find(
            (e) =>
              node.spec.inputs[e.toIndex]!.source === input ||
              node.spec.inputs[e.toIndex]!.block === input,
          );
    if (!edge) {
      const names = node.spec.inputs.map((i) => i.source).join(", ");
      throw new Error(
        `block '${block}' has no input '${String(input)}' (its inputs: ${names || "none"})`,
      );
    }
    if (edge.subscribed === subscribed)
      return `${block} ${subscribed ? "already subscribed to" : "was not subscribed to"} ${node.spec.inputs[edge.toIndex]!.source}`;
    edge.subscribed = subscribed;
    if (!subscribed) this.cancelPending(edge, edge.queue.length);
    return `${block} ${subscribed ? "subscribed to" : "unsubscribed from"} ${node.spec.inputs[edge.toIndex]!.source}`;
  }

  /** Runs a block action: built-ins `subscribe`, `unsubscribe`, `reset`, then the block's own. */
  invoke(block: string, action: string, arg?: unknown): string {
    const node = this.byName.get(block);
    if (!node) throw new Error(`no block '${block}' on worker '${this.worker}'`);
    if (action === "subscribe" || action === "unsubscribe") {
      if (typeof arg !== "string" && typeof arg !== "number") {
        throw new Error(`'${action}' needs the input's name or position`);
      }
      return this.setSubscribed(block, arg, action === "subscribe");
    }
    const a = node.instance.actions?.[action];
    // A block's own `reset` action (a predictor's "Reset model") takes the place of the built-in.
    if (action === "reset" && !a) {
      node.instance.reset?.();
      return `${block} reset`;
    }
    if (!a) {
      const own = Object.keys(node.instance.actions ?? {});
      const names = [...new Set(["subscribe", "unsubscribe", "reset", ...own])];
      throw new Error(
        `block '${block}' has no action '${action}' (its actions: ${names.join(", ")})`,
      );
    }
    const r = a.run(arg);
    this.onWake?.();
    return typeof r === "string" ? r : `${block}: ${a.label}`;
  }

  /** Sets a live parameter after validating it against the block's schema. */
  setParam(block: string, param: string, value: unknown): string {
    const node = this.byName.get(block);
    if (!node) throw new Error(`no block '${block}' on worker '${this.worker}'`);
    const live = node.def.live ?? [];
    if (!live.includes(param)) {
      throw new Error(
        `param '${param}' of ${node.spec.type} cannot be changed while running` +
          (live.length ? ` (live params: ${live.join(", ")})` : " (it has no live params)"),
      );
    }
    const merged = { ...(node.params as Record<string, unknown>), [param]: value };
    const r = node.def.params.safeParse(merged);
    if (!r.success) {
      const issue = r.error.issues[0]!;
      throw new Error(`invalid value for '${param}': ${issue.message}`);
    }
    // The block may still refuse the value (e.g. a width it cannot apply): keep the params in step.
    node.instance.setParam?.(param, (r.data as Record<string, unknown>)[param]);
    node.params = r.data;
    return `${block}.${param} = ${JSON.stringify(value)}`;
  }

  /** Observes every frame a block emits on `port` (default port when omitted); returns an unsubscribe. */
  tap(block: string, port: string | undefined, fn: (f: Frame) => void): () => void {
    const node = this.byName.get(block);
    if (!node) throw new Error(`no block '${block}' on worker '${this.worker}'`);
    const p = port === undefined ? node.ports[0] : node.ports.find((x) => x.name === port);
    if (!p) throw new Error(`block '${block}' has no output '${port ?? "(default)"}'`);
    p.taps.push(fn);
    return () => {
      p.taps = p.taps.filter((x) => x !== fn);
    };
  }

  resetTiming(): void {
    for (const n of this.nodes) {
      n.status.resetTiming();
      for (const t of n.timers) t.lateness?.reset();
    }
  }

  // -------------------------------------------------------------------------------------------
  // Telemetry

  /**
   * Per-block status, rates and counters. `at` is when status is judged (default now): the loops
   * pass the start of the step that reports, so that a worker stalled inside that step does not
   * see its own blocks as idle for want of outputs it had not yet had the chance to make.
   */
  telemetry(at?: number): Telemetry {
    const now = at ?? this.clock.now();
    const blocks = this.nodes.map((n) => blockTelemetry(n, this.worker, now));
    const edges = this.edges.map(edgeTelemetry);
    const events = this.events.splice(0, this.events.length);
    return { t: now, worker: this.worker, blocks, edges, events, finished: this.finished };
  }
}

/** The pipeline's own batching interval (`Pipeline: { BatchingMs }`), or the default, s. */
export function batchingOf(spec: PipelineSpec): number {
  return spec.settings.batchingMs !== undefined
    ? spec.settings.batchingMs / 1000
    : DEFAULT_BATCHING_S;
}

/** One block's telemetry at clock time `now`; starts the block's next telemetry window. */
function blockTelemetry(n: Node, worker: string, now: number): BlockTelemetry {
  const s = n.status;
  const ev = s.evaluate(now);
  let dropsIn = 0;
  for (const e of n.inEdges) dropsIn += e.dropped;
  const bt: BlockTelemetry = {
    name: n.name,
    type: n.spec.type,
    worker,
    status: ev.status,
    lagging: ev.lagging,
    stumbling: ev.stumbling,
    rate: Number.isFinite(ev.rate) ? hz(ev.rate) : 0,
    desiredRate: n.desiredRate,
    events: s.events,
    computeLastMs: ms(s.computeLast),
    computeMeanMs: s.callsWindow ? ms(s.computeSumWindow / s.callsWindow) : 0,
    computeMaxMs: ms(s.computeMaxWindow),
    latencyMs: s.latencyN ? ms((s.latencySum / s.latencyN) * 1000) : 0,
    delay: delayFigures(s),
    dropsIn,
    text: n.text,
    errors: n.errors,
    lastError: n.lastError,
    finished: n.finished,
    timing: timingFigures(s),
  };
  const timer = n.def.timer ? n.timers[0] : undefined;
  if (timer) bt.timer = timerFigures(timer);
  s.resetWindow();
  return bt;
}

/** ΔT statistics and compute totals since the start or the last timing reset (Table 5). */
function timingFigures(s: StatusTracker): BlockTelemetry["timing"] {
  return {
    n: s.dtN,
    meanDt: seconds(s.dtMean),
    stdDt: seconds(s.dtStd()),
    computeTotalMs: ms(s.computeTotal),
    calls: s.calls,
  };
}

/** A timer block's counters and lateness (fire − deadline) figures. */
function timerFigures(timer: TimerEntry): NonNullable<BlockTelemetry["timer"]> {
  const h = timer.lateness;
  return {
    fired: timer.fired,
    missed: timer.missed,
    catchUp: timer.catchUp,
    batchingMs: timer.batchS * 1000,
    latenessP50Us: h ? h.quantile(0.5) : 0,
    latenessP99Us: h ? h.quantile(0.99) : 0,
    latenessMaxUs: h && h.count ? Math.round(h.maxUs * 10) / 10 : 0,
    running: timer.running,
  };
}

function edgeTelemetry(e: Edge): EdgeTelemetry {
  return {
    id: e.id,
    from: e.fromName,
    fromPort: e.fromPortName,
    to: e.to.name,
    toIndex: e.toIndex,
    subscribed: e.subscribed,
    rate: hz(e.rate()),
    delivered: e.delivered,
    dropped: e.dropped,
    pending: e.pendingEvents,
  };
}

function delayFigures(s: StatusTracker): BlockTelemetry["delay"] {
  const h = s.delay;
  const toMs = (x: number): number => (Number.isFinite(x) ? ms(x * 1000) : 0);
  return {
    p50Ms: toMs(h.p50),
    p99Ms: toMs(h.p99),
    maxMs: toMs(h.max),
    windowMaxMs: toMs(s.delayMaxWindow),
    n: h.count,
    lateMs: toMs(s.lateAfter()),
  };
}

// Telemetry figures are rounded to what they can mean (a clock read takes ~50 ns; rates are
// judged at 95 %): shorter JSON, encoded, posted and printed 20 times a second by every worker.

/** Milliseconds to 0.1 µs. */
function ms(x: number): number {
  return Math.round(x * 1e4) / 1e4;
}

/** Hz to 0.1 mHz. */
function hz(x: number): number {
  return Math.round(x * 1e4) / 1e4;
}

/** Seconds to 1 ns (NaN stays NaN). */
function seconds(x: number): number {
  return Math.round(x * 1e9) / 1e9;
}
