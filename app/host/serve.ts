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
 * Slow clients (serve-clients.ts): what waits on a client's socket (`ws`'s `bufferedAmount`) is
 * bounded. Above `dropAboveBytes` its telemetry (replaced 20 times a second), panel data and
 * events are dropped and counted; a client that sends none of what waits for `stalledMs`, or that
 * has more than `maxBufferedBytes` waiting and sent none of it since the last look (every 0.5 s),
 * is disconnected (close code 1008 and the reason), and its socket destroyed `closeGraceMs` later
 * if it does not read the close. A client that is receiving (a large graph on its way) stays.
 */
import { randomBytes, timingSafeEqual } from "node:crypto";
import type { IncomingMessage } from "node:http";
import type { Duplex } from "node:stream";
import { WebSocketServer } from "ws";
import { CLOSE_BAD_TOKEN, CLOSE_FOREIGN_ORIGIN } from "../engine/protocol-wire";
import {
  SLOW_CLIENT_LIMITS,
  ServeClients,
  type ServeStats,
  type SlowClientLimits,
} from "./serve-clients";
import { defaultAllowedDirs, SessionHub, type SessionHubOptions } from "./session-hub";
import { serveStatic, type WebServer } from "./web-server";

export {
  CLOSE_TOO_SLOW,
  SLOW_CLIENT_LIMITS,
  type ServeStats,
  type SlowClientLimits,
} from "./serve-clients";

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

/**
 * What to do with a WebSocket upgrade request: accept it; refuse it with an HTTP status (not a
 * WebSocket request for us); or turn it away, opening the socket only to close it with a code
 * and the reason, so that the page learns the cause.
 */
type Verdict =
  | { action: "accept" }
  | { action: "refuse"; status: number; why: string }
  | { action: "turn-away"; code: number; why: string };

/** The verdict on an upgrade request: the path `/ws`, the token, and a same-origin page. */
function judgeUpgrade(req: IncomingMessage, origin: string, token: string): Verdict {
  let url: URL;
  try {
    url = new URL(req.url ?? "/", origin);
  } catch {
    return { action: "refuse", status: 400, why: "Bad Request" };
  }
  if (url.pathname !== "/ws") return { action: "refuse", status: 404, why: "Not Found" };
  if (!sameToken(url.searchParams.get("token") ?? "", token)) {
    return { action: "turn-away", code: CLOSE_BAD_TOKEN, why: "wrong or missing token" };
  }
  // Browsers always send Origin on WebSocket requests: only our own page may connect.
  const from = req.headers.origin;
  if (from !== undefined && from !== origin && from !== origin.replace("127.0.0.1", "localhost")) {
    // A close reason holds 123 bytes: the foreign origin, printable ASCII, is cut short.
    const shown = from.replace(/[^\x20-\x7e]/g, "?").slice(0, 48);
    return {
      action: "turn-away",
      code: CLOSE_FOREIGN_ORIGIN,
      why: `a page from ${shown} (not ${origin})`,
    };
  }
  return { action: "accept" };
}

/** Answers the web server's upgrade requests: sockets judged acceptable go to `accept`. */
function guardUpgrades(
  web: WebServer,
  wss: WebSocketServer,
  token: string,
  accept: ServeClients,
): void {
  const origin = new URL(web.url).origin;
  web.server.on("upgrade", (req: IncomingMessage, socket: Duplex, head: Buffer) => {
    const verdict = judgeUpgrade(req, origin, token);
    if (verdict.action === "refuse") {
      const { status, why } = verdict;
      socket.end(`HTTP/1.1 ${status} ${why}\r\nConnection: close\r\nContent-Length: 0\r\n\r\n`);
    } else if (verdict.action === "turn-away") {
      wss.handleUpgrade(req, socket, head, (ws) => {
        ws.close(verdict.code, verdict.why);
        // The close frame is out; a client that never answers it is not waited for (ws waits 30 s).
        setTimeout(() => ws.terminate(), 1000).unref();
      });
    } else {
      wss.handleUpgrade(req, socket, head, (ws) => accept.attach(ws));
    }
  });
}

/** The session hub, confined to the allowed folders; the web server is closed if it fails. */
async function startHub(o: ServeOptions, web: WebServer): Promise<SessionHub> {
  try {
    return await SessionHub.start({
      ...o,
      allowedDirs: o.allowedDirs ?? defaultAllowedDirs(o.pipelinesDir, o.dataDir),
    });
  } catch (e) {
    await web.close();
    throw e;
  }
}

export async function serve(o: ServeOptions): Promise<Served> {
  const token = o.token ?? randomBytes(24).toString("base64url");
  const host = o.host ?? "127.0.0.1";
  const web = await serveStatic(o.webRoot, o.port, host);
  const hub = await startHub(o, web);
  const address = web.server.address();
  const port = typeof address === "object" && address ? address.port : o.port;
  const wss = new WebSocketServer({ noServer: true, maxPayload: 8 * 1024 * 1024 });
  const limits: SlowClientLimits = { ...SLOW_CLIENT_LIMITS, ...o.slowClients };
  const clients = new ServeClients(hub, limits, o.onProblem);
  guardUpgrades(web, wss, token, clients);
  return {
    url: `${web.url}?token=${encodeURIComponent(token)}`,
    token,
    port,
    hub,
    web,
    stats: () => clients.stats(),
    async close() {
      clients.stop();
      for (const c of wss.clients) c.terminate();
      wss.close();
      await hub.close();
      await web.close();
    },
  };
}
