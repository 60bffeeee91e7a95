/**
 * UI benchmark (issue 5; a benchmark, not a test): the Delsys-like pipeline (32 ch @ 1926 Hz)
 * runs in the browser build with three scopes open; for 30 s it records the main thread's long
 * tasks (PerformanceObserver 'longtask': every task over 50 ms, count and longest) and each
 * scope's redraw rate (draws counted by the panels in `window.__mosaicPanelStats`), the page's
 * frame rate (requestAnimationFrame), how busy the main thread is (Chrome's TaskDuration over wall
 * time, CDP Performance.getMetrics) and the CPU time of Chromium's threads (Linux /proc: unlike
 * wall-clock figures, not inflated when other programs compete for the cores), and the engine's
 * side from the telemetry the page receives: ticks lost (timers' missed ticks, edge drops), each
 * block's share of time in each status and its delivery delay. Targets: no long task over 50 ms
 * in 30 s; every scope ≥ 30 redraws per second; no tick lost; every block on time (green)
 * throughout. Prints the figures and writes bench/results/ui-latest.json and ui-latest.md.
 *
 * Run: `npm run bench:ui` (= node scripts/build-ts.mjs && node scripts/build-web.mjs &&
 * node tests/bench/ui/run.mjs [options]; `npm run bench:ui -- --seconds 10` etc.). Options:
 * --mode app|harness (app: the real shell, panels opened by clicking the graph's nodes
 * [data-block]; harness: the panels alone, see harness.tsx), --seconds 30, --warmup 5,
 * --pipeline pipelines/bench/delsys.yaml, --blocks Delsys,LowPass,Resampler (--blocks "" opens
 * none: the cost of the graph alone), --shots DIR (screenshots of every tab of every panel),
 * --trace FILE (a 5 s Chrome trace and a summary of the main thread's work), --no-isolation
 * (served without COOP/COEP: no shared memory, the engine on its coarse loop), --no-write.
 */
import {
  createReadStream,
  existsSync,
  mkdirSync,
  readdirSync,
  readFileSync,
  statSync,
  writeFileSync,
} from "node:fs";
import { createServer, type Server } from "node:http";
import { cpus, loadavg } from "node:os";
import { extname, join, normalize, resolve, sep } from "node:path";
import { chromium, type Browser, type CDPSession, type Page } from "playwright-core";

const ROOT = resolve(process.env.MOSAIC_ROOT ?? process.cwd());
const WEB = join(ROOT, "dist/web");
const HARNESS = join(ROOT, "dist/bench-ui");

interface Options {
  mode: "app" | "harness";
  seconds: number;
  warmup: number;
  pipeline: string;
  blocks: string[];
  shots: string | undefined;
  /** A Chrome trace of 5 s after the measurement, with a summary of the main thread's work. */
  trace: string | undefined;
  write: boolean;
  /** Serve with COOP/COEP (cross-origin isolated: shared memory, the precise loop). */
  isolated: boolean;
  chromium: string;
}

function parseArgs(argv: string[]): Options {
  const o: Options = {
    mode: "app",
    seconds: 30,
    warmup: 5,
    pipeline: "pipelines/bench/delsys.yaml",
    blocks: ["Delsys", "LowPass", "Resampler"],
    shots: undefined,
    trace: undefined,
    write: true,
    isolated: true,
    chromium: process.env.CHROMIUM ?? "/usr/bin/chromium",
  };
  for (let i = 0; i < argv.length; i++) {
    const a = argv[i]!;
    const next = (): string => {
      const v = argv[++i];
      if (v === undefined) throw new Error(`${a} needs a value`);
      return v;
    };
    if (a === "--mode") {
      const m = next();
      if (m !== "app" && m !== "harness") throw new Error("--mode is app or harness");
      o.mode = m;
    } else if (a === "--seconds") o.seconds = Number(next());
    else if (a === "--warmup") o.warmup = Number(next());
    else if (a === "--pipeline") o.pipeline = next();
    else if (a === "--blocks") o.blocks = next().split(",").filter(Boolean);
    else if (a === "--shots") o.shots = resolve(next());
    else if (a === "--trace") o.trace = resolve(next());
    else if (a === "--no-write") o.write = false;
    else if (a === "--no-isolation") o.isolated = false;
    else if (a === "--chromium") o.chromium = next();
    else throw new Error(`unknown option ${a}`);
  }
  return o;
}

const MIME: Record<string, string> = {
  ".html": "text/html; charset=utf-8",
  ".js": "text/javascript; charset=utf-8",
  ".css": "text/css; charset=utf-8",
  ".json": "application/json",
  ".map": "application/json",
  ".wasm": "application/wasm",
  ".yaml": "text/yaml; charset=utf-8",
  ".csv": "text/csv; charset=utf-8",
  ".txt": "text/plain; charset=utf-8",
};

/** `rel` under `base` when it is a file there (never outside it). */
function inside(base: string, rel: string): string | undefined {
  const f = resolve(base, rel);
  return f.startsWith(base + sep) && existsSync(f) && statSync(f).isFile() ? f : undefined;
}

