/**
 * The participant window (issue 17): beside the clinician's page, on one engine, through a whole
 * training protocol (tests/e2e/fixtures/participant.yaml: two cues, then the held-out test). The
 * clinician opens it with the toolbar's "Participant window" button; both pages record what they
 * show as it changes (a MutationObserver in the page, so no step is missed between polls); the
 * participant's steps must be the protocol's, in order (rest with the next gesture, the cue,
 * rest, the cue, the test cued as a test, the end) and each must show on the clinician's page
 * within a few seconds of the participant's. Over `mosaic serve` (two pages on the host's
 * engine) and in the browser build (the participant page has no engine: the clinician page's
 * worker drives it through the relay). Screenshots of both windows at 1920×1080.
 */
import type { Page } from "playwright-core";
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
  type AppPage,
  type Chromium,
  type CliServer,
  type Served,
} from "./harness";

const FIXTURE = "tests/e2e/fixtures/participant.yaml";
const FULL_HD = { width: 1920, height: 1080 };
/** How far apart the two pages may show the same step (both follow one engine). */
const IN_STEP_MS = 3000;

/** What a page shows at one moment (participant: its screen; clinician: the nodes' texts). */
interface Step {
  t: number;
  screen?: string;
  gesture?: string;
  next?: string;
  /** The clinician's graph: the Stimulus's and the test Trigger's status texts. */
  cues?: string;
  test?: string;
}

/** Records every change of what the page shows into window.__steps (run in the page). */
const RECORDER = `(() => {
  const steps = [];
  window.__steps = steps;
  let last = "";
  const snap = () => {
    const p = document.querySelector("[data-participant]");
    const text = (b) => {
      const n = document.querySelector('.block-node[data-block="' + b + '"] .block-node__text');
      return n ? n.textContent : undefined;
    };
    return {
      screen: p ? p.dataset.screen : undefined,
      gesture: p ? p.dataset.gesture : undefined,
      next: p ? p.dataset.next : undefined,
      cues: text("Cues"),
      test: text("Session"),
    };
  };
  const record = () => {
    const now = snap();
    const key = JSON.stringify(now);
    if (key === last) return;
    last = key;
    steps.push({ t: Date.now(), ...now });
  };
  new MutationObserver(record).observe(document.body, {
    subtree: true, childList: true, attributes: true, characterData: true,
  });
  record();
})()`;

const steps = (page: Page): Promise<Step[]> => page.evaluate("window.__steps") as Promise<Step[]>;

/** The participant's steps as "screen gesture/next", repeats merged. */
function screens(recorded: Step[]): { key: string; t: number }[] {
  const out: { key: string; t: number }[] = [];
  for (const s of recorded) {
    if (s.screen === undefined) continue;
    const what = s.screen === "cue" || s.screen === "test-cue" ? s.gesture : s.next;
    const key = `${s.screen} ${what ?? ""}`.trim();
    if (out.at(-1)?.key !== key) out.push({ key, t: s.t });
  }
  return out;
}

/** The protocol of the fixture as the participant must see it, in order. */
const EXPECTED = [
  "rest fist",
  "cue fist",
  "rest open",
  "cue open",
  "test-ready fist",
  "test-cue fist",
  "test-rest open",
  "test-cue open",
  "end",
];

/** The first time at or after `from` when the clinician's page showed what `match` wants. */
function clinicianShows(recorded: Step[], from: number, match: (s: Step) => boolean): number {
  return recorded.find((s) => s.t >= from - IN_STEP_MS && match(s))?.t ?? NaN;
}

/** What the clinician's page shows for a participant step (the nodes' status texts). */
function clinicianMatch(key: string): (s: Step) => boolean {
  const [screen, what] = key.split(" ");
  const cues = (re: RegExp) => (s: Step) => re.test(s.cues ?? "");
  const test = (re: RegExp) => (s: Step) => re.test(s.test ?? "");
  switch (screen) {
    case "rest":
      return cues(new RegExp(`^rest: ${what} \\(`));
    case "cue":
      return cues(new RegExp(`^(rise|hold|capture|fall): ${what} \\(`));
    case "test-ready":
      return (s) => /^done:/.test(s.cues ?? "") && /schedule 0\/2/.test(s.test ?? "");
    case "test-cue":
      return test(new RegExp(`^capturing '${what}'`));
    case "test-rest":
      return test(/not capturing; schedule 1\/2/);
    default:
      return test(/not capturing; schedule 2\/2/);
  }
}

/** Takes both windows' screenshots once the participant shows `key`. */
async function shoot(clinician: Page, participant: Page, key: string, name: string) {
  const [screen] = key.split(" ");
  await participant.waitForSelector(`[data-participant][data-screen="${screen}"]`, {
    timeout: 60_000,
  });
  await participant.screenshot({ path: artifact(`participant-${name}.png`) });
  await clinician.screenshot({ path: artifact(`clinician-${name}.png`) });
}

