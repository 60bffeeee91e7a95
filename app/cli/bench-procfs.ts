/**
 * `mosaic bench`: what /proc says about a process — CPU time (stat ticks, per-thread schedstat),
 * context switches, memory, descendants — and the marks the bench takes of them once a second.
 */
import { execFileSync } from "node:child_process";
import { readdirSync, readFileSync } from "node:fs";

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
export function readStatTicks(pid: number): number {
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
export function readTaskNs(pid: number): Map<string, number> | undefined {
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

export type ContextSwitches = Map<string, { vol: number; nonvol: number }>;

/** Voluntary and involuntary context switches of every thread (empty map when unreadable). */
export function readTaskCtxt(pid: number): ContextSwitches {
  const out: ContextSwitches = new Map();
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

/** A `Vm…:` line of /proc/<pid>/status, KiB; NaN when unreadable. */
export function readStatusKiB(pid: number, key: "VmRSS" | "VmHWM"): number {
  try {
    const s = readFileSync(`/proc/${pid}/status`, "utf8");
    const m = new RegExp(`^${key}:\\s+(\\d+) kB`, "m").exec(s);
    return m ? Number(m[1]) : NaN;
  } catch {
    return NaN;
  }
}

/** A reading of a process's CPU time at `at` (seconds since it was spawned). */
export interface CpuMark {
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

/** CPU ticks the descendants used between two marks (a descendant born in between: all its ticks). */
export function childrenDelta(a: Map<number, number>, b: Map<number, number>): number {
  let d = 0;
  for (const [pid, v] of b) d += Math.max(0, v - (a.get(pid) ?? 0));
  return d;
}

/** Reads the CPU time of `pid`, its threads and its descendants now. */
export function mark(pid: number, at: number): CpuMark {
  const children = new Map<number, number>();
  for (const c of descendants(pid)) {
    const t = readStatTicks(c);
    if (Number.isFinite(t)) children.set(c, t);
  }
  return { at, ticks: readStatTicks(pid), ns: readTaskNs(pid), children };
}

/** Schedstat ns the threads used between two readings; NaN without readings. */
export function nsDelta(
  a: Map<string, number> | undefined,
  b: Map<string, number> | undefined,
): number {
  if (!a || !b || b.size === 0) return NaN;
  let d = 0;
  for (const [tid, v] of b) {
    const prev = a.get(tid);
    // A thread born during the interval ran only in it; a thread that exited is lost (tiny).
    d += prev === undefined ? v : Math.max(0, v - prev);
  }
  return d;
}