/**
 * A static server for the browser build, cross-origin isolated (COOP/COEP) like `npm start`, or
 * not (`isolated` false: a plain static host, where the engine falls back to its coarse loop).
 */
function serve(isolated: boolean): Promise<{ server: Server; url: string }> {
  const server = createServer((req, res) => {
    const path = decodeURIComponent(new URL(req.url ?? "/", "http://x").pathname);
    const rel = normalize(path === "/" ? "/index.html" : path).replace(/^([/\\])+/, "");
    const file = inside(HARNESS, rel) ?? inside(WEB, rel);
    if (!file) {
      res.writeHead(404).end("not found");
      return;
    }
    res.writeHead(200, {
      "Content-Type": MIME[extname(file)] ?? "application/octet-stream",
      ...(isolated
        ? {
            "Cross-Origin-Opener-Policy": "same-origin",
            "Cross-Origin-Embedder-Policy": "require-corp",
          }
        : {}),
      "Cache-Control": "no-store",
    });
    createReadStream(file).pipe(res);
  });
  return new Promise((ok) =>
    server.listen(0, "127.0.0.1", () => {
      const a = server.address();
      const port = typeof a === "object" && a ? a.port : 0;
      ok({ server, url: `http://127.0.0.1:${port}/` });
    }),
  );
}

/** Installed before any page script: every long task the main thread runs, and every frame. */
const LONGTASK_OBSERVER = `
  window.__benchRaf = 0;
  const countFrame = () => { window.__benchRaf++; requestAnimationFrame(countFrame); };
  requestAnimationFrame(countFrame);
  window.__benchLongTasks = [];
  try {
    new PerformanceObserver((list) => {
      for (const e of list.getEntries()) window.__benchLongTasks.push({ start: e.startTime, duration: e.duration });
    }).observe({ type: "longtask", buffered: true });
  } catch (e) { window.__benchLongTasksError = String(e); }
  // Long animation frames (Chrome 123+) say which scripts a long frame ran: for diagnosis.
  window.__benchLoaf = [];
  try {
    new PerformanceObserver((list) => {
      for (const e of list.getEntries()) {
        if (e.duration <= 50) continue;
        window.__benchLoaf.push({
          start: e.startTime,
          duration: e.duration,
          blocking: e.blockingDuration,
          render: e.renderStart ? e.startTime + e.duration - e.renderStart : 0,
          layout: e.styleAndLayoutStart ? e.startTime + e.duration - e.styleAndLayoutStart : 0,
          scripts: (e.scripts || []).map((x) => ({
            invoker: x.invoker,
            source: (x.sourceURL || "").split("/").pop() + ":" + x.sourceFunctionName + "@" + x.sourceCharPosition,
            duration: Math.round(x.duration),
            forcedLayout: Math.round(x.forcedStyleAndLayoutDuration || 0),
          })),
        });
      }
    }).observe({ type: "long-animation-frame", buffered: true });
  } catch (e) { window.__benchLoafError = String(e); }
`;

interface ViewStats {
  draws: number;
  drawMs: number;
  maxDrawMs: number;
  messages: number;
  events: number;
  skipped: number;
}
interface Snapshot {
  now: number;
  /** requestAnimationFrame callbacks of the page (its frame rate). */
  raf: number;
  frames: number;
  tasks: number;
  views: Record<string, ViewStats>;
  longTasks: { start: number; duration: number }[];
  loaf: LongFrame[];
}

interface LongFrame {
  start: number;
  duration: number;
  blocking: number;
  render: number;
  layout: number;
  scripts: { invoker: string; source: string; duration: number; forcedLayout: number }[];
}

const SNAPSHOT = `(() => {
  const s = window.__mosaicPanelStats ?? { frames: 0, tasks: 0, views: {} };
  return { now: performance.now(), raf: window.__benchRaf ?? 0, frames: s.frames, tasks: s.tasks, views: JSON.parse(JSON.stringify(s.views)), longTasks: window.__benchLongTasks ?? [], loaf: window.__benchLoaf ?? [] };
})()`;

async function snapshot(page: Page): Promise<Snapshot> {
  return (await page.evaluate(SNAPSHOT)) as Snapshot;
}

/**
 * Installed once the page's engine client exists: every telemetry message the page receives,
 * summed per block (status counts, the largest delivery delay of each telemetry window) and the
 * longest gap between two messages. `__benchEngineReset()` starts the sums again (the
 * measurement's start).
 */
const ENGINE_RECORDER = `(() => {
  const client = window.mosaic && window.mosaic.client;
  if (!client) return false;
  if (window.__benchEngine) return true;
  const rec = { messages: 0, maxGapMs: 0, last: 0, blocks: {} };
  window.__benchEngine = rec;
  window.__benchEngineReset = () => { rec.messages = 0; rec.maxGapMs = 0; rec.blocks = {}; };
  client.onTelemetry((t) => {
    const now = performance.now();
    if (rec.last && rec.messages > 0) rec.maxGapMs = Math.max(rec.maxGapMs, now - rec.last);
    rec.last = now;
    rec.messages++;
    for (const b of t.blocks) {
      const r = (rec.blocks[b.name] ??= { ontime: 0, lagging: 0, stumbling: 0, idle: 0, windowMaxMs: 0, rateMin: Infinity, rateMax: 0 });
      r[b.status] = (r[b.status] ?? 0) + 1;
      const w = b.delay ? b.delay.windowMaxMs : 0;
      if (w > r.windowMaxMs) r.windowMaxMs = w;
      if (b.rate < r.rateMin) r.rateMin = b.rate;
      if (b.rate > r.rateMax) r.rateMax = b.rate;
    }
  });
  return true;
})()`;

