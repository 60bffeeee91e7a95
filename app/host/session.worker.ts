/**
 * The engine behind `mosaic serve` and the desktop app: one EngineSession (the UI protocol) in a
 * Node worker thread, with the real-time loop, the native I/O bridges and `Path` logs written by
 * the host's main thread. The main thread (app/host/session-hub.ts) relays the protocol to its
 * clients (WebSocket tabs, the Electron window) and runs what cannot run in a worker (serial).
 *
 * Large pipeline files are parsed and validated off the session's message loop, in a loader
 * thread started from this same file (`workerData.role === "loader"`): while one client's big
 * file loads, the others' requests are answered. A loader that runs out of memory or time is
 * stopped and the load refused; the session goes on.
 *
 * Pipelines loaded by the hub's clients are confined to the folders the hub says (`confine`
 * before each load): their files (AllowedFolders in resources.ts) and `Path` logs.
 */
import { readFileSync, unwatchFile, watchFile } from "node:fs";
import { dirname, isAbsolute, resolve } from "node:path";
import { parentPort, Worker, workerData, type MessagePort } from "node:worker_threads";
import { catalog } from "../blocks/catalog";
import type { ModuleLoadResult } from "../engine/user-blocks";
import { MonotonicClock } from "../engine/clock";
import { errorMessage, type Diagnostic } from "../engine/diagnostics";
import { initDsp } from "../engine/dsp";
import type { Frame, Shape } from "../engine/frame";
import {
  loadPipeline,
  type BlockSpec,
  type LoadResult,
  type PipelineSettings,
} from "../engine/pipeline/loader";
import { logFileName, type LogChannel, type LogSink } from "../engine/runtime/logsink";
import { RealtimeLoop } from "../engine/runtime/loop";
import type { Runtime } from "../engine/runtime/runtime";
import { SabRing, type SabRingInit } from "../engine/runtime/sab-ring";
import { EngineSession, type LoopHooks, type SessionPlatform } from "../engine/session";
import { bleProxy } from "../../native-bridges/ble-proxy";
import { nodeRosBridge } from "../../native-bridges/ros";
import { serialProxy } from "../../native-bridges/serial-proxy";
import { nodeLslBridge } from "../../native-bridges/lsl";
import { nodeTcpBridge } from "../../native-bridges/tcp";
import { nodeUdpBridge } from "../../native-bridges/udp";
import { createPythonBridge } from "../../native-bridges/python";
import { sessionRecordingFormats } from "../blocks/recording/session-formats";
import { AllowedFolders, nodeResources } from "./resources";
import { clockFromBase } from "./time-base";
import { loadBlockModule } from "./user-blocks";
import type { HubToSession, SessionToHub } from "./session-protocol";

/** Files up to this size are parsed here (a few milliseconds); larger ones in the loader. */
const INLINE_CHARS = 32 * 1024;
/** The loader's memory (MB) and time (s) before it is stopped and the load refused. */
const LOADER_MEMORY_MB = 1024;
const LOADER_TIME_S = 60;

// ---------------------------------------------------------------------------------------------
// The loader thread: text → LoadResult, without what cannot cross threads (block definitions,
// the YAML document); the session puts the definitions back from its catalog.

interface LoadJob {
  id: number;
  source: string;
  file: string;
}

type Portable = Omit<LoadResult, "doc" | "spec"> & {
  spec?: { file: string; settings: unknown; blocks: Omit<BlockSpec, "def">[] };
};

function runLoader(p: MessagePort): void {
  p.on("message", (job: LoadJob) => {
    const r = loadPipeline(job.source, job.file, catalog);
    const out: Portable = { ok: r.ok, diagnostics: r.diagnostics };
    if (r.spec) {
      out.spec = {
        file: r.spec.file,
        settings: r.spec.settings,
        blocks: r.spec.blocks.map(({ def: _def, ...rest }) => rest),
      };
    }
    try {
      p.postMessage({ id: job.id, result: out });
    } catch {
      // Params that cannot cross threads: the session parses this one itself.
      p.postMessage({ id: job.id, result: undefined });
    }
  });
}

