/**
 * An engine session: serves the UI protocol (app/engine/protocol.ts) for one pipeline at a time.
 * Runs wherever a single runtime runs — the browser build's Web Worker now, the Node host and
 * Electron later — with the platform's clock, files, logs and real-time loop injected.
 */
import { z } from "zod";
import { outputNames } from "./block";
import { catalogTypes, type Catalog } from "./catalog";
import { VirtualClock, type Clock } from "./clock";
import { errorMessage, type Diagnostic } from "./diagnostics";
import type { Frame } from "./frame";
import { loadPipeline, type LoadResult, type PipelineSpec } from "./pipeline/loader";
import { withSimulatedDevices } from "./pipeline/simulate";
import type { LocalFolder } from "./protocol-folder";
import {
  PROTOCOL_VERSION,
  PROTOCOL_VERSIONS,
  parseUiMessage,
  unsupportedHello,
  type BlockInfo,
  type BlockParamsInfo,
  type CatalogInfo,
  type DataMessage,
  type EngineMessage,
  type EngineState,
  type GraphInfo,
  type UiMessage,
} from "./protocol";
import type { LogSink } from "./runtime/logsink";
import { Runtime } from "./runtime/runtime";
import type { Resources } from "./block";
import type { IoBridges } from "./io";
import type { RecordingFormats } from "./recording/format";
import { SessionRecorder } from "./recording/session-recorder";
import { validatePipeline } from "./validate";
import { pipelineCatalog, type LoadedBlockModule, type ModuleLoader } from "./user-blocks";

export interface LoopHandle {
  stop(): void;
  /** Re-plan the wait now (timers changed, a message was handled). */
  wake(): void;
}

export interface LoopHooks {
  telemetryIntervalS: number;
  /** `at`: when the step that reports began (status is judged then; see Runtime.telemetry). */
  onTelemetry(at?: number): void;
  onFinished(): void;
}

export interface SessionPlatform {
  /** Name reported in `hello` (e.g. "browser worker", "node host"). */
  engine: string;
  sharedMemory: boolean;
  clock(): Clock;
  /**
   * File access relative to the pipeline file's folder; `folder`: the files of the folder a page
   * opened the file from (the browser build; hosts that read files ignore it).
   */
  resources(file: string, folder?: LocalFolder): Resources;
  logs?(file: string): LogSink | undefined;
  /**
   * Parses and validates a pipeline file off this thread (the Node host's loader thread, so that
   * a large file does not hold up other requests); `loadPipeline` here when absent.
   */
  loadPipeline?(source: string, file: string, catalog?: Catalog): Promise<LoadResult>;
  /**
   * Loads a user's block module (`Pipeline: { Blocks }`, docs/writing-blocks.md); absent where
   * modules cannot be loaded (the browser build): such a pipeline is refused, saying so.
   */
  blockModules?: ModuleLoader;
  /**
   * Watches the files the loaded pipeline's block modules were built from (replacing what it
   * watched before; none: stop watching) and calls `changed` when one is saved.
   */
  watchBlocks?(files: string[], changed: (file: string) => void): void;
  /** Device and network bridges for blocks (the Node host's; none in the browser). */
  io?: IoBridges;
  /** The file formats session recordings (`record-start`) can write; none: it refuses. */
  recordingFormats?: RecordingFormats;
  /**
   * Where session recordings of the pipeline `file` go (their `recordings/` folder is created
   * there); default `resources(file)`. Without `openWrite` they are kept in memory and downloaded.
   */
  recordings?(file: string): Resources;
  startLoop(rt: Runtime, hooks: LoopHooks): LoopHandle;
  post(msg: EngineMessage, transfer?: ArrayBuffer[]): void;
}

const BUILT_IN_ACTIONS = [
  { name: "reset", label: "Reset", description: "Clear the block's state" },
  {
    name: "subscribe",
    label: "Subscribe input",
    description: "Start delivering one of its inputs",
  },
  {
    name: "unsubscribe",
    label: "Unsubscribe input",
    description: "Stop delivering one of its inputs",
  },
];

/** A block's actions then the built-in ones it does not define itself (its own `reset` wins). */
export function withBuiltInActions<A extends { name: string }>(
  own: A[],
): (A | (typeof BUILT_IN_ACTIONS)[number])[] {
  return [...own, ...BUILT_IN_ACTIONS.filter((b) => !own.some((a) => a.name === b.name))];
}

