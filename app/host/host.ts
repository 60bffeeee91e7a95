/**
 * The Node host: loads a pipeline, runs its blocks in engine workers (one per `Worker:` name,
 * "main" by default; the main thread never runs blocks), links cross-worker edges through SAB
 * rings, writes logs, and merges telemetry. `mosaic run` (and the bench's UDP latency run) drive
 * a pipeline through this class; the server and Electron run editing sessions (session-hub.ts).
 */
import { existsSync, readFileSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { Worker } from "node:worker_threads";
import { errorMessage, type Diagnostic } from "../engine/diagnostics";
import { shapeSize } from "../engine/frame";
import type { SimulateOptions } from "../engine/pipeline/simulate";
import type { Plan, RuntimeEvent, Telemetry } from "../engine/runtime/runtime";
import { SabRing } from "../engine/runtime/sab-ring";
import { serialHub } from "../../native-bridges/serial-proxy";
import { bleHub } from "../../native-bridges/ble-proxy";
import type { BleBridge } from "../engine/io";
import { LogWriter } from "./log-writer";
import { takeTimeBase, type TimeBase } from "./time-base";
import { telemetryGroup } from "./telemetry-outbox";
import { tuneTiering } from "./tiering";
import {
  DEFAULT_TELEMETRY_HZ,
  type ClockMode,
  type ControlOp,
  type HostToWorker,
  type InitMessage,
  type TelemetryReport,
  type WorkerToHost,
} from "./worker-protocol";

export interface HostOptions {
  mode?: ClockMode;
  /** Spin the last ~0.3 ms before each tick (lower jitter, more CPU). */
  precision?: boolean;
  /** Base folder for relative `Path` logs (default: the pipeline file's folder). */
  logDir?: string;
  /** Virtual clock start (UNIX seconds, default 0) and length (default: until the input ends). */
  virtualStart?: number;
  virtualDuration?: number;
  telemetryHz?: number;
  /**
   * Seconds of telemetry a worker gathers before sending it to this thread, as one message
   * (default 0.25: the CLI's table redraws 4 times a second, and this thread then wakes 4 times a
   * second instead of 20; every report still arrives, each with its own time); 0: each at once.
   */
  telemetryGroupS?: number;
  /**
   * The batching interval, s, for blocks that do not set their own: overrides the pipeline's
   * `Pipeline: { BatchingMs }` (undefined: the file's, else the default).
   */
  batchingS?: number;
  /** Replace device blocks by simulators (`--simulate-devices`); undefined: off. */
  simulateDevices?: SimulateOptions;
  /**
   * A Bluetooth LE bridge used instead of noble's: a simulated peripheral for demos without an
   * adapter (`mosaic run --simulate-ble nilspod`); the blocks speak their protocol to it.
   */
  ble?: BleBridge;
  workerPath?: string;
  wasmPath?: string;
}

export interface HostEvents {
  /** Merged telemetry of all workers, as objects (parsed from the workers' reports on demand). */
  telemetry?: (t: Telemetry) => void;
  /**
   * The same as one JSON line, `{"type":"telemetry",…}` (what `mosaic run --json` prints), built
   * from the workers' JSON text without parsing it.
   */
  telemetryLine?: (line: string) => void;
  event?: (e: RuntimeEvent) => void;
  finished?: () => void;
  fatal?: (message: string) => void;
}

function repoRootFrom(here: string): string {
  let d = dirname(here);
  for (let i = 0; i < 6; i++) {
    if (existsSync(join(d, "package.json"))) return d;
    d = dirname(d);
  }
  return dirname(here);
}

/** A file of the bundle: next to this module, or one folder up (this module may be a chunk). */
function distFile(name: string): string | undefined {
  const here = fileURLToPath(import.meta.url);
  if (!here.endsWith(".mjs")) return undefined;
  for (const d of [dirname(here), dirname(dirname(here))]) {
    if (existsSync(join(d, name))) return join(d, name);
  }
  return undefined;
}

/** dist/engine.worker.mjs of the running bundle, or the repo's dist when running from sources. */
export function defaultWorkerPath(): string {
  return (
    distFile("engine.worker.mjs") ??
    join(repoRootFrom(fileURLToPath(import.meta.url)), "dist", "engine.worker.mjs")
  );
}

/** The browser build (dist/web) next to the running bundle or in the repo; undefined if not built. */
export function webRoot(): string | undefined {
  const found = distFile("web/index.html");
  if (found) return dirname(found);
  const d = join(repoRootFrom(fileURLToPath(import.meta.url)), "dist", "web");
  return existsSync(join(d, "index.html")) ? d : undefined;
}

export function defaultWasmPath(): string {
  const found = distFile("mosaic_core_bg.wasm");
  if (found) return found;
  const root = repoRootFrom(fileURLToPath(import.meta.url));
  const dist = join(root, "dist", "mosaic_core_bg.wasm");
  return existsSync(dist) ? dist : join(root, "core-wasm", "pkg", "mosaic_core_bg.wasm");
}

interface WorkerState {
  name: string;
  worker: Worker;
  doorbell?: SharedArrayBuffer;
  /** The latest telemetry as the worker sent it (JSON text), and as objects once parsed. */
  report?: TelemetryReport;
  telemetry?: Telemetry;
  stopped: boolean;
  exited: boolean;
  waiters: ((m: WorkerToHost) => boolean)[];
  /** The worker's serial ports, opened here (created on first use). */
  serial?: ReturnType<typeof serialHub>;
  /** The worker's Bluetooth LE (noble runs here, not in workers: native-bridges/ble.ts). */
  ble?: ReturnType<typeof bleHub>;
  /** When the worker last sent anything (ms, Date.now), and whether its silence was reported. */
  heardAt: number;
  silent: boolean;
}

/** A running worker silent this long (it sends telemetry at 20 Hz) is reported as stuck. */
export const STUCK_WORKER_MS = 3000;

export interface LoadOutcome {
  host: Host | undefined;
  diagnostics: Diagnostic[];
}

/** What every worker's init message carries besides the options: the file, its text, the clock. */
interface Boot {
  full: string;
  source: string;
  timeBase: TimeBase;
}

/** The pipeline file's text, or the diagnostic that says why it cannot be read. */
function readSource(file: string, full: string): string | Diagnostic {
  try {
    return readFileSync(full, "utf8");
  } catch (e) {
    const code = (e as NodeJS.ErrnoException).code;
    return {
      severity: "error",
      code: "file",
      message: code === "ENOENT" ? "no such file" : `cannot read the file: ${errorMessage(e)}`,
      file,
      line: 0,
      col: 0,
    };
  }
}

/** The host's options with every default filled in (`full`: the pipeline file's path). */
function hostDefaults(full: string, opts: HostOptions): Host["options"] {
  return {
    mode: opts.mode ?? "realtime",
    precision: opts.precision ?? false,
    logDir: opts.logDir ?? dirname(full),
    virtualStart: opts.virtualStart ?? 0,
    virtualDuration: opts.virtualDuration ?? Infinity,
    telemetryHz: opts.telemetryHz ?? DEFAULT_TELEMETRY_HZ,
    telemetryGroupS: opts.telemetryGroupS ?? 0.25,
    batchingS: opts.batchingS,
    simulateDevices: opts.simulateDevices,
    ble: opts.ble,
    workerPath: opts.workerPath ?? defaultWorkerPath(),
    wasmPath: opts.wasmPath ?? defaultWasmPath(),
  };
}

export class Host {
  private readonly workers = new Map<string, WorkerState>();
  private readonly logWriter: LogWriter;
  private readonly replies = new Map<number, (r: { ok: boolean; message: string }) => void>();
  private nextReply = 0;
  private finishedWorkers = new Set<string>();
  private stopping: Promise<Telemetry> | undefined;
  events: HostEvents = {};
  plan: Plan | undefined;
  readonly startedAt = Date.now();

  private constructor(
    readonly file: string,
    readonly options: Required<
      Omit<HostOptions, "logDir" | "batchingS" | "simulateDevices" | "ble">
    > & {
      logDir: string;
      batchingS: number | undefined;
      simulateDevices: SimulateOptions | undefined;
      ble: BleBridge | undefined;
    },
  ) {
    this.logWriter = new LogWriter(
      options.logDir,
      {
        onError: (file, message) =>
          this.events.event?.({ t: Date.now() / 1000, level: "error", block: file, message }),
      },
      options.mode === "virtual" ? 20 : 100,
    );
  }

  /**
   * Loads and instantiates a pipeline file; on failure returns its diagnostics and no host. The
   * main thread does not load the catalog: the main worker parses, validates and plans; the other
   * workers (`Worker:` names) then instantiate their blocks from that plan, and the host links them.
   */
  static async load(
    file: string,
    opts: HostOptions = {},
    events: HostEvents = {},
  ): Promise<LoadOutcome> {
    const full = resolve(file);
    const source = readSource(file, full);
    if (typeof source !== "string") return { host: undefined, diagnostics: [source] };
    const host = new Host(file, hostDefaults(full, opts));
    host.events = events;
    const boot: Boot = { full, source, timeBase: takeTimeBase() };
    // The main worker instantiates everything once to learn shapes and rates (the plan).
    const main = await host.createWorker("main", boot);
    if (!main.ok) return host.failed(main.diagnostics);
    const { plan, diagnostics } = main;
    host.plan = plan;
    for (const name of host.otherWorkers(plan)) {
      const w = await host.createWorker(name, boot, plan);
      if (!w.ok) return host.failed([...diagnostics, ...w.diagnostics]);
    }
    host.linkWorkers(
      plan.blocks.map((b) => ({
        name: b.name,
        worker: b.worker,
        inputs: b.inputs,
        capacity: b.queueCapacity,
      })),
    );
    return { host, diagnostics };
  }

  /**
   * Starts a worker and has it instantiate its blocks (all of them for "main", which makes the
   * plan; the planned ones otherwise): the plan and the loader's diagnostics, or why it failed.
   */
  private async createWorker(
    name: string,
    boot: Boot,
    plan?: Plan,
  ): Promise<
    { ok: true; plan: Plan; diagnostics: Diagnostic[] } | { ok: false; diagnostics: Diagnostic[] }
  > {
    const w = this.spawn(name);
    const r = await this.request(
      w,
      this.initMessage(name, boot, plan),
      (m) => m.type === "created" || m.type === "failed" || m.type === "fatal",
    );
    if (r.type === "created") {
      w.doorbell = r.doorbell;
      return { ok: true, plan: r.plan, diagnostics: r.diagnostics };
    }
    if (r.type === "fatal") {
      const d: Diagnostic = {
        severity: "error",
        code: "fatal",
        message: r.message,
        file: this.file,
        line: 0,
        col: 0,
      };
      return { ok: false, diagnostics: [d] };
    }
    return { ok: false, diagnostics: r.type === "failed" ? r.diagnostics : [] };
  }

  /** The init message for a worker (`plan`: the main worker's, for the others). */
  private initMessage(name: string, boot: Boot, plan?: Plan): InitMessage {
    const o = this.options;
    return {
      type: "init",
      file: boot.full,
      source: boot.source,
      worker: name,
      mode: o.mode,
      timeBase: boot.timeBase,
      virtualStart: o.virtualStart,
      virtualDuration: o.virtualDuration,
      wasmPath: o.wasmPath,
      ...(plan ? { plan } : {}),
      precision: o.precision,
      telemetryHz: o.telemetryHz,
      telemetryGroup: telemetryGroup(o.telemetryGroupS, o.telemetryHz),
      ...(o.batchingS !== undefined ? { batchingS: o.batchingS } : {}),
      ...(o.simulateDevices ? { simulateDevices: o.simulateDevices } : {}),
    };
  }

  /** The workers besides "main" that the plan places blocks on (none on the virtual clock). */
  private otherWorkers(plan: Plan): string[] {
    if (this.options.mode === "virtual") return [];
    return [...new Set(plan.blocks.map((b) => b.worker).filter((w) => w !== "main"))];
  }

  /** Loading failed: every worker started so far is ended; the diagnostics say why. */
  private async failed(diagnostics: Diagnostic[]): Promise<LoadOutcome> {
    await this.terminateAll();
    return { host: undefined, diagnostics };
  }

  private spawn(name: string): WorkerState {
    tuneTiering();
    const worker = new Worker(this.options.workerPath, {
      name: `mosaic-engine-${name}`,
      // A small young generation keeps the worker's footprint down; its garbage is tiny.
      resourceLimits: { maxYoungGenerationSizeMb: 4 },
    });
    const st: WorkerState = {
      name,
      worker,
      stopped: false,
      exited: false,
      waiters: [],
      heardAt: Date.now(),
      silent: false,
    };
    this.workers.set(name, st);
    worker.on("message", (m: WorkerToHost) => this.onMessage(st, m));
    worker.on("error", (e) => {
      this.events.fatal?.(`engine worker '${name}' crashed: ${errorMessage(e)}`);
    });
    worker.on("exit", (code) => {
      st.exited = true;
      void st.serial?.closeAll();
      st.ble?.closeAll();
      if (!st.stopped && code !== 0)
        this.events.fatal?.(`engine worker '${name}' exited with code ${code}`);
      for (const w of st.waiters.splice(0))
        w({ type: "fatal", message: `worker '${name}' exited (${code})` });
    });
    return st;
  }

  /** Posts a message and rings the worker's doorbell, so a worker blocked between ticks reads it now. */
  private post(st: WorkerState, msg: HostToWorker): void {
    st.worker.postMessage(msg);
    if (st.doorbell) {
      const bell = new Int32Array(st.doorbell);
      Atomics.store(bell, 1, 1);
      Atomics.add(bell, 0, 1);
      Atomics.notify(bell, 0);
    }
  }

  private request(
    st: WorkerState,
    msg: HostToWorker,
    until: (m: WorkerToHost) => boolean,
  ): Promise<WorkerToHost> {
    return new Promise((res) => {
      st.waiters.push((m) => {
        if (until(m)) {
          res(m);
          return true;
        }
        return false;
      });
      this.post(st, msg);
    });
  }

  private onMessage(st: WorkerState, m: WorkerToHost): void {
    st.heardAt = Date.now();
    if (st.silent) this.answersAgain(st);
    st.waiters = st.waiters.filter((w) => !w(m));
    switch (m.type) {
      case "log-open":
        this.logWriter.open(
          `${st.name}:${m.id}`,
          m.block,
          m.port,
          m.isDefaultPort,
          m.path,
          m.shape,
          m.ring,
        );
        break;
      case "log-close":
        this.logWriter.close(`${st.name}:${m.id}`);
        break;
      case "telemetry":
        this.reportGroup(st, m.reports);
        break;
      case "finished":
      case "stopped":
        st.report = undefined;
        st.telemetry = m.telemetry;
        for (const e of m.telemetry.events) this.events.event?.(e);
        m.telemetry.events = [];
        this.reportTelemetry();
        if (m.type === "finished") {
          this.finishedWorkers.add(st.name);
          if (st.name === "main" || this.finishedWorkers.size === this.workers.size)
            this.events.finished?.();
        }
        break;
      case "reply": {
        const r = this.replies.get(m.id);
        this.replies.delete(m.id);
        r?.({ ok: m.ok, message: m.message });
        break;
      }
      case "fatal":
        this.events.fatal?.(`engine worker '${st.name}': ${m.message}`);
        break;
      case "serial":
        st.serial ??= serialHub((r) => {
          if (!st.exited) this.post(st, r);
        });
        st.serial.receive(m);
        break;
      case "ble":
        st.ble ??= bleHub((r) => {
          if (!st.exited) this.post(st, r);
        }, this.options.ble);
        st.ble.receive(m);
        break;
      default:
        break;
    }
  }

  /** Creates a SAB ring for every edge whose ends live on different workers. */
  private linkWorkers(
    blocks: {
      name: string;
      worker: string;
      inputs: { block: string; port: string }[];
      capacity: number | undefined;
    }[],
  ): void {
    if (this.workers.size < 2 || !this.plan) return;
    const planOf = new Map(this.plan.blocks.map((b) => [b.name, b]));
    const links = new Map<string, { outs: unknown[]; ins: unknown[] }>();
    const get = (w: string) => {
      let l = links.get(w);
      if (!l) links.set(w, (l = { outs: [], ins: [] }));
      return l;
    };
    for (const b of blocks) {
      b.inputs.forEach((inp, index) => {
        const src = planOf.get(inp.block);
        if (!src || src.worker === b.worker) return;
        const shape = src.outputs.find((o) => o.name === inp.port)?.shape ?? { rows: 1, cols: 0 };
        const capacity = b.capacity ?? Math.max(256, Math.ceil(src.desiredRate));
        const ring = SabRing.allocate(capacity, shapeSize(shape));
        const consumer = this.workers.get(b.worker)!;
        get(src.worker).outs.push({
          block: inp.block,
          port: inp.port,
          ring,
          bell: consumer.doorbell!,
        });
        get(b.worker).ins.push({ block: b.name, index, ring });
      });
    }
    for (const [w, l] of links) {
      this.workers
        .get(w)!
        .worker.postMessage({ type: "link", outs: l.outs, ins: l.ins } as HostToWorker);
    }
  }

  start(): void {
    for (const w of this.workers.values()) {
      w.heardAt = Date.now();
      this.post(w, { type: "start" } satisfies HostToWorker);
    }
    if (this.options.mode === "realtime") {
      this.watchdog = setInterval(() => this.checkSilence(), 500);
      this.watchdog.unref();
    }
  }

  private watchdog: NodeJS.Timeout | undefined;

  /** The names of the blocks a worker runs, for an event's block ("Loop, Other"). */
  private blockNames(worker: string): string {
    const blocks = (this.plan?.blocks ?? []).filter((b) => b.worker === worker);
    return blocks.map((b) => b.name).join(", ") || `worker ${worker}`;
  }

  /** The blocks a worker runs, for messages ("'Loop' (Looper)"). */
  private blocksOn(worker: string): string {
    const blocks = (this.plan?.blocks ?? []).filter((b) => b.worker === worker);
    return blocks.map((b) => `'${b.name}' (${b.type})`).join(", ") || "none";
  }

  /**
   * A worker that stopped sending telemetry is stuck inside a block (an endless loop in
   * `process`): said once, naming its blocks, while the other workers go on.
   */
  private checkSilence(): void {
    const now = Date.now();
    for (const w of this.workers.values()) {
      if (w.stopped || w.exited || w.silent || now - w.heardAt < STUCK_WORKER_MS) continue;
      w.silent = true;
      const s = ((now - w.heardAt) / 1000).toFixed(1);
      this.events.event?.({
        t: now / 1000,
        level: "error",
        block: this.blockNames(w.name),
        message: `engine worker '${w.name}' has not answered for ${s} s: its blocks ${this.blocksOn(w.name)} are stuck (an endless loop in process?); the other workers go on`,
      });
    }
  }

  private answersAgain(w: WorkerState): void {
    w.silent = false;
    this.events.event?.({
      t: Date.now() / 1000,
      level: "info",
      block: this.blockNames(w.name),
      message: `engine worker '${w.name}' answers again`,
    });
  }

  private reportTelemetry(): void {
    if (this.events.telemetry) this.events.telemetry(this.telemetry());
    if (this.events.telemetryLine) this.events.telemetryLine(this.telemetryLine());
  }

  /** A worker's group of reports (oldest first): each one's events and telemetry in turn. */
  private reportGroup(st: WorkerState, reports: TelemetryReport[]): void {
    for (const r of reports) {
      st.report = r;
      st.telemetry = undefined;
      for (const e of r.events) this.events.event?.(e);
      r.events = [];
      this.reportTelemetry();
    }
  }

  /** The telemetry of one worker as objects (its report parsed once). */
  private workerTelemetry(w: WorkerState): Telemetry | undefined {
    if (!w.telemetry && w.report) {
      const r = w.report;
      w.telemetry = {
        t: r.t,
        worker: r.worker,
        blocks: JSON.parse(r.blocks) as Telemetry["blocks"],
        edges: JSON.parse(r.edges) as Telemetry["edges"],
        events: [],
        finished: r.finished,
      };
    }
    return w.telemetry;
  }

  /**
   * Merged telemetry of all workers as one JSON line, exactly `JSON.stringify({ type:
   * "telemetry", ...this.telemetry() })`, joined from the workers' JSON text.
   */
  telemetryLine(): string {
    let t = 0;
    let finished = true;
    let any = false;
    const blocks: string[] = [];
    const edges: string[] = [];
    for (const w of this.workers.values()) {
      const r = w.report;
      const o = r ? undefined : w.telemetry;
      if (!r && !o) continue;
      any = true;
      t = Math.max(t, r ? r.t : o!.t);
      finished &&= r ? r.finished : o!.finished;
      const b = r ? r.blocks : JSON.stringify(o!.blocks);
      const e = r ? r.edges : JSON.stringify(o!.edges);
      if (b.length > 2) blocks.push(b.slice(1, -1));
      if (e.length > 2) edges.push(e.slice(1, -1));
    }
    return (
      `{"type":"telemetry","t":${JSON.stringify(t)},"worker":"*",` +
      `"blocks":[${blocks.join(",")}],"edges":[${edges.join(",")}],` +
      `"events":[],"finished":${String(any && finished)}}`
    );
  }

  /** Merged telemetry of all workers (latest of each). */
  telemetry(): Telemetry {
    const parts = [...this.workers.values()]
      .map((w) => this.workerTelemetry(w))
      .filter((t): t is Telemetry => !!t);
    return {
      t: Math.max(0, ...parts.map((p) => p.t)),
      worker: "*",
      blocks: parts.flatMap((p) => p.blocks),
      edges: parts.flatMap((p) => p.edges),
      events: [],
      finished: parts.length > 0 && parts.every((p) => p.finished),
    };
  }

  /** Sends a control request to the worker that runs `block` (or to all for resetTiming). */
  control(op: ControlOp): Promise<{ ok: boolean; message: string }> {
    const targets =
      op.op === "resetTiming"
        ? [...this.workers.values()]
        : [this.workers.get(this.plan?.blocks.find((b) => b.name === op.block)?.worker ?? "main")!];
    return Promise.all(
      targets.map(
        (w) =>
          new Promise<{ ok: boolean; message: string }>((res) => {
            const id = this.nextReply++;
            this.replies.set(id, res);
            this.post(w, { type: "control", id, ...op } as HostToWorker);
          }),
      ),
    ).then((rs) => ({ ok: rs.every((r) => r.ok), message: rs.map((r) => r.message).join("; ") }));
  }

  /** Stops every worker, waits for their final telemetry, flushes and closes the logs. */
  stop(timeoutMs = 5000): Promise<Telemetry> {
    if (this.stopping) return this.stopping;
    clearInterval(this.watchdog);
    this.stopping = (async () => {
      await Promise.all(
        [...this.workers.values()].map((w) => {
          w.stopped = true;
          // A stuck worker (checkSilence) will not answer: it is terminated below.
          if (w.exited || w.silent) return Promise.resolve();
          let timer: NodeJS.Timeout | undefined;
          return Promise.race([
            this.request(w, { type: "stop" }, (m) => m.type === "stopped" || m.type === "fatal"),
            new Promise((r) => (timer = setTimeout(r, timeoutMs))),
          ]).finally(() => clearTimeout(timer));
        }),
      );
      this.logWriter.closeAll();
      const t = this.telemetry();
      await this.terminateAll();
      return t;
    })();
    return this.stopping;
  }

  private async terminateAll(): Promise<void> {
    await Promise.all(
      [...this.workers.values()].map(async (w) => {
        w.stopped = true;
        w.ble?.closeAll();
        if (!w.exited) await w.worker.terminate();
        // After the worker: its last writes (posted before it stopped) are out before we return.
        await w.serial?.closeAll();
      }),
    );
  }

  get logFiles(): string[] {
    return this.logWriter.files;
  }
}