/** A LoadResult from the loader, with the block definitions put back (undefined: cannot). */
function fromPortable(r: Portable): LoadResult | undefined {
  if (!r.spec) return { ok: false, diagnostics: r.diagnostics, spec: undefined, doc: undefined };
  const blocks: BlockSpec[] = [];
  for (const b of r.spec.blocks) {
    const def = catalog.get(b.type);
    if (!def) return undefined;
    blocks.push({ ...b, def });
  }
  return {
    ok: r.ok,
    diagnostics: r.diagnostics,
    doc: undefined,
    spec: {
      file: r.spec.file,
      settings: r.spec.settings as PipelineSettings,
      blocks,
      byName: new Map(blocks.map((b) => [b.name, b])),
    },
  };
}

/** The loader thread, started on the first large file and kept (one load at a time). */
class Loader {
  private worker: Worker | undefined;
  private nextId = 1;
  private readonly waiting = new Map<number, (r: Portable | undefined | string) => void>();

  private start(): Worker {
    if (this.worker) return this.worker;
    const w = new Worker(new URL(import.meta.url), {
      name: "mosaic-loader",
      workerData: { role: "loader" },
      resourceLimits: { maxOldGenerationSizeMb: LOADER_MEMORY_MB },
    });
    w.unref();
    w.on("message", (m: { id: number; result: Portable | undefined }) => {
      const f = this.waiting.get(m.id);
      this.waiting.delete(m.id);
      f?.(m.result);
    });
    const fail = (why: string): void => {
      if (this.worker !== w) return;
      this.worker = undefined;
      for (const f of this.waiting.values()) f(why);
      this.waiting.clear();
    };
    w.on("error", (e) =>
      fail(
        (e as { code?: string }).code === "ERR_WORKER_OUT_OF_MEMORY"
          ? `loading it needs more than the ${LOADER_MEMORY_MB} MB the loader may use`
          : `the loader failed: ${errorMessage(e)}`,
      ),
    );
    w.on("exit", () => fail("the loader stopped"));
    this.worker = w;
    return w;
  }

  /** The result, or a sentence saying why there is none (undefined: parse it here). */
  load(source: string, file: string): Promise<Portable | undefined | string> {
    const w = this.start();
    const id = this.nextId++;
    return new Promise((done) => {
      const timer = setTimeout(() => {
        if (!this.waiting.has(id)) return;
        this.waiting.delete(id);
        done(`loading took longer than ${LOADER_TIME_S} s and was stopped`);
        if (this.worker === w) this.worker = undefined;
        void w.terminate();
      }, LOADER_TIME_S * 1000);
      timer.unref();
      this.waiting.set(id, (r) => {
        clearTimeout(timer);
        done(r);
      });
      w.postMessage({ id, source, file } satisfies LoadJob);
    });
  }
}

// ---------------------------------------------------------------------------------------------
// The session thread.

/** Where `rel` lies: itself when absolute, else inside `baseDir`. */
function within(baseDir: string, rel: string): string {
  return isAbsolute(rel) ? rel : resolve(baseDir, rel);
}

/** A `Path` log's ring to the host's log writer: about 2^17 values, 4096 frames at least. */
function allocateLogRing(shape: Shape): SabRingInit {
  const stride = shape.rows * shape.cols;
  const capacity = Math.max(4096, Math.ceil((1 << 17) / (stride + 1)));
  return SabRing.allocate(capacity, stride);
}

/** A refused load, saying why (`cannot load the pipeline: …` at the file's first line). */
function loadFailed(file: string, why: string): LoadResult {
  return {
    ok: false,
    spec: undefined,
    doc: undefined,
    diagnostics: [
      {
        severity: "error",
        code: "load-failed",
        message: `cannot load the pipeline: ${why}`,
        file,
        line: 1,
        col: 1,
      },
    ],
  };
}