/** Seconds of panel data one flush may carry (telemetry flushes every 50 ms). */
const WATCH_HOLD_S = 0.25;
/** Values one watch may hold, whatever its rate and shape (8 MiB). */
const WATCH_MAX_VALUES = 1 << 20;

/**
 * Panel data of one watched output. `add` runs on the engine's hot path (a tap inside `emit`),
 * so it does as little as possible: it keeps every `every`-th event (at most `maxRate` events
 * per second, from the block's desired rate; all of them when the rate is not known), finds the
 * kept ones by arithmetic instead of visiting every event, and copies their values into rings
 * allocated once: no allocation, no work for the events left out. The rings hold what one flush
 * may carry (`maxRate` for WATCH_HOLD_S): when a flush comes late, the oldest kept events make
 * room for the newest and count as skipped. Packing and posting (`take`) happen at telemetry
 * time, off the hot path.
 */
export class Watch {
  private readonly t: Float64Array;
  private readonly v: Float64Array;
  /** Capacity of the rings, events. */
  readonly capacity: number;
  /** Next event to write (ring index) and events held. */
  private head = 0;
  private n = 0;
  private skipped = 0;
  /** Events to leave out before the next kept one. */
  private gap = 0;
  readonly every: number;
  readonly stride: number;
  untap: () => void = () => {};

  constructor(
    readonly block: string,
    readonly port: string,
    readonly rows: number,
    readonly cols: number,
    rate: number,
    maxRate: number,
  ) {
    this.stride = rows * cols;
    this.every = rate > maxRate ? Math.ceil(rate / maxRate) : 1;
    const wanted = Math.ceil(maxRate * WATCH_HOLD_S) + 8;
    this.capacity = Math.max(
      2,
      Math.min(wanted, Math.floor(WATCH_MAX_VALUES / Math.max(1, this.stride))),
    );
    this.t = new Float64Array(this.capacity);
    this.v = new Float64Array(this.capacity * this.stride);
  }

  /** Events held for the next flush. */
  get held(): number {
    return this.n;
  }

  add(f: Frame): void {
    const n = f.n;
    let i = this.gap;
    if (i >= n) {
      // Nothing of this frame is kept (the common case of a fast output).
      this.gap = i - n;
      this.skipped += n;
      return;
    }
    const every = this.every;
    if (every === 1) {
      this.copy(f, 0, n);
      return;
    }
    let kept = 0;
    for (; i < n; i += every) {
      this.copy(f, i, 1);
      kept++;
    }
    this.gap = i - n;
    this.skipped += n - kept;
  }

  /** Copies events [from, from + count) of `f` into the rings (overwriting the oldest). */
  private copy(f: Frame, from: number, count: number): void {
    const cap = this.capacity;
    if (count > cap) {
      this.skipped += count - cap;
      from += count - cap;
      count = cap;
    }
    const s = this.stride;
    const ft = f.t;
    const fv = f.v;
    const t = this.t;
    const v = this.v;
    let h = this.head;
    let src = from * s;
    for (let e = 0; e < count; e++) {
      t[h] = ft[from + e]!;
      let dst = h * s;
      for (let k = 0; k < s; k++) v[dst++] = fv[src++]!;
      if (++h === cap) h = 0;
    }
    this.head = h;
    const held = this.n + count;
    if (held > cap) {
      this.skipped += held - cap;
      this.n = cap;
    } else this.n = held;
  }

  /** The events held since the previous flush, as a data message (null when none). */
  take(): DataMessage | null {
    const n = this.n;
    if (n === 0) return null;
    const s = this.stride;
    const cap = this.capacity;
    const start = (this.head - n + cap) % cap;
    const first = Math.min(n, cap - start);
    const t = new Float64Array(n);
    const v = new Float64Array(n * s);
    t.set(this.t.subarray(start, start + first));
    v.set(this.v.subarray(start * s, (start + first) * s));
    if (first < n) {
      t.set(this.t.subarray(0, n - first), first);
      v.set(this.v.subarray(0, (n - first) * s), first * s);
    }
    const msg: DataMessage = {
      type: "data",
      block: this.block,
      port: this.port,
      rows: this.rows,
      cols: this.cols,
      t,
      v,
      skipped: this.skipped,
    };
    this.n = 0;
    this.skipped = 0;
    return msg;
  }
}

