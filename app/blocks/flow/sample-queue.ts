/**
 * A FIFO of signal events (timestamp + values) that a sample-and-hold consumes up to a tick's
 * time: `consumeUntil(t)` folds every queued event stamped at or before `t` into the held value
 * (and into a running sum, for means). Growing buffers, no allocation in steady state; beyond
 * `maxEvents` the oldest events are folded in early so memory stays bounded when ticks stop.
 */
export class SampleQueue {
  private t: Float64Array;
  private v: Float64Array;
  private head = 0;
  private count = 0;
  /** The value of the last event consumed. */
  readonly held: Float64Array;
  /** Sum of the values consumed since `takeMean` was last called, and how many. */
  readonly sum: Float64Array;
  summed = 0;
  /** True once an event has been consumed (a value is held). */
  holding = false;

  constructor(
    private readonly size: number,
    private readonly maxEvents = 1 << 16,
  ) {
    this.t = new Float64Array(64);
    this.v = new Float64Array(64 * size);
    this.held = new Float64Array(size);
    this.sum = new Float64Array(size);
  }

  get length(): number {
    return this.count;
  }

  /** Timestamp of the newest queued event (NaN when empty). */
  get newest(): number {
    return this.count > 0 ? this.t[(this.head + this.count - 1) % this.t.length]! : NaN;
  }

  /** Appends events `[0, n)` of a frame's arrays. */
  push(times: Float64Array, values: Float64Array, n: number): void {
    const size = this.size;
    for (let e = 0; e < n; e++) {
      if (this.count === this.t.length) {
        if (this.t.length >= this.maxEvents) this.consumeOne();
        else this.grow();
      }
      const slot = (this.head + this.count) % this.t.length;
      this.t[slot] = times[e]!;
      const dst = slot * size;
      const src = e * size;
      for (let k = 0; k < size; k++) this.v[dst + k] = values[src + k]!;
      this.count++;
    }
  }

  /** Consumes every queued event stamped at or before `t`. */
  consumeUntil(t: number): void {
    while (this.count > 0 && this.t[this.head]! <= t) this.consumeOne();
  }

  /** Writes the mean of the values consumed since the last call (the held value when none) to `out` at `offset`, and restarts the sum. */
  takeMean(out: Float64Array, offset: number): void {
    const size = this.size;
    if (this.summed > 0) {
      for (let k = 0; k < size; k++) {
        out[offset + k] = this.sum[k]! / this.summed;
        this.sum[k] = 0;
      }
      this.summed = 0;
    } else {
      for (let k = 0; k < size; k++) out[offset + k] = this.held[k]!;
    }
  }

  clear(): void {
    this.head = 0;
    this.count = 0;
    this.held.fill(0);
    this.sum.fill(0);
    this.summed = 0;
    this.holding = false;
  }

  private consumeOne(): void {
    const size = this.size;
    const src = this.head * size;
    for (let k = 0; k < size; k++) {
      const x = this.v[src + k]!;
      this.held[k] = x;
      this.sum[k] += x;
    }
    this.summed++;
    this.holding = true;
    this.head = (this.head + 1) % this.t.length;
    this.count--;
  }

  private grow(): void {
    const cap = this.t.length * 2;
    const size = this.size;
    const t = new Float64Array(cap);
    const v = new Float64Array(cap * size);
    for (let i = 0; i < this.count; i++) {
      const s = (this.head + i) % this.t.length;
      t[i] = this.t[s]!;
      v.set(this.v.subarray(s * size, (s + 1) * size), i * size);
    }
    this.t = t;
    this.v = v;
    this.head = 0;
  }
}
