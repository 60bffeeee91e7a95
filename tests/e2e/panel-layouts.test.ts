/**
 * Saved panel layouts per pipeline (issue 17): the panels open on a pipeline — docked or
 * floating, where, how big, which tab, which output channels the scope watches and its time
 * window — come back when the page is loaded again on the same pipeline (localStorage, keyed by
 * the pipeline's file); another pipeline has its own. In the browser build and with
 * `mosaic serve` (whose page adopts the pipeline the host runs).
 *
 * Needs Chromium (skipped without it).
 */
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { Page } from "playwright-core";
import { requireBuild } from "../integration/helpers";
import {
  ensureWebBuild,
  haveChromium,
  launchChromium,
  openApp,
  serveApp,
  startCliServer,
  type Chromium,
  type CliServer,
  type Served,
} from "./harness";
import type { InPageElement, InPageWindow } from "./in-page";

const frame = (name: string) => `.panel-frame[data-panel="${name}"]`;

async function openPanel(page: Page, block: string): Promise<void> {
  await page.click(`.block-table .react-flow__node[data-id="${block}"] .block-node__name`);
  await page.waitForSelector(frame(block));
}

/** What the page shows of the open panels (by name): place, size, tab and scope settings. */
async function panelState(page: Page) {
  const state = await page.$$eval(".panel-frame", (els) =>
    els.map((el) => {
      const e = el as unknown as InPageElement;
      const floating = e.classList.contains("is-floating");
      return {
        name: e.dataset.panel,
        floating,
        box: floating
          ? { x: e.offsetLeft, y: e.offsetTop, w: e.offsetWidth, h: e.offsetHeight }
          : null,
        tab: e.querySelector('.mp-tab[aria-selected="true"]')?.getAttribute("data-tab"),
        channels: e.querySelector(".mp-picker > button")?.textContent?.trim() ?? null,
        window:
          [...e.querySelectorAll(".mp-field select")].find((s) =>
            s.closest("label")?.textContent?.startsWith("Window"),
          )?.value ?? null,
      };
    }),
  );
  return state.sort((a, b) => (a.name! < b.name! ? -1 : 1));
}

async function drag(page: Page, from: { x: number; y: number }, dx: number, dy: number) {
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  await page.mouse.move(from.x + dx / 2, from.y + dy / 2, { steps: 4 });
  await page.mouse.move(from.x + dx, from.y + dy, { steps: 4 });
  await page.mouse.up();
}

/**
 * Opens Emg (docked, its scope watching channels 0-2 and 5 over 10 s) and LowPass (floating on
 * its Params tab, moved to the lower right and made bigger), reloads the page and checks they
 * come back as they were; returns what they were.
 */