interface BlockRecord {
  ontime: number;
  lagging: number;
  stumbling: number;
  idle: number;
  windowMaxMs: number;
  rateMin: number;
  rateMax: number;
}
interface EngineRecord {
  messages: number;
  maxGapMs: number;
  blocks: Record<string, BlockRecord>;
}

/** The latest telemetry's counters that the benchmark takes differences of. */
interface EngineSnapshot {
  t: number;
  blocks: {
    name: string;
    status: string;
    rate: number;
    desiredRate: number;
    dropsIn: number;
    computeTotalMs: number;
    delay: { p50Ms: number; p99Ms: number; maxMs: number; n: number } | undefined;
    timer: { fired: number; missed: number; catchUp: string; batchingMs: number } | undefined;
  }[];
  edgeDrops: number;
}

const ENGINE_SNAPSHOT = `(() => {
  const t = window.mosaic && window.mosaic.client && window.mosaic.client.telemetry;
  if (!t) return { t: 0, blocks: [], edgeDrops: 0 };
  return {
    t: t.t,
    blocks: t.blocks.map((b) => ({
      name: b.name, status: b.status, rate: b.rate, desiredRate: b.desiredRate, dropsIn: b.dropsIn,
      computeTotalMs: b.timing ? b.timing.computeTotalMs : 0,
      delay: b.delay ? { p50Ms: b.delay.p50Ms, p99Ms: b.delay.p99Ms, maxMs: b.delay.maxMs, n: b.delay.n } : undefined,
      timer: b.timer ? { fired: b.timer.fired, missed: b.timer.missed, catchUp: b.timer.catchUp, batchingMs: b.timer.batchingMs } : undefined,
    })),
    edgeDrops: t.edges.reduce((n, e) => n + e.dropped, 0),
  };
})()`;

async function engineSnapshot(page: Page): Promise<EngineSnapshot> {
  return (await page.evaluate(ENGINE_SNAPSHOT)) as EngineSnapshot;
}

async function openPanels(page: Page, o: Options, base: string): Promise<void> {
  if (o.mode === "harness") {
    await page.goto(
      `${base}harness.html?pipeline=${encodeURIComponent(o.pipeline)}&blocks=${o.blocks.join(",")}`,
    );
  } else {
    await page.goto(`${base}?pipeline=${encodeURIComponent(o.pipeline)}`);
    for (const b of o.blocks) {
      const node = page.locator(`[data-block="${b}"]`).first();
      await node.waitFor({ state: "visible", timeout: 30_000 });
      await node.click();
    }
  }
  for (const b of o.blocks) {
    try {
      await page
        .locator(`[data-view="scope"][data-block="${b}"]`)
        .first()
        .waitFor({ state: "visible", timeout: 20_000 });
    } catch {
      throw new Error(
        `no scope of ${b} appeared: ${o.mode === "app" ? "the app shell does not mount BlockPanel (app/ui/panels/block-panel.tsx) yet, or" : ""} the block has no scope view. Try --mode harness.`,
      );
    }
  }
  // Every scope must be on screen: a panel scrolled out of the dock is not visible and draws nothing.
  const hidden = (await page.evaluate(
    `[...document.querySelectorAll("[data-block-panel]")].filter((e) => e.getAttribute("data-visible") !== "true").map((e) => e.getAttribute("data-block-panel"))`,
  )) as string[];
  if (hidden.length)
    console.log(`ui-bench: warning: panels not visible (off screen?): ${hidden.join(", ")}`);
}

