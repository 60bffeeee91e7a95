/**
 * `mosaic serve`: the UI (the browser build's files) over HTTP and the engine over a WebSocket,
 * the engine running here in a worker thread with the native bridges (UDP, serial, …). Binds
 * 127.0.0.1 by default. The WebSocket needs the session's random token (in the printed URL) and
 * a same-origin page: another site open in the same browser cannot drive the devices. A socket
 * without them is opened and closed at once, before any message, with close code 4401 (token) or
 * 4403 (origin) and the reason in words, so the page can say why it got no engine (a browser
 * hides an HTTP refusal's status from the page). Several
 * tabs may watch and control the same engine; closing one changes nothing for the others.
 *
 * Pipelines loaded over the socket read and write only inside the allowed folders (the examples'
 * folder, `--data-dir`, the folder of the file named on the command line; SessionHubOptions).
 *
 * Slow clients: what waits on a client's socket (`ws`'s `bufferedAmount`) is bounded. Above
 * `dropAboveBytes` its telemetry (replaced 20 times a second), panel data and events are dropped
 * and counted; a client that sends none of what waits for `stalledMs`, or that has more than
 * `maxBufferedBytes` waiting and sent none of it since the last look (every 0.5 s), is
 * disconnected (close code 1008 and the reason), and its socket destroyed `closeGraceMs` later if
 * it does not read the close. A client that is receiving (a large graph on its way) stays.
 */
import { randomBytes, timingSafeEqual } from "node:crypto";
import type { IncomingMessage } from "node:http";
import type { Duplex } from "node:stream";
import { WebSocketServer, type WebSocket } from "ws";
import { errorMessage } from "../engine/diagnostics";
import {
  CLOSE_BAD_TOKEN,
  CLOSE_FOREIGN_ORIGIN,
  decodeWire,
  encodeWire,
} from "../engine/protocol-wire";
import { defaultAllowedDirs, SessionHub, type SessionHubOptions } from "./session-hub";
import { serveStatic, type WebServer } from "./web-server";

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

export interface ServeOptions extends SessionHubOptions {
  /** The browser build (dist/web). */
  webRoot: string;
  port: number;
  host?: string;
  /** Fixed token (tests); a random one by default. */
  token?: string;
  /**
   * A folder pipelines loaded over the socket may read and write besides their own
   * (`mosaic serve --data-dir DIR`); see allowedDirs.
   */
  dataDir?: string;
  slowClients?: Partial<SlowClientLimits>;
}

export interface Served {
  /** The URL to open, token included. */
  url: string;
  token: string;
  port: number;
  hub: SessionHub;
  web: WebServer;
  /** Clients, and what slow ones were left out of or disconnected for. */
  stats(): ServeStats;
  close(): Promise<void>;
}

function sameToken(a: string, b: string): boolean {
  const x = Buffer.from(a);
  const y = Buffer.from(b);
  return x.length === y.length && timingSafeEqual(x, y);
}

