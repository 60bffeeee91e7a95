/**
 * Issue 17, defect 2 and training feedback, in the browser build (Chromium): a model trained in
 * one page (scripted rows: the same features on every loop of the file) and saved from the
 * predictor's Training view (a download), loaded from that file into a NEW page that runs only
 * the features, predicts exactly the same numbers for the same rows. The Training view shows R²
 * per output and, the targets being gestures, the confusion matrix. Waits are on what the page
 * shows or receives, never on fixed sleeps. On the training example the Stimulus's gestures
 * name the figures.
 */
import { readFileSync } from "node:fs";
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
}

/** Rows of model-rows.csv seen with their prediction: features (as text) → prediction. */
type Pairs = Record<string, number[]>;

/**
 * Watches the Features player and the predictor's predictions in the page until `rows` distinct
 * feature rows have their prediction (paired by timestamp), counting only events stamped after
 * the first telemetry whose Predictor status matches `after` (so nothing predicted by an earlier
 * model counts, even when a data message brings it later).
 */
function predictions(page: Page, rows: number, after: string): Promise<Pairs> {
  return page.evaluate(
    ({ rows, after }) =>
      new Promise<Record<string, number[]>>((resolve) => {
        const client = (globalThis as unknown as InPage).mosaic.client;
        const re = new RegExp(after);
        let since = Infinity;
        const feats = new Map<number, string>();
        const preds = new Map<number, number[]>();
        const out: Record<string, number[]> = {};
        const stopTelemetry = client.onTelemetry((t) => {
          const text = t.blocks.find((b) => b.name === "Predictor")?.text ?? "";
          if (since === Infinity && re.test(text)) since = t.t;
        });
        const match = (): void => {
          for (const [t, p] of preds) {
            const f = feats.get(t);
            if (f === undefined) continue;
            out[f] = p;
            preds.delete(t);
            feats.delete(t);
          }
          if (Object.keys(out).length >= rows) {
            stopFeats();
            stopPreds();
            stopTelemetry();
            resolve(out);
          }
        };
        const stopFeats = client.watch("Features", undefined, (m) => {
          for (let e = 0; e < m.t.length; e++)
            if (m.t[e]! > since)
              feats.set(m.t[e]!, Array.from(m.v.subarray(e * 3, e * 3 + 3)).join(","));
          match();
        });
        const stopPreds = client.watch("Predictor", "prediction", (m) => {
          for (let e = 0; e < m.t.length; e++)
            if (m.t[e]! > since) preds.set(m.t[e]!, Array.from(m.v.subarray(e * 2, e * 2 + 2)));
          match();
        });
      }),
    { rows, after },
  );
}

async function openTraining(page: Page): Promise<void> {
  const panel = page.locator('[data-block-panel="Predictor"]');
  // A panel layout saved for the pipeline may have opened it already (a click would close it).
  if ((await panel.count()) === 0) await page.click('.block-node[data-block="Predictor"]');
  await panel.getByRole("tab", { name: "Training" }).click();
  await panel.locator('[data-view="training"]').waitFor();
}

