/**
 * The UI served by `mosaic serve` (issue 6): the page talks to the engine in the Node process
 * over the token-guarded WebSocket. Two tabs share the running pipeline; closing one leaves the
 * other's graph live; a page whose token is wrong gets no engine from the host.
 */
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { requireBuild } from "../integration/helpers";
import {
  artifact,
  ensureWebBuild,
  haveChromium,
  launchChromium,
  openApp,
  statuses,
  type Chromium,
  type CliServer,
  startCliServer,
} from "./harness";

describe.skipIf(!haveChromium)("mosaic serve in Chromium", () => {
  let server: CliServer | undefined;
  let url: string;
  let browser: Chromium;

  beforeAll(async () => {
    ensureWebBuild();
    requireBuild();
    server = await startCliServer(["serve", "pipelines/demo.yaml", "--port", "0"], 20_000);
    url = server.url;
    browser = await launchChromium();
  }, 60_000);

  afterAll(async () => {
    await browser?.close();
    await server?.stop();
  });

  test("two tabs show the host's running demo; closing one leaves the other live", async () => {
    const a = await openApp(browser, url);
    await a.page.waitForFunction(
      `document.querySelectorAll('[data-block][data-status="ontime"]').length >= 9`,
      undefined,
      { timeout: 10_000 },
    );
    expect(await a.page.textContent("header")).toMatch(/node host|precise timing/);
    const b = await openApp(browser, url);
    await b.page.waitForFunction(
      `document.querySelectorAll('[data-block][data-status="ontime"]').length >= 9`,
      undefined,
      { timeout: 10_000 },
    );
    // B did not reload the pipeline: A's page never went back to "loaded".
    expect(Object.keys(await statuses(b.page))).toEqual(Object.keys(await statuses(a.page)));
    await b.page.screenshot({ path: artifact("serve-second-tab.png") });
    await a.close();
    await new Promise((r) => setTimeout(r, 1500));
    const s = await statuses(b.page);
    expect(Object.values(s).filter((x) => x !== "idle").length).toBeGreaterThanOrEqual(8);
    expect(b.errors).toEqual([]);
    await b.close();
  }, 60_000);

  test("a wrong token gets no engine: the page says mosaic serve refused it", async () => {
    const bad = url.replace(/token=[^&]+/, "token=wrong");
    const p = await openApp(browser, bad, undefined, { waitRunning: false });
    await p.page.waitForFunction(
      `/mosaic serve refused this page/.test(document.body.textContent || "")`,
      undefined,
      {
        timeout: 10_000,
      },
    );
    await p.close();
  }, 30_000);
});
