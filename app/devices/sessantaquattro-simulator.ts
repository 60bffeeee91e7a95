/**
 * OT Bioelettronica's Sessantaquattro / Sessantaquattro+, simulated from its TCP protocol
 * (docs/protocols.md, "OT Bioelettronica Sessantaquattro"): a TCP client, as the device is. It
 * connects to the PC's port (45454), reads 16-bit command words (big-endian) and, for a SET word
 * with GO, streams the commanded channels (NCH, halved in bipolar mode; 2 AUX; 4 IMU on the +;
 * buffer; sample counter) as big-endian integers of 2 bytes (3 with HRES) at the commanded rate
 * (FSAMP: 500…4000 Hz). A word with GO clear stops the stream and closes the socket, as the
 * device does; whenever its connection ends it connects again after `retry` s (the device keeps
 * searching for the PC's socket). GET words and the modes it does not simulate (accelerometers,
 * impedance, test) are logged and ignored. The firmware's high-pass filter is not simulated:
 * HPF changes nothing in the values.
 *
 * Values are deterministic: `sessantaquattroRaw(seed, kind, index, k, highRes)` is what channel
 * `index` of that kind carries at sample k (from 0 at the start word), so a test computes what a
 * block must output. Samples go out every 10 ms (at least one).
 *
 * Faults for tests and demos: `dropConnection()`, `inject(bytes)` (malformed bytes between two
 * samples), `truncate()` (part of a sample, then the connection drops), `skip(n)` (n samples never
 * sent: the counter jumps, as when the device loses samples).
 *
 * Pure Node (node:net); used by the tests and by `mosaic simulate sessantaquattro`.
 */
import { connect, type Socket } from "node:net";
import { PacedSampleStream } from "./paced-sample-stream";

/** The port the device connects to by default, and what FSAMP and NCH select. */
export const SESSANTAQUATTRO_PORT = 45454;
const RATES = [500, 1000, 2000, 4000] as const;
const NCH = [8, 16, 32, 64] as const;
/** MODE 0…2; the others (accelerometers, impedance, test) are not simulated. */
const MODES = ["monopolar", "bipolar", "differential"] as const;

export type SimModel = "Sessantaquattro" | "Sessantaquattro+";
export type SimKind = "bio" | "aux" | "imu" | "buffer" | "counter";

/** What a SET command word with GO asks for, as the simulator reads it. */
export interface SimConfig {
  model: SimModel;
  mode: (typeof MODES)[number];
  /** Bioelectrical channels streamed (NCH's count, halved in bipolar mode). */
  bio: number;
  rate: number;
  highRes: boolean;
  hpf: boolean;
}

/** The kinds of the channels of one sample, in order on the wire. */
export function simLayout(c: Pick<SimConfig, "model" | "bio">): SimKind[] {
  const imu: SimKind[] = c.model === "Sessantaquattro+" ? ["imu", "imu", "imu", "imu"] : [];
  return [...Array<SimKind>(c.bio).fill("bio"), "aux", "aux", ...imu, "buffer", "counter"];
}

/** Bytes the PC may leave unread before samples to it are dropped. */
const MAX_UNREAD = 4 << 20;
/** How often samples go out, ms. */
const PACKET_MS = 10;

/** A 32-bit integer hash of (seed, a, b): the seeded noise, random access. */
function hash3(seed: number, a: number, b: number): number {
  let h = Math.imul(seed ^ 0x5bd1e995, 0x85ebca6b) ^ Math.imul(a + 3, 0xc2b2ae35);
  h = Math.imul(h ^ (h >>> 16), 0x7feb352d) ^ Math.imul(b, 0x846ca68b);
  h = Math.imul(h ^ (h >>> 15), 0x165667b1);
  return (h ^ (h >>> 16)) >>> 0;
}

/** x rounded and clamped to `bits` bits, two's complement (| 0: never -0). */
const clampTo = (x: number, bits: number): number => {
  const max = 2 ** (bits - 1) - 1;
  return Math.max(-max - 1, Math.min(max, Math.round(x))) | 0;
};

/**
 * What channel `index` (0-based within its kind) carries at sample k:
 * - bio: a sine of 300–1100 counts at 20 + 3·index Hz (× 64 at 24 bits) plus ±400 counts of
 *   seeded noise (× 64 at 24 bits), the sample rate taken as 2000 Hz for the phase;
 * - aux: a slow sine, ±8000 counts (× 256 at 24 bits);
 * - imu: a quaternion component (±16384, 14 bits used) that changes every 20 samples (the IMU
 *   updates at 100 Hz);
 * - buffer: a small buffer level (0…9 %); counter: k modulo 2¹⁶ (a real Sessantaquattro wraps
 *   its counter at 16 bits even at 24-bit resolution, as one public reader found).
 */