export class EngineSession {
  private rt: Runtime | undefined;
  private spec: PipelineSpec | undefined;
  private loop: LoopHandle | undefined;
  private state: EngineState = "empty";
  private file = "";
  /** The loaded pipeline runs with simulated devices. */
  private simulated = false;
  /** The pipeline's text as loaded or last written back (`params-written`). */
  private source = "";
  /** Each block's live params as the file has them (the "changed since loaded" reference). */
  private fileParams = new Map<string, Record<string, unknown>>();
  private readonly watches = new Map<string, Watch>();
  /** The load in progress (loads go one after another). */
  private loading: Promise<unknown> = Promise.resolve();
  /** The session recording (Record button), and when its status was last sent. */
  private recorder: SessionRecorder | undefined;
  private recordingSentAt = -Infinity;

  constructor(
    private readonly catalog: Catalog,
    private readonly platform: SessionPlatform,
  ) {}

  /** Handles one message from the UI (validated here). Never throws. */
  async handle(raw: unknown): Promise<void> {
    const unsupported = unsupportedHello(raw);
    if (unsupported !== undefined) {
      this.platform.post({ ...this.hello(), error: unsupported });
      return;
    }
    const parsed = parseUiMessage(raw);
    if (!parsed.ok) {
      const id = (raw as { id?: unknown } | null)?.id;
      this.platform.post({
        type: "reply",
        id: typeof id === "number" ? id : -1,
        ok: false,
        message: parsed.error,
      });
      return;
    }
    const msg = parsed.msg;
    try {
      await this.dispatch(msg);
    } catch (e) {
      if ("id" in msg) this.reply(msg.id, false, errorMessage(e));
    }
  }

  private reply(
    id: number,
    ok: boolean,
    message?: string,
    extra: Partial<EngineMessage> = {},
  ): void {
    this.platform.post({
      type: "reply",
      id,
      ok,
      ...(message !== undefined ? { message } : {}),
      ...extra,
    } as EngineMessage);
  }

  private setState(state: EngineState): void {
    this.state = state;
    this.platform.post({ type: "state", state, file: this.file });
  }

  /** Carries out one request from the UI and replies to it (errors are replied by the caller). */
  private async dispatch(msg: UiMessage): Promise<void> {
    switch (msg.type) {
      case "hello":
        this.platform.post(this.hello());
        return;
      case "load":
        return this.loadRequest(msg);
      case "validate":
        return this.validateRequest(msg);
      case "catalog":
        this.reply(msg.id, true, undefined, { catalog: this.catalogInfo() });
        return;
      case "start":
        this.start();
        this.reply(msg.id, true);
        return;
      case "stop":
        this.stop();
        this.reply(msg.id, true);
        return;
      case "setParam":
        this.reply(msg.id, true, this.setParam(msg));
        return;
      case "params-written":
        this.reply(msg.id, true, this.paramsWritten(msg));
        return;
      case "invoke":
        this.reply(msg.id, true, this.invoke(msg));
        return;
      case "watch":
        this.watch(msg);
        this.reply(msg.id, true);
        return;
      case "record-start":
        this.reply(msg.id, true, this.startRecording(msg));
        return;
      case "record-stop": {
        const m = this.finishRecording();
        this.reply(msg.id, m !== undefined, m ?? "no recording is running");
        return;
      }
      case "unwatch":
        this.unwatch(msg);
        this.reply(msg.id, true);
        return;
    }
  }

  /** Loads a pipeline (one load at a time: a load may wait for its parse) and replies with it. */
  private async loadRequest(msg: Extract<UiMessage, { type: "load" }>): Promise<void> {
    const run = this.loading.then(() =>
      this.load(msg.file, msg.source, msg.simulateDevices === true, msg.folder),
    );
    this.loading = run.catch(() => {});
    const { diagnostics, graph } = await run;
    const ok = graph !== undefined;
    this.reply(msg.id, ok, ok ? undefined : "the pipeline has errors", {
      diagnostics,
      ...(graph ? { graph } : {}),
    });
  }

