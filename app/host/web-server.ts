/**
 * A small static file server for the browser build (dist/web), used by `npm start` and
 * `mosaic web`. Binds 127.0.0.1 by default and sends the cross-origin isolation headers, so the
 * engine worker gets shared memory and the precise real-time loop.
 */
import { createReadStream, existsSync, statSync } from "node:fs";
import { createServer, type IncomingMessage, type Server, type ServerResponse } from "node:http";
import { extname, join, normalize, resolve, sep } from "node:path";

const TYPES: Record<string, string> = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".mjs": "text/javascript; charset=utf-8",
  ".css": "text/css; charset=utf-8",
  ".json": "application/json; charset=utf-8",
  ".map": "application/json; charset=utf-8",
  ".wasm": "application/wasm",
  ".yaml": "text/yaml; charset=utf-8",
  ".csv": "text/csv; charset=utf-8",
  ".txt": "text/plain; charset=utf-8",
  ".md": "text/markdown; charset=utf-8",
  ".svg": "image/svg+xml",
  ".png": "image/png",
};

export interface ServeOptions {
  /**
   * Send COOP/COEP (default true): the page is cross-origin isolated, so the engine worker gets
   * SharedArrayBuffer. False serves the same files without them (tests of the fallback).
   */
  crossOriginIsolated?: boolean;
}

export interface WebServer {
  server: Server;
  url: string;
  close(): Promise<void>;
}

/** Serves `root` on host:port (port 0 picks a free one). Rejects when the port is taken. */
export function serveStatic(
  root: string,
  port: number,
  host = "127.0.0.1",
  options: ServeOptions = {},
): Promise<WebServer> {
  const base = resolve(root);
  const isolation = isolationHeaders(options);
  const server = createServer((req, res) => handleRequest(base, isolation, req, res));
  return listen(server, port, host);
}

/** The cross-origin isolation headers (COOP/COEP/CORP), unless the options turn them off. */
function isolationHeaders(options: ServeOptions): Record<string, string> {
  return options.crossOriginIsolated === false
    ? {}
    : {
        "Cross-Origin-Opener-Policy": "same-origin",
        "Cross-Origin-Embedder-Policy": "require-corp",
        "Cross-Origin-Resource-Policy": "same-origin",
      };
}

/** Answers one request with a file under `base` (GET and HEAD only), or an error status. */
function handleRequest(
  base: string,
  isolation: Record<string, string>,
  req: IncomingMessage,
  res: ServerResponse,
): void {
  const headers = {
    ...isolation,
    "X-Content-Type-Options": "nosniff",
    "Cache-Control": "no-cache",
  };
  if (req.method !== "GET" && req.method !== "HEAD") {
    res.writeHead(405, headers).end();
    return;
  }
  const path = requestPath(req);
  if (path === undefined) {
    res.writeHead(400, headers).end("bad request");
    return;
  }
  const file = normalize(join(base, path.endsWith("/") ? path + "index.html" : path));
  if (file !== base && !file.startsWith(base + sep)) {
    res.writeHead(403, headers).end("forbidden");
    return;
  }
  if (!existsSync(file) || !statSync(file).isFile()) {
    res.writeHead(404, { ...headers, "Content-Type": "text/plain" }).end("not found");
    return;
  }
  sendFile(file, req, res, headers);
}

/** The request URL's decoded path; undefined when it cannot be decoded. */
function requestPath(req: IncomingMessage): string | undefined {
  try {
    return decodeURIComponent(new URL(req.url ?? "/", "http://localhost").pathname);
  } catch {
    return undefined;
  }
}

/** 200 with the file's type and length, and its bytes unless the request is HEAD. */
function sendFile(
  file: string,
  req: IncomingMessage,
  res: ServerResponse,
  headers: Record<string, string>,
): void {
  res.writeHead(200, {
    ...headers,
    "Content-Type": TYPES[extname(file).toLowerCase()] ?? "application/octet-stream",
    "Content-Length": statSync(file).size,
  });
  if (req.method === "HEAD") res.end();
  else createReadStream(file).pipe(res);
}

/** Starts `server` listening; resolves with its URL, rejects when the port is taken. */
function listen(server: Server, port: number, host: string): Promise<WebServer> {
  return new Promise((resolvePromise, reject) => {
    server.once("error", (e: NodeJS.ErrnoException) => {
      reject(
        e.code === "EADDRINUSE"
          ? new Error(`port ${port} on ${host} is already in use: pick another with --port N`)
          : e,
      );
    });
    server.listen(port, host, () => {
      const addr = server.address();
      const p = typeof addr === "object" && addr ? addr.port : port;
      resolvePromise({
        server,
        url: `http://${host === "0.0.0.0" ? "127.0.0.1" : host}:${p}/`,
        close: () => new Promise((r) => server.close(() => r())),
      });
    });
  });
}
