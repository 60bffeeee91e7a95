/**
 * OT Bioelettronica's Quattrocento, simulated from its configuration protocol (docs/protocols.md,
 * "OT Bioelettronica Quattrocento"): a TCP server (the device listens on 23456) that reads
 * 40-byte configuration commands. A command whose CRC-8 (CRC-8/MAXIM of the 39 bytes before it)
 * or fixed bits are wrong is logged, counted in `refused` and otherwise ignored (OTB's document
 * does not say what the device does: we assume it ignores it and sends nothing back). A good one
 * with ACQ_ON starts the stream (or changes it: a new rate or channel count restarts it, the
 * sample counter from 0), one without ACQ_ON stops it.
 *
 * Values are deterministic: `quattrocentoRaw(seed, nch, channel, k)` is channel `channel` of
 * sample k (from 0 at the start) when streaming NCH code `nch`: EMG-like on the inputs (a sine
 * from a table plus seeded noise from a table, cheap enough for 408 channels at 10240 Hz), slow
 * sines on AUX IN, and on the 8 accessory channels: the sample counter (k, 16 bits, unsigned),
 * the trigger (31767 while REC_ON, else 0), 0, the buffer space (20000) and 0s. Samples go out
 * every 5 ms, as many as are due at the commanded rate.
 *
 * Faults for tests and demos: `dropConnections()`, `inject(bytes)` (bytes between two samples),
 * `truncate()` (half a sample, then the connection drops), `skip(n)` (the counter jumps by n).
 *
 * Pure Node (node:net); used by the tests and by `mosaic simulate quattrocento`.
 */
import { createServer, type AddressInfo, type Server, type Socket } from "node:net";
import { crc8Table } from "./muovi-simulator";
import { PacedSampleStream, type PacedSource } from "./paced-sample-stream";

export const QUATTROCENTO_PORT = 23456;
export const QUATTROCENTO_RATES = [512, 2048, 5120, 10240] as const;
export const QUATTROCENTO_CHANNEL_COUNTS = [120, 216, 312, 408] as const;
export const COMMAND_BYTES = 40;
const AUX = 16;
const ACCESSORY = 8;
/** Accessory channel 2 while the trigger is high, and accessory channel 4 (free buffer bytes). */
export const TRIGGER_HIGH = 31767;
export const BUFFER_SPACE = 20000;
/** Bytes a client may leave unread before samples to it are dropped (counted as skipped). */
const MAX_UNREAD = 16 << 20;

/** What a configuration command asks for. */
export interface QuattrocentoRequest {
  acquire: boolean;
  decimator: boolean;
  recording: boolean;
  rate: number;
  nch: number;
  channels: number;
  /** The 37 bytes after ACQ_SETT (analog output and the 12 inputs' configuration). */
  settings: number[];
}

/** Reads the 40-byte command at the start of `b`: the request, or why it is refused. */
export function readQuattrocentoCommand(
  b: Uint8Array,
): { request: QuattrocentoRequest } | { error: string } {
  if (b.length !== COMMAND_BYTES) return { error: `${b.length} bytes, not ${COMMAND_BYTES}` };
  const crc = crc8Table(b, COMMAND_BYTES - 1);
  if (crc !== b[COMMAND_BYTES - 1]) {
    return { error: `CRC-8 ${b[COMMAND_BYTES - 1]} where ${crc} was due` };
  }
  const acq = b[0]!;
  if (!(acq & 0x80)) return { error: `ACQ_SETT ${acq}: bit 7 must be 1` };
  if (b[1]! & 0xc0 || b[2]! & 0xc0) {
    return { error: `AN_OUT bytes ${b[1]}, ${b[2]}: bits 7 and 6 must be 0` };
  }
  if ((b[1]! & 0x0f) > 12) return { error: `AN_OUT_IN_SEL ${b[1]}: no input ${b[1]! & 0x0f}` };
  for (let i = 0; i < 12; i++) {
    const conf0 = b[3 + 3 * i]!;
    const conf2 = b[5 + 3 * i]!;
    if (conf0 & 0x80) return { error: `input ${i + 1} CONF0 ${conf0}: bit 7 must be 0` };
    if ((conf2 & 3) === 3) return { error: `input ${i + 1} CONF2 ${conf2}: MODE 11 is undefined` };
  }
  const nch = (acq >> 1) & 3;
  return {
    request: {
      acquire: (acq & 1) === 1,
      decimator: (acq & 0x40) !== 0,
      recording: (acq & 0x20) !== 0,
      rate: QUATTROCENTO_RATES[(acq >> 3) & 3]!,
      nch,
      channels: QUATTROCENTO_CHANNEL_COUNTS[nch]!,
      settings: [...b.subarray(1, COMMAND_BYTES - 1)],
    },
  };
}

