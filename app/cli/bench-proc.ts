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
import { spawn } from "node:child_process";
import { execFileSync } from "node:child_process";
import { readdirSync, readFileSync } from "node:fs";
import type { Telemetry } from "../engine/runtime/runtime";
import type { Status } from "../engine/runtime/status";

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
}

let clkTckCache: number | undefined;
/** Clock ticks per second of /proc/<pid>/stat times (`getconf CLK_TCK`, normally 100). */
export function clkTck(): number {
  if (clkTckCache !== undefined) return clkTckCache;
  let v = 100;
  try {
    const s = execFileSync("getconf", ["CLK_TCK"], { encoding: "utf8" }).trim();
    const n = Number(s);
    if (Number.isInteger(n) && n > 0) v = n;
  } catch {
    // getconf missing: Linux's USER_HZ is 100 on every mainstream architecture
  }
  clkTckCache = v;
  return v;
}

/** utime + stime of the whole process (all threads), in ticks; NaN when unreadable. */
function readStatTicks(pid: number): number {
  try {
    const s = readFileSync(`/proc/${pid}/stat`, "utf8");
    // The command name (field 2) is in parentheses and may hold spaces: split after the last ')'.
    const rest = s.slice(s.lastIndexOf(")") + 2).split(" ");
    // rest[0] is field 3 (state); utime is field 14, stime field 15.
    return Number(rest[11]) + Number(rest[12]);
  } catch {
    return NaN;
  }
}

/** CPU time of every thread from schedstat, ns (empty map when unavailable). */
function readTaskNs(pid: number): Map<string, number> | undefined {
  try {
    const out = new Map<string, number>();
    for (const tid of readdirSync(`/proc/${pid}/task`)) {
      try {
        const s = readFileSync(`/proc/${pid}/task/${tid}/schedstat`, "utf8");
        const ns = Number(s.split(" ")[0]);
        if (Number.isFinite(ns)) out.set(tid, ns);
      } catch {
        // the thread exited between readdir and read
      }
    }
    return out;
  } catch {
    return undefined;
  }
}

/** Whether per-thread schedstat works here (some kernels lack CONFIG_SCHED_INFO). */
export function schedstatAvailable(): boolean {
  const m = readTaskNs(process.pid);
  return m !== undefined && m.size > 0 && [...m.values()].some((v) => v > 0);
}

/** Voluntary and involuntary context switches of every thread (empty map when unreadable). */
function readTaskCtxt(pid: number): Map<string, { vol: number; nonvol: number }> {
  const out = new Map<string, { vol: number; nonvol: number }>();
  let tids: string[];
  try {
    tids = readdirSync(`/proc/${pid}/task`);
  } catch {
    return out;
  }
  for (const tid of tids) {
    try {
      const s = readFileSync(`/proc/${pid}/task/${tid}/status`, "utf8");
      const vol = /^voluntary_ctxt_switches:\s+(\d+)/m.exec(s);
      const nonvol = /^nonvoluntary_ctxt_switches:\s+(\d+)/m.exec(s);
      if (vol && nonvol) out.set(tid, { vol: Number(vol[1]), nonvol: Number(nonvol[1]) });
    } catch {
      // the thread exited between readdir and read
    }
  }
  return out;
}

function readStatusKiB(pid: number, key: "VmRSS" | "VmHWM"): number {
  try {
    const s = readFileSync(`/proc/${pid}/status`, "utf8");
    const m = new RegExp(`^${key}:\\s+(\\d+) kB`, "m").exec(s);
    return m ? Number(m[1]) : NaN;
  } catch {
    return NaN;
  }
}

interface CpuMark {
  at: number;
  ticks: number;
  ns: Map<string, number> | undefined;
  /** utime + stime of every descendant process, ticks, by pid. */
  children: Map<number, number>;
}

/** Every descendant of `pid` (children of all its threads, recursively). */
function descendants(pid: number, out: number[] = []): number[] {
  let tids: string[];
  try {
    tids = readdirSync(`/proc/${pid}/task`);
  } catch {
    return out;
  }
  for (const tid of tids) {
    let kids: string;
    try {
      kids = readFileSync(`/proc/${pid}/task/${tid}/children`, "utf8");
    } catch {
      continue;
    }
    for (const k of kids.split(" ")) {
      const c = Number(k);
      if (Number.isInteger(c) && c > 0 && !out.includes(c)) {
        out.push(c);
        descendants(c, out);
      }
    }
  }
  return out;
}

