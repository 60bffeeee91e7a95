/**
 * The serial bridge for Node hosts (`ctx.io.serial`), on the `serialport` package. The package's
 * native binding is loaded on first use, so a host where it cannot load still starts (the
 * SerialPort block then reports the reason). Ports are kept open: after a failed open or an
 * unplug the bridge reports the error and retries every `reconnectMs`.
 */
import { existsSync, readdirSync } from "node:fs";
import { createRequire } from "node:module";
import type { SerialBridge, SerialHandle, SerialOptions, SerialStatus } from "../app/engine/io";

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

type PortConstructor = new (options: {
  path: string;
  baudRate: number;
  dataBits: 5 | 6 | 7 | 8;
  stopBits: 1 | 1.5 | 2;
  parity: string;
  autoOpen: boolean;
}) => NativePort & { open(cb: (err: Error | null) => void): void };

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

function openPort(
  o: SerialOptions & {
    reconnectMs: number;
    onData: (data: Uint8Array) => void;
    onStatus: (status: SerialStatus, message?: string) => void;
  },
  injected?: PortConstructor,
): SerialHandle {
  let closed = false;
  let port: (NativePort & { open(cb: (err: Error | null) => void): void }) | undefined;
  let retry: ReturnType<typeof setTimeout> | undefined;
  let whenClosed: Promise<void> = Promise.resolve();

  const scheduleRetry = (reason: string): void => {
    port = undefined;
    if (closed) return;
    if (o.reconnectMs > 0) {
      o.onStatus("error", `${reason}; retrying every ${formatSeconds(o.reconnectMs)}`);
      retry = setTimeout(attempt, o.reconnectMs);
      retry.unref?.();
    } else {
      o.onStatus("error", reason);
    }
  };

  const attempt = (): void => {
    retry = undefined;
    if (closed) return;
    const lib = injected ? { ctor: injected } : load();
    if ("error" in lib) {
      o.onStatus("error", lib.error);
      return;
    }
    o.onStatus("opening");
    let p: NativePort & { open(cb: (err: Error | null) => void): void };
    try {
      p = new lib.ctor({
        path: o.path,
        baudRate: o.baudRate,
        dataBits: o.dataBits,
        stopBits: o.stopBits,
        parity: o.parity,
        autoOpen: false,
      });
    } catch (e) {
      scheduleRetry(describe(e as Error));
      return;
    }
    port = p;
    p.on("data", (d) => {
      if (!closed && port === p) o.onData(new Uint8Array(d.buffer, d.byteOffset, d.byteLength));
    });
    p.on("error", (e) => {
      if (!closed && port === p) o.onStatus("error", describe(e));
    });
    p.on("close", (e) => {
      if (closed || port !== p) return;
      scheduleRetry(e?.disconnected ? "disconnected (unplugged?)" : "closed by the device");
    });
    p.open((err) => {
      if (closed) {
        if (!err) p.close();
        return;
      }
      if (err) scheduleRetry(describe(err));
      else o.onStatus("open");
    });
  };

  attempt();

  return {
    write(data) {
      const p = port;
      if (!p || !p.isOpen) return;
      p.write(data, (err) => {
        if (err && !closed && port === p) o.onStatus("error", `write failed: ${describe(err)}`);
      });
    },
    close() {
      if (closed) return;
      closed = true;
      if (retry) clearTimeout(retry);
      const p = port;
      port = undefined;
      if (p?.isOpen) whenClosed = drainThenClose(p);
      o.onStatus("closed");
    },
    closed: () => whenClosed,
  };
}

function formatSeconds(ms: number): string {
  return ms % 1000 === 0 ? `${ms / 1000} s` : `${(ms / 1000).toFixed(1)} s`;
}
