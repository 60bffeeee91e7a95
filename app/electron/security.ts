/**
 * The desktop window's security settings, as plain data and pure functions (tested in Node; the
 * Electron main process only applies them).
 *
 * The UI is served from the app's own privileged scheme (`app://mosaic/`, see protocol-files.ts),
 * never from `file://` or the network. Every response carries a strict Content Security Policy
 * (nothing remote, no `eval`; WebAssembly compilation is allowed with `'wasm-unsafe-eval'`) and
 * the cross-origin isolation headers (COOP/COEP), so the page gets `SharedArrayBuffer` like the
 * browser build served by `mosaic web`. The renderer is sandboxed with context isolation and no
 * Node; it reaches the engine only through the preload's `mosaicHost` (the UI↔engine protocol on
 * one IPC channel), and the main process accepts IPC only from its window's main frame showing
 * the app origin.
 */

/** The scheme the UI is served on. */
export const APP_SCHEME = "app";
/** The only host of that scheme. */
export const APP_HOST = "mosaic";
/** The app origin, as Chromium writes it for a standard scheme. */
export const APP_ORIGIN = `${APP_SCHEME}://${APP_HOST}`;
/** The page the window opens. */
export const APP_ENTRY = `${APP_ORIGIN}/index.html`;

/**
 * Privileges for `protocol.registerSchemesAsPrivileged` (before the app is ready): a standard,
 * secure scheme (so relative URLs, `fetch`, module scripts, module Web Workers and
 * `WebAssembly.instantiateStreaming` work as on https), streamed responses, V8 code cache.
 * Not `bypassCSP`: the policy below applies. Not `corsEnabled`: the page only loads its own origin.
 */
export const APP_SCHEME_PRIVILEGES = {
  standard: true,
  secure: true,
  supportFetchAPI: true,
  stream: true,
  codeCache: true,
} as const;

/**
 * The Content Security Policy of every app:// response. What the built page (dist/web) needs:
 * a module script (app.js) and a stylesheet (app.css) of its own origin; a module Web Worker
 * (engine.worker.js, used by the browser build's in-page engine); the .wasm core compiled from
 * bytes (`'wasm-unsafe-eval'`, which does not allow `eval`); `fetch` of pipelines/index.json and
 * pipelines/*.yaml; the `data:` favicon; `blob:` for "Save layout…" downloads. No inline code
 * and no inline `<style>` or `style="…"` markup: React, React Flow and uPlot set styles through
 * the CSSOM, which style-src does not restrict. Checked in Chromium against the built page (graph,
 * running engine worker, scope panels): no violations, cross-origin isolated (docs/desktop.md).
 */
export const CSP_DIRECTIVES: Readonly<Record<string, readonly string[]>> = {
  "default-src": ["'none'"],
  "script-src": ["'self'", "'wasm-unsafe-eval'"],
  "worker-src": ["'self'"],
  "style-src": ["'self'"],
  "img-src": ["'self'", "data:", "blob:"],
  "font-src": ["'self'", "data:"],
  "connect-src": ["'self'"],
  "media-src": ["'none'"],
  "object-src": ["'none'"],
  "frame-src": ["'none'"],
  "child-src": ["'self'"],
  "manifest-src": ["'none'"],
  "base-uri": ["'none'"],
  "form-action": ["'none'"],
  "frame-ancestors": ["'none'"],
};

export const CONTENT_SECURITY_POLICY = Object.entries(CSP_DIRECTIVES)
  .map(([name, values]) => `${name} ${values.join(" ")}`)
  .join("; ");

/** Headers of every response of the app protocol (content type added per file). */
export function responseHeaders(contentType?: string): Record<string, string> {
  return {
    "Content-Security-Policy": CONTENT_SECURITY_POLICY,
    "Cross-Origin-Opener-Policy": "same-origin",
    "Cross-Origin-Embedder-Policy": "require-corp",
    "Cross-Origin-Resource-Policy": "same-origin",
    "X-Content-Type-Options": "nosniff",
    "Referrer-Policy": "no-referrer",
    "Cache-Control": "no-cache",
    ...(contentType !== undefined ? { "Content-Type": contentType } : {}),
  };
}

/** The window's `webPreferences` (a plain object: `BrowserWindow` takes it as it is). */
export function windowWebPreferences(preload: string, devTools: boolean) {
  return {
    preload,
    contextIsolation: true,
    nodeIntegration: false,
    nodeIntegrationInWorker: false,
    nodeIntegrationInSubFrames: false,
    sandbox: true,
    webSecurity: true,
    allowRunningInsecureContent: false,
    experimentalFeatures: false,
    webviewTag: false,
    navigateOnDragDrop: false,
    safeDialogs: true,
    spellcheck: false,
    devTools,
  } as const;
}

/** Parses a URL; undefined when it is not one. */
function parse(url: string): URL | undefined {
  try {
    return new URL(url);
  } catch {
    return undefined;
  }
}

/**
 * Whether the window may show `url`: only pages of the app origin (`app://mosaic/…`, no port, no
 * credentials). Everything else (http(s), file:, javascript:, data:, another app host) is refused;
 * `window.open` is always refused. (Node's URL reports `origin` "null" for non-special schemes,
 * so scheme and host are compared.)
 */
export function isAllowedNavigation(url: string): boolean {
  const u = parse(url);
  if (!u) return false;
  return (
    u.protocol === `${APP_SCHEME}:` &&
    u.hostname === APP_HOST &&
    u.port === "" &&
    u.username === "" &&
    u.password === ""
  );
}

/** The parts of Electron's `WebFrameMain` the IPC check reads. */
export interface SenderFrame {
  readonly url: string;
  readonly parent: unknown;
}

/**
 * Whether an IPC message comes from our window: the sending frame is the window's main frame
 * (not an iframe, not another window), it has no parent and shows a page of the app origin.
 * `frame` is `event.senderFrame` (null once the frame navigated away or was destroyed).
 */
export function isTrustedIpcSender(
  frame: SenderFrame | null | undefined,
  mainFrame: SenderFrame | null | undefined,
): boolean {
  if (!frame || !mainFrame || frame !== mainFrame) return false;
  if (frame.parent !== null && frame.parent !== undefined) return false;
  return isAllowedNavigation(frame.url);
}

/**
 * Permissions the page may have (camera, microphone, geolocation, notifications, HID, serial,
 * Bluetooth, …: none; devices are opened by the host, not the page). Only writing to the
 * clipboard (copying a diagnostic) is allowed.
 */
const ALLOWED_PERMISSIONS = new Set(["clipboard-sanitized-write"]);

export function isAllowedPermission(permission: string, requestingUrl: string): boolean {
  return ALLOWED_PERMISSIONS.has(permission) && isAllowedNavigation(requestingUrl);
}
