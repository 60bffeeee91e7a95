/**
 * OT Bioelettronica's SyncStation and Muovi probe, simulated from the protocol as OTB's examples
 * and the original MOSAIC use it (docs/protocols.md, "OT Bioelettronica Muovi and SyncStation"):
 *
 * - `SyncStationSimulator`: a TCP server (the SyncStation listens on 54320). It waits for a start
 *   command (`[count·2 + 1, probe bytes…, CRC-8]`; a bad CRC or probe byte is logged and ignored),
 *   then streams, per sample at 2 kHz, 38 int16 big-endian channels per enabled Muovi slot in
 *   slot order and its own 6 channels; a stop command (`[0, CRC]`) stops the stream.
 * - `MuoviProbeSimulator`: a TCP client (the probe connects to the PC's port 54321, and connects
 *   again 0.5 s after its connection ends). A command byte with bit 0 set starts 38 channels per
 *   sample at 2 kHz (EMG mode); with bit 0 clear it stops.
 *
 * Values are deterministic: `muoviRaw(seed, slot, channel, k)` is channel `channel` (0…37) of the
 * probe in `slot` at sample k (from 0 at the start command): EMG-like sines plus seeded noise on
 * 0…31, a quaternion on 32…35, a buffer level on 36 and the sample counter k (16 bits) on 37, so a
 * test computes what a block must output. `syncStationRaw(seed, channel, k)` are the SyncStation's
 * own channels (its counter last). Samples go out in packets of 20 (every 10 ms).
 *
 * Faults for tests and demos: `dropConnections()`, `inject(bytes)` (malformed bytes between two
 * samples), `truncate()` (half a sample, then the connection drops), `skip(n)` (n samples never
 * sent: the counter jumps, as when the device loses packets).
 *
 * Pure Node (node:net); used by the tests and by `mosaic simulate syncstation|muovi`.
 */
import { createServer, connect, type AddressInfo, type Server, type Socket } from "node:net";
import { PacedSampleStream } from "./paced-sample-stream";

/** The probes' EMG rate, channels per Muovi on the wire, and the SyncStation's own channels. */
export const MUOVI_RATE = 2000;
export const MUOVI_WIRE_CHANNELS = 38;
export const SYNCSTATION_CHANNELS = 6;

/** CRC-8/MAXIM (reflected 0x31, init 0) by table: the checksum of OTB's examples, written anew. */
const CRC_TABLE = Uint8Array.from({ length: 256 }, (_, i) => {
  let c = i;
  for (let k = 0; k < 8; k++) c = c & 1 ? (c >>> 1) ^ 0x8c : c >>> 1;
  return c;
});

export function crc8Table(bytes: ArrayLike<number>, len = bytes.length): number {
  let crc = 0;
  for (let i = 0; i < len; i++) crc = CRC_TABLE[(crc ^ bytes[i]!) & 0xff]!;
  return crc;
}

/** What a start command asks for. */
export interface SyncStationRequest {
  go: boolean;
  probes: { slot: number; emg: boolean; mode: number }[];
}

/**
 * Reads a SyncStation command from the start of `b`: `[probes·2 + GO, probe bytes…, CRC-8]`.
 * Returns the request and the bytes used, or how many more bytes are needed, or why it is wrong.
 */
export function readSyncStationCommand(
  b: Uint8Array,
): { used: number; request: SyncStationRequest } | { need: number } | { error: string } {
  if (b.length === 0) return { need: 1 };
  const count = b[0]! >> 1;
  if (count > 16) return { error: `header byte ${b[0]}: ${count} probes (at most 16)` };
  const len = count + 2;
  if (b.length < len) return { need: len - b.length };
  const crc = crc8Table(b, len - 1);
  if (crc !== b[len - 1]) {
    return { error: `CRC-8 ${b[len - 1]} where ${crc} was due (command of ${len} bytes)` };
  }
  const probes: SyncStationRequest["probes"] = [];
  for (let i = 1; i <= count; i++) {
    const p = b[i]!;
    if (!(p & 1)) return { error: `probe byte ${p} has its enable bit off` };
    probes.push({ slot: p >> 4, emg: (p & 8) !== 0, mode: (p >> 1) & 3 });
  }
  return { used: len, request: { go: (b[0]! & 1) === 1, probes } };
}

/** The SyncStation's port and the port a probe connects to. */
export const SYNCSTATION_PORT = 54320;
export const MUOVI_PROBE_PORT = 54321;
/** Samples per packet (10 ms at 2 kHz). */
export const PACKET_SAMPLES = 20;
/** Bytes a client may leave unread before packets to it are dropped. */
const MAX_UNREAD = 4 << 20;

