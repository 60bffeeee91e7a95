/**
 * `mosaic bench`, process side: runs `mosaic run … --json` as a child process and measures it from
 * outside, the way the paper measured MOSAIC (section V-B, Fig. 6/7): CPU and memory sampled once a
 * second from the operating system, timing statistics and block statuses from the product's own
 * telemetry.
 *
 * CPU: every second, the child's CPU time is read twice:
 * - `/proc/<pid>/stat` utime + stime (all threads, in clock ticks of `getconf CLK_TCK`, usually
 *   100 Hz, so one tick is 1 % of one core in a 1-s sample);
 * - the sum over `/proc/<pid>/task/<tid>/schedstat` (time on CPU in ns, per thread), which has no
 *   tick quantisation. This is the figure reported when the kernel provides it.
 * Memory: `/proc/<pid>/status` VmRSS every second, and VmHWM (peak RSS) every second and once more
 * when the summary line arrives (the process is still alive then), keeping the last value read.
 * Wake-ups: `voluntary_ctxt_switches` of every thread (`/proc/<pid>/task/<tid>/status`) at the start
 * and the end of the steady-state window: a thread that blocks (Atomics.wait, epoll) and is woken
 * again counts one voluntary switch, so their rate is the thread's wake-ups per second.
 */
import { spawn, type ChildProcessByStdio } from "node:child_process";
import type { Readable } from "node:stream";
import type { Telemetry } from "../engine/runtime/runtime";
import type { Status } from "../engine/runtime/status";
import {
  childrenDelta,
  clkTck,
  mark,
  nsDelta,
  readStatusKiB,
  readTaskCtxt,
  type ContextSwitches,
  type CpuMark,
} from "./bench-procfs";

export interface CpuSample {
  /** Seconds since the child was spawned, at the end of the sample. */
  t: number;
  /** Length of the sample, s. */
  dt: number;
  /** CPU % of one core from /proc/<pid>/stat utime + stime. */
  ticksPct: number;
  /** CPU % of one core from the per-thread schedstat sum (NaN when unavailable). */
  nsPct: number;
  /** VmRSS at the end of the sample, KiB. */
  rssKiB: number;
  /** CPU % of one core of the child's own child processes (e.g. Python sidecars), from their
   * /proc/<pid>/stat; 0 when it has none. */
  childrenPct: number;
  /** VmRSS of those child processes together, KiB (0 without). */
  childrenRssKiB: number;
  /** After the warm-up (steady state)? */
  steady: boolean;
}

export interface Summary extends Telemetry {
  type: "summary";
  reason: string;
  exitCode: number;
  wallSeconds: number;
  measuredSeconds: number;
  logs: string[];
}

export interface ChildRun {
  args: string[];
  ok: boolean;
  /** Why the run is not usable (spawn failure, no summary, non-zero exit). */
  error?: string;
  exitCode: number | null;
  summary?: Summary;
  /** Last telemetry line before `warmup-done` (baseline for all-time counters). */
  baseline?: Telemetry;
  /** Status counts per block over the telemetry lines of the steady-state window. */
  statusCounts: Map<string, Record<Status, number>>;
  /** Telemetry lines counted in the steady-state window. */
  telemetryLines: number;
  samples: CpuSample[];
  /** CPU of each thread over the steady-state window (% of one core, busiest first; schedstat),
   * with its voluntary (wake-ups) and involuntary (preempted) context switches per second. */
  threads: {
    tid: number;
    main: boolean;
    pct: number;
    voluntaryPerS: number;
    nonvoluntaryPerS: number;
  }[];
  /** The steady-state window, performance.now() times in this process (NaN until it started). */
  windowMs: { from: number; to: number };
  /** Peak RSS (VmHWM) read last, KiB (NaN when never read). */
  peakRssKiB: number;
  /** Seconds from spawn to the summary line minus the run's own wallSeconds: process start,
   * module and WASM load, pipeline load, worker start. */
  loadSeconds: number;
  /** Seconds from spawn to the summary line. */
  toSummarySeconds: number;
  /** Seconds the child stayed alive after printing its summary (until exit or our SIGTERM). */
  lingerSeconds: number;
  /** The child had to be terminated after its summary. */
  killedAfterSummary: boolean;
  /** Warning and error events printed by the child (first few kept). */
  events: { level: string; block: string; message: string }[];
  eventCount: number;
  /** Events printed by the child, by level (error, warning, info). */
  eventsByLevel: Record<string, number>;
  stderrTail: string;
}