/**
 * Stops the running fixture, opens the participant window from the toolbar, starts the protocol
 * and follows it to the end on both pages; returns the participant page.
 */
async function runProtocol(app: AppPage, shots: string): Promise<Page> {
  const clinician = app.page;
  await clinician.setViewportSize(FULL_HD);
  await clinician.click('.block-node[data-block="Cues"]');
  await clinician.waitForSelector('[data-panel="Cues"]');
  await clinician.click('.toolbar button:has-text("Stop")');
  await clinician.waitForSelector('.app[data-engine-state="stopped"]');
  const [participant] = await Promise.all([
    clinician.context().waitForEvent("page"),
    clinician.click('.toolbar button:has-text("Participant window")'),
  ]);
  const errors: string[] = [];
  participant.on("pageerror", (e) => errors.push(e.message));
  await participant.setViewportSize(FULL_HD);
  expect(participant.url()).toContain("view=participant");
  expect(participant.url()).toContain("block=Cues");
  // It follows the engine: stopped, so it waits (and shows no controls).
  await participant.waitForSelector('[data-participant][data-screen="waiting"]', {
    timeout: 30_000,
  });
  expect(await participant.locator("button").count()).toBe(0);
  await participant.evaluate(RECORDER);
  await clinician.evaluate(RECORDER);
  await clinician.click('.toolbar button:has-text("Start")');
  await shoot(clinician, participant, "rest", `${shots}-rest`);
  await shoot(clinician, participant, "cue", `${shots}-cue`);
  await shoot(clinician, participant, "test-cue", `${shots}-test`);
  await shoot(clinician, participant, "end", `${shots}-end`);
  expect(errors).toEqual([]);
  return participant;
}

/** The participant saw the protocol's steps in order, each in step with the clinician's page. */
async function expectInStep(clinician: Page, participant: Page): Promise<void> {
  const seen = screens(await steps(participant));
  const keys = seen.map((s) => s.key);
  // Every expected step, in order (a page may also show short in-between states).
  let i = 0;
  for (const k of keys) if (k === EXPECTED[i]) i++;
  expect(EXPECTED.slice(0, i), `participant steps: ${keys.join(" → ")}`).toEqual(EXPECTED);
  // No training screen once the test began; the end stays.
  const firstTest = keys.findIndex((k) => k.startsWith("test-"));
  expect(keys.slice(firstTest).filter((k) => /^(rest|cue)\b/.test(k))).toEqual([]);
  expect(keys.at(-1)).toBe("end");
  const recorded = await steps(clinician);
  for (const key of EXPECTED) {
    const at = seen.find((s) => s.key === key)!.t;
    const there = clinicianShows(recorded, at, clinicianMatch(key));
    expect(Math.abs(there - at), `clinician shows "${key}"`).toBeLessThan(IN_STEP_MS);
  }
}

describe.skipIf(!haveChromium)("participant window", () => {
  let browser: Chromium;

  beforeAll(async () => {
    ensureWebBuild();
    browser = await launchChromium();
  }, 120_000);

  afterAll(async () => {
    await browser?.close();
  });

  describe("with mosaic serve", () => {
    let server: CliServer | undefined;
    let url: string;

    beforeAll(async () => {
      requireBuild();
      server = await startCliServer(["serve", FIXTURE, "--port", "0"]);
      url = server.url;
    }, 60_000);

    afterAll(async () => {
      await server?.stop();
    });

    test("the participant page follows the clinician's protocol on the host's engine", async () => {
      const app = await openApp(browser, url);
      const participant = await runProtocol(app, "serve");
      expect(participant.url()).toContain("token=");
      await expectInStep(app.page, participant);
      expect(app.errors).toEqual([]);
      await participant.close();
      await app.close();
    }, 180_000);
  });

  describe("in the browser build", () => {
    let served: Served;

    beforeAll(async () => {
      served = await serveApp();
    });

    afterAll(async () => {
      await served?.close();
    });

    test("the participant page is driven by the clinician page's engine, not one of its own", async () => {
      const app = await openApp(browser, served.url, "e2e/participant.yaml");
      const participant = await runProtocol(app, "web");
      // One engine: the clinician page's worker; the participant page runs none.
      expect(app.page.workers().length).toBeGreaterThan(0);
      expect(participant.workers()).toHaveLength(0);
      expect(participant.url()).toContain("relay=");
      await expectInStep(app.page, participant);
      expect(app.errors).toEqual([]);
      // The clinician's page closes: the participant window says so.
      await app.close();
      await participant.waitForSelector("text=The clinician's MOSAIC window was closed", {
        timeout: 30_000,
      });
      await participant.close();
    }, 180_000);
  });
});
