/**
 * End-to-end test of edit mode (issue 8): from an empty canvas, a 5-block pipeline built by drag
 * and drop, connected by dragging handles, its timer's DesiredRate set in the inspector; applied
 * it runs and goes green; saved (a download) it passes `mosaic validate` and loads back as the
 * same graph. An invalid edit (a dangling input) is shown and blocks Save.
 *
 * Needs Chromium (skipped without it) and, for `mosaic validate`, dist/ (node
 * scripts/build-ts.mjs).
 */
import { execFileSync } from "node:child_process";
import { existsSync, mkdtempSync, readFileSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { parseDocument } from "yaml";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { Page } from "playwright-core";
import type { EngineClient } from "../../app/ui/client/engine-client";
import {
  ROOT,
  artifact,
  haveChromium,
  launchChromium,
  openApp,
  serveApp,
  statuses,
  type Chromium,
  type Served,
} from "./harness";

interface InPage {
  mosaic: { client: EngineClient };
}

const CHAIN = ["ScheduledTimer", "EmgSimulator", "Function", "Filter", "Sink"];

/** The loaded graph as the engine sent it: names, types, inputs. */
function graphShape(page: Page) {
  return page.evaluate(() =>
    ((globalThis as unknown as InPage).mosaic.client.graph?.blocks ?? []).map((b) => ({
      name: b.name,
      type: b.type,
      inputs: b.inputs.map((i) => i.source),
      desiredRate: b.desiredRate,
    })),
  );
}

async function dropBlock(page: Page, type: string, x: number, y: number): Promise<void> {
  await page.dragAndDrop(
    `.palette__item[data-block-type="${type}"]`,
    ".edit-canvas .react-flow__pane",
    { targetPosition: { x, y } },
  );
  await page.waitForSelector(`.edit-canvas .react-flow__node[data-id="${type}"]`);
}

/** Waits until the engine has checked the text on screen (the problems shown are its). */
async function checked(page: Page): Promise<void> {
  await page.waitForSelector('.editor[data-checking="false"]');
}

async function connect(page: Page, from: string, to: string): Promise<void> {
  // The check of the last edit may still resize the nodes (their problems): wait for it.
  await checked(page);
  const a = (await page
    .locator(`.edit-canvas .react-flow__node[data-id="${from}"] .react-flow__handle.source`)
    .boundingBox())!;
  const b = (await page
    .locator(`.edit-canvas .react-flow__node[data-id="${to}"] .react-flow__handle.target`)
    .boundingBox())!;
  await page.mouse.move(a.x + a.width / 2, a.y + a.height / 2);
  await page.mouse.down();
  await page.mouse.move(b.x + b.width / 2, b.y + b.height / 2, { steps: 10 });
  await page.mouse.up();
  await page.waitForSelector(`.edit-canvas [data-edge="${from}->${to}"]`, { state: "attached" });
}

async function select(page: Page, block: string): Promise<void> {
  await page.click(`.edit-canvas .react-flow__node[data-id="${block}"] .block-node__type`);
  await page.waitForSelector(`[data-inspector="${block}"]`);
}

/** Types into an inspector field (by its label) and commits with Enter. */
async function inspectorField(page: Page, label: string, value: string): Promise<void> {
  const input = page.getByLabel(label, { exact: true });
  await input.fill(value);
  await input.press("Enter");
}

describe.skipIf(!haveChromium)("edit mode, end to end (Chromium)", () => {
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

  test("build a 5-block pipeline by drag and drop, run it green, save it, load it back", async () => {
    const app = await openApp(chromium, served.url);
    const { page } = app;
    await page.click('button:has-text("Edit")');
    await page.waitForSelector(".palette__item[data-block-type='ScheduledTimer']");
    // The palette: grouped by category, searchable, with help.
    expect(await page.locator(".palette__category").count()).toBeGreaterThan(4);
    await page.fill(".palette__search input", "butterworth");
    expect(await page.locator(".palette__item").count()).toBeLessThan(6);
    await page.fill(".palette__search input", "");

    // Templates: an example from pipelines/, then the empty pipeline.
    await page.selectOption(
      'select[aria-label="New pipeline from an example"]',
      "pipelines/examples/training.yaml",
    );
    await page.waitForSelector('.edit-canvas .block-node[data-block="Cues"]');
    await checked(page);
    expect(await page.getAttribute(".editor", "data-errors")).toBe("0");
    await page.selectOption('select[aria-label="New pipeline from an example"]', "(empty)");
    await page.waitForSelector(".edit-canvas__hint");
    expect(await page.locator(".edit-canvas .react-flow__node").count()).toBe(0);

    const pane = (await page.locator(".edit-canvas .react-flow__pane").boundingBox())!;
    for (const [i, type] of CHAIN.entries())
      await dropBlock(page, type, 40 + (i * (pane.width - 240)) / 4, 80 + (i % 2) * 140);
    for (let i = 0; i + 1 < CHAIN.length; i++) await connect(page, CHAIN[i]!, CHAIN[i + 1]!);

    // Problems are shown until the params and the timer's rate are set.
    await checked(page);
    expect(Number(await page.getAttribute(".editor", "data-errors"))).toBeGreaterThan(0);
    expect(await page.isDisabled('button:has-text("Save…")')).toBe(true);
    await select(page, "ScheduledTimer");
    await inspectorField(page, "DesiredRate (Hz)", "200");
    await select(page, "Function");
    await page.selectOption('[data-inspector="Function"] [data-param="Operation"] select', "abs");
    await select(page, "Filter");
    const num = page.locator('[data-inspector="Filter"] [data-param="Numerator"] input').first();
    await num.fill("0.5, 0.5");
    await num.press("Enter");
    await page.waitForSelector('.editor[data-errors="0"]');
    await page.screenshot({ path: artifact("editor-built.png") });

    // Apply: a visible restart, then every block on time.
    await page.click('.editor__bar button:has-text("Apply")');
    await page.waitForSelector('.app[data-engine-state="running"]', { timeout: 15_000 });
    await page.waitForFunction(
      (n) => {
        const els = [
          ...(
            globalThis as unknown as {
              document: { querySelectorAll(s: string): Iterable<{ dataset: { status?: string } }> };
            }
          ).document.querySelectorAll(".edit-canvas .block-node[data-status]"),
        ];
        return els.length === n && els.every((e) => e.dataset.status === "ontime");
      },
      CHAIN.length,
      { timeout: 10_000 },
    );
    await page.screenshot({ path: artifact("editor-running.png") });
    const built = await graphShape(page);
    expect(built.map((b) => b.name)).toEqual(CHAIN);
    expect(built.map((b) => b.inputs)).toEqual([[], ...CHAIN.slice(0, -1).map((n) => [n])]);
    expect(built[0]!.desiredRate).toBe(200);

    // Save: a download that passes `mosaic validate`.
    const [download] = await Promise.all([
      page.waitForEvent("download"),
      page.click('.editor__bar button:has-text("Save…")'),
    ]);
    expect(download.suggestedFilename()).toBe("untitled.yaml");
    const text = readFileSync((await download.path())!, "utf8");
    const dir = mkdtempSync(join(tmpdir(), "mosaic-editor-"));
    const saved = join(dir, "built.yaml");
    writeFileSync(saved, text);
    writeFileSync(artifact("editor-saved.yaml"), text);
    const doc = parseDocument(text).toJS() as Record<string, { Type: string }>;
    expect(Object.entries(doc).map(([k, v]) => [k, v.Type])).toEqual(CHAIN.map((t) => [t, t]));
    if (existsSync(join(ROOT, "dist/cli.mjs"))) {
      const out = execFileSync(process.execPath, ["bin/mosaic.mjs", "validate", saved], {
        cwd: ROOT,
        encoding: "utf8",
      });
      console.log(`mosaic validate: ${out.trim()}`);
    } else
      console.warn("dist/cli.mjs missing: `mosaic validate` not run (node scripts/build-ts.mjs)");

    // Load the saved file back (leave edit mode, Open file…): the same graph.
    await page.click('.editor__bar button:has-text("Done")');
    await page.setInputFiles(".file-open input[type=file]", saved);
    await page.waitForFunction(
      () =>
        (globalThis as unknown as InPage).mosaic.client.graph?.file === "built.yaml" &&
        (globalThis as unknown as InPage).mosaic.client.state === "running",
      null,
      { timeout: 15_000 },
    );
    expect(await graphShape(page)).toEqual(built);
    await page.waitForFunction(
      () =>
        [
          ...(
            globalThis as unknown as {
              document: { querySelectorAll(s: string): Iterable<{ dataset: { status?: string } }> };
            }
          ).document.querySelectorAll(".block-node[data-status]"),
        ].every((e) => e.dataset.status === "ontime"),
      null,
      { timeout: 10_000 },
    );
    expect(Object.values(await statuses(page))).toEqual(CHAIN.map(() => "ontime"));
    await page.screenshot({ path: artifact("editor-reloaded.png") });
    expect(app.errors).toEqual([]);
    await app.close();
  }, 90_000);

  test("an invalid edit (a dangling input) is shown on the node and blocks Save and Apply", async () => {
    const app = await openApp(chromium, served.url);
    const { page } = app;
    await page.click('button:has-text("Edit")');
    await page.waitForSelector('.edit-canvas .react-flow__node[data-id="Device"]');
    await checked(page);
    expect(await page.getAttribute(".editor", "data-errors")).toBe("0");
    await select(page, "Device");
    // The inspector refuses a reference to a block that does not exist: shown, never written.
    await inspectorField(page, "Inputs", "Nowhere");
    await page.waitForSelector(".inspector__error");
    expect(await page.textContent(".inspector__error")).toMatch(/Nowhere/);
    expect(await page.getAttribute(".editor", "data-errors")).toBe("0");
    // Typed in the text view, it is shown on the node and in the problems list.
    const demo = readFileSync(join(ROOT, "pipelines/demo.yaml"), "utf8");
    const broken = demo.replace(
      "Device: { Type: Sink, Inputs: [Decoder] }",
      "Device: { Type: Sink, Inputs: [Nowhere] }",
    );
    expect(broken).not.toBe(demo);
    await page.fill('.text-view [aria-label="Pipeline YAML"]', broken);
    await page.waitForSelector('.block-node[data-block="Device"][data-issues="1"]');
    expect(await page.textContent('.block-node[data-block="Device"]')).toContain(
      "'Nowhere' is not a block",
    );
    expect(await page.textContent(".text-view__issues")).toContain("'Nowhere' is not a block");
    expect(await page.isDisabled('.editor__bar button:has-text("Save…")')).toBe(true);
    expect(await page.isDisabled('.editor__bar button:has-text("Apply")')).toBe(true);
    await page.screenshot({ path: artifact("editor-invalid.png") });
    // Undo (Ctrl+Z on the canvas) restores the valid pipeline.
    await page.locator('.edit-canvas .react-flow__node[data-id="Device"]').focus();
    await page.keyboard.press("Control+z");
    await page.waitForSelector('.editor[data-errors="0"]');
    expect(await page.isDisabled('.editor__bar button:has-text("Save…")')).toBe(false);
    expect(app.errors).toEqual([]);
    await app.close();
  }, 60_000);

  test("rename (references follow), duplicate, delete, undo and redo on the document", async () => {
    const app = await openApp(chromium, served.url);
    const { page } = app;
    await page.click('button:has-text("Edit")');
    await page.waitForSelector('.edit-canvas .react-flow__node[data-id="Decoder"]');
    // The document's text, as Save downloads it.
    const text = async (): Promise<string> => {
      const [d] = await Promise.all([
        page.waitForEvent("download"),
        page.click('.editor__bar button:has-text("Save…")'),
      ]);
      return readFileSync((await d.path())!, "utf8");
    };
    const original = await text();
    await select(page, "Decoder");
    await inspectorField(page, "Name", "Dec");
    await page.waitForSelector('.edit-canvas .react-flow__node[data-id="Dec"]');
    expect(await text()).toContain("Device: { Type: Sink, Inputs: [Dec] }");
    // Comments and untouched blocks stay byte for byte.
    expect((await text()).replace(/\bDec\b/g, "Decoder")).toBe(original);
    await page.click('.editor__bar button:has-text("Duplicate")');
    await page.waitForSelector('.edit-canvas .react-flow__node[data-id="Dec2"]');
    await page.click('.editor__bar button:has-text("Delete")');
    await page.waitForSelector('.edit-canvas .react-flow__node[data-id="Dec2"]', {
      state: "detached",
    });
    // Delete key on a selected block.
    await select(page, "Device");
    await page.locator('.edit-canvas .react-flow__node[data-id="Device"]').focus();
    await page.keyboard.press("Delete");
    await page.waitForSelector('.edit-canvas .react-flow__node[data-id="Device"]', {
      state: "detached",
    });
    await page.screenshot({ path: artifact("editor-edits.png") });
    // Undo three times: Device, Dec2 and the duplicate come back and go; the rename stays.
    for (let k = 0; k < 3; k++) await page.click('.editor__bar button:has-text("Undo")');
    expect(await text()).toContain("Inputs: [Dec] }");
    expect(await text()).not.toContain("Dec2");
    await page.click('.editor__bar button:has-text("Undo")');
    expect(await text()).toBe(original);
    await page.locator(".edit-canvas .react-flow__pane").click();
    await page.keyboard.press("Control+Shift+z");
    expect(await text()).toContain("Inputs: [Dec] }");
    expect(app.errors).toEqual([]);
    await app.close();
  }, 60_000);

  test("while running: a live param applies at once; a structural edit waits for Apply, a visible restart", async () => {
    const app = await openApp(chromium, served.url);
    const { page } = app;
    await page.click('button:has-text("Edit")');
    await select(page, "Amplification");
    const value = page
      .locator('[data-inspector="Amplification"] [data-param="Value"] input')
      .first();
    await value.fill("2");
    await value.press("Enter");
    await page.waitForFunction(
      () =>
        (globalThis as unknown as InPage).mosaic.client.graph?.blocks.find(
          (b) => b.name === "Amplification",
        )?.params.Value === 2,
    );
    // Applied live: nothing waits for Apply, the engine kept running.
    expect(await page.getAttribute(".editor", "data-dirty")).toBe("false");
    expect(await page.getAttribute(".app", "data-engine-state")).toBe("running");

    // A new block: not in the engine until Apply, which restarts it visibly.
    const pane = (await page.locator(".edit-canvas .react-flow__pane").boundingBox())!;
    await dropBlock(page, "Sink", pane.width - 160, pane.height - 120);
    await connect(page, "Decoder", "Sink");
    await checked(page);
    expect(await page.getAttribute(".editor", "data-dirty")).toBe("true");
    expect(await page.textContent(".editor__state")).toBe("changes not applied");
    await page.evaluate(() => {
      const g = globalThis as unknown as {
        __states: string[];
        document: { querySelector(s: string): { textContent: string | null } };
        MutationObserver: new (cb: () => void) => { observe(n: unknown, o: object): void };
      };
      g.__states = [];
      new g.MutationObserver(() => {
        g.__states.push(g.document.querySelector(".engine-state")!.textContent ?? "");
      }).observe(g.document, { subtree: true, childList: true, characterData: true });
    });
    await page.click('.editor__bar button:has-text("Apply")');
    await page.waitForFunction(
      () =>
        (globalThis as unknown as InPage).mosaic.client.graph?.blocks.some(
          (b) => b.name === "Sink",
        ) === true && (globalThis as unknown as InPage).mosaic.client.state === "running",
    );
    const seen = await page.evaluate(
      () => (globalThis as unknown as { __states: string[] }).__states,
    );
    expect(seen).toContain("restarting…");
    await page.waitForSelector('.edit-canvas .block-node[data-block="Sink"][data-status="ontime"]');
    expect(await page.textContent(".editor__state")).toBe("applied");
    await page.screenshot({ path: artifact("editor-applied-live.png") });
    expect(app.errors).toEqual([]);
    await app.close();
  }, 60_000);
});
