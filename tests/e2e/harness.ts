/**
 * End-to-end harness: the built browser app (dist/web) served by the product's own static server
 * (with the COOP/COEP headers), and Debian's Chromium driven by playwright-core.
 *
 * The served root is a temporary folder that links every entry of dist/web and adds `e2e/` with
 * the test pipelines of ./fixtures, so the build folder itself is never written.
 */
import { execFileSync, type ChildProcess } from "node:child_process";
import {
  cpSync,
  existsSync,
  mkdirSync,
  mkdtempSync,
  readdirSync,
  rmSync,
  statSync,
  symlinkSync,
} from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import { chromium, type BrowserContext, type Page } from "playwright-core";
import { serveStatic, type WebServer } from "../../app/host/web-server";
import { startCli } from "../integration/helpers";

export const ROOT = resolve(dirname(fileURLToPath(import.meta.url)), "../..");
export const WEB = join(ROOT, "dist/web");
export const ARTIFACTS = join(ROOT, "tests/e2e/artifacts");
export const CHROMIUM = process.env.MOSAIC_CHROMIUM ?? "/usr/bin/chromium";
export const haveChromium = existsSync(CHROMIUM);

const SOURCES = [
  "app/ui",
  "app/web",
  "app/engine",
  "app/blocks",
  "scripts/build-web.mjs",
  "pipelines",
];

function newest(path: string): number {
  const s = statSync(path);
  if (!s.isDirectory()) return s.mtimeMs;
  let t = s.mtimeMs;
  for (const e of readdirSync(path)) t = Math.max(t, newest(join(path, e)));
  return t;
}

/** Builds dist/web when it is missing or older than its sources. */
export function ensureWebBuild(): void {
  const app = join(WEB, "app.js");
  const stale =
    !existsSync(app) ||
    SOURCES.some((s) => existsSync(join(ROOT, s)) && newest(join(ROOT, s)) > statSync(app).mtimeMs);
  if (stale)
    execFileSync(process.execPath, ["scripts/build-web.mjs"], { cwd: ROOT, stdio: "inherit" });
}

export interface Served {
  url: string;
  root: string;
  close(): Promise<void>;
}

/**
 * Serves dist/web plus the e2e fixtures under `e2e/`; with `crossOriginIsolated: false`, without
 * the COOP/COEP headers (no SharedArrayBuffer in the page: the engine's fallback).
 */
export async function serveApp(opts: { crossOriginIsolated?: boolean } = {}): Promise<Served> {
  ensureWebBuild();
  const root = mkdtempSync(join(tmpdir(), "mosaic-e2e-web-"));
  for (const e of readdirSync(WEB)) symlinkSync(join(WEB, e), join(root, e));
  mkdirSync(join(root, "e2e"));
  cpSync(join(ROOT, "tests/e2e/fixtures"), join(root, "e2e"), { recursive: true });
  const server: WebServer = await serveStatic(root, 0, "127.0.0.1", {
    crossOriginIsolated: opts.crossOriginIsolated ?? true,
  });
  return {
    url: server.url,
    root,
    async close() {
      await server.close();
      rmSync(root, { recursive: true, force: true });
    },
  };
}

export interface Chromium {
  context: BrowserContext;
  close(): Promise<void>;
}

/** Debian's Chromium, headless, with a fresh profile in a temporary folder. */
export async function launchChromium(): Promise<Chromium> {
  const profile = mkdtempSync(join(tmpdir(), "mosaic-e2e-profile-"));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM,
    headless: true,
    args: [
      "--headless",
      "--no-sandbox",
      "--disable-gpu",
      "--disable-quic",
      "--no-first-run",
      "--disable-background-networking",
      "--disable-component-update",
      "--disable-sync",
    ],
    viewport: { width: 1440, height: 900 },
    acceptDownloads: true,
  });
  return {
    context,
    async close() {
      await context.close();
      rmSync(profile, { recursive: true, force: true });
    },
  };
}

export interface AppPage {
  page: Page;
  /** Errors the page reported (uncaught exceptions, console.error). */
  errors: string[];
  close(): Promise<void>;
}

/**
 * Run first in every page openApp opens: the page starts without saved panel layouts (kept in
 * localStorage, which all pages of one Chromium share: a test would find the panels an earlier
 * test left open); a reload of the same page keeps them (sessionStorage marks it as started).
 */