interface Figures {
  date: string;
  mode: string;
  pipeline: string;
  blocks: string[];
  seconds: number;
  chromium: string;
  /**
   * The machine during the window: `busyPercent` is all its cores' busy time (% of one core,
   * /proc/stat), `othersPercent` the part not used by this benchmark's Chromium (other programs
   * competing for the cores: what makes a run on a shared machine noisy).
   */
  host: { cpus: number; load1: number; busyPercent: number; othersPercent: number };
  sharedMemory: boolean;
  longTasks: { count: number; maxMs: number; totalMs: number; durationsMs: number[] };
  /** Long animation frames over 50 ms in the window, with the scripts they ran (diagnosis). */
  longFrames: LongFrame[];
  /** Page frames (requestAnimationFrame) and frames of the panels' shared draw loop, per second. */
  frames: { perSecond: number; panelLoopPerSecond: number };
  /**
   * The renderer's main thread, from Chrome's own counters (CDP Performance.getMetrics):
   * share of the wall time spent in tasks, and of it in script, style and layout (the rest is
   * mostly paint and compositing work on the main thread).
   */
  /**
   * CPU use of Chromium's threads over the window (% of one core, from /proc), keyed
   * "process type/thread": renderer/main is the page's main thread, renderer/DedicatedWorker the
   * engine, gpu-process/VizCompositor the software compositor.
   */
  cpuPercent: Record<string, number>;
  mainThread: {
    busyPercent: number;
    scriptPercent: number;
    stylePercent: number;
    layoutPercent: number;
    otherPercent: number;
  };
  scopes: {
    view: string;
    redrawsPerSecond: number;
    minPerSecond: number;
    drawMsMean: number;
    drawMsMax: number;
    eventsPerSecond: number;
    skippedPerSecond: number;
  }[];
  afterClose: { tasks: number; messagesInOneSecond: number } | undefined;
  /**
   * The engine side, from the telemetry the page received during the measurement: ticks lost
   * (timers' missed ticks and drops on every edge, differences over the window), and per block
   * the share of telemetry messages in each status, the delivery delay (p50/p99/max since the
   * pipeline started: the engine's histogram, warm-up included; `windowMaxMs`: the largest of
   * the measured window) and the blocks' compute time (% of one core).
   */
  engine: {
    telemetryMessages: number;
    /** Longest gap between two telemetry messages arriving on the page (20 Hz: 50 ms). */
    maxGapMs: number;
    ticksLost: { missed: number; edgeDrops: number };
    /** Sum of the blocks' measured compute time over the window (% of one core). */
    computePercent: number;
    blocks: {
      name: string;
      status: string;
      /** Share of the telemetry messages in each status (%). */
      share: { ontime: number; lagging: number; stumbling: number; idle: number };
      rate: number;
      rateMin: number;
      desiredRate: number;
      delayP50Ms: number;
      delayP99Ms: number;
      delayMaxMs: number;
      windowMaxMs: number;
      computePercent: number;
      dropsIn: number;
      /** Timers: ticks fired per second over the window, missed ticks, catch-up, batching. */
      firedPerSecond?: number;
      missed?: number;
      catchUp?: string;
      batchingMs?: number;
    }[];
  };
  targets: {
    noLongTask: boolean;
    scopesAt30fps: boolean;
    noTickLost: boolean;
    /** Every block on time (green) in every telemetry message of the window. */
    allOnTime: boolean;
  };
}

/**
 * CPU time (seconds) of every thread of the Chromium processes this benchmark started (Linux
 * /proc; empty elsewhere), by "process type/thread name". Unlike wall-clock task durations, CPU
 * time does not grow when other programs compete for the cores.
 */
/** Busy and total time of all cores, in USER_HZ ticks (Linux /proc/stat; zeros elsewhere). */
function machineTimes(): { busy: number; total: number } {
  try {
    const line = readFileSync("/proc/stat", "utf8").split("\n")[0]!;
    const f = line.trim().split(/\s+/).slice(1).map(Number);
    const total = f.reduce((a, b) => a + b, 0);
    const idle = (f[3] ?? 0) + (f[4] ?? 0);
    return { busy: total - idle, total };
  } catch {
    return { busy: 0, total: 0 };
  }
}

function cpuTimes(): Map<string, number> {
  const out = new Map<string, number>();
  let pids: string[];
  try {
    pids = readdirSync("/proc").filter((d) => /^\d+$/.test(d));
  } catch {
    return out;
  }
  const parent = new Map<string, string>();
  for (const p of pids) {
    try {
      const stat = readFileSync(`/proc/${p}/stat`, "utf8");
      parent.set(p, stat.slice(stat.lastIndexOf(")") + 2).split(" ")[1]!);
    } catch {
      // gone
    }
  }
  const mine = (p: string): boolean => {
    for (let q: string | undefined = p, i = 0; q && q !== "0" && i < 20; q = parent.get(q), i++)
      if (q === String(process.pid)) return p !== String(process.pid);
    return false;
  };
  const tick = 100; // USER_HZ on Linux
  for (const p of parent.keys()) {
    if (!mine(p)) continue;
    let type = "browser";
    try {
      const cmd = readFileSync(`/proc/${p}/cmdline`, "utf8");
      type = /--type=([a-z-]+)/.exec(cmd)?.[1] ?? "browser";
      if (/--extension-process|--utility-sub-type=[^\0]*network/.test(cmd)) type += "*";
    } catch {
      continue;
    }
    let tids: string[] = [];
    try {
      tids = readdirSync(`/proc/${p}/task`);
    } catch {
      continue;
    }
    for (const t of tids) {
      try {
        const comm = readFileSync(`/proc/${p}/task/${t}/comm`, "utf8").trim();
        const stat = readFileSync(`/proc/${p}/task/${t}/stat`, "utf8");
        const f = stat.slice(stat.lastIndexOf(")") + 2).split(" ");
        const sec = (Number(f[11]) + Number(f[12])) / tick;
        const name = t === p ? "main" : comm.replace(/\d+$/, "");
        const k = `${type}/${name}`;
        out.set(k, (out.get(k) ?? 0) + sec);
      } catch {
        // thread gone
      }
    }
  }
  return out;
}