  /** What `mosaic validate` says of the text (app/engine/validate.ts); the running pipeline stays. */
  private async validateRequest(msg: Extract<UiMessage, { type: "validate" }>): Promise<void> {
    const own = await this.ownBlocks(msg.source, msg.file);
    const parse = this.platform.loadPipeline?.bind(this.platform);
    const diagnostics = own.failed
      ? own.diagnostics
      : await validatePipeline(msg.source, msg.file, own.catalog, {
          resources: this.platform.resources(msg.file, msg.folder),
          ...(parse ? { parse: (text, f) => parse(text, f, own.catalog) } : {}),
        });
    this.reply(msg.id, true, undefined, { diagnostics });
  }

  /** Sets a live param; every client is sent the engine's value (issue 17, defect 1). */
  private setParam(msg: Extract<UiMessage, { type: "setParam" }>): string {
    const rt = this.requireRuntime();
    const said = rt.setParam(msg.block, msg.param, msg.value);
    this.platform.post({ type: "params", blocks: [this.blockParams(msg.block)] });
    return said;
  }

  /** Runs a block's action, and has the loop look at once (the action may have made events). */
  private invoke(msg: Extract<UiMessage, { type: "invoke" }>): string {
    const rt = this.requireRuntime();
    const m = rt.invoke(msg.block, msg.action, msg.arg);
    this.loop?.wake();
    return m;
  }

  /** Starts sending a block output's data for a panel (a watch of the same output is replaced). */
  private watch(msg: Extract<UiMessage, { type: "watch" }>): void {
    const rt = this.requireRuntime();
    const node = rt.node(msg.block);
    if (!node) throw new Error(`no block '${msg.block}'`);
    const port = msg.port ?? node.ports[0]?.name;
    const p = node.ports.find((x) => x.name === port);
    if (!p) throw new Error(`block '${msg.block}' has no output '${msg.port ?? "(default)"}'`);
    const key = `${msg.block}.${p.name}`;
    this.watches.get(key)?.untap();
    const w = new Watch(
      msg.block,
      p.name,
      p.shape.rows,
      p.shape.cols,
      node.desiredRate,
      msg.maxRate ?? 500,
    );
    w.untap = rt.tap(msg.block, p.name, (f) => w.add(f));
    this.watches.set(key, w);
  }

  /** Stops the watches of a block (of one output, or all of them). */
  private unwatch(msg: Extract<UiMessage, { type: "unwatch" }>): void {
    for (const [key, w] of this.watches) {
      if (w.block === msg.block && (msg.port === undefined || w.port === msg.port)) {
        w.untap();
        this.watches.delete(key);
      }
    }
  }

  private hello(): Extract<EngineMessage, { type: "hello" }> {
    return {
      type: "hello",
      version: PROTOCOL_VERSION,
      versions: PROTOCOL_VERSIONS,
      engine: this.platform.engine,
      sharedMemory: this.platform.sharedMemory,
    };
  }

  private requireRuntime(): Runtime {
    if (!this.rt) throw new Error("no pipeline is loaded");
    return this.rt;
  }

  private async load(
    file: string,
    source: string,
    simulateDevices = false,
    folder?: LocalFolder,
  ): Promise<{ diagnostics: Diagnostic[]; graph?: GraphInfo }> {
    const own = await this.ownBlocks(source, file);
    if (own.failed) return this.rejected(own.diagnostics);
    const parsed = this.platform.loadPipeline
      ? await this.platform.loadPipeline(source, file, own.catalog)
      : loadPipeline(source, file, own.catalog);
    const loaded = withSimulatedDevices(parsed, own.catalog, simulateDevices ? {} : undefined);
    // A text that does not load leaves what runs running (issue 17, defect 4).
    if (!loaded.spec) return this.rejected(loaded.diagnostics);
    const rejected = await this.precheck(loaded.spec, file, folder);
    if (rejected.length > 0) return this.rejected([...loaded.diagnostics, ...rejected]);
    this.unload();
    this.file = file;
    this.simulated = simulateDevices;
    const logs = this.platform.logs?.(file);
    const created = await Runtime.create({
      spec: loaded.spec,
      catalog: this.catalog,
      clock: this.platform.clock(),
      virtual: false,
      resources: this.platform.resources(file, folder),
      ...(logs ? { logs } : {}),
      ...(this.platform.io ? { io: this.platform.io } : {}),
      ignorePlacement: true,
    });
    const diagnostics = [...loaded.diagnostics, ...created.diagnostics];
    if (!created.runtime) {
      this.setState("empty");
      return { diagnostics };
    }
    this.rt = created.runtime;
    this.spec = loaded.spec;
    this.useBlocks(own, source);
    this.source = source;
    this.fileParams = this.liveParamsNow();
    this.setState("loaded");
    return { diagnostics, graph: this.graph() };
  }

