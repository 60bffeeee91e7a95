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

export function createBleBridge(options: BleBridgeOptions = {}): BleBridge {
  const load = options.load ?? loadNoble;
  const connectTimeoutMs = options.connectTimeoutMs ?? 10_000;
  let lib: NobleLoad | undefined;
  let state: BleAdapterState = "unknown";
  let message: string | undefined;
  const watchers = new Set<(s: BleAdapterState, m?: string) => void>();
  const scans = new Set<{
    services: Set<string>;
    seen: Set<string>;
    onFound: (p: BlePeripheral) => void;
    onError: (m: string) => void;
  }>();
  const peripherals = new Map<string, NoblePeripheral>();
  let scanning = false;

  const setState = (s: BleAdapterState, m?: string): void => {
    state = s;
    message = m;
    for (const w of [...watchers]) w(s, m);
    if (s === "poweredOn") updateScan();
    else scanning = false;
  };

  const onDiscover = (p: NoblePeripheral): void => {
    const address = p.address && p.address !== "unknown" ? p.address.toLowerCase() : p.id;
    peripherals.set(keyOf(address), p);
    const services = (p.advertisement?.serviceUuids ?? []).map(uuidOf);
    const info: BlePeripheral = {
      address,
      services,
      ...(p.advertisement?.localName ? { name: p.advertisement.localName } : {}),
      ...(typeof p.rssi === "number" ? { rssi: p.rssi } : {}),
    };
    for (const s of [...scans]) {
      if (s.seen.has(address)) continue;
      if (s.services.size > 0 && !services.some((u) => s.services.has(u))) continue;
      s.seen.add(address);
      s.onFound(info);
    }
  };

  /** Noble, loaded and watched on first use; undefined (state `unavailable`) when it cannot be. */
  const noble = (): NobleLike | undefined => {
    if (!lib) {
      lib = load();
      if ("error" in lib) {
        setState("unavailable", lib.error);
      } else {
        const n = lib.noble;
        n.on("warning", (w: string) => {
          // Noble reports a failed adapter initialisation (bind) as a warning.
          if (/^Initialization/.test(w))
            setState("unavailable", describeBleError(w.replace(/^Initialization[^:]*: /, "")));
        });
        n.on("discover", onDiscover);
        n.on("stateChange", (s: string) => {
          const known = STATES.has(s as BleAdapterState);
          setState(known ? (s as BleAdapterState) : "unknown", known ? undefined : s);
        });
      }
    }
    return "noble" in lib ? lib.noble : undefined;
  };

  const updateScan = (): void => {
    const n = lib && "noble" in lib ? lib.noble : undefined;
    if (!n) return;
    const want = scans.size > 0 && state === "poweredOn";
    if (want === scanning) return;
    scanning = want;
    // Unfiltered with duplicates: several scans share noble's one scan and filter here, and each
    // sees peripherals that another scan found before it started.
    const op = want ? n.startScanningAsync([], true) : n.stopScanningAsync();
    op.catch((e: unknown) => {
      if (!want) return;
      scanning = false;
      for (const s of [...scans]) s.onError(`scan failed: ${describeBleError(e)}`);
    });
  };

  return {
    watchState(onChange) {
      noble();
      watchers.add(onChange);
      onChange(state, message);
      return {
        close: () => {
          watchers.delete(onChange);
        },
      };
    },

    scan(o) {
      const s = {
        services: new Set(o.services.map(uuidOf)),
        seen: new Set<string>(),
        onFound: o.onFound,
        onError: o.onError,
      };
      scans.add(s);
      if (!noble()) o.onError(message ?? "Bluetooth LE unavailable");
      else updateScan();
      return {
        stop: () => {
          if (scans.delete(s)) updateScan();
        },
      };
    },

    async connect(address, onDisconnect) {
      if (!noble()) throw new Error(message ?? "Bluetooth LE unavailable");
      const p = peripherals.get(keyOf(address));
      if (!p) throw new Error(`${address} has not been found by a scan`);
      let timer: ReturnType<typeof setTimeout> | undefined;
      try {
        await Promise.race([
          p.connectAsync(),
          new Promise<never>((_, reject) => {
            timer = setTimeout(() => {
              p.cancelConnect?.();
              reject(new Error(`no answer within ${connectTimeoutMs / 1000} s`));
            }, connectTimeoutMs);
          }),
        ]);
      } finally {
        clearTimeout(timer);
      }
      return openConnection(p, address, onDisconnect);
    },
  };
}

function openConnection(
  p: NoblePeripheral,
  address: string,
  onDisconnect: (reason: string) => void,
): BleConnection {
  let closed = false;
  const chars = new Map<string, NobleCharacteristic>();
  const listeners: { c: NobleCharacteristic; fn: (d: Buffer) => void }[] = [];
  const detach = (): void => {
    for (const { c, fn } of listeners.splice(0)) c.removeListener("data", fn);
  };
  const lost = (reason?: unknown): void => {
    if (closed) return;
    closed = true;
    detach();
    onDisconnect(typeof reason === "string" && reason !== "" ? reason : "the link was lost");
  };
  p.once("disconnect", lost);
  const find = (service: string, uuid: string): NobleCharacteristic => {
    const c = chars.get(`${uuidOf(service)}/${uuidOf(uuid)}`);
    if (!c) throw new Error(`characteristic ${uuid} of service ${service} not discovered`);
    return c;
  };
  return {
    address,
    async discover(services) {
      const r = await p.discoverSomeServicesAndCharacteristicsAsync(services.map(uuidOf), []);
      const out: BleCharacteristic[] = [];
      for (const s of r.services) {
        for (const c of s.characteristics ?? []) {
          chars.set(`${uuidOf(s.uuid)}/${uuidOf(c.uuid)}`, c);
          out.push({
            service: uuidOf(s.uuid),
            uuid: uuidOf(c.uuid),
            properties: [...c.properties],
          });
        }
      }
      return out;
    },
    async subscribe(service, uuid, onData) {
      const c = find(service, uuid);
      const fn = (d: Buffer): void => {
        if (!closed) onData(new Uint8Array(d.buffer, d.byteOffset, d.byteLength));
      };
      c.on("data", fn);
      listeners.push({ c, fn });
      await c.subscribeAsync();
    },
    async write(service, uuid, data, withoutResponse = false) {
      if (closed) throw new Error("disconnected");
      await find(service, uuid).writeAsync(Buffer.from(data), withoutResponse);
    },
    disconnect() {
      if (closed) return;
      closed = true;
      detach();
      p.removeListener("disconnect", lost);
      p.disconnectAsync().catch(() => {});
    },
  };
}
