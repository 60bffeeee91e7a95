/**
 * A simulated NilsPod: a Bluetooth LE peripheral behind the host's `BleBridge` interface (this
 * machine, like most CI machines, has no Bluetooth adapter, so the simulator replaces the adapter
 * and the device together). Written from the protocol as docs/protocols.md ("NilsPod (BLE)")
 * states it, independently of the block's decoder: it advertises as "NilsPod-XXXX", offers the
 * streaming service (6e400001-…) with its command (6e400002-…, write and write without response)
 * and sample (6e400003-…, notify) characteristics, starts streaming on 0xC2, stops on 0xC1, and
 * notifies 14-byte samples (gyroscope x, y, z, accelerometer x, y, z as little-endian int16, a
 * little-endian uint16 counter) at its sampling rate, `samplesPerNotification` per notification.
 *
 * The signal is deterministic (`nilsPodSimRaw`): a forearm rolling ±60° every 4 s — gravity
 * turning in the accelerometer's y–z plane, the roll rate on the gyroscope's x axis — in raw
 * counts of ±16 g and ±2000 deg/s. Sample k carries counter k mod 2^16.
 *
 * Time: samples fall due at k / rate seconds after streaming started, on the clock `now` gives;
 * `pump()` sends every sample due. Tests pump on their virtual clock; `realtime: true` pumps every
 * 10 ms on the wall clock. Faults on demand: `drop()` (link lost, no advertising until
 * `recover()`), `malformed()`, `skip(n)` (the device skips samples: a counter gap),
 * `stall()` (connected but silent), `failNextConnect()`, `setAdapter()`.
 */
import type {
  BleAdapterState,
  BleBridge,
  BleCharacteristic,
  BleConnection,
  BlePeripheral,
} from "../engine/io";

const SERVICE = "6e400001b5a3f393e0a9e50e24dcca9e";
const COMMANDS = "6e400002b5a3f393e0a9e50e24dcca9e";
const SAMPLES = "6e400003b5a3f393e0a9e50e24dcca9e";
/** The configuration service (its characteristics are not simulated). */
const CONFIG_SERVICE = "98ff0000770d4a839e9bce6bbd75e472";
const START = 0xc2;
const STOP = 0xc1;
const SAMPLE_BYTES = 14;

/** Raw counts per g at ±16 g, per deg/s at ±2000 deg/s. */
const COUNTS_PER_G = 32768 / 16;
const COUNTS_PER_DPS = 32768 / 2000;

/**
 * The simulated device's raw int16 value `axis` (0–2 gyroscope x, y, z; 3–5 accelerometer x, y,
 * z, the wire's order) of sample `k` at `rate` Hz.
 */
export function nilsPodSimRaw(k: number, axis: number, rate: number): number {
  const period = 4;
  const amp = (60 * Math.PI) / 180;
  const w = (2 * Math.PI) / period;
  const t = k / rate;
  const theta = amp * Math.sin(w * t);
  const rollDps = (amp * w * Math.cos(w * t) * 180) / Math.PI;
  let v: number;
  switch (axis) {
    case 0:
      v = rollDps * COUNTS_PER_DPS;
      break;
    case 1:
      v = 3 * Math.sin(k); // a little sensor noise, deterministic
      break;
    case 2:
      v = -2;
      break;
    case 3:
      v = 5 * Math.cos(k);
      break;
    case 4:
      v = Math.sin(theta) * COUNTS_PER_G;
      break;
    default:
      v = Math.cos(theta) * COUNTS_PER_G;
  }
  return Math.max(-32768, Math.min(32767, Math.round(v))) + 0; // + 0: never -0
}

export interface NilsPodSimulatorOptions {
  /** Default "d4:22:cd:00:4e:01". */
  address?: string;
  /** Advertised name; default "NilsPod-4E01". */
  name?: string;
  /** Sampling rate (Hz); default 102.4 (a NilsPod rate). */
  rate?: number;
  /** Samples per notification; default 1 (a 20-byte payload holds one). */
  samplesPerNotification?: number;
  /** Seconds; default the wall clock. */
  now?: () => number;
  /** Pump every 10 ms on a timer (for demos); default false (call `pump()`). */
  realtime?: boolean;
  /** The adapter's state at first; default poweredOn. */
  adapter?: BleAdapterState;
}

interface Scan {
  services: Set<string>;
  seen: boolean;
  onFound: (p: BlePeripheral) => void;
}