/** 1024 steps of a sine, ±1, and 4096 values of seeded-looking noise in [-1, 1). */
const SINE = Float64Array.from({ length: 1024 }, (_, i) => Math.sin((2 * Math.PI * i) / 1024));
const NOISE = Float64Array.from({ length: 4096 }, (_, i) => {
  let h = Math.imul(i + 1, 0x9e3779b1);
  h = Math.imul(h ^ (h >>> 15), 0x85ebca6b);
  h ^= h >>> 13;
  return (h >>> 0) / 2 ** 31 - 1;
});

/** x rounded and clamped to int16 (| 0: never -0). */
const int16 = (x: number): number => Math.max(-32768, Math.min(32767, Math.round(x))) | 0;

/**
 * Channel `channel` of sample k for NCH code `nch`, as the int16 on the wire (the counter as
 * its two's complement): see the file comment. `trigger` is the REC_ON state.
 */
export function quattrocentoRaw(
  seed: number,
  nch: number,
  channel: number,
  k: number,
  trigger = false,
): number {
  const channels = QUATTROCENTO_CHANNEL_COUNTS[nch]!;
  const acc = channel - (channels - ACCESSORY);
  if (acc >= 0) {
    if (acc === 0) return ((k & 0xffff) << 16) >> 16;
    if (acc === 1) return trigger ? TRIGGER_HIGH : 0;
    return acc === 3 ? BUFFER_SPACE : 0;
  }
  if (channel >= channels - ACCESSORY - AUX) {
    const a = channel - (channels - ACCESSORY - AUX);
    return int16(2000 * SINE[(k * (1 + a) + 64 * seed) & 1023]!);
  }
  const amp = 400 + 60 * ((channel + seed) % 13);
  const step = 3 + (channel % 29);
  const sine = amp * SINE[(k * step + 37 * channel) & 1023]!;
  const noise = 300 * NOISE[(k * 13 + 977 * channel + 101 * seed) & 4095]!;
  return int16(sine + noise);
}

/** Writes n samples from k0 (int16 little-endian). */
function encode(seed: number, req: QuattrocentoRequest, k0: number, n: number): Buffer {
  const C = req.channels;
  const b = Buffer.alloc(n * C * 2);
  let at = 0;
  for (let k = k0; k < k0 + n; k++) {
    for (let ch = 0; ch < C; ch++, at += 2) {
      b.writeInt16LE(quattrocentoRaw(seed, req.nch, ch, k, req.recording), at);
    }
  }
  return b;
}

/** The samples of a stream whose request may change (REC_ON) without restarting it. */
class QuattrocentoSource implements PacedSource {
  readonly packetSamples = 1;
  constructor(
    readonly seed: number,
    public req: QuattrocentoRequest,
  ) {}

  get rate(): number {
    return this.req.rate;
  }

  encode(k0: number, n: number): Buffer {
    return encode(this.seed, this.req, k0, n);
  }
}

type Stream = PacedSampleStream<QuattrocentoSource>;

export interface QuattrocentoSimulatorOptions {
  /** Address to listen on (default 127.0.0.1). */
  host?: string;
  /** Port; 0 picks a free one (tests). Default 23456. */
  port?: number;
  /** Seed of the signals (default 1). */
  seed?: number;
  /** Called with one line for what happens (connections, commands), for the CLI. */
  log?: (line: string) => void;
}

/** A Quattrocento (see the file comment). */
export class QuattrocentoSimulator {
  readonly seed: number;
  readonly host: string;
  /** Commands that started or changed a stream, in order, and the reasons of refused ones. */
  readonly commands: QuattrocentoRequest[] = [];
  readonly refused: string[] = [];
  /** Stop commands received. */
  stops = 0;
  private readonly streams = new Set<Stream>();
  private readonly sockets = new Set<Socket>();
  private readonly log: (line: string) => void;

  private constructor(
    private readonly server: Server,
    o: QuattrocentoSimulatorOptions,
  ) {
    this.seed = o.seed ?? 1;
    this.host = o.host ?? "127.0.0.1";
    this.log = o.log ?? (() => {});
  }

