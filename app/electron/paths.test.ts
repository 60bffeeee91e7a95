import { join, sep } from "node:path";
import { describe, expect, test } from "vitest";
import { appLayout, unpackedPath } from "./paths";

describe("app layout", () => {
  test("development: the repository's dist and pipelines", () => {
    const repo = join(sep, "work", "mosaic");
    const l = appLayout({ mainDir: join(repo, "dist", "electron"), isPackaged: false });
    expect(l).toEqual({
      preload: join(repo, "dist", "electron", "preload.cjs"),
      webRoot: join(repo, "dist", "web"),
      sessionWorker: join(repo, "dist", "session.worker.mjs"),
      wasm: join(repo, "dist", "mosaic_core_bg.wasm"),
      pipelinesBase: repo,
    });
  });

  test("packaged: engine and UI files from app.asar.unpacked, pipelines from resources", () => {
    const res = join(sep, "opt", "MOSAIC", "resources");
    const l = appLayout({
      mainDir: join(res, "app.asar", "dist", "electron"),
      isPackaged: true,
      resourcesPath: res,
    });
    expect(l.preload).toBe(join(res, "app.asar", "dist", "electron", "preload.cjs"));
    expect(l.sessionWorker).toBe(join(res, "app.asar.unpacked", "dist", "session.worker.mjs"));
    expect(l.wasm).toBe(join(res, "app.asar.unpacked", "dist", "mosaic_core_bg.wasm"));
    expect(l.webRoot).toBe(join(res, "app.asar.unpacked", "dist", "web"));
    expect(l.pipelinesBase).toBe(res);
  });

  test("unpackedPath rewrites only the asar folder", () => {
    expect(unpackedPath(join(sep, "a", "app.asar", "x.mjs"))).toBe(
      join(sep, "a", "app.asar.unpacked", "x.mjs"),
    );
    expect(unpackedPath(join(sep, "a", "app.asar"))).toBe(join(sep, "a", "app.asar.unpacked"));
    expect(unpackedPath(join(sep, "a", "my.app.asarx", "x"))).toBe(
      join(sep, "a", "my.app.asarx", "x"),
    );
    expect(unpackedPath(join(sep, "a", "b"))).toBe(join(sep, "a", "b"));
  });
});
