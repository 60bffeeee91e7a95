/** A FIFO of tick timestamps (ticks that wait for their signal), growing, no allocation in steady state. */
export class TickQueue {
  private t = new Float64Array(16);
  private head = 0;
  private count = 0;

  get length(): number {
    return this.count;
  }

  push(times: Float64Array, n: number): void {
    for (let i = 0; i < n; i++) {
      if (this.count === this.t.length) this.grow();
      this.t[(this.head + this.count) % this.t.length] = times[i]!;
      this.count++;
    }
  }

  /** How many queued ticks, from the oldest, are stamped at or before `until`. */
  countUntil(until: number): number {
    let m = 0;
    while (m < this.count && this.t[(this.head + m) % this.t.length]! <= until) m++;
    return m;
  }

  /** Removes and returns the oldest tick (call only when `length` > 0). */
  shift(): number {
    const t = this.t[this.head]!;
    this.head = (this.head + 1) % this.t.length;
    this.count--;
    return t;
  }

  clear(): void {
    this.head = 0;
    this.count = 0;
  }

  private grow(): void {
    const t = new Float64Array(this.t.length * 2);
    for (let i = 0; i < this.count; i++) t[i] = this.t[(this.head + i) % this.t.length]!;
    this.t = t;
    this.head = 0;
  }
}
