/**
 * A pipeline opened from this computer whose blocks name files next to it (issue 17, defect 5):
 * opened alone, it is one clear error naming the block, the param and the path, with no false
 * "feedback cycle" and no HTTP 404, and the page offers to open its folder; opened with its
 * folder, it reads its data from there and runs. Open folder… with several pipelines asks which.
 */
import { copyFileSync, mkdirSync, mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { Page } from "playwright-core";
import {
  ROOT,
  artifact,
  haveChromium,
  launchChromium,
  openApp,
  serveApp,
  type Chromium,
  type Served,
} from "./harness";

const REPLAY = join(ROOT, "pipelines/examples/replay-envelope.yaml");

/** A folder of this computer as a person would have it: the pipeline, its data, another one. */
function sessionFolder(): string {
  const dir = join(mkdtempSync(join(tmpdir(), "mosaic-open-folder-")), "session");
  mkdirSync(join(dir, "examples"), { recursive: true });
  mkdirSync(join(dir, "data"));
  copyFileSync(REPLAY, join(dir, "examples/replay-envelope.yaml"));
  copyFileSync(join(ROOT, "pipelines/demo.yaml"), join(dir, "examples/demo.yaml"));
  copyFileSync(
    join(ROOT, "pipelines/data/emg_bursts_1000hz.csv"),
    join(dir, "data/emg_bursts_1000hz.csv"),
  );
  return dir;
}

/** Waits until the replay opened from the folder runs, its chain on time. */
async function replayRuns(page: Page): Promise<void> {
  await page.waitForSelector('.app[data-pipeline="session/examples/replay-envelope.yaml"]', {
    timeout: 20_000,
  });
  await page.waitForSelector('.app[data-engine-state="running"]', { timeout: 20_000 });
  await page.waitForSelector('.block-node[data-block="Rectified"][data-status="ontime"]', {
    timeout: 20_000,
  });
}

describe.skipIf(!haveChromium)("opening a pipeline and its folder (Chromium)", () => {
  let served: Served;
  let chromium: Chromium;
  let folder: string;

  beforeAll(async () => {
    folder = sessionFolder();
    served = await serveApp();
    chromium = await launchChromium();
  }, 180_000);

  afterAll(async () => {
    await chromium?.close();
    await served?.close();
    rmSync(join(folder, ".."), { recursive: true, force: true });
  });

  test("opened alone: one error naming block, param and path; its folder then runs it", async () => {
    const app = await openApp(chromium, served.url);
    const { page } = app;
    await page.setInputFiles(".file-open input[type=file]", REPLAY);
    const banner = ".rejected-banner .diagnostic";
    await page.waitForSelector(banner, { timeout: 20_000 });
    const shown = await page.$$eval(banner, (els) =>
      els.map((e) => ({ severity: e.getAttribute("data-severity"), text: e.textContent ?? "" })),
    );
    await page.screenshot({ path: artifact("open-file-needs-folder.png") });
    const errors = shown.filter((d) => d.severity === "error");
    expect(errors, JSON.stringify(shown)).toHaveLength(1);
    const text = errors[0]!.text;
    expect(text).toContain("block 'Recording' (FilePlayer)");
    expect(text).toContain("File");
    expect(text).toContain("../data/emg_bursts_1000hz.csv");
    expect(text).toContain("open its folder (Open folder…)");
    expect(shown.map((d) => d.text).join("\n")).not.toMatch(/feedback cycle|HTTP 404/);
    // The demo goes on running; the page asks for the file's folder.
    expect(await page.getAttribute(".app", "data-pipeline")).toBe("pipelines/demo.yaml");
    await page.waitForSelector('[data-needs-folder="replay-envelope.yaml"]');
    const chooser = page.waitForEvent("filechooser");
    await page.click('[data-needs-folder] button:has-text("Open its folder")');
    await (await chooser).setFiles(folder);
    await replayRuns(page);
    expect(await page.locator(".block-node").count()).toBe(5);
    await page.screenshot({ path: artifact("open-folder-running.png") });
    expect(app.errors).toEqual([]);
    await app.close();
  }, 120_000);

  test("Open folder… with two pipelines asks which one, then reads its data from there", async () => {
    const app = await openApp(chromium, served.url);
    const { page } = app;
    await page.setInputFiles(".folder-open input[type=file]", folder);
    const dialog = '[role="dialog"][aria-label="Pipelines in session"]';
    await page.waitForSelector(dialog);
    const offered = await page.$$eval(`${dialog} [data-pipeline-file]`, (els) =>
      els.map((e) => e.getAttribute("data-pipeline-file")),
    );
    expect(offered).toEqual([
      "session/examples/demo.yaml",
      "session/examples/replay-envelope.yaml",
    ]);
    await page.click(`${dialog} [data-pipeline-file="session/examples/replay-envelope.yaml"]`);
    await replayRuns(page);
    expect(await page.locator(".diagnostic.severity-error").count()).toBe(0);
    expect(app.errors).toEqual([]);
    await app.close();
  }, 120_000);
});
