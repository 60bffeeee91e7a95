/**
 * Bluetooth LE for engine workers, run by the host's main thread. Noble's HCI binding cannot run
 * in a worker thread (it polls on the default libuv loop: see ble.ts), so an engine worker gets a
 * proxy `BleBridge` that forwards every call to the main thread, where a hub runs the real bridge
 * and sends states, peripherals found, notifications and results back. Both ends are plain
 * functions over a `post` callback, testable without threads (like serial-proxy.ts).
 */
import type {
  BleAdapterState,
  BleBridge,
  BleCharacteristic,
  BleConnection,
  BlePeripheral,
} from "../app/engine/io";
import { createBleBridge } from "./ble";

/** Worker → main thread. `conn` is the id of the `connect` request that opened the connection. */
export type BleRequest =
  | { type: "ble"; op: "watch"; id: number }
  | { type: "ble"; op: "unwatch"; id: number }
  | { type: "ble"; op: "scan"; id: number; services: string[] }
  | { type: "ble"; op: "stopScan"; id: number }
  | { type: "ble"; op: "connect"; id: number; address: string }
  | { type: "ble"; op: "discover"; id: number; conn: number; services: string[] }
  | {
      type: "ble";
      op: "subscribe";
      id: number;
      conn: number;
      service: string;
      characteristic: string;
    }
  | {
      type: "ble";
      op: "write";
      id: number;
      conn: number;
      service: string;
      characteristic: string;
      data: Uint8Array;
      withoutResponse: boolean;
    }
  | { type: "ble"; op: "disconnect"; conn: number };

/** Main thread → worker. */
export type BleReply =
  | { type: "ble"; op: "state"; id: number; state: BleAdapterState; message?: string }
  | { type: "ble"; op: "found"; id: number; peripheral: BlePeripheral }
  | { type: "ble"; op: "scanError"; id: number; message: string }
  | { type: "ble"; op: "result"; id: number; ok: true; characteristics?: BleCharacteristic[] }
  | { type: "ble"; op: "result"; id: number; ok: false; error: string }
  | { type: "ble"; op: "data"; id: number; data: Uint8Array }
  | { type: "ble"; op: "disconnected"; conn: number; reason: string };

/** A `BleRequest` of one `op`. */
type RequestOf<O extends BleRequest["op"]> = Extract<BleRequest, { op: O }>;
/** A `BleReply` of one `op`. */
type ReplyOf<O extends BleReply["op"]> = Extract<BleReply, { op: O }>;

/** The worker's side: a `BleBridge` whose adapter lives on the main thread. */
export function bleProxy(post: (m: BleRequest) => void): {
  bridge: BleBridge;
  receive(m: BleReply): void;
} {
  const proxy = new BleProxy(post);
  return {
    bridge: {
      watchState: (onChange) => proxy.watchState(onChange),
      scan: (o) => proxy.scan(o),
      connect: (address, onDisconnect) => proxy.connect(address, onDisconnect),
    },
    receive: (m) => proxy.receive(m),
  };
}

/** The worker's end of the relay: the callbacks and calls waiting for the main thread, by id. */
class BleProxy {
  private next = 1;
  private readonly watchers = new Map<number, (s: BleAdapterState, m?: string) => void>();
  private readonly scans = new Map<
    number,
    { onFound: (p: BlePeripheral) => void; onError: (m: string) => void }
  >();
  /** Requests waiting for their `result`. */
  private readonly pending = new Map<
    number,
    { resolve: (c?: BleCharacteristic[]) => void; reject: (e: Error) => void }
  >();
  /** Notification callbacks by the id of their `subscribe` request. */
  private readonly notifications = new Map<
    number,
    { conn: number; onData: (d: Uint8Array) => void }
  >();
  /** The `onDisconnect` of each open connection. */
  private readonly connections = new Map<number, (reason: string) => void>();

  constructor(private readonly post: (m: BleRequest) => void) {}

  watchState(onChange: (s: BleAdapterState, m?: string) => void): { close(): void } {
    const id = this.next++;
    this.watchers.set(id, onChange);
    this.post({ type: "ble", op: "watch", id });
    return {
      close: () => {
        if (this.watchers.delete(id)) this.post({ type: "ble", op: "unwatch", id });
      },
    };
  }

