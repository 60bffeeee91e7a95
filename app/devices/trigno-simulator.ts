/**
 * A Delsys Trigno Control Utility (TCU) SDK server, simulated from the protocol as public clients
 * use it (docs/protocols.md, "Delsys Trigno"): a command port (ASCII commands and replies, each
 * ended by "\r\n\r\n"; a banner on connect), the Avanti EMG data port (16 sensor slots × float32
 * little-endian, interleaved sensor by sensor, volts) and the AUX port (144 float32 per sample:
 * 16 × 9 IMU values). Once `START`ed it streams one frame every 13.5 ms: 26 EMG samples (1925.926
 * Hz, backwards compatibility off) or 27 (2000 Hz, backwards compatibility on), and 2 AUX samples
 * (148.148 Hz); unpaired slots are zeros.
 *
 * The values are deterministic: `trignoEmgValue(seed, sensor, k)` is sample k (from 0 at START)
 * of a sensor, a sine per sensor plus seeded noise, rounded to float32 as it goes on the wire, so
 * tests compare bit for bit. Faults for tests and demos: `dropConnections()` (as a TCU that
 * crashed and came back), `injectEmg(bytes)` / `injectAux(bytes)` (malformed bytes between two
 * samples), `truncate()`
 * (half a sample, then the connections drop).
 *
 * Pure Node (node:net); used by the tests and by `mosaic simulate delsys`.
 */
import { createServer, type AddressInfo, type Server, type Socket } from "node:net";

/** The TCU's default ports (configurable in its GUI). */
export const TCU_PORTS = { command: 50040, emg: 50043, aux: 50044 } as const;
export const TCU_SLOTS = 16;
export const TCU_AUX_PER_SLOT = 9;
/** Seconds between two frames of the TCU's stream. */
export const TCU_FRAME_INTERVAL = 0.0135;
/** EMG samples per frame: native (backwards compatibility off) and backwards compatible. */
export const TCU_EMG_SAMPLES = { native: 26, compatible: 27 } as const;
export const TCU_AUX_SAMPLES = 2;
const TERM = "\r\n\r\n";
/** Bytes a client may leave unread before frames to it are dropped. */
const MAX_UNREAD = 4 << 20;
const BANNER = "Delsys Trigno System Digital Protocol Version 3.6.0 (MOSAIC simulator)";

export interface TrignoSimulatorOptions {
  /** Address to listen on (default 127.0.0.1). */
  host?: string;
  /** Ports; 0 picks a free one (tests). Defaults: the TCU's 50040, 50043, 50044. */
  commandPort?: number;
  emgPort?: number;
  auxPort?: number;
  /** Paired sensors: a count N (sensors 1…N) or the sensor numbers (1…16). Default 16. */
  sensors?: number | readonly number[];
  /** Seed of the signals (default 1). */
  seed?: number;
  /** Called with one line for what happens (connections, commands), for the CLI. */
  log?: (line: string) => void;
}

/** A 32-bit integer hash of (seed, sensor, k): the seeded noise, random access. */
function hash3(seed: number, a: number, b: number): number {
  let h = Math.imul(seed ^ 0x9e3779b9, 0x85ebca6b) ^ Math.imul(a + 1, 0xc2b2ae35);
  h = Math.imul(h ^ (h >>> 16), 0x7feb352d) ^ Math.imul(b, 0x846ca68b);
  h = Math.imul(h ^ (h >>> 15), 0x846ca68b);
  return (h ^ (h >>> 16)) >>> 0;
}

/**
 * Sample k (0 at START) of sensor `sensor` (1…16) as the simulator sends it, in volts: a sine of
 * 0.1–0.4 mV at 20 + 7·sensor Hz plus uniform noise of ±0.05 mV, rounded to float32. The rate is
 * the native one (1925.926 Hz) whatever the mode, so a value depends on (seed, sensor, k) only.
 */
export function trignoEmgValue(seed: number, sensor: number, k: number): number {
  const rate = TCU_EMG_SAMPLES.native / TCU_FRAME_INTERVAL;
  const amp = 1e-4 * (1 + ((sensor - 1) % 4));
  const sine = amp * Math.sin((2 * Math.PI * (20 + 7 * sensor) * k) / rate + sensor);
  const noise = 5e-5 * (hash3(seed, sensor, k) / 2 ** 31 - 1);
  return Math.fround(sine + noise);
}

