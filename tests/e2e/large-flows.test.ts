/**
 * Large flows on the BlockTable (issue 17): the minimap moves the view, the search field (Ctrl+F)
 * outlines the blocks whose name matches and Enter centres them, and group and comment boxes
 * are created, renamed, moved (a group carries its blocks) and resized, saved into the file's
 * `Pipeline: { Layout }` (a download that keeps the file's comments and passes
 * `mosaic validate`), and are there again when the saved file is opened.
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
  type Chromium,
  type Served,
} from "./harness";
import type { InPageElement, InPageWindow } from "./in-page";

interface InPage {
  mosaic: { client: EngineClient };
}

/** The graph's pan and zoom: React Flow's viewport transform. */
async function viewport(page: Page): Promise<{ x: number; y: number; zoom: number }> {
  const t = await page.$eval(
    ".block-table .react-flow__viewport",
    (el) =>
      (globalThis as unknown as InPageWindow).getComputedStyle(el as unknown as InPageElement)
        .transform,
  );
  const m = /matrix\(([^)]+)\)/.exec(t)!;
  const [a, , , , e, f] = m[1]!.split(",").map(Number);
  return { x: e!, y: f!, zoom: a! };
}

async function waitViewportChange(page: Page, before: { x: number; y: number }): Promise<void> {
  await page.waitForFunction(
    (b) => {
      const el = (globalThis as unknown as InPageWindow).document.querySelector(
        ".block-table .react-flow__viewport",
      );
      const m = /matrix\(([^)]+)\)/.exec(
        el
          ? (globalThis as unknown as InPageWindow).getComputedStyle(el as unknown as InPageElement)
              .transform
          : "",
      );
      if (!m) return false;
      const v = m[1]!.split(",").map(Number);
      return Math.hypot(v[4]! - b.x, v[5]! - b.y) > 20;
    },
    before,
    { timeout: 10_000 },
  );
}

/**
 * The viewport once it has stopped moving (the same for 150 ms): a minimap click animates the
 * view there, and a reading taken on the way is not where it ends.
 */
async function settledViewport(page: Page): Promise<{ x: number; y: number; zoom: number }> {
  let last = await viewport(page);
  for (let i = 0; i < 100; i++) {
    await page.waitForTimeout(150);
    const v = await viewport(page);
    if (v.x === last.x && v.y === last.y && v.zoom === last.zoom) return v;
    last = v;
  }
  throw new Error(`the viewport never settled (last ${JSON.stringify(last)})`);
}

/** Centre of an element on screen. */
async function centre(page: Page, selector: string): Promise<{ x: number; y: number }> {
  const b = (await page.locator(selector).boundingBox())!;
  return { x: b.x + b.width / 2, y: b.y + b.height / 2 };
}

/** Position of a block node in canvas pixels (what its Layout would say). */
async function nodePosition(page: Page, id: string): Promise<{ x: number; y: number }> {
  return page.$eval(`.block-table .react-flow__node[data-id="${id}"]`, (el) => {
    const m = /translate\(([-\d.]+)px,\s*([-\d.]+)px\)/.exec(
      (el as unknown as InPageElement).style.transform,
    )!;
    return { x: Number(m[1]), y: Number(m[2]) };
  });
}

async function drag(page: Page, from: { x: number; y: number }, dx: number, dy: number) {
  await page.mouse.move(from.x, from.y);
  await page.mouse.down();
  await page.mouse.move(from.x + dx / 2, from.y + dy / 2, { steps: 5 });
  await page.mouse.move(from.x + dx, from.y + dy, { steps: 5 });
  await page.mouse.up();
}

