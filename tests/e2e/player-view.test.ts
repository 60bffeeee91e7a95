/**
 * Issue 17, FilePlayer panel, in the browser build (Chromium): the Player view's seek bar shows
 * the position and the duration and seeks; pause and resume; Speed and Loop change while it
 * plays. Waits are on what the page shows (or the engine reports), never on fixed sleeps.
 */
import type { Page } from "playwright-core";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
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
  document: {
    // eslint-disable-next-line @typescript-eslint/no-explicit-any -- DOM elements, untyped here
    querySelector(selector: string): any;
  };
}

const TIME = '[data-block-panel="Player"] .mp-seek__time';

/** Waits until the seek bar's label says `test` of its seconds and duration. */
function waitPosition(page: Page, test: string, arg: number): Promise<unknown> {
  return page.waitForFunction(
    ({ sel, test, arg }) => {
      const el = (globalThis as unknown as InPage).document.querySelector(sel);
      if (!el) return false;
      const s = Number(el.getAttribute("data-seconds"));
      const d = Number(el.getAttribute("data-duration"));
      return new Function("s", "d", "arg", `return ${test}`)(s, d, arg) as boolean;
    },
    { sel: TIME, test, arg },
    { timeout: 20_000, polling: 100 },
  );
}

/** The Player block's status text as telemetry reports it. */
const statusText = (page: Page): Promise<string> =>
  page.evaluate(
    () =>
      (globalThis as unknown as InPage).mosaic.client.telemetry?.blocks.find(
        (b) => b.name === "Player",
      )?.text ?? "",
  );

describe.skipIf(!haveChromium)("FilePlayer's Player view (browser build, Chromium)", () => {
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

  test("seek bar, pause/resume, Speed and Loop while it plays", async () => {
    const app = await openApp(chromium, served.url, "e2e/player.yaml");
    const { page } = app;
    const panel = page.locator('[data-block-panel="Player"]');
    if ((await panel.count()) === 0) await page.click('.block-node[data-block="Player"]');
    await panel.locator('[data-view="player"]').waitFor();
    // Position and duration (30 s of rows at 20 Hz: the last row at 29.95 s).
    await waitPosition(page, "d === arg && s > 0", 29.95);
    expect(await page.textContent(TIME)).toMatch(/^0:\d\d\.\d \/ 0:29\.9 · row \d+ \/ 600$/);

    // Seek: the range input's change (a release of the thumb) plays on from 20 s.
    await page.evaluate((sel) => {
      const input = (globalThis as unknown as InPage).document.querySelector(
        `${sel} input[type=range]`,
      );
      input.value = "20";
      input.dispatchEvent(new Event("change", { bubbles: true }));
    }, '[data-block-panel="Player"]');
    await waitPosition(page, "s >= 20 && s < 25", 0);
    await panel.getByRole("status").filter({ hasText: "at 20 s (row 401)" }).waitFor();

    // Pause stops it; resume goes on.
    await panel.getByRole("button", { name: /Pause/ }).click();
    await page.waitForFunction(
      () =>
        /^paused at row \d+/.test(
          (globalThis as unknown as InPage).mosaic.client.telemetry?.blocks.find(
            (b) => b.name === "Player",
          )?.text ?? "",
        ),
      undefined,
      { timeout: 10_000 },
    );
    await panel.getByRole("button", { name: /Resume/ }).click();
    await panel
      .getByRole("status")
      .filter({ hasText: /^resumed at row/ })
      .waitFor();

    // Speed 4×: the engine plays its rows at 80 Hz (the block's measured rate).
    await panel.getByLabel("Speed").selectOption("4");
    await page.waitForFunction(
      () => {
        const b = (globalThis as unknown as InPage).mosaic.client.telemetry?.blocks.find(
          (x) => x.name === "Player",
        );
        return b !== undefined && b.rate > 60;
      },
      undefined,
      { timeout: 20_000, polling: 100 },
    );

    // Loop on, then seek near the end: it starts again (loop 2) instead of finishing.
    await panel.getByLabel("Loop").check();
    await panel.getByRole("status").filter({ hasText: "Player.Loop = true" }).waitFor();
    await page.evaluate((sel) => {
      const input = (globalThis as unknown as InPage).document.querySelector(
        `${sel} input[type=range]`,
      );
      input.value = "29";
      input.dispatchEvent(new Event("change", { bubbles: true }));
    }, '[data-block-panel="Player"]');
    await page.waitForFunction(
      () =>
        /\(loop 2\)/.test(
          (globalThis as unknown as InPage).mosaic.client.telemetry?.blocks.find(
            (b) => b.name === "Player",
          )?.text ?? "",
        ),
      undefined,
      { timeout: 20_000, polling: 100 },
    );
    expect(await statusText(page)).not.toMatch(/finished/);
    await page.screenshot({ path: artifact("player-view.png") });
    expect(app.errors).toEqual([]);
    await app.close();
  }, 120_000);
});