const FRESH_PANEL_LAYOUTS = `(() => {
  try {
    if (sessionStorage.getItem("mosaic-e2e-page")) return;
    sessionStorage.setItem("mosaic-e2e-page", "1");
    for (const k of Object.keys(localStorage))
      if (k.startsWith("mosaic.panels.")) localStorage.removeItem(k);
  } catch {}
})();`;

/** Opens the app on `pipeline` (default: the demo) in a new tab and waits until it runs. */
export async function openApp(
  browser: Chromium,
  base: string,
  pipeline?: string,
  opts: {
    reducedMotion?: boolean;
    waitRunning?: boolean;
    /** A script run in the page before its own (e.g. observers that time what happens). */
    initScript?: string;
  } = {},
): Promise<AppPage> {
  const page = await browser.context.newPage();
  await page.addInitScript(FRESH_PANEL_LAYOUTS);
  if (opts.initScript !== undefined) await page.addInitScript(opts.initScript);
  await page.emulateMedia({ reducedMotion: opts.reducedMotion ? "reduce" : "no-preference" });
  const errors: string[] = [];
  page.on("pageerror", (e) => errors.push(`pageerror: ${e.message}`));
  page.on("console", (m) => {
    if (m.type() === "error") errors.push(`console: ${m.text()}`);
  });
  const url = pipeline ? `${base}?pipeline=${encodeURIComponent(pipeline)}` : base;
  await page.goto(url);
  if (opts.waitRunning !== false) {
    await page.waitForSelector('.app[data-engine-state="running"]', { timeout: 15_000 });
  }
  return { page, errors, close: () => page.close() };
}

export function artifact(name: string): string {
  mkdirSync(ARTIFACTS, { recursive: true });
  return join(ARTIFACTS, name);
}

/** Statuses of every node, by block name. */
export async function statuses(page: Page): Promise<Record<string, string>> {
  return page.$$eval("[data-block][data-status]", (els) =>
    Object.fromEntries(
      els.map((e) => [e.getAttribute("data-block"), e.getAttribute("data-status")]),
    ),
  );
}

/**
 * The first whole line `child` prints on stdout that matches `re`. Rejects, with what it printed
 * on stdout and stderr, when it ends first or after `ms`.
 */
export function printedLine(child: ChildProcess, re: RegExp, ms: number): Promise<string> {
  let printed = "";
  let stdout = "";
  let done = false;
  return new Promise<string>((resolve, reject) => {
    const fail = (why: string): void => {
      if (done) return;
      done = true;
      clearTimeout(t);
      reject(new Error(`${why}: ${printed}`));
    };
    const t = setTimeout(() => fail(`no line matching ${re} in ${ms} ms`), ms);
    child.stdout!.on("data", (d: Buffer) => {
      if (done) return;
      printed += d.toString();
      stdout += d.toString();
      const line = stdout
        .split("\n")
        .slice(0, -1)
        .find((l) => re.test(l));
      if (line === undefined) return;
      done = true;
      clearTimeout(t);
      resolve(line);
    });
    child.stderr!.on("data", (d: Buffer) => {
      if (!done) printed += d.toString();
    });
    child.once("close", (code) => fail(`ended (exit code ${code}) before printing ${re}`));
  });
}

const SERVED_AT = /MOSAIC is at (\S+)/;

/**
 * The URL `mosaic serve` prints ("MOSAIC is at URL"); rejects with what it printed if it ends
 * first or after `ms`.
 */
export async function servedUrl(cli: ChildProcess, ms = 30_000): Promise<string> {
  return SERVED_AT.exec(await printedLine(cli, SERVED_AT, ms))![1]!;
}

export interface CliServer {
  /** The URL the CLI printed ("MOSAIC is at URL"), token included. */
  url: string;
  child: ChildProcess;
  /** SIGINT, then waits for the exit (nothing when it has already exited). */
  stop(): Promise<void>;
}

/**
 * Starts the built CLI with `args` (`["serve", pipeline, "--port", "0"]`) and waits up to `ms` for
 * the URL it prints. When it prints none, it is stopped and the error (with what it printed) is
 * thrown. Stop it with `stop()` in the suite's afterAll.
 */
export async function startCliServer(args: string[], ms = 30_000): Promise<CliServer> {
  const child = startCli(args);
  const stop = async (): Promise<void> => {
    // A child killed by a signal has exitCode null and signalCode set: its exit has fired.
    if (child.exitCode === null && child.signalCode === null) {
      child.kill("SIGINT");
      await new Promise((r) => child.once("exit", r));
    }
  };
  try {
    return { url: await servedUrl(child, ms), child, stop };
  } catch (e) {
    await stop();
    throw e;
  }
}