  scan(o: Parameters<BleBridge["scan"]>[0]): { stop(): void } {
    const id = this.next++;
    this.scans.set(id, { onFound: o.onFound, onError: o.onError });
    this.post({ type: "ble", op: "scan", id, services: [...o.services] });
    return {
      stop: () => {
        if (this.scans.delete(id)) this.post({ type: "ble", op: "stopScan", id });
      },
    };
  }

  async connect(address: string, onDisconnect: (reason: string) => void): Promise<BleConnection> {
    const id = this.next++;
    this.connections.set(id, onDisconnect);
    try {
      await this.call({ type: "ble", op: "connect", id, address });
    } catch (e) {
      this.connections.delete(id);
      throw e;
    }
    return this.connection(id, address);
  }

  receive(m: BleReply): void {
    switch (m.op) {
      case "state":
        this.watchers.get(m.id)?.(m.state, m.message);
        break;
      case "found":
        this.scans.get(m.id)?.onFound(m.peripheral);
        break;
      case "scanError":
        this.scans.get(m.id)?.onError(m.message);
        break;
      case "result":
        this.settle(m);
        break;
      case "data":
        this.notifications.get(m.id)?.onData(m.data);
        break;
      case "disconnected":
        this.lost(m);
        break;
    }
  }

  /** Resolves or rejects the request this `result` answers. */
  private settle(m: ReplyOf<"result">): void {
    const p = this.pending.get(m.id);
    this.pending.delete(m.id);
    if (!p) return;
    if (m.ok) p.resolve(m.characteristics);
    else p.reject(new Error(m.error));
  }

  /** The main thread lost a connection: forgets it, then tells its owner. */
  private lost(m: ReplyOf<"disconnected">): void {
    const lost = this.connections.get(m.conn);
    this.forget(m.conn);
    lost?.(m.reason);
  }

  /** Posts a request and waits for its `result`. */
  private call(m: BleRequest & { id: number }): Promise<BleCharacteristic[] | undefined> {
    return new Promise((resolve, reject) => {
      this.pending.set(m.id, { resolve, reject });
      this.post(m);
    });
  }

  /** Drops a connection and its notification callbacks. */
  private forget(conn: number): void {
    this.connections.delete(conn);
    for (const [id, n] of this.notifications) if (n.conn === conn) this.notifications.delete(id);
  }

  /** The worker's handle on connection `conn` (the id of its `connect` request). */
  private connection(conn: number, address: string): BleConnection {
    return {
      address,
      discover: (services) => this.discover(conn, services),
      subscribe: (service, characteristic, onData) =>
        this.subscribe(conn, service, characteristic, onData),
      write: (service, characteristic, data, withoutResponse) =>
        this.write(conn, service, characteristic, data, withoutResponse),
      disconnect: () => this.disconnect(conn),
    };
  }

  private async discover(conn: number, services: readonly string[]): Promise<BleCharacteristic[]> {
    const id = this.next++;
    return (
      (await this.call({ type: "ble", op: "discover", id, conn, services: [...services] })) ?? []
    );
  }

  private async subscribe(
    conn: number,
    service: string,
    characteristic: string,
    onData: (d: Uint8Array) => void,
  ): Promise<void> {
    const id = this.next++;
    this.notifications.set(id, { conn, onData });
    await this.call({ type: "ble", op: "subscribe", id, conn, service, characteristic });
  }

  private async write(
    conn: number,
    service: string,
    characteristic: string,
    data: Uint8Array,
    withoutResponse = false,
  ): Promise<void> {
    const id = this.next++;
    await this.call({
      type: "ble",
      op: "write",
      id,
      conn,
      service,
      characteristic,
      data: data.slice(),
      withoutResponse,
    });
  }

  private disconnect(conn: number): void {
    if (!this.connections.has(conn)) return;
    this.forget(conn);
    this.post({ type: "ble", op: "disconnect", conn });
  }
}

/** The main thread's side: runs the real bridge for one worker. */
export function bleHub(
  post: (m: BleReply) => void,
  bridge: BleBridge = createBleBridge(),
): { receive(m: BleRequest): void; closeAll(): void } {
  const hub = new BleHub(post, bridge);
  return { receive: (m) => hub.receive(m), closeAll: () => hub.closeAll() };
}

/** The main thread's end of the relay: the real bridge's watches, scans and connections, by id. */
class BleHub {
  private readonly watches = new Map<number, { close(): void }>();
  private readonly scans = new Map<number, { stop(): void }>();
  private readonly connections = new Map<number, BleConnection>();
  /** Connections asked to close while their `connect` was still pending. */
  private readonly dropped = new Set<number>();
  private closed = false;

