/**
 * End-to-end (issue 17, defect 4): opening a file that does not load leaves the running pipeline
 * running, named in the header's picker and the window's title, with the file's errors shown
 * beside it; applying an untitled pipeline from the editor renames the header to it. Waits on
 * conditions only (no fixed sleeps).
 */
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { Page } from "playwright-core";
import {
  artifact,
  haveChromium,
  launchChromium,
  openApp,
  ROOT,
  serveApp,
  type Chromium,
  type Served,
} from "./harness";

const DEMO = "pipelines/demo.yaml";
const UNTITLED = "pipelines/untitled.yaml";
const BROKEN = join(ROOT, "tests/e2e/fixtures/broken.yaml");

/** A small valid pipeline typed into the editor's YAML pane. */
const SMALL =
  "Timer: { Type: ScheduledTimer, DesiredRate: 100 }\n" +
  "Emg: { Type: EmgSimulator, Inputs: [Timer] }\n" +
  "Out: { Type: Sink, Inputs: [Emg] }\n";

/** The page as the evaluated functions see it (this file has no DOM library). */
interface InPage {
  mosaic: { client: { telemetry?: { t: number } } };
}

/** The engine's time in its latest telemetry (-1: none yet). */
function engineTime(page: Page): Promise<number> {
  return page.evaluate(() => (globalThis as unknown as InPage).mosaic.client.telemetry?.t ?? -1);
}

/** Waits until the engine's time has gone `by` seconds past `from` (it is still running). */
async function timeAdvances(page: Page, from: number, by: number): Promise<void> {
  await page.waitForFunction(
    ([t0, d]) => ((globalThis as unknown as InPage).mosaic.client.telemetry?.t ?? -1) > t0! + d!,
    [from, by],
    { timeout: 20_000 },
  );
}

/** What names the pipeline: the picker's choice, its text and the window's title. */
async function named(page: Page): Promise<{ value: string; text: string; title: string }> {
  const select = page.locator(".picker select");
  return {
    value: await select.inputValue(),
    text: (await select.locator("option:checked").textContent()) ?? "",
    title: await page.title(),
  };
}

describe.skipIf(!haveChromium)("a file that does not load (Chromium)", () => {
  let served: Served;
  let chromium: Chromium;
  beforeAll(async () => {
    served = await serveApp();
    chromium = await launchChromium();
  }, 180_000);
  afterAll(async () => {
    await chromium?.close();
    await served?.close();
  });

  test("keeps the demo running and named; an applied untitled pipeline is named untitled", async () => {
    const app = await openApp(chromium, served.url, DEMO);
    const { page } = app;
    await page.waitForSelector(`.app[data-pipeline="${DEMO}"][data-engine-state="running"]`);
    await timeAdvances(page, -1, 0);

    // Open a broken file: its errors are shown…
    await page.setInputFiles(".file-open input[type=file]", BROKEN);
    await page.waitForFunction(
      () =>
        Array.from(
          (
            globalThis as unknown as {
              document: { querySelectorAll(s: string): ArrayLike<{ textContent: string | null }> };
            }
          ).document.querySelectorAll(".diagnostics"),
        ).some((d) => (d.textContent ?? "").includes("unknown block type 'EmgSimulatr'")),
      undefined,
      { timeout: 20_000 },
    );
    await page.waitForSelector('.app[data-loading="false"]');
    const errors = (await page.textContent(".diagnostics"))!;
    expect(errors).toContain("broken.yaml:3:14");
    expect(errors).toContain("EmgSimulator");
    // …and the demo goes on: running, its time advancing, its blocks shown, named everywhere.
    expect(await page.getAttribute(".app", "data-engine-state")).toBe("running");
    await timeAdvances(page, await engineTime(page), 0.5);
    expect(await page.getAttribute(".app", "data-pipeline")).toBe(DEMO);
    expect(await page.locator('.block-node[data-block="Emg"]').count()).toBe(1);
    const afterBroken = await named(page);
    expect(afterBroken.value).toBe(DEMO);
    expect(afterBroken.text).toBe("demo.yaml");
    expect(afterBroken.title).toContain("demo.yaml");
    await page.screenshot({ path: artifact("keep-running-broken.png") });

    // The editor: an empty pipeline, a small valid text, Apply: the header names it untitled.
    await page.click('button:has-text("Edit")');
    await page.selectOption('select[aria-label="New pipeline from an example"]', "(empty)");
    await page.click('.text-view [aria-label="Pipeline YAML"]');
    await page.keyboard.press("Control+a");
    await page.keyboard.insertText(SMALL);
    await page.waitForSelector('.editor[data-errors="0"][data-checking="false"]', {
      timeout: 20_000,
    });
    await page.click('.editor__bar button:has-text("Apply")');
    await page.waitForSelector(
      `.app[data-pipeline="${UNTITLED}"][data-loading="false"][data-engine-state="running"]`,
      { timeout: 20_000 },
    );
    const afterApply = await named(page);
    expect(afterApply.value).toBe(UNTITLED);
    expect(afterApply.text).toBe("untitled.yaml");
    expect(afterApply.title).toContain("untitled.yaml");
    expect(afterApply.title).not.toContain("demo");
    await timeAdvances(page, await engineTime(page), 0.2);
    expect(app.errors).toEqual([]);
    await app.close();
  }, 120_000);
});
