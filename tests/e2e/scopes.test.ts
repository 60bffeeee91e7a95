/**
 * Scopes and panel views in the browser build (issue 17: the Scopes features and defect 10):
 * channel and gesture names, zoom/pan/pause with a cursor readout, the spectrum with its median
 * frequency, CSV and PNG export of the visible window, resizable and popped-out panels, and a
 * recording Buffer that does not read idle. Real Chromium, the engine in the page's worker; waits
 * are on what the page shows, never on fixed sleeps.
 */
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { Page } from "playwright-core";
import type { EngineClient } from "../../app/ui/client/engine-client";
import {
  artifact,
  haveChromium,
  launchChromium,
  openApp,
  serveApp,
  type Chromium,
  type Served,
} from "./harness";

interface InPage {
  mosaic: { client: EngineClient };
  statusSeen: string[];
}

/**
 * The statuses the engine reports for `block` in its next `n` telemetry messages (20 a second),
 * as the graph's node colours them.
 */
async function telemetryStatuses(page: Page, block: string, n: number): Promise<string[]> {
  await page.evaluate((b) => {
    const w = globalThis as unknown as InPage;
    w.statusSeen = [];
    w.mosaic.client.connection.onMessage((m) => {
      if (m.type !== "telemetry") return;
      const s = m.telemetry.blocks.find((x) => x.name === b)?.status;
      if (s) w.statusSeen.push(s);
    });
  }, block);
  await page.waitForFunction((k) => (globalThis as unknown as InPage).statusSeen.length >= k, n, {
    timeout: 30_000,
  });
  return page.evaluate(() => (globalThis as unknown as InPage).statusSeen);
}

describe.skipIf(!haveChromium)("scopes and panel views (browser build, Chromium)", () => {
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

  test("a Buffer that records (and emits nothing) is not idle while it writes rows", async () => {
    const app = await openApp(chromium, served.url, "e2e/recorder-status.yaml");
    const { page } = app;
    const node = '.block-node[data-block="Recorder"]';
    // Its status text says it records (the capture phase lasts 10 minutes).
    await page.click(node);
    await page.waitForSelector('[data-panel="Recorder"] .mp-status-text:has-text("recording")', {
      timeout: 20_000,
    });
    const seen = await telemetryStatuses(page, "Recorder", 40);
    expect(seen.filter((s) => s === "idle")).toEqual([]);
    expect(await page.getAttribute(node, "data-status")).toBe("ontime");
    await page.screenshot({ path: artifact("recorder-status.png") });
    expect(app.errors).toEqual([]);
    await app.close();
  }, 90_000);

  test("channels and outputs are named: EMG 1…8 and the gestures in legends, picker and labels", async () => {
    const app = await openApp(chromium, served.url, "pipelines/examples/training.yaml");
    const { page } = app;
    const legend = (panel: string) =>
      page.locator(`[data-panel="${panel}"] .mp-legend .mp-chip`).allTextContents();
    await page.click('.block-node[data-block="Myo"]');
    await page.waitForSelector('[data-panel="Myo"] .mp-legend .mp-chip');
    expect(await legend("Myo")).toEqual(Array.from({ length: 8 }, (_, k) => `EMG ${k + 1}`));
    // The channel picker's toggles.
    await page.click('[data-panel="Myo"] .mp-picker > button');
    expect(await page.locator('[data-panel="Myo"] .mp-toggles label').allTextContents()).toEqual(
      Array.from({ length: 8 }, (_, k) => `EMG ${k + 1}`),
    );

    const gestures = ["fist", "open", "pinch", "flexion", "extension"];
    await page.click('.block-node[data-block="Predictor"]');
    await page.waitForSelector('[data-panel="Predictor"] .mp-legend .mp-chip');
    expect(await legend("Predictor")).toEqual(gestures);
    // The spider's spokes and the label view.
    await page.click('[data-panel="Predictor"] [data-tab="spider"]');
    await page.waitForSelector('[data-panel="Predictor"] [data-view="spider"]');
    const spider = await page.getAttribute(
      '[data-panel="Predictor"] [data-view="spider"] canvas',
      "aria-label",
    );
    for (const g of gestures) expect(spider).toContain(g);
    await page.click('[data-panel="Predictor"] [data-tab="label"]');
    await page.waitForSelector('[data-panel="Predictor"] [data-view="label"] dt');
    const dts = await page
      .locator('[data-panel="Predictor"] section[aria-label="Output prediction"] dt')
      .allTextContents();
    expect(dts).toEqual(gestures);
    // The fit output sends values once the first capture trains the model (about 3 s in).
    await page.waitForSelector('[data-panel="Predictor"] section[aria-label="Output fit"] dt', {
      timeout: 30_000,
    });
    const fit = await page
      .locator('[data-panel="Predictor"] section[aria-label="Output fit"] dt')
      .allTextContents();
    expect(fit).toEqual(["samples", ...gestures.map((g) => `R² ${g}`)]);
    await page.screenshot({ path: artifact("names-training.png") });
    expect(app.errors).toEqual([]);
    await app.close();
  }, 90_000);
});