  /** A load that failed: what runs stays (nothing loaded: the state says "empty"). */
  private rejected(diagnostics: Diagnostic[]): { diagnostics: Diagnostic[] } {
    if (!this.rt) this.setState("empty");
    return { diagnostics };
  }

  /**
   * While a pipeline is loaded, the blocks of its replacement are first instantiated on a
   * virtual clock (as `validate` does) so that one that cannot be created does not stop it.
   */
  private async precheck(
    spec: PipelineSpec,
    file: string,
    folder?: LocalFolder,
  ): Promise<Diagnostic[]> {
    if (!this.rt) return [];
    const created = await Runtime.create({
      spec,
      catalog: this.catalog,
      clock: new VirtualClock(0),
      virtual: true,
      resources: this.platform.resources(file, folder),
      ignorePlacement: true,
    });
    created.runtime?.dispose();
    return created.diagnostics.filter((d) => d.severity === "error");
  }

  /** The loaded pipeline's own blocks (`Pipeline: { Blocks }`) and the text they came from. */
  private blocks: { catalog: Catalog; modules: LoadedBlockModule[]; source: string } | undefined;

  /** The catalog for a pipeline text: the built-in blocks and those of its `Blocks:` modules. */
  private async ownBlocks(source: string, file: string) {
    const own = await pipelineCatalog(source, file, this.catalog, this.platform.blockModules);
    return { ...own, failed: own.diagnostics.some((d) => d.severity === "error") };
  }

  /** A pipeline with these blocks was loaded: the palette lists them, their files are watched. */
  private useBlocks(own: { catalog: Catalog; modules: LoadedBlockModule[] }, source: string): void {
    this.blocks = { catalog: own.catalog, modules: own.modules, source };
    this.catalogCache = undefined;
    const files = [...new Set(own.modules.flatMap((m) => m.inputs))];
    this.platform.watchBlocks?.(files, (changed) => void this.reloadBlocks(changed));
  }

  /**
   * A file of the loaded pipeline's block modules was saved: loads the pipeline again with the
   * new code and restarts it when it ran; when the new code does not load, what runs stays and
   * the log says why. Either way an event says what happened (hot reload, issue 18).
   */
  async reloadBlocks(changed: string): Promise<void> {
    const blocks = this.blocks;
    if (!this.rt || !blocks) return;
    const name = changed.split(/[/\\]/).pop() ?? changed;
    const running = this.state === "running";
    const run = this.loading.then(() => this.load(this.file, blocks.source, this.simulated));
    this.loading = run.catch(() => {});
    const { diagnostics, graph } = await run;
    const t = this.rt.clock.now();
    if (!graph) {
      const why = diagnostics.filter((d) => d.severity === "error").map((d) => d.message);
      const message = `${name} changed but does not load, the previous version keeps running: ${why.join("; ")}`;
      this.platform.post({
        type: "event",
        event: { t, level: "error", block: "user blocks", message },
      });
      return;
    }
    this.platform.post({ type: "graph", graph });
    if (running) this.start();
    const message = `reloaded ${name}: pipeline ${running ? "restarted" : "loaded again"}`;
    this.platform.post({
      type: "event",
      event: { t, level: "info", block: "user blocks", message },
    });
  }

  /** The catalog's metadata for the editor (built once per pipeline's own blocks). */
  private catalogCache: CatalogInfo | undefined;
  private catalogInfo(): CatalogInfo {
    if (this.catalogCache) return this.catalogCache;
    const types = catalogTypes(this.blocks?.catalog ?? this.catalog).map((d) => {
      let schema: unknown = {};
      try {
        schema = z.toJSONSchema(d.params, { io: "input", unrepresentable: "any" });
      } catch {
        schema = {};
      }
      let outputs: string[] = ["out"];
      try {
        const defaults = d.params.safeParse({});
        outputs = [...outputNames(d, defaults.success ? defaults.data : {})];
      } catch {
        /* ports that need params: the default port */
      }
      return {
        type: d.type,
        aliases: [...(d.aliases ?? [])],
        category: d.category,
        summary: d.summary,
        help: d.help,
        paramsSchema: schema,
        inputs: {
          min: d.inputs.min,
          max: Number.isFinite(d.inputs.max) ? d.inputs.max : null,
          labels: [...(d.inputs.labels ?? [])],
        },
        outputs,
        timer: d.timer === true,
        requiresRate: d.requiresRate === true || d.timer === true,
        live: [...(d.live ?? [])],
        views: [...(d.views ?? [])],
      };
    });
    types.sort((a, b) => a.category.localeCompare(b.category) || a.type.localeCompare(b.type));
    this.catalogCache = { types };
    return this.catalogCache;
  }

