/**
 * One clock for the whole process (DESIGN.md §3): UNIX seconds from one monotonic clock, mapped
 * to wall time once at start. The main thread takes a (wall, monotonic) pair; every worker turns
 * it into an offset for its own `performance.now()`, so all threads read the same time.
 */
import { MonotonicClock } from "../engine/clock";

export interface TimeBase {
  /** Wall time at the reference instant, ms since the UNIX epoch (sub-ms precision). */
  wallMs: number;
  /** process.hrtime.bigint() at the same instant, as a decimal string. */
  monoNs: string;
}

export function takeTimeBase(): TimeBase {
  // The first use of `performance` loads perf_hooks (1–3 ms): do it before taking the pair, or
  // the clock runs that much ahead of wall time.
  performance.now();
  const mono = process.hrtime.bigint();
  const wallMs = performance.timeOrigin + performance.now();
  return { wallMs, monoNs: mono.toString() };
}

/** A clock for this thread that agrees with every other thread given the same base. */
export function clockFromBase(base: TimeBase): MonotonicClock {
  performance.now();
  const p = performance.now();
  const mono = process.hrtime.bigint();
  const offsetMs = base.wallMs + Number(mono - BigInt(base.monoNs)) / 1e6 - p;
  return new MonotonicClock(offsetMs);
}
