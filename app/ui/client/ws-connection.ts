/**
 * The UI protocol over a WebSocket to a Node host (`mosaic serve`): the page's URL carries the
 * session token, the socket is `ws(s)://<same host>/ws?token=…`. Messages are JSON with typed
 * arrays and non-finite numbers kept (app/engine/protocol-wire.ts). Messages sent before the
 * socket opens are queued; when it closes the UI is told with an error event and `onLost` with its
 * cause in words (a refusal by the host — wrong token, foreign page — names why: connection-status.ts).
 */
import type { EngineConnection, EngineMessage, UiMessage } from "../../engine/protocol";
import { decodeWire, encodeWire } from "../../engine/protocol-wire";
import { explainClose, type ConnectionLoss } from "./connection-status";

/** The minimal WebSocket surface used (the browser's, or `ws` in tests). */
export interface SocketLike {
  readonly readyState: number;
  send(data: string): void;
  close(): void;
  onopen: ((ev: unknown) => void) | null;
  onmessage: ((ev: { data: unknown }) => void) | null;
  onclose: ((ev: { code: number; reason: string }) => void) | null;
  onerror: ((ev: unknown) => void) | null;
}

/** The socket URL for a page served by `mosaic serve` (null when the page has no token). */
export function hostSocketUrl(page: { href: string }): string | null {
  const u = new URL(page.href);
  const token = u.searchParams.get("token");
  if (!token) return null;
  const ws = new URL("/ws", u);
  ws.protocol = u.protocol === "https:" ? "wss:" : "ws:";
  ws.search = "";
  ws.searchParams.set("token", token);
  return ws.href;
}

/** A connection to `mosaic serve` that also tells why it ended. */
export interface HostConnection extends EngineConnection {
  /** Why the socket closed (undefined while it is open or opening). */
  readonly lost: ConnectionLoss | undefined;
  /** Called once when the socket closes, with its cause; returns the unsubscribe. */
  onLost(h: (loss: ConnectionLoss) => void): () => void;
}

export function wsConnection(socket: SocketLike): HostConnection {
  const handlers = new Set<(m: EngineMessage) => void>();
  const lostHandlers = new Set<(loss: ConnectionLoss) => void>();
  const queue: string[] = [];
  let open = socket.readyState === 1;
  let opened = open;
  let lost: ConnectionLoss | undefined;
  const emit = (m: EngineMessage): void => {
    for (const h of handlers) h(m);
  };
  socket.onopen = () => {
    open = true;
    opened = true;
    for (const q of queue.splice(0)) socket.send(q);
  };
  socket.onmessage = (ev) => {
    if (typeof ev.data !== "string") return;
    let m: unknown;
    try {
      m = decodeWire(ev.data);
    } catch {
      return;
    }
    emit(m as EngineMessage);
  };
  socket.onclose = (ev) => {
    open = false;
    lost = explainClose(ev.code, ev.reason, opened);
    emit({
      type: "event",
      event: { t: Date.now() / 1000, level: "error", block: "engine", message: lost.message },
    });
    for (const h of lostHandlers) h(lost);
  };
  socket.onerror = () => {};
  return {
    get lost() {
      return lost;
    },
    onLost(h) {
      lostHandlers.add(h);
      return () => lostHandlers.delete(h);
    },
    send(msg: UiMessage) {
      const text = encodeWire(msg);
      if (open) socket.send(text);
      else queue.push(text);
    },
    onMessage(h) {
      handlers.add(h);
      return () => handlers.delete(h);
    },
    close() {
      handlers.clear();
      lostHandlers.clear();
      socket.close();
    },
  };
}
