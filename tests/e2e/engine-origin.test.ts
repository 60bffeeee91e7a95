/**
 * Issue 17, defect 3: the page says which engine runs its pipeline and why `mosaic serve`
 * refused it. A wrong token shows the refusal's cause in the page (not "engine starting…"); the
 * right token names mosaic serve and its address; the browser build, and a serve URL without
 * its token, name the page's own engine.
 */
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { requireBuild } from "../integration/helpers";
import {
  artifact,
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

/** The toolbar's engine label once it names one ("" while none). */
const ENGINE_LABEL = `(document.querySelector("header .engine-where")?.textContent ?? "")`;

describe.skipIf(!haveChromium)("the page names its engine and a refusal's cause", () => {
  let server: CliServer | undefined;
  let url: URL;
  let browser: Chromium;
  let web: Served | undefined;

  beforeAll(async () => {
    ensureWebBuild();
    requireBuild();
    server = await startCliServer(["serve", "pipelines/demo.yaml", "--port", "0"], 20_000);
    url = new URL(server.url);
    browser = await launchChromium();
  }, 60_000);

  afterAll(async () => {
    await browser?.close();
    await web?.close();
    await server?.stop();
  });

  test("a wrong token: the page says mosaic serve refused it and why", async () => {
    const bad = new URL(url);
    bad.searchParams.set("token", "wrong");
    const p = await openApp(browser, bad.href, undefined, { waitRunning: false });
    const alert = await p.page.waitForSelector('[role="alert"]', { timeout: 15_000 });
    const text = (await alert.textContent()) ?? "";
    expect(text).toMatch(/mosaic serve refused this page: wrong or missing token/);
    expect(text).toMatch(/open the URL mosaic serve printed/);
    const header = (await p.page.textContent("header")) ?? "";
    expect(header).not.toMatch(/engine starting/);
    expect(header).toContain(`engine: mosaic serve at ${url.host}`);
    expect(await p.page.textContent("main")).not.toMatch(/No pipeline loaded/);
    await p.page.setViewportSize({ width: 1280, height: 720 });
    await p.page.screenshot({ path: artifact("engine-refused.png") });
    await p.close();
  }, 30_000);

  test("the right token: the toolbar names mosaic serve and its address", async () => {
    const p = await openApp(browser, url.href);
    await p.page.waitForFunction(`${ENGINE_LABEL} !== ""`, undefined, { timeout: 10_000 });
    const label = await p.page.evaluate(ENGINE_LABEL);
    expect(label).toBe(`engine: mosaic serve at ${url.host}`);
    expect(await p.page.$('[role="alert"]')).toBeNull();
    expect(p.errors).toEqual([]);
    await p.page.setViewportSize({ width: 1280, height: 720 });
    await p.page.screenshot({ path: artifact("engine-serve.png") });
    await p.close();
  }, 30_000);

  test("no token on mosaic serve's address: the toolbar says the page runs its own engine", async () => {
    const bare = new URL(url);
    bare.search = "";
    const p = await openApp(browser, bare.href);
    const label = await p.page.evaluate(ENGINE_LABEL);
    expect(label).toBe("engine: in this page (browser build)");
    expect(p.errors).toEqual([]);
    await p.close();
  }, 30_000);

  test("the browser build: the toolbar names the in-page engine", async () => {
    web = await serveApp();
    const p = await openApp(browser, web.url);
    const label = await p.page.evaluate(ENGINE_LABEL);
    expect(label).toBe("engine: in this page (browser build)");
    expect(await p.page.textContent("header")).not.toMatch(/mosaic serve/);
    await p.close();
  }, 30_000);
});
