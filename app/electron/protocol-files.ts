/**
 * The app protocol's file server: maps `app://mosaic/<path>` to a file under the web root (the
 * browser build, dist/web) and answers with the security headers of security.ts. Refuses other
 * hosts, other methods, `..` and encoded separators that would leave the root, NUL bytes and
 * symbolic links pointing out of the root. Plain Node (fs), so it is tested without Electron; the
 * main process turns the answer into a `Response` in its `protocol.handle` callback.
 */
import { readFile, realpath, stat } from "node:fs/promises";
import { extname, isAbsolute, join, relative, resolve, sep } from "node:path";
import { APP_HOST, APP_SCHEME, responseHeaders } from "./security";

export const CONTENT_TYPES: Readonly<Record<string, string>> = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".mjs": "text/javascript; charset=utf-8",
  ".css": "text/css; charset=utf-8",
  ".json": "application/json; charset=utf-8",
  ".map": "application/json; charset=utf-8",
  ".wasm": "application/wasm",
  ".yaml": "text/yaml; charset=utf-8",
  ".yml": "text/yaml; charset=utf-8",
  ".csv": "text/csv; charset=utf-8",
  ".txt": "text/plain; charset=utf-8",
  ".md": "text/markdown; charset=utf-8",
  ".svg": "image/svg+xml",
  ".png": "image/png",
  ".ico": "image/x-icon",
  ".woff2": "font/woff2",
};

export function contentType(file: string): string {
  return CONTENT_TYPES[extname(file).toLowerCase()] ?? "application/octet-stream";
}

/** Whether a path relative to the root points out of it. */
function outside(rel: string): boolean {
  return isAbsolute(rel) || rel.split(sep).includes("..");
}

export type PathResult = { ok: true; file: string } | { ok: false; status: number; why: string };

/**
 * The file under `root` that `url` names (a directory's index.html for a path ending in "/"),
 * or why not: 400 (not a URL of the app origin, bad escapes, NUL), 403 (leaves the root).
 * Does not touch the disk.
 */
export function resolveAppPath(root: string, url: string): PathResult {
  let u: URL;
  try {
    u = new URL(url);
  } catch {
    return { ok: false, status: 400, why: "not a URL" };
  }
  if (u.protocol !== `${APP_SCHEME}:` || u.hostname !== APP_HOST || u.port !== "") {
    return { ok: false, status: 400, why: `not an ${APP_SCHEME}://${APP_HOST}/ URL` };
  }
  let path: string;
  try {
    path = decodeURIComponent(u.pathname);
  } catch {
    return { ok: false, status: 400, why: "bad percent-encoding" };
  }
  if (path.includes("\0")) return { ok: false, status: 400, why: "NUL in path" };
  // The URL parser already resolved literal `..` segments; encoded ones (%2e%2e, %2f, %5c) and
  // backslashes come through decoding and are refused here.
  const segments = path.split(/[/\\]/);
  if (segments.some((s) => s === ".."))
    return { ok: false, status: 403, why: "path leaves the root" };
  const base = resolve(root);
  const file = resolve(join(base, ...segments, path.endsWith("/") ? "index.html" : ""));
  const rel = relative(base, file);
  if (rel === "" || outside(rel)) {
    return { ok: false, status: 403, why: "path leaves the root" };
  }
  return { ok: true, file };
}

/** An answer of the app protocol, ready for `new Response(body, { status, headers })`. */
export interface AppResponse {
  status: number;
  headers: Record<string, string>;
  /** File bytes, a short text saying why not, or null (HEAD). */
  body: Uint8Array | string | null;
}

function refuse(status: number, why: string): AppResponse {
  return { status, headers: responseHeaders("text/plain; charset=utf-8"), body: why };
}

/**
 * Answers one request of the app protocol from files under `root` (GET and HEAD only; the whole
 * file is read: the build's biggest files are a few MB).
 */
export async function serveAppRequest(
  root: string,
  url: string,
  method = "GET",
): Promise<AppResponse> {
  if (method !== "GET" && method !== "HEAD") return refuse(405, "method not allowed");
  const target = resolveAppPath(root, url);
  if (!target.ok) return refuse(target.status, target.why);
  let real: string;
  let realRoot: string;
  try {
    [real, realRoot] = await Promise.all([realpath(target.file), realpath(resolve(root))]);
  } catch {
    return refuse(404, "not found");
  }
  // A symbolic link inside the root must not lead out of it.
  const rel = relative(realRoot, real);
  if (rel === "" || outside(rel)) return refuse(403, "path leaves the root");
  try {
    const info = await stat(real);
    if (!info.isFile()) return refuse(404, "not found");
    const headers = { ...responseHeaders(contentType(real)), "Content-Length": String(info.size) };
    if (method === "HEAD") return { status: 200, headers, body: null };
    return { status: 200, headers, body: new Uint8Array(await readFile(real)) };
  } catch {
    return refuse(404, "not found");
  }
}
