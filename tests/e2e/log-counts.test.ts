/**
 * End-to-end (issue 17, defect 9): the Log and the warnings banner agree. A pipeline with load
 * warnings (the MOSAIC-syntax example: its positional Params are converted, one warning per
 * block) shows the same count in the banner, in the Log's counts and in the Log's list; loading
 * another pipeline starts the counts again. Waits on conditions only (no fixed sleeps).
 */
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { Page } from "playwright-core";
import {
  artifact,
  haveChromium,
  launchChromium,
  openApp,
  serveApp,
  type Chromium,
  type Served,
} from "./harness";

const LEGACY = "pipelines/legacy/mosaic-syntax.yaml";
const DEMO = "pipelines/demo.yaml";

/** A load warning of the MOSAIC-syntax example, as the banner and the Log word it. */
const CONVERTED = "converted MOSAIC positional";

/**
 * What the page says about warnings, read at one moment: the banner, the Log's counts and the
 * (open) Log's list of the current load. Runtime warnings, should a block raise one on a busy
 * machine, are counted by the Log and listed there too; the load's own are told by their text.
 */
interface Shown {
  bannerTitle: string;
  bannerWarnings: number;
  countsText: string;
  countsWarnings: number;
  countsErrors: number;
  listedWarnings: number;
  listedErrors: number;
  listedLoadWarnings: number;
}

function shown(page: Page): Promise<Shown> {
  return page.evaluate((converted) => {
    const doc = (globalThis as unknown as { document: Doc }).document;
    const counts = doc.querySelector(".event-log__counts");
    const listed = (level: string): string[] =>
      Array.from(
        doc.querySelectorAll(`#event-log-list [data-level="${level}"]`),
        (e) => e.textContent ?? "",
      );
    return {
      bannerTitle: doc.querySelector(".warnings-banner .diagnostics h2")?.textContent ?? "",
      bannerWarnings: doc.querySelectorAll('.warnings-banner [data-severity="warning"]').length,
      countsText: counts?.textContent ?? "",
      countsWarnings: Number(counts?.getAttribute("data-warnings")),
      countsErrors: Number(counts?.getAttribute("data-errors")),
      listedWarnings: listed("warning").length,
      listedErrors: listed("error").length,
      listedLoadWarnings: listed("warning").filter((t) => t.includes(converted)).length,
    };
  }, CONVERTED);
}

/** The page's document as the evaluated functions see it (this file has no DOM library). */
interface Doc {
  querySelector(s: string): {
    textContent: string | null;
    getAttribute(name: string): string | null;
  } | null;
  querySelectorAll(s: string): ArrayLike<{ textContent: string | null }>;
}

/** The Log's counts are what its list holds, said plainly ("no errors" never beside warnings). */
function expectCountsMatchList(s: Shown): void {
  expect(s.countsWarnings).toBe(s.listedWarnings);
  expect(s.countsErrors).toBe(s.listedErrors);
  if (s.countsWarnings > 0) {
    expect(s.countsText).toContain(`${s.countsWarnings} warning`);
    expect(s.countsText).not.toContain("no errors");
  }
}

/** Loads `file` with the picker and waits until it runs. */
async function loadWithPicker(page: Page, file: string): Promise<void> {
  await page.selectOption(".picker select", file);
  await page.click('button:has-text("Load")');
  await page.waitForSelector(
    `.app[data-pipeline="${file}"][data-loading="false"][data-engine-state="running"]`,
  );
}

describe.skipIf(!haveChromium)("the Log's counts (Chromium)", () => {
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

  test("load warnings: one count in the banner and the Log; a new load starts again", async () => {
    const app = await openApp(chromium, served.url, LEGACY);
    const { page } = app;
    await page.waitForSelector(".warnings-banner .diagnostics");
    const banner = await shown(page);
    const n = banner.bannerWarnings;
    expect(n).toBeGreaterThan(0);
    expect(banner.bannerTitle).toContain(`${n} warnings while loading`);
    // The Log's counts say the same, plainly, and never "no errors" beside them…
    expect(banner.countsWarnings).toBeGreaterThanOrEqual(n);
    expect(banner.countsErrors).toBe(0);
    expect(banner.countsText).toContain("warnings");
    expect(banner.countsText).not.toContain("no errors");
    // …and the Log lists the load's warnings, as many as the banner and its counts say.
    await page.click(".event-log__toggle");
    await page.waitForSelector("#event-log-list");
    const first = await shown(page);
    expect(first.listedLoadWarnings).toBe(n);
    expectCountsMatchList(first);
    await page.screenshot({ path: artifact("log-counts-warnings.png") });

    // Another pipeline, without load warnings: the counts start again.
    await loadWithPicker(page, DEMO);
    await page.waitForSelector(".warnings-banner", { state: "detached" });
    const second = await shown(page);
    expect(second.listedLoadWarnings).toBe(0);
    expectCountsMatchList(second);
    expect(second.countsWarnings).toBeLessThan(n);

    // Back to the first: the same count again, not twice it.
    await loadWithPicker(page, LEGACY);
    await page.waitForSelector(".warnings-banner .diagnostics");
    const third = await shown(page);
    expect(third.bannerWarnings).toBe(n);
    expect(third.listedLoadWarnings).toBe(n);
    expectCountsMatchList(third);
    expect(third.countsWarnings).toBeLessThan(2 * n);
    expect(app.errors).toEqual([]);
    await app.close();
  }, 120_000);
});
