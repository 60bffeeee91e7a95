/**
 * Frames: what travels on an edge (DESIGN.md §3).
 *
 * A frame is a batch of `n` events. Every event has a timestamp (UNIX seconds, f64) and a value of
 * a fixed shape `[rows, cols]` stored row-major. Values of event `i` occupy
 * `v[i * stride, (i + 1) * stride)` with `stride = rows * cols`. Buffers may be longer than needed
 * (capacity); only the first `n` events are meaningful.
 *
 * A frame handed to `process` is borrowed: read it during the call, never keep a reference to it
 * (copy what you need). Frames are pooled and reused, which is how the hot path avoids allocation.
 */

export interface Shape {
  readonly rows: number;
  readonly cols: number;
}

export const vectorShape = (channels: number): Shape => ({ rows: 1, cols: channels });
export const matrixShape = (rows: number, cols: number): Shape => ({ rows, cols });
/** Timers emit events without values. */
export const EMPTY_SHAPE: Shape = { rows: 1, cols: 0 };

export const shapeSize = (s: Shape): number => s.rows * s.cols;
export const sameShape = (a: Shape, b: Shape): boolean => a.rows === b.rows && a.cols === b.cols;
export const formatShape = (s: Shape): string => `[${s.rows}, ${s.cols}]`;

export class Frame {
  /** Number of valid events. */
  n = 0;
  /** Timestamps, UNIX seconds; length is the capacity. */
  t: Float64Array;
  /** Values, row-major per event; length is capacity * stride. */
  v: Float64Array;
  readonly rows: number;
  readonly cols: number;
  readonly stride: number;
  /** @internal pending deliveries still reading this frame. */
  refs = 0;
  /** @internal the pool this frame returns to. */
  pool: FramePool | null = null;

  constructor(shape: Shape, capacity: number) {
    this.rows = shape.rows;
    this.cols = shape.cols;
    this.stride = shape.rows * shape.cols;
    const cap = Math.max(1, capacity | 0);
    this.t = new Float64Array(cap);
    this.v = new Float64Array(cap * this.stride);
  }

  get capacity(): number {
    return this.t.length;
  }

  get shape(): Shape {
    return { rows: this.rows, cols: this.cols };
  }

  /** Grows the buffers (allocates; only when a larger batch than ever before arrives). */
  ensureCapacity(events: number): void {
    if (events <= this.t.length) return;
    let cap = this.t.length;
    while (cap < events) cap *= 2;
    const t = new Float64Array(cap);
    t.set(this.t);
    const v = new Float64Array(cap * this.stride);
    v.set(this.v);
    this.t = t;
    this.v = v;
  }

  /** Value `c` (column-major index within the event for vectors) of event `i`. */
  get(i: number, k: number): number {
    return this.v[i * this.stride + k]!;
  }

  /** Copies events `[from, from + count)` of `src` into this frame starting at event `at`. */
  copyEvents(src: Frame, from: number, count: number, at: number): void {
    const s = this.stride;
    const t = this.t;
    const st = src.t;
    for (let i = 0; i < count; i++) t[at + i] = st[from + i]!;
    const v = this.v;
    const sv = src.v;
    const a = at * s;
    const b = from * s;
    const m = count * s;
    for (let k = 0; k < m; k++) v[a + k] = sv[b + k]!;
  }

  /** A fresh standalone copy (allocates; for tests and tools, not for the hot path). */
  clone(): Frame {
    const f = new Frame(this.shape, Math.max(1, this.n));
    f.copyEvents(this, 0, this.n, 0);
    f.n = this.n;
    return f;
  }

  /** Event values as plain arrays (allocates; for tests, panels and tools). */
  toArrays(): { t: number[]; v: number[][] } {
    const t: number[] = [];
    const v: number[][] = [];
    for (let i = 0; i < this.n; i++) {
      t.push(this.t[i]!);
      v.push(Array.from(this.v.subarray(i * this.stride, (i + 1) * this.stride)));
    }
    return { t, v };
  }

  /** Builds a frame from plain arrays (allocates; for tests and tools). */
  static from(shape: Shape, t: readonly number[], values: readonly (readonly number[])[]): Frame {
    const f = new Frame(shape, Math.max(1, t.length));
    const s = f.stride;
    for (let i = 0; i < t.length; i++) {
      f.t[i] = t[i]!;
      const row = values[i] ?? [];
      if (row.length !== s) {
        throw new Error(
          `event ${i} has ${row.length} values; shape ${formatShape(shape)} needs ${s}`,
        );
      }
      for (let k = 0; k < s; k++) f.v[i * s + k] = row[k]!;
    }
    f.n = t.length;
    return f;
  }
}

/**
 * A pool of frames of one shape. `take(n)` returns a frame with room for `n` events; frames come
 * back through `release` once every delivery has read them. In steady state nothing is allocated.
 */
export class FramePool {
  private readonly free: Frame[] = [];
  allocated = 0;

  constructor(
    readonly shape: Shape,
    private readonly defaultCapacity = 16,
  ) {}

  take(n: number): Frame {
    const f = this.free.pop();
    if (f !== undefined) {
      f.ensureCapacity(n);
      f.n = n;
      f.refs = 0;
      return f;
    }
    this.allocated++;
    const nf = new Frame(this.shape, Math.max(n, this.defaultCapacity));
    nf.pool = this;
    nf.n = n;
    return nf;
  }

  release(f: Frame): void {
    this.free.push(f);
  }
}
