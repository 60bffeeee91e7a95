/**
 * A single-producer single-consumer ring of events on a SharedArrayBuffer: the transport of
 * cross-worker edges and of `Path` logs (engine worker → log writer). Each event is stored as
 * `[t, v0 … v(stride-1)]`. Indices are event counters that wrap in 32 bits.
 *
 * Full ring: `write` either drops the events that do not fit and counts them (real time: never
 * block the hot path) or, with `block: true`, waits for the consumer (virtual clock: lose nothing).
 */
import type { Frame } from "../frame";

const W = 0; // events written
const R = 1; // events read
const DROPPED = 2;
const CLOSED = 3;
const HEADER_BYTES = 64;

export interface SabRingInit {
  sab: SharedArrayBuffer;
  capacity: number;
  stride: number;
}

export class SabRing {
  readonly ctrl: Int32Array;
  readonly data: Float64Array;
  readonly capacity: number;
  readonly stride: number;
  private readonly slot: number;

  constructor(init: SabRingInit) {
    this.capacity = init.capacity;
    this.stride = init.stride;
    this.slot = init.stride + 1;
    this.ctrl = new Int32Array(init.sab, 0, HEADER_BYTES / 4);
    this.data = new Float64Array(init.sab, HEADER_BYTES, init.capacity * this.slot);
  }

  /** Capacity is rounded up to a power of two (the 32-bit counters then wrap cleanly). */
  static allocate(capacity: number, stride: number): SabRingInit {
    let cap = 2;
    while (cap < capacity) cap *= 2;
    const sab = new SharedArrayBuffer(HEADER_BYTES + cap * (stride + 1) * 8);
    return { sab, capacity: cap, stride };
  }

  get init(): SabRingInit {
    return {
      sab: this.ctrl.buffer as SharedArrayBuffer,
      capacity: this.capacity,
      stride: this.stride,
    };
  }

  available(): number {
    return (Atomics.load(this.ctrl, W) - Atomics.load(this.ctrl, R)) | 0;
  }

  get dropped(): number {
    return Atomics.load(this.ctrl, DROPPED);
  }

  get closed(): boolean {
    return Atomics.load(this.ctrl, CLOSED) !== 0;
  }

  close(): void {
    Atomics.store(this.ctrl, CLOSED, 1);
    Atomics.notify(this.ctrl, R);
  }

  /**
   * Appends the frame's events. Returns how many were dropped (0 when `block` is set: the call
   * then waits, in slices of `waitMs`, until the consumer made room).
   */
  write(f: Frame, block = false, waitMs = 50): number {
    const n = f.n;
    const s = this.stride;
    const slot = this.slot;
    const cap = this.capacity;
    const data = this.data;
    let done = 0;
    let dropped = 0;
    while (done < n) {
      const w = Atomics.load(this.ctrl, W);
      const r = Atomics.load(this.ctrl, R);
      const free = cap - ((w - r) | 0);
      if (free <= 0) {
        if (!block || this.closed) {
          dropped = n - done;
          Atomics.add(this.ctrl, DROPPED, dropped);
          break;
        }
        Atomics.wait(this.ctrl, R, r, waitMs);
        continue;
      }
      const k = Math.min(free, n - done);
      for (let i = 0; i < k; i++) {
        const base = (((w + i) >>> 0) % cap) * slot;
        const e = done + i;
        data[base] = f.t[e]!;
        const src = e * s;
        for (let j = 0; j < s; j++) data[base + 1 + j] = f.v[src + j]!;
      }
      Atomics.store(this.ctrl, W, (w + k) | 0);
      done += k;
    }
    return dropped;
  }

  /**
   * Reads up to `max` events into `into` (from event 0; grows it when needed) and returns the
   * count; wakes a producer waiting for room.
   */
  read(into: Frame, max = Infinity): number {
    const w = Atomics.load(this.ctrl, W);
    const r = Atomics.load(this.ctrl, R);
    const n = Math.min((w - r) | 0, max);
    if (n <= 0) return 0;
    into.ensureCapacity(n);
    const s = this.stride;
    const slot = this.slot;
    const cap = this.capacity;
    const data = this.data;
    for (let i = 0; i < n; i++) {
      const base = (((r + i) >>> 0) % cap) * slot;
      into.t[i] = data[base]!;
      const dst = i * s;
      for (let j = 0; j < s; j++) into.v[dst + j] = data[base + 1 + j]!;
    }
    into.n = n;
    Atomics.store(this.ctrl, R, (r + n) | 0);
    Atomics.notify(this.ctrl, R);
    return n;
  }
}