/** One error at each block with a `Path` log outside the folders (its first refused output). */
function pathErrors(
  spec: NonNullable<LoadResult["spec"]>,
  baseDir: string,
  confined: AllowedFolders,
): Diagnostic[] {
  const errors: Diagnostic[] = [];
  for (const b of spec.blocks) {
    if (b.path === undefined) continue;
    const outputs = b.outputs.length > 0 ? b.outputs : ["out"];
    for (const [i, o] of outputs.entries()) {
      const rel = logFileName(b.path, b.name, o, i === 0);
      const refused = confined.check(within(baseDir, rel), "write");
      if (refused === undefined) continue;
      errors.push({
        severity: "error",
        code: "outside-folders",
        message: `block '${b.name}': Path: ${refused}`,
        file: spec.file,
        line: b.pos.line,
        col: b.pos.col,
        block: b.name,
        param: "Path",
      });
      break;
    }
  }
  return errors;
}

/**
 * The session thread: the hub's messages in, the EngineSession's out. Until `session-init` boots
 * the session, the UI's messages wait; `confine` sets the folders of the pipelines loaded next;
 * serial and Bluetooth LE replies go to their proxies.
 */
class SessionThread {
  private session: EngineSession | undefined;
  private pipelinesDir = process.cwd();
  /** What the pipelines loaded from now on may use (null: anything); see `confine`. */
  private allowed: AllowedFolders | null = null;
  private readonly pending: unknown[] = [];
  private readonly doorbell = new Int32Array(new SharedArrayBuffer(8));
  private loop: RealtimeLoop | undefined;
  private readonly serial = serialProxy((m) => this.post(m));
  private readonly ble = bleProxy((m) => this.post(m));
  private readonly loader = new Loader();
  private nextLog = 0;
  /** The files of the loaded pipeline's block modules, polled (see `watchBlocks`). */
  private watched: string[] = [];

  constructor(private readonly port: MessagePort) {}

  listen(): void {
    this.port.on("message", (msg: HubToSession) => this.receive(msg));
  }

  private post(m: SessionToHub, transfer?: ArrayBuffer[]): void {
    this.port.postMessage(m, transfer ?? []);
  }

  private receive(msg: HubToSession): void {
    try {
      if (msg.type === "session-init") this.boot(msg);
      else if (msg.type === "confine") {
        this.allowed = msg.dirs ? new AllowedFolders(msg.dirs) : null;
      } else if (msg.type === "serial") this.serial.receive(msg);
      else if (msg.type === "ble") this.ble.receive(msg);
      else if (this.session) void this.session.handle(msg);
      else this.pending.push(msg);
      // The loop turns the event loop only when rung or every 50 ms: answer at once.
      this.loop?.wake();
    } catch (e) {
      this.post({
        type: "event",
        event: { t: Date.now() / 1000, level: "error", block: "engine", message: errorMessage(e) },
      });
    }
  }

  private boot(msg: Extract<HubToSession, { type: "session-init" }>): void {
    this.pipelinesDir = msg.pipelinesDir;
    initDsp(readFileSync(msg.wasmPath));
    const session = new EngineSession(catalog, this.platform(msg));
    this.session = session;
    this.post({ type: "session-ready", doorbell: this.doorbell.buffer as SharedArrayBuffer });
    for (const m of this.pending.splice(0)) void session.handle(m);
  }

  /** What the EngineSession runs on here: files, logs and loads confined, the native bridges. */
  private platform(msg: Extract<HubToSession, { type: "session-init" }>): SessionPlatform {
    return {
      engine: "node host",
      sharedMemory: true,
      clock: () => clockFromBase(msg.timeBase) as MonotonicClock,
      resources: (file) => nodeResources(this.folderOf(file), this.allowed ?? undefined),
      logs: (file) => this.logSink(file, this.allowed),
      loadPipeline: (source, file, blocks) => this.parse(source, file, blocks),
      blockModules: (path) => this.blockModule(path),
      watchBlocks: (files, changed) => this.watchBlocks(files, changed),
      recordingFormats: sessionRecordingFormats,
      // The data folder when there is one, confined as the pipeline is.
      recordings: (file) =>
        nodeResources(msg.dataDir ?? this.folderOf(file), this.allowed ?? undefined),
      io: {
        udp: nodeUdpBridge(),
        tcp: nodeTcpBridge(),
        ros: nodeRosBridge(),
        serial: this.serial.bridge,
        ble: this.ble.bridge,
        python: createPythonBridge(),
        lsl: nodeLslBridge(),
      },
      startLoop: (rt, hooks) => this.startLoop(rt, hooks),
      post: (m, transfer) => this.post(m, transfer),
    };
  }

