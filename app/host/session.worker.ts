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
import { SabRing } from "../engine/runtime/sab-ring";
import { EngineSession, type LoopHooks } from "../engine/session";
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

function runSession(port: MessagePort): void {
  const post = (m: SessionToHub, transfer?: ArrayBuffer[]): void =>
    port.postMessage(m, transfer ?? []);

  let session: EngineSession | undefined;
  let pipelinesDir = process.cwd();
  /** What the pipelines loaded from now on may use (null: anything); see `confine`. */
  let allowed: AllowedFolders | null = null;
  const pending: unknown[] = [];
  const doorbell = new Int32Array(new SharedArrayBuffer(8));
  let loop: RealtimeLoop | undefined;
  const serial = serialProxy((m) => post(m));
  const ble = bleProxy((m) => post(m));
  const loader = new Loader();

  /** Where a pipeline's relative paths (data, logs) start: its folder. */
  const folderOf = (file: string): string =>
    dirname(isAbsolute(file) ? file : resolve(pipelinesDir, file));

  let nextLog = 0;
  function logSink(file: string, confined: AllowedFolders | null): LogSink {
    const baseDir = folderOf(file);
    return {
      open(block: string, portName: string, isDefaultPort: boolean, path: string, shape: Shape) {
        const rel = logFileName(path, block, portName, isDefaultPort);
        const refused = confined?.check(isAbsolute(rel) ? rel : resolve(baseDir, rel), "write");
        if (refused !== undefined) throw new Error(`block '${block}': ${refused}`);
        const id = nextLog++;
        const stride = shape.rows * shape.cols;
        const capacity = Math.max(4096, Math.ceil((1 << 17) / (stride + 1)));
        const init = SabRing.allocate(capacity, stride);
        const ring = new SabRing(init);
        post({
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
          close() {
            ring.close();
            post({ type: "log-close", id });
          },
        };
        return channel;
      },
    };
  }

  /** Every `Path` of a confined pipeline inside its folders: one error at each block that is not. */
  function checkPaths(r: LoadResult, file: string, confined: AllowedFolders): LoadResult {
    if (!r.spec) return r;
    const baseDir = folderOf(file);
    const errors: Diagnostic[] = [];
    for (const b of r.spec.blocks) {
      if (b.path === undefined) continue;
      const outputs = b.outputs.length > 0 ? b.outputs : ["out"];
      for (const [i, o] of outputs.entries()) {
        const rel = logFileName(b.path, b.name, o, i === 0);
        const refused = confined.check(isAbsolute(rel) ? rel : resolve(baseDir, rel), "write");
        if (refused === undefined) continue;
        errors.push({
          severity: "error",
          code: "outside-folders",
          message: `block '${b.name}': Path: ${refused}`,
          file: r.spec.file,
          line: b.pos.line,
          col: b.pos.col,
          block: b.name,
          param: "Path",
        });
        break;
      }
    }
    if (errors.length === 0) return r;
    return { ...r, ok: false, spec: undefined, diagnostics: [...r.diagnostics, ...errors] };
  }

  /**
   * Parses and validates `source`: here when small or when it has its own blocks (the loader
   * thread knows only the built-in ones), in the loader thread otherwise.
   */
  async function parse(source: string, file: string, blocks = catalog): Promise<LoadResult> {
    const confined = allowed;
    let r: LoadResult | undefined;
    if (source.length > INLINE_CHARS && blocks === catalog) {
      const got = await loader.load(source, file);
      if (typeof got === "string") {
        return {
          ok: false,
          spec: undefined,
          doc: undefined,
          diagnostics: [
            {
              severity: "error",
              code: "load-failed",
              message: `cannot load the pipeline: ${got}`,
              file,
              line: 1,
              col: 1,
            },
          ],
        };
      }
      if (got) r = fromPortable(got);
    }
    r ??= loadPipeline(source, file, blocks);
    return confined ? checkPaths(r, file, confined) : r;
  }

  /** A user's block module, when the pipeline may run code from where it is (confinement). */
  function blockModule(path: string): Promise<ModuleLoadResult> {
    const confined = allowed;
    return loadBlockModule(path, confined ? (f) => confined.check(f, "run code from") : undefined);
  }

  /** The files of the loaded pipeline's block modules, polled (an editor may save by renaming). */
  let watched: string[] = [];
  function watchBlocks(files: string[], changed: (file: string) => void): void {
    for (const f of watched) unwatchFile(f);
    watched = files;
    let pending: NodeJS.Timeout | undefined;
    for (const f of files) {
      watchFile(f, { interval: 250, persistent: false }, (now, before) => {
        if (now.mtimeMs === before.mtimeMs && now.size === before.size) return;
        // One reload for a save that touches the file several times.
        clearTimeout(pending);
        pending = setTimeout(() => changed(f), 150);
      });
    }
  }

  const yieldNow = (fn: () => void): void => void setImmediate(fn);

  function startLoop(rt: Runtime, hooks: LoopHooks) {
    loop = new RealtimeLoop({
      runtime: rt,
      yieldNow,
      clock: rt.clock,
      doorbell,
      precision: false,
      ...hooks,
    });
    loop.start();
    return loop;
  }

  function boot(msg: Extract<HubToSession, { type: "session-init" }>): void {
    pipelinesDir = msg.pipelinesDir;
    initDsp(readFileSync(msg.wasmPath));
    session = new EngineSession(catalog, {
      engine: "node host",
      sharedMemory: true,
      clock: () => clockFromBase(msg.timeBase) as MonotonicClock,
      resources: (file) => nodeResources(folderOf(file), allowed ?? undefined),
      logs: (file) => logSink(file, allowed),
      loadPipeline: parse,
      blockModules: blockModule,
      watchBlocks,
      recordingFormats: sessionRecordingFormats,
      // The data folder when there is one, confined as the pipeline is.
      recordings: (file) => nodeResources(msg.dataDir ?? folderOf(file), allowed ?? undefined),
      io: {
        udp: nodeUdpBridge(),
        tcp: nodeTcpBridge(),
        ros: nodeRosBridge(),
        serial: serial.bridge,
        ble: ble.bridge,
        python: createPythonBridge(),
        lsl: nodeLslBridge(),
      },
      startLoop,
      post: (m, transfer) => post(m, transfer),
    });
    post({ type: "session-ready", doorbell: doorbell.buffer as SharedArrayBuffer });
    for (const m of pending.splice(0)) void session.handle(m);
  }

  port.on("message", (msg: HubToSession) => {
    try {
      if (msg.type === "session-init") boot(msg);
      else if (msg.type === "confine") allowed = msg.dirs ? new AllowedFolders(msg.dirs) : null;
      else if (msg.type === "serial") serial.receive(msg);
      else if (msg.type === "ble") ble.receive(msg);
      else if (session) void session.handle(msg);
      else pending.push(msg);
      // The loop turns the event loop only when rung or every 50 ms: answer at once.
      loop?.wake();
    } catch (e) {
      post({
        type: "event",
        event: { t: Date.now() / 1000, level: "error", block: "engine", message: errorMessage(e) },
      });
    }
  });
}

// Last: the functions and classes above exist by now.
const port = parentPort;
if (!port) throw new Error("session.worker must run in a worker thread");
if ((workerData as { role?: string } | null)?.role === "loader") runLoader(port);
else runSession(port);