/** Chrome's main-thread counters (seconds), through the DevTools protocol. */
async function metrics(cdp: CDPSession): Promise<Record<string, number>> {
  const r = (await cdp.send("Performance.getMetrics")) as {
    metrics: { name: string; value: number }[];
  };
  return Object.fromEntries(r.metrics.map((m) => [m.name, m.value]));
}

async function measure(page: Page, o: Options): Promise<Figures> {
  const cdp = await page.context().newCDPSession(page);
  await cdp.send("Performance.enable", { timeDomain: "timeTicks" });
  await page.waitForTimeout(o.warmup * 1000);
  if (!(await page.evaluate(ENGINE_RECORDER)))
    throw new Error("the page has no window.mosaic.client: cannot read the engine's telemetry");
  await page.evaluate("window.__benchEngineReset()");
  const e0 = await engineSnapshot(page);
  const m0 = await metrics(cdp);
  const c0 = cpuTimes();
  const h0 = machineTimes();
  const start = await snapshot(page);
  const perSecond: Record<string, number[]> = {};
  let prev = start;
  for (let s = 0; s < o.seconds; s++) {
    await page.waitForTimeout(1000);
    const cur = await snapshot(page);
    const dt = (cur.now - prev.now) / 1000;
    for (const [k, v] of Object.entries(cur.views)) {
      if (!k.startsWith("scope:")) continue;
      (perSecond[k] ??= []).push((v.draws - (prev.views[k]?.draws ?? 0)) / dt);
    }
    prev = cur;
  }
  const end = prev;
  const m1 = await metrics(cdp);
  const c1 = cpuTimes();
  const h1 = machineTimes();
  const e1 = await engineSnapshot(page);
  const rec = (await page.evaluate("window.__benchEngine")) as EngineRecord;
  const elapsed = (end.now - start.now) / 1000;
  const wall = (m1.Timestamp ?? 0) - (m0.Timestamp ?? 0) || elapsed;
  const share = (k: string): number => round((100 * ((m1[k] ?? 0) - (m0[k] ?? 0))) / wall, 1);
  const busy = share("TaskDuration");
  const cpu: Record<string, number> = {};
  for (const [k, v] of c1) {
    const used = round((100 * (v - (c0.get(k) ?? 0))) / wall, 1);
    if (used >= 0.5) cpu[k] = used;
  }
  // Busy ticks of all cores over the window, as % of one core (USER_HZ 100).
  const machineBusy = round((h1.busy - h0.busy) / wall, 1);
  const script = share("ScriptDuration");
  const style = share("RecalcStyleDuration");
  const layout = share("LayoutDuration");
  const tasks = end.longTasks.filter((t) => t.start >= start.now && t.start <= end.now);
  const scopes = Object.entries(end.views)
    .filter(([k]) => k.startsWith("scope:"))
    .map(([k, v]) => {
      const a = start.views[k] ?? {
        draws: 0,
        drawMs: 0,
        maxDrawMs: 0,
        events: 0,
        skipped: 0,
        messages: 0,
      };
      const draws = v.draws - a.draws;
      return {
        view: k,
        redrawsPerSecond: round(draws / elapsed, 1),
        minPerSecond: round(Math.min(...(perSecond[k] ?? [0])), 1),
        drawMsMean: round(draws ? (v.drawMs - a.drawMs) / draws : 0, 2),
        drawMsMax: round(v.maxDrawMs, 1),
        eventsPerSecond: round((v.events - a.events) / elapsed, 0),
        skippedPerSecond: round((v.skipped - a.skipped) / elapsed, 0),
      };
    });
  const engine = engineFigures(e0, e1, rec);
  const sharedMemory = (await page.evaluate("self.crossOriginIsolated === true")) as boolean;
  const longest = tasks.reduce((m, t) => Math.max(m, t.duration), 0);
  return {
    date: new Date().toISOString(),
    mode: o.mode,
    pipeline: o.pipeline,
    blocks: o.blocks,
    seconds: round(elapsed, 1),
    chromium: o.chromium,
    host: {
      cpus: cpus().length,
      load1: round(loadavg()[0] ?? 0, 2),
      busyPercent: machineBusy,
      othersPercent: round(
        Math.max(0, machineBusy - Object.values(cpu).reduce((a, b) => a + b, 0)),
        1,
      ),
    },
    sharedMemory,
    longTasks: {
      count: tasks.length,
      maxMs: round(longest, 0),
      totalMs: round(
        tasks.reduce((m, t) => m + t.duration, 0),
        0,
      ),
      durationsMs: tasks.map((t) => round(t.duration, 0)),
    },
    longFrames: end.loaf
      .filter((f) => f.start >= start.now && f.start <= end.now)
      .map((f) => ({
        ...f,
        start: round(f.start - start.now, 0),
        duration: round(f.duration, 0),
        blocking: round(f.blocking, 0),
        render: round(f.render, 0),
        layout: round(f.layout, 0),
      })),
    frames: {
      perSecond: round((end.raf - start.raf) / elapsed, 1),
      panelLoopPerSecond: round((end.frames - start.frames) / elapsed, 1),
    },
    cpuPercent: Object.fromEntries(Object.entries(cpu).sort((a, b) => b[1] - a[1])),
    mainThread: {
      busyPercent: busy,
      scriptPercent: script,
      stylePercent: style,
      layoutPercent: layout,
      otherPercent: round(Math.max(0, busy - script - style - layout), 1),
    },
    scopes,
    afterClose: undefined,
    engine,
    targets: {
      noLongTask: tasks.length === 0,
      scopesAt30fps:
        scopes.length === o.blocks.length && scopes.every((s) => s.redrawsPerSecond >= 30),
      noTickLost:
        engine.blocks.length > 0 &&
        engine.ticksLost.missed === 0 &&
        engine.ticksLost.edgeDrops === 0,
      allOnTime:
        engine.telemetryMessages > 0 &&
        engine.blocks.length > 0 &&
        engine.blocks.every((b) => b.share.ontime === 100),
    },
  };
}