/** AUX value `channel` (0…8) of sensor `sensor` at AUX sample k: a slow sine, float32. */
export function trignoAuxValue(seed: number, sensor: number, channel: number, k: number): number {
  return Math.fround(
    Math.sin((2 * Math.PI * 0.5 * k) / (TCU_AUX_SAMPLES / TCU_FRAME_INTERVAL) + channel + seed) *
      (channel < 3 ? 1 : 100) +
      sensor / 100,
  );
}

/** Sensor numbers from a count or a list, checked. */
export function pairedSensors(sensors: number | readonly number[] | undefined): number[] {
  const list =
    sensors === undefined
      ? range(TCU_SLOTS)
      : typeof sensors === "number"
        ? range(sensors)
        : [...sensors];
  for (const s of list) {
    if (!Number.isInteger(s) || s < 1 || s > TCU_SLOTS) {
      throw new Error(`sensor ${s} is not a Trigno sensor number (1…${TCU_SLOTS})`);
    }
  }
  return list;
}

function range(n: number): number[] {
  if (!Number.isInteger(n) || n < 0 || n > TCU_SLOTS) {
    throw new Error(`a Trigno base pairs 0…${TCU_SLOTS} sensors, not ${n}`);
  }
  return Array.from({ length: n }, (_, i) => i + 1);
}

/** One listening port and its connected clients. */
class Port {
  readonly clients = new Set<Socket>();
  constructor(readonly server: Server) {}
  get port(): number {
    return (this.server.address() as AddressInfo).port;
  }
  /** Writes to every client that reads (one that stopped reading loses frames, as over Wi-Fi). */
  write(b: Buffer): void {
    for (const c of this.clients) {
      if (!c.destroyed && c.writableLength < MAX_UNREAD) c.write(b);
    }
  }
  drop(): void {
    for (const c of this.clients) c.destroy();
    this.clients.clear();
  }
}

async function listen(host: string, port: number, onSocket: (s: Socket) => void): Promise<Port> {
  const server = createServer();
  const p = new Port(server);
  server.on("connection", (s: Socket) => {
    s.setNoDelay(true);
    p.clients.add(s);
    s.on("close", () => p.clients.delete(s));
    s.on("error", () => s.destroy());
    onSocket(s);
  });
  await new Promise<void>((resolve, reject) => {
    server.once("error", (e: NodeJS.ErrnoException) =>
      reject(
        new Error(
          e.code === "EADDRINUSE"
            ? `port ${port} on ${host} is already in use (EADDRINUSE): is a Trigno Control Utility or another simulator running? Choose other ports`
            : `cannot listen on ${host}:${port}: ${e.message}`,
        ),
      ),
    );
    server.listen({ host, port, exclusive: true }, resolve);
  });
  server.on("error", () => {}); // after listening: nothing to report (clients fail on their own)
  return p;
}

export class TrignoSimulator {
  readonly seed: number;
  readonly host: string;
  /** Paired sensor numbers. */
  readonly paired: ReadonlySet<number>;
  private backwardsCompatible = false;
  private upsample = false;
  private streaming = false;
  private timer: ReturnType<typeof setTimeout> | undefined;
  private startedAt = 0;
  private frames = 0;
  /** EMG samples sent per slot since the last START. */
  emgSamples = 0;
  auxSamples = 0;
  /** Commands received, in order (tests read them). */
  readonly commands: string[] = [];
  private closed = false;

  private constructor(
    private readonly command: Port,
    private readonly emg: Port,
    private readonly aux: Port,
    o: TrignoSimulatorOptions,
    private readonly log: (line: string) => void,
  ) {
    this.seed = o.seed ?? 1;
    this.host = o.host ?? "127.0.0.1";
    this.paired = new Set(pairedSensors(o.sensors));
  }

