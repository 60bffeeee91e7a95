/**
 * The Python block's bookkeeping, apart from its behaviour: inputs waiting for a call, the calls
 * in flight (results come back in order), and the recent call times with their percentiles.
 */

/** Call times kept for the status's percentiles. */
const TIMES = 256;

/** Events (timestamp + values) waiting, oldest first: a ring that grows when full. */
export class EventQueue {
  private t: Float64Array;
  private v: Float64Array;
  private head = 0;
  n = 0;

  constructor(
    private readonly size: number,
    private cap = 4,
  ) {
    this.t = new Float64Array(cap);
    this.v = new Float64Array(cap * size);
  }

  push(values: Float64Array, t: number): void {
    if (this.n === this.cap) this.grow();
    this.put((this.head + this.n) % this.cap, values, t);
    this.n++;
  }

  /** Replaces the newest event (there must be one). */
  replaceNewest(values: Float64Array, t: number): void {
    this.put((this.head + this.n - 1) % this.cap, values, t);
  }

  get oldestT(): number {
    return this.t[this.head]!;
  }

  get oldest(): Float64Array {
    return this.v.subarray(this.head * this.size, (this.head + 1) * this.size);
  }

  shift(): void {
    this.head = (this.head + 1) % this.cap;
    this.n--;
  }

  clear(): void {
    this.head = 0;
    this.n = 0;
  }

  private put(k: number, values: Float64Array, t: number): void {
    this.t[k] = t;
    this.v.set(values, k * this.size);
  }

  private grow(): void {
    const cap = this.cap * 2;
    const t = new Float64Array(cap);
    const v = new Float64Array(cap * this.size);
    for (let i = 0; i < this.n; i++) {
      const k = (this.head + i) % this.cap;
      t[i] = this.t[k]!;
      v.set(this.v.subarray(k * this.size, (k + 1) * this.size), i * this.size);
    }
    this.t = t;
    this.v = v;
    this.cap = cap;
    this.head = 0;
  }
}

/** A call taken off the queue: its input's timestamp, its round trip (ms), counted late already. */
export interface TakenCall {
  t: number;
  tookMs: number;
  countedLate: boolean;
}

/**
 * Calls sent and not answered yet, oldest first: input timestamps, send times, and whether the
 * call was already counted as over budget while it ran.
 */
export class InFlightCalls {
  private readonly sentT: Float64Array;
  private readonly sentAt: Float64Array;
  private readonly counted: Uint8Array;
  private head = 0;
  count = 0;

  constructor(readonly cap: number) {
    this.sentT = new Float64Array(cap);
    this.sentAt = new Float64Array(cap);
    this.counted = new Uint8Array(cap);
  }

  get full(): boolean {
    return this.count >= this.cap;
  }

  /** A call for the input at `t` goes out now. */
  add(t: number): void {
    const k = (this.head + this.count) % this.cap;
    this.sentT[k] = t;
    this.sentAt[k] = performance.now();
    this.counted[k] = 0;
    this.count++;
  }

  /** The call just added did not go out after all. */
  dropNewest(): void {
    this.count--;
  }

  /** The oldest call, answered (or lost) now. */
  take(): TakenCall | undefined {
    if (this.count === 0) return undefined;
    const h = this.head;
    const taken = {
      t: this.sentT[h]!,
      tookMs: performance.now() - this.sentAt[h]!,
      countedLate: this.counted[h] === 1,
    };
    this.head = (h + 1) % this.cap;
    this.count--;
    return taken;
  }

  /** Marks the oldest call counted as over budget; false when it was already (or none runs). */
  markOldestLate(): boolean {
    if (this.count === 0 || this.counted[this.head] === 1) return false;
    this.counted[this.head] = 1;
    return true;
  }

  clear(): void {
    this.count = 0;
    this.head = 0;
  }
}

/** p50 and p99 of the first `n` values of `ring` (a copy is sorted). */
export function percentiles(
  ring: Float64Array,
  n: number,
  scratch: Float64Array,
): [number, number] {
  if (n === 0) return [NaN, NaN];
  const s = scratch.subarray(0, n);
  s.set(ring.subarray(0, n));
  s.sort();
  const at = (q: number): number => s[Math.min(n - 1, Math.ceil(q * n) - 1)]!;
  return [at(0.5), at(0.99)];
}

/** A duration in ms as the status shows it ("–" for none). */
export const ms = (x: number): string =>
  !(x === x)
    ? "–"
    : x < 1
      ? `${x.toFixed(2)} ms`
      : x < 100
        ? `${x.toFixed(1)} ms`
        : `${Math.round(x)} ms`;

/** A duration of a call still running: ms below 10 s, then s. */
export const running = (x: number): string => (x < 10_000 ? ms(x) : `${(x / 1000).toFixed(1)} s`);

/** The round trips and Python's own times of the last TIMES calls. */
export class CallTimes {
  private readonly rtt = new Float64Array(TIMES);
  private readonly py = new Float64Array(TIMES);
  private readonly scratch = new Float64Array(TIMES);
  private at = 0;
  n = 0;

  add(rttMs: number, pythonMs: number): void {
    this.rtt[this.at] = rttMs;
    this.py[this.at] = pythonMs;
    this.at = (this.at + 1) % TIMES;
    if (this.n < TIMES) this.n++;
  }

  /** "p50 … p99 … (Python …)": round-trip percentiles and Python's median. */
  summary(): string {
    const [p50, p99] = percentiles(this.rtt, this.n, this.scratch);
    const [py50] = percentiles(this.py, this.n, this.scratch);
    return `p50 ${ms(p50)} p99 ${ms(p99)} (Python ${ms(py50)})`;
  }
}
