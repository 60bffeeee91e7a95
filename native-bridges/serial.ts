/**
 * The serial bridge for Node hosts (`ctx.io.serial`), on the `serialport` package. The package's
 * native binding is loaded on first use, so a host where it cannot load still starts (the
 * SerialPort block then reports the reason). Ports are kept open: after a failed open or an
 * unplug the bridge reports the error and retries every `reconnectMs`.
 */
import { existsSync, readdirSync } from "node:fs";
import { createRequire } from "node:module";
import type { SerialBridge, SerialHandle } from "../app/engine/io";

/** The part of serialport's `SerialPort` class this bridge uses. */
interface NativePort {
  on(event: "open", fn: () => void): void;
  on(event: "data", fn: (data: Buffer) => void): void;
  on(event: "close", fn: (err: (Error & { disconnected?: boolean }) | null) => void): void;
  on(event: "error", fn: (err: Error) => void): void;
  write(data: Uint8Array, cb?: (err: Error | null | undefined) => void): boolean;
  close(cb?: (err: Error | null) => void): void;
  /** Calls back once the bytes written so far have been handed to the device. */
  drain(cb: (err: Error | null) => void): void;
  readonly isOpen: boolean;
}

/** A port as constructed, before it is opened. */
type OpenablePort = NativePort & { open(cb: (err: Error | null) => void): void };

type PortConstructor = new (options: {
  path: string;
  baudRate: number;
  dataBits: 5 | 6 | 7 | 8;
  stopBits: 1 | 1.5 | 2;
  parity: string;
  autoOpen: boolean;
}) => OpenablePort;

let loaded: { ctor: PortConstructor } | { error: string } | undefined;

function load(): { ctor: PortConstructor } | { error: string } {
  if (!loaded) {
    try {
      const require = createRequire(import.meta.url);
      const mod = require("serialport") as { SerialPort: PortConstructor };
      loaded = { ctor: mod.SerialPort };
    } catch (e) {
      loaded = { error: `the serialport module cannot be loaded: ${(e as Error).message}` };
    }
  }
  return loaded;
}

/** Options of `createSerialBridge` (tests inject a port class). */
export interface SerialBridgeOptions {
  port?: PortConstructor;
}

export function createSerialBridge(options: SerialBridgeOptions = {}): SerialBridge {
  return {
    open(o) {
      return openPort(o, options.port);
    },
    async list() {
      // serialport's list() spawns `udevadm` on Linux and crashes the process where it is
      // missing (containers): list the device nodes ourselves there.
      if (process.platform === "linux") return listLinux();
      const lib = load();
      if ("error" in lib) return [];
      const mod = createRequire(import.meta.url)("serialport") as {
        SerialPort: { list(): Promise<{ path: string; manufacturer?: string }[]> };
      };
      return (await mod.SerialPort.list()).map((p) => ({
        path: p.path,
        manufacturer: p.manufacturer,
      }));
    },
  };
}

function listLinux(): { path: string; manufacturer?: string }[] {
  const byId = "/dev/serial/by-id";
  const names = existsSync(byId) ? readdirSync(byId).map((n) => `${byId}/${n}`) : [];
  for (const n of existsSync("/dev") ? readdirSync("/dev") : []) {
    if (/^tty(USB|ACM|AMA)\d+$/.test(n)) names.push(`/dev/${n}`);
  }
  return names.map((path) => ({ path }));
}

function describe(err: Error & { code?: string }): string {
  const m = err.message.replace(/^Error: /, "");
  if (/ENOENT|No such file/i.test(m)) return "no such device (unplugged?)";
  if (/EACCES|Permission denied/i.test(m))
    return "permission denied (on Linux, add yourself to the dialout group)";
  if (/EBUSY|Resource busy|Cannot lock/i.test(m)) return "the port is in use by another program";
  return m;
}

/** How long a closing port may take to send what was written before it (then it closes anyway). */
export const SERIAL_DRAIN_MS = 1000;

/**
 * Closes `p` once its pending writes are out — a block's last words (a hand's neutral pose) must
 * reach the device even when the host exits right after — and at most SERIAL_DRAIN_MS later.
 */
function drainThenClose(p: NativePort): Promise<void> {
  return new Promise((resolve) => {
    let done = false;
    const close = (): void => {
      if (done) return;
      done = true;
      clearTimeout(timer);
      try {
        p.close(() => resolve());
      } catch {
        resolve();
      }
    };
    const timer = setTimeout(close, SERIAL_DRAIN_MS);
    p.drain(close);
  });
}