/** The simulated adapter and NilsPod (see the file comment). */
export class NilsPodSimulator implements BleBridge {
  readonly address: string;
  readonly name: string;
  readonly rate: number;
  /** Every write to the device: "6e400002… c2" (characteristic, hex). */
  readonly writes: string[] = [];
  /** Index k of every sample sent, in order (the first million). */
  readonly sent: number[] = [];
  /** Notifications sent (malformed included), and connections accepted. */
  notifications = 0;
  connections = 0;
  /** Scans started by centrals. */
  scansStarted = 0;
  private readonly perNotification: number;
  private readonly now: () => number;
  private adapter: BleAdapterState;
  private readonly watchers = new Set<(s: BleAdapterState, m?: string) => void>();
  private readonly scans = new Set<Scan>();
  private advertising = true;
  private connectError = "";
  /** The connection up now, its subscriber and who hears of a loss. */
  private link:
    | { onDisconnect: (r: string) => void; onData?: (d: Uint8Array) => void; closed: boolean }
    | undefined;
  private streaming = false;
  private stalled = false;
  private startedAt = 0;
  /** Index of the next sample; samples since the start that were sent or skipped. */
  private k = 0;
  private due = 0;
  private timer: ReturnType<typeof setInterval> | undefined;

  constructor(o: NilsPodSimulatorOptions = {}) {
    this.address = o.address ?? "d4:22:cd:00:4e:01";
    this.name = o.name ?? "NilsPod-4E01";
    this.rate = o.rate ?? 102.4;
    this.perNotification = Math.max(1, Math.floor(o.samplesPerNotification ?? 1));
    this.now = o.now ?? (() => performance.now() / 1000);
    this.adapter = o.adapter ?? "poweredOn";
    if (o.realtime) this.timer = setInterval(() => this.pump(), 10);
  }

  get isStreaming(): boolean {
    return this.streaming;
  }

  get isConnected(): boolean {
    return this.link !== undefined;
  }

  // ---- BleBridge ----

  watchState(onChange: (state: BleAdapterState, message?: string) => void): { close(): void } {
    this.watchers.add(onChange);
    onChange(this.adapter);
    return { close: () => void this.watchers.delete(onChange) };
  }

  scan(o: {
    services: readonly string[];
    onFound: (peripheral: BlePeripheral) => void;
    onError: (message: string) => void;
  }): { stop(): void } {
    this.scansStarted++;
    const s: Scan = { services: new Set(o.services.map(norm)), seen: false, onFound: o.onFound };
    this.scans.add(s);
    if (this.adapter !== "poweredOn") {
      queueMicrotask(() => o.onError(`Bluetooth adapter ${this.adapter}`));
    } else queueMicrotask(() => this.advertise());
    return { stop: () => void this.scans.delete(s) };
  }

  async connect(address: string, onDisconnect: (reason: string) => void): Promise<BleConnection> {
    await Promise.resolve();
    if (norm(address) !== norm(this.address)) throw new Error(`${address} has not been found`);
    if (this.connectError !== "") {
      const m = this.connectError;
      this.connectError = "";
      throw new Error(m);
    }
    if (!this.advertising || this.adapter !== "poweredOn") throw new Error("no answer within 10 s");
    if (this.link) throw new Error(`${address} is connected to another central`);
    const link: NonNullable<NilsPodSimulator["link"]> = { onDisconnect, closed: false };
    this.link = link;
    this.connections++;
    return this.connection(link);
  }

  // ---- the device ----

  /** Sends every sample due by now; returns how many were sent. */
  pump(): number {
    if (!this.streaming || this.stalled || !this.link?.onData) return 0;
    const due = this.dueNow();
    let sent = 0;
    while (this.due + this.perNotification <= due) {
      this.notify(this.packet(this.perNotification));
      this.due += this.perNotification;
      sent += this.perNotification;
    }
    return sent;
  }

  /** The link is lost (out of range, switched off): the central hears `reason`. */
  drop(reason = "connection timeout"): void {
    this.advertising = false;
    const l = this.link;
    this.endLink();
    if (l && !l.closed) {
      l.closed = true;
      l.onDisconnect(reason);
    }
  }

  /** Back in range: advertising again (running scans find it). */
  recover(): void {
    this.advertising = true;
    this.advertise();
  }

  /** One notification of `bytes` bytes (not a whole number of samples). */
  malformed(bytes = 5): void {
    this.notify(new Uint8Array(bytes).fill(0xa5));
  }

