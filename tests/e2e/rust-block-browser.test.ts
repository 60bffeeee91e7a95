/**
 * rustBlock in a browser (issue 18): the template built with cargo, its bytes handed to a Web
 * Worker in Chromium (where the browser build's engine runs) that wraps them with rustBlock and
 * runs the block: the output equals the NumPy reference bit for bit, split into frames of 1 or of
 * 600 events alike; a module of another ABI version is refused there with the same words as in
 * Node.
 */
import { rmSync } from "node:fs";
import { join } from "node:path";
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { abiVersionEdit, buildTemplate, tkeoFixture } from "../support/rust-template";
import { tempDir } from "../integration/helpers";
import { haveChromium, launchChromium, ROOT, type Chromium } from "./harness";
import type { WorkerReply, WorkerRequest } from "./rust-block-worker";

const fixture = tkeoFixture();

/** The part of the page's Worker API used here (this file is type-checked without the DOM). */
interface PageWorker {
  onmessage: ((e: { data: WorkerReply }) => void) | null;
  onerror: ((e: { message: string }) => void) | null;
  postMessage(data: unknown): void;
  terminate(): void;
}
interface PageGlobals {
  Worker: new (url: string) => PageWorker;
  Blob: new (parts: string[], options: { type: string }) => object;
  URL: { createObjectURL(blob: object): string };
}

/** Runs one request in a fresh Web Worker of `page` built from `code`. */
async function inWorker(page: Page, code: string, req: WorkerRequest): Promise<WorkerReply> {
  const wasm = Array.from(req.wasm);
  return page.evaluate(
    ({ code, req, wasm }) =>
      new Promise<WorkerReply>((resolve) => {
        const g = globalThis as unknown as PageGlobals;
        const url = g.URL.createObjectURL(new g.Blob([code], { type: "text/javascript" }));
        const worker = new g.Worker(url);
        worker.onmessage = (e) => {
          worker.terminate();
          resolve(e.data);
        };
        worker.onerror = (e) => resolve({ ok: false, message: `worker: ${e.message}` });
        worker.postMessage({ ...req, wasm: new Uint8Array(wasm) });
      }),
    { code, req: { ...req, wasm: new Uint8Array(0) }, wasm },
  );
}

describe.skipIf(!haveChromium)("rustBlock in a browser's Web Worker (Chromium)", () => {
  let work: string;
  let tkeo: Uint8Array;
  let abi2: Uint8Array;
  let code: string;
  let browser: Chromium;
  let page: Page;

  beforeAll(async () => {
    work = tempDir("mosaic-e2e-rust-browser-");
    tkeo = buildTemplate(join(work, "tkeo"));
    abi2 = buildTemplate(join(work, "abi2"), [abiVersionEdit(2)]);
    const esbuild = await import("esbuild");
    const built = await esbuild.build({
      entryPoints: [join(ROOT, "tests/e2e/rust-block-worker.ts")],
      bundle: true,
      write: false,
      format: "iife",
      platform: "browser",
      logLevel: "error",
    });
    code = built.outputFiles[0]!.text;
    browser = await launchChromium();
    page = await browser.context.newPage();
    await page.setContent("<!doctype html><title>rustBlock</title>");
  }, 300_000);

  afterAll(async () => {
    await browser?.close();
    rmSync(work, { recursive: true, force: true });
  });

  test("equals the NumPy reference bit for bit, however the events are split", async () => {
    for (const [split, rectify] of [
      [fixture.frames, false],
      [1, false],
      [7, true],
    ] as const) {
      const reply = await inWorker(page, code, {
        wasm: tkeo,
        channels: fixture.channels,
        input: fixture.input,
        split,
        rectify,
      });
      if (!reply.ok) throw new Error(reply.message);
      expect(reply.frames).toBe(Math.ceil(fixture.frames / split));
      const expected = rectify ? fixture.expected_rectified : fixture.expected;
      expect(reply.values.length).toBe(expected.length);
      const differing = reply.values.flatMap((v, i) => (Object.is(v, expected[i]) ? [] : [i]));
      expect(differing).toEqual([]);
    }
  }, 120_000);

  test("refuses a module of another ABI version with what to do", async () => {
    const reply = await inWorker(page, code, {
      wasm: abi2,
      channels: fixture.channels,
      input: fixture.input.slice(0, 3),
      split: 1,
      rectify: false,
    });
    expect(reply).toEqual({
      ok: false,
      message:
        "tkeo.wasm speaks Rust block ABI version 2, but this MOSAIC speaks version 1 " +
        "(docs/rust-block-abi.md): update MOSAIC, or rebuild the block from this MOSAIC's template",
    });
  }, 120_000);
});
