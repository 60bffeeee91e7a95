/**
 * Issue 17 in the browser build (Chromium): the gesture legend's buttons (touch and mouse demos)
 * hold a gesture on the simulated participant as the keys do, and the Log downloads as a JSON
 * Lines file holding what it lists. Waits are on what the page shows, never on fixed sleeps.
 */
import { readFileSync } from "node:fs";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import {
  artifact,
  haveChromium,
  launchChromium,
  openApp,
  serveApp,
  type Chromium,
  type Served,
} from "./harness";

describe.skipIf(!haveChromium)("demo controls (browser build, Chromium)", () => {
  let served: Served;
  let chromium: Chromium;

  beforeAll(async () => {
    served = await serveApp();
    chromium = await launchChromium();
  }, 120_000);

  afterAll(async () => {
    await chromium?.close();
    await served?.close();
  });

  test("a click on a gesture button makes the simulated participant hold it", async () => {
    const app = await openApp(chromium, served.url);
    const { page } = app;
    const legend = page.getByRole("region", { name: /Simulated gestures/ });
    const fist = legend.getByRole("button", { name: /fist$/ });
    // Big enough to tap.
    const box = (await fist.boundingBox())!;
    expect(box.height).toBeGreaterThanOrEqual(32);
    await fist.click();
    await page.waitForSelector('[data-gesture="fist"][aria-current="true"]', { timeout: 15_000 });
    await page.waitForFunction(
      () =>
        (
          globalThis as unknown as {
            document: { querySelector(s: string): { textContent: string } | null };
          }
        ).document.querySelector('.block-node[data-block="Emg"] .block-node__note')?.textContent ===
        "fist",
      undefined,
      { timeout: 15_000 },
    );
    expect(await fist.getAttribute("aria-pressed")).toBe("true");
    await page.screenshot({ path: artifact("gesture-buttons.png") });
    // The rest button (0/Space) goes back to rest.
    await legend.getByRole("button", { name: /Space rest$/ }).click();
    await page.waitForSelector('[data-gesture="rest"][aria-current="true"]', { timeout: 15_000 });
    expect(await fist.getAttribute("aria-pressed")).toBe("false");
    expect(app.errors).toEqual([]);
    await app.close();
  });

  test("Download saves the Log as JSON Lines: the load and the replies it lists", async () => {
    const app = await openApp(chromium, served.url);
    const { page } = app;
    await page
      .getByRole("region", { name: /Simulated gestures/ })
      .getByRole("button", {
        name: /open$/,
      })
      .click();
    await page.waitForSelector('[data-gesture="open"][aria-current="true"]', { timeout: 15_000 });
    await page.getByRole("button", { name: /Log$/ }).click();
    await page.waitForSelector(".event-log__entry >> text=/open/");
    const [download] = await Promise.all([
      page.waitForEvent("download"),
      page.getByRole("button", { name: "Download" }).click(),
    ]);
    expect(download.suggestedFilename()).toMatch(/^mosaic-log-\d{8}-\d{6}\.jsonl$/);
    const lines = readFileSync((await download.path())!, "utf8")
      .trimEnd()
      .split("\n");
    const rows = lines.map(
      (l) =>
        JSON.parse(l) as {
          time: string;
          level: string;
          block: string;
          message: string;
          currentLoad: boolean;
        },
    );
    expect(rows[0]).toMatchObject({ level: "info", block: "", currentLoad: true });
    expect(rows[0]!.message).toMatch(/^loaded .*demo\.yaml: /);
    const gesture = rows.find((r) => r.block === "Emg");
    expect(gesture?.message).toMatch(/open/);
    expect(Date.parse(gesture!.time)).toBeGreaterThan(Date.now() - 10 * 60_000);
    // As many lines as the Log lists for this load.
    const listed = await page.locator("#event-log-list .event-log__entry").count();
    expect(rows.filter((r) => r.currentLoad)).toHaveLength(listed);
    expect(app.errors).toEqual([]);
    await app.close();
  });
});