export function sessantaquattroRaw(
  seed: number,
  kind: SimKind,
  index: number,
  k: number,
  highRes: boolean,
): number {
  const bits = highRes ? 24 : 16;
  const big = highRes ? 64 : 1;
  switch (kind) {
    case "bio": {
      const amp = 300 + 100 * (index % 9);
      const sine = amp * Math.sin((2 * Math.PI * (20 + 3 * index) * k) / 2000 + seed);
      const noise = 400 * (hash3(seed, index, k) / 2 ** 31 - 1);
      return clampTo((sine + noise) * big, bits);
    }
    case "aux":
      return clampTo(
        8000 * Math.sin((2 * Math.PI * (1 + index) * k) / 4000) * (highRes ? 256 : 1),
        bits,
      );
    case "imu":
      return clampTo(16384 * Math.cos(0.01 * Math.floor(k / 20) + index), bits);
    case "buffer":
      return (k >> 8) % 10;
    case "counter":
      return k & 0xffff;
  }
}

/**
 * A command word read as the device reads it (bit 15 GETSET, 14-13 FSAMP, 12-11 NCH, 10-8 MODE,
 * 7 HRES, 6 HPF, 0 GO), or why the simulator ignores it.
 */
export function configOf(
  word: number,
  model: SimModel,
): { config: SimConfig; go: boolean } | { ignored: string } {
  if (word & 0x8000) return { ignored: "a GET request (not simulated)" };
  const modeCode = (word >> 8) & 7;
  const mode = MODES[modeCode];
  if (!mode)
    return { ignored: `MODE ${modeCode} (accelerometers, impedance or test: not simulated)` };
  const nch = NCH[(word >> 11) & 3]!;
  const config: SimConfig = {
    model,
    mode,
    bio: mode === "bipolar" ? nch / 2 : nch,
    rate: RATES[(word >> 13) & 3]!,
    highRes: ((word >> 7) & 1) === 1,
    hpf: ((word >> 6) & 1) === 1,
  };
  return { config, go: (word & 1) === 1 };
}

/** The bytes of samples k0…k0+n-1 for `config`. */
export function encodeSamples(seed: number, config: SimConfig, k0: number, n: number): Buffer {
  const layout = simLayout(config);
  const bytes = config.highRes ? 3 : 2;
  const b = Buffer.alloc(n * layout.length * bytes);
  const index = new Map<SimKind, number>();
  const within = layout.map((kind) => {
    const i = index.get(kind) ?? 0;
    index.set(kind, i + 1);
    return i;
  });
  let at = 0;
  for (let k = k0; k < k0 + n; k++) {
    for (let ch = 0; ch < layout.length; ch++, at += bytes) {
      const v = sessantaquattroRaw(seed, layout[ch]!, within[ch]!, k, config.highRes);
      if (bytes === 2) b.writeUInt16BE(v & 0xffff, at);
      else b.writeUIntBE(v & 0xffffff, at, 3);
    }
  }
  return b;
}

export interface SessantaquattroSimulatorOptions {
  /** Where the device connects (the PC running the block). */
  host: string;
  port: number;
  /** Sessantaquattro+ (default) adds the 4 IMU channels. */
  model?: SimModel;
  seed?: number;
  /** Seconds between a connection's end and the next attempt (default 0.5). */
  retry?: number;
  log?: (line: string) => void;
}

/** A Sessantaquattro that connects to the PC (see the file comment). */
export class SessantaquattroSimulator {
  readonly seed: number;
  readonly model: SimModel;
  /** Command words received, in order. */
  readonly received: number[] = [];
  /** Connections made. */
  connections = 0;
  /** The configuration streaming now (or last). */
  config: SimConfig | undefined;
  private socket: Socket | undefined;
  private stream: PacedSampleStream | undefined;
  private retryTimer: NodeJS.Timeout | undefined;
  private closed = false;
  private readonly log: (line: string) => void;

  constructor(private readonly o: SessantaquattroSimulatorOptions) {
    this.seed = o.seed ?? 1;
    this.model = o.model ?? "Sessantaquattro+";
    this.log = o.log ?? (() => {});
    this.connect();
  }

  /** Whether it is connected now, and streaming. */
  get connected(): boolean {
    return this.socket !== undefined && !this.socket.destroyed && this.socket.readyState === "open";
  }

  get streaming(): boolean {
    return this.stream?.running ?? false;
  }

  /** Samples sent (and skipped) since the last start word. */
  get samples(): number {
    return this.stream?.samples ?? 0;
  }

  /** When the last start word came (performance.now(), ms): samples never run ahead of it. */
  get startedAt(): number {
    return this.stream?.startedAt ?? 0;
  }

