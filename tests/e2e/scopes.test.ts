/**
 * Scopes and panel views in the browser build (issue 17: the Scopes features and defect 10):
 * channel and gesture names, zoom/pan/pause with a cursor readout, the spectrum with its median
 * frequency, CSV and PNG export of the visible window, resizable and popped-out panels, and a
 * recording Buffer that does not read idle. Real Chromium, the engine in the page's worker; waits
 * are on what the page shows, never on fixed sleeps.
 */
import { readFileSync } from "node:fs";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { Page } from "playwright-core";
import type { EngineClient } from "../../app/ui/client/engine-client";
import { medianFrequency, sampleRate, welch } from "../../app/ui/panels/spectrum";
import {
  artifact,
  haveChromium,
  launchChromium,
  openApp,
  serveApp,
  type AppPage,
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
    timeout: 60_000,
  });
  return page.evaluate(() => (globalThis as unknown as InPage).statusSeen);
}

const EMG = Array.from({ length: 8 }, (_, k) => `EMG ${k + 1}`);
const SCOPE = '[data-panel="Emg"] [data-view="scope"]';

/** Clicks the Emg scope's export `button`: the file it downloads, its name and its bytes. */
async function download(page: Page, button: string): Promise<{ name: string; data: Buffer }> {
  const [file] = await Promise.all([
    page.waitForEvent("download"),
    page.click(`${SCOPE} button:has-text("${button}")`),
  ]);
  return { name: file.suggestedFilename(), data: readFileSync((await file.path())!) };
}

/** The CSV export of the Emg scope, parsed: header and rows of numbers. */
async function exportCsv(page: Page): Promise<{ header: string[]; rows: number[][] }> {
  const csv = await download(page, "CSV");
  expect(csv.name).toMatch(/^Emg\.emg-.*\.csv$/);
  const text = csv.data.toString("utf8");
  const [head, ...lines] = text.trimEnd().split("\n");
  return {
    header: head!.split(","),
    rows: lines.map((l) => l.split(",").map(Number)),
  };
}

/** Waits for `n` animation frames of the page. */
function frames(page: Page, n: number): Promise<unknown> {
  return page.evaluate(
    `new Promise((r) => { let k = ${n}; const f = () => (--k <= 0 ? r(true) : requestAnimationFrame(f)); requestAnimationFrame(f); })`,
  );
}

/** Time span of the exported rows, s. */
const spanOf = (rows: number[][]): number => rows[rows.length - 1]![0]! - rows[0]![0]!;

/** Coloured pixels of the scope's canvas per channel colour band: rows spanned, count, by colour. */
function colourRows(
  page: Page,
  rgb: [number, number, number],
): Promise<{ top: number; bottom: number; n: number }> {
  return page.$eval(
    `${SCOPE} .mp-plot canvas`,
    (c, want) => {
      const canvas = c as unknown as {
        width: number;
        height: number;
        getContext(k: "2d"): {
          getImageData(x: number, y: number, w: number, h: number): { data: Uint8ClampedArray };
        };
      };
      const { data } = canvas.getContext("2d").getImageData(0, 0, canvas.width, canvas.height);
      let top = Infinity;
      let bottom = -1;
      let n = 0;
      for (let i = 0; i < data.length; i += 4) {
        if (
          Math.abs(data[i]! - want[0]) +
            Math.abs(data[i + 1]! - want[1]) +
            Math.abs(data[i + 2]! - want[2]) >
          30
        )
          continue;
        const y = Math.floor(i / 4 / canvas.width);
        top = Math.min(top, y);
        bottom = Math.max(bottom, y);
        n++;
      }
      return { top, bottom, n, height: canvas.height };
    },
    rgb,
  );
}

/** Opens the app on `pipeline` and waits (generously: the machine may be busy) until it runs. */
async function open(chromium: Chromium, base: string, pipeline?: string): Promise<AppPage> {
  const app = await openApp(chromium, base, pipeline, { waitRunning: false });
  app.page.setDefaultTimeout(60_000);
  await app.page
    .waitForSelector('.app[data-engine-state="running"]', { timeout: 60_000 })
    .catch(async (e: unknown) => {
      const state = await app.page.getAttribute(".app", "data-engine-state").catch(() => null);
      await app.page.screenshot({ path: artifact("scopes-not-running.png") }).catch(() => null);
      throw new Error(`${String(e)}; engine state ${state}; errors: ${app.errors.join("; ")}`);
    });
  return app;
}