async function arrangeAndReload(page: Page) {
  // Emg, docked: its scope watching channels 0-2 and 5 over a 10 s window.
  await openPanel(page, "Emg");
  await page.click(`${frame("Emg")} .mp-tab[data-tab="scope"]`);
  await page.click(`${frame("Emg")} .mp-picker > button`);
  await page.fill(`${frame("Emg")} .mp-range-input`, "0-2, 5");
  await page.press(`${frame("Emg")} .mp-range-input`, "Enter");
  await page.waitForSelector(`${frame("Emg")} .mp-picker > button:has-text("0-2, 5")`);
  await page.selectOption(`${frame("Emg")} label:has-text("Window") select`, "10");

  // LowPass, floating on its Params tab, moved to the lower right and made bigger.
  await openPanel(page, "LowPass");
  await page.click(`${frame("LowPass")} .mp-tab[data-tab="params"]`);
  await page.click(`${frame("LowPass")} .panel-frame__float`);
  await page.waitForSelector(`${frame("LowPass")}.is-floating`);
  const area = (await page.locator(".workspace__graph").boundingBox())!;
  const head = (await page.locator(`${frame("LowPass")} .panel-frame__title`).boundingBox())!;
  await drag(
    page,
    { x: head.x + 10, y: head.y + head.height / 2 },
    area.x + area.width - 560 - head.x,
    area.y + area.height - 420 - head.y,
  );
  const before = (await page.locator(frame("LowPass")).boundingBox())!;
  // The browser's resize grip, bottom-right corner.
  await drag(page, { x: before.x + before.width - 3, y: before.y + before.height - 3 }, 60, 40);
  await page.waitForFunction(
    ({ sel, w }) =>
      (globalThis as unknown as InPageWindow).document.querySelector(sel)!.offsetWidth >= w + 50,
    { sel: frame("LowPass"), w: before.width },
  );

  const saved = await panelState(page);
  expect(saved.map((p) => [p.name, p.floating, p.tab])).toEqual([
    ["Emg", false, "scope"],
    ["LowPass", true, "params"],
  ]);
  expect(saved[0]).toMatchObject({ window: "10" });
  expect(saved[0]!.channels).toContain("0-2, 5");

  // Wait until the layout is stored (the last change: the resize), then reload the page.
  await page.waitForFunction((w) => {
    const raw = (globalThis as unknown as InPageWindow).localStorage.getItem(
      `mosaic.panels.v1:${(globalThis as unknown as InPageWindow).document.querySelector(".app")!.dataset.pipeline}`,
    );
    const p = raw ? (JSON.parse(raw) as { panels: { name: string; width?: number }[] }) : null;
    return p?.panels.find((x) => x.name === "LowPass")?.width === w;
  }, saved[1]!.box!.w);
  await page.reload();
  await page.waitForSelector('.app[data-engine-state="running"]', { timeout: 15_000 });
  await page.waitForSelector(`${frame("LowPass")}.is-floating`);
  await page.waitForSelector(`${frame("Emg")} .mp-picker > button:has-text("0-2, 5")`);
  expect(await panelState(page)).toEqual(saved);

  return saved;
}

describe.skipIf(!haveChromium)("saved panel layouts (Chromium)", () => {
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

  test("panels, their place, size, tab and watched channels come back after a reload", async () => {
    const { page, errors, close } = await openApp(chromium, served.url);
    await page.waitForSelector(".block-table.is-fitted");

    const saved = await arrangeAndReload(page);

    // Another pipeline: none saved for it, so only the panel of a block it shares (LowPass, a
    // Filter there too) stays, as on any load; it is that pipeline's layout from then on.
    await page.selectOption(".picker select", "pipelines/examples/training.yaml");
    await page.click('button:has-text("Load")');
    await page.waitForSelector('.app[data-pipeline="pipelines/examples/training.yaml"]');
    await page.waitForFunction(
      () =>
        [...(globalThis as unknown as InPageWindow).document.querySelectorAll(".panel-frame")]
          .map((e) => e.dataset.panel)
          .join() === "LowPass",
    );
    await page.click(`${frame("LowPass")} .panel-frame__close`);
    await page.waitForFunction(
      () =>
        (globalThis as unknown as InPageWindow).document.querySelectorAll(".panel-frame").length ===
        0,
    );
    await page.selectOption(".picker select", "pipelines/demo.yaml");
    await page.click('button:has-text("Load")');
    await page.waitForSelector(`${frame("LowPass")}.is-floating`);
    await page.waitForSelector(`${frame("Emg")} .mp-picker > button:has-text("0-2, 5")`);
    expect(await panelState(page)).toEqual(saved);
    expect(errors).toEqual([]);
    await close();
  }, 120_000);
});

describe.skipIf(!haveChromium)("saved panel layouts with mosaic serve (Chromium)", () => {
  let server: CliServer | undefined;
  let url: string;
  let chromium: Chromium;

  beforeAll(async () => {
    ensureWebBuild();
    requireBuild();
    server = await startCliServer(["serve", "pipelines/demo.yaml", "--port", "0"]);
    url = server.url;
    chromium = await launchChromium();
  }, 90_000);

  afterAll(async () => {
    await chromium?.close();
    await server?.stop();
  });

  test("the host's pipeline: the panels come back after a reload of the page", async () => {
    const { page, errors, close } = await openApp(chromium, url);
    await page.waitForSelector(".block-table.is-fitted");
    expect(await page.textContent("header")).toMatch(/mosaic serve/);
    await arrangeAndReload(page);
    expect(errors).toEqual([]);
    await close();
  }, 120_000);
});
