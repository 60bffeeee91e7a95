/**
 * The UI's handle on an engine (any transport): request/reply with promises, the latest
 * telemetry, and panel data streams shared between the panels that watch the same output.
 * Framework-free; React components use it through the hooks in ./hooks.ts.
 */
import type {
  BlockParamsInfo,
  CatalogInfo,
  DataMessage,
  EngineConnection,
  EngineMessage,
  EngineState,
  GraphInfo,
  RecordingFormatName,
  RecordingStatus,
  UiMessage,
} from "../../engine/protocol";
import type { LocalFolder } from "../../engine/protocol-folder";
import type { Diagnostic } from "../../engine/diagnostics";
import type { RuntimeEvent, Telemetry } from "../../engine/runtime/runtime";

type Request = UiMessage extends infer M
  ? M extends { id: number }
    ? Omit<M, "id">
    : never
  : never;

export interface Reply {
  ok: boolean;
  message?: string;
  diagnostics?: Diagnostic[];
  graph?: GraphInfo;
  catalog?: CatalogInfo;
}

export type DataListener = (m: DataMessage) => void;

/** A file the engine hands the page to save (browser build: recordings, saved models). */
export interface DownloadFile {
  name: string;
  mime: string;
  bytes: Uint8Array;
}

export class EngineClient {
  private nextId = 1;
  private readonly pending = new Map<number, (r: Reply) => void>();
  private readonly telemetryListeners = new Set<(t: Telemetry) => void>();
  private readonly eventListeners = new Set<(e: RuntimeEvent) => void>();
  private readonly stateListeners = new Set<(s: EngineState) => void>();
  private readonly dataListeners = new Map<string, Set<DataListener>>();
  private readonly helloListeners = new Set<() => void>();
  private readonly graphListeners = new Set<(g: GraphInfo | undefined) => void>();
  private readonly remoteGraphListeners = new Set<(g: GraphInfo) => void>();
  private readonly recordingListeners = new Set<(r: RecordingStatus) => void>();
  private readonly downloadListeners = new Set<(d: DownloadFile) => void>();
  private readonly paramsListeners = new Set<
    (blocks: BlockParamsInfo[], source?: string) => void
  >();
  private readonly off: () => void;
  telemetry: Telemetry | undefined;
  state: EngineState = "empty";
  graph: GraphInfo | undefined;
  /** The latest session recording's status (Record button), if any. */
  recording: RecordingStatus | undefined;
  engineName = "";
  sharedMemory = false;
  /** True once the engine answered `hello`. */
  connected = false;
  /** Pipelines opened from this computer (in-page engine): the files of their folders. */
  private readonly localFolders = new Map<string, LocalFolder>();

  /**
   * `file` came from this computer with the files of its folder (empty: the browser did not say
   * which): its loads and checks carry them, so the engine reads what the file names next to it.
   */
  openedLocally(file: string, folder: LocalFolder): void {
    this.localFolders.set(file, folder);
  }

  constructor(readonly connection: EngineConnection) {
    this.off = connection.onMessage((m) => this.receive(m));
    connection.send({ type: "hello", version: 1 });
  }

  private receive(m: EngineMessage): void {
    switch (m.type) {
      case "hello":
        this.engineName = m.engine;
        this.sharedMemory = m.sharedMemory;
        this.connected = true;
        for (const l of this.helloListeners) l();
        break;
      case "reply": {
        const r = this.pending.get(m.id);
        this.pending.delete(m.id);
        r?.(m);
        break;
      }
      case "state":
        this.state = m.state;
        for (const l of this.stateListeners) l(m.state);
        break;
      case "telemetry":
        this.telemetry = m.telemetry;
        for (const l of this.telemetryListeners) l(m.telemetry);
        break;
      case "event":
        for (const l of this.eventListeners) l(m.event);
        break;
      case "data":
        for (const l of this.dataListeners.get(`${m.block}.${m.port}`) ?? []) l(m);
        break;
      case "graph":
        // A pipeline this client did not load (a shared engine: another tab, the desktop menu).
        this.graph = m.graph;
        for (const l of this.graphListeners) l(this.graph);
        for (const l of this.remoteGraphListeners) l(m.graph);
        break;
      case "recording":
        this.recording = m.recording;
        for (const l of this.recordingListeners) l(m.recording);
        break;
      case "download":
        for (const l of this.downloadListeners) l(m);
        break;
      case "params":
        this.applyParams(m.blocks, m.source);
        break;
    }
  }

  /** Sends a request and resolves with the engine's reply (never rejects). */
  request(msg: Request): Promise<Reply> {
    const id = this.nextId++;
    return new Promise((resolve) => {
      this.pending.set(id, resolve);
      const folder =
        msg.type === "load" || msg.type === "validate"
          ? this.localFolders.get(msg.file)
          : undefined;
      this.connection.send({ ...msg, ...(folder ? { folder } : {}), id } as UiMessage);
    });
  }

  /** Loads a pipeline; `simulateDevices` replaces its device blocks by simulators. */
  async load(file: string, source: string, simulateDevices = false): Promise<Reply> {
    const r = await this.request({
      type: "load",
      file,
      source,
      ...(simulateDevices ? { simulateDevices: true } : {}),
    });
    this.graph = r.graph;
    for (const l of this.graphListeners) l(this.graph);
    return r;
  }

