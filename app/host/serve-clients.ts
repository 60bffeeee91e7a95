/**
 * `mosaic serve`'s WebSocket clients (serve.ts accepts them): each one attached to the session
 * hub, and what waits on its socket watched. Slow clients are bounded as serve.ts describes:
 * their telemetry, panel data and events are dropped above `dropAboveBytes`, and a client too
 * slow or stalled is disconnected (close code 1008 and the reason).
 */
import type { WebSocket } from "ws";
import { errorMessage } from "../engine/diagnostics";
import { decodeWire, encodeWire } from "../engine/protocol-wire";
import type { SessionHub } from "./session-hub";

export interface SlowClientLimits {
  /** Bytes waiting on a client's socket above which its telemetry, data and events are dropped. */
  dropAboveBytes: number;
  /** Bytes waiting above which a client that sent nothing since the last look goes at once. */
  maxBufferedBytes: number;
  /** A client with more than `dropAboveBytes` waiting that sent none of it for this long goes. */
  stalledMs: number;
  /** How long a disconnected client has to read the close frame before its socket is destroyed. */
  closeGraceMs: number;
}

export const SLOW_CLIENT_LIMITS: Readonly<SlowClientLimits> = {
  dropAboveBytes: 256 * 1024,
  maxBufferedBytes: 32 * 1024 * 1024,
  stalledMs: 10_000,
  closeGraceMs: 2_000,
};

/** The WebSocket close code for a client too slow to keep (RFC 6455: policy violation). */
export const CLOSE_TOO_SLOW = 1008;

export interface ServeStats {
  clients: number;
  /** Bytes waiting on each client's socket. */
  waiting: number[];
  /** Messages left out for slow clients, by type. */
  dropped: { telemetry: number; data: number; event: number };
  /** Clients disconnected for being too slow, with the reason each was given. */
  disconnected: string[];
}

/**
 * Per socket: bytes handed to it, bytes it had sent at the last look (handed − waiting), when
 * it last sent any while bytes waited, and whether it is being disconnected.
 */
interface Watched {
  queued: number;
  sent: number;
  progressAt: number;
  left: boolean;
}

/** The message types a client that cannot keep up skips rather than queues. */
type BestEffort = keyof ServeStats["dropped"];

function isBestEffort(type: string): type is BestEffort {
  return type === "telemetry" || type === "data" || type === "event";
}

/**
 * The connected clients: what each was handed and has sent, looked at every 0.5 s (or a quarter
 * of `stalledMs`), and what slow ones were left out of or disconnected for.
 */
export class ServeClients {
  private readonly watch = new Map<WebSocket, Watched>();
  private readonly counts: Omit<ServeStats, "waiting"> = {
    clients: 0,
    dropped: { telemetry: 0, data: 0, event: 0 },
    disconnected: [],
  };
  private readonly sweep: NodeJS.Timeout;
  /** The hub hands the same message object to every client: encoded once, not once per tab. */
  private readonly encoded = new WeakMap<object, { text: string; bytes: number }>();

  constructor(
    private readonly hub: SessionHub,
    private readonly limits: SlowClientLimits,
    private readonly onProblem: ((message: string) => void) | undefined,
  ) {
    this.sweep = setInterval(() => this.lookAtAll(), Math.min(500, limits.stalledMs / 4));
    this.sweep.unref();
  }

  /** Connects a socket to the hub: the hub's messages go out to it, its messages in to the hub. */
  attach(ws: WebSocket): void {
    const w: Watched = { queued: 0, sent: 0, progressAt: Date.now(), left: false };
    this.watch.set(ws, w);
    this.counts.clients++;
    const conn = this.hub.connect({ send: (msg) => this.send(ws, w, msg) });
    ws.on("message", (data, isBinary) => {
      if (isBinary) return;
      const msg = decodeOrAnswer(ws, String(data));
      if (msg !== undefined) conn.receive(msg.value);
    });
    const gone = (): void => {
      if (!this.watch.delete(ws)) return;
      this.counts.clients--;
      conn.close();
    };
    ws.on("close", gone);
    ws.on("error", gone);
  }

