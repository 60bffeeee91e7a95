/**
 * `mosaic web --port N` (what `npm start -- --port N` ends in, after scripts/setup.sh): the real
 * CLI bundle serves the browser build on the given port, prints its URL, sends the cross-origin
 * isolation headers, and stops cleanly on SIGTERM. Also the static server's option to leave those
 * headers out (the e2e test of the engine's fallback without SharedArrayBuffer uses it).
 */
import { spawn, type ChildProcess } from "node:child_process";
import { existsSync } from "node:fs";
import { createServer } from "node:net";
import { join } from "node:path";
import { afterEach, describe, expect, test } from "vitest";
import { serveStatic } from "../../app/host/web-server";
import { ROOT, WEB, ensureWebBuild, printedLine } from "./harness";

const CLI = join(ROOT, "dist/cli.mjs");

/** A port that was free a moment ago (listen on 0, read it, close). */
function freePort(): Promise<number> {
  return new Promise((resolve, reject) => {
    const s = createServer();
    s.once("error", reject);
    s.listen(0, "127.0.0.1", () => {
      const a = s.address();
      const port = typeof a === "object" && a ? a.port : 0;
      s.close(() => resolve(port));
    });
  });
}

const ISOLATION = {
  "cross-origin-opener-policy": "same-origin",
  "cross-origin-embedder-policy": "require-corp",
};

describe.skipIf(!existsSync(CLI))("mosaic web", () => {
  let child: ChildProcess | undefined;

  afterEach(() => {
    if (child && child.exitCode === null) child.kill("SIGKILL");
    child = undefined;
  });

  test("serves the browser build on --port N with COOP/COEP and prints the URL", async () => {
    ensureWebBuild();
    const port = await freePort();
    child = spawn(process.execPath, [CLI, "web", "--port", String(port)], {
      cwd: ROOT,
      stdio: ["ignore", "pipe", "pipe"],
      env: { ...process.env, NO_COLOR: "1" },
    });
    const line = await printedLine(child, /MOSAIC is at /, 15_000);
    expect(line).toBe(`MOSAIC is at http://127.0.0.1:${port}/`);

    const page = await fetch(`http://127.0.0.1:${port}/`);
    expect(page.status).toBe(200);
    expect(page.headers.get("content-type")).toMatch(/^text\/html/);
    for (const [k, v] of Object.entries(ISOLATION)) expect(page.headers.get(k)).toBe(v);
    expect(await page.text()).toContain('<div id="root">');
    for (const f of ["app.js", "engine.worker.js", "mosaic_core_bg.wasm", "pipelines/demo.yaml"]) {
      const r = await fetch(`http://127.0.0.1:${port}/${f}`);
      expect(r.status, f).toBe(200);
      expect(r.headers.get("cross-origin-embedder-policy"), f).toBe("require-corp");
      await r.arrayBuffer();
    }
    expect((await fetch(`http://127.0.0.1:${port}/../package.json`)).status).not.toBe(200);

    const exited = new Promise<number | null>((r) => child!.once("exit", (code) => r(code)));
    child.kill("SIGTERM");
    expect(await exited).toBe(0);
  });

  test("a port in use is an error that names the port", async () => {
    const port = await freePort();
    const busy = await serveStatic(WEB, port);
    try {
      child = spawn(process.execPath, [CLI, "web", "--port", String(port)], {
        cwd: ROOT,
        stdio: ["ignore", "pipe", "pipe"],
      });
      let stderr = "";
      child.stderr!.on("data", (d: Buffer) => (stderr += d.toString()));
      const code = await new Promise<number | null>((r) => child!.once("exit", (c) => r(c)));
      expect(code).toBe(1);
      expect(stderr).toContain(`port ${port}`);
      expect(stderr).toContain("--port N");
    } finally {
      await busy.close();
    }
  });
});

describe("serveStatic", () => {
  test("leaves COOP/COEP out with crossOriginIsolated: false", async () => {
    ensureWebBuild();
    const isolated = await serveStatic(WEB, 0);
    const plain = await serveStatic(WEB, 0, "127.0.0.1", { crossOriginIsolated: false });
    try {
      const a = await fetch(isolated.url);
      const b = await fetch(plain.url);
      await a.text();
      await b.text();
      expect(a.status).toBe(200);
      expect(b.status).toBe(200);
      for (const [k, v] of Object.entries(ISOLATION)) {
        expect(a.headers.get(k)).toBe(v);
        expect(b.headers.get(k)).toBeNull();
      }
      expect(b.headers.get("x-content-type-options")).toBe("nosniff");
    } finally {
      await isolated.close();
      await plain.close();
    }
  });
});
