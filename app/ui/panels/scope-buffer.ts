/**
 * The scope's sample store (no DOM): one ring per plotted channel plus one for the times, each
 * written twice (at i and i + capacity) so that the newest n samples are always one contiguous,
 * time-ordered range — the plot gets `subarray` views of it, and nothing big is allocated per
 * frame. Times are seconds since the first event (`t0`), which keeps the axis labels short.
 *
 * Matrices (e.g. windows [L, C] from a SlidingWindow): `newest` keeps the last row of each event
 * (its newest sample, at the event's time: right whatever the window overlap); `flatten` keeps all
 * rows in time order, spread evenly over the time since the previous event (exact for windows
 * that do not overlap, Step = Length, and that the engine did not decimate).
 */
export type MatrixMode = "newest" | "flatten";

export class ScopeBuffer {
  private cap: number;
  t: Float64Array;
  y: Float64Array[];
  private head = 0;
  count = 0;
  /** Absolute time of x = 0 (first event seen), UNIX seconds. */
  t0 = NaN;
  /** Absolute time of the newest event. */
  lastT = NaN;
  /** Seconds the plot shows: the rings grow (up to maxCapacity) to hold at least this much. */
  windowS: number;
  private readonly out: Float64Array[];

  constructor(
    readonly channels: readonly number[],
    capacity: number,
    windowS: number,
    readonly maxCapacity = 1 << 20,
  ) {
    this.cap = Math.max(16, Math.min(maxCapacity, Math.ceil(capacity)));
    this.windowS = windowS;
    this.t = new Float64Array(this.cap * 2);
    this.y = channels.map(() => new Float64Array(this.cap * 2));
    this.out = new Array<Float64Array>(channels.length + 1);
  }

  get capacity(): number {
    return this.cap;
  }

  clear(): void {
    this.head = 0;
    this.count = 0;
    this.t0 = NaN;
    this.lastT = NaN;
  }

  /** Appends the events of one data message (times `t`, values row-major `rows * cols` each). */
  append(
    t: Float64Array,
    v: Float64Array,
    rows: number,
    cols: number,
    mode: MatrixMode = "newest",
  ): void {
    const stride = rows * cols;
    if (stride === 0) return;
    for (let e = 0; e < t.length; e++) {
      const te = t[e]!;
      // A clock that went back (a new run) starts the plot again.
      if (Number.isFinite(this.lastT) && te < this.lastT - 1) this.clear();
      if (!Number.isFinite(this.t0)) this.t0 = te;
      const base = e * stride;
      if (rows === 1 || mode === "newest") {
        this.push(te - this.t0, v, base + (rows - 1) * cols);
      } else {
        const prev = this.lastT;
        const dt = Number.isFinite(prev) && te > prev ? (te - prev) / rows : 0;
        for (let r = 0; r < rows; r++)
          this.push(te - this.t0 - (rows - 1 - r) * dt, v, base + r * cols);
      }
      this.lastT = te;
    }
  }

  private push(x: number, v: Float64Array, rowOffset: number): void {
    if (this.count === this.cap && this.cap < this.maxCapacity) {
      // Full: grow when the rings hold less than the window (a faster stream than expected).
      const oldest = this.t[this.head]!;
      if (x - oldest < this.windowS * 1.1) this.grow();
    }
    const i = this.head;
    const j = i + this.cap;
    this.t[i] = x;
    this.t[j] = x;
    const ch = this.channels;
    for (let c = 0; c < ch.length; c++) {
      const val = v[rowOffset + ch[c]!]!;
      const y = this.y[c]!;
      y[i] = val;
      y[j] = val;
    }
    this.head = i + 1 === this.cap ? 0 : i + 1;
    if (this.count < this.cap) this.count++;
  }

  private grow(): void {
    const n = this.count;
    const start = this.startIndex();
    const cap = Math.min(this.maxCapacity, this.cap * 2);
    const t = new Float64Array(cap * 2);
    t.set(this.t.subarray(start, start + n));
    this.y = this.y.map((y) => {
      const ny = new Float64Array(cap * 2);
      ny.set(y.subarray(start, start + n));
      return ny;
    });
    this.t = t;
    this.cap = cap;
    this.head = n === cap ? 0 : n;
    // Mirror what was copied so the contiguous-view invariant holds.
    this.t.copyWithin(cap, 0, n);
    for (const y of this.y) y.copyWithin(cap, 0, n);
  }

  /** Index of the oldest sample in the doubled arrays. */
  private startIndex(): number {
    const s = this.head - this.count;
    return s < 0 ? s + this.cap : s;
  }

  /** Relative time of the newest sample (NaN when empty). */
  get newestX(): number {
    return Number.isFinite(this.lastT) ? this.lastT - this.t0 : NaN;
  }

  /**
   * The samples with x ≥ fromX (and x ≤ toX), as [times, channel 0, channel 1, …] views into the
   * rings: valid until the next append. The same outer array is returned every call.
   */
  view(fromX: number, toX = Infinity): Float64Array[] {
    const start = this.startIndex();
    let lo = start;
    let hi = start + this.count;
    const t = this.t;
    // First index with t ≥ fromX, last with t ≤ toX (times ascend within the rings).
    let a = lo;
    let b = hi;
    while (a < b) {
      const m = (a + b) >> 1;
      if (t[m]! < fromX) a = m + 1;
      else b = m;
    }
    // One sample before the window keeps the line going to the left edge.
    lo = a > start ? a - 1 : a;
    if (toX !== Infinity) {
      a = lo;
      b = hi;
      while (a < b) {
        const m = (a + b) >> 1;
        if (t[m]! <= toX) a = m + 1;
        else b = m;
      }
      hi = a < start + this.count ? a + 1 : a;
    }
    const out = this.out;
    out[0] = t.subarray(lo, hi);
    for (let c = 0; c < this.y.length; c++) out[c + 1] = this.y[c]!.subarray(lo, hi);
    return out;
  }
}