/** A 32-bit integer hash of (seed, a, b, c): the seeded noise, random access. */
function hash4(seed: number, a: number, b: number, c: number): number {
  let h = Math.imul(seed ^ 0x9e3779b9, 0x85ebca6b) ^ Math.imul(a + 1, 0xc2b2ae35);
  h = Math.imul(h ^ (h >>> 16), 0x7feb352d) ^ Math.imul(b + 7, 0x846ca68b);
  h = Math.imul(h ^ (h >>> 15), 0x846ca68b) ^ Math.imul(c, 0x27d4eb2d);
  h = Math.imul(h ^ (h >>> 13), 0x165667b1);
  return (h ^ (h >>> 16)) >>> 0;
}

/** x rounded and clamped to int16 (| 0: never -0, which the wire cannot carry). */
const int16 = (x: number): number => Math.max(-32768, Math.min(32767, Math.round(x))) | 0;

/**
 * Channel `channel` (0…37) of the Muovi in `slot` (0…3) at sample k, as an int16: EMG-like on
 * 0…31 (a sine of 300–1100 counts at 20 + 3·channel Hz plus ±400 counts of seeded noise), a
 * slowly turning quaternion on 32…35 (±16384), a buffer level on 36 (rising by 1 every 16
 * samples, so that it never looks like the counter), and the sample
 * counter k (two's complement, 16 bits) on 37.
 */
export function muoviRaw(seed: number, slot: number, channel: number, k: number): number {
  if (channel < 32) {
    const amp = 300 + 100 * ((channel + 2 * slot) % 9);
    const sine = amp * Math.sin((2 * Math.PI * (20 + 3 * channel) * k) / MUOVI_RATE + slot);
    const noise = 400 * (hash4(seed, slot, channel, k) / 2 ** 31 - 1);
    return int16(sine + noise);
  }
  if (channel < 36) return int16(16384 * Math.cos((2 * Math.PI * 0.2 * k) / MUOVI_RATE + channel));
  if (channel === 36) return (k >> 4) % 500;
  return ((k & 0xffff) << 16) >> 16;
}

/** The SyncStation's own channel `channel` (0…5) at sample k: AUX sines, then its counter. */
export function syncStationRaw(seed: number, channel: number, k: number): number {
  if (channel === SYNCSTATION_CHANNELS - 1) return ((k & 0xffff) << 16) >> 16;
  return int16(1000 * Math.sin((2 * Math.PI * (1 + channel) * k) / MUOVI_RATE + seed));
}

/** Writes n samples from k0, each `channels` int16 big-endian values from `value(ch, k)`. */
function encode(
  k0: number,
  n: number,
  channels: number,
  value: (ch: number, k: number) => number,
): Buffer {
  const b = Buffer.alloc(n * channels * 2);
  let at = 0;
  for (let k = k0; k < k0 + n; k++) {
    for (let ch = 0; ch < channels; ch++, at += 2) b.writeInt16BE(value(ch, k), at);
  }
  return b;
}

/** A stream of `channels` int16 big-endian values per sample at 2 kHz, in packets of 20 samples. */
function muoviStream(
  socket: Socket,
  channels: number,
  value: (ch: number, k: number) => number,
): PacedSampleStream {
  const source = {
    rate: MUOVI_RATE,
    packetSamples: PACKET_SAMPLES,
    encode: (k0: number, n: number) => encode(k0, n, channels, value),
  };
  return new PacedSampleStream(socket, source, { pumpMs: 5, maxUnread: MAX_UNREAD });
}

export interface SyncStationSimulatorOptions {
  /** Address to listen on (default 127.0.0.1). */
  host?: string;
  /** Port; 0 picks a free one (tests). Default 54320. */
  port?: number;
  /** Seed of the signals (default 1). */
  seed?: number;
  /** Called with one line for what happens (connections, commands), for the CLI. */
  log?: (line: string) => void;
}

/** A SyncStation (see the file comment). */
export class SyncStationSimulator {
  readonly seed: number;
  readonly host: string;
  /** Start commands received (in order), and commands refused with the reason. */
  readonly commands: SyncStationRequest[] = [];
  readonly refused: string[] = [];
  /** Stop commands received. */
  stops = 0;
  private readonly streams = new Set<PacedSampleStream>();
  private readonly sockets = new Set<Socket>();
  private readonly log: (line: string) => void;

  private constructor(
    private readonly server: Server,
    o: SyncStationSimulatorOptions,
  ) {
    this.seed = o.seed ?? 1;
    this.host = o.host ?? "127.0.0.1";
    this.log = o.log ?? (() => {});
  }