describe.skipIf(!haveChromium)("large flows on the BlockTable (Chromium)", () => {
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

  test("the minimap moves the view: a click centres that point, a drag pans", async () => {
    const { page, errors, close } = await openApp(
      chromium,
      served.url,
      "pipelines/examples/training.yaml",
    );
    await page.waitForSelector(".block-table.is-fitted .graph-minimap svg");
    const before = await settledViewport(page);
    const map = (await page.locator(".graph-minimap svg").boundingBox())!;
    // A click near the minimap's top-left corner brings that part of the canvas to the middle.
    await page.mouse.click(map.x + 8, map.y + 8);
    await waitViewportChange(page, before);
    const clicked = await settledViewport(page);
    expect(clicked.x).toBeGreaterThan(before.x);
    expect(clicked.zoom).toBeCloseTo(before.zoom, 5);
    // Dragging the minimap's view box pans the other way round (the box follows the pointer).
    await drag(page, { x: map.x + map.width / 2, y: map.y + map.height / 2 }, 40, 25);
    await waitViewportChange(page, clicked);
    const dragged = await settledViewport(page);
    expect(dragged.x).toBeLessThan(clicked.x);
    expect(dragged.y).toBeLessThan(clicked.y);
    expect(errors).toEqual([]);
    await close();
  }, 90_000);

  test("Ctrl+F finds blocks by name: matches outlined, Enter centres the next one", async () => {
    const { page, errors, close } = await openApp(chromium, served.url);
    await page.waitForSelector(".block-table.is-fitted");
    const names = await page.evaluate(() =>
      ((globalThis as unknown as InPage).mosaic.client.graph?.blocks ?? []).map((b) => b.name),
    );
    await page.hover(".block-table .react-flow__pane");
    await page.keyboard.press("Control+f");
    await page.waitForFunction(() =>
      (globalThis as unknown as InPageWindow).document.activeElement?.matches(
        ".block-search input",
      ),
    );
    await page.keyboard.type("ti");
    const expected = names.filter((n) => n.toLowerCase().includes("ti"));
    expect(expected.length).toBeGreaterThan(1); // Amplification, Rectification, …
    await page.waitForSelector(`.block-search[data-matches="${expected.join(",")}"]`);
    const outline = (id: string) =>
      page.$eval(
        `.block-table .react-flow__node[data-id="${id}"]`,
        (el) =>
          (globalThis as unknown as InPageWindow).getComputedStyle(el as unknown as InPageElement)
            .outlineStyle,
      );
    expect(await outline(expected[0]!)).toBe("solid");
    expect(await outline(names.find((n) => !expected.includes(n))!)).toBe("none");

    for (const target of [expected[0]!, expected[1]!]) {
      await page.keyboard.press("Enter");
      await page.waitForSelector(`.block-search[data-current="${target}"]`);
      // Centred: the node's middle comes to the graph's middle (the view animates there).
      await page.waitForFunction(
        (id) => {
          const g = (globalThis as unknown as InPageWindow).document
            .querySelector(".block-table")!
            .getBoundingClientRect();
          const n = (globalThis as unknown as InPageWindow).document
            .querySelector(`.block-table .react-flow__node[data-id="${id}"]`)!
            .getBoundingClientRect();
          return (
            Math.abs(n.x + n.width / 2 - (g.x + g.width / 2)) < 4 &&
            Math.abs(n.y + n.height / 2 - (g.y + g.height / 2)) < 4
          );
        },
        target,
        { timeout: 10_000 },
      );
    }
    await page.keyboard.press("Escape");
    await page.waitForSelector('.block-search[data-matches=""]');
    expect(errors).toEqual([]);
    await close();
  }, 90_000);

  test("a group and a comment: made, renamed, moved, resized, saved, there again on reload", async () => {
    const { page, errors, close } = await openApp(chromium, served.url);
    await page.waitForSelector(".block-table.is-fitted");
    const original = readFileSync(join(ROOT, "pipelines/demo.yaml"), "utf8");

    await page.click('.graph-tools button:has-text("+ Group")');
    const group = page.locator('.graph-box[data-box="group"]');
    await group.waitFor();
    await page.dblclick('.graph-box[data-box="group"] .graph-box__title');
    await page.fill('.graph-box[data-box="group"] input', "Acquisition");
    await page.keyboard.press("Enter");
    await page.waitForSelector('.graph-box[data-box="group"][data-label="Acquisition"]');

    // The group goes round Timer and Emg (moved there by its title bar, then resized).
    const timer = await nodePosition(page, "Timer");
    const emg = await nodePosition(page, "Emg");
    const { zoom } = await viewport(page);
    const head = await centre(page, '.graph-box[data-box="group"] .graph-box__title');
    const gb = await group.evaluate((el) => ({
      x: parseFloat((el as unknown as InPageElement).style.left),
      y: parseFloat((el as unknown as InPageElement).style.top),
    }));
    const top = Math.min(timer.y, emg.y) - 40;
    await drag(page, head, (timer.x - 30 - gb.x) * zoom, (top - gb.y) * zoom);
    const corner = await centre(page, '.graph-box[data-box="group"] .graph-box__corner');
    const size = await group.evaluate((el) => ({
      w: parseFloat((el as unknown as InPageElement).style.width),
      h: parseFloat((el as unknown as InPageElement).style.height),
      x: parseFloat((el as unknown as InPageElement).style.left),
      y: parseFloat((el as unknown as InPageElement).style.top),
    }));
    const wantW = Math.max(emg.x + 260 - size.x, size.w);
    const wantH = Math.max(emg.y + 160 - size.y, timer.y + 160 - size.y, size.h);
    await drag(page, corner, (wantW - size.w) * zoom, (wantH - size.h) * zoom);
    const inside = await page.evaluate(() => {
      const g = (globalThis as unknown as InPageWindow).document
        .querySelector('.graph-box[data-box="group"]')!
        .getBoundingClientRect();
      return [
        ...(globalThis as unknown as InPageWindow).document.querySelectorAll(
          ".block-table .react-flow__node",
        ),
      ]
        .filter((n) => {
          const r = n.getBoundingClientRect();
          return r.left >= g.left && r.top >= g.top && r.right <= g.right && r.bottom <= g.bottom;
        })
        .map((n) => n.dataset.id);
    });
    expect(inside).toEqual(expect.arrayContaining(["Timer", "Emg"]));

    // Moving the group carries the blocks inside it, and only them.
    const ids = await page.$$eval(".block-table .react-flow__node", (els) =>
      els.map((e) => (e as unknown as InPageElement).dataset.id!),
    );
    const before = Object.fromEntries(
      await Promise.all(ids.map(async (id) => [id, await nodePosition(page, id)] as const)),
    );
    await page.screenshot({ path: artifact("large-flows-group.png") });
    await drag(
      page,
      await centre(page, '.graph-box[data-box="group"] .graph-box__title'),
      0,
      80 * zoom,
    );
    // (The view follows pointer moves at the next frame: wait for the last one.)
    await page.waitForFunction(
      ({ ids, before }) =>
        ids.every((id) => {
          const el = (globalThis as unknown as InPageWindow).document.querySelector(
            `.block-table .react-flow__node[data-id="${id}"]`,
          );
          const m = /translate\(([-\d.]+)px,\s*([-\d.]+)px\)/.exec(
            (el as unknown as InPageElement).style.transform,
          );
          return m !== null && Math.abs(Number(m[2]) - before[id]!.y - 80) < 0.5;
        }),
      { ids: inside as string[], before },
      { timeout: 10_000 },
    );
    for (const id of ids.filter((i) => !inside.includes(i)))
      expect(await nodePosition(page, id), id).toEqual(before[id]);

    // A comment with two lines of text.
    await page.click('.graph-tools button:has-text("+ Comment")');
    await page.dblclick('.graph-box[data-box="comment"] .graph-box__text');
    await page.fill(
      '.graph-box[data-box="comment"] textarea',
      "Band-pass here\n# not a YAML comment",
    );
    await page.keyboard.press("Control+Enter");
    await page.waitForSelector('.graph-box[data-box="comment"] .graph-box__text');
    // Their text is never under 11 px on screen, whatever the zoom (as the graph's own).
    const smallest = await page.evaluate(() => {
      const w = globalThis as unknown as InPageWindow;
      const v = w.document.querySelector(".block-table .react-flow__viewport")!;
      const zoom = Number(/matrix\(([^,]+)/.exec(w.getComputedStyle(v).transform)![1]);
      const sel = ".graph-box__title, .graph-box__text, .graph-box__buttons button";
      return Math.min(
        ...[...w.document.querySelectorAll(sel)].map(
          (e) => parseFloat(w.getComputedStyle(e).fontSize!) * zoom,
        ),
      );
    });
    expect(smallest).toBeGreaterThanOrEqual(11);

    const [download] = await Promise.all([
      page.waitForEvent("download"),
      page.click('.graph-actions button:has-text("Save layout")'),
    ]);
    const text = readFileSync((await download.path())!, "utf8");
    writeFileSync(artifact("large-flows-saved.yaml"), text);
    // Every comment of the original file is still there.
    for (const line of original.split("\n").filter((l) => l.trim().startsWith("#")))
      expect(text).toContain(line);
    const doc = parseDocument(text).toJS() as {
      Pipeline: {
        Layout: { Groups: Record<string, unknown>[]; Comments: Record<string, unknown>[] };
      };
    };
    const savedGroup = doc.Pipeline.Layout.Groups[0]!;
    expect(doc.Pipeline.Layout.Groups).toHaveLength(1);
    expect(savedGroup.Title).toBe("Acquisition");
    expect(savedGroup.Width as number).toBeGreaterThanOrEqual(Math.round(wantW) - 2);
    expect(doc.Pipeline.Layout.Comments).toEqual([
      expect.objectContaining({ Text: "Band-pass here\n# not a YAML comment" }),
    ]);
    const dir = mkdtempSync(join(tmpdir(), "mosaic-large-flows-"));
    const saved = join(dir, "demo-grouped.yaml");
    writeFileSync(saved, text);
    if (existsSync(join(ROOT, "dist/cli.mjs"))) {
      const out = execFileSync(process.execPath, ["bin/mosaic.mjs", "validate", saved], {
        cwd: ROOT,
        encoding: "utf8",
      });
      console.log(`mosaic validate: ${out.trim()}`);
    } else
      console.warn("dist/cli.mjs missing: `mosaic validate` not run (node scripts/build-ts.mjs)");
    await close();

    // A fresh page opens the saved file: the boxes are where they were saved.
    const again = await openApp(chromium, served.url);
    await again.page.setInputFiles(".file-open input[type=file]", saved);
    await again.page.waitForSelector('.graph-box[data-box="group"][data-label="Acquisition"]');
    const box = await again.page.$eval('.graph-box[data-box="group"]', (el) => {
      const s = (el as unknown as InPageElement).style;
      return {
        X: parseFloat(s.left),
        Y: parseFloat(s.top),
        Width: parseFloat(s.width),
        Height: parseFloat(s.height),
      };
    });
    expect(box).toEqual({
      X: savedGroup.X,
      Y: savedGroup.Y,
      Width: savedGroup.Width,
      Height: savedGroup.Height,
    });
    expect(await again.page.textContent('.graph-box[data-box="comment"] .graph-box__text')).toBe(
      "Band-pass here\n# not a YAML comment",
    );
    expect([...errors, ...again.errors]).toEqual([]);
    await again.close();
  }, 120_000);
});