  stats(): ServeStats {
    return {
      ...this.counts,
      waiting: [...this.watch.keys()].map((ws) => ws.bufferedAmount),
      dropped: { ...this.counts.dropped },
      disconnected: [...this.counts.disconnected],
    };
  }

  /** Stops looking at the clients (the sockets are the server's to close). */
  stop(): void {
    clearInterval(this.sweep);
  }

  /**
   * One of the hub's messages to one client. Telemetry (replaced 20 times a second), panel data
   * and events are best effort: a tab that cannot keep up (hidden, slow, stalled) skips them
   * rather than queueing them.
   */
  private send(ws: WebSocket, w: Watched, msg: { type: string }): void {
    if (ws.readyState !== ws.OPEN || w.left) return;
    if (isBestEffort(msg.type) && ws.bufferedAmount > this.limits.dropAboveBytes) {
      this.counts.dropped[msg.type]++;
      return;
    }
    const e = this.encode(msg);
    w.queued += e.bytes;
    ws.send(e.text);
  }

  private encode(msg: object): { text: string; bytes: number } {
    let e = this.encoded.get(msg);
    if (e === undefined) {
      const text = encodeWire(msg);
      e = { text, bytes: Buffer.byteLength(text) };
      this.encoded.set(msg, e);
    }
    return e;
  }

  private lookAtAll(): void {
    const now = Date.now();
    for (const [ws, w] of this.watch) this.look(ws, w, now);
  }

  /**
   * Looks at one client: it goes when more than `maxBufferedBytes` wait and nothing was sent
   * since the last look, or when more than `dropAboveBytes` have waited with nothing sent for
   * `stalledMs`. (A client that is sending — a large graph on its way — stays.)
   */
  private look(ws: WebSocket, w: Watched, now: number): void {
    if (w.left) return;
    const { dropAboveBytes, maxBufferedBytes, stalledMs } = this.limits;
    const waiting = ws.bufferedAmount;
    const sent = w.queued - waiting;
    const progressed = sent > w.sent;
    w.sent = sent;
    if (progressed || waiting <= dropAboveBytes) w.progressAt = now;
    const mib = (waiting / (1024 * 1024)).toFixed(1);
    if (waiting > maxBufferedBytes && !progressed) {
      this.disconnect(ws, w, `too slow: ${mib} MiB waiting to be sent`);
    } else if (now - w.progressAt >= stalledMs) {
      this.disconnect(ws, w, `stalled: read nothing of ${mib} MiB for ${stalledMs / 1000} s`);
    }
  }

  private disconnect(ws: WebSocket, w: Watched, reason: string): void {
    w.left = true;
    this.counts.disconnected.push(reason);
    this.onProblem?.(`a client was disconnected: ${reason}`);
    ws.close(CLOSE_TOO_SLOW, reason.slice(0, 120));
    setTimeout(() => ws.terminate(), this.limits.closeGraceMs).unref();
  }
}

/**
 * A client's text message, decoded; or undefined when it cannot be, after a failed reply to it
 * (with its id when it has one: JSON too deep for the decoder's walk still parses).
 */
function decodeOrAnswer(ws: WebSocket, text: string): { value: unknown } | undefined {
  try {
    return { value: decodeWire(text) };
  } catch (e) {
    const why = e instanceof RangeError ? "the message nests too deeply" : "not JSON";
    ws.send(
      encodeWire({
        type: "reply",
        id: idOf(text),
        ok: false,
        message: `${why}: ${errorMessage(e)}`,
      }),
    );
    return undefined;
  }
}

/** The numeric `id` of a JSON message, -1 when it has none or is not JSON at all. */
function idOf(text: string): number {
  try {
    const raw = JSON.parse(text) as { id?: unknown } | null;
    if (typeof raw?.id === "number") return raw.id;
  } catch {
    // not JSON at all
  }
  return -1;
}
