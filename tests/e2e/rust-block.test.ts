/**
 * A block written in Rust (issue 18) in the UI that `mosaic serve` serves, made as
 * docs/writing-blocks.md ("Rust blocks") says, in a folder outside the repository:
 * `mosaic new-block --rust tkeo`, the cargo build, the guide's pipeline. The page shows the Rust
 * block's node running and lists its type in the editor's palette with its summary; rebuilding
 * the kernel reloads it (the Log says `reloaded tkeo.wasm: pipeline restarted`); a rebuild of
 * another ABI version leaves the running version running and the Log says why. In the browser
 * build, the block bundled into one block.js with the guide's esbuild command runs in the page's
 * engine and is in the palette.
 */
import { spawnSync } from "node:child_process";
import { mkdirSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { requireBuild, runCli, tempDir } from "../integration/helpers";
import {
  artifact,
  ensureWebBuild,
  haveChromium,
  launchChromium,
  openApp,
  ROOT,
  serveApp,
  type Chromium,
  type CliServer,
  type Served,
  startCliServer,
} from "./harness";

/** The pipeline of the guide's Rust section (the YAML block that names tkeo/block.ts). */
function guidePipeline(): string {
  const md = readFileSync(join(ROOT, "docs/writing-blocks.md"), "utf8");
  const yaml = [...md.matchAll(/```yaml\n([\s\S]*?)```/g)]
    .map((m) => m[1]!)
    .find((text) => text.includes("tkeo/block.ts"));
  if (yaml === undefined) throw new Error("docs/writing-blocks.md has no pipeline for tkeo");
  return yaml;
}

/** The guide's esbuild command for the browser build, run with MOSAIC's own esbuild. */
function bundleForBrowser(crate: string): void {
  const md = readFileSync(join(ROOT, "docs/writing-blocks.md"), "utf8");
  const line = md.split("\n").find((l) => l.startsWith("npx esbuild block.ts"));
  if (line === undefined) throw new Error("docs/writing-blocks.md has no esbuild command");
  const args = line.split(/\s+/).slice(2);
  const r = spawnSync(join(ROOT, "node_modules/.bin/esbuild"), args, {
    cwd: crate,
    encoding: "utf8",
    timeout: 60_000,
  });
  if (r.status !== 0) throw new Error(`esbuild failed:\n${r.stderr}`);
}

function cargoBuild(crate: string): void {
  const r = spawnSync("cargo", ["build", "--release", "--target", "wasm32-unknown-unknown"], {
    cwd: crate,
    encoding: "utf8",
    timeout: 240_000,
  });
  if (r.status !== 0) throw new Error(`cargo build failed:\n${r.stderr}`);
}

/** Replaces `from` (which must be there) with `to` in `file`. */
function edit(file: string, from: string, to: string): void {
  const text = readFileSync(file, "utf8");
  if (!text.includes(from)) throw new Error(`${file} has no '${from}'`);
  writeFileSync(file, text.replace(from, to));
}

/** The text of the Log's entries (opened once). */
async function logText(page: import("playwright-core").Page): Promise<string> {
  if ((await page.$("#event-log-list")) === null) await page.click(".event-log__toggle");
  await page.waitForSelector("#event-log-list");
  return (await page.textContent("#event-log-list")) ?? "";
}

describe.skipIf(!haveChromium)("a Rust block in mosaic serve's UI (Chromium)", () => {
  let server: CliServer | undefined;
  let url: string;
  let browser: Chromium;
  let dir: string;

  beforeAll(async () => {
    ensureWebBuild();
    requireBuild();
    dir = tempDir("mosaic-e2e-rust-block-");
    const made = runCli(["new-block", "--rust", "tkeo", dir]);
    if (made.code !== 0) throw new Error(`new-block failed: ${made.stderr}`);
    cargoBuild(join(dir, "tkeo"));
    writeFileSync(join(dir, "pipeline.yaml"), guidePipeline());
    server = await startCliServer(["serve", join(dir, "pipeline.yaml"), "--port", "0"]);
    url = server.url;
    browser = await launchChromium();
  }, 300_000);

  afterAll(async () => {
    await browser?.close();
    await server?.stop();
  });

  test("runs, is in the palette, and a rebuilt kernel reloads it visibly", async () => {
    const { page, errors, close } = await openApp(browser, url);
    await page.waitForSelector('[data-block="Energy"][data-status="ontime"]', { timeout: 20_000 });
    expect(await page.textContent('[data-block="Energy"]')).toContain("Tkeo");

    await page.click('button:has-text("Edit")');
    const item = page.locator('.palette__item[data-block-type="Tkeo"]');
    await item.waitFor({ timeout: 15_000 });
    expect(await item.textContent()).toContain("Teager–Kaiser energy of every channel");
    await page.screenshot({ path: artifact("rust-block-palette.png") });
    await page.click('button:has-text("Edit")');

    // A changed kernel, rebuilt: the module reloads and the pipeline restarts.
    const crate = join(dir, "tkeo");
    edit(
      join(crate, "src/tkeo.rs"),
      "let psi = x1 * x1 - x2 * x[c];",
      "let psi = 2.0 * (x1 * x1 - x2 * x[c]);",
    );
    cargoBuild(crate);
    await expect
      .poll(() => logText(page), { timeout: 30_000 })
      .toContain("reloaded tkeo.wasm: pipeline restarted");
    await page.waitForSelector('[data-block="Energy"][data-status="ontime"]', { timeout: 20_000 });

    // A module of another ABI version does not load; the running version stays.
    edit(join(crate, "src/abi.rs"), "ABI_VERSION: u32 = 1", "ABI_VERSION: u32 = 2");
    cargoBuild(crate);
    await expect
      .poll(() => logText(page), { timeout: 30_000 })
      .toMatch(
        /tkeo\.wasm changed but does not load, the previous version keeps running: cannot load user blocks from tkeo\/block\.ts(:\d+:\d+)?: its top level threw: tkeo\.wasm speaks Rust block ABI version 2, but this MOSAIC speaks version 1/,
      );
    await page.screenshot({ path: artifact("rust-block-abi-mismatch.png") });
    expect(await page.getAttribute(".app", "data-engine-state")).toBe("running");
    await page.waitForSelector('[data-block="Energy"][data-status="ontime"]', { timeout: 20_000 });
    expect(errors).toEqual([]);
    await close();
  }, 300_000);
});

describe.skipIf(!haveChromium)("a Rust block in the browser build (Chromium)", () => {
  let served: Served;
  let browser: Chromium;

  beforeAll(async () => {
    served = await serveApp();
    const dir = join(served.root, "e2e", "rust");
    mkdirSync(dir);
    const made = runCli(["new-block", "--rust", "tkeo", dir]);
    if (made.code !== 0) throw new Error(`new-block failed: ${made.stderr}`);
    cargoBuild(join(dir, "tkeo"));
    bundleForBrowser(join(dir, "tkeo"));
    writeFileSync(
      join(dir, "pipeline.yaml"),
      guidePipeline().replace("tkeo/block.ts", "tkeo/block.js"),
    );
    browser = await launchChromium();
  }, 300_000);

  afterAll(async () => {
    await browser?.close();
    await served?.close();
  });

  test("its bundled block.js runs in the page's engine and is in the palette", async () => {
    const { page, errors, close } = await openApp(browser, served.url, "e2e/rust/pipeline.yaml");
    await page.waitForSelector('[data-block="Energy"][data-status="ontime"]', { timeout: 20_000 });
    expect(await page.textContent("header")).toMatch(/in this page/);
    expect(await page.textContent('[data-block="Energy"]')).toContain("Tkeo");
    await page.click('button:has-text("Edit")');
    const item = page.locator('.palette__item[data-block-type="Tkeo"]');
    await item.waitFor({ timeout: 15_000 });
    expect(await item.textContent()).toContain("Teager–Kaiser energy of every channel");
    await page.screenshot({ path: artifact("rust-block-browser.png") });
    expect(errors).toEqual([]);
    await close();
  }, 120_000);
});
