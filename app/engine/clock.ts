/** The pipeline clock: UNIX seconds as f64 (DESIGN.md §3). */
export interface Clock {
  now(): number;
}

/**
 * Real time from one monotonic clock mapped to wall time once: `offsetMs` is added to the
 * thread's `performance.now()`. The host computes the offset per thread from one shared
 * (wall, monotonic) pair taken at start, so every worker reads the same clock.
 */
export class MonotonicClock implements Clock {
  constructor(private readonly offsetMs: number = performance.timeOrigin) {}
  now(): number {
    return (this.offsetMs + performance.now()) / 1000;
  }
}

/** Virtual time: advanced by the runtime from deadline to deadline, as fast as possible. */
export class VirtualClock implements Clock {
  constructor(public t = 0) {}
  now(): number {
    return this.t;
  }
}