  /** Listens on the three ports; rejects with a clear message when one is taken. */
  static async start(o: TrignoSimulatorOptions = {}): Promise<TrignoSimulator> {
    pairedSensors(o.sensors);
    const host = o.host ?? "127.0.0.1";
    const log = o.log ?? (() => {});
    let sim: TrignoSimulator | undefined;
    const opened: Port[] = [];
    try {
      const command = await listen(host, o.commandPort ?? TCU_PORTS.command, (s) =>
        sim ? sim.onCommandClient(s) : s.destroy(),
      );
      opened.push(command);
      const emg = await listen(host, o.emgPort ?? TCU_PORTS.emg, (s) =>
        log(`EMG client ${s.remoteAddress}:${s.remotePort} connected`),
      );
      opened.push(emg);
      const aux = await listen(host, o.auxPort ?? TCU_PORTS.aux, (s) =>
        log(`AUX client ${s.remoteAddress}:${s.remotePort} connected`),
      );
      opened.push(aux);
      sim = new TrignoSimulator(command, emg, aux, o, log);
      return sim;
    } catch (e) {
      for (const p of opened) p.server.close();
      throw e;
    }
  }

  get ports(): { command: number; emg: number; aux: number } {
    return { command: this.command.port, emg: this.emg.port, aux: this.aux.port };
  }

  /** EMG samples per 13.5 ms frame in the current mode. */
  get samplesPerFrame(): number {
    return this.backwardsCompatible ? TCU_EMG_SAMPLES.compatible : TCU_EMG_SAMPLES.native;
  }

  /** EMG rate in the current mode, Hz. */
  get rate(): number {
    return this.samplesPerFrame / TCU_FRAME_INTERVAL;
  }

  get started(): boolean {
    return this.streaming;
  }

  /** Clients connected to each port now. */
  get clients(): { command: number; emg: number; aux: number } {
    return {
      command: this.command.clients.size,
      emg: this.emg.clients.size,
      aux: this.aux.clients.size,
    };
  }

  private onCommandClient(s: Socket): void {
    this.log(`command client ${s.remoteAddress}:${s.remotePort} connected`);
    s.write(BANNER + TERM);
    let text = "";
    s.setEncoding("latin1");
    s.on("data", (chunk: string) => {
      text += chunk;
      for (let end = text.indexOf(TERM); end >= 0; end = text.indexOf(TERM)) {
        const cmd = text.slice(0, end).trim();
        text = text.slice(end + TERM.length);
        this.commands.push(cmd);
        const reply = this.answer(cmd);
        this.log(`${cmd} → ${reply}`);
        if (!s.destroyed) s.write(reply + TERM);
        if (cmd.toUpperCase() === "QUIT") s.end();
      }
      if (text.length > 4096) {
        s.write("INVALID COMMAND" + TERM);
        text = "";
      }
    });
  }

  /** The reply to one command (without the terminator). */
  answer(command: string): string {
    const c = command.toUpperCase().replace(/\s+/g, " ").trim();
    const sensor = /^SENSOR (\d+) (.+)$/.exec(c);
    if (sensor) return this.answerSensor(Number(sensor[1]), sensor[2]!);
    switch (c) {
      case "START":
        this.startStream();
        return "OK";
      case "STOP":
        this.stopStream();
        return "OK";
      case "QUIT":
        return "BYE";
      case "MASTER":
        return "NEW MASTER";
      case "BACKWARDS COMPATIBILITY ON":
      case "BACKWARDS COMPATIBILITY OFF":
      case "UPSAMPLE ON":
      case "UPSAMPLE OFF": {
        if (this.streaming) return "CANNOT COMPLETE: STOP FIRST";
        const on = c.endsWith(" ON");
        if (c.startsWith("UPSAMPLE")) this.upsample = on;
        else this.backwardsCompatible = on;
        return "OK";
      }
      case "BACKWARDS COMPATIBILITY?":
        return this.backwardsCompatible ? "ON" : "OFF";
      case "UPSAMPLING?":
      case "UPSAMPLE?":
        return this.upsample ? "ON" : "OFF";
      case "FRAME INTERVAL?":
        return String(TCU_FRAME_INTERVAL);
      case "MAX SAMPLES EMG":
      case "MAX SAMPLES EMG?":
        return String(this.samplesPerFrame);
      case "MAX SAMPLES AUX":
      case "MAX SAMPLES AUX?":
        return String(TCU_AUX_SAMPLES);
      case "RATE?":
        return this.rate.toFixed(3);
      case "ENDIANNESS?":
        return "LITTLE";
      default:
        return "INVALID COMMAND";
    }
  }

