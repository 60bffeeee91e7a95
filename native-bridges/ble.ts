/**
 * The Bluetooth LE bridge for Node hosts (`ctx.io.ble`, MOSAIC's BluetoothLEManager), on
 * `@abandonware/noble`. Noble is loaded on first use, never at import: on Linux its HCI binding
 * opens a Bluetooth socket as the module loads, and that throws where the kernel has no Bluetooth
 * (EAFNOSUPPORT) or there is no adapter (ENODEV). The bridge then reports the adapter state
 * `unavailable` with the reason ("no Bluetooth adapter (…)") and the host goes on.
 *
 * Noble cannot run in an engine worker thread: the HCI binding polls its socket on the process's
 * default libuv loop (`uv_poll_init(uv_default_loop(), …)` in bluetooth-hci-socket's
 * BluetoothHciSocket.cpp) and calls back into JavaScript from there, i.e. on the main thread, into
 * the worker's isolate — the same fault as serialport's. Hosts therefore run this bridge on their
 * main thread and give engine workers the relay of ble-proxy.ts.
 */
import { createRequire } from "node:module";
import type {
  BleAdapterState,
  BleBridge,
  BleCharacteristic,
  BleConnection,
  BlePeripheral,
} from "../app/engine/io";

/** The parts of noble's API this bridge uses. */
export interface NobleLike {
  readonly state: string;
  on(event: "stateChange", fn: (state: string) => void): unknown;
  on(event: "discover", fn: (p: NoblePeripheral) => void): unknown;
  on(event: "warning", fn: (message: string) => void): unknown;
  removeListener(event: string, fn: (...a: never[]) => void): unknown;
  startScanningAsync(services?: string[], allowDuplicates?: boolean): Promise<void>;
  stopScanningAsync(): Promise<void>;
}

export interface NoblePeripheral {
  readonly id: string;
  readonly address: string;
  readonly rssi?: number;
  readonly advertisement?: { localName?: string; serviceUuids?: string[] };
  connectAsync(): Promise<void>;
  disconnectAsync(): Promise<void>;
  cancelConnect?(): void;
  discoverSomeServicesAndCharacteristicsAsync(
    services: string[],
    characteristics: string[],
  ): Promise<{ services: NobleService[] }>;
  once(event: "disconnect", fn: (reason?: unknown) => void): unknown;
  removeListener(event: "disconnect", fn: (reason?: unknown) => void): unknown;
}

export interface NobleService {
  readonly uuid: string;
  readonly characteristics?: NobleCharacteristic[];
}

export interface NobleCharacteristic {
  readonly uuid: string;
  readonly properties: string[];
  on(event: "data", fn: (data: Buffer, isNotification: boolean) => void): unknown;
  removeListener(event: "data", fn: (data: Buffer, isNotification: boolean) => void): unknown;
  subscribeAsync(): Promise<void>;
  writeAsync(data: Buffer, withoutResponse: boolean): Promise<void>;
}

export type NobleLoad = { noble: NobleLike } | { error: string };

/** A UUID in noble's form (lower case, no dashes). */
const uuidOf = (u: string): string => u.replace(/-/g, "").toLowerCase();
/** An address as a key: lower case, no separators. */
const keyOf = (a: string): string => a.replace(/[:-]/g, "").toLowerCase();

/** Why Bluetooth LE cannot be used, in words, from the error noble (or its binding) threw. */
export function describeBleError(e: unknown): string {
  const err = e as { code?: string; message?: string };
  const m = String(err?.message ?? e).replace(/^Error: /, "");
  const code = err?.code ?? /\b(E[A-Z]+)\b/.exec(m)?.[1];
  if (code === "MODULE_NOT_FOUND" || /Cannot find module/.test(m))
    return "Bluetooth LE driver missing (the @abandonware/noble module is not installed)";
  if (code === "EAFNOSUPPORT")
    return `no Bluetooth adapter (this system has no Bluetooth support: ${m})`;
  if (code === "ENODEV") return `no Bluetooth adapter (${m})`;
  if (code === "EPERM" || code === "EACCES")
    return (
      `no permission to use the Bluetooth adapter (${m}): on Linux give node the CAP_NET_RAW ` +
      "capability (sudo setcap cap_net_raw+eip $(readlink -f $(which node)))"
    );
  return `Bluetooth LE unavailable (${m})`;
}

/** Loads noble now (the first time it is asked for); a failure is reported, never thrown. */
export function loadNoble(): NobleLoad {
  try {
    const require = createRequire(import.meta.url);
    return { noble: require("@abandonware/noble") as NobleLike };
  } catch (e) {
    return { error: describeBleError(e) };
  }
}

/** Options of `createBleBridge` (tests inject a fake noble). */
export interface BleBridgeOptions {
  load?: () => NobleLoad;
  /** Milliseconds a connection attempt may take (default 10 s). */
  connectTimeoutMs?: number;
}

