/**
 * The Python sidecar bridge for Node hosts (`ctx.io.python`). Every Python block gets its own
 * process (`python -m mosaic_sidecar` with the interpreter of the uv environment of
 * native-bridges/python, found once per host process with `python3 -m uv run --frozen …`, never
 * downloading an interpreter, and then started directly, so that signals reach it and it is the
 * host's own child), so one slow or crashing block never stalls another, and the engine never
 * waits on any of them: `call` writes one framed message to the process's stdin and returns; the
 * result arrives on the worker's event loop. A process that dies (a crash, `kill -9`, an
 * out-of-memory kill) is reported and started again with backoff (0.5 s doubling to 10 s), its
 * module loaded again with a fresh state; so is one whose call passes the hard limit
 * (`hardLimitMs`: it is killed first). The process runs niced (`nice`, default +10) with its data
 * memory limited (`memoryLimitMb`), and never outlives the host: it ends itself when its stdin's
 * write end closes (the host stopped it, or died), and on Linux the kernel kills it with its
 * parent (PR_SET_PDEATHSIG; see mosaic_sidecar/server.py). The wire format is in docs/protocols.md
 * ("Python sidecar") and native-bridges/python/mosaic_sidecar/protocol.py.
 *
 * `MOSAIC_PYTHON=/path/to/python` runs that interpreter instead of the uv environment (it needs
 * NumPy, and whatever the user's modules import).
 */
