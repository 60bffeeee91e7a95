/**
 * The scheduler behind ScheduledTimer and every `ctx.every` / `ctx.at` (paper III-D, DESIGN.md §3
 * Scheduling): tick k of a periodic entry is due at base + k / rate.
 *
 * Lossless: when the worker wakes, every tick whose deadline has passed since the entry last fired
 * goes out in ONE call with n ticks, each stamped with its own deadline — no burst of calls, no
 * hole in the data. An entry whose stale ticks are worthless (`catchUp: "skip"`, e.g. a 25 Hz
 * control timer after a long stall) fires only the newest and counts the others as missed.
 *
 * Batching: a worker need not wake for every deadline. An entry with a batching interval B lets
 * its ticks wait up to B so that they go out together: it asks to be woken at the deadline of the
 * last tick that falls within B of its oldest pending one (`wakeTime`). A wake-up then fires every
 * entry that has a tick due, whatever its own wake time. B = 0 wakes for every tick.
 *
 * Lateness (wake-up time − the newest deadline fired) is recorded per periodic entry in a 1 µs
 * histogram; how long the oldest tick waited is the delivery delay, measured by the runtime.
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

/** How stale ticks are handled after a stall: all of them go out (default), or only the newest. */
export type CatchUp = "all" | "skip";

/** Receives `n` ticks: their deadlines are `times[0] … times[n − 1]` (read them during the call). */
export type TickCallback = (times: Float64Array, n: number) => void;

export interface TimerEntry {
  readonly id: number;
  readonly owner: string;
  /** Seconds; 0 for a one-shot. */
  period: number;
  /** Ticks per second (1 / period; deadlines are base + k / rate, exact for whole rates). */
  rate: number;
  base: number;
  /** Index of the next tick. */
  k: number;
  /** Deadline of the next tick (Infinity when not running). */
  next: number;
  running: boolean;
  /** Ticks delivered. */
  fired: number;
  /** Ticks skipped (`catchUp: "skip"` only). */
  missed: number;
  catchUp: CatchUp;
  /** Batching interval, s (see the module comment). */
  batchS: number;
  readonly lateness: LatenessHistogram | null;
  /** Deadlines of the ticks being fired (scratch, grows with the largest batch). */
  times: Float64Array;
  /** Periodic entries. */
  onTicks: TickCallback;
  /** One-shot entries. */
  cb: (t: number) => void;
  /**
   * One-shots: when the worker must wake for it at the latest (≥ next). Between `next` and this,
   * it runs when the worker is awake anyway, as a batched timer's ticks do.
   */
  wakeAt: number;
}

/** Largest batch of one call (after a very long stall the rest follows in further calls). */
const MAX_BATCH = 65536;
const noTicks: TickCallback = () => {};
const noShot = (): void => {};

export class Scheduler {
  readonly entries: TimerEntry[] = [];
  private nextId = 0;
  /** Fire entries whose deadline is at most this far in the future (the host wakes slightly early). */
  earlyTolerance = 0;

  constructor(private readonly virtual: boolean) {}

  /** A periodic entry of `hz` ticks per second, stopped until `start`. */
  addPeriodic(
    owner: string,
    hz: number,
    onTicks: TickCallback,
    options: { catchUp?: CatchUp; batchS?: number } = {},
  ): TimerEntry {
    return this.push(owner, hz, onTicks, noShot, options);
  }

  /** A one-shot entry, armed by `once`. */
  addOneShot(owner: string, cb: (t: number) => void): TimerEntry {
    return this.push(owner, 0, noTicks, cb, {});
  }

  /** Changes a periodic entry's rate (it restarts from `now` when running). */
  setRate(e: TimerEntry, hz: number, now: number): void {
    e.rate = hz;
    e.period = 1 / hz;
    if (e.running) this.start(e, now);
  }