  /** The params' JSON Schema of each block type (graph). */
  private readonly schemas = new WeakMap<object, unknown>();

  private graph(): GraphInfo {
    const rt = this.rt!;
    const blocks: BlockInfo[] = this.spec!.blocks.map((b) => {
      const node = rt.node(b.name)!;
      // Once per block type: a pipeline of thousands of blocks has a few dozen types.
      let schema = this.schemas.get(b.def);
      if (schema === undefined) {
        try {
          schema = z.toJSONSchema(b.def.params, { io: "input", unrepresentable: "any" });
        } catch {
          schema = {};
        }
        this.schemas.set(b.def, schema);
      }
      const own = Object.entries(node.instance.actions ?? {}).map(([name, a]) => ({
        name,
        label: a.label,
        ...(a.description !== undefined ? { description: a.description } : {}),
      }));
      return {
        name: b.name,
        type: b.type,
        category: b.def.category,
        summary: b.def.summary,
        help: b.def.help,
        worker: b.worker,
        timer: b.def.timer === true,
        desiredRate: node.desiredRate,
        inputs: b.inputs.map((i) => ({
          source: i.source,
          block: i.block,
          port: i.port,
          subscribed: i.subscribed,
        })),
        outputs: node.ports.map((p) => ({ name: p.name, shape: p.shape, ...p.meta })),
        views: [...(b.def.views ?? [])],
        panel: b.def.panel ?? "",
        live: [...(b.def.live ?? [])],
        params: (node.params ?? {}) as Record<string, unknown>,
        fileParams: this.fileParams.get(b.name) ?? {},
        paramsSchema: schema,
        actions: withBuiltInActions(own),
        ...(b.layout ? { layout: b.layout } : {}),
        ...(b.path !== undefined ? { path: b.path } : {}),
      };
    });
    return {
      file: this.file,
      blocks,
      source: this.source,
      ...(this.simulated ? { simulateDevices: true } : {}),
      ...(this.spec!.settings.layout ? { layout: this.spec!.settings.layout } : {}),
    };
  }

  /** Each block's live params as they are now (those it has: a block may have none). */
  private liveParamsNow(): Map<string, Record<string, unknown>> {
    const out = new Map<string, Record<string, unknown>>();
    for (const b of this.spec?.blocks ?? []) {
      const params = (this.rt?.node(b.name)?.params ?? {}) as Record<string, unknown>;
      const live: Record<string, unknown> = {};
      for (const p of b.def.live ?? []) if (p in params) live[p] = params[p];
      out.set(b.name, live);
    }
    return out;
  }

  private blockParams(name: string): BlockParamsInfo {
    const node = this.requireRuntime().node(name);
    if (!node) throw new Error(`no block '${name}'`);
    return {
      name,
      params: (node.params ?? {}) as Record<string, unknown>,
      fileParams: this.fileParams.get(name) ?? {},
    };
  }

  /**
   * The UI wrote live values into the pipeline's text: they are the file's from now on (each
   * validated as `setParam` would; a block or param that is not live here is refused).
   */
  private paramsWritten(msg: Extract<UiMessage, { type: "params-written" }>): string {
    const rt = this.requireRuntime();
    const next = new Map([...this.fileParams].map(([k, v]) => [k, { ...v }]));
    for (const { block, param, value } of msg.values) {
      const node = rt.node(block);
      if (!node) throw new Error(`no block '${block}'`);
      if (!(node.def.live ?? []).includes(param))
        throw new Error(`param '${param}' of '${block}' is not live`);
      const r = node.def.params.safeParse({ ...(node.params as object), [param]: value });
      if (!r.success) throw new Error(`invalid value for '${block}.${param}'`);
      const file = next.get(block) ?? {};
      file[param] = (r.data as Record<string, unknown>)[param];
      next.set(block, file);
    }
    this.fileParams = next;
    this.source = msg.source;
    const blocks = [...new Set(msg.values.map((v) => v.block))].map((b) => this.blockParams(b));
    this.platform.post({ type: "params", blocks, source: msg.source });
    const n = msg.values.length;
    return `${n} live value${n === 1 ? "" : "s"} written to ${this.file}`;
  }