  static async start(o: SyncStationSimulatorOptions = {}): Promise<SyncStationSimulator> {
    const server = createServer();
    const sim = new SyncStationSimulator(server, o);
    server.on("connection", (s) => sim.accept(s));
    await listenOn(server, sim.host, o.port ?? SYNCSTATION_PORT, "SyncStation");
    return sim;
  }

  get port(): number {
    return (this.server.address() as AddressInfo).port;
  }

  /** Samples sent by the newest stream since its start command. */
  get samples(): number {
    let n = 0;
    for (const s of this.streams) n = s.samples;
    return n;
  }

  /** Clients connected now. */
  get clients(): number {
    return this.sockets.size;
  }

  private accept(s: Socket): void {
    s.setNoDelay(true);
    this.sockets.add(s);
    this.log(`client connected from ${s.remoteAddress}:${s.remotePort}`);
    let stream: PacedSampleStream | undefined;
    let pending = Buffer.alloc(0);
    const end = () => {
      stream?.stop();
      if (stream) this.streams.delete(stream);
      this.sockets.delete(s);
    };
    s.on("close", () => {
      end();
      this.log("client disconnected");
    });
    s.on("error", () => s.destroy());
    s.on("data", (d: Buffer) => {
      pending = Buffer.concat([pending, d]);
      for (;;) {
        const r = readSyncStationCommand(new Uint8Array(pending));
        if ("need" in r) return;
        if ("error" in r) {
          this.refused.push(r.error);
          this.log(`refused a command: ${r.error}`);
          pending = Buffer.alloc(0);
          return;
        }
        pending = pending.subarray(r.used);
        stream?.stop();
        if (stream) this.streams.delete(stream);
        stream = undefined;
        if (!r.request.go || r.request.probes.length === 0) {
          this.stops++;
          this.log("stop command: streaming stopped");
          continue;
        }
        this.commands.push(r.request);
        stream = this.streamFor(s, r.request);
        this.streams.add(stream);
        stream.start();
      }
    });
  }

  private streamFor(s: Socket, req: SyncStationRequest): PacedSampleStream {
    const slots = req.probes.map((p) => p.slot).sort((a, b) => a - b);
    const channels = slots.length * MUOVI_WIRE_CHANNELS + SYNCSTATION_CHANNELS;
    const seed = this.seed;
    this.log(
      `start command: Muovi slot${slots.length === 1 ? "" : "s"} ${slots.join(", ")}; streaming ${channels} channels at ${MUOVI_RATE} Hz`,
    );
    return muoviStream(s, channels, (ch, k) => {
      const probe = Math.floor(ch / MUOVI_WIRE_CHANNELS);
      return probe < slots.length
        ? muoviRaw(seed, slots[probe]!, ch % MUOVI_WIRE_CHANNELS, k)
        : syncStationRaw(seed, ch - slots.length * MUOVI_WIRE_CHANNELS, k);
    });
  }

  /** Every client's connection drops (as a SyncStation switched off and on). */
  dropConnections(): void {
    for (const s of this.sockets) s.destroy();
  }

  /** These bytes go out between two samples of the next packet of every stream. */
  inject(bytes: Uint8Array): void {
    for (const s of this.streams) s.inject(bytes);
  }

  /** Every stream skips n samples (its counter jumps by n). */
  skip(n: number): void {
    for (const s of this.streams) s.skip(n);
  }

  /** Every stream sends half a sample, then its connection drops. */
  truncate(): void {
    for (const s of this.streams) s.truncate();
  }

  async close(): Promise<void> {
    this.dropConnections();
    await new Promise<void>((r) => this.server.close(() => r()));
  }
}

export interface MuoviProbeSimulatorOptions {
  /** Where the probe connects (the PC running the block). */
  host: string;
  port: number;
  /** Its slot in muoviRaw's values (default 0). */
  slot?: number;
  seed?: number;
  /** Seconds between a connection's end and the next attempt (default 0.5). */
  retry?: number;
  log?: (line: string) => void;
}

/** A Muovi probe that connects to the PC (see the file comment). */
export class MuoviProbeSimulator {
  readonly seed: number;
  readonly slot: number;
  /** Command bytes received, in order. */
  readonly received: number[] = [];
  /** Connections made. */
  connections = 0;
  private socket: Socket | undefined;
  private stream: PacedSampleStream | undefined;
  private closed = false;
  private retryTimer: NodeJS.Timeout | undefined;
  private readonly log: (line: string) => void;

