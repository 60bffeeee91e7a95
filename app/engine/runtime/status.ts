/**
 * Timing status as DESIGN.md §3 / the paper III-B, for a runtime that delivers events in batches:
 * - rate = (n − 1) / (t_last − t_first) over the last 100 outputs (event timestamps);
 * - idle (grey) when there was no output for 10 periods and at least 50 ms (a gap between a
 *   device's packets is not idleness), plus the batching interval (during which a batch is
 *   allowed to wait), or none at all. A block without a desired rate emits on request (a Buffer
 *   recording rows, a recorder): while its outputs are silent it is timed by what it consumes, so
 *   it reads idle only when neither output nor input came for a second;
 * - lagging (red) when rate < 95 % of DesiredRate, or when an input batch reached the block
 *   late: its oldest event waited longer than max(2 periods, 50 ms) plus the batching interval
 *   (the engine is behind real time; lossless timers keep rates exact, so a rate alone would not
 *   show it). A late batch keeps the block red for as long as it was delayed, at least LATE_HOLD_S,
 *   whatever the block's rate; so do ticks a `CatchUp: skip` timer skipped (for as long as they
 *   span): a timer that misses ticks is never green;
 * - stumbling (magenta) when one `process` call (measured) took longer than the time its events
 *   span, max(1, n) / DesiredRate, within the current window;
 * - on time (green) otherwise. Precedence idle > lagging > stumbling > on time.
 *
 * Delivery delay (processing time − timestamp of the oldest event of a batch) is kept in a
 * histogram since the last `resetTiming` (p50 / p99 / max in telemetry) and as a per-telemetry
 * window maximum.
 */
import type { Frame } from "../frame";
import { DelayHistogram } from "./delay-histogram";

export type Status = "idle" | "lagging" | "stumbling" | "ontime";
export const STATUSES: readonly Status[] = ["ontime", "idle", "lagging", "stumbling"];

export const RATE_WINDOW = 100;
export const LAG_FRACTION = 0.95;
export const IDLE_PERIODS = 10;
/** Idle threshold for blocks without a desired rate (aperiodic, e.g. triggers). */
export const APERIODIC_IDLE_S = 1;
/**
 * The shortest silence that reads idle, whatever the rate: devices deliver packets (a Trigno
 * base 26 samples every 13.5 ms, a Myo two every 10 ms), and a gap between two packets is not
 * idleness. 50 ms as LATE_MIN_S: one telemetry report at 20 Hz.
 */
export const IDLE_MIN_S = 0.05;

/** How long without output reads idle for a block at `rate` Hz (≤ 0: aperiodic). */
export function idleAfterS(rate: number, batchS: number): number {
  return (rate > 0 ? Math.max(IDLE_PERIODS / rate, IDLE_MIN_S) : APERIODIC_IDLE_S) + batchS;
}
/** A batch is late when its oldest event waited longer than this many periods … */
export const LATE_PERIODS = 2;
/**
 * … or this long, whichever is more, plus the batching interval. 50 ms: well inside the ~100 ms
 * a myoelectric control loop tolerates (Farrell & Weir 2007), and above the hiccups (GC, a
 * descheduled VM) that a busy machine has without the engine being behind.
 */
export const LATE_MIN_S = 0.05;
/** The shortest time a late batch shows (two telemetry reports at 20 Hz: visible in the UI). */
export const LATE_HOLD_S = 0.1;

export interface StatusEval {
  status: Status;
  rate: number;
  lagging: boolean;
  stumbling: boolean;
}

export class StatusTracker {
  /** Event timestamps of the last RATE_WINDOW outputs (ring). */
  private readonly ts = new Float64Array(RATE_WINDOW);
  /** Clock time at which each of those outputs was emitted (ring). */
  private readonly wall = new Float64Array(RATE_WINDOW);
  private idx = 0;
  private inWindow = 0;
  /** Total output events. */
  events = 0;
  lastWall = -Infinity;
  /** Clock time of the last input batch processed (see `consumed`). */
  lastInputWall = -Infinity;
  lastOverrunWall = -Infinity;
  /** Until when a late batch keeps the block lagging (clock time). */
  lateUntil = -Infinity;
  /** The batching interval that applies to this block's inputs, s (set by the runtime). */
  batchS = 0;