/** The engine's figures over the window: differences of two snapshots and the page's sums. */
function engineFigures(
  e0: EngineSnapshot,
  e1: EngineSnapshot,
  rec: EngineRecord,
): Figures["engine"] {
  const dt = e1.t - e0.t;
  let missed = 0;
  let computeMs = 0;
  const blocks = e1.blocks.map((b) => {
    const a = e0.blocks.find((x) => x.name === b.name);
    const r = rec.blocks[b.name];
    const n = r ? r.ontime + r.lagging + r.stumbling + r.idle : 0;
    const pct = (k: number): number => (n ? round((100 * k) / n, 1) : 0);
    const compute = b.computeTotalMs - (a?.computeTotalMs ?? 0);
    computeMs += compute;
    const out: Figures["engine"]["blocks"][number] = {
      name: b.name,
      status: b.status,
      share: {
        ontime: pct(r?.ontime ?? 0),
        lagging: pct(r?.lagging ?? 0),
        stumbling: pct(r?.stumbling ?? 0),
        idle: pct(r?.idle ?? 0),
      },
      rate: round(b.rate, 1),
      rateMin: round(r && Number.isFinite(r.rateMin) ? r.rateMin : 0, 1),
      desiredRate: round(b.desiredRate, 3),
      delayP50Ms: round(b.delay?.p50Ms ?? 0, 2),
      delayP99Ms: round(b.delay?.p99Ms ?? 0, 2),
      delayMaxMs: round(b.delay?.maxMs ?? 0, 2),
      windowMaxMs: round(r?.windowMaxMs ?? 0, 2),
      computePercent: round(dt > 0 ? compute / (10 * dt) : 0, 2),
      dropsIn: b.dropsIn - (a?.dropsIn ?? 0),
    };
    if (b.timer) {
      const m = b.timer.missed - (a?.timer?.missed ?? 0);
      missed += m;
      out.firedPerSecond = round(dt > 0 ? (b.timer.fired - (a?.timer?.fired ?? 0)) / dt : 0, 1);
      out.missed = m;
      out.catchUp = b.timer.catchUp;
      out.batchingMs = b.timer.batchingMs;
    }
    return out;
  });
  return {
    telemetryMessages: rec.messages,
    maxGapMs: round(rec.maxGapMs, 0),
    ticksLost: { missed, edgeDrops: e1.edgeDrops - e0.edgeDrops },
    computePercent: round(dt > 0 ? computeMs / (10 * dt) : 0, 2),
    blocks,
  };
}

/** Closes (app) or hides (harness) the panels and checks that no draw task nor data remains. */
async function checkRelease(page: Page, o: Options): Promise<Figures["afterClose"]> {
  if (o.mode === "harness") await page.locator('[data-harness="close-all"]').click();
  else {
    for (const b of o.blocks) {
      const close = page.locator(`[data-panel="${b}"] button[aria-label^="Close"]`).first();
      if (await close.count()) await close.click();
    }
  }
  await page.waitForTimeout(500);
  const a = await snapshot(page);
  await page.waitForTimeout(1000);
  const b = await snapshot(page);
  let messages = 0;
  for (const [k, v] of Object.entries(b.views))
    messages += v.messages - (a.views[k]?.messages ?? 0);
  return { tasks: b.tasks, messagesInOneSecond: messages };
}

/** Screenshots of every tab of every open panel (to look at them). */
async function screenshots(page: Page, o: Options, dir: string): Promise<string[]> {
  mkdirSync(dir, { recursive: true });
  const files: string[] = [];
  for (const b of o.blocks) {
    const panel = page.locator(`[data-block-panel="${b}"]`).first();
    const tabs = await panel
      .locator("[role=tab]")
      .evaluateAll((els) => els.map((e) => e.getAttribute("data-tab") ?? ""));
    for (const t of tabs) {
      await panel.locator(`[data-tab="${t}"]`).click();
      await page.waitForTimeout(t === "status" ? 1500 : 1200);
      const f = join(dir, `${o.mode}-${b}-${t}.png`);
      await panel.screenshot({ path: f });
      files.push(f);
    }
    await panel
      .locator('[data-tab="scope"]')
      .click()
      .catch(() => undefined);
  }
  const f = join(dir, `${o.mode}-page.png`);
  await page.screenshot({ path: f });
  files.push(f);
  return files;
}

