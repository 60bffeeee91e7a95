/**
 * Issue 17, defect 7, end to end: a broken pipeline typed into the editor's text view shows every
 * problem `mosaic validate` finds in the same text, at once, in the CLI's words ("did you mean",
 * "at least 1 input") and at its line and column — while the pipeline that runs keeps running.
 *
 * Needs Chromium (skipped without it) and the web build (built when stale, see harness.ts).
 */
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { diagnosticText } from "../../app/engine/diagnostics";
import { loadDspFromDisk, validatePipelineFile } from "../../app/host/validate";
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

/** What the page function uses of the page's document (the test is type-checked for Node). */
interface InPageDocument {
  querySelectorAll(selector: string): ArrayLike<{ textContent: string | null }>;
}

/** The demo with a misspelt type, a misspelt param value, a dangling input and a block without inputs. */
function brokenDemo(): string {
  const demo = readFileSync(join(ROOT, "pipelines/demo.yaml"), "utf8");
  const broken = demo
    .replace("Type: EmgSimulator", "Type: EmgSimulatr")
    .replace("Operation: abs", "Operation: abz")
    .replace(
      "Device: { Type: Sink, Inputs: [Decoder] }",
      "Device: { Type: Sink, Inputs: [Decodr] }",
    )
    .concat("Spare: { Type: Sink }\n");
  expect(broken.match(/EmgSimulatr|abz|Decodr/g)).toHaveLength(3);
  return broken;
}

/** What the editor should list for `text`: the CLI's diagnostics as "line:col text". */
async function cliLines(dir: string, text: string): Promise<string[]> {
  const file = join(dir, "demo.yaml");
  writeFileSync(file, text);
  loadDspFromDisk();
  const ds = await validatePipelineFile(file);
  return ds
    .filter((d) => d.severity !== "info")
    .map((d) => `${d.line}:${d.col} ${diagnosticText(d)}`);
}

describe.skipIf(!haveChromium)("editor diagnostics, end to end (Chromium)", () => {
  let served: Served;
  let chromium: Chromium;
  let dir: string;

  beforeAll(async () => {
    dir = mkdtempSync(join(tmpdir(), "mosaic-e2e-diag-"));
    served = await serveApp();
    chromium = await launchChromium();
  }, 120_000);

  afterAll(async () => {
    await chromium?.close();
    await served?.close();
    if (dir) rmSync(dir, { recursive: true, force: true });
  });

  test("a broken pipeline typed in the text view: all of validate's messages at once", async () => {
    const broken = brokenDemo();
    const want = await cliLines(dir, broken);
    const all = want.join("\n");
    expect(all).toContain("unknown block type 'EmgSimulatr'; did you mean 'EmgSimulator'?");
    expect(all).toContain("did you mean 'abs'?");
    expect(all).toContain(
      "input 'Decodr' is not a block in this pipeline; did you mean 'Decoder'?",
    );
    expect(all).toContain("has 0 inputs (expected at least 1 input)");

    const app = await openApp(chromium, served.url);
    const { page } = app;
    await page.click('button:has-text("Edit")');
    // Typed over the whole text: CodeMirror's select-all (a DOM selection may cover only the
    // lines it has drawn so far), then the text as one input.
    await page.click('.text-view [aria-label="Pipeline YAML"]');
    await page.keyboard.press("Control+a");
    await page.keyboard.insertText(broken);

    // Every message the CLI prints, shown together (whatever order they arrive in); on a
    // timeout the comparison below says what was shown instead.
    await page
      .waitForFunction(
        (lines) => {
          const doc = (globalThis as unknown as { document: InPageDocument }).document;
          const shown = Array.from(doc.querySelectorAll(".text-view__issues li"), (li) =>
            (li.textContent ?? "").trim(),
          );
          return lines.every((l) => shown.includes(l));
        },
        want,
        { timeout: 20_000 },
      )
      .catch(() => undefined);
    const shown = await page.$$eval(".text-view__issues li", (lis) =>
      lis.map((li) => (li.textContent ?? "").trim()),
    );
    expect(shown).toEqual(want);
    expect(await page.getAttribute(".editor", "data-errors")).toBe(String(want.length));
    expect(await page.isDisabled('.editor__bar button:has-text("Apply")')).toBe(true);
    expect(await page.isDisabled('.editor__bar button:has-text("Save…")')).toBe(true);
    // Marked in the text at its line and column: the misspelt type is underlined.
    await page.waitForSelector('.text-view .cm-lintRange-error:text-is("EmgSimulatr")', {
      state: "attached",
    });
    expect(await page.locator(".text-view .cm-lint-marker-error").count()).toBeGreaterThan(0);
    // On the canvas, each block with its own message.
    expect(await page.textContent('.block-node[data-block="Emg"]')).toContain(
      "did you mean 'EmgSimulator'?",
    );
    // Checking the text loaded nothing: the running pipeline runs on.
    expect(await page.getAttribute(".app", "data-engine-state")).toBe("running");
    await page.screenshot({ path: artifact("editor-diagnostics.png") });
    expect(app.errors).toEqual([]);
    await app.close();
  }, 90_000);
});