export interface ChildOptions {
  cli: string;
  args: string[];
  /** Seconds after `warmup-done` during which CPU samples and telemetry count as steady state
   * (whole 1-s samples only). Without a warm-up the window starts at spawn. */
  steadySeconds: number;
  /** Expect a `warmup-done` line (the run was given --warmup). */
  warmup: boolean;
  /** Hard limit for the child, s (it is killed after this). */
  timeoutSeconds: number;
  /** How long the child may stay alive after its summary before it is terminated, s. */
  lingerLimitSeconds?: number;
  cwd?: string;
  /** Variables added to the child's environment. */
  env?: Record<string, string>;
}

/** Runs `node dist/cli.mjs <args>` and measures it. Never rejects. */
export function runChild(o: ChildOptions): Promise<ChildRun> {
  return new Promise((resolveRun) => new ChildMonitor(o, resolveRun).start());
}

type Child = ChildProcessByStdio<null, Readable, Readable>;

/**
 * One measured run: spawns the child, samples /proc once a second (CPU, RSS, and the threads
 * over the steady-state window), reads its JSON lines (telemetry, warm-up end, events, summary)
 * and settles the result when it exits.
 */
class ChildMonitor {
  private readonly o: ChildOptions;
  private readonly resolveRun: (r: ChildRun) => void;
  private readonly res: ChildRun;
  private readonly tck = clkTck();
  /** Whole 1-s samples in the steady-state window. */
  private readonly windowSamples: number;
  private t0 = NaN;
  private child: Child | undefined;
  private pid: number | undefined;
  /** The steady-state window, seconds since spawn (unbounded until `warmup-done`). */
  private steadyFrom: number;
  private steadyUntil: number;
  /** The child's time at the end of the warm-up (its `warmup-done` line), UNIX seconds. */
  private warmupT: number | undefined;
  private steadySamples = 0;
  private last: CpuMark | undefined;
  /** The mark at the start of the steady state (per-thread breakdown). */
  private steadyStart: CpuMark | undefined;
  private steadyCtxt: ContextSwitches | undefined;
  private sampler: NodeJS.Timeout | undefined;
  private summaryAt = NaN;
  private lastTelemetry: Telemetry | undefined;
  private lingerTimer: NodeJS.Timeout | undefined;
  private hardLimit: NodeJS.Timeout | undefined;
  /** Stdout not yet split into lines. */
  private buf = "";

  constructor(o: ChildOptions, resolveRun: (r: ChildRun) => void) {
    this.o = o;
    this.resolveRun = resolveRun;
    this.windowSamples = Math.floor(o.steadySeconds);
    this.steadyFrom = o.warmup ? Infinity : 0;
    this.steadyUntil = o.warmup ? Infinity : o.steadySeconds;
    this.res = {
      args: o.args,
      ok: false,
      exitCode: null,
      statusCounts: new Map(),
      telemetryLines: 0,
      samples: [],
      threads: [],
      windowMs: { from: NaN, to: NaN },
      peakRssKiB: NaN,
      loadSeconds: NaN,
      toSummarySeconds: NaN,
      lingerSeconds: NaN,
      killedAfterSummary: false,
      events: [],
      eventCount: 0,
      eventsByLevel: {},
      stderrTail: "",
    };
  }

  start(): void {
    const o = this.o;
    this.t0 = performance.now();
    const child = spawn(process.execPath, [o.cli, ...o.args], {
      cwd: o.cwd,
      stdio: ["ignore", "pipe", "pipe"],
      ...(o.env ? { env: { ...process.env, ...o.env } } : {}),
    });
    this.child = child;
    const pid = (this.pid = child.pid);
    this.last = pid !== undefined ? mark(pid, this.since()) : undefined;
    this.steadyStart = o.warmup ? undefined : this.last;
    this.steadyCtxt = o.warmup || pid === undefined ? undefined : readTaskCtxt(pid);
    if (!o.warmup) {
      this.res.windowMs = { from: this.t0, to: this.t0 + this.windowSamples * 1000 };
    }
    this.startSampler();
    this.hardLimit = setTimeout(() => {
      this.res.error = `no summary within ${o.timeoutSeconds} s; terminated`;
      child.kill("SIGKILL");
    }, o.timeoutSeconds * 1000);
    child.stdout.setEncoding("utf8");
    child.stdout.on("data", (d: string) => this.onStdout(d));
    child.stderr.setEncoding("utf8");
    child.stderr.on("data", (d: string) => {
      this.res.stderrTail = (this.res.stderrTail + d).slice(-4000);
    });
    child.on("error", (e) => this.finish(null, `cannot start: ${e.message}`));
    child.on("close", (code, signal) => {
      const killedByUs = this.res.killedAfterSummary && signal === "SIGTERM";
      this.finish(killedByUs ? (this.res.summary?.exitCode ?? code) : code);
    });
  }