describe.skipIf(!haveChromium)("a model file in the browser build (Chromium)", () => {
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

  test("trained and downloaded here, loaded from the file in a new page: identical predictions", async () => {
    // ---- page 1: train while watching the Training view, then pause and save (a download)
    const first = await openApp(chromium, served.url, "e2e/model-train.yaml");
    const p1 = first.page;
    await openTraining(p1);
    const panel = p1.locator('[data-block-panel="Predictor"]');
    await p1.waitForFunction(
      () =>
        Number(
          (
            globalThis as unknown as {
              document: { querySelector(s: string): { getAttribute(a: string): string } | null };
            }
          ).document
            .querySelector('[data-block-panel="Predictor"] [data-samples]')
            ?.getAttribute("data-samples") ?? 0,
        ) >= 150,
      undefined,
      { timeout: 30_000, polling: 200 },
    );
    // R² of both outputs, and the gestures' confusion matrix: rest, then the two outputs.
    const r2 = await panel
      .locator(".mp-r2 td[data-r2]")
      .evaluateAll((els) => els.map((e) => Number(e.getAttribute("data-r2"))));
    expect(r2).toHaveLength(2);
    for (const v of r2) expect(v).toBeGreaterThan(0.5);
    // The block's own (prequential) fit since training began, beside the window's figures.
    const fit = panel.getByRole("table", { name: "R² per output (the block's fit)" });
    expect(await fit.locator("tbody tr").count()).toBe(2);
    const matrix = panel.getByRole("table", { name: "Confusion matrix" });
    expect(await matrix.locator("tbody tr").count()).toBe(3);
    expect(
      Number(await panel.locator("[data-accuracy]").first().getAttribute("data-accuracy")),
    ).toBeGreaterThan(0.8);
    await p1.screenshot({ path: artifact("training-view.png") });

    const paused = await p1.evaluate(() =>
      (globalThis as unknown as InPage).mosaic.client.invoke("Predictor", "pause"),
    );
    expect(paused).toMatchObject({ ok: true });
    const [download] = await Promise.all([
      p1.waitForEvent("download"),
      panel.getByRole("button", { name: "Save model" }).click(),
    ]);
    expect(download.suggestedFilename()).toBe("Predictor.model.json");
    const modelPath = (await download.path())!;
    expect(JSON.parse(readFileSync(modelPath, "utf8"))).toMatchObject({ format: "mosaic-model" });
    const trained = await predictions(p1, 60, "^paused");
    expect(first.errors).toEqual([]);
    await first.close();

    // ---- page 2: a new page and engine, the features only; the model from the downloaded file
    const second = await openApp(chromium, served.url, "e2e/model-predict.yaml");
    const p2 = second.page;
    await openTraining(p2);
    const panel2 = p2.locator('[data-block-panel="Predictor"]');
    // The file as the user picks it (the download's own path has a random name).
    await panel2.getByLabel("Model file to load").setInputFiles({
      name: "Predictor.model.json",
      mimeType: "application/json",
      buffer: readFileSync(modelPath),
    });
    await panel2
      .getByRole("status")
      .filter({ hasText: /^loaded Predictor\.model\.json: rff/ })
      .waitFor({ timeout: 15_000 });
    const reloaded = await predictions(p2, 60, "loaded Predictor\\.model\\.json");

    // The same rows give the same numbers, bit for bit.
    const common = Object.keys(trained).filter((k) => k in reloaded);
    expect(common).toHaveLength(60);
    for (const k of common) expect([k, reloaded[k]]).toEqual([k, trained[k]]);
    // And the model learnt something: fist rows predict fist, open rows open.
    const moving = common.filter((k) => trained[k]!.some((v) => Math.abs(v) > 0.5));
    expect(moving.length).toBeGreaterThan(0);
    expect(second.errors).toEqual([]);
    await second.close();
  }, 120_000);

  test("the training example: the Stimulus's gestures name the Training view's figures", async () => {
    const app = await openApp(chromium, served.url, "pipelines/examples/training.yaml");
    const { page } = app;
    await openTraining(page);
    const panel = page.locator('[data-block-panel="Predictor"]');
    // The first capture (3 s at 25 Hz) gives labelled samples.
    await panel
      .locator("[data-samples]")
      .filter({ hasText: /^[1-9]\d+ labelled/ })
      .waitFor({
        timeout: 30_000,
      });
    const gestures = ["fist", "open", "pinch", "flexion", "extension"];
    const r2Rows = await panel
      .locator(".mp-r2 tbody th")
      .evaluateAll((els) => els.map((e) => e.textContent));
    expect(r2Rows).toEqual(gestures);
    const heads = await panel
      .getByRole("table", { name: "Confusion matrix" })
      .locator("thead th")
      .evaluateAll((els) => els.map((e) => e.textContent));
    expect(heads).toEqual(["cued ↓ / predicted →", "rest", ...gestures, "accuracy"]);
    expect(app.errors).toEqual([]);
    await app.close();
  }, 60_000);

  test("a file that is no model is refused with the reason; the model stays", async () => {
    const app = await openApp(chromium, served.url, "e2e/model-predict.yaml");
    const { page } = app;
    await openTraining(page);
    const panel = page.locator('[data-block-panel="Predictor"]');
    await panel.getByLabel("Model file to load").setInputFiles({
      name: "notes.json",
      mimeType: "application/json",
      buffer: Buffer.from('{"hello": 1}'),
    });
    await panel
      .getByRole("alert")
      .filter({ hasText: "model file 'notes.json': not a MOSAIC model file" })
      .waitFor({ timeout: 15_000 });
    expect(await panel.locator(".mp-status-text").textContent()).toMatch(/^untrained/);
    expect(app.errors).toEqual([]);
    await app.close();
  }, 60_000);
});