  /** Delivery delay since the last `resetTiming` (real time only). */
  readonly delay = new DelayHistogram();
  /** Largest delivery delay since the last telemetry, s. */
  delayMaxWindow = 0;

  // compute time of `process` calls (ms)
  calls = 0;
  computeLast = 0;
  computeMaxWindow = 0;
  computeSumWindow = 0;
  callsWindow = 0;
  computeTotal = 0;

  // latency: emission clock time − event timestamp (s), mean since last telemetry
  latencySum = 0;
  latencyN = 0;

  // ΔT between consecutive output events, by event timestamps (Welford), for the bench's Table 5
  dtN = 0;
  dtMean = 0;
  dtM2 = 0;
  private prevT = NaN;

  constructor(public desiredRate: number) {}

  /** Records an emitted frame at clock time `now`. */
  record(f: Frame, now: number): void {
    const n = f.n;
    const rate = this.desiredRate;
    // Back from idle: the window restarts, so a pause does not read as lagging afterwards.
    if (rate > 0 && now - this.lastWall > idleAfterS(rate, this.batchS)) {
      this.inWindow = 0;
      this.prevT = NaN;
    }
    const t = f.t;
    const start = n > RATE_WINDOW ? n - RATE_WINDOW : 0;
    for (let i = start; i < n; i++) {
      this.ts[this.idx] = t[i]!;
      this.wall[this.idx] = now;
      this.idx = (this.idx + 1) % RATE_WINDOW;
    }
    this.inWindow = Math.min(RATE_WINDOW, this.inWindow + (n - start));
    this.events += n;
    this.lastWall = now;
    this.latencySum += now - t[n - 1]!;
    this.latencyN++;
    // ΔT stats between consecutive events by their timestamps (how regular the data is; how
    // late it was processed is the delivery delay).
    let prev = this.prevT;
    for (let i = 0; i < n; i++) {
      const ti = t[i]!;
      if (prev === prev) {
        const dt = ti - prev;
        this.dtN++;
        const d = dt - this.dtMean;
        this.dtMean += d / this.dtN;
        this.dtM2 += d * (dt - this.dtMean);
      }
      prev = ti;
    }
    this.prevT = prev;
  }

  /**
   * Records the delivery delay of a batch at clock time `now`: `now − oldest`, where `oldest` is
   * the timestamp of its oldest event.
   */
  delivered(oldest: number, now: number): void {
    const d = now - oldest;
    this.delay.add(d);
    if (d > this.delayMaxWindow) this.delayMaxWindow = d;
    if (d > this.lateAfter())
      this.lateUntil = Math.max(this.lateUntil, now + Math.max(d, LATE_HOLD_S));
  }

  /**
   * Records that the block processed an input batch at clock time `now`. A block without a
   * desired rate (it emits on request: a Buffer that records, a recorder) is not idle while it
   * consumes, even when it emits nothing.
   */
  consumed(now: number): void {
    this.lastInputWall = now;
  }

  /** Ticks the block's `CatchUp: skip` timer has skipped so far (see `missed`). */
  missedTicks = 0;

  /**
   * A timer that skipped ticks (`CatchUp: skip`) is behind like a late batch: given the timer's
   * count of skipped ticks so far at clock time `now`, the block reads lagging for as long as the
   * newly skipped ticks span, at least LATE_HOLD_S.
   */
  missed(total: number, now: number): void {
    const n = total - this.missedTicks;
    if (n <= 0) return;
    this.missedTicks = total;
    const r = this.desiredRate;
    this.lateUntil = Math.max(this.lateUntil, now + Math.max(r > 0 ? n / r : 0, LATE_HOLD_S));
  }