  private connect(): void {
    if (this.closed) return;
    const s = connect({ host: this.o.host, port: this.o.port });
    this.socket = s;
    s.setNoDelay(true);
    let pending: number[] = [];
    s.on("connect", () => {
      this.connections++;
      this.log(`connected to ${this.o.host}:${this.o.port}; waiting for the command word`);
    });
    s.on("data", (d: Buffer) => {
      pending.push(...d);
      while (pending.length >= 2) {
        this.command(s, (pending[0]! << 8) | pending[1]!);
        pending = pending.slice(2);
      }
    });
    s.on("error", () => s.destroy());
    s.on("close", () => {
      this.stopStream();
      if (this.socket === s) this.socket = undefined;
      if (this.closed) return;
      this.retryTimer = setTimeout(() => this.connect(), (this.o.retry ?? 0.5) * 1000);
    });
  }

  private command(s: Socket, word: number): void {
    this.received.push(word);
    const hex = `0x${word.toString(16).padStart(4, "0")}`;
    const r = configOf(word, this.model);
    if ("ignored" in r) {
      this.log(`command ${hex}: ${r.ignored}; ignored`);
      return;
    }
    if (!r.go) {
      this.log(`command ${hex}: GO clear: stopped, closing the socket`);
      this.stopStream();
      s.end();
      return;
    }
    const c = r.config;
    const n = simLayout(c).length;
    this.log(
      `command ${hex}: streaming ${n} channels (${c.bio} ${c.mode}) at ${c.rate} Hz, ${c.highRes ? 24 : 16}-bit${c.hpf ? ", HPF on (not simulated)" : ""}`,
    );
    this.startStream(s, c);
  }

  private startStream(s: Socket, c: SimConfig): void {
    this.stopStream();
    this.config = c;
    const seed = this.seed;
    const source = {
      rate: c.rate,
      packetSamples: Math.max(1, Math.round((c.rate * PACKET_MS) / 1000)),
      encode: (k0: number, n: number) => encodeSamples(seed, c, k0, n),
    };
    this.stream = new PacedSampleStream(s, source, {
      pumpMs: PACKET_MS / 2,
      maxUnread: MAX_UNREAD,
    });
    this.stream.start();
  }

  private stopStream(): void {
    this.stream?.stop();
  }

  /** The connection drops (it connects again after `retry`). */
  dropConnection(): void {
    this.socket?.destroy();
  }

  /** These bytes go out between two samples of the next packet. */
  inject(bytes: Uint8Array): void {
    this.stream?.inject(bytes);
  }

  /** n samples are never sent (the counter jumps by n). */
  skip(n: number): void {
    this.stream?.skip(n);
  }

  /** Half a sample goes out, then the connection drops. */
  truncate(): void {
    this.stream?.truncate();
  }

  async close(): Promise<void> {
    this.closed = true;
    if (this.retryTimer) clearTimeout(this.retryTimer);
    this.stopStream();
    const s = this.socket;
    if (!s || s.destroyed) return;
    await new Promise<void>((r) => {
      s.once("close", () => r());
      s.destroy();
    });
  }
}

type OptionValues = Record<string, string | boolean | undefined>;

/** `mosaic simulate sessantaquattro`'s options, checked (`--connect HOST:PORT` is required). */
export function sessantaquattroSimulatorOptions(v: OptionValues): SessantaquattroSimulatorOptions {
  const raw = v.connect;
  if (typeof raw !== "string") {
    throw new Error(
      `--connect HOST:PORT is required (where a Sessantaquattro block listens, e.g. --connect 127.0.0.1:${SESSANTAQUATTRO_PORT})`,
    );
  }
  const m = /^(.+):(\d+)$/.exec(raw.trim());
  if (!m || Number(m[2]) < 1 || Number(m[2]) > 65535) {
    throw new Error(
      `--connect takes HOST:PORT (e.g. 127.0.0.1:${SESSANTAQUATTRO_PORT}), not '${raw}'`,
    );
  }
  const model = v.model === undefined ? "plus" : String(v.model).toLowerCase();
  if (!["plus", "sessantaquattro+", "sessantaquattro"].includes(model)) {
    throw new Error(
      `--model must be sessantaquattro or sessantaquattro+ (plus), not '${String(v.model)}'`,
    );
  }
  const seed = v.seed === undefined ? "1" : String(v.seed);
  if (!/^\d+$/.test(seed) || Number(seed) > 2 ** 31 - 1) {
    throw new Error(`--seed must be an integer from 0 to ${2 ** 31 - 1}, not '${seed}'`);
  }
  return {
    host: m[1]!.replace(/^\[(.*)\]$/, "$1"),
    port: Number(m[2]),
    model: model === "sessantaquattro" ? "Sessantaquattro" : "Sessantaquattro+",
    seed: Number(seed),
  };
}
