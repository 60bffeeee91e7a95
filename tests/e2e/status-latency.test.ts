/**
 * End-to-end (issue 17, defect 10): the Status tab never shows a negative latency. The demo's
 * timer-paced sources (Timer, Emg) emit their ticks up to ~0.2 ms before the ticks' deadlines,
 * which read as "Latency −5 µs" … "−100 µs" before the fix (app/ui/panels/latency.ts). Reads the
 * figure at every change until enough changes were seen (conditions, no fixed sleeps).
 */
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { Page } from "playwright-core";
import {
  haveChromium,
  launchChromium,
  openApp,
  serveApp,
  type Chromium,
  type Served,
} from "./harness";

/** How many different readings of the figure to see per block. */
const CHANGES = 12;

/** Opens `block`'s Status tab and collects the Latency figure's readings as they change. */
async function latencyReadings(page: Page, block: string): Promise<string[]> {
  await page.click(`.block-node[data-block="${block}"]`);
  await page.click(`[data-panel="${block}"] [data-tab="status"]`);
  const sel = `[data-panel="${block}"] .mp-figure:has(dt:text-is("Latency")) dd`;
  await page.waitForSelector(sel);
  const dd = await page.$(sel);
  const handle = await page.waitForFunction(
    ([el, n]) => {
      const g = globalThis as unknown as { __latency?: string[] };
      const seen = (g.__latency ??= []);
      const text = (el as { textContent: string | null }).textContent ?? "";
      if (seen[seen.length - 1] !== text) seen.push(text);
      // Stop at once on a negative reading, else after n changes.
      return seen.some((s) => /^[−-]/.test(s)) || seen.length >= n ? seen.splice(0) : false;
    },
    [dd, CHANGES] as const,
    { polling: 50, timeout: 60_000 },
  );
  return (await handle.jsonValue()) as string[];
}

describe.skipIf(!haveChromium)("the Status tab's latency (Chromium)", () => {
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

  test("timer-paced sources never read a negative latency", async () => {
    const app = await openApp(chromium, served.url);
    for (const block of ["Emg", "Timer"]) {
      const readings = await latencyReadings(app.page, block);
      expect(readings.length, `${block}: ${readings.join(", ")}`).toBeGreaterThanOrEqual(CHANGES);
      for (const r of readings) expect(r, `${block}: ${readings.join(", ")}`).toMatch(/^\d/);
    }
    expect(app.errors).toEqual([]);
    await app.close();
  }, 150_000);
});
