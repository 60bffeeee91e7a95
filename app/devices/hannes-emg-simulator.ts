/**
 * The Hannes's EMG stream as MOSAIC's HannesReceiver reads it (docs/protocols.md, "Hannes",
 * HannesReceiver; written from the format, not from the block's code): a UDP sender to a
 * receiver's HOST:PORT, `rate` datagrams a second, each two header bytes (`%` and 0x10: the
 * original read neither, what the Hannes puts there is not known) and then `channels`
 * little-endian unsigned 16-bit values. Value k of datagram i is `hannesEmgRaw(i, k)`, a pure
 * function, so a test compares what a pipeline logged (raw / 2¹⁶) exactly. The values look like
 * surface EMG around mid-scale: noise whose amplitude swells and fades on each channel in turn.
 * Used by the tests and by `mosaic simulate hannes-emg`.
 */
import { createSocket, type Socket } from "node:dgram";
import {
  errorText,
  hostPort,
  numberOption,
  StateReporter,
  type SimulatorValues,
} from "./hannes-simulator-common";

/** Datagrams per second when not told (the original's source does not say the Hannes's rate). */
export const HANNES_EMG_DEFAULT_RATE = 100;
/** Values per datagram when not told (the original decoded six). */
export const HANNES_EMG_DEFAULT_CHANNELS = 6;
/** The header bytes the simulator sends (nothing reads them). */
export const HANNES_EMG_HEADER = [0x25, 0x10] as const;

/** A 32-bit hash of (i, k): the noise, random access. */
function hash2(i: number, k: number): number {
  let h = Math.imul(i ^ 0x2545f491, 0x9e3779b1) ^ Math.imul(k + 1, 0x85ebca77);
  h = Math.imul(h ^ (h >>> 15), 0xc2b2ae3d);
  h = Math.imul(h ^ (h >>> 13), 0x165667b1);
  return (h ^ (h >>> 16)) >>> 0;
}

/**
 * The raw value (0…65535) of channel k in datagram i: 32768 plus noise of ±(600 + 14000·a),
 * where the activation a = sin²(π·(i/400 − k/6)) ^ 4 swells once every 400 datagrams (4 s at
 * 100 Hz), channel by channel.
 */
export function hannesEmgRaw(i: number, k: number): number {
  const s = Math.sin(Math.PI * (i / 400 - k / 6));
  const a = (s * s) ** 4;
  const noise = (hash2(i, k) / 0xffffffff) * 2 - 1;
  return Math.max(0, Math.min(65535, Math.round(32768 + (600 + 14000 * a) * noise)));
}

/** What HannesReceiver makes of it: raw / 2¹⁶. */
export function hannesEmgValue(i: number, k: number): number {
  return hannesEmgRaw(i, k) / 65536;
}

/** Datagram i's bytes for `channels` values. */
export function hannesEmgDatagram(i: number, channels: number): Uint8Array {
  const b = new Uint8Array(2 + 2 * channels);
  b[0] = HANNES_EMG_HEADER[0];
  b[1] = HANNES_EMG_HEADER[1];
  for (let k = 0; k < channels; k++) {
    const v = hannesEmgRaw(i, k);
    b[2 + 2 * k] = v & 0xff;
    b[3 + 2 * k] = v >> 8;
  }
  return b;
}

export interface HannesEmgSimulatorOptions {
  host: string;
  port: number;
  /** Datagrams per second (default 100). */
  rate?: number;
  /** Values per datagram (default 6). */
  channels?: number;
  /** Stop after this many datagrams (default: never). */
  count?: number;
  /** Index i of the first datagram (default 0). */
  first?: number;
  /** What it sends, one line a second at most (the CLI prints it). */
  log?: (line: string) => void;
}

function checkOptions(o: HannesEmgSimulatorOptions): void {
  const rate = o.rate ?? HANNES_EMG_DEFAULT_RATE;
  if (!(rate > 0 && rate <= 10_000)) throw new Error(`rate must be in (0, 10000] Hz, not ${rate}`);
  const ch = o.channels ?? HANNES_EMG_DEFAULT_CHANNELS;
  if (!Number.isInteger(ch) || ch < 1 || ch > 1000) {
    throw new Error(`channels must be 1…1000, not ${ch}`);
  }
  if (o.count !== undefined && !(Number.isInteger(o.count) && o.count >= 1)) {
    throw new Error(`count must be a whole number ≥ 1, not ${o.count}`);
  }
}