/** Waits until `block` has emitted `n` more events (telemetry) than now. */
async function waitEvents(page: Page, block: string, n: number): Promise<void> {
  await page.evaluate(
    ([b, k]) => {
      const w = globalThis as unknown as InPage & { eventsGoal?: { start: number; now: number } };
      const goal = { start: -1, now: -1 };
      w.eventsGoal = goal;
      w.mosaic.client.connection.onMessage((m) => {
        if (m.type !== "telemetry") return;
        const e = m.telemetry.blocks.find((x) => x.name === b)?.events;
        if (e === undefined) return;
        if (goal.start < 0) goal.start = e + (k as number);
        goal.now = e;
      });
    },
    [block, n] as const,
  );
  await page.waitForFunction(
    () => {
      const g = (globalThis as unknown as { eventsGoal: { start: number; now: number } })
        .eventsGoal;
      return g.start >= 0 && g.now >= g.start;
    },
    undefined,
    { timeout: 60_000 },
  );
}

/** Opens a block's panel by clicking its node (again, while the graph still settles under it). */
async function openPanel(page: Page, block: string): Promise<void> {
  for (let i = 0; i < 10; i++) {
    await page.click(`.block-node[data-block="${block}"]`);
    const open = await page
      .waitForSelector(`[data-panel="${block}"]`, { timeout: 5000 })
      .then(() => true)
      .catch(() => false);
    if (open) return;
  }
  throw new Error(`the panel of ${block} did not open`);
}

/** Opens the demo's Emg scope and waits until its 5-s window is full of data. */
async function openEmgScope(page: Page): Promise<void> {
  await openPanel(page, "Emg");
  await page.waitForSelector(`${SCOPE} .mp-plot canvas`).catch(async (e: unknown) => {
    await page.screenshot({ path: artifact("scopes-open-failed.png") });
    throw e;
  });
  await page.waitForFunction(
    (sel) =>
      /events\/s/.test(
        (
          globalThis as unknown as {
            document: { querySelector(q: string): { textContent: string } | null };
          }
        ).document.querySelector(sel)?.textContent ?? "",
      ),
    `${SCOPE} .mp-foot`,
    { timeout: 60_000 },
  );
  await waitEvents(page, "Emg", 1100);
}

/** The plot area's box on the page. */
async function plotArea(
  page: Page,
): Promise<{ x: number; y: number; width: number; height: number }> {
  const box = await page.locator(`${SCOPE} .u-over`).boundingBox();
  expect(box).not.toBeNull();
  return box!;
}

/** Pauses the Emg scope and waits until its footer says it is paused. */
async function pause(page: Page): Promise<void> {
  await page.click(`${SCOPE} button:has-text("Pause")`);
  await page.waitForSelector(`${SCOPE} .mp-foot:has-text("paused")`);
}

/** The texts of the elements `sel`, in the page's order. */
function texts(page: Page, sel: string): Promise<string[]> {
  return page.locator(sel).allTextContents();
}

/** The Emg scope's cursor readout: "t = … s", then a line per channel ("EMG 1: … mV"). */
function readoutLines(page: Page): Promise<string[]> {
  return texts(page, `${SCOPE} .mp-readout div`);
}

