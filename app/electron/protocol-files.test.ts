import { mkdirSync, mkdtempSync, rmSync, symlinkSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { contentType, resolveAppPath, serveAppRequest } from "./protocol-files";
import { CONTENT_SECURITY_POLICY } from "./security";

let dir: string;
let root: string;

beforeAll(() => {
  dir = mkdtempSync(join(tmpdir(), "mosaic-protocol-"));
  root = join(dir, "web");
  mkdirSync(join(root, "pipelines"), { recursive: true });
  writeFileSync(join(root, "index.html"), "<!doctype html><title>x</title>");
  writeFileSync(join(root, "app.js"), "export {};");
  writeFileSync(join(root, "mosaic_core_bg.wasm"), new Uint8Array([0, 97, 115, 109]));
  writeFileSync(join(root, "pipelines", "demo.yaml"), "a: 1\n");
  writeFileSync(join(root, "pipelines", "my pipeline.yaml"), "b: 2\n");
  writeFileSync(join(dir, "secret.txt"), "secret");
  try {
    symlinkSync(join(dir, "secret.txt"), join(root, "link.txt"));
  } catch {
    // No symlinks on this file system: that case is then not tested.
  }
});
afterAll(() => rmSync(dir, { recursive: true, force: true }));

describe("resolveAppPath", () => {
  test("maps app://mosaic/<path> under the root; / is index.html", () => {
    expect(resolveAppPath(root, "app://mosaic/app.js")).toEqual({
      ok: true,
      file: join(root, "app.js"),
    });
    expect(resolveAppPath(root, "app://mosaic/")).toEqual({
      ok: true,
      file: join(root, "index.html"),
    });
    expect(resolveAppPath(root, "app://mosaic/pipelines/my%20pipeline.yaml?x=1#y")).toEqual({
      ok: true,
      file: join(root, "pipelines", "my pipeline.yaml"),
    });
  });

  test("refuses traversal, encoded separators, NUL and other origins", () => {
    for (const url of [
      "app://mosaic/..%2fsecret.txt",
      "app://mosaic/%2e%2e%2fsecret.txt",
      "app://mosaic/..%5csecret.txt",
      "app://mosaic/pipelines/..%2f..%2fsecret.txt",
    ]) {
      const r = resolveAppPath(root, url);
      expect(r.ok, url).toBe(false);
      if (!r.ok) expect(r.status, url).toBe(403);
    }
    // Literal and percent-encoded ".." segments are resolved by the URL parser: inside the root.
    for (const url of [
      "app://mosaic/../../secret.txt",
      "app://mosaic/%2e%2e/secret.txt",
      "app://mosaic/pipelines/%2E%2E/%2e./secret.txt",
    ]) {
      expect(resolveAppPath(root, url), url).toEqual({ ok: true, file: join(root, "secret.txt") });
    }
    for (const url of [
      "app://mosaic/a%00b",
      "app://mosaic/%E0%A4%A",
      "app://other/app.js",
      "app://mosaic:1/app.js",
      "https://mosaic/app.js",
      "file:///etc/passwd",
      "nonsense",
    ]) {
      const r = resolveAppPath(root, url);
      expect(r.ok, url).toBe(false);
      if (!r.ok) expect(r.status, url).toBe(400);
    }
  });
});

describe("serveAppRequest", () => {
  test("serves files with their type and the security headers", async () => {
    const r = await serveAppRequest(root, "app://mosaic/mosaic_core_bg.wasm");
    expect(r.status).toBe(200);
    expect(r.headers["Content-Type"]).toBe("application/wasm");
    expect(r.headers["Content-Length"]).toBe("4");
    expect(r.headers["Content-Security-Policy"]).toBe(CONTENT_SECURITY_POLICY);
    expect(r.headers["Cross-Origin-Embedder-Policy"]).toBe("require-corp");
    expect([...(r.body as Uint8Array)]).toEqual([0, 97, 115, 109]);

    const html = await serveAppRequest(root, "app://mosaic/");
    expect(html.headers["Content-Type"]).toBe("text/html; charset=utf-8");
    expect(new TextDecoder().decode(html.body as Uint8Array)).toContain("<title>x</title>");

    const head = await serveAppRequest(root, "app://mosaic/pipelines/demo.yaml", "HEAD");
    expect(head).toMatchObject({ status: 200, body: null });
    expect(head.headers["Content-Type"]).toBe("text/yaml; charset=utf-8");
  });

  test("404 for missing files and folders, 405 for other methods, 403 out of the root", async () => {
    expect((await serveAppRequest(root, "app://mosaic/nope.js")).status).toBe(404);
    expect((await serveAppRequest(root, "app://mosaic/pipelines")).status).toBe(404);
    expect((await serveAppRequest(root, "app://mosaic/app.js", "POST")).status).toBe(405);
    const out = await serveAppRequest(root, "app://mosaic/..%2fsecret.txt");
    expect(out.status).toBe(403);
    expect(out.body).not.toContain("secret\n");
    // Refusals carry the policy too.
    expect(out.headers["Content-Security-Policy"]).toBe(CONTENT_SECURITY_POLICY);
  });

  test("a symbolic link may not lead out of the root", async () => {
    const r = await serveAppRequest(root, "app://mosaic/link.txt");
    expect([403, 404]).toContain(r.status);
    expect(r.body).not.toBe("secret");
  });

  test("content types", () => {
    expect(contentType("a.js")).toBe("text/javascript; charset=utf-8");
    expect(contentType("a.CSS")).toBe("text/css; charset=utf-8");
    expect(contentType("pipelines/index.json")).toBe("application/json; charset=utf-8");
    expect(contentType("x.bin")).toBe("application/octet-stream");
  });
});
