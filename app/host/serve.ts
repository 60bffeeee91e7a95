/**
 * `mosaic serve`: the UI (the browser build's files) over HTTP and the engine over a WebSocket,
 * the engine running here in a worker thread with the native bridges (UDP, serial, …). Binds
 * 127.0.0.1 by default. The WebSocket needs the session's random token (in the printed URL) and
 * a same-origin page: another site open in the same browser cannot drive the devices. Several
 * tabs may watch and control the same engine; closing one changes nothing for the others.
 */
import { randomBytes, timingSafeEqual } from "node:crypto";
import type { IncomingMessage } from "node:http";
import type { Duplex } from "node:stream";
import { WebSocketServer, type WebSocket } from "ws";
import { errorMessage } from "../engine/diagnostics";
import { decodeWire, encodeWire } from "../engine/protocol-wire";
import { SessionHub, type SessionHubOptions } from "./session-hub";
import { serveStatic, type WebServer } from "./web-server";

export interface ServeOptions extends SessionHubOptions {
  /** The browser build (dist/web). */
  webRoot: string;
  port: number;
  host?: string;
  /** Fixed token (tests); a random one by default. */
  token?: string;
}

export interface Served {
  /** The URL to open, token included. */
  url: string;
  token: string;
  port: number;
  hub: SessionHub;
  web: WebServer;
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
    hub = await SessionHub.start(o);
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
      refuse(socket, 401, "Unauthorized");
      return;
    }
    // Browsers always send Origin on WebSocket requests: only our own page may connect.
    const from = req.headers.origin;
    if (
      from !== undefined &&
      from !== origin &&
      from !== origin.replace("127.0.0.1", "localhost")
    ) {
      refuse(socket, 403, "Forbidden");
      return;
    }
    wss.handleUpgrade(req, socket, head, (ws) => attach(ws));
  });

  // The hub hands the same message object to every client: encode it once, not once per tab.
  const encoded = new WeakMap<object, string>();
  const encode = (msg: object): string => {
    let text = encoded.get(msg);
    if (text === undefined) {
      text = encodeWire(msg);
      encoded.set(msg, text);
    }
    return text;
  };

  const attach = (ws: WebSocket): void => {
    const conn = hub.connect({
      send(msg) {
        if (ws.readyState !== ws.OPEN) return;
        // Panel data is best effort: a tab that cannot keep up (hidden, slow) skips frames
        // rather than queueing without bound.
        if (msg.type === "data" && ws.bufferedAmount > 4 * 1024 * 1024) return;
        ws.send(encode(msg));
      },
    });
    ws.on("message", (data, isBinary) => {
      if (isBinary) return;
      let msg: unknown;
      try {
        msg = decodeWire(String(data));
      } catch (e) {
        ws.send(
          encodeWire({ type: "reply", id: -1, ok: false, message: `not JSON: ${errorMessage(e)}` }),
        );
        return;
      }
      conn.receive(msg);
    });
    ws.on("close", () => conn.close());
    ws.on("error", () => conn.close());
  };

  const url = `${web.url}?token=${encodeURIComponent(token)}`;
  return {
    url,
    token,
    port,
    hub,
    web,
    async close() {
      for (const c of wss.clients) c.terminate();
      wss.close();
      await hub.close();
      await web.close();
    },
  };
}