/** Drags the mouse from (x, y) by `dx` pixels across, in `steps` moves. */
async function drag(page: Page, x: number, y: number, dx: number, steps: number): Promise<void> {
  await page.mouse.move(x, y);
  await page.mouse.down();
  await page.mouse.move(x + dx, y, { steps });
  await page.mouse.up();
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

  type Check = (page: Page) => Promise<void>;

  /**
   * A test on a new page of the app on `pipeline` (default: the demo): `check` runs on the page,
   * then the page must have reported no errors. The page is closed after, leaving a screenshot of
   * how it ended in artifacts/ (scopes-<part of the test's name>.png: what a failed test left).
   */
  function testOnPage(name: string, check: Check): void;
  function testOnPage(name: string, pipeline: string, check: Check): void;
  function testOnPage(name: string, a: string | Check, b?: Check): void {
    const [pipeline, check] = typeof a === "string" ? [a, b!] : [undefined, a];
    test(
      name,
      async () => {
        const app = await open(chromium, served.url, pipeline);
        try {
          await check(app.page);
          expect(app.errors.join("\n")).toBe("");
        } finally {
          const shot = expect.getState().currentTestName?.slice(52, 70).replace(/\W+/g, "-");
          await app.page
            .screenshot({ path: artifact(`scopes-${shot}.png`) })
            .catch(() => undefined);
          await app.close();
        }
      },
      180_000,
    );
  }

  testOnPage(
    "a Buffer that records (and emits nothing) is not idle while it writes rows",
    "e2e/recorder-status.yaml",
    async (page) => {
      const node = '.block-node[data-block="Recorder"]';
      // Its status text says it records (the capture phase lasts 10 minutes).
      await page.click(node);
      await page.waitForSelector('[data-panel="Recorder"] .mp-status-text:has-text("recording")', {
        timeout: 60_000,
      });
      const seen = await telemetryStatuses(page, "Recorder", 40);
      expect(seen.filter((s) => s === "idle")).toEqual([]);
      expect(await page.getAttribute(node, "data-status")).toBe("ontime");
      await page.screenshot({ path: artifact("recorder-status.png") });
    },
  );

  testOnPage(
    "channels and outputs are named: EMG 1…8 and the gestures in legends, picker and labels",
    "pipelines/examples/training.yaml",
    async (page) => {
      const legend = (panel: string) => texts(page, `[data-panel="${panel}"] .mp-legend .mp-chip`);
      await openPanel(page, "Myo");
      await page.waitForSelector('[data-panel="Myo"] .mp-legend .mp-chip');
      expect(await legend("Myo")).toEqual(EMG);
      // The channel picker's toggles.
      await page.click('[data-panel="Myo"] .mp-picker > button');
      expect(await texts(page, '[data-panel="Myo"] .mp-toggles label')).toEqual(EMG);

      const gestures = ["fist", "open", "pinch", "flexion", "extension"];
      const predictor = '[data-panel="Predictor"]';
      const showTab = (tab: string) => page.click(`${predictor} [data-tab="${tab}"]`);
      await openPanel(page, "Predictor");
      await showTab("scope");
      await page.waitForSelector(`${predictor} .mp-legend .mp-chip`);
      expect(await legend("Predictor")).toEqual(gestures);
      // The spider's spokes and the label view.
      await showTab("spider");
      await page.waitForSelector(`${predictor} [data-view="spider"]`);
      const spider = await page.getAttribute(
        `${predictor} [data-view="spider"] canvas`,
        "aria-label",
      );
      for (const g of gestures) expect(spider).toContain(g);
      await showTab("label");
      await page.waitForSelector(`${predictor} [data-view="label"] dt`);
      const dts = await texts(page, `${predictor} section[aria-label="Output prediction"] dt`);
      expect(dts).toEqual(gestures);
      // The fit output sends values once the first capture trains the model (about 3 s in).
      const fitNames = `${predictor} section[aria-label="Output fit"] dt`;
      await page.waitForSelector(fitNames, { timeout: 60_000 });
      const fit = await texts(page, fitNames);
      expect(fit).toEqual(["samples", ...gestures.map((g) => `R² ${g}`)]);
      await page.screenshot({ path: artifact("names-training.png") });
    },
  );

  testOnPage(
    "pause holds the picture; wheel zooms time and amplitude, drag pans, the readout names each value",
    async (page) => {
      await page.keyboard.press("2"); // fist: a strong signal
      await openEmgScope(page);
      const area = await plotArea(page);
      const cx = area.x + area.width / 2;
      const cy = area.y + area.height / 2;

      // The readout: the time and every channel's value, named, with the unit.
      await page.mouse.move(cx, cy);
      await page.locator(`${SCOPE} .mp-readout`).waitFor();
      const live = await readoutLines(page);
      expect(live[0]).toMatch(/^t = \d+\.\d{3} s$/);
      expect(live.slice(1).map((l) => l.split(":")[0])).toEqual(EMG);
      expect(live.slice(1).every((l) => / mV$/.test(l))).toBe(true);

      // Pause: the picture holds (two looks a few frames apart are the same).
      await pause(page);
      const plot = page.locator(`${SCOPE} .mp-plot`);
      const a = await plot.screenshot();
      await frames(page, 3);
      expect((await plot.screenshot()).equals(a)).toBe(true);
      const whole = await exportCsv(page);
      expect(spanOf(whole.rows)).toBeGreaterThan(4.8);
      expect(spanOf(whole.rows)).toBeLessThanOrEqual(5.0001);

      // The readout's values are the data's: the CSV row at the readout's time.
      await page.mouse.move(area.x + area.width * 0.3, cy);
      await page.waitForFunction(
        (sel) =>
          !(
            globalThis as unknown as {
              document: { querySelector(q: string): { hidden: boolean } };
            }
          ).document.querySelector(sel).hidden,
        `${SCOPE} .mp-readout`,
      );
      const lines = await readoutLines(page);
      const t = Number(/t = ([\d.]+) s/.exec(lines[0]!)![1]);
      const row = whole.rows.reduce((best, r) =>
        Math.abs(r[0]! - t) < Math.abs(best[0]! - t) ? r : best,
      );
      expect(Math.abs(row[0]! - t)).toBeLessThan(0.0006);
      for (let k = 0; k < 8; k++) {
        const shown = Number(lines[k + 1]!.split(": ")[1]!.replace(" mV", "").replace("−", "-"));
        expect(Math.abs(shown - row[k + 1]!)).toBeLessThanOrEqual(
          Math.abs(row[k + 1]!) * 1e-3 + 1e-4,
        );
      }

      // Wheel: 3 notches zoom the time in around the cursor (0.8³ of the window).
      for (let i = 0; i < 3; i++) {
        await page.mouse.move(cx, cy);
        await page.mouse.wheel(0, -100);
      }
      await page.waitForSelector(`${SCOPE} button:has-text("Reset zoom")`);
      const zoomed = await exportCsv(page);
      expect(spanOf(zoomed.rows)).toBeGreaterThan(5 * 0.512 - 0.05);
      expect(spanOf(zoomed.rows)).toBeLessThan(5 * 0.512 + 0.01);
      // Centred on the cursor: the middle of the view stays where it was.
      const mid = (r: number[][]) => (r[0]![0]! + r[r.length - 1]![0]!) / 2;
      expect(Math.abs(mid(zoomed.rows) - mid(whole.rows))).toBeLessThan(0.05);

      // Drag to the right by a quarter of the plot: the view goes back a quarter of its span.
      await drag(page, cx, cy, area.width / 4, 5);
      const panned = await exportCsv(page);
      const back =
        zoomed.rows[zoomed.rows.length - 1]![0]! - panned.rows[panned.rows.length - 1]![0]!;
      expect(Math.abs(back - spanOf(zoomed.rows) / 4)).toBeLessThan(0.05);

      // Shift + wheel zooms the amplitude (out: nothing is clipped): the traces shrink.
      const blue: [number, number, number] = [0x1f, 0x77, 0xb4];
      const before = await colourRows(page, blue);
      await page.mouse.move(cx, cy);
      await page.keyboard.down("Shift");
      await page.mouse.wheel(0, 100);
      await page.mouse.wheel(0, 100);
      await page.keyboard.up("Shift");
      await frames(page, 2);
      const after = await colourRows(page, blue);
      // Two notches: 1.25² wider, the traces 0.64 as tall.
      expect(after.bottom - after.top).toBeLessThan((before.bottom - before.top) * 0.75);
      expect(after.bottom - after.top).toBeGreaterThan((before.bottom - before.top) * 0.5);

      // Double click: the whole window again.
      await page.mouse.dblclick(cx, cy);
      await page.waitForSelector(`${SCOPE} button:has-text("Reset zoom")`, { state: "detached" });
      const reset = await exportCsv(page);
      expect(spanOf(reset.rows)).toBeGreaterThan(4.8);
      await page.screenshot({ path: artifact("scope-zoom.png") });

      // Resume: it follows the data again.
      await page.click(`${SCOPE} button:has-text("Resume")`);
      await page.waitForSelector(`${SCOPE} .mp-foot:has-text("events/s")`, { timeout: 60_000 });
    },
  );

  testOnPage(
    "CSV export: the header names the channels, the rows are the visible window",
    async (page) => {
      await openEmgScope(page);
      await pause(page);
      const { header, rows } = await exportCsv(page);
      expect(header).toEqual(["time_s", ...EMG]);
      // 5 s at 200 Hz: about 1000 rows, in time order, every value a number.
      expect(rows.length).toBeGreaterThan(950);
      expect(rows.length).toBeLessThanOrEqual(1001);
      for (let i = 1; i < rows.length; i++) expect(rows[i]![0]!).toBeGreaterThan(rows[i - 1]![0]!);
      expect(rows.every((r) => r.length === 9 && r.every(Number.isFinite))).toBe(true);
      expect(sampleRate(rows.map((r) => r[0]!))).toBeCloseTo(200, 0);
    },
  );

  testOnPage("PNG export is a valid PNG of the plot with its legend", async (page) => {
    await openEmgScope(page);
    const { name, data: png } = await download(page, "PNG");
    expect(name).toMatch(/^Emg\.emg-.*\.png$/);
    expect([...png.subarray(0, 8)]).toEqual([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]);
    expect(png.subarray(12, 16).toString("latin1")).toBe("IHDR");
    const canvas = await page.$eval(`${SCOPE} .mp-plot canvas`, (c) => {
      const el = c as unknown as { width: number; height: number };
      return { width: el.width, height: el.height };
    });
    expect(png.readUInt32BE(16)).toBe(canvas.width);
    // The legend strip under the plot.
    expect(png.readUInt32BE(20)).toBeGreaterThan(canvas.height);
    expect(png.subarray(png.length - 8, png.length - 4).toString("latin1")).toBe("IEND");
  });

  testOnPage("stacked channels: a lane each, named, with the unit", async (page) => {
    await page.keyboard.press("2");
    await openEmgScope(page);
    await page.selectOption(`${SCOPE} select:near(:text("Layout"))`, "stacked");
    await page.waitForSelector(`${SCOPE}[data-layout="stacked"]`);
    expect(await page.textContent(`${SCOPE} .mp-legend`)).toContain("values in mV");
    await pause(page);
    // Channel 1 (blue) stays in the top eighth of the plot area, channel 2 (orange) in the next.
    const area = await plotArea(page);
    const dpr = await page.evaluate(
      () => (globalThis as unknown as { devicePixelRatio: number }).devicePixelRatio,
    );
    const bbox = await page.$eval(`${SCOPE} .u-over`, (o) => {
      const el = o as unknown as { offsetTop: number; offsetHeight: number };
      return { top: el.offsetTop, height: el.offsetHeight };
    });
    const laneH = (bbox.height * dpr) / 8;
    const top = bbox.top * dpr;
    const blue = await colourRows(page, [0x1f, 0x77, 0xb4]);
    const orange = await colourRows(page, [0xff, 0x7f, 0x0e]);
    expect(blue.n).toBeGreaterThan(100);
    expect(blue.top).toBeGreaterThanOrEqual(top - 1);
    expect(blue.bottom).toBeLessThanOrEqual(top + laneH + 1);
    expect(orange.top).toBeGreaterThanOrEqual(top + laneH - 1);
    expect(orange.bottom).toBeLessThanOrEqual(top + 2 * laneH + 1);
    // The readout names each lane's value with the unit.
    await page.mouse.move(area.x + area.width / 2, area.y + area.height / 2);
    const lines = await readoutLines(page);
    expect(lines.slice(1).map((l) => l.split(":")[0])).toEqual(EMG);
    await page.screenshot({ path: artifact("scope-stacked.png") });
  });

  testOnPage(
    "spectrum of the window in view with each channel's median frequency (as Welch's)",
    async (page) => {
      await page.keyboard.press("2");
      await openEmgScope(page);
      await pause(page);
      await page.click(`${SCOPE} button:has-text("Spectrum")`);
      const items = page.locator(`${SCOPE} .mp-mdf-item`);
      await items.nth(7).waitFor({ timeout: 60_000 });
      const shown = await items.evaluateAll((els) =>
        els.map((e) => {
          const el = e as unknown as { getAttribute(a: string): string };
          return {
            name: el.getAttribute("data-channel"),
            hz: Number(el.getAttribute("data-hz")),
          };
        }),
      );
      expect(shown.map((s) => s.name)).toEqual(EMG);
      expect(await page.textContent(`${SCOPE} .mp-mdf`)).toMatch(
        /Median frequency: .*EMG 1 \d+\.\d Hz/,
      );
      // The same numbers from the exported window through Welch (checked against scipy).
      const { rows } = await exportCsv(page);
      const fs = sampleRate(rows.map((r) => r[0]!));
      for (let k = 0; k < 8; k++) {
        const mdf = medianFrequency(
          welch(
            rows.map((r) => r[k + 1]!),
            fs,
          )!,
        );
        expect(shown[k]!.hz).toBeCloseTo(mdf, 6);
        expect(mdf).toBeGreaterThan(10);
        expect(mdf).toBeLessThan(100);
      }
      await page.screenshot({ path: artifact("scope-spectrum.png") });
    },
  );

  testOnPage(
    "a panel pops out into its own window, draws there, and comes back when it closes",
    async (page) => {
      await openEmgScope(page);
      const [popup] = await Promise.all([
        page.context().waitForEvent("page"),
        page.click('[data-panel="Emg"] .panel-frame__popout'),
      ]);
      await popup.waitForSelector('[data-popout="Emg"] [data-view="scope"] .mp-plot canvas');
      // It receives data and draws in its window; the page keeps a note in its place.
      await popup.waitForSelector('[data-popout="Emg"] .mp-foot:has-text("events/s")', {
        timeout: 60_000,
      });
      expect(await page.textContent('[data-panel="Emg"] .panel-frame__body')).toContain(
        "Shown in its own window",
      );
      const plot = popup.locator('[data-popout="Emg"] .mp-plot');
      const a = await plot.screenshot();
      await frames(page, 10);
      expect((await plot.screenshot()).equals(a)).toBe(false);
      // Its legend names the channels there too.
      expect(await texts(popup, ".mp-legend .mp-chip")).toEqual(EMG);
      await popup.screenshot({ path: artifact("panel-popped-out.png") });
      // Closing the window brings the panel back into the page.
      await popup.close();
      await page.waitForSelector(`${SCOPE} .mp-plot canvas`);
      expect(await page.textContent('[data-panel="Emg"] .panel-frame__body')).not.toContain(
        "Shown in its own window",
      );
    },
  );

  testOnPage("the docked panels' edge drags wider and the scope widens with it", async (page) => {
    await openEmgScope(page);
    const width = (sel: string) =>
      page.$eval(sel, (e) => (e as unknown as { offsetWidth: number }).offsetWidth);
    const dock0 = await width("aside.dock");
    const plot0 = await width(`${SCOPE} .mp-plot canvas`);
    const edge = (await page.locator(".dock-resizer").boundingBox())!;
    await drag(page, edge.x + edge.width / 2, edge.y + 200, -300, 6);
    expect(Math.abs((await width("aside.dock")) - (dock0 + 300))).toBeLessThanOrEqual(2);
    // The scope's plot follows its panel's width.
    await page.waitForFunction(
      ([sel, w]) =>
        ((
          globalThis as unknown as { document: { querySelector(q: string): { width: number } } }
        ).document.querySelector(sel).width ?? 0) >
        (w as number) + 200,
      [`${SCOPE} .mp-plot canvas`, plot0] as const,
    );
    // Arrow keys on the focused edge: 40 px a press.
    await page.focus(".dock-resizer");
    await page.keyboard.press("ArrowLeft");
    expect(Math.abs((await width("aside.dock")) - (dock0 + 340))).toBeLessThanOrEqual(2);
    await page.screenshot({ path: artifact("dock-wide.png") });
  });
});
