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

/** The worker's side: a `BleBridge` whose adapter lives on the main thread. */
export function bleProxy(post: (m: BleRequest) => void): {
  bridge: BleBridge;
  receive(m: BleReply): void;
} {
  let next = 1;
  const watchers = new Map<number, (s: BleAdapterState, m?: string) => void>();
  const scans = new Map<
    number,
    { onFound: (p: BlePeripheral) => void; onError: (m: string) => void }
  >();
  const pending = new Map<
    number,
    { resolve: (c?: BleCharacteristic[]) => void; reject: (e: Error) => void }
  >();
  const notifications = new Map<number, { conn: number; onData: (d: Uint8Array) => void }>();
  const connections = new Map<number, (reason: string) => void>();

  const call = (m: BleRequest & { id: number }): Promise<BleCharacteristic[] | undefined> =>
    new Promise((resolve, reject) => {
      pending.set(m.id, { resolve, reject });
      post(m);
    });

  const forget = (conn: number): void => {
    connections.delete(conn);
    for (const [id, n] of notifications) if (n.conn === conn) notifications.delete(id);
  };

  const connection = (conn: number, address: string): BleConnection => ({
    address,
    async discover(services) {
      const id = next++;
      return (await call({ type: "ble", op: "discover", id, conn, services: [...services] })) ?? [];
    },
    async subscribe(service, characteristic, onData) {
      const id = next++;
      notifications.set(id, { conn, onData });
      await call({ type: "ble", op: "subscribe", id, conn, service, characteristic });
    },
    async write(service, characteristic, data, withoutResponse = false) {
      const id = next++;
      await call({
        type: "ble",
        op: "write",
        id,
        conn,
        service,
        characteristic,
        data: data.slice(),
        withoutResponse,
      });
    },
    disconnect() {
      if (!connections.has(conn)) return;
      forget(conn);
      post({ type: "ble", op: "disconnect", conn });
    },
  });

  return {
    bridge: {
      watchState(onChange) {
        const id = next++;
        watchers.set(id, onChange);
        post({ type: "ble", op: "watch", id });
        return {
          close() {
            if (watchers.delete(id)) post({ type: "ble", op: "unwatch", id });
          },
        };
      },
      scan(o) {
        const id = next++;
        scans.set(id, { onFound: o.onFound, onError: o.onError });
        post({ type: "ble", op: "scan", id, services: [...o.services] });
        return {
          stop() {
            if (scans.delete(id)) post({ type: "ble", op: "stopScan", id });
          },
        };
      },
      async connect(address, onDisconnect) {
        const id = next++;
        connections.set(id, onDisconnect);
        try {
          await call({ type: "ble", op: "connect", id, address });
        } catch (e) {
          connections.delete(id);
          throw e;
        }
        return connection(id, address);
      },
    },
    receive(m) {
      switch (m.op) {
        case "state":
          watchers.get(m.id)?.(m.state, m.message);
          break;
        case "found":
          scans.get(m.id)?.onFound(m.peripheral);
          break;
        case "scanError":
          scans.get(m.id)?.onError(m.message);
          break;
        case "result": {
          const p = pending.get(m.id);
          pending.delete(m.id);
          if (!p) break;
          if (m.ok) p.resolve(m.characteristics);
          else p.reject(new Error(m.error));
          break;
        }
        case "data":
          notifications.get(m.id)?.onData(m.data);
          break;
        case "disconnected": {
          const lost = connections.get(m.conn);
          forget(m.conn);
          lost?.(m.reason);
          break;
        }
      }
    },
  };
}

/** The main thread's side: runs the real bridge for one worker. */
export function bleHub(
  post: (m: BleReply) => void,
  bridge: BleBridge = createBleBridge(),
): { receive(m: BleRequest): void; closeAll(): void } {
  const watches = new Map<number, { close(): void }>();
  const scans = new Map<number, { stop(): void }>();
  const connections = new Map<number, BleConnection>();
  /** Connections asked to close while their `connect` was still pending. */
  const dropped = new Set<number>();
  let closed = false;

  const settle = (id: number, op: Promise<BleCharacteristic[] | void>): void => {
    op.then(
      (c) =>
        post({
          type: "ble",
          op: "result",
          id,
          ok: true,
          ...(Array.isArray(c) ? { characteristics: c } : {}),
        }),
      (e: unknown) =>
        post({
          type: "ble",
          op: "result",
          id,
          ok: false,
          error: (e as Error)?.message ?? String(e),
        }),
    );
  };
  const conn = (id: number): BleConnection => {
    const c = connections.get(id);
    if (!c) throw new Error("not connected");
    return c;
  };

  return {
    receive(m) {
      switch (m.op) {
        case "watch":
          watches.set(
            m.id,
            bridge.watchState((state, message) =>
              post({
                type: "ble",
                op: "state",
                id: m.id,
                state,
                ...(message === undefined ? {} : { message }),
              }),
            ),
          );
          break;
        case "unwatch":
          watches.get(m.id)?.close();
          watches.delete(m.id);
          break;
        case "scan":
          scans.get(m.id)?.stop();
          scans.set(
            m.id,
            bridge.scan({
              services: m.services,
              onFound: (peripheral) => post({ type: "ble", op: "found", id: m.id, peripheral }),
              onError: (message) => post({ type: "ble", op: "scanError", id: m.id, message }),
            }),
          );
          break;
        case "stopScan":
          scans.get(m.id)?.stop();
          scans.delete(m.id);
          break;
        case "connect":
          settle(
            m.id,
            bridge
              .connect(m.address, (reason) => {
                connections.delete(m.id);
                post({ type: "ble", op: "disconnected", conn: m.id, reason });
              })
              .then((c) => {
                if (closed || dropped.delete(m.id)) {
                  c.disconnect();
                  throw new Error("disconnected");
                }
                connections.set(m.id, c);
              }),
          );
          break;
        case "discover":
          settle(
            m.id,
            Promise.resolve().then(() => conn(m.conn).discover(m.services)),
          );
          break;
        case "subscribe":
          settle(
            m.id,
            Promise.resolve().then(() =>
              conn(m.conn).subscribe(m.service, m.characteristic, (data) =>
                // A copy of just these bytes: noble's buffer may be a slice of a larger one.
                post({ type: "ble", op: "data", id: m.id, data: data.slice() }),
              ),
            ),
          );
          break;
        case "write":
          settle(
            m.id,
            Promise.resolve().then(() =>
              conn(m.conn).write(m.service, m.characteristic, m.data, m.withoutResponse),
            ),
          );
          break;
        case "disconnect": {
          const c = connections.get(m.conn);
          if (c) {
            connections.delete(m.conn);
            c.disconnect();
          } else {
            dropped.add(m.conn);
          }
          break;
        }
      }
    },
    closeAll() {
      closed = true;
      for (const w of watches.values()) w.close();
      for (const s of scans.values()) s.stop();
      for (const c of connections.values()) c.disconnect();
      watches.clear();
      scans.clear();
      connections.clear();
    },
  };
}
