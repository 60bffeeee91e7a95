/**
 * The host's side of `mosaic serve` and the desktop app: one engine session in a worker thread
 * (app/host/session.worker.ts), shared by any number of clients (browser tabs over WebSocket,
 * the Electron window over IPC). The hub validates what clients send, gives each request a
 * hub-wide id and routes the reply back to its client; telemetry, state and events go to every
 * client; panel data goes to the clients watching that block (a block stays watched while any
 * client watches it). A client that joins late gets the engine's hello, the loaded graph and the
 * state at once; a client that goes away (a closed tab) only drops its watches: the pipeline runs
 * on. `Path` logs are written here, and serial ports are opened here (see serial-proxy.ts).
 */
import { existsSync } from "node:fs";
import { dirname, isAbsolute, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { Worker } from "node:worker_threads";
import { errorMessage } from "../engine/diagnostics";
import {
  parseUiMessage,
  PROTOCOL_VERSION,
  PROTOCOL_VERSIONS,
  unsupportedHello,
  type EngineMessage,
  type GraphInfo,
  type UiMessage,
} from "../engine/protocol";
import { bleHub } from "../../native-bridges/ble-proxy";
import { serialHub } from "../../native-bridges/serial-proxy";
import { defaultWasmPath } from "./host";
import { LogWriter } from "./log-writer";
import type { HubToSession, SessionToHub } from "./session-protocol";
import { takeTimeBase } from "./time-base";
import { tuneTiering } from "./tiering";

/** One client of the hub: where its engine messages go. */
export interface HubClient {
  send(msg: EngineMessage): void;
}

/** A connected client: what it sends goes to `receive`; `close` when it goes away. */
export interface HubConnection {
  receive(raw: unknown): void;
  close(): void;
}

export interface SessionHubOptions {
  /**
   * Relative pipeline names resolve against this folder: the UI's list gives them as
   * "pipelines/x.yaml", relative to the repository (the packaged app's resources).
   */
  pipelinesDir: string;
  workerPath?: string;
  wasmPath?: string;
  /**
   * Confines the pipelines that clients load (browser tabs over the socket, a desktop window) to
   * these folders: everything they read and write (data and model files, `Path` logs, Python
   * modules) must lie inside one of them, or it is refused with a message that says so. The
   * folder of every pipeline the host loads itself (`request`: `mosaic serve FILE`, the desktop
   * app's File → Open) joins them; those loads are not confined, as with `mosaic run`.
   * Undefined: nothing is confined.
   */
  allowedDirs?: string[];
  /**
   * The data folder: session recordings (the UI's Record button) go to its `recordings/`
   * (`mosaic serve --data-dir`, the desktop app's data folder); else to the pipeline's folder.
   */
  dataDir?: string;
  /** The session worker died or a log could not be written. */
  onProblem?(message: string): void;
}

type Reply = Extract<EngineMessage, { type: "reply" }>;
/** A request without its id (the hub adds one); distributes over the union. */
type Request<T = Extract<UiMessage, { id: number }>> = T extends unknown ? Omit<T, "id"> : never;

interface Pending {
  client?: Client;
  clientId: number;
  resolve?: (r: Reply) => void;
  /** A load: the next may go once this one is answered. */
  done?: () => void;
}

interface Client {
  sink: HubClient;
  /** Watch keys this client holds. */
  watches: Set<string>;
  open: boolean;
  /** Said hello: gets broadcasts from then on (its first messages are hello, graph, state). */
  greeted: boolean;
}

/**
 * The folders pipelines loaded by clients may use by default: the examples' folder the UI lists
 * ("pipelines/…" under `pipelinesDir`) and the data folder.
 */
export function defaultAllowedDirs(pipelinesDir: string, dataDir?: string): string[] {
  return [join(pipelinesDir, "pipelines"), ...(dataDir !== undefined ? [dataDir] : [])];
}

/** `graph` with a `params` message's current and file values (and the file's new text). */
export function withParams(
  graph: GraphInfo,
  m: Extract<EngineMessage, { type: "params" }>,
): GraphInfo {
  const by = new Map(m.blocks.map((b) => [b.name, b]));
  return {
    ...graph,
    ...(m.source !== undefined ? { source: m.source } : {}),
    blocks: graph.blocks.map((b) => {
      const p = by.get(b.name);
      return p ? { ...b, params: p.params, fileParams: p.fileParams } : b;
    }),
  };
}

export function defaultSessionWorkerPath(): string {
  const here = dirname(fileURLToPath(import.meta.url));
  for (const p of [
    join(here, "session.worker.mjs"),
    join(here, "..", "..", "dist", "session.worker.mjs"),
  ]) {
    if (existsSync(p)) return p;
  }
  return join(here, "session.worker.mjs");
}

/** The hub's key of a watched block output. */
const watchKey = (block: string, port: string): string => `${block}\u0000${port}`;

export class SessionHub {
  private readonly worker: Worker;
  private doorbell: Int32Array | undefined;
  private readonly clients = new Set<Client>();
  private readonly pending = new Map<number, Pending>();
  private nextId = 1;
  /** Watch key → clients holding it. */
  private readonly watchers = new Map<string, Set<Client>>();
  private hello: EngineMessage | undefined;
  private graph: GraphInfo | undefined;
  private lastState: EngineMessage | undefined;
  private readonly logs = new Map<number, { writer: LogWriter; key: string }>();
  private readonly writers = new Map<string, LogWriter>();
  private readonly serial = serialHub((m) => this.toWorker(m));
  private readonly ble = bleHub((m) => this.toWorker(m));
  private exited = false;
  private closing = false;
  private readonly ready: Promise<void>;
  /** Loads go one at a time (each with the folders it may use): the last one queued. */
  private loads: Promise<void> = Promise.resolve();
  /** See SessionHubOptions.allowedDirs. */
  private readonly allowed: Set<string> | undefined;

  private constructor(private readonly options: SessionHubOptions) {
    this.allowed = options.allowedDirs
      ? new Set(options.allowedDirs.map((d) => resolve(d)))
      : undefined;
    tuneTiering();
    this.worker = new Worker(options.workerPath ?? defaultSessionWorkerPath(), {
      name: "mosaic-session",
      resourceLimits: { maxYoungGenerationSizeMb: 8 },
    });
    this.ready = new Promise((resolve, reject) => {
      const onMessage = (m: SessionToHub): void => {
        if (m.type === "hello") {
          this.hello = m;
          resolve();
        }
      };
      this.worker.on("message", onMessage);
      this.worker.once("error", (e) => reject(e));
    });
    this.worker.on("message", (m: SessionToHub) => this.fromWorker(m));
    this.worker.on("error", (e) => this.problem(`the engine crashed: ${errorMessage(e)}`));
    this.worker.on("exit", (code) => {
      this.exited = true;
      void this.serial.closeAll();
      this.ble.closeAll();
      for (const w of this.writers.values()) w.closeAll();
      if (code !== 0 && !this.closing) this.problem(`the engine exited (code ${code})`);
    });
    this.toWorker({
      type: "session-init",
      wasmPath: options.wasmPath ?? defaultWasmPath(),
      pipelinesDir: options.pipelinesDir,
      timeBase: takeTimeBase(),
      ...(options.dataDir !== undefined ? { dataDir: resolve(options.dataDir) } : {}),
    });
    this.toWorker({ type: "hello", version: PROTOCOL_VERSION });
  }

  /** Starts the engine worker; resolves when it answered `hello`. */
  static async start(options: SessionHubOptions): Promise<SessionHub> {
    const hub = new SessionHub(options);
    await hub.ready;
    return hub;
  }

  get clientCount(): number {
    return this.clients.size;
  }

  /** The graph of the loaded pipeline (undefined when none is loaded). */
  get loaded(): GraphInfo | undefined {
    return this.graph;
  }

  private problem(message: string): void {
    this.options.onProblem?.(message);
    this.broadcast({
      type: "event",
      event: { t: Date.now() / 1000, level: "error", block: "engine", message },
    });
  }

  /** False when the message could not be passed (it cannot be cloned: a value nested too deep). */
  private toWorker(m: HubToSession): boolean {
    if (this.exited) return true;
    try {
      this.worker.postMessage(m);
    } catch {
      return false;
    }
    if (this.doorbell) {
      Atomics.store(this.doorbell, 1, 1);
      Atomics.add(this.doorbell, 0, 1);
      Atomics.notify(this.doorbell, 0);
    }
    return true;
  }

  /** Where a pipeline's relative paths start (as the session worker resolves them). */
  private folderOf(file: string): string {
    return dirname(isAbsolute(file) ? file : resolve(this.options.pipelinesDir, file));
  }

  /**
   * Sends request `id` (a `load` or a `validate`, which reads files as a load does; pending
   * already) once the loads before it are answered, after the folders it may use (`dirs`, null:
   * anywhere).
   */
  private sendLoad(
    id: number,
    msg: Extract<UiMessage, { type: "load" | "validate" }>,
    dirs: string[] | null,
  ) {
    this.loads = this.loads.then(
      () =>
        new Promise<void>((done) => {
          const p = this.pending.get(id);
          if (!p || this.exited) return done();
          p.done = done;
          this.toWorker({ type: "confine", dirs });
          if (!this.toWorker({ ...msg, id })) {
            this.fromWorker({
              type: "reply",
              id,
              ok: false,
              message: "the pipeline cannot be passed to the engine",
            });
          }
        }),
    );
  }

  private broadcast(m: EngineMessage): void {
    for (const c of this.clients) if (c.greeted) c.sink.send(m);
  }

  private fromWorker(m: SessionToHub): void {
    switch (m.type) {
      case "session-ready":
        this.doorbell = new Int32Array(m.doorbell);
        return;
      case "hello":
        this.hello = m;
        return;
      case "reply":
        this.onReply(m);
        return;
      case "state":
        this.lastState = m;
        if (m.state === "empty") this.graph = undefined;
        this.broadcast(m);
        return;
      case "telemetry":
      case "event":
      case "recording":
        this.broadcast(m);
        return;
      case "params":
        // A client that joins later gets the engine's values with the graph.
        if (this.graph) this.graph = withParams(this.graph, m);
        this.broadcast(m);
        return;
      case "graph":
        this.graph = m.graph;
        this.broadcast(m);
        return;
      case "data":
        this.onData(m);
        return;
      case "log-open":
        this.onLogOpen(m);
        return;
      case "log-close":
        this.onLogClose(m);
        return;
      case "serial":
        this.serial.receive(m);
        return;
      case "ble":
        this.ble.receive(m);
        return;
    }
  }

  /** The engine's answer to a pending request: to its client (or `request`'s promise), under its id. */
  private onReply(m: Extract<SessionToHub, { type: "reply" }>): void {
    const p = this.pending.get(m.id);
    this.pending.delete(m.id);
    if (!p) return;
    p.done?.();
    if (m.graph !== undefined && m.ok) this.graph = m.graph;
    else if (m.diagnostics !== undefined && !m.ok) this.graph = undefined;
    const reply: Reply = { ...m, id: p.clientId };
    p.resolve?.(reply);
    if (p.client?.open) p.client.sink.send(reply);
    // A pipeline loaded by one client is every client's: the others get the graph too.
    if (m.graph !== undefined && m.ok) {
      for (const c of this.clients)
        if (c !== p.client) c.sink.send({ type: "graph", graph: m.graph });
    }
  }

  /** Panel data: to the open clients watching that output. */
  private onData(m: Extract<SessionToHub, { type: "data" }>): void {
    const holders = this.watchers.get(watchKey(m.block, m.port));
    if (holders) for (const c of holders) if (c.open) c.sink.send(m);
  }

  /** A `Path` log opens: written here, by one LogWriter per base folder. */
  private onLogOpen(m: Extract<SessionToHub, { type: "log-open" }>): void {
    let writer = this.writers.get(m.baseDir);
    if (!writer) {
      writer = new LogWriter(m.baseDir, {
        onError: (file, message) => this.problem(`log ${file}: ${message}`),
      });
      this.writers.set(m.baseDir, writer);
    }
    const key = `log:${m.id}`;
    writer.open(key, m.block, m.port, m.isDefaultPort, m.path, m.shape, m.ring);
    this.logs.set(m.id, { writer, key });
  }

  private onLogClose(m: Extract<SessionToHub, { type: "log-close" }>): void {
    const l = this.logs.get(m.id);
    this.logs.delete(m.id);
    l?.writer.close(l.key);
  }

  /** Sends a request on behalf of the hub itself (not a client) and waits for the reply. */
  request(msg: Request): Promise<Reply> {
    return new Promise((resolve) => {
      const id = this.nextId++;
      this.pending.set(id, { clientId: id, resolve });
      if (msg.type === "load") {
        // The host's own choice (a file named on its command line, opened from its menu): not
        // confined, and its folder is the clients' too from now on.
        this.allowed?.add(this.folderOf(msg.file));
        this.sendLoad(id, { ...msg, id }, null);
        return;
      }
      this.toWorker({ ...msg, id } as HubToSession);
    });
  }

  connect(sink: HubClient): HubConnection {
    const client: Client = { sink, watches: new Set(), open: true, greeted: false };
    this.clients.add(client);
    const replyTo = (id: number, ok: boolean, message?: string): void =>
      sink.send({ type: "reply", id, ok, ...(message !== undefined ? { message } : {}) });
    return {
      receive: (raw) => {
        if (!client.open) return;
        const unsupported = unsupportedHello(raw);
        if (unsupported !== undefined) {
          const hello = this.hello?.type === "hello" ? this.hello : undefined;
          sink.send({
            type: "hello",
            version: PROTOCOL_VERSION,
            versions: PROTOCOL_VERSIONS,
            engine: hello?.engine ?? "node host",
            sharedMemory: hello?.sharedMemory ?? true,
            error: unsupported,
          });
          return;
        }
        const parsed = parseUiMessage(raw);
        if (!parsed.ok) {
          const id = (raw as { id?: unknown } | null)?.id;
          replyTo(typeof id === "number" ? id : -1, false, parsed.error);
          return;
        }
        const msg = parsed.msg;
        if (msg.type === "hello") {
          // The engine said hello once, at start; a client joining now gets it with the state.
          if (this.hello) sink.send(this.hello);
          if (this.graph) sink.send({ type: "graph", graph: this.graph });
          // Always a state, so a client knows whether the engine already has a pipeline.
          sink.send(this.lastState ?? { type: "state", state: "empty" });
          client.greeted = true;
          return;
        }
        if (msg.type === "watch" || msg.type === "unwatch") {
          this.watch(client, msg);
          return;
        }
        this.forward(client, msg);
      },
      close: () => {
        if (!client.open) return;
        client.open = false;
        this.clients.delete(client);
        for (const key of [...client.watches]) this.unwatchFor(client, key);
        for (const p of this.pending.values()) if (p.client === client) p.client = undefined;
      },
    };
  }

  private forward(client: Client, msg: Extract<UiMessage, { id: number }>): void {
    const id = this.nextId++;
    this.pending.set(id, { client, clientId: msg.id });
    if (msg.type === "load" || msg.type === "validate") {
      this.sendLoad(id, msg, this.allowed ? [...this.allowed] : null);
      return;
    }
    if (!this.toWorker({ ...msg, id })) {
      this.pending.delete(id);
      client.sink.send({
        type: "reply",
        id: msg.id,
        ok: false,
        message: "the message cannot be passed to the engine (a value nested too deeply?)",
      });
    }
  }

  private watch(client: Client, msg: Extract<UiMessage, { type: "watch" | "unwatch" }>): void {
    // One key per output: a client may watch several outputs of a block (the participant
    // screen: a Stimulus's phase, cue and progress). No port: the block's first output.
    const port =
      msg.port ?? this.graph?.blocks.find((b) => b.name === msg.block)?.outputs[0]?.name ?? "";
    const key = watchKey(msg.block, port);
    if (msg.type === "watch") {
      const holders = this.watchers.get(key) ?? new Set<Client>();
      const first = holders.size === 0;
      holders.add(client);
      client.watches.add(key);
      this.watchers.set(key, holders);
      if (first) this.forward(client, msg);
      else client.sink.send({ type: "reply", id: msg.id, ok: true });
      return;
    }
    const last = this.unwatchFor(client, key, msg.id);
    if (!last) client.sink.send({ type: "reply", id: msg.id, ok: true });
  }

  /** Drops one client's watch; unwatches in the engine when it was the last. */
  private unwatchFor(client: Client, key: string, replyId?: number): boolean {
    const holders = this.watchers.get(key);
    client.watches.delete(key);
    if (!holders || !holders.delete(client)) return false;
    if (holders.size > 0) return false;
    this.watchers.delete(key);
    const [block, port] = key.split("\u0000") as [string, string];
    const output = port !== "" ? { port } : {};
    if (replyId !== undefined && client.open) {
      this.forward(client, { type: "unwatch", id: replyId, block, ...output });
    } else {
      const id = this.nextId++;
      this.pending.set(id, { clientId: id });
      this.toWorker({ type: "unwatch", id, block, ...output });
    }
    return true;
  }

  /** Stops the pipeline, closes the logs and ends the worker. */
  async close(): Promise<void> {
    if (this.exited || this.closing) return;
    this.closing = true;
    await Promise.race([this.request({ type: "stop" }), new Promise((r) => setTimeout(r, 2000))]);
    for (const w of this.writers.values()) w.closeAll();
    const serialClosed = this.serial.closeAll();
    this.ble.closeAll();
    this.exited = true;
    await this.worker.terminate();
    await serialClosed;
  }
}
