/**
 * Serial ports for engine workers, opened by the host's main thread. The `serialport` native
 * binding cannot run in a worker thread (it polls on the process's default libuv loop and then
 * calls into V8 from the wrong thread: serialport/node-serialport#2250, #2748), so an engine
 * worker gets a proxy bridge that forwards open/write/close to the main thread, where a hub runs
 * the real bridge and sends data and status back. Both ends are plain functions over a
 * `post` callback, testable without threads.
 */
import type { SerialBridge, SerialHandle, SerialOptions, SerialStatus } from "../app/engine/io";
import { createSerialBridge } from "./serial";

/** Worker → main thread. */
export type SerialRequest =
  | {
      type: "serial";
      op: "open";
      id: number;
      options: SerialOptions & { reconnectMs: number };
    }
  | { type: "serial"; op: "write"; id: number; data: Uint8Array }
  | { type: "serial"; op: "close"; id: number }
  | { type: "serial"; op: "list"; id: number };

/** Main thread → worker. */
export type SerialReply =
  | { type: "serial"; op: "data"; id: number; data: Uint8Array }
  | { type: "serial"; op: "status"; id: number; status: SerialStatus; message?: string }
  | { type: "serial"; op: "list"; id: number; ports: { path: string; manufacturer?: string }[] };

/** The worker's side: a `SerialBridge` whose ports live on the main thread. */
export function serialProxy(post: (m: SerialRequest) => void): {
  bridge: SerialBridge;
  receive(m: SerialReply): void;
} {
  let next = 1;
  const ports = new Map<
    number,
    { onData: (d: Uint8Array) => void; onStatus: (s: SerialStatus, m?: string) => void }
  >();
  const lists = new Map<number, (p: { path: string; manufacturer?: string }[]) => void>();
  return {
    bridge: {
      open(o): SerialHandle {
        const id = next++;
        ports.set(id, { onData: o.onData, onStatus: o.onStatus });
        const { onData: _d, onStatus: _s, ...options } = o;
        post({ type: "serial", op: "open", id, options });
        return {
          write(data) {
            if (ports.has(id)) post({ type: "serial", op: "write", id, data: data.slice() });
          },
          close() {
            if (!ports.has(id)) return;
            post({ type: "serial", op: "close", id });
            ports.delete(id);
            o.onStatus("closed");
          },
        };
      },
      list() {
        const id = next++;
        return new Promise((resolve) => {
          lists.set(id, resolve);
          post({ type: "serial", op: "list", id });
        });
      },
    },
    receive(m) {
      if (m.op === "list") {
        lists.get(m.id)?.(m.ports);
        lists.delete(m.id);
        return;
      }
      const p = ports.get(m.id);
      if (!p) return;
      if (m.op === "data") p.onData(m.data);
      else p.onStatus(m.status, m.message);
    },
  };
}

/** The main thread's side: runs the real bridge for one worker. */
export function serialHub(
  post: (m: SerialReply) => void,
  bridge: SerialBridge = createSerialBridge(),
): { receive(m: SerialRequest): void; closeAll(): Promise<void> } {
  const handles = new Map<number, SerialHandle>();
  // Ports closed and still sending their last writes: closeAll waits for them too.
  const closing = new Set<Promise<void>>();
  const close = (h: SerialHandle | undefined): void => {
    if (!h) return;
    h.close();
    const c = h.closed?.();
    if (!c) return;
    closing.add(c);
    void c.then(() => closing.delete(c));
  };
  return {
    receive(m) {
      switch (m.op) {
        case "open":
          close(handles.get(m.id));
          handles.set(
            m.id,
            bridge.open({
              ...m.options,
              // A copy of just these bytes: the binding's buffer may be a slice of a larger one.
              onData: (data) => post({ type: "serial", op: "data", id: m.id, data: data.slice() }),
              onStatus: (status, message) =>
                post({
                  type: "serial",
                  op: "status",
                  id: m.id,
                  status,
                  ...(message === undefined ? {} : { message }),
                }),
            }),
          );
          break;
        case "write":
          handles.get(m.id)?.write(m.data);
          break;
        case "close":
          close(handles.get(m.id));
          handles.delete(m.id);
          break;
        case "list":
          void bridge
            .list()
            .catch(() => [])
            .then((ports) => post({ type: "serial", op: "list", id: m.id, ports }));
          break;
      }
    },
    /** Closes every port; resolves once each has sent what was written to it (or given up). */
    async closeAll() {
      for (const h of handles.values()) close(h);
      handles.clear();
      await Promise.all(closing);
    },
  };
}
