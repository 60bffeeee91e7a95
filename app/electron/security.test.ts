import { describe, expect, test } from "vitest";
import {
  APP_ENTRY,
  CONTENT_SECURITY_POLICY,
  CSP_DIRECTIVES,
  isAllowedNavigation,
  isAllowedPermission,
  isTrustedIpcSender,
  responseHeaders,
  windowWebPreferences,
} from "./security";

describe("Content Security Policy", () => {
  test("allows only the app's own origin and WebAssembly, never eval or remote content", () => {
    const script = CSP_DIRECTIVES["script-src"]!;
    expect(script).toEqual(["'self'", "'wasm-unsafe-eval'"]);
    expect(CONTENT_SECURITY_POLICY).not.toMatch(/'unsafe-eval'/);
    expect(CONTENT_SECURITY_POLICY).not.toMatch(/https?:|\*/);
    expect(CSP_DIRECTIVES["default-src"]).toEqual(["'none'"]);
    expect(CSP_DIRECTIVES["connect-src"]).toEqual(["'self'"]);
    expect(CSP_DIRECTIVES["worker-src"]).toEqual(["'self'"]);
    expect(CSP_DIRECTIVES["object-src"]).toEqual(["'none'"]);
    expect(CSP_DIRECTIVES["frame-ancestors"]).toEqual(["'none'"]);
    expect(CONTENT_SECURITY_POLICY).not.toMatch(/'unsafe-inline'/);
    expect(CSP_DIRECTIVES["style-src"]).toEqual(["'self'"]);
  });

  test("is one header value: directives separated by semicolons", () => {
    expect(CONTENT_SECURITY_POLICY.split("; ")).toContain("script-src 'self' 'wasm-unsafe-eval'");
    expect(CONTENT_SECURITY_POLICY).not.toMatch(/[\r\n]/);
  });

  test("every response is cross-origin isolated and carries the policy", () => {
    const h = responseHeaders("text/html; charset=utf-8");
    expect(h).toMatchObject({
      "Content-Security-Policy": CONTENT_SECURITY_POLICY,
      "Cross-Origin-Opener-Policy": "same-origin",
      "Cross-Origin-Embedder-Policy": "require-corp",
      "Cross-Origin-Resource-Policy": "same-origin",
      "X-Content-Type-Options": "nosniff",
      "Content-Type": "text/html; charset=utf-8",
    });
    expect(responseHeaders()).not.toHaveProperty("Content-Type");
  });
});

describe("window preferences", () => {
  test("sandboxed, isolated, no Node, web security on", () => {
    const p = windowWebPreferences("/app/dist/electron/preload.cjs", false);
    expect(p).toMatchObject({
      preload: "/app/dist/electron/preload.cjs",
      contextIsolation: true,
      nodeIntegration: false,
      nodeIntegrationInWorker: false,
      nodeIntegrationInSubFrames: false,
      sandbox: true,
      webSecurity: true,
      allowRunningInsecureContent: false,
      webviewTag: false,
      devTools: false,
    });
    expect(windowWebPreferences("p", true).devTools).toBe(true);
  });
});

describe("navigation", () => {
  test("only pages of app://mosaic/", () => {
    expect(isAllowedNavigation(APP_ENTRY)).toBe(true);
    expect(isAllowedNavigation("app://mosaic/index.html?pipeline=pipelines/demo.yaml#x")).toBe(
      true,
    );
    expect(isAllowedNavigation("app://mosaic/")).toBe(true);
    for (const bad of [
      "https://example.com/",
      "http://127.0.0.1:8321/",
      "file:///etc/passwd",
      "javascript:alert(1)",
      "data:text/html,<script>1</script>",
      "app://evil/index.html",
      "app://mosaic.evil.com/",
      "app://mosaic:8080/",
      "app://user:pw@mosaic/",
      "devtools://devtools/bundled/inspector.html",
      "not a url",
      "",
    ]) {
      expect(isAllowedNavigation(bad), bad).toBe(false);
    }
  });
});

describe("IPC sender check", () => {
  const main = { url: "app://mosaic/index.html", parent: null };
  test("accepts the window's main frame on the app origin", () => {
    expect(isTrustedIpcSender(main, main)).toBe(true);
  });
  test("refuses other frames, iframes, foreign pages and destroyed frames", () => {
    const child = { url: "app://mosaic/index.html", parent: main };
    expect(isTrustedIpcSender(child, main)).toBe(false);
    expect(isTrustedIpcSender({ ...main }, main)).toBe(false); // another window's frame
    const foreign = { url: "https://example.com/", parent: null };
    expect(isTrustedIpcSender(foreign, foreign)).toBe(false);
    expect(isTrustedIpcSender(null, main)).toBe(false);
    expect(isTrustedIpcSender(undefined, main)).toBe(false);
    expect(isTrustedIpcSender(main, null)).toBe(false);
  });
});

describe("permissions", () => {
  test("devices and sensors are refused; clipboard writes from the app are allowed", () => {
    for (const p of [
      "media",
      "geolocation",
      "notifications",
      "hid",
      "serial",
      "usb",
      "bluetooth",
    ]) {
      expect(isAllowedPermission(p, APP_ENTRY)).toBe(false);
    }
    expect(isAllowedPermission("clipboard-sanitized-write", APP_ENTRY)).toBe(true);
    expect(isAllowedPermission("clipboard-sanitized-write", "https://example.com/")).toBe(false);
  });
});