  static async start(o: QuattrocentoSimulatorOptions = {}): Promise<QuattrocentoSimulator> {
    const server = createServer();
    const sim = new QuattrocentoSimulator(server, o);
    server.on("connection", (s) => sim.accept(s));
    await listenOn(server, sim.host, o.port ?? QUATTROCENTO_PORT);
    return sim;
  }

  get port(): number {
    return (this.server.address() as AddressInfo).port;
  }

  /** Samples sent by the newest stream since it started. */
  get samples(): number {
    let n = 0;
    for (const s of this.streams) n = s.samples;
    return n;
  }

  /** Whether a stream is running now. */
  get streaming(): boolean {
    for (const s of this.streams) if (s.running) return true;
    return false;
  }

  get clients(): number {
    return this.sockets.size;
  }

  private accept(s: Socket): void {
    s.setNoDelay(true);
    this.sockets.add(s);
    this.log(`client connected from ${s.remoteAddress}:${s.remotePort}`);
    let stream: Stream | undefined;
    let pending = Buffer.alloc(0);
    s.on("close", () => {
      stream?.stop();
      if (stream) this.streams.delete(stream);
      this.sockets.delete(s);
      this.log("client disconnected");
    });
    s.on("error", () => s.destroy());
    s.on("data", (d: Buffer) => {
      pending = Buffer.concat([pending, d]);
      while (pending.length >= COMMAND_BYTES) {
        const r = readQuattrocentoCommand(new Uint8Array(pending.subarray(0, COMMAND_BYTES)));
        pending = pending.subarray(COMMAND_BYTES);
        if ("error" in r) {
          this.refused.push(r.error);
          this.log(`refused a command (ignored): ${r.error}`);
          continue;
        }
        stream = this.apply(s, stream, r.request);
      }
    });
  }

  /** A valid command on this socket: start, change or stop its stream. */
  private apply(
    s: Socket,
    stream: Stream | undefined,
    req: QuattrocentoRequest,
  ): Stream | undefined {
    if (!req.acquire) {
      stream?.stop();
      this.stops++;
      this.log("acquisition off: streaming stopped");
      return stream;
    }
    const same =
      stream?.running && stream.source.req.rate === req.rate && stream.source.req.nch === req.nch;
    this.commands.push(req);
    if (same) {
      stream!.source.req = req;
      this.log(`acquisition on, same rate and channels (REC_ON ${req.recording ? 1 : 0})`);
      return stream;
    }
    stream?.stop();
    if (stream) this.streams.delete(stream);
    const next = new PacedSampleStream(s, new QuattrocentoSource(this.seed, req), {
      pumpMs: 5,
      maxUnread: MAX_UNREAD,
    });
    this.streams.add(next);
    next.start();
    this.log(
      `acquisition on: streaming ${req.channels} channels at ${req.rate} Hz${req.decimator ? " (decimator on)" : ""}${req.recording ? ", REC_ON" : ""}`,
    );
    return next;
  }

  /** Every client's connection drops (as a Quattrocento switched off and on). */
  dropConnections(): void {
    for (const s of this.sockets) s.destroy();
  }

  /** These bytes go out between two samples of the next write of every stream. */
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

async function listenOn(server: Server, host: string, port: number): Promise<void> {
  await new Promise<void>((resolve, reject) => {
    server.once("error", (e: NodeJS.ErrnoException) =>
      reject(
        new Error(
          e.code === "EADDRINUSE"
            ? `port ${port} on ${host} is already in use (EADDRINUSE): is a Quattrocento simulator running? Choose another port`
            : `cannot listen on ${host}:${port}: ${e.message}`,
        ),
      ),
    );
    server.listen({ host, port, exclusive: true }, resolve);
  });
  server.on("error", () => {});
}

type OptionValues = Record<string, string | boolean | undefined>;

/** `mosaic simulate quattrocento`'s options, checked. */
export function quattrocentoSimulatorOptions(v: OptionValues): QuattrocentoSimulatorOptions {
  const int = (name: string, fallback: number, max: number): number => {
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
  };
  return {
    host: typeof v.host === "string" ? v.host : "127.0.0.1",
    port: int("port", QUATTROCENTO_PORT, 65535),
    seed: int("seed", 1, 2 ** 31 - 1),
  };
}