export class HannesEmgSimulator {
  readonly host: string;
  readonly port: number;
  readonly rate: number;
  readonly channels: number;
  readonly first: number;
  /** Datagrams sent (index of the next: first + sent). */
  sent = 0;
  /** Send errors (e.g. nothing listening, reported by some systems as ECONNREFUSED). */
  failed = 0;
  private readonly socket: Socket;
  private readonly timer: ReturnType<typeof setInterval>;
  private readonly t0 = performance.now();
  private readonly reporter: StateReporter;
  private lastError = "";
  private closed = false;

  constructor(private readonly o: HannesEmgSimulatorOptions) {
    checkOptions(o);
    this.host = o.host;
    this.port = o.port;
    this.rate = o.rate ?? HANNES_EMG_DEFAULT_RATE;
    this.channels = o.channels ?? HANNES_EMG_DEFAULT_CHANNELS;
    this.first = o.first ?? 0;
    this.reporter = new StateReporter(o.log ?? (() => {}), 1000);
    this.socket = createSocket(o.host.includes(":") ? "udp6" : "udp4");
    this.socket.on("error", (e) => this.onError(e));
    this.timer = setInterval(() => this.tick(), Math.max(2, Math.min(20, 500 / this.rate)));
  }

  /** True once `count` datagrams went out. */
  get done(): boolean {
    return this.o.count !== undefined && this.sent >= this.o.count;
  }

  async waitFor(cond: () => boolean, what: string, timeoutMs = 10_000): Promise<void> {
    const end = Date.now() + timeoutMs;
    while (!cond()) {
      if (Date.now() > end)
        throw new Error(`the Hannes EMG simulator: no ${what} in ${timeoutMs} ms`);
      await new Promise((r) => setTimeout(r, 10));
    }
  }

  async close(): Promise<void> {
    if (this.closed) return;
    this.closed = true;
    clearInterval(this.timer);
    this.reporter.flush();
    await new Promise<void>((r) => this.socket.close(() => r()));
  }

  /** Sends the datagrams due since the start (at most half a second's worth after a stall). */
  private tick(): void {
    if (this.closed) return;
    const due = Math.floor(((performance.now() - this.t0) / 1000) * this.rate) + 1;
    const limit = this.o.count ?? Infinity;
    const n = Math.min(due - this.sent, Math.ceil(this.rate / 2), limit - this.sent);
    for (let j = 0; j < n; j++) {
      const d = hannesEmgDatagram(this.first + this.sent, this.channels);
      this.socket.send(d, this.port, this.host, (e) => {
        if (e) this.onError(e);
      });
      this.sent++;
    }
    if (this.done) clearInterval(this.timer);
    let s = `${this.sent} datagrams sent`;
    if (this.failed > 0) s += ` · ${this.failed} failed (${this.lastError})`;
    if (this.done) s += " · done";
    this.reporter.update(s);
  }

  private onError(e: Error): void {
    this.failed++;
    this.lastError = errorText(e);
  }
}

/**
 * The simulator's options from `mosaic simulate hannes-emg`'s (`--to HOST:PORT [--rate HZ]
 * [--channels N] [--count N]`); throws an Error saying what is wrong.
 */
export function hannesEmgSimulatorOptions(v: SimulatorValues): HannesEmgSimulatorOptions {
  if (typeof v.to !== "string") {
    throw new Error(
      "--to HOST:PORT is required: where the HannesReceiver listens, e.g. --to 127.0.0.1:11000",
    );
  }
  const o: HannesEmgSimulatorOptions = hostPort(v.to, "to");
  const rate = numberOption(v, "rate", { integer: false, min: 0.1, max: 10_000, unit: "Hz" });
  const channels = numberOption(v, "channels", { integer: true, min: 1, max: 1000 });
  const count = numberOption(v, "count", { integer: true, min: 1, max: 1e12 });
  if (rate !== undefined) o.rate = rate;
  if (channels !== undefined) o.channels = channels;
  if (count !== undefined) o.count = count;
  return o;
}