  constructor(private readonly o: MuoviProbeSimulatorOptions) {
    this.seed = o.seed ?? 1;
    this.slot = o.slot ?? 0;
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

  get samples(): number {
    return this.stream?.samples ?? 0;
  }

  private connect(): void {
    if (this.closed) return;
    const s = connect({ host: this.o.host, port: this.o.port });
    this.socket = s;
    s.setNoDelay(true);
    s.on("connect", () => {
      this.connections++;
      this.log(`connected to ${this.o.host}:${this.o.port}; waiting for the command byte`);
    });
    s.on("data", (d: Buffer) => {
      for (const byte of d) this.command(s, byte);
    });
    s.on("error", () => s.destroy());
    s.on("close", () => {
      this.stream?.stop();
      this.stream = undefined;
      if (this.socket === s) this.socket = undefined;
      if (this.closed) return;
      this.retryTimer = setTimeout(() => this.connect(), (this.o.retry ?? 0.5) * 1000);
    });
  }

  private command(s: Socket, byte: number): void {
    this.received.push(byte);
    if (!(byte & 1)) {
      this.stream?.stop();
      this.log(`command ${byte}: stopped`);
      return;
    }
    if (!(byte & 8)) {
      this.log(`command ${byte}: EEG mode (24-bit, 500 Hz) is not simulated; ignored`);
      return;
    }
    this.log(`command ${byte}: streaming ${MUOVI_WIRE_CHANNELS} channels at ${MUOVI_RATE} Hz`);
    this.stream?.stop();
    this.stream = muoviStream(s, MUOVI_WIRE_CHANNELS, (ch, k) =>
      muoviRaw(this.seed, this.slot, ch, k),
    );
    this.stream.start();
  }

  /** The connection drops (the probe connects again after `retry`). */
  dropConnection(): void {
    this.socket?.destroy();
  }

  inject(bytes: Uint8Array): void {
    this.stream?.inject(bytes);
  }

  skip(n: number): void {
    this.stream?.skip(n);
  }

  truncate(): void {
    this.stream?.truncate();
  }

  async close(): Promise<void> {
    this.closed = true;
    if (this.retryTimer) clearTimeout(this.retryTimer);
    this.stream?.stop();
    const s = this.socket;
    if (!s || s.destroyed) return;
    await new Promise<void>((r) => {
      s.once("close", () => r());
      s.destroy();
    });
  }
}

async function listenOn(server: Server, host: string, port: number, what: string): Promise<void> {
  await new Promise<void>((resolve, reject) => {
    server.once("error", (e: NodeJS.ErrnoException) =>
      reject(
        new Error(
          e.code === "EADDRINUSE"
            ? `port ${port} on ${host} is already in use (EADDRINUSE): is a ${what} simulator running? Choose another port`
            : `cannot listen on ${host}:${port}: ${e.message}`,
        ),
      ),
    );
    server.listen({ host, port, exclusive: true }, resolve);
  });
  server.on("error", () => {});
}

type OptionValues = Record<string, string | boolean | undefined>;

/** An integer option, or its default; throws with the option's name and the value given. */
function intOption(v: OptionValues, name: string, fallback: number, max: number): number {
  const raw = v[name];
  if (raw === undefined) return fallback;
  if (typeof raw !== "string" || !/^\d+$/.test(raw) || Number(raw) > max) {
    throw new Error(
      name === "port"
        ? `--port must be a port number (0 for any free port), not '${String(raw)}'`
        : `--${name} must be an integer from 0 to ${max}, not '${String(raw)}'`,
    );
  }
  return Number(raw);
}

/** `mosaic simulate syncstation`'s options, checked. */
export function syncStationSimulatorOptions(v: OptionValues): SyncStationSimulatorOptions {
  return {
    host: typeof v.host === "string" ? v.host : "127.0.0.1",
    port: intOption(v, "port", SYNCSTATION_PORT, 65535),
    seed: intOption(v, "seed", 1, 2 ** 31 - 1),
  };
}

/** `mosaic simulate muovi`'s options, checked (`--connect HOST:PORT` is required). */
export function muoviProbeSimulatorOptions(v: OptionValues): MuoviProbeSimulatorOptions {
  const raw = v.connect;
  if (typeof raw !== "string") {
    throw new Error(
      `--connect HOST:PORT is required (where a MuoviSingleProbe block listens, e.g. --connect 127.0.0.1:${MUOVI_PROBE_PORT})`,
    );
  }
  const m = /^(.+):(\d+)$/.exec(raw.trim());
  if (!m || Number(m[2]) < 1 || Number(m[2]) > 65535) {
    throw new Error(`--connect takes HOST:PORT (e.g. 127.0.0.1:${MUOVI_PROBE_PORT}), not '${raw}'`);
  }
  return {
    host: m[1]!.replace(/^\[(.*)\]$/, "$1"),
    port: Number(m[2]),
    slot: intOption(v, "slot", 0, 3),
    seed: intOption(v, "seed", 1, 2 ** 31 - 1),
  };
}
