/**
 * The scheduler behind ScheduledTimer and every `ctx.every` / `ctx.at` (paper III-D): each entry
 * fires at base + k / rate. Ticks are never fired late in a burst to catch up: when the worker
 * wakes after one or more deadlines passed, it fires once and counts the skipped ticks as missed.
 * Lateness (fire time − deadline) is recorded per periodic entry in a 1 µs histogram.
 */

const HIST_MIN_US = -1000;
/** A callback that keeps re-arming itself in the past cannot hang the worker: the loop yields. */
const MAX_FIRES_PER_CALL = 100_000;
const HIST_MAX_US = 20000;

export class LatenessHistogram {
  readonly bins = new Uint32Array(HIST_MAX_US - HIST_MIN_US + 1);
  count = 0;
  overflow = 0;
  maxUs = -Infinity;
  sumUs = 0;

  add(us: number): void {
    const b = Math.round(us) - HIST_MIN_US;
    if (b < 0) this.bins[0]!++;
    else if (b >= this.bins.length) {
      this.overflow++;
      this.bins[this.bins.length - 1]!++;
    } else this.bins[b]!++;
    this.count++;
    this.sumUs += us;
    if (us > this.maxUs) this.maxUs = us;
  }

  /** Quantile in µs (q in [0, 1]). */
  quantile(q: number): number {
    if (this.count === 0) return NaN;
    const target = Math.ceil(q * this.count);
    let acc = 0;
    for (let i = 0; i < this.bins.length; i++) {
      acc += this.bins[i]!;
      if (acc >= target) return i + HIST_MIN_US;
    }
    return HIST_MAX_US;
  }

  reset(): void {
    this.bins.fill(0);
    this.count = 0;
    this.overflow = 0;
    this.maxUs = -Infinity;
    this.sumUs = 0;
  }
}

export interface TimerEntry {
  readonly id: number;
  readonly owner: string;
  /** Seconds; 0 for a one-shot. */
  period: number;
  base: number;
  k: number;
  next: number;
  running: boolean;
  fired: number;
  missed: number;
  readonly lateness: LatenessHistogram | null;
  cb: (t: number) => void;
}

export class Scheduler {
  readonly entries: TimerEntry[] = [];
  private nextId = 0;
  /** Fire entries whose deadline is at most this far in the future (the host wakes slightly early). */
  earlyTolerance = 0;

  constructor(private readonly virtual: boolean) {}

  add(owner: string, periodSec: number, cb: (t: number) => void): TimerEntry {
    const e: TimerEntry = {
      id: this.nextId++,
      owner,
      period: periodSec,
      base: 0,
      k: 0,
      next: Infinity,
      running: false,
      fired: 0,
      missed: 0,
      lateness: periodSec > 0 && !this.virtual ? new LatenessHistogram() : null,
      cb,
    };
    this.entries.push(e);
    return e;
  }

  start(e: TimerEntry, now: number): void {
    e.base = now;
    e.k = 0;
    e.next = now;
    e.running = true;
  }

  stop(e: TimerEntry): void {
    e.running = false;
    e.next = Infinity;
  }

  /** Schedules a one-shot entry at absolute time t. */
  once(e: TimerEntry, t: number): void {
    e.period = 0;
    e.next = t;
    e.running = true;
  }

  nextDeadline(): number {
    let m = Infinity;
    const es = this.entries;
    for (let i = 0; i < es.length; i++) {
      const e = es[i]!;
      if (e.running && e.next < m) m = e.next;
    }
    return m;
  }

  /**
   * Fires every entry due at `now`, in deadline order (ties: creation order), through `fire`.
   * Returns how many fired.
   */
  fireDue(now: number, fire: (e: TimerEntry, t: number) => void): number {
    let count = 0;
    const limit = now + this.earlyTolerance;
    for (;;) {
      let due: TimerEntry | undefined;
      const es = this.entries;
      for (let i = 0; i < es.length; i++) {
        const e = es[i]!;
        if (e.running && e.next <= limit && (due === undefined || e.next < due.next)) due = e;
      }
      if (due === undefined) return count;
      const deadline = due.next;
      if (due.period > 0) {
        if (this.virtual) {
          due.k++;
        } else {
          // Skip, and count, the older ticks whose deadlines have all passed: fire once, for the
          // most recent deadline, and measure lateness against that one.
          const behind = Math.floor((now - deadline) / due.period);
          if (behind > 0) {
            due.missed += behind;
            due.k += behind;
          }
          due.lateness?.add((now - (due.base + due.k * due.period)) * 1e6);
          due.k++;
        }
        due.next = due.base + due.k * due.period;
      } else {
        due.running = false;
        due.next = Infinity;
      }
      due.fired++;
      count++;
      // Woken slightly early (within earlyTolerance), an entry is still stamped no earlier than
      // its deadline: a callback that re-arms itself "at the next due time" then moves on.
      fire(due, this.virtual ? deadline : Math.max(now, deadline));
      if (count >= MAX_FIRES_PER_CALL) return count;
    }
  }
}