  private answerSensor(n: number, what: string): string {
    if (n < 1 || n > TCU_SLOTS) return "INVALID SENSOR NUMBER";
    const paired = this.paired.has(n);
    switch (what) {
      case "PAIRED?":
        return paired ? "YES" : "NO";
      case "TYPE?":
        return paired ? "O" : "INVALID SENSOR";
      case "EMGCHANNELCOUNT?":
        return paired ? "1" : "0";
      case "AUXCHANNELCOUNT?":
        return paired ? String(TCU_AUX_PER_SLOT) : "0";
      case "RATE?":
        return paired ? this.rate.toFixed(3) : "INVALID SENSOR";
      default:
        return "INVALID COMMAND";
    }
  }

  private startStream(): void {
    if (this.streaming) return;
    this.streaming = true;
    this.startedAt = performance.now();
    this.frames = 0;
    this.emgSamples = 0;
    this.auxSamples = 0;
    this.schedule();
  }

  private stopStream(): void {
    this.streaming = false;
    if (this.timer !== undefined) clearTimeout(this.timer);
    this.timer = undefined;
  }

  /** Sends every frame due (a late timer catches up) and waits for the next one. */
  private schedule(): void {
    if (!this.streaming) return;
    const period = TCU_FRAME_INTERVAL * 1000;
    const now = performance.now();
    while (this.startedAt + (this.frames + 1) * period <= now) {
      this.sendFrame();
      this.frames++;
    }
    const next = this.startedAt + (this.frames + 1) * period;
    this.timer = setTimeout(() => this.schedule(), Math.max(0, next - performance.now()));
  }

  /** One EMG frame and one AUX frame. */
  private sendFrame(): void {
    const n = this.samplesPerFrame;
    const emg = Buffer.alloc(n * TCU_SLOTS * 4);
    for (let i = 0; i < n; i++) {
      const k = this.emgSamples + i;
      for (let s = 1; s <= TCU_SLOTS; s++) {
        const v = this.paired.has(s) ? trignoEmgValue(this.seed, s, k) : 0;
        emg.writeFloatLE(v, (i * TCU_SLOTS + s - 1) * 4);
      }
    }
    this.emgSamples += n;
    this.emg.write(emg);
    const perSample = TCU_SLOTS * TCU_AUX_PER_SLOT;
    const aux = Buffer.alloc(TCU_AUX_SAMPLES * perSample * 4);
    for (let i = 0; i < TCU_AUX_SAMPLES; i++) {
      const k = this.auxSamples + i;
      for (let s = 1; s <= TCU_SLOTS; s++) {
        if (!this.paired.has(s)) continue;
        for (let c = 0; c < TCU_AUX_PER_SLOT; c++) {
          const at = (i * perSample + (s - 1) * TCU_AUX_PER_SLOT + c) * 4;
          aux.writeFloatLE(trignoAuxValue(this.seed, s, c, k), at);
        }
      }
    }
    this.auxSamples += TCU_AUX_SAMPLES;
    this.aux.write(aux);
  }

  /** Fault: every client connection drops at once and streaming stops (a TCU that crashed). */
  dropConnections(): void {
    this.stopStream();
    this.command.drop();
    this.emg.drop();
    this.aux.drop();
    this.log("dropped every connection");
  }

  /** Fault: raw bytes on the EMG port now, between two samples (misaligns the stream). */
  injectEmg(bytes: Uint8Array): void {
    this.emg.write(Buffer.from(bytes));
  }

  /** Fault: raw bytes on the AUX port now, between two samples (misaligns the stream). */
  injectAux(bytes: Uint8Array): void {
    this.aux.write(Buffer.from(bytes));
  }

  /** Fault: half of one EMG sample, then every connection drops (a sample cut short). */
  truncate(): void {
    const half = Buffer.alloc((TCU_SLOTS * 4) / 2);
    this.emg.write(half);
    // Let the half sample leave before the connections go.
    setTimeout(() => this.dropConnections(), 20);
  }

  /** Stops streaming, drops the clients and closes the ports. */
  async close(): Promise<void> {
    if (this.closed) return;
    this.closed = true;
    this.dropConnections();
    await Promise.all(
      [this.command, this.emg, this.aux].map(
        (p) => new Promise<void>((r) => p.server.close(() => r())),
      ),
    );
  }
}