export async function serve(o: ServeOptions): Promise<Served> {
  const token = o.token ?? randomBytes(24).toString("base64url");
  const host = o.host ?? "127.0.0.1";
  const web = await serveStatic(o.webRoot, o.port, host);
  let hub: SessionHub;
  try {
    hub = await SessionHub.start({
      ...o,
      allowedDirs: o.allowedDirs ?? defaultAllowedDirs(o.pipelinesDir, o.dataDir),
    });
  } catch (e) {
    await web.close();
    throw e;
  }
  const address = web.server.address();
  const port = typeof address === "object" && address ? address.port : o.port;
  const origin = new URL(web.url).origin;
  const wss = new WebSocketServer({ noServer: true, maxPayload: 8 * 1024 * 1024 });

  const refuse = (socket: Duplex, code: number, why: string): void => {
    socket.end(`HTTP/1.1 ${code} ${why}\r\nConnection: close\r\nContent-Length: 0\r\n\r\n`);
  };
  /** Opens the socket only to close it with `code` and `why`: the page learns the cause. */
  const turnAway = (
    req: IncomingMessage,
    socket: Duplex,
    head: Buffer,
    code: number,
    why: string,
  ): void => {
    wss.handleUpgrade(req, socket, head, (ws) => {
      ws.close(code, why);
      // The close frame is out; a client that never answers it is not waited for (ws waits 30 s).
      setTimeout(() => ws.terminate(), 1000).unref();
    });
  };

  web.server.on("upgrade", (req: IncomingMessage, socket: Duplex, head: Buffer) => {
    let url: URL;
    try {
      url = new URL(req.url ?? "/", origin);
    } catch {
      refuse(socket, 400, "Bad Request");
      return;
    }
    if (url.pathname !== "/ws") {
      refuse(socket, 404, "Not Found");
      return;
    }
    if (!sameToken(url.searchParams.get("token") ?? "", token)) {
      turnAway(req, socket, head, CLOSE_BAD_TOKEN, "wrong or missing token");
      return;
    }
    // Browsers always send Origin on WebSocket requests: only our own page may connect.
    const from = req.headers.origin;
    if (
      from !== undefined &&
      from !== origin &&
      from !== origin.replace("127.0.0.1", "localhost")
    ) {
      // A close reason holds 123 bytes: the foreign origin, printable ASCII, is cut short.
      const shown = from.replace(/[^\x20-\x7e]/g, "?").slice(0, 48);
      turnAway(req, socket, head, CLOSE_FOREIGN_ORIGIN, `a page from ${shown} (not ${origin})`);
      return;
    }
    wss.handleUpgrade(req, socket, head, (ws) => attach(ws));
  });

  // The hub hands the same message object to every client: encode it once, not once per tab.
  const encoded = new WeakMap<object, { text: string; bytes: number }>();
  const encode = (msg: object): { text: string; bytes: number } => {
    let e = encoded.get(msg);
    if (e === undefined) {
      const text = encodeWire(msg);
      e = { text, bytes: Buffer.byteLength(text) };
      encoded.set(msg, e);
    }
    return e;
  };

  const limits: SlowClientLimits = { ...SLOW_CLIENT_LIMITS, ...o.slowClients };
  const stats: Omit<ServeStats, "waiting"> = {
    clients: 0,
    dropped: { telemetry: 0, data: 0, event: 0 },
    disconnected: [],
  };
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
  const watch = new Map<WebSocket, Watched>();

  const disconnect = (ws: WebSocket, w: Watched, reason: string): void => {
    w.left = true;
    stats.disconnected.push(reason);
    o.onProblem?.(`a client was disconnected: ${reason}`);
    ws.close(CLOSE_TOO_SLOW, reason.slice(0, 120));
    setTimeout(() => ws.terminate(), limits.closeGraceMs).unref();
  };

  /**
   * Looks at one client: it goes when more than `maxBufferedBytes` wait and nothing was sent
   * since the last look, or when more than `dropAboveBytes` have waited with nothing sent for
   * `stalledMs`. (A client that is sending — a large graph on its way — stays.)
   */
  const look = (ws: WebSocket, w: Watched, now: number): void => {
    if (w.left) return;
    const waiting = ws.bufferedAmount;
    const sent = w.queued - waiting;
    const progressed = sent > w.sent;
    w.sent = sent;
    if (progressed || waiting <= limits.dropAboveBytes) w.progressAt = now;
    const mib = (waiting / (1024 * 1024)).toFixed(1);
    if (waiting > limits.maxBufferedBytes && !progressed) {
      disconnect(ws, w, `too slow: ${mib} MiB waiting to be sent`);
    } else if (now - w.progressAt >= limits.stalledMs) {
      disconnect(ws, w, `stalled: read nothing of ${mib} MiB for ${limits.stalledMs / 1000} s`);
    }
  };
  const sweep = setInterval(
    () => {
      const now = Date.now();
      for (const [ws, w] of watch) look(ws, w, now);
    },
    Math.min(500, limits.stalledMs / 4),
  );
  sweep.unref();

  const attach = (ws: WebSocket): void => {
    const w: Watched = { queued: 0, sent: 0, progressAt: Date.now(), left: false };
    watch.set(ws, w);
    stats.clients++;
    const conn = hub.connect({
      send(msg) {
        if (ws.readyState !== ws.OPEN || w.left) return;
        // Telemetry (replaced 20 times a second), panel data and events are best effort: a tab
        // that cannot keep up (hidden, slow, stalled) skips them rather than queueing them.
        if (
          (msg.type === "telemetry" || msg.type === "data" || msg.type === "event") &&
          ws.bufferedAmount > limits.dropAboveBytes
        ) {
          stats.dropped[msg.type]++;
          return;
        }
        const e = encode(msg);
        w.queued += e.bytes;
        ws.send(e.text);
      },
    });
    ws.on("message", (data, isBinary) => {
      if (isBinary) return;
      let msg: unknown;
      const text = String(data);
      try {
        msg = decodeWire(text);
      } catch (e) {
        // JSON too deep for the decoder's walk still parses: answer its id.
        let id = -1;
        try {
          const raw = JSON.parse(text) as { id?: unknown } | null;
          if (typeof raw?.id === "number") id = raw.id;
        } catch {
          // not JSON at all
        }
        const why = e instanceof RangeError ? "the message nests too deeply" : "not JSON";
        ws.send(
          encodeWire({ type: "reply", id, ok: false, message: `${why}: ${errorMessage(e)}` }),
        );
        return;
      }
      conn.receive(msg);
    });
    const gone = (): void => {
      if (!watch.delete(ws)) return;
      stats.clients--;
      conn.close();
    };
    ws.on("close", gone);
    ws.on("error", gone);
  };

  const url = `${web.url}?token=${encodeURIComponent(token)}`;
  return {
    url,
    token,
    port,
    hub,
    web,
    stats: () => ({
      ...stats,
      waiting: [...watch.keys()].map((ws) => ws.bufferedAmount),
      dropped: { ...stats.dropped },
      disconnected: [...stats.disconnected],
    }),
    async close() {
      clearInterval(sweep);
      for (const c of wss.clients) c.terminate();
      wss.close();
      await hub.close();
      await web.close();
    },
  };
}