const STATES = new Set<BleAdapterState>([
  "unknown",
  "resetting",
  "unsupported",
  "unauthorized",
  "poweredOff",
  "poweredOn",
]);

/** One `scan` of a bridge: its filter, the addresses it has reported, and its callbacks. */
interface Scan {
  services: Set<string>;
  seen: Set<string>;
  onFound: (p: BlePeripheral) => void;
  onError: (m: string) => void;
}

/** The bridge on noble, which it loads on first use (a `watchState`, `scan` or `connect`). */
export function createBleBridge(options: BleBridgeOptions = {}): BleBridge {
  const bridge = new NobleBridge(options.load ?? loadNoble, options.connectTimeoutMs ?? 10_000);
  return {
    watchState: (onChange) => bridge.watchState(onChange),
    scan: (o) => bridge.scan(o),
    connect: (address, onDisconnect) => bridge.connect(address, onDisconnect),
  };
}

/**
 * The bridge's state: noble (once loaded), the adapter state, the scans sharing noble's one scan,
 * and the peripherals found (by address key) that `connect` may connect to.
 */
class NobleBridge {
  private lib: NobleLoad | undefined;
  private state: BleAdapterState = "unknown";
  private message: string | undefined;
  private readonly watchers = new Set<(s: BleAdapterState, m?: string) => void>();
  private readonly scans = new Set<Scan>();
  private readonly peripherals = new Map<string, NoblePeripheral>();
  /** Noble's scan is running (or starting). */
  private scanning = false;

  constructor(
    private readonly load: () => NobleLoad,
    private readonly connectTimeoutMs: number,
  ) {}

  watchState(onChange: (s: BleAdapterState, m?: string) => void): { close(): void } {
    this.noble();
    this.watchers.add(onChange);
    onChange(this.state, this.message);
    return {
      close: () => {
        this.watchers.delete(onChange);
      },
    };
  }

  scan(o: Parameters<BleBridge["scan"]>[0]): { stop(): void } {
    const s: Scan = {
      services: new Set(o.services.map(uuidOf)),
      seen: new Set<string>(),
      onFound: o.onFound,
      onError: o.onError,
    };
    this.scans.add(s);
    if (!this.noble()) o.onError(this.message ?? "Bluetooth LE unavailable");
    else this.updateScan();
    return {
      stop: () => {
        if (this.scans.delete(s)) this.updateScan();
      },
    };
  }

  async connect(address: string, onDisconnect: (reason: string) => void): Promise<BleConnection> {
    if (!this.noble()) throw new Error(this.message ?? "Bluetooth LE unavailable");
    const p = this.peripherals.get(keyOf(address));
    if (!p) throw new Error(`${address} has not been found by a scan`);
    let timer: ReturnType<typeof setTimeout> | undefined;
    try {
      await Promise.race([
        p.connectAsync(),
        new Promise<never>((_, reject) => {
          timer = setTimeout(() => {
            p.cancelConnect?.();
            reject(new Error(`no answer within ${this.connectTimeoutMs / 1000} s`));
          }, this.connectTimeoutMs);
        }),
      ]);
    } finally {
      clearTimeout(timer);
    }
    return openConnection(p, address, onDisconnect);
  }

  /** Noble, loaded and watched on first use; undefined (state `unavailable`) when it cannot be. */
  private noble(): NobleLike | undefined {
    if (!this.lib) {
      const lib = this.load();
      this.lib = lib;
      if ("error" in lib) this.setState("unavailable", lib.error);
      else this.listen(lib.noble);
    }
    return "noble" in this.lib ? this.lib.noble : undefined;
  }

  /** Follows noble's adapter state, its failed initialisation and the peripherals it finds. */
  private listen(n: NobleLike): void {
    n.on("warning", (w: string) => {
      // Noble reports a failed adapter initialisation (bind) as a warning.
      if (/^Initialization/.test(w))
        this.setState("unavailable", describeBleError(w.replace(/^Initialization[^:]*: /, "")));
    });
    n.on("discover", (p: NoblePeripheral) => this.onDiscover(p));
    n.on("stateChange", (s: string) => {
      const known = STATES.has(s as BleAdapterState);
      this.setState(known ? (s as BleAdapterState) : "unknown", known ? undefined : s);
    });
  }

  /** Tells the watchers; noble's scan runs only while the adapter is on. */
  private setState(s: BleAdapterState, m?: string): void {
    this.state = s;
    this.message = m;
    for (const w of [...this.watchers]) w(s, m);
    if (s === "poweredOn") this.updateScan();
    else this.scanning = false;
  }

  /** Remembers a peripheral for `connect` and reports it to each scan that wants it, once. */
  private onDiscover(p: NoblePeripheral): void {
    const address = addressOf(p);
    this.peripherals.set(keyOf(address), p);
    const info = peripheralInfo(p, address);
    for (const s of [...this.scans]) {
      if (s.seen.has(address)) continue;
      if (s.services.size > 0 && !info.services.some((u) => s.services.has(u))) continue;
      s.seen.add(address);
      s.onFound(info);
    }
  }