  private push(
    owner: string,
    hz: number,
    onTicks: TickCallback,
    cb: (t: number) => void,
    options: { catchUp?: CatchUp; batchS?: number },
  ): TimerEntry {
    const period = hz > 0 ? 1 / hz : 0;
    const e: TimerEntry = {
      id: this.nextId++,
      owner,
      period,
      rate: hz,
      base: 0,
      k: 0,
      next: Infinity,
      running: false,
      fired: 0,
      missed: 0,
      catchUp: options.catchUp ?? "all",
      batchS: Math.max(0, options.batchS ?? 0),
      lateness: period > 0 && !this.virtual ? new LatenessHistogram() : null,
      times: new Float64Array(period > 0 ? 8 : 1),
      onTicks,
      cb,
      wakeAt: Infinity,
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
  once(e: TimerEntry, t: number, latest = t): void {
    e.period = 0;
    e.next = t;
    e.wakeAt = Math.max(t, latest);
    e.running = true;
  }

  /** The earliest deadline of any running entry. */
  nextDeadline(): number {
    let m = Infinity;
    const es = this.entries;
    for (let i = 0; i < es.length; i++) {
      const e = es[i]!;
      if (e.running && e.next < m) m = e.next;
    }
    return m;
  }

  /** When the worker should wake next: the earliest wake time of any running entry. */
  nextWake(): number {
    let m = Infinity;
    const es = this.entries;
    for (let i = 0; i < es.length; i++) {
      const e = es[i]!;
      if (!e.running) continue;
      const w = wakeTime(e);
      if (w < m) m = w;
    }
    return m;
  }

  /**
   * Fires every entry with a tick due at `now`, in deadline order (ties: creation order), through
   * `fire(entry, n)`: the ticks' deadlines are in `entry.times[0 … n)`. Returns how many calls.
   */
  fireDue(now: number, fire: (e: TimerEntry, n: number) => void): number {
    let calls = 0;
    const limit = now + this.earlyTolerance;
    for (;;) {
      const due = this.earliestDue(limit);
      if (due === undefined) return calls;
      const n = due.period > 0 ? this.takeTicks(due, now, limit) : this.takeShot(due, now);
      due.fired += n;
      calls++;
      fire(due, n);
      // A callback that keeps re-arming itself in the past cannot hang the worker: the loop yields.
      if (calls >= MAX_FIRES_PER_CALL) return calls;
    }
  }

  private earliestDue(limit: number): TimerEntry | undefined {
    let due: TimerEntry | undefined;
    const es = this.entries;
    for (let i = 0; i < es.length; i++) {
      const e = es[i]!;
      if (e.running && e.next <= limit && (due === undefined || e.next < due.next)) due = e;
    }
    return due;
  }

  /** Moves the due ticks of a periodic entry into `e.times`; returns how many. */
  private takeTicks(e: TimerEntry, now: number, limit: number): number {
    let n = Math.min(MAX_BATCH, dueCount(e, limit));
    if (e.catchUp === "skip" && n > 1) {
      e.missed += n - 1;
      e.k += n - 1;
      n = 1;
    }
    if (e.times.length < n) e.times = new Float64Array(Math.max(n, e.times.length * 2));
    const times = e.times;
    for (let i = 0; i < n; i++) times[i] = e.base + (e.k + i) / e.rate;
    e.k += n;
    e.next = e.base + e.k / e.rate;
    e.lateness?.add((now - times[n - 1]!) * 1e6);
    return n;
  }

  private takeShot(e: TimerEntry, now: number): number {
    // Stamped with its deadline, or with the time it really ran when the worker woke late (a
    // callback that re-arms itself "at the next due time" then moves on).
    e.times[0] = this.virtual ? e.next : Math.max(now, e.next);
    e.running = false;
    e.next = Infinity;
    return 1;
  }
}

/** How many ticks of `e`, from its next one, are due at `limit` (at least 1 when `e.next <= limit`). */
function dueCount(e: TimerEntry, limit: number): number {
  let last = Math.floor((limit - e.base) * e.rate);
  // Floating point: make sure base + last / rate really is <= limit, and at least the next tick.
  while (last > e.k && e.base + last / e.rate > limit) last--;
  return Math.max(1, last - e.k + 1);
}

/** The time at which `e` wants the worker awake (see the module comment on batching). */
export function wakeTime(e: TimerEntry): number {
  if (e.period <= 0) return e.running ? e.wakeAt : e.next;
  if (e.catchUp === "skip" || e.batchS <= 0) return e.next;
  const extra = Math.floor(e.batchS * e.rate + 1e-9);
  return extra > 0 ? e.base + (e.k + extra) / e.rate : e.next;
}