  /** Seconds since the child was spawned. */
  private since(): number {
    return (performance.now() - this.t0) / 1000;
  }

  // -------------------------------------------------------------------------------------------
  // Sampling /proc

  private startSampler(): void {
    if (this.sampler) clearInterval(this.sampler);
    this.sampler = setInterval(() => this.sample(), 1000);
  }

  /** A 1-s sample; once the window is full, the threads' shares, then memory only. */
  private sample(): void {
    const pid = this.pid;
    if (pid === undefined || !this.last) return;
    const now = this.since();
    const cur = mark(pid, now);
    this.addSample(pid, now, this.last, cur);
    this.last = cur;
    const windowFull = this.steadySamples >= this.windowSamples;
    if (this.steadyStart && windowFull && this.res.threads.length === 0) {
      this.res.threads = threadShares(pid, this.steadyStart, cur, this.steadyCtxt);
    }
    if (this.o.warmup && windowFull && now > this.steadyFrom) {
      // steady-state window done; keep reading memory only
      if (this.sampler) clearInterval(this.sampler);
      this.sampler = setInterval(() => this.readPeakRss(pid), 1000);
    }
  }

  private addSample(pid: number, now: number, last: CpuMark, cur: CpuMark): void {
    const dt = cur.at - last.at;
    if (!(dt > 0 && Number.isFinite(cur.ticks))) return;
    const steady = now > this.steadyFrom && this.steadySamples < this.windowSamples;
    if (steady) this.steadySamples++;
    this.res.samples.push({
      t: now,
      dt,
      ticksPct: ((cur.ticks - last.ticks) / this.tck / dt) * 100,
      nsPct: (nsDelta(last.ns, cur.ns) / 1e9 / dt) * 100,
      rssKiB: readStatusKiB(pid, "VmRSS"),
      childrenPct: (childrenDelta(last.children, cur.children) / this.tck / dt) * 100,
      childrenRssKiB: [...cur.children.keys()].reduce(
        (a, c) => a + (readStatusKiB(c, "VmRSS") || 0),
        0,
      ),
      steady,
    });
    this.readPeakRss(pid);
  }

  /** VmHWM, kept when readable: the last value read is the peak. */
  private readPeakRss(pid: number): void {
    const hwm = readStatusKiB(pid, "VmHWM");
    if (Number.isFinite(hwm)) this.res.peakRssKiB = hwm;
  }

  // -------------------------------------------------------------------------------------------
  // The child's JSON lines

  private onStdout(d: string): void {
    this.buf += d;
    let i: number;
    while ((i = this.buf.indexOf("\n")) >= 0) {
      this.onLine(this.buf.slice(0, i));
      this.buf = this.buf.slice(i + 1);
    }
  }

  private onLine(line: string): void {
    if (line.length === 0) return;
    let m: { type?: string } & Record<string, unknown>;
    try {
      m = JSON.parse(line) as typeof m;
    } catch {
      return; // not a JSON line (should not happen with --json)
    }
    switch (m.type) {
      case "telemetry":
        this.onTelemetry(m as unknown as Telemetry);
        break;
      case "warmup-done":
        this.onWarmupDone(Number(m.t));
        break;
      case "event":
        this.onEvent(m);
        break;
      case "fatal":
        this.res.error = `fatal: ${String(m.message)}`;
        break;
      case "summary":
        this.onSummary(m as unknown as Summary);
        break;
    }
  }

  /**
   * Counts the blocks' statuses of the reports in the window; a report before it is the baseline.
   * With a warm-up, a report belongs where its own time `t` falls (the CLI hands reports over in
   * groups of a quarter second, so a line can arrive after `warmup-done` and still be from the
   * warm-up); without one, where it arrives.
   */
  private onTelemetry(t: Telemetry): void {
    const at = this.warmupT === undefined ? this.since() : t.t - this.warmupT;
    const from = this.warmupT === undefined ? this.steadyFrom : 0;
    const until = this.warmupT === undefined ? this.steadyUntil : this.windowSamples;
    if (at > from && at <= until) {
      this.res.telemetryLines++;
      for (const b of t.blocks) {
        let c = this.res.statusCounts.get(b.name);
        if (!c) this.res.statusCounts.set(b.name, (c = EMPTY_COUNTS()));
        c[b.status]++;
      }
    }
    if (this.steadyFrom === Infinity || (this.warmupT !== undefined && at <= 0)) {
      this.res.baseline = t;
    }
    this.lastTelemetry = t;
  }