  /** Starts or stops noble's scan: it runs while there are scans and the adapter is on. */
  private updateScan(): void {
    const n = this.lib && "noble" in this.lib ? this.lib.noble : undefined;
    if (!n) return;
    const want = this.scans.size > 0 && this.state === "poweredOn";
    if (want === this.scanning) return;
    this.scanning = want;
    // Unfiltered with duplicates: several scans share noble's one scan and filter here, and each
    // sees peripherals that another scan found before it started.
    const op = want ? n.startScanningAsync([], true) : n.stopScanningAsync();
    op.catch((e: unknown) => {
      if (!want) return;
      this.scanning = false;
      for (const s of [...this.scans]) s.onError(`scan failed: ${describeBleError(e)}`);
    });
  }
}

/** A peripheral's address (lower case), or noble's id of it where the OS hides the address. */
function addressOf(p: NoblePeripheral): string {
  return p.address && p.address !== "unknown" ? p.address.toLowerCase() : p.id;
}

/** What a scan reports of a peripheral: its address, advertised services, name and RSSI. */
function peripheralInfo(p: NoblePeripheral, address: string): BlePeripheral {
  return {
    address,
    services: (p.advertisement?.serviceUuids ?? []).map(uuidOf),
    ...(p.advertisement?.localName ? { name: p.advertisement.localName } : {}),
    ...(typeof p.rssi === "number" ? { rssi: p.rssi } : {}),
  };
}

/** The key of a characteristic in a connection's map: service and characteristic UUIDs. */
const charKey = (service: string, uuid: string): string => `${uuidOf(service)}/${uuidOf(uuid)}`;

/** The `BleConnection` of a peripheral just connected; a lost link calls `onDisconnect` once. */
function openConnection(
  p: NoblePeripheral,
  address: string,
  onDisconnect: (reason: string) => void,
): BleConnection {
  const link = new NobleLink(p, onDisconnect);
  return {
    address,
    discover: (services) => link.discover(services),
    subscribe: (service, uuid, onData) => link.subscribe(service, uuid, onData),
    write: (service, uuid, data, withoutResponse) =>
      link.write(service, uuid, data, withoutResponse),
    disconnect: () => link.disconnect(),
  };
}

/** One connection to a peripheral: the characteristics discovered and the notification listeners. */
class NobleLink {
  private closed = false;
  private readonly chars = new Map<string, NobleCharacteristic>();
  private readonly listeners: { c: NobleCharacteristic; fn: (d: Buffer) => void }[] = [];

  /** The peripheral's `disconnect` listener: a link lost, not asked for. */
  private readonly lost = (reason?: unknown): void => {
    if (this.closed) return;
    this.closed = true;
    this.detach();
    this.onDisconnect(typeof reason === "string" && reason !== "" ? reason : "the link was lost");
  };

  constructor(
    private readonly p: NoblePeripheral,
    private readonly onDisconnect: (reason: string) => void,
  ) {
    p.once("disconnect", this.lost);
  }

  async discover(services: readonly string[]): Promise<BleCharacteristic[]> {
    const r = await this.p.discoverSomeServicesAndCharacteristicsAsync(services.map(uuidOf), []);
    const out: BleCharacteristic[] = [];
    for (const s of r.services) {
      for (const c of s.characteristics ?? []) {
        this.chars.set(charKey(s.uuid, c.uuid), c);
        out.push({
          service: uuidOf(s.uuid),
          uuid: uuidOf(c.uuid),
          properties: [...c.properties],
        });
      }
    }
    return out;
  }

  async subscribe(service: string, uuid: string, onData: (d: Uint8Array) => void): Promise<void> {
    const c = this.find(service, uuid);
    const fn = (d: Buffer): void => {
      if (!this.closed) onData(new Uint8Array(d.buffer, d.byteOffset, d.byteLength));
    };
    c.on("data", fn);
    this.listeners.push({ c, fn });
    await c.subscribeAsync();
  }

  async write(
    service: string,
    uuid: string,
    data: Uint8Array,
    withoutResponse = false,
  ): Promise<void> {
    if (this.closed) throw new Error("disconnected");
    await this.find(service, uuid).writeAsync(Buffer.from(data), withoutResponse);
  }

  disconnect(): void {
    if (this.closed) return;
    this.closed = true;
    this.detach();
    this.p.removeListener("disconnect", this.lost);
    this.p.disconnectAsync().catch(() => {});
  }

  private detach(): void {
    for (const { c, fn } of this.listeners.splice(0)) c.removeListener("data", fn);
  }

  private find(service: string, uuid: string): NobleCharacteristic {
    const c = this.chars.get(charKey(service, uuid));
    if (!c) throw new Error(`characteristic ${uuid} of service ${service} not discovered`);
    return c;
  }
}