/** What `SerialBridge.open` is given: the port's settings and where to report. */
type PortOptions = Parameters<SerialBridge["open"]>[0];

function openPort(o: PortOptions, injected?: PortConstructor): SerialHandle {
  const kept = new KeptPort(o, injected);
  kept.attempt();
  return {
    write: (data) => kept.write(data),
    close: () => kept.close(),
    closed: () => kept.whenClosed,
  };
}

/**
 * One port kept open until `close`: each attempt constructs and opens a fresh native port; a
 * failure or an unplug schedules the next attempt. Events of a port that is no longer the
 * current one (replaced, or closed by us) are ignored.
 */
class KeptPort {
  private closed = false;
  private port: OpenablePort | undefined;
  private retry: ReturnType<typeof setTimeout> | undefined;
  /** Resolves when the port closed by `close` has drained and closed. */
  whenClosed: Promise<void> = Promise.resolve();

  constructor(
    private readonly o: PortOptions,
    private readonly injected: PortConstructor | undefined,
  ) {}

  /** One try at opening the port: reports `opening`, then `open` or an error (and a retry). */
  attempt(): void {
    this.retry = undefined;
    if (this.closed) return;
    const lib = this.injected ? { ctor: this.injected } : load();
    if ("error" in lib) {
      this.o.onStatus("error", lib.error);
      return;
    }
    this.o.onStatus("opening");
    let p: OpenablePort;
    try {
      p = this.construct(lib.ctor);
    } catch (e) {
      this.scheduleRetry(describe(e as Error));
      return;
    }
    this.port = p;
    this.listen(p);
    p.open((err) => this.opened(p, err));
  }

  private construct(ctor: PortConstructor): OpenablePort {
    const o = this.o;
    return new ctor({
      path: o.path,
      baudRate: o.baudRate,
      dataBits: o.dataBits,
      stopBits: o.stopBits,
      parity: o.parity,
      autoOpen: false,
    });
  }

  /** Whether `p` is the port in use (not replaced, not closed by `close`). */
  private isCurrent(p: NativePort): boolean {
    return !this.closed && this.port === p;
  }

  /** Passes on `p`'s data and errors, and retries when the device closes it. */
  private listen(p: OpenablePort): void {
    p.on("data", (d) => {
      if (this.isCurrent(p)) this.o.onData(new Uint8Array(d.buffer, d.byteOffset, d.byteLength));
    });
    p.on("error", (e) => {
      if (this.isCurrent(p)) this.o.onStatus("error", describe(e));
    });
    p.on("close", (e) => {
      if (!this.isCurrent(p)) return;
      this.scheduleRetry(e?.disconnected ? "disconnected (unplugged?)" : "closed by the device");
    });
  }

  /** The end of `p.open`: closes a port opened after `close`, else reports the outcome. */
  private opened(p: OpenablePort, err: Error | null): void {
    if (this.closed) {
      if (!err) p.close();
      return;
    }
    if (err) this.scheduleRetry(describe(err));
    else this.o.onStatus("open");
  }

  /** Forgets the port, reports `reason` and, unless `reconnectMs` is 0, tries again then. */
  private scheduleRetry(reason: string): void {
    this.port = undefined;
    if (this.closed) return;
    const o = this.o;
    if (o.reconnectMs > 0) {
      o.onStatus("error", `${reason}; retrying every ${formatSeconds(o.reconnectMs)}`);
      this.retry = setTimeout(() => this.attempt(), o.reconnectMs);
      this.retry.unref?.();
    } else {
      o.onStatus("error", reason);
    }
  }

  /** Writes to the open port (dropped while none is open); a failed write is reported. */
  write(data: Uint8Array): void {
    const p = this.port;
    if (!p || !p.isOpen) return;
    p.write(data, (err) => {
      if (err && this.isCurrent(p)) this.o.onStatus("error", `write failed: ${describe(err)}`);
    });
  }

  /** Stops retrying and closes the port once its pending writes are out. */
  close(): void {
    if (this.closed) return;
    this.closed = true;
    if (this.retry) clearTimeout(this.retry);
    const p = this.port;
    this.port = undefined;
    if (p?.isOpen) this.whenClosed = drainThenClose(p);
    this.o.onStatus("closed");
  }
}

function formatSeconds(ms: number): string {
  return ms % 1000 === 0 ? `${ms / 1000} s` : `${(ms / 1000).toFixed(1)} s`;
}