function childrenDelta(a: Map<number, number>, b: Map<number, number>): number {
  let d = 0;
  for (const [pid, v] of b) d += Math.max(0, v - (a.get(pid) ?? 0));
  return d;
}

function mark(pid: number, at: number): CpuMark {
  const children = new Map<number, number>();
  for (const c of descendants(pid)) {
    const t = readStatTicks(c);
    if (Number.isFinite(t)) children.set(c, t);
  }
  return { at, ticks: readStatTicks(pid), ns: readTaskNs(pid), children };
}

function nsDelta(a: Map<string, number> | undefined, b: Map<string, number> | undefined): number {
  if (!a || !b || b.size === 0) return NaN;
  let d = 0;
  for (const [tid, v] of b) {
    const prev = a.get(tid);
    // A thread born during the interval ran only in it; a thread that exited is lost (tiny).
    d += prev === undefined ? v : Math.max(0, v - prev);
  }
  return d;
}

const EMPTY_COUNTS = (): Record<Status, number> => ({
  ontime: 0,
  idle: 0,
  lagging: 0,
  stumbling: 0,
});

/** Runs `node dist/cli.mjs <args>` and measures it. Never rejects. */
export function runChild(o: ChildOptions): Promise<ChildRun> {
  const tck = clkTck();
  const lingerLimit = o.lingerLimitSeconds ?? 1;
  const res: ChildRun = {
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
    stderrTail: "",
  };
  return new Promise((resolveRun) => {
    const t0 = performance.now();
    const since = () => (performance.now() - t0) / 1000;
    const child = spawn(process.execPath, [o.cli, ...o.args], {
      cwd: o.cwd,
      stdio: ["ignore", "pipe", "pipe"],
    });
    const pid = child.pid;
    let steadyFrom = o.warmup ? Infinity : 0;
    let steadyUntil = o.warmup ? Infinity : o.steadySeconds;
    let steadySamples = 0;
    let last: CpuMark | undefined = pid !== undefined ? mark(pid, since()) : undefined;
    /** The mark at the start of the steady state (per-thread breakdown). */
    let steadyStart: CpuMark | undefined = o.warmup ? undefined : last;
    let steadyCtxt = o.warmup || pid === undefined ? undefined : readTaskCtxt(pid);
    if (!o.warmup) res.windowMs = { from: t0, to: t0 + Math.floor(o.steadySeconds) * 1000 };
    let sampler: NodeJS.Timeout | undefined;
    let summaryAt = NaN;
    let lastTelemetry: Telemetry | undefined;
    let lingerTimer: NodeJS.Timeout | undefined;

    const sample = (): void => {
      if (pid === undefined || !last) return;
      const now = since();
      const cur = mark(pid, now);
      const dt = cur.at - last.at;
      if (dt > 0 && Number.isFinite(cur.ticks)) {
        const steady = now > steadyFrom && steadySamples < Math.floor(o.steadySeconds);
        if (steady) steadySamples++;
        res.samples.push({
          t: now,
          dt,
          ticksPct: ((cur.ticks - last.ticks) / tck / dt) * 100,
          nsPct: (nsDelta(last.ns, cur.ns) / 1e9 / dt) * 100,
          rssKiB: readStatusKiB(pid, "VmRSS"),
          childrenPct: (childrenDelta(last.children, cur.children) / tck / dt) * 100,
          steady,
        });
        const hwm = readStatusKiB(pid, "VmHWM");
        if (Number.isFinite(hwm)) res.peakRssKiB = hwm;
      }
      last = cur;
      if (steadyStart && steadySamples >= Math.floor(o.steadySeconds) && res.threads.length === 0) {
        const span = cur.at - steadyStart.at;
        const ns = steadyStart.ns;
        if (span > 0 && ns && cur.ns) {
          const c0 = steadyCtxt ?? new Map<string, { vol: number; nonvol: number }>();
          const c1 = readTaskCtxt(pid);
          res.threads = [...cur.ns]
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
      }
      if (o.warmup && steadySamples >= Math.floor(o.steadySeconds) && now > steadyFrom) {
        // steady-state window done; keep reading memory only
        if (sampler) clearInterval(sampler);
        sampler = setInterval(() => {
          const hwm = readStatusKiB(pid, "VmHWM");
          if (Number.isFinite(hwm)) res.peakRssKiB = hwm;
        }, 1000);
      }
    };
    const startSampler = (): void => {
      if (sampler) clearInterval(sampler);
      sampler = setInterval(sample, 1000);
    };
    startSampler();

    const hardLimit = setTimeout(() => {
      res.error = `no summary within ${o.timeoutSeconds} s; terminated`;
      child.kill("SIGKILL");
    }, o.timeoutSeconds * 1000);

    const onLine = (line: string): void => {
      if (line.length === 0) return;
      let m: { type?: string } & Record<string, unknown>;
      try {
        m = JSON.parse(line) as typeof m;
      } catch {
        return; // not a JSON line (should not happen with --json)
      }
      switch (m.type) {
        case "telemetry": {
          const t = m as unknown as Telemetry;
          const now = since();
          if (now > steadyFrom && now <= steadyUntil) {
            res.telemetryLines++;
            for (const b of t.blocks) {
              let c = res.statusCounts.get(b.name);
              if (!c) res.statusCounts.set(b.name, (c = EMPTY_COUNTS()));
              c[b.status]++;
            }
          }
          if (steadyFrom === Infinity) res.baseline = t;
          lastTelemetry = t;
          break;
        }
        case "warmup-done": {
          // The steady state starts now: close the last (partial) warm-up sample and restart the
          // 1-s samples on this instant.
          if (pid !== undefined) sample();
          const now = since();
          steadyFrom = now;
          steadyUntil = now + Math.floor(o.steadySeconds);
          if (pid !== undefined) {
            last = steadyStart = mark(pid, now);
            steadyCtxt = readTaskCtxt(pid);
            startSampler();
          }
          res.windowMs = { from: t0 + now * 1000, to: t0 + steadyUntil * 1000 };
          if (!res.baseline) res.baseline = lastTelemetry;
          break;
        }
        case "event": {
          res.eventCount++;
          if (res.events.length < 20) {
            res.events.push({
              level: String(m.level),
              block: String(m.block),
              message: String(m.message),
            });
          }
          break;
        }
        case "fatal":
          res.error = `fatal: ${String(m.message)}`;
          break;
        case "summary": {
          summaryAt = since();
          res.summary = m as unknown as Summary;
          if (pid !== undefined) {
            const hwm = readStatusKiB(pid, "VmHWM");
            if (Number.isFinite(hwm)) res.peakRssKiB = hwm;
          }
          if (sampler) clearInterval(sampler);
          sampler = undefined;
          res.toSummarySeconds = summaryAt;
          res.loadSeconds = summaryAt - res.summary.wallSeconds;
          // Everything is flushed once the summary is out; a child that lingers is stopped.
          lingerTimer = setTimeout(() => {
            res.killedAfterSummary = true;
            child.kill("SIGTERM");
          }, lingerLimit * 1000);
          break;
        }
      }
    };

    let buf = "";
    child.stdout.setEncoding("utf8");
    child.stdout.on("data", (d: string) => {
      buf += d;
      let i: number;
      while ((i = buf.indexOf("\n")) >= 0) {
        onLine(buf.slice(0, i));
        buf = buf.slice(i + 1);
      }
    });
    child.stderr.setEncoding("utf8");
    child.stderr.on("data", (d: string) => {
      res.stderrTail = (res.stderrTail + d).slice(-4000);
    });
    const finish = (code: number | null, why?: string): void => {
      if (sampler) clearInterval(sampler);
      if (lingerTimer) clearTimeout(lingerTimer);
      clearTimeout(hardLimit);
      if (buf.length > 0) onLine(buf);
      res.exitCode = code;
      res.lingerSeconds = Number.isFinite(summaryAt) ? since() - summaryAt : NaN;
      if (why && !res.error) res.error = why;
      if (!res.summary && !res.error) {
        res.error = `exited with code ${code} without a summary${res.stderrTail ? `: ${res.stderrTail.trim().split("\n").slice(-3).join(" | ")}` : ""}`;
      }
      if (res.summary && res.summary.exitCode !== 0 && !res.error) {
        res.error = `the run reported exit code ${res.summary.exitCode} (${res.summary.reason})`;
      }
      res.ok = res.summary !== undefined && res.error === undefined;
      resolveRun(res);
    };
    child.on("error", (e) => finish(null, `cannot start: ${e.message}`));
    child.on("close", (code, signal) => {
      const killedByUs = res.killedAfterSummary && signal === "SIGTERM";
      finish(killedByUs ? (res.summary?.exitCode ?? code) : code);
    });
  });
}

/** Median and percentile of a list (linear interpolation, as numpy's default). */
export function quantile(xs: readonly number[], q: number): number {
  const a = xs.filter((x) => Number.isFinite(x)).sort((x, y) => x - y);
  if (a.length === 0) return NaN;
  const pos = (a.length - 1) * q;
  const lo = Math.floor(pos);
  const hi = Math.ceil(pos);
  return a[lo]! + (a[hi]! - a[lo]!) * (pos - lo);
}

export function mean(xs: readonly number[]): number {
  const a = xs.filter((x) => Number.isFinite(x));
  return a.length ? a.reduce((s, x) => s + x, 0) / a.length : NaN;
}

export function std(xs: readonly number[]): number {
  const a = xs.filter((x) => Number.isFinite(x));
  if (a.length < 2) return NaN;
  const m = mean(a);
  return Math.sqrt(a.reduce((s, x) => s + (x - m) ** 2, 0) / (a.length - 1));
}

/**
 * How often a worker wakes for a timer of `hz` ticks per second with a batching interval of
 * `batchingMs` (DESIGN.md §3): it wakes at the deadline of the last tick within the interval of the
 * oldest pending one, i.e. once per floor(interval · hz) + 1 ticks.
 */
export function wakeRate(hz: number, batchingMs: number): number {
  if (!(batchingMs > 0)) return hz;
  return hz / (Math.floor((batchingMs / 1000) * hz + 1e-9) + 1);
}

/**
 * The cost of waking up alone on this machine: a bare Node worker that does nothing but sleep in
 * `Atomics.wait` until each deadline at `hz` (no engine, no event-loop turns), as % of one core
 * (median of 1-s samples over `seconds`). Pipelines cannot go below this at the same wake-up rate
 * (`wakeRate`).
 */
export async function measureWakeFloor(hz: number, seconds: number): Promise<number> {
  const worker =
    "const b=new Int32Array(new SharedArrayBuffer(4));const p=1000/" +
    String(hz) +
    ";const s=performance.now();let k=1;for(;;){const r=s+k*p-performance.now();if(r>0)Atomics.wait(b,0,0,r);k++;}";
  const child = spawn(
    process.execPath,
    ["-e", `new (require("node:worker_threads").Worker)(${JSON.stringify(worker)},{eval:true})`],
    { stdio: "ignore" },
  );
  const pid = child.pid;
  try {
    if (pid === undefined) return NaN;
    await new Promise((r) => setTimeout(r, 1500));
    const samples: number[] = [];
    let prev = readTaskNs(pid);
    for (let i = 0; i < seconds; i++) {
      await new Promise((r) => setTimeout(r, 1000));
      const cur = readTaskNs(pid);
      const d = nsDelta(prev, cur);
      if (Number.isFinite(d)) samples.push(d / 1e7);
      prev = cur;
    }
    return quantile(samples, 0.5);
  } finally {
    child.kill("SIGKILL");
  }
}

/**
 * A neighbour that burns one core at normal priority (`node -e "for(;;){}"`), for the loaded
 * variant of a workload. `stop()` kills it and returns the CPU it used, % of one core over its life
 * (from /proc/<pid>/stat; NaN when unreadable), so a report shows that it really ran.
 */
export function startNeighbour(): { command: string; stop: () => number } {
  const code = "for(;;){}";
  const child = spawn(process.execPath, ["-e", code], { stdio: "ignore" });
  const t0 = performance.now();
  const pid = child.pid;
  return {
    command: `node -e "${code}"`,
    stop(): number {
      const ticks = pid !== undefined ? readStatTicks(pid) : NaN;
      const seconds = (performance.now() - t0) / 1000;
      child.kill("SIGKILL");
      return seconds > 0 ? (ticks / clkTck() / seconds) * 100 : NaN;
    },
  };
}