  private catalogPromise: Promise<CatalogInfo | undefined> | undefined;

  /** Every block type the engine knows, with its metadata (asked once, then cached). */
  catalog(): Promise<CatalogInfo | undefined> {
    this.catalogPromise ??= this.request({ type: "catalog" }).then((r) => {
      if (!r.ok) this.catalogPromise = undefined;
      return r.catalog;
    });
    return this.catalogPromise;
  }

  start(): Promise<Reply> {
    return this.request({ type: "start" });
  }

  stop(): Promise<Reply> {
    return this.request({ type: "stop" });
  }

  /**
   * Sets a live param. The engine answers every client with the block's params (a `params`
   * message, before this reply): `graph` then holds the engine's values.
   */
  setParam(block: string, param: string, value: unknown): Promise<Reply> {
    return this.request({ type: "setParam", block, param, value });
  }

  /**
   * Tells the engine that the pipeline's text is now `source`, with these live values written
   * into it: their "changed since loaded" markers clear in every client.
   */
  paramsWritten(
    source: string,
    values: { block: string; param: string; value: unknown }[],
  ): Promise<Reply> {
    return this.request({ type: "params-written", source, values });
  }

  /**
   * The engine's live params changed (any client) or were written to the file: `graph`'s blocks
   * get the new values (new objects, so that React sees them), then the listeners are told.
   */
  private applyParams(blocks: BlockParamsInfo[], source: string | undefined): void {
    const g = this.graph;
    if (g) {
      const by = new Map(blocks.map((b) => [b.name, b]));
      g.blocks = g.blocks.map((b) => {
        const p = by.get(b.name);
        return p ? { ...b, params: p.params, fileParams: p.fileParams } : b;
      });
      if (source !== undefined) g.source = source;
    }
    for (const l of this.paramsListeners) l(blocks, source);
  }

  /** Live params changed or were written back (see applyParams); `graph` is up to date then. */
  onParams(l: (blocks: BlockParamsInfo[], source?: string) => void): () => void {
    this.paramsListeners.add(l);
    return () => this.paramsListeners.delete(l);
  }

  invoke(block: string, action: string, arg?: unknown): Promise<Reply> {
    return this.request({ type: "invoke", block, action, ...(arg !== undefined ? { arg } : {}) });
  }

  /** Records block outputs (default port when `port` is omitted) into one file. */
  recordStart(
    outputs: { block: string; port?: string }[],
    format: RecordingFormatName,
    file?: string,
  ): Promise<Reply> {
    return this.request({
      type: "record-start",
      outputs,
      format,
      ...(file !== undefined ? { file } : {}),
    });
  }

  recordStop(): Promise<Reply> {
    return this.request({ type: "record-stop" });
  }

  /** The session recording's status: while it runs (~4 Hz) and when it ends. */
  onRecording(l: (r: RecordingStatus) => void): () => void {
    this.recordingListeners.add(l);
    return () => this.recordingListeners.delete(l);
  }

  /** A file to save (the browser build's engine cannot write files). */
  onDownload(l: (d: DownloadFile) => void): () => void {
    this.downloadListeners.add(l);
    return () => this.downloadListeners.delete(l);
  }

  onTelemetry(l: (t: Telemetry) => void): () => void {
    this.telemetryListeners.add(l);
    return () => this.telemetryListeners.delete(l);
  }

  onEvent(l: (e: RuntimeEvent) => void): () => void {
    this.eventListeners.add(l);
    return () => this.eventListeners.delete(l);
  }

  /** Called when the engine answers `hello` (engine name, shared memory). */
  onHello(l: () => void): () => void {
    this.helloListeners.add(l);
    return () => this.helloListeners.delete(l);
  }

  /** Called after every `load` with the new graph (undefined when the pipeline has errors). */
  onGraph(l: (g: GraphInfo | undefined) => void): () => void {
    this.graphListeners.add(l);
    return () => this.graphListeners.delete(l);
  }

  /** Called when the engine announces a pipeline that this client did not load itself. */
  onRemoteGraph(l: (g: GraphInfo) => void): () => void {
    this.remoteGraphListeners.add(l);
    return () => this.remoteGraphListeners.delete(l);
  }

  onState(l: (s: EngineState) => void): () => void {
    this.stateListeners.add(l);
    return () => this.stateListeners.delete(l);
  }

  /**
   * Streams a block output's data (panel open). Several listeners share one engine watch; the
   * engine stops sending when the last one leaves. Returns the unsubscribe function.
   */
  watch(block: string, port: string | undefined, l: DataListener, maxRate = 500): () => void {
    const key = `${block}.${port ?? this.defaultPort(block)}`;
    let set = this.dataListeners.get(key);
    if (!set) {
      set = new Set();
      this.dataListeners.set(key, set);
      void this.request({ type: "watch", block, ...(port !== undefined ? { port } : {}), maxRate });
    }
    set.add(l);
    return () => {
      const s = this.dataListeners.get(key);
      if (!s) return;
      s.delete(l);
      if (s.size === 0) {
        this.dataListeners.delete(key);
        void this.request({ type: "unwatch", block, ...(port !== undefined ? { port } : {}) });
      }
    };
  }

  private defaultPort(block: string): string {
    return this.graph?.blocks.find((b) => b.name === block)?.outputs[0]?.name ?? "out";
  }

  close(): void {
    this.off();
    this.connection.close();
  }
}