  private onWarmupDone(t: number): void {
    this.warmupT = t;
    // The steady state starts now: close the last (partial) warm-up sample and restart the
    // 1-s samples on this instant.
    const pid = this.pid;
    if (pid !== undefined) this.sample();
    const now = this.since();
    this.steadyFrom = now;
    this.steadyUntil = now + this.windowSamples;
    if (pid !== undefined) {
      this.last = this.steadyStart = mark(pid, now);
      this.steadyCtxt = readTaskCtxt(pid);
      this.startSampler();
    }
    this.res.windowMs = { from: this.t0 + now * 1000, to: this.t0 + this.steadyUntil * 1000 };
    if (!this.res.baseline) this.res.baseline = this.lastTelemetry;
  }

  private onEvent(m: Record<string, unknown>): void {
    this.res.eventCount++;
    const level = String(m.level);
    this.res.eventsByLevel[level] = (this.res.eventsByLevel[level] ?? 0) + 1;
    if (this.res.events.length < 20) {
      this.res.events.push({
        level: String(m.level),
        block: String(m.block),
        message: String(m.message),
      });
    }
  }

  private onSummary(s: Summary): void {
    this.summaryAt = this.since();
    this.res.summary = s;
    if (this.pid !== undefined) this.readPeakRss(this.pid);
    if (this.sampler) clearInterval(this.sampler);
    this.sampler = undefined;
    this.res.toSummarySeconds = this.summaryAt;
    this.res.loadSeconds = this.summaryAt - s.wallSeconds;
    // Everything is flushed once the summary is out; a child that lingers is stopped.
    this.lingerTimer = setTimeout(
      () => {
        this.res.killedAfterSummary = true;
        this.child?.kill("SIGTERM");
      },
      (this.o.lingerLimitSeconds ?? 1) * 1000,
    );
  }

  // -------------------------------------------------------------------------------------------
  // The end

  private finish(code: number | null, why?: string): void {
    const res = this.res;
    if (this.sampler) clearInterval(this.sampler);
    if (this.lingerTimer) clearTimeout(this.lingerTimer);
    clearTimeout(this.hardLimit);
    if (this.buf.length > 0) this.onLine(this.buf);
    res.exitCode = code;
    res.lingerSeconds = Number.isFinite(this.summaryAt) ? this.since() - this.summaryAt : NaN;
    if (why && !res.error) res.error = why;
    if (!res.summary && !res.error) {
      res.error = `exited with code ${code} without a summary${res.stderrTail ? `: ${res.stderrTail.trim().split("\n").slice(-3).join(" | ")}` : ""}`;
    }
    if (res.summary && res.summary.exitCode !== 0 && !res.error) {
      res.error = `the run reported exit code ${res.summary.exitCode} (${res.summary.reason})`;
    }
    res.ok = res.summary !== undefined && res.error === undefined;
    this.resolveRun(res);
  }
}

const EMPTY_COUNTS = (): Record<Status, number> => ({
  ontime: 0,
  idle: 0,
  lagging: 0,
  stumbling: 0,
});

/**
 * Each thread's CPU over the steady-state window (% of one core, busiest first) and its voluntary
 * (wake-ups) and involuntary (preempted) context switches per second; empty without schedstat.
 */
function threadShares(
  pid: number,
  start: CpuMark,
  cur: CpuMark,
  ctxtStart: ContextSwitches | undefined,
): ChildRun["threads"] {
  const span = cur.at - start.at;
  const ns = start.ns;
  if (!(span > 0 && ns && cur.ns)) return [];
  const c0 = ctxtStart ?? new Map();
  const c1 = readTaskCtxt(pid);
  return [...cur.ns]
    .map(([tid, v]) => {
      const a = c0.get(tid);
      const b = c1.get(tid);
      return {
        tid: Number(tid),
        main: Number(tid) === pid,
        pct: ((v - (ns.get(tid) ?? 0)) / 1e9 / span) * 100,
        voluntaryPerS: b ? (b.vol - (a?.vol ?? 0)) / span : NaN,
        nonvoluntaryPerS: b ? (b.nonvol - (a?.nonvol ?? 0)) / span : NaN,
      };
    })
    .sort((a, b) => b.pct - a.pct);
}
