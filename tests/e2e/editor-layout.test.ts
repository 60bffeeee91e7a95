/**
 * Edit mode at 1280×720 (issue 17, defect 8): the inspector's form is usable (not collapsed to
 * its headings), the YAML pane never scrolls its text under its line numbers, and a block added
 * in the YAML lands in free space, not on top of another node.
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

async function openEditor(page: Page): Promise<void> {
  await page.click('.toolbar button:has-text("Edit")');
  await page.waitForSelector(".editor .cm-content");
  await page.waitForSelector('.editor[data-checking="false"]');
}

describe.skipIf(!haveChromium)("edit mode at 1280×720 (Chromium)", () => {
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

  test("the inspector's form is usable: its first params are on screen, not only headings", async () => {
    const app = await openApp(chromium, served.url, "pipelines/demo.yaml");
    const { page } = app;
    await page.setViewportSize({ width: 1280, height: 720 });
    await openEditor(page);
    await page.click('.edit-canvas .react-flow__node[data-id="Emg"] .block-node__type');
    await page.waitForSelector('[data-inspector="Emg"] [data-param="Channels"] input', {
      state: "attached",
    });
    await page.screenshot({ path: artifact("editor-1280-inspector.png") });
    // Shown without scrolling: the block's fields and its first params, each input whole
    // inside the inspector's visible area.
    const visible = await page.evaluate(`(() => {
      const box = document.querySelector('[data-inspector="Emg"]').closest(".inspector") ??
        document.querySelector('[data-inspector="Emg"]');
      const r = box.getBoundingClientRect();
      const clip = { top: Math.max(r.top, 0), bottom: Math.min(r.bottom, window.innerHeight) };
      const shown = (sel) => {
        const e = box.querySelector(sel);
        if (!e) return false;
        const b = e.getBoundingClientRect();
        return b.height > 0 && b.top >= clip.top - 0.5 && b.bottom <= clip.bottom + 0.5;
      };
      const params = [...box.querySelectorAll("[data-param]")].slice(0, 2);
      return {
        name: shown('.inspector__field input'),
        firstParams: params.length === 2 && params.every((p) => {
          const b = p.querySelector("input, select, textarea").getBoundingClientRect();
          return b.height > 0 && b.top >= clip.top - 0.5 && b.bottom <= clip.bottom + 0.5;
        }),
      };
    })()`);
    expect(visible).toEqual({ name: true, firstParams: true });
    await app.close();
  }, 90_000);

  test("the YAML pane never scrolls sideways under its line numbers", async () => {
    const app = await openApp(chromium, served.url, "pipelines/demo.yaml");
    const { page } = app;
    await page.setViewportSize({ width: 1280, height: 720 });
    await openEditor(page);
    // The YAML on screen (a tab at this height, or beside the inspector).
    const tab = page.locator('.editor__side [role="tab"]:has-text("YAML")');
    if ((await tab.count()) > 0) await tab.click();
    await page.waitForSelector(".text-view .cm-line");
    // To the end of the longest line (a comment of the demo), as a person would with End.
    await page.click('.text-view [aria-label="Pipeline YAML"]');
    await page.keyboard.press("Control+Home");
    await page.keyboard.press("ArrowDown");
    await page.keyboard.press("ArrowDown");
    await page.keyboard.press("End");
    await page.screenshot({ path: artifact("editor-1280-yaml.png") });
    const layout = await page.evaluate(`(() => {
      const view = document.querySelector(".text-view");
      const gutter = view.querySelector(".cm-gutters").getBoundingClientRect();
      const lines = [...view.querySelectorAll(".cm-line")].map((l) => l.getBoundingClientRect());
      const scrolled = [view, ...view.querySelectorAll("*")].filter(
        (e) => e.scrollLeft > 0 || getComputedStyle(e).overflowX === "scroll" ||
          (getComputedStyle(e).overflowX === "auto" && e.scrollWidth > e.clientWidth + 1),
      ).map((e) => e.className);
      return {
        scrolled,
        gutterLeft: gutter.left - view.getBoundingClientRect().left,
        textUnderGutter: lines.filter((l) => l.width > 0 && l.left < gutter.right - 0.5).length,
        textPastRight: lines.filter((l) => l.right > view.getBoundingClientRect().right + 0.5).length,
      };
    })()`);
    expect(layout).toEqual({ scrolled: [], gutterLeft: 0, textUnderGutter: 0, textPastRight: 0 });
    await app.close();
  }, 90_000);

  test("a block added in the YAML lands in free space, not on another node", async () => {
    const app = await openApp(chromium, served.url, "pipelines/demo.yaml");
    const { page } = app;
    await page.setViewportSize({ width: 1280, height: 720 });
    await openEditor(page);
    const tab = page.locator('.editor__side [role="tab"]:has-text("YAML")');
    if ((await tab.count()) > 0) await tab.click();
    await page.click('.text-view [aria-label="Pipeline YAML"]');
    await page.keyboard.press("Control+End");
    await page.keyboard.insertText(
      "\nExtra: { Type: Function, Inputs: [Emg], Params: { Operation: abs } }\n",
    );
    await page.waitForSelector('.edit-canvas .react-flow__node[data-id="Extra"]');
    await page.waitForSelector('.editor[data-checking="false"]');
    await page.screenshot({ path: artifact("editor-1280-added.png") });
    const boxes = await page.$$eval(".edit-canvas .react-flow__node", (els) =>
      els.map((e) => {
        const r = e.getBoundingClientRect();
        return { id: e.getAttribute("data-id"), x: r.x, y: r.y, w: r.width, h: r.height };
      }),
    );
    const extra = boxes.find((b) => b.id === "Extra")!;
    const covered = boxes.filter(
      (b) =>
        b.id !== "Extra" &&
        b.x < extra.x + extra.w &&
        extra.x < b.x + b.w &&
        b.y < extra.y + extra.h &&
        extra.y < b.y + b.h,
    );
    expect(covered.map((b) => b.id)).toEqual([]);
    await app.close();
  }, 90_000);
});