  /** The delivery delay above which a batch is late (the block reads as lagging), s. */
  lateAfter(): number {
    const r = this.desiredRate;
    return Math.max(r > 0 ? LATE_PERIODS / r : 0, LATE_MIN_S) + this.batchS;
  }

  /**
   * Records one measured `process` (or timer callback) call of `ms` milliseconds that handled
   * `events` events (a call may take as long as the time they span).
   */
  compute(ms: number, now: number, events = 1): void {
    this.calls++;
    this.callsWindow++;
    this.computeLast = ms;
    this.computeSumWindow += ms;
    this.computeTotal += ms;
    if (ms > this.computeMaxWindow) this.computeMaxWindow = ms;
    if (this.desiredRate > 0 && ms > (1000 * Math.max(1, events)) / this.desiredRate) {
      this.lastOverrunWall = now;
    }
  }

  /**
   * Records work done for the block elsewhere (a sidecar call, reported by the block): it shows in
   * the compute max and, beyond `budgetMs` (default one period), marks stumbling; it does not count
   * as a call nor toward the worker's CPU total.
   */
  external(ms: number, now: number, budgetMs?: number): void {
    this.computeLast = ms;
    if (ms > this.computeMaxWindow) this.computeMaxWindow = ms;
    const limit = budgetMs ?? (this.desiredRate > 0 ? 1000 / this.desiredRate : Infinity);
    if (ms > limit) this.lastOverrunWall = now;
  }

  /** Rate over the window, Hz (NaN with fewer than two outputs). */
  rate(): number {
    const n = this.inWindow;
    if (n < 2) return NaN;
    const last = this.ts[(this.idx - 1 + RATE_WINDOW) % RATE_WINDOW]!;
    const first = this.ts[(this.idx - n + RATE_WINDOW) % RATE_WINDOW]!;
    const span = last - first;
    if (!(span > 0)) return Infinity;
    return (n - 1) / span;
  }

  evaluate(now: number): StatusEval {
    const rate = this.rate();
    const d = this.desiredRate;
    const idleAfter = idleAfterS(d, this.batchS);
    const silent = this.events === 0 || now - this.lastWall > idleAfter;
    const consuming = !(d > 0) && now - this.lastInputWall <= idleAfter;
    if (silent) {
      return {
        status: consuming ? "ontime" : "idle",
        rate: this.events === 0 ? 0 : rate,
        lagging: false,
        stumbling: false,
      };
    }
    const n = this.inWindow;
    const windowStart = n > 0 ? this.wall[(this.idx - n + RATE_WINDOW) % RATE_WINDOW]! : now;
    const slow = d > 0 && rate === rate && rate < LAG_FRACTION * d;
    const lagging = slow || now < this.lateUntil;
    const stumbling = d > 0 && this.lastOverrunWall >= windowStart;
    const status: Status = lagging ? "lagging" : stumbling ? "stumbling" : "ontime";
    return { status, rate, lagging, stumbling };
  }

  /** Resets the per-telemetry window counters (compute max/mean, latency). */
  resetWindow(): void {
    this.computeMaxWindow = 0;
    this.computeSumWindow = 0;
    this.callsWindow = 0;
    this.latencySum = 0;
    this.latencyN = 0;
    this.delayMaxWindow = 0;
  }

  /** Resets the ΔT and delivery-delay statistics (e.g. after a bench warm-up). */
  resetTiming(): void {
    this.dtN = 0;
    this.dtMean = 0;
    this.dtM2 = 0;
    this.prevT = NaN;
    this.delay.reset();
    this.computeTotal = 0;
    this.calls = 0;
  }

  dtStd(): number {
    return this.dtN > 1 ? Math.sqrt(this.dtM2 / (this.dtN - 1)) : NaN;
  }
}