  private start(): void {
    const rt = this.requireRuntime();
    if (this.state === "running") return;
    rt.start();
    this.loop = this.platform.startLoop(rt, {
      telemetryIntervalS: 0.05,
      onTelemetry: (at) => this.flush(at),
      onFinished: () => {
        this.flush();
        this.finishRecording();
        this.setState("finished");
      },
    });
    rt.onWake = () => this.loop?.wake();
    this.setState("running");
  }

  /** Sends telemetry, events and the panel data gathered since the previous flush. */
  private flush(at?: number): void {
    const rt = this.rt;
    if (!rt) return;
    const telemetry = rt.telemetry(at);
    const events = telemetry.events;
    telemetry.events = [];
    this.platform.post({ type: "telemetry", telemetry });
    for (const event of events) this.platform.post({ type: "event", event });
    for (const w of this.watches.values()) {
      const m = w.take();
      if (m) this.platform.post(m, [m.t.buffer as ArrayBuffer, m.v.buffer as ArrayBuffer]);
    }
    this.tickRecording(rt.clock.now());
  }

  private startRecording(msg: Extract<UiMessage, { type: "record-start" }>): string {
    const rt = this.requireRuntime();
    if (this.state !== "running") {
      throw new Error(
        "start the pipeline first: a recording takes what the running pipeline sends",
      );
    }
    if (this.recorder) throw new Error("a recording is running already: stop it first");
    const resources = this.platform.recordings?.(this.file) ?? this.platform.resources(this.file);
    this.recorder = SessionRecorder.start(rt, msg, this.platform.recordingFormats ?? {}, resources);
    const status = this.recorder.status(rt.clock.now());
    this.recordingSentAt = rt.clock.now();
    this.platform.post({ type: "recording", recording: status });
    return `recording ${status.outputs.join(", ")} to ${status.file}`;
  }

  /** Writes what waits; sends the status about 4 times a second; ends a failed recording. */
  private tickRecording(now: number): void {
    const r = this.recorder;
    if (!r) return;
    r.tick(now);
    if (r.failed) {
      this.finishRecording();
      return;
    }
    if (now - this.recordingSentAt < 0.25) return;
    this.recordingSentAt = now;
    this.platform.post({ type: "recording", recording: r.status(now) });
  }

  /**
   * Finishes the session recording: its last status, and the file's bytes for the page to save
   * when it was kept in memory. Returns what happened (undefined: none was running).
   */
  private finishRecording(): string | undefined {
    const r = this.recorder;
    if (!r || !this.rt) return undefined;
    this.recorder = undefined;
    const done = r.stop(this.rt.clock.now());
    const s = done.status;
    this.platform.post({ type: "recording", recording: s });
    if (done.bytes) {
      const name = s.file.split(/[/\\]/).pop() ?? s.file;
      const bytes = done.bytes;
      this.platform.post({ type: "download", name, mime: done.mime, bytes }, [
        bytes.buffer as ArrayBuffer,
      ]);
    }
    const facts = `${s.duration.toFixed(1)} s, ${s.bytes} bytes, ${s.samples} samples`;
    if (s.state === "failed") {
      const message = `recording to ${s.file} failed: ${s.error ?? "unknown error"} (${facts} kept)`;
      this.platform.post({
        type: "event",
        event: { t: this.rt.clock.now(), level: "error", block: "recording", message },
      });
      return message;
    }
    return `${s.inMemory ? "downloading" : "saved"} ${s.file} (${facts})`;
  }

  private stop(): void {
    if (!this.rt || this.state !== "running") return;
    this.loop?.stop();
    this.loop = undefined;
    this.rt.stop();
    this.rt.dispatch();
    this.flush();
    this.finishRecording();
    this.setState("stopped");
  }

  private unload(): void {
    this.stop();
    this.finishRecording();
    for (const w of this.watches.values()) w.untap();
    this.watches.clear();
    this.rt?.dispose();
    this.rt = undefined;
    this.spec = undefined;
    this.fileParams = new Map();
  }

  dispose(): void {
    this.unload();
  }
}