interface TraceEvent {
  name: string;
  ph: string;
  ts: number;
  dur?: number;
  pid: number;
  tid: number;
  args?: { name?: string };
}

/**
 * Records a Chrome trace for 5 s and prints where the renderer's main thread spent its time:
 * the events with the most total duration (an event's time includes the events nested in it).
 */
async function trace(browser: Browser, page: Page, file: string): Promise<void> {
  await browser.startTracing(page, {
    path: file,
    categories: [
      "devtools.timeline",
      "disabled-by-default-devtools.timeline",
      "blink",
      "cc",
      "gpu",
    ],
  });
  await page.waitForTimeout(5000);
  const buf = await browser.stopTracing();
  const parsed = JSON.parse(buf.toString()) as { traceEvents: TraceEvent[] } | TraceEvent[];
  const events = Array.isArray(parsed) ? parsed : parsed.traceEvents;
  const threads = new Map<string, string>();
  for (const e of events)
    if (e.ph === "M" && e.name === "thread_name")
      threads.set(`${e.pid}:${e.tid}`, e.args?.name ?? "");
  const totals = new Map<string, { ms: number; n: number }>();
  for (const e of events) {
    if (e.ph !== "X" || e.dur === undefined) continue;
    const thread = threads.get(`${e.pid}:${e.tid}`) ?? "?";
    if (!/CrRendererMain|Compositor|Raster|VizCompositor|CrGpuMain/.test(thread)) continue;
    const k = `${thread.replace(/Thread.*/, "")} ${e.name}`;
    const t = totals.get(k) ?? { ms: 0, n: 0 };
    t.ms += e.dur / 1000;
    t.n++;
    totals.set(k, t);
  }
  const top = [...totals.entries()].sort((a, b) => b[1].ms - a[1].ms).slice(0, 40);
  console.log(`ui-bench: trace in ${file}; over 5 s, the longest (nested times included):`);
  for (const [k, t] of top)
    console.log(`  ${k.padEnd(60)} ${t.ms.toFixed(0).padStart(6)} ms  ×${t.n}`);
}

const round = (x: number, d: number): number => Math.round(x * 10 ** d) / 10 ** d;

function markdown(f: Figures): string {
  const yes = (b: boolean): string => (b ? "met" : "**missed**");
  const lines = [
    "# UI benchmark",
    "",
    `${f.date} · ${f.mode === "app" ? "the app shell" : "panels alone (harness)"} · \`${f.pipeline}\` · scopes of ${f.blocks.join(", ")} · ${f.seconds} s measured · Chromium headless (${f.chromium}) · ${f.host.cpus} CPUs, load ${f.host.load1}, ${f.host.busyPercent} % of a core busy of which ${f.host.othersPercent} % by other programs · shared memory: ${f.sharedMemory ? "yes" : "no"}`,
    "",
    "| figure | target | measured | result |",
    "| --- | --- | --- | --- |",
    `| main-thread long tasks (> 50 ms) | none | ${f.longTasks.count}${f.longTasks.count ? ` (longest ${f.longTasks.maxMs} ms)` : ""} | ${yes(f.targets.noLongTask)} |`,
    ...f.scopes.map(
      (s) =>
        `| ${s.view} redraws/s (slowest second) | ≥ 30 | ${s.redrawsPerSecond} (${s.minPerSecond}); draw ${s.drawMsMean} ms mean, ${s.drawMsMax} ms max | ${yes(s.redrawsPerSecond >= 30)} |`,
    ),
    `| main thread busy | — | ${f.mainThread.busyPercent} % (script ${f.mainThread.scriptPercent} %, style ${f.mainThread.stylePercent} %, layout ${f.mainThread.layoutPercent} %, paint and other ${f.mainThread.otherPercent} %) | — |`,
    `| main thread CPU | — | ${f.cpuPercent["renderer/main"] ?? "?"} % of a core (the engine's worker ${f.cpuPercent["renderer/DedicatedWorker"] ?? "?"} %) | — |`,
    `| page frames/s (requestAnimationFrame) | — | ${f.frames.perSecond} (panels' draw loop ${f.frames.panelLoopPerSecond}) | — |`,
    `| engine: ticks lost (timers' missed ticks + edge drops) | 0 | ${f.engine.ticksLost.missed} + ${f.engine.ticksLost.edgeDrops} | ${yes(f.targets.noTickLost)} |`,
    `| engine: blocks on time (green) | every block, every telemetry | ${f.engine.blocks.filter((b) => b.share.ontime === 100).length} of ${f.engine.blocks.length} always; least ${Math.min(...f.engine.blocks.map((b) => b.share.ontime))} % | ${yes(f.targets.allOnTime)} |`,
    `| engine: delivery delay p99 (largest block) | — | ${Math.max(0, ...f.engine.blocks.map((b) => b.delayP99Ms))} ms since start; largest in the window ${Math.max(0, ...f.engine.blocks.map((b) => b.windowMaxMs))} ms | — |`,
    "",
    ...(f.longFrames.length
      ? [
          "Long animation frames (> 50 ms) and what ran in them:",
          "",
          ...f.longFrames.map(
            (l) =>
              `- at ${(l.start / 1000).toFixed(1)} s: ${l.duration} ms (blocking ${l.blocking} ms, rendering ${l.render} ms)` +
              (l.scripts.length
                ? `: ${l.scripts.map((x) => `${x.invoker} ${x.source} ${x.duration} ms`).join("; ")}`
                : ""),
          ),
          "",
        ]
      : []),
    "CPU of Chromium's threads (% of one core): " +
      Object.entries(f.cpuPercent)
        .map(([k, v]) => `${k} ${v}`)
        .join(", ") +
      ".",
    "",
    "Scope data: " +
      f.scopes
        .map(
          (s) =>
            `${s.view} ${s.eventsPerSecond} events/s plotted (${s.skippedPerSecond}/s left out by the engine's maxRate)`,
        )
        .join("; ") +
      ".",
    "",
    f.afterClose
      ? `After closing the panels: ${f.afterClose.tasks} draw tasks left, ${f.afterClose.messagesInOneSecond} data messages in the next second.`
      : "",
    "",
    ...engineLines(f),
    "",
  ];
  return lines.join("\n");
}

