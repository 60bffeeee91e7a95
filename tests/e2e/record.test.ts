/**
 * The Record button in the browser build (issue 16, item 5): the engine in the page's Web Worker
 * cannot write files, so a session recording is kept in memory and downloaded when it stops; our
 * own XDF reader parses the download. Waits are on what the page shows, never on fixed sleeps.
 */
import { readFileSync } from "node:fs";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { bytesSource, readXdf } from "../../app/blocks/recording/xdf-reader";
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

/** Samples written, as the status beside the button says ("… · 1 234 samples"). */
const SAMPLES = /([\d\u202f]+) samples/;
const samplesOf = (text: string | null): number =>
  Number((SAMPLES.exec(text ?? "")?.[1] ?? "0").replaceAll("\u202f", ""));

describe.skipIf(!haveChromium)("Record button (browser build, Chromium)", () => {
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

  test("Record → dialog → Start → Stop downloads an XDF that our reader parses", async () => {
    const app = await openApp(chromium, served.url);
    const { page } = app;

    // The dialog opens from the keyboard and Escape closes it.
    const record = page.getByRole("button", { name: "Record…" });
    await record.focus();
    await page.keyboard.press("Enter");
    const dialog = page.getByRole("dialog", { name: "Record" });
    await dialog.waitFor();
    await page.keyboard.press("Escape");
    await dialog.waitFor({ state: "detached" });

    await record.click();
    await dialog.waitFor();
    // The acquisition block's outputs (the EMG simulator's signal and gesture) are chosen by
    // default; add the low-pass output.
    expect(await dialog.getByRole("checkbox", { name: /^Emg / }).isChecked()).toBe(true);
    expect(await dialog.getByRole("checkbox", { name: /^Emg\.gesture / }).isChecked()).toBe(true);
    expect(await dialog.getByRole("checkbox", { name: /^LowPass\b/ }).isChecked()).toBe(false);
    await dialog.getByRole("checkbox", { name: /^LowPass\b/ }).check();
    expect(await dialog.getByRole("radio", { name: "XDF" }).isChecked()).toBe(true);
    expect(await dialog.textContent()).toContain("downloaded when you stop it");
    await page.screenshot({ path: artifact("record-dialog.png") });
    await dialog.getByRole("button", { name: "Start recording" }).click();
    await dialog.waitFor({ state: "detached" });

    // While it records: a red dot on the button, and file · duration · size · samples.
    const stop = page.getByRole("button", { name: "Stop recording" });
    await stop.waitFor();
    await page.waitForFunction(
      (re) => {
        const el = (globalThis as unknown as InPage).document.querySelector(
          ".record-status.state-recording",
        );
        const m = new RegExp(re).exec(el?.textContent ?? "");
        return m !== null && Number(m[1]!.replaceAll("\u202f", "")) >= 200;
      },
      SAMPLES.source,
      { timeout: 20_000, polling: 100 },
    );
    const live = await page.textContent(".record-status");
    await page.screenshot({ path: artifact("record-running.png") });
    expect(live).toMatch(/\d{4}-\d\d-\d\d_\d\d-\d\d-\d\d\.xdf · \d+\.\d s · [\d.]+ (B|kB|MB) · /);

    const [download] = await Promise.all([page.waitForEvent("download"), stop.click()]);
    expect(download.suggestedFilename()).toMatch(/\.xdf$/);
    const bytes = new Uint8Array(readFileSync((await download.path())!));
    await page.waitForSelector(".record-status.state-finished");
    const written = samplesOf(await page.textContent(".record-status"));

    const xdf = readXdf(bytesSource(bytes));
    expect(xdf.problem).toBe("");
    expect(xdf.streams.map((s) => s.header.name)).toEqual(["Emg", "Emg.gesture", "LowPass"]);
    let total = 0;
    for (const s of xdf.streams) {
      expect(s.footer).toBeDefined();
      expect(s.header.format).toBe("double64");
      expect(s.header.channelCount).toBeGreaterThan(0);
      expect(s.values!.length).toBe(s.t.length * s.header.channelCount);
      for (let i = 1; i < s.t.length; i++) expect(s.t[i]!).toBeGreaterThan(s.t[i - 1]!);
      total += s.t.length;
    }
    // Every event the status counted is in the file.
    expect(xdf.streams[0]!.t.length).toBeGreaterThanOrEqual(100);
    expect(total).toBe(written);
    // The button is back, and the page reported no error.
    await page.getByRole("button", { name: "Record…" }).waitFor();
    expect(app.errors).toEqual([]);
    await app.close();
  });

  test("an XdfRecorder block in the browser build: its file is downloaded when it closes", async () => {
    const app = await openApp(chromium, served.url, "e2e/record-block.yaml");
    const { page } = app;
    const node = '.block-node[data-block="Recorder"]';
    // It records (in memory): its status counts the samples written.
    await page.waitForFunction(
      (sel) => {
        const text =
          (globalThis as unknown as InPage).document.querySelector(sel)?.textContent ?? "";
        const m = /recording rec-block\.xdf: .* ([\d,]+) samples/.exec(text);
        return m !== null && Number(m[1]!.replaceAll(",", "")) >= 100;
      },
      node,
      { timeout: 20_000, polling: 100 },
    );
    const [download, reply] = await Promise.all([
      page.waitForEvent("download"),
      page.evaluate(() =>
        (globalThis as unknown as InPage).mosaic.client.invoke("Recorder", "stop"),
      ),
    ]);
    expect(reply).toMatchObject({ ok: true });
    expect(download.suggestedFilename()).toBe("rec-block.xdf");
    const xdf = readXdf(bytesSource(new Uint8Array(readFileSync((await download.path())!))));
    expect(xdf.problem).toBe("");
    const [emg] = xdf.streams;
    expect(emg!.header.name).toBe("Emg");
    expect(emg!.header.channelCount).toBe(4);
    expect(emg!.footer).toBeDefined();
    expect(emg!.t.length).toBeGreaterThanOrEqual(100);
    for (let i = 1; i < emg!.t.length; i++) expect(emg!.t[i]!).toBeGreaterThan(emg!.t[i - 1]!);
    expect(app.errors).toEqual([]);
    await app.close();
  });

  test("Save model in the browser build downloads the model file instead of failing", async () => {
    const app = await openApp(chromium, served.url, "e2e/save-model.yaml");
    const { page } = app;
    const [download, reply] = await Promise.all([
      page.waitForEvent("download"),
      page.evaluate(() =>
        (globalThis as unknown as InPage).mosaic.client.invoke("Predictor", "save"),
      ),
    ]);
    expect(reply).toMatchObject({
      ok: true,
      message: /saving the model .* to Predictor\.model\.json/,
    });
    expect(download.suggestedFilename()).toBe("Predictor.model.json");
    const text = readFileSync((await download.path())!, "utf8");
    expect(JSON.parse(text)).toBeTypeOf("object");
    expect(text).toContain('"Predictor"');
    // The block says it saved (no warning that it cannot write files).
    await page.waitForFunction(() =>
      /saved to Predictor\.model\.json/.test(
        (globalThis as unknown as InPage).document.querySelector(
          '.block-node[data-block="Predictor"]',
        )?.textContent ?? "",
      ),
    );
    expect(app.errors).toEqual([]);
    await app.close();
  });
});