  /**
   * The device stops sending while staying connected (`false`: it goes on with the samples due
   * then; those in between are never sent, and the counter jumps over them).
   */
  stall(stalled = true): void {
    if (this.stalled && !stalled) {
      const due = this.dueNow();
      this.k += due - this.due;
      this.due = due;
    }
    this.stalled = stalled;
  }

  /** The device skips `n` samples: they are never sent and the counter jumps over them. */
  skip(n: number): void {
    this.k += n;
  }

  /** The next `connect` fails with `message`. */
  failNextConnect(message: string): void {
    this.connectError = message;
  }

  setAdapter(state: BleAdapterState, message?: string): void {
    this.adapter = state;
    if (state !== "poweredOn") this.drop("the adapter went away");
    else this.advertising = true;
    for (const w of [...this.watchers]) w(state, message);
    if (state === "poweredOn") this.advertise();
  }

  /** Stops the realtime timer and the link. */
  close(): void {
    if (this.timer) clearInterval(this.timer);
    this.timer = undefined;
    this.endLink();
  }

  // ---- internals ----

  private advertise(): void {
    if (!this.advertising || this.link || this.adapter !== "poweredOn") return;
    const p: BlePeripheral = {
      address: this.address,
      name: this.name,
      rssi: -60,
      services: [SERVICE],
    };
    for (const s of [...this.scans]) {
      if (s.seen || !this.scans.has(s)) continue;
      if (s.services.size > 0 && !s.services.has(SERVICE)) continue;
      s.seen = true;
      s.onFound({ ...p, services: [...p.services] });
    }
  }

  private connection(link: NonNullable<NilsPodSimulator["link"]>): BleConnection {
    const alive = (): void => {
      if (link.closed) throw new Error("disconnected");
    };
    return {
      address: this.address,
      discover: async (services) => {
        await Promise.resolve();
        alive();
        const all: BleCharacteristic[] = [
          { service: SERVICE, uuid: COMMANDS, properties: ["write", "writeWithoutResponse"] },
          { service: SERVICE, uuid: SAMPLES, properties: ["notify"] },
          {
            service: CONFIG_SERVICE,
            uuid: "98ff0a0a770d4a839e9bce6bbd75e472",
            properties: ["read"],
          },
        ];
        const want = new Set(services.map(norm));
        return all.filter((c) => want.size === 0 || want.has(c.service));
      },
      subscribe: async (service, characteristic, onData) => {
        await Promise.resolve();
        alive();
        if (norm(service) !== SERVICE || norm(characteristic) !== SAMPLES) {
          throw new Error(`characteristic ${characteristic} does not notify`);
        }
        link.onData = onData;
      },
      write: async (service, characteristic, data) => {
        await Promise.resolve();
        alive();
        const hex = Array.from(data, (b) => b.toString(16).padStart(2, "0")).join("");
        this.writes.push(`${norm(characteristic)} ${hex}`);
        if (norm(service) !== SERVICE || norm(characteristic) !== COMMANDS) return;
        if (data.length === 1 && data[0] === START) this.start();
        else if (data.length === 1 && data[0] === STOP) this.streaming = false;
      },
      disconnect: () => {
        if (link.closed) return;
        link.closed = true;
        if (this.link === link) this.endLink();
      },
    };
  }

  /** Samples due since streaming started (sample 0 at the start). */
  private dueNow(): number {
    return Math.floor((this.now() - this.startedAt) * this.rate + 1e-9) + 1;
  }

  private start(): void {
    if (this.streaming) return;
    this.streaming = true;
    this.startedAt = this.now();
    this.due = 0;
  }

  private endLink(): void {
    this.streaming = false;
    this.link = undefined;
    queueMicrotask(() => this.advertise());
  }

  /** `n` consecutive samples from index k on. */
  private packet(n: number): Uint8Array {
    const bytes = new Uint8Array(n * SAMPLE_BYTES);
    const dv = new DataView(bytes.buffer);
    for (let s = 0; s < n; s++) {
      const k = this.k++;
      const at = s * SAMPLE_BYTES;
      for (let axis = 0; axis < 6; axis++) {
        dv.setInt16(at + 2 * axis, nilsPodSimRaw(k, axis, this.rate), true);
      }
      dv.setUint16(at + 12, k & 0xffff, true);
      if (this.sent.length < 1_000_000) this.sent.push(k);
    }
    return bytes;
  }

  private notify(bytes: Uint8Array): void {
    const l = this.link;
    if (!l?.onData || l.closed) return;
    this.notifications++;
    l.onData(bytes);
  }
}

const norm = (u: string): string => u.replace(/[-:]/g, "").toLowerCase();