/** The engine's section: one row per block. */
function engineLines(f: Figures): string[] {
  const e = f.engine;
  return [
    `Engine (${e.telemetryMessages} telemetry messages received in the window, longest gap ${e.maxGapMs} ms; blocks' compute ${e.computePercent} % of a core). Status shares are of the telemetry messages; the delay is the engine's delivery delay (processing time − the oldest event's timestamp of each batch), p50/p99/max since the pipeline started, and the largest of the measured window:`,
    "",
    "| block | on time | lagging | stumbling | idle | rate (min) / desired, Hz | delay p50 / p99 / max, ms | window max, ms | compute, % core | lost |",
    "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
    ...e.blocks.map(
      (b) =>
        `| ${b.name} | ${b.share.ontime} % | ${b.share.lagging} % | ${b.share.stumbling} % | ${b.share.idle} % | ${b.rate} (${b.rateMin}) / ${b.desiredRate} | ${b.delayP50Ms} / ${b.delayP99Ms} / ${b.delayMaxMs} | ${b.windowMaxMs} | ${b.computePercent} | ${
          b.firedPerSecond !== undefined
            ? `${b.missed ?? 0} missed of ${b.firedPerSecond}/s (catch-up ${b.catchUp}, batching ${b.batchingMs} ms)`
            : ""
        }${b.dropsIn ? `${b.firedPerSecond !== undefined ? ", " : ""}${b.dropsIn} dropped in` : ""} |`,
    ),
    "",
  ];
}

async function main(): Promise<void> {
  const o = parseArgs(process.argv.slice(2));
  if (!existsSync(join(WEB, "index.html")))
    throw new Error("dist/web is missing: run node scripts/build-web.mjs first");
  if (o.mode === "harness" && !existsSync(join(HARNESS, "harness.html")))
    throw new Error(
      "dist/bench-ui is missing: run node tests/bench/ui/run.mjs (it builds the harness)",
    );
  const { server, url } = await serve(o.isolated);
  let browser: Browser | undefined;
  try {
    browser = await chromium.launch({
      executablePath: o.chromium,
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
    });
    // Tall enough for three docked panels to be on screen at once.
    const page = await browser.newPage({
      viewport: { width: 1600, height: o.mode === "app" ? 1500 : 1000 },
    });
    const errors: string[] = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    page.on("console", (m) => {
      if (m.type() === "error") errors.push(m.text());
    });
    await page.addInitScript(LONGTASK_OBSERVER);
    console.log(`ui-bench: ${o.mode} mode, ${url}, opening scopes of ${o.blocks.join(", ")}`);
    await openPanels(page, o, url);
    const f = await measure(page, o);
    if (o.shots) {
      const files = await screenshots(page, o, o.shots);
      console.log(`ui-bench: ${files.length} screenshots in ${o.shots}`);
    }
    if (o.trace) await trace(browser, page, o.trace);
    f.afterClose = await checkRelease(page, o);
    const md = markdown(f);
    console.log(md);
    if (errors.length) console.log(`page errors:\n  ${errors.slice(0, 10).join("\n  ")}`);
    if (o.write) {
      const dir = join(ROOT, "bench/results");
      mkdirSync(dir, { recursive: true });
      writeFileSync(join(dir, "ui-latest.json"), JSON.stringify(f, null, 2) + "\n");
      writeFileSync(join(dir, "ui-latest.md"), md);
      console.log("ui-bench: wrote bench/results/ui-latest.json and ui-latest.md");
    }
  } finally {
    await browser?.close();
    server.close();
  }
}

main().catch((e: unknown) => {
  console.error(`ui-bench: ${e instanceof Error ? e.message : String(e)}`);
  process.exitCode = 1;
});