  constructor(
    private readonly post: (m: BleReply) => void,
    private readonly bridge: BleBridge,
  ) {}

  receive(m: BleRequest): void {
    switch (m.op) {
      case "watch":
        this.watch(m);
        break;
      case "unwatch":
        this.watches.get(m.id)?.close();
        this.watches.delete(m.id);
        break;
      case "scan":
        this.scan(m);
        break;
      case "stopScan":
        this.scans.get(m.id)?.stop();
        this.scans.delete(m.id);
        break;
      case "connect":
        this.connect(m);
        break;
      case "discover":
        this.settleOn(m.id, m.conn, (c) => c.discover(m.services));
        break;
      case "subscribe":
        this.settleOn(m.id, m.conn, (c) =>
          c.subscribe(m.service, m.characteristic, (data) =>
            // A copy of just these bytes: noble's buffer may be a slice of a larger one.
            this.post({ type: "ble", op: "data", id: m.id, data: data.slice() }),
          ),
        );
        break;
      case "write":
        this.settleOn(m.id, m.conn, (c) =>
          c.write(m.service, m.characteristic, m.data, m.withoutResponse),
        );
        break;
      case "disconnect":
        this.disconnect(m.conn);
        break;
    }
  }

  closeAll(): void {
    this.closed = true;
    for (const w of this.watches.values()) w.close();
    for (const s of this.scans.values()) s.stop();
    for (const c of this.connections.values()) c.disconnect();
    this.watches.clear();
    this.scans.clear();
    this.connections.clear();
  }

  /** Watches the adapter's state, posting every state to the worker. */
  private watch(m: RequestOf<"watch">): void {
    this.watches.set(
      m.id,
      this.bridge.watchState((state, message) =>
        this.post({
          type: "ble",
          op: "state",
          id: m.id,
          state,
          ...(message === undefined ? {} : { message }),
        }),
      ),
    );
  }

  /** Starts a scan (replacing one of the same id), posting what it finds and its errors. */
  private scan(m: RequestOf<"scan">): void {
    this.scans.get(m.id)?.stop();
    this.scans.set(
      m.id,
      this.bridge.scan({
        services: m.services,
        onFound: (peripheral) => this.post({ type: "ble", op: "found", id: m.id, peripheral }),
        onError: (message) => this.post({ type: "ble", op: "scanError", id: m.id, message }),
      }),
    );
  }

  /** Connects; the connection is known by the request's id, and a lost link is posted. */
  private connect(m: RequestOf<"connect">): void {
    this.settle(
      m.id,
      this.bridge
        .connect(m.address, (reason) => {
          this.connections.delete(m.id);
          this.post({ type: "ble", op: "disconnected", conn: m.id, reason });
        })
        .then((c) => this.opened(m.id, c)),
    );
  }

  /** Keeps a new connection, or closes it if the worker (or `closeAll`) dropped it meanwhile. */
  private opened(id: number, c: BleConnection): void {
    if (this.closed || this.dropped.delete(id)) {
      c.disconnect();
      throw new Error("disconnected");
    }
    this.connections.set(id, c);
  }

  private disconnect(conn: number): void {
    const c = this.connections.get(conn);
    if (c) {
      this.connections.delete(conn);
      c.disconnect();
    } else {
      this.dropped.add(conn);
    }
  }

  /** Runs `op` on connection `conn` a microtask later and posts its result (`not connected`). */
  private settleOn(
    id: number,
    conn: number,
    op: (c: BleConnection) => Promise<BleCharacteristic[] | void>,
  ): void {
    this.settle(
      id,
      Promise.resolve().then(() => op(this.connectionOf(conn))),
    );
  }

  /** Posts the `result` of request `id` when `op` settles. */
  private settle(id: number, op: Promise<BleCharacteristic[] | void>): void {
    op.then(
      (c) =>
        this.post({
          type: "ble",
          op: "result",
          id,
          ok: true,
          ...(Array.isArray(c) ? { characteristics: c } : {}),
        }),
      (e: unknown) =>
        this.post({
          type: "ble",
          op: "result",
          id,
          ok: false,
          error: (e as Error)?.message ?? String(e),
        }),
    );
  }

  private connectionOf(id: number): BleConnection {
    const c = this.connections.get(id);
    if (!c) throw new Error("not connected");
    return c;
  }
}
