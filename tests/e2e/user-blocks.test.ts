/**
 * A block written by a user (issue 18) in the UI that `mosaic serve` serves: the guide's
 * (docs/writing-blocks.md) block and pipeline in a folder outside the repository; the page shows
 * the user block's node running, lists its type in the editor's palette (with its help), and
 * saving the block's file reloads it: the pipeline restarts and the Log says so; a save with a
 * syntax error leaves the running version running and the Log names the file and line.
 */
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

/** The guide's block and pipeline, written into `dir`. */
function projectFromGuide(dir: string): void {
  const md = readFileSync(join(ROOT, "docs/writing-blocks.md"), "utf8");
  const code = [...md.matchAll(/```(\w+)\n([\s\S]*?)```/g)].map((m) => ({
    lang: m[1]!,
    text: m[2]!,
  }));
  mkdirSync(join(dir, "blocks"));
  writeFileSync(
    join(dir, "blocks/smoother.ts"),
    code.find((c) => c.lang === "ts" && c.text.includes("defineBlock({"))!.text,
  );
  writeFileSync(
    join(dir, "pipeline.yaml"),
    code.find((c) => c.lang === "yaml" && c.text.includes("Blocks:"))!.text,
  );
}

/** The text of the Log's entries (opened once). */
async function logText(page: import("playwright-core").Page): Promise<string> {
  if ((await page.$("#event-log-list")) === null) await page.click(".event-log__toggle");
  await page.waitForSelector("#event-log-list");
  return (await page.textContent("#event-log-list")) ?? "";
}

describe.skipIf(!haveChromium)("a user's block in mosaic serve's UI (Chromium)", () => {
  let server: CliServer | undefined;
  let url: string;
  let browser: Chromium;
  let dir: string;

  beforeAll(async () => {
    ensureWebBuild();
    requireBuild();
    dir = tempDir("mosaic-e2e-user-blocks-");
    projectFromGuide(dir);
    server = await startCliServer(["serve", join(dir, "pipeline.yaml"), "--port", "0"]);
    url = server.url;
    browser = await launchChromium();
  }, 60_000);

  afterAll(async () => {
    await browser?.close();
    await server?.stop();
  });

  test("runs, is in the palette, and a saved file reloads it visibly", async () => {
    const { page, errors, close } = await openApp(browser, url);
    // The user block's node runs with the built-in ones.
    await page.waitForSelector('[data-block="Smooth"][data-status="ontime"]', { timeout: 20_000 });
    expect(await page.textContent('[data-block="Smooth"]')).toContain("Smoother");

    // The editor's palette lists the type, with the guide's help and the file it came from.
    await page.click('button:has-text("Edit")');
    const item = page.locator('.palette__item[data-block-type="Smoother"]');
    await item.waitFor({ timeout: 15_000 });
    expect(await item.textContent()).toContain("Exponential smoothing of every channel");
    // The editor checks the text as mosaic validate does, user blocks included: no problems.
    await page.waitForSelector('.editor[data-checking="false"][data-errors="0"]', {
      timeout: 15_000,
    });
    await page.screenshot({ path: artifact("user-blocks-palette.png") });
    await page.click('button:has-text("Edit")');

    // Saving the block's file reloads it: the pipeline restarts and the Log says so.
    const file = join(dir, "blocks/smoother.ts");
    const good = readFileSync(file, "utf8");
    writeFileSync(file, good.replace("near 0 it smooths a lot", "near 0 it smooths much"));
    await expect
      .poll(() => logText(page), { timeout: 20_000 })
      .toContain("reloaded smoother.ts: pipeline restarted");
    await page.waitForSelector('[data-block="Smooth"][data-status="ontime"]', { timeout: 20_000 });

    // A save with a syntax error: the running version stays, the Log names the file and line.
    writeFileSync(file, good.replace("const n = shape.rows", "const n = = shape.rows"));
    await expect
      .poll(() => logText(page), { timeout: 20_000 })
      .toMatch(
        /smoother\.ts changed but does not load, the previous version keeps running: cannot load user blocks from blocks\/smoother\.ts:\d+:\d+/,
      );
    await page.screenshot({ path: artifact("user-blocks-reload.png") });
    expect(await page.getAttribute(".app", "data-engine-state")).toBe("running");
    await page.waitForSelector('[data-block="Smooth"][data-status="ontime"]', { timeout: 20_000 });
    writeFileSync(file, good);

    // The editor checks a user block's params with its own schema, at their line, in the CLI's words.
    const text = readFileSync(join(dir, "pipeline.yaml"), "utf8").replace("Alpha: 0.2", "Alpha: 5");
    writeFileSync(join(dir, "too-big.yaml"), text);
    const cli = runCli(["validate", "too-big.yaml"], { cwd: dir });
    const want = cli.stderr.split("\n").find((l) => l.includes(": error: "))!;
    expect(want).toMatch(/too-big\.yaml:\d+:\d+: error: block 'Smooth' \(Smoother\): .*Alpha/);
    await page.click('button:has-text("Edit")');
    await page.click('.text-view [aria-label="Pipeline YAML"]');
    await page.keyboard.press("Control+a");
    await page.keyboard.insertText(text);
    const message = want.replace(/^.*?: error: /, "");
    await page.waitForFunction(
      (m) =>
        Array.from(
          (
            globalThis as unknown as {
              document: { querySelectorAll(s: string): { textContent: string | null }[] };
            }
          ).document.querySelectorAll(".text-view__issues li"),
          (li) => li.textContent ?? "",
        ).some((t) => t.includes(m)),
      message,
      { timeout: 20_000 },
    );
    expect(errors).toEqual([]);
    await close();
  }, 120_000);
});

describe.skipIf(!haveChromium)("a user's JavaScript block in the browser build (Chromium)", () => {
  let served: Served;
  let browser: Chromium;

  beforeAll(async () => {
    served = await serveApp();
    browser = await launchChromium();
  }, 120_000);

  afterAll(async () => {
    await browser?.close();
    await served?.close();
  });

  test("a module served beside the pipeline runs in the page's engine and is in the palette", async () => {
    const { page, errors, close } = await openApp(
      browser,
      served.url,
      "e2e/user-blocks/pipeline.yaml",
    );
    await page.waitForSelector('[data-block="Smooth"][data-status="ontime"]', { timeout: 20_000 });
    expect(await page.textContent("header")).toMatch(/in this page/);
    await page.click('button:has-text("Edit")');
    await page.locator('.palette__item[data-block-type="Smoother"]').waitFor({ timeout: 15_000 });
    await page.screenshot({ path: artifact("user-blocks-browser.png") });
    expect(errors).toEqual([]);
    await close();
  }, 60_000);

  test("a TypeScript module is refused with the reason, at its Blocks: line", async () => {
    const { page, close } = await openApp(browser, served.url, "e2e/user-blocks/typescript.yaml", {
      waitRunning: false,
    });
    await page.waitForFunction(
      `/typescript\\.yaml:3:\\d+.*cannot load user blocks from blocks\\/smoother\\.ts: the browser build cannot transpile TypeScript/s.test(document.body.textContent || "")`,
      undefined,
      { timeout: 20_000 },
    );
    await close();
  }, 60_000);
});