import { execFile, spawn, type ChildProcess } from "node:child_process";
import { existsSync } from "node:fs";
import { delimiter, dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import type {
  PythonBridge,
  PythonCallError,
  PythonLoadOptions,
  PythonSidecar,
} from "../app/engine/io";

export const MAGIC = 0x5950534d;
export const VERSION = 1;
export const HEADER_SIZE = 16;
export const MSG = {
  hello: 1,
  load: 2,
  ok: 3,
  error: 4,
  call: 5,
  result: 6,
  reset: 7,
  shutdown: 8,
} as const;
const MAX_PAYLOAD = 1 << 30;
/** How much lower than the host's the sidecar's scheduling priority is (a nice increment). */
export const SIDECAR_NICE = 10;
/** The sidecar's exit status after running out of memory outside the user's function. */
const EXIT_OUT_OF_MEMORY = 3;

/** A load failure; `kind` says which param is at fault (missing-module, syntax, shape, …). */
export class PythonLoadError extends Error {
  constructor(
    message: string,
    readonly kind: string,
    readonly traceback = "",
  ) {
    super(message);
    this.name = "PythonLoadError";
  }
}

// ---------------------------------------------------------------------------------------------
// Framing (little-endian; every supported host is)

export function encodeMessage(type: number, id: number, payload?: Uint8Array): Buffer {
  const len = payload?.byteLength ?? 0;
  const b = Buffer.allocUnsafe(HEADER_SIZE + len);
  b.writeUInt32LE(MAGIC, 0);
  b.writeUInt16LE(VERSION, 4);
  b.writeUInt16LE(type, 6);
  b.writeUInt32LE(id >>> 0, 8);
  b.writeUInt32LE(len, 12);
  if (payload) b.set(payload, HEADER_SIZE);
  return b;
}

const arrayPrefix = (ndim: number): number => (4 + 4 * ndim + 7) & ~7;

/** A `call` message: the header, then `values` as an f64 array of shape [rows, cols]. */
export function encodeCall(id: number, values: Float64Array, rows: number, cols: number): Buffer {
  const pre = arrayPrefix(2);
  const len = pre + values.byteLength;
  const b = Buffer.alloc(HEADER_SIZE + len);
  b.writeUInt32LE(MAGIC, 0);
  b.writeUInt16LE(VERSION, 4);
  b.writeUInt16LE(MSG.call, 6);
  b.writeUInt32LE(id >>> 0, 8);
  b.writeUInt32LE(len, 12);
  b.writeUInt8(1, 16); // f64
  b.writeUInt8(2, 17); // ndim
  b.writeUInt32LE(rows, 20);
  b.writeUInt32LE(cols, 24);
  b.set(new Uint8Array(values.buffer, values.byteOffset, values.byteLength), HEADER_SIZE + pre);
  return b;
}

/**
 * Decodes the array at `offset` of `payload` into `out` (bit for bit for f64); returns the number
 * of values, or a string saying what is wrong.
 */
export function decodeArrayInto(
  payload: Buffer,
  offset: number,
  out: Float64Array,
): number | string {
  if (payload.length - offset < 4) return "array header truncated";
  const dtype = payload.readUInt8(offset);
  const ndim = payload.readUInt8(offset + 1);
  const pre = arrayPrefix(ndim);
  if (payload.length - offset < pre) return "array shape truncated";
  let count = 1;
  for (let i = 0; i < ndim; i++) count *= payload.readUInt32LE(offset + 4 + 4 * i);
  const size = dtype === 1 ? 8 : dtype === 2 ? 4 : 0;
  if (size === 0) return `unknown dtype code ${dtype}`;
  const start = offset + pre;
  if (payload.length - start !== count * size) return "array length does not match its shape";
  if (count !== out.length) return `${count} values, expected ${out.length}`;
  if (size === 8) {
    new Uint8Array(out.buffer, out.byteOffset, out.byteLength).set(
      payload.subarray(start, start + count * 8),
    );
  } else {
    for (let i = 0; i < count; i++) out[i] = payload.readFloatLE(start + 4 * i);
  }
  return count;
}

/** Splits a byte stream into messages. */
export class MessageReader {
  private buf: Buffer = Buffer.alloc(0);

  constructor(private readonly onMessage: (type: number, id: number, payload: Buffer) => void) {}

  /** Feeds bytes; returns an error text when the stream is corrupt (then stop reading). */
  push(chunk: Buffer): string | undefined {
    this.buf = this.buf.length === 0 ? chunk : Buffer.concat([this.buf, chunk]);
    for (;;) {
      const b = this.buf;
      if (b.length < HEADER_SIZE) return undefined;
      if (b.readUInt32LE(0) !== MAGIC) {
        return `bad magic in the sidecar's output (${JSON.stringify(b.subarray(0, 16).toString("latin1"))}…)`;
      }
      if (b.readUInt16LE(4) !== VERSION) return `sidecar speaks protocol ${b.readUInt16LE(4)}`;
      const len = b.readUInt32LE(12);
      if (len > MAX_PAYLOAD) return `message of ${len} bytes`;
      if (b.length < HEADER_SIZE + len) return undefined;
      const payload = b.subarray(HEADER_SIZE, HEADER_SIZE + len);
      this.buf = b.subarray(HEADER_SIZE + len);
      this.onMessage(b.readUInt16LE(6), b.readUInt32LE(8), payload);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Processes

export interface SidecarCommand {
  file: string;
  args: string[];
  env: Record<string, string>;
}

export interface PythonBridgeOptions {
  /** The repository root (holds native-bridges/python); found from this file by default. */
  root?: string;
  /** How to start a sidecar (tests); default: the interpreter of native-bridges/python's uv environment. */
  command?: (cwd: string) => SidecarCommand | Promise<SidecarCommand>;
  /** The sidecar's nice increment over the host (default SIDECAR_NICE; 0 keeps the host's). */
  nice?: number;
  /** First restart delay and its cap (ms). */
  backoffMs?: { first: number; max: number };
  /** How long a start (hello + load, imports included) may take. */
  loadTimeoutMs?: number;
}

function repoRoot(): string {
  let d = dirname(fileURLToPath(import.meta.url));
  for (let i = 0; i < 6; i++) {
    if (existsSync(join(d, "native-bridges", "python", "pyproject.toml"))) return d;
    d = dirname(d);
  }
  return process.cwd();
}

const uvRun = (project: string): string[] => [
  "-m",
  "uv",
  "run",
  "--quiet",
  "--frozen",
  "--project",
  project,
  "--python",
  "python3.11",
  "python",
];

/** The uv environment's interpreter, per project, found once per host process. */
const interpreters = new Map<string, Promise<string | undefined>>();

/**
 * The interpreter of `project`'s uv environment (`uv run` syncs it if needed, never downloading
 * Python); undefined when uv cannot run it (then the sidecar is started through `uv run` and its
 * failure says why).
 */
function uvInterpreter(project: string): Promise<string | undefined> {
  let found = interpreters.get(project);
  if (!found) {
    found = new Promise((resolve) => {
      execFile(
        process.env.MOSAIC_PYTHON3 ?? "python3",
        [...uvRun(project), "-c", "import sys; print(sys.executable)"],
        { env: { ...process.env, UV_PYTHON_DOWNLOADS: "never" }, timeout: 120_000 },
        (err, stdout) => {
          const exe = String(stdout).trim().split("\n").at(-1);
          const ok = !err && exe !== undefined && exe !== "" && existsSync(exe);
          if (!ok) interpreters.delete(project);
          resolve(ok ? exe : undefined);
        },
      );
    });
    interpreters.set(project, found);
  }
  return found;
}

/**
 * The default command: the interpreter of native-bridges/python's uv environment (or
 * `MOSAIC_PYTHON`), started directly so that the sidecar is the host's own child (signals reach
 * it; the kernel kills it with its parent); `uv run` itself when that interpreter cannot be found.
 */
export function defaultCommand(root: string): (cwd: string) => Promise<SidecarCommand> {
  const project = join(root, "native-bridges", "python");
  return async (cwd) => {
    const pythonPath = [project, cwd, process.env.PYTHONPATH].filter(Boolean).join(delimiter);
    const env = {
      PYTHONPATH: pythonPath,
      PYTHONUNBUFFERED: "1",
      UV_PYTHON_DOWNLOADS: "never",
      MOSAIC_PARENT_PID: String(process.pid),
    };
    const own = process.env.MOSAIC_PYTHON ?? (await uvInterpreter(project));
    if (own) return { file: own, args: ["-m", "mosaic_sidecar"], env };
    return {
      file: process.env.MOSAIC_PYTHON3 ?? "python3",
      args: [...uvRun(project), "-m", "mosaic_sidecar"],
      env,
    };
  };
}

interface Control {
  resolve: (payload: Buffer, type: number) => void;
}

/** One process: spawn, framed messages, control requests as promises. */
class Proc {
  readonly child: ChildProcess;
  private readonly reader: MessageReader;
  private readonly control = new Map<number, Control>();
  private stderrTail: string[] = [];
  private partialLine = "";
  exited = false;
  exitReason = "";
  /** Why the host killed it (the hard limit), said before the exit reason. */
  cause = "";
  pid: number | undefined;

  constructor(
    cmd: SidecarCommand,
    cwd: string,
    private readonly onCall: (type: number, id: number, payload: Buffer) => void,
    private readonly onLine: (line: string) => void,
    private readonly onExit: (reason: string) => void,
  ) {
    this.reader = new MessageReader((type, id, payload) => {
      const c = this.control.get(id);
      if (c) {
        this.control.delete(id);
        c.resolve(payload, type);
      } else {
        this.onCall(type, id, payload);
      }
    });
    this.child = spawn(cmd.file, cmd.args, {
      cwd,
      env: { ...process.env, ...cmd.env },
      stdio: ["pipe", "pipe", "pipe"],
    });
    this.child.stdout!.on("data", (d: Buffer) => {
      const problem = this.reader.push(d);
      if (problem) {
        this.exitReason = `protocol error: ${problem}`;
        this.kill();
      }
    });
    this.child.stderr!.on("data", (d: Buffer) => {
      const text = this.partialLine + d.toString("utf8");
      const lines = text.split(/\r?\n/);
      this.partialLine = lines.pop() ?? "";
      for (const l of lines) {
        if (l.trim() === "") continue;
        this.stderrTail.push(l);
        if (this.stderrTail.length > 40) this.stderrTail.shift();
        this.onLine(l);
      }
    });
    this.child.stdin!.on("error", () => {}); // EPIPE after a crash: the exit event reports it
    this.child.on("error", (e) => this.finish(`cannot start ${cmd.file}: ${e.message}`));
    this.child.on("exit", (code, signal) =>
      this.finish(
        signal
          ? `killed by ${signal}`
          : code === EXIT_OUT_OF_MEMORY
            ? `ran out of memory (exit code ${code}): ${this.stderr(1).replace(/^mosaic_sidecar: out of memory; /, "")}`
            : `exited with code ${code}`,
      ),
    );
  }

  private finish(reason: string): void {
    if (this.exited) return;
    this.exited = true;
    if (!this.exitReason) this.exitReason = reason;
    for (const c of this.control.values()) c.resolve(Buffer.alloc(0), -1);
    this.control.clear();
    this.onExit(this.exitReason);
  }

  stderr(lines = 12): string {
    const tail = this.partialLine ? [...this.stderrTail, this.partialLine] : this.stderrTail;
    return tail.slice(-lines).join("\n");
  }

  write(b: Buffer): void {
    if (!this.exited) this.child.stdin!.write(b);
  }

  request(type: number, id: number, json?: unknown): Promise<{ type: number; payload: Buffer }> {
    return new Promise((resolve) => {
      this.control.set(id, { resolve: (payload, t) => resolve({ type: t, payload }) });
      this.write(
        encodeMessage(type, id, json === undefined ? undefined : Buffer.from(JSON.stringify(json))),
      );
    });
  }

  /** Asks the process to stop: shutdown, end of input, then signals if it lingers. */
  stop(): void {
    if (this.exited) return;
    try {
      this.child.stdin!.write(encodeMessage(MSG.shutdown, 0));
      this.child.stdin!.end();
    } catch {
      // already gone
    }
    const term = setTimeout(() => {
      if (!this.exited) this.child.kill("SIGTERM");
    }, 2000);
    const kill = setTimeout(() => {
      if (!this.exited) this.kill();
    }, 5000);
    term.unref();
    kill.unref();
  }

  kill(): void {
    if (this.exited) return;
    // With `uv run` (or another launcher) between us, the interpreter is another process.
    if (this.pid !== undefined && this.pid !== this.child.pid) {
      try {
        process.kill(this.pid, "SIGKILL");
      } catch {
        // gone
      }
    }
    try {
      this.child.kill("SIGKILL");
    } catch {
      // gone
    }
    this.child.stdin?.destroy();
  }
}

function parseJson(b: Buffer): Record<string, unknown> {
  try {
    return JSON.parse(b.toString("utf8")) as Record<string, unknown>;
  } catch {
    return { message: b.toString("utf8") };
  }
}

const formatS = (ms: number): string => `${ms % 1000 === 0 ? ms / 1000 : (ms / 1000).toFixed(1)} s`;

export function createPythonBridge(options: PythonBridgeOptions = {}): PythonBridge {
  const root = options.root ?? repoRoot();
  const settings: SidecarSettings = {
    command: options.command ?? defaultCommand(root),
    backoff: options.backoffMs ?? { first: 500, max: 10_000 },
    loadTimeoutMs: options.loadTimeoutMs ?? 120_000,
    nice: options.nice ?? SIDECAR_NICE,
  };
  return { load: (o) => Sidecar.start(o, settings) };
}

/** How the bridge starts and restarts sidecars (`PythonBridgeOptions` with their defaults). */
interface SidecarSettings {
  command: (cwd: string) => SidecarCommand | Promise<SidecarCommand>;
  backoff: { first: number; max: number };
  loadTimeoutMs: number;
  nice: number;
}

/**
 * One Python block's sidecar: its current process, the calls in flight, the watchdog for slow
 * and hung calls, and restarts with backoff after the process dies.
 */
class Sidecar implements PythonSidecar {
  private readonly cwd: string;
  private nextId = 1;
  private proc: Proc | undefined;
  /** A process is loaded and accepting calls. */
  private loaded = false;
  private closed = false;
  private versionText = "";
  private shape = { rows: 1, cols: 1 };
  private out = new Float64Array(1);
  /** Calls sent to the current process and not answered yet, oldest first. */
  private readonly inFlight: number[] = [];
  /** Since when the oldest call in flight is the one the process works on (ms). */
  private headSince = 0;
  private delay: number;
  private readySince = 0;
  private retry: ReturnType<typeof setTimeout> | undefined;
  private readonly hardLimitMs: number;
  private readonly lateAfterMs: number;
  /** The call that passed the hard limit (its process is being killed). */
  private timedOut = -1;
  /**
   * One entry per `reset` not answered yet: how many calls in flight are still ahead of it.
   * `init` may take long (training); the calls behind it wait and their time does not run.
   */
  private readonly resets: number[] = [];
  private watchdog: ReturnType<typeof setInterval> | undefined;

  /** Starts the first process and loads the module; rejects with a PythonLoadError. */
  static async start(o: PythonLoadOptions, settings: SidecarSettings): Promise<PythonSidecar> {
    const sidecar = new Sidecar(o, settings);
    await sidecar.launch();
    sidecar.markReady();
    sidecar.startWatchdog();
    o.onStatus("ready");
    return sidecar;
  }

  private constructor(
    private readonly o: PythonLoadOptions,
    private readonly settings: SidecarSettings,
  ) {
    this.cwd = o.cwd ?? process.cwd();
    this.delay = settings.backoff.first;
    this.hardLimitMs = o.hardLimitMs !== undefined && o.hardLimitMs > 0 ? o.hardLimitMs : Infinity;
    this.lateAfterMs =
      o.onLate && o.lateAfterMs !== undefined && o.lateAfterMs >= 0 ? o.lateAfterMs : Infinity;
  }

  get outputShape(): { rows: number; cols: number } {
    return this.shape;
  }

  get pid(): number | undefined {
    return this.proc?.pid;
  }

  get version(): string {
    return this.versionText;
  }

  get ready(): boolean {
    return this.loaded && !this.closed;
  }

  call(values: Float64Array): number {
    const p = this.proc;
    if (!this.loaded || this.closed || !p) return -1;
    const callId = this.newId();
    if (this.inFlight.length === 0) this.headSince = performance.now();
    this.inFlight.push(callId);
    p.write(encodeCall(callId, values, this.o.inputShape.rows, this.o.inputShape.cols));
    return callId;
  }

  reset(): void {
    const p = this.proc;
    if (!this.loaded || this.closed || !p) return;
    this.resets.push(this.inFlight.length);
    void p.request(MSG.reset, this.newId()).then(({ type, payload }) => {
      this.resetAnswered(p, type, payload);
    });
  }

  close(): void {
    if (this.closed) return;
    this.closed = true;
    this.loaded = false;
    if (this.retry) clearTimeout(this.retry);
    this.retry = undefined;
    if (this.watchdog) clearInterval(this.watchdog);
    this.watchdog = undefined;
    const p = this.proc;
    this.proc = undefined;
    p?.stop();
    this.o.onStatus("closed");
  }

  private newId(): number {
    const i = this.nextId;
    this.nextId = this.nextId >= 0xfffffff0 ? 1 : this.nextId + 1;
    return i;
  }

  private markReady(): void {
    this.loaded = true;
    this.readySince = performance.now();
  }

  // --- Launching ------------------------------------------------------------------------------

  /** Starts a process and loads the module; resolves when ready, rejects with a PythonLoadError. */
  private async launch(): Promise<void> {
    const cmd = await this.settings.command(this.cwd);
    const p = this.spawn(cmd);
    this.proc = p;
    let timer: ReturnType<typeof setTimeout> | undefined;
    const timeout = new Promise<never>((_, reject) => {
      timer = setTimeout(() => reject(this.loadTimedOut()), this.settings.loadTimeoutMs);
    });
    try {
      await Promise.race([this.handshake(p), timeout]);
    } catch (e) {
      if (this.proc === p) this.proc = undefined;
      p.stop();
      throw e;
    } finally {
      clearTimeout(timer);
    }
  }

  /** A process whose messages, output and exit count only while it is the current one. */
  private spawn(cmd: SidecarCommand): Proc {
    const p: Proc = new Proc(
      cmd,
      this.cwd,
      (type, callId, payload) => {
        if (p === this.proc) this.answered(type, callId, payload);
      },
      (line) => {
        if (p === this.proc && !this.closed) this.o.onOutput?.(line);
      },
      (reason) => {
        // While loading, `launch` itself fails (and its caller decides); once ready, a restart.
        if (p === this.proc && this.loaded) this.crashed(reason);
      },
    );
    return p;
  }

  private loadTimedOut(): PythonLoadError {
    return new PythonLoadError(
      `the Python sidecar did not load ${this.o.module} within ${formatS(this.settings.loadTimeoutMs)}`,
      "start",
    );
  }

  /** `hello`, then `load` with the block's module and params; adopts the output shape. */
  private async handshake(p: Proc): Promise<void> {
    const h = await p.request(MSG.hello, this.newId());
    if (h.type !== MSG.hello) throw startFailed(p, "did not start");
    const info = parseJson(h.payload);
    this.versionText = `Python ${String(info.python)}, NumPy ${String(info.numpy)}`;
    p.pid = typeof info.pid === "number" ? info.pid : p.child.pid;
    const l = await p.request(MSG.load, this.newId(), this.loadRequest());
    if (l.type === MSG.error) {
      const e = parseJson(l.payload);
      throw new PythonLoadError(
        String(e.message ?? "load failed"),
        String(e.kind ?? "load"),
        String(e.traceback ?? ""),
      );
    }
    if (l.type !== MSG.ok) throw startFailed(p, "stopped while loading");
    this.adoptOutputShape(parseJson(l.payload).output_shape as [number, number]);
  }

  private loadRequest(): Record<string, unknown> {
    const o = this.o;
    return {
      module: o.module,
      function: o.function,
      init: o.init ?? null,
      params: o.params,
      input_shape: [o.inputShape.rows, o.inputShape.cols],
      output_shape: o.outputShape ? [o.outputShape.rows, o.outputShape.cols] : null,
      cwd: this.cwd,
      nice: this.settings.nice,
      memory_limit_mb: o.memoryLimitMb ?? 0,
    };
  }

  private adoptOutputShape(shape: [number, number]): void {
    this.shape = { rows: shape[0], cols: shape[1] };
    const size = shape[0] * shape[1];
    if (this.out.length !== size) this.out = new Float64Array(size);
  }

  // --- Calls ----------------------------------------------------------------------------------

  /** A result or error for a call of the current process. */
  private answered(type: number, callId: number, payload: Buffer): void {
    this.settle(callId);
    if (this.closed) return;
    if (type === MSG.result) this.deliverResult(callId, payload);
    else if (type === MSG.error) this.deliverError(callId, payload);
  }

  /** Removes an answered call from the calls in flight (the next one starts its time). */
  private settle(callId: number): void {
    const k = this.inFlight.indexOf(callId);
    if (k < 0) return;
    this.inFlight.splice(k, 1);
    if (k === 0) this.headSince = performance.now();
    for (let i = 0; i < this.resets.length; i++) if (this.resets[i]! > 0) this.resets[i]!--;
  }

  private deliverResult(callId: number, payload: Buffer): void {
    const us = payload.length >= 8 ? payload.readDoubleLE(0) : NaN;
    const n = decodeArrayInto(payload, 8, this.out);
    if (typeof n === "string") {
      this.o.onError(callId, {
        message: `bad result from the sidecar: ${n}`,
        traceback: "",
        kind: "protocol",
      });
    } else {
      this.o.onResult(callId, this.out, us);
    }
  }

  private deliverError(callId: number, payload: Buffer): void {
    const e = parseJson(payload);
    const err: PythonCallError = {
      message: String(e.message ?? "error"),
      traceback: String(e.traceback ?? ""),
      kind: String(e.kind ?? "call"),
    };
    this.o.onError(callId, err);
  }

  /** The answer to a `reset`: the calls that waited for `init` start their time now. */
  private resetAnswered(p: Proc, type: number, payload: Buffer): void {
    if (this.proc === p && this.resets.length > 0) {
      this.resets.shift();
      if (this.inFlight.length > 0) this.headSince = performance.now();
    }
    if (type === MSG.error && !this.closed) {
      const e = parseJson(payload);
      this.o.onError(0, {
        message: `init raised on reset: ${String(e.message)}`,
        traceback: String(e.traceback ?? ""),
        kind: "init",
      });
    }
  }

  // --- Watchdog -------------------------------------------------------------------------------

  private startWatchdog(): void {
    const { hardLimitMs, lateAfterMs } = this;
    if (hardLimitMs === Infinity && lateAfterMs === Infinity) return;
    const every = Math.min(lateAfterMs < Infinity ? 50 : 250, Math.max(10, hardLimitMs / 8));
    this.watchdog = setInterval(() => this.watchCalls(), every);
    this.watchdog.unref?.();
  }

  /**
   * The oldest call in flight: reported while it runs past `lateAfterMs`; past the hard limit
   * the process is killed (and restarted by `crashed`).
   */
  private watchCalls(): void {
    const p = this.proc;
    if (!p || !this.loaded || this.closed || this.inFlight.length === 0 || p.cause) return;
    if (this.resets.length > 0 && this.resets[0] === 0) return; // the oldest call waits behind a reset
    const running = performance.now() - this.headSince;
    if (running > this.lateAfterMs) this.o.onLate?.(this.inFlight[0]!, running);
    if (running <= this.hardLimitMs || this.closed || this.proc !== p) return;
    this.timedOut = this.inFlight[0]!;
    p.cause = `a call ran longer than its hard limit of ${formatS(this.hardLimitMs)} (HardLimit)`;
    p.kill();
  }

  // --- Crashes and restarts -------------------------------------------------------------------

  /** The current process died: its calls fail, the status says why, a restart is scheduled. */
  private crashed(reason: string): void {
    const p = this.proc;
    this.proc = undefined;
    const wasReady = this.loaded;
    this.loaded = false;
    if (this.closed) return;
    this.failCallsInFlight(p, reason);
    this.timedOut = -1;
    this.resets.length = 0;
    const backoff = this.settings.backoff;
    if (wasReady && performance.now() - this.readySince > backoff.max) this.delay = backoff.first;
    const pid = `the Python process (pid ${p?.pid ?? "?"})`;
    const cause = p?.cause ?? "";
    this.o.onStatus(
      "restarting",
      `${cause ? `${cause}: ${pid} was killed` : `${pid} ${reason}`}; restarting in ${formatS(this.delay)}`,
    );
    this.scheduleRestart();
  }

  /** Every call in flight fails: "timeout" for the one that passed the hard limit, else "crash". */
  private failCallsInFlight(p: Proc | undefined, reason: string): void {
    const lost = this.inFlight.splice(0);
    const tail = p?.stderr(6) ?? "";
    const cause = p?.cause ?? "";
    for (const callId of lost) {
      const hung = cause !== "" && callId === this.timedOut;
      this.o.onError(callId, {
        message: hung
          ? `${cause}: the Python process was killed`
          : `the Python process died (${cause || reason})`,
        traceback: tail,
        kind: hung ? "timeout" : "crash",
      });
    }
  }

  private scheduleRestart(): void {
    if (this.closed || this.retry) return;
    const wait = this.delay;
    this.delay = Math.min(this.delay * 2, this.settings.backoff.max);
    this.retry = setTimeout(() => {
      this.retry = undefined;
      if (!this.closed) this.restart();
    }, wait);
    this.retry.unref?.();
  }

  private restart(): void {
    this.launch().then(
      () => {
        if (this.closed) {
          this.proc?.stop();
          return;
        }
        this.markReady();
        this.o.onStatus("ready", `restarted (pid ${this.proc?.pid ?? "?"})`);
      },
      (e: unknown) => {
        if (this.closed) return;
        this.o.onStatus(
          "restarting",
          `restart failed: ${(e as Error).message.split("\n")[0]}; retrying in ${formatS(this.delay)}`,
        );
        this.scheduleRestart();
      },
    );
  }
}

/** A start that failed: the process's exit reason and its last stderr lines, with a setup hint. */
function startFailed(p: Proc, what: string): PythonLoadError {
  const tail = p.stderr();
  const hint = /No module named uv|uv: not found|ENOENT|No interpreter found|python3\.11/.test(
    `${p.exitReason}\n${tail}`,
  )
    ? " (install uv and the environment with scripts/setup.sh; Python 3.11 must be on the PATH)"
    : "";
  return new PythonLoadError(
    `the Python sidecar ${what}: ${p.exitReason}${tail ? `\n${tail}` : ""}${hint}`,
    "start",
  );
}