  /** Where a pipeline's relative paths (data, logs) start: its folder. */
  private folderOf(file: string): string {
    return dirname(isAbsolute(file) ? file : resolve(this.pipelinesDir, file));
  }

  /** `Path` logs of the pipeline `file`, written by the host through a ring each. */
  private logSink(file: string, confined: AllowedFolders | null): LogSink {
    const baseDir = this.folderOf(file);
    return {
      open: (block, portName, isDefaultPort, path, shape) => {
        const rel = logFileName(path, block, portName, isDefaultPort);
        const refused = confined?.check(within(baseDir, rel), "write");
        if (refused !== undefined) throw new Error(`block '${block}': ${refused}`);
        const id = this.nextLog++;
        const init = allocateLogRing(shape);
        const ring = new SabRing(init);
        this.post({
          type: "log-open",
          id,
          baseDir,
          block,
          port: portName,
          isDefaultPort,
          path,
          shape,
          ring: init,
        });
        const channel: LogChannel = {
          write(f: Frame) {
            ring.write(f, false);
          },
          close: () => {
            ring.close();
            this.post({ type: "log-close", id });
          },
        };
        return channel;
      },
    };
  }

  /**
   * Parses and validates `source`: here when small or when it has its own blocks (the loader
   * thread knows only the built-in ones), in the loader thread otherwise.
   */
  private async parse(source: string, file: string, blocks = catalog): Promise<LoadResult> {
    const confined = this.allowed;
    let r: LoadResult | undefined;
    if (source.length > INLINE_CHARS && blocks === catalog) {
      const got = await this.loader.load(source, file);
      if (typeof got === "string") return loadFailed(file, got);
      if (got) r = fromPortable(got);
    }
    r ??= loadPipeline(source, file, blocks);
    return confined ? this.checkPaths(r, file, confined) : r;
  }

  /** Every `Path` of a confined pipeline inside its folders: one error at each block that is not. */
  private checkPaths(r: LoadResult, file: string, confined: AllowedFolders): LoadResult {
    if (!r.spec) return r;
    const errors = pathErrors(r.spec, this.folderOf(file), confined);
    if (errors.length === 0) return r;
    return { ...r, ok: false, spec: undefined, diagnostics: [...r.diagnostics, ...errors] };
  }

  /** A user's block module, when the pipeline may run code from where it is (confinement). */
  private blockModule(path: string): Promise<ModuleLoadResult> {
    const confined = this.allowed;
    return loadBlockModule(path, confined ? (f) => confined.check(f, "run code from") : undefined);
  }

  /** Polls the block modules' files (an editor may save by renaming), replacing the last ones. */
  private watchBlocks(files: string[], changed: (file: string) => void): void {
    for (const f of this.watched) unwatchFile(f);
    this.watched = files;
    let reload: NodeJS.Timeout | undefined;
    for (const f of files) {
      watchFile(f, { interval: 250, persistent: false }, (now, before) => {
        if (now.mtimeMs === before.mtimeMs && now.size === before.size) return;
        // One reload for a save that touches the file several times.
        clearTimeout(reload);
        reload = setTimeout(() => changed(f), 150);
      });
    }
  }

  private startLoop(rt: Runtime, hooks: LoopHooks): RealtimeLoop {
    const loop = new RealtimeLoop({
      runtime: rt,
      yieldNow: (fn: () => void): void => void setImmediate(fn),
      clock: rt.clock,
      doorbell: this.doorbell,
      precision: false,
      ...hooks,
    });
    this.loop = loop;
    loop.start();
    return loop;
  }
}

// Last: the functions and classes above exist by now.
const port = parentPort;
if (!port) throw new Error("session.worker must run in a worker thread");
if ((workerData as { role?: string } | null)?.role === "loader") runLoader(port);
else new SessionThread(port).listen();
