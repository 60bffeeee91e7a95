/**
 * The wasm memory as the kernel wrappers see it (shared by `index.ts` and `learn.ts`): a cached
 * `Float64Array` view of the whole memory, scratch buffers inside it, and the checks and errors
 * every wrapper uses. Internal to `app/engine/dsp/`.
 */

export interface WasmMemoryLike {
  readonly buffer: ArrayBuffer;
}

let memory: WasmMemoryLike | null = null;
/** View of the whole wasm memory; re-created when the memory grows. */
let heap = new Float64Array(0);

/** The heap view, re-created if the memory grew since it was made. */
export function f64(): Float64Array {
  if (heap.byteLength === 0) heap = new Float64Array((memory as WasmMemoryLike).buffer);
  return heap;
}

/** Events a new kernel's scratch buffers hold before the first call that needs more. */
export const INITIAL_CAPACITY = 64;

/** Records the module's memory (called once by `initDsp`). */
export function setMemory(m: WasmMemoryLike): void {
  memory = m;
  heap = new Float64Array(m.buffer);
}

/** `true` once the module's memory is known. */
export function memoryReady(): boolean {
  return memory !== null;
}

export function requireReady(what: string): void {
  if (memory === null) {
    throw new Error(`${what} needs the DSP module: call initDsp(wasmBytes) first`);
  }
}

export function errorMessage(e: unknown): string {
  return e instanceof Error ? e.message : String(e);
}

/** Rust constructor errors arrive as JS `Error`s carrying the Rust message; keep them. */
export function asError(e: unknown): Error {
  return e instanceof Error ? e : new Error(String(e));
}

export function checkChannels(what: string, channels: number): void {
  if (!Number.isInteger(channels) || channels < 1 || channels > 0xffff) {
    throw new Error(`${what}: channels must be an integer from 1 to 65535; got ${channels}`);
  }
}

/**
 * Validates a call's event count and array lengths; `b` may be `a` or omitted (`null`). Nothing
 * is allocated unless it throws.
 */
export function checkCall(
  what: string,
  nEvents: number,
  channels: number,
  a: ArrayLike<number>,
  b: ArrayLike<number> | null,
): void {
  const n = nEvents * channels;
  if (!(
    nEvents >= 0 &&
    Number.isInteger(nEvents) &&
    a.length >= n &&
    (b === null || b.length >= n)
  )) {
    if (!Number.isInteger(nEvents) || nEvents < 0) {
      throw new Error(`${what}: nEvents must be a non-negative integer; got ${nEvents}`);
    }
    const [name, len] =
      a.length < n
        ? [b === null ? "output" : "input", a.length]
        : ["output", (b as ArrayLike<number>).length];
    throw new Error(
      `${what}: ${name} has ${len} values but ${nEvents} events × ${channels} channels need ${n}`,
    );
  }
}

export function failed(what: string): Error {
  return new Error(`${what}: the wasm kernel refused the call (capacity out of step)`);
}

/** Up to this many values a plain loop is the fastest copy; above, `TypedArray.set`. */
const LOOP_MAX = 8;
/** Views cached per scratch buffer (one per distinct batch size seen). */
const VIEW_CACHE_MAX = 32;

/**
 * Prefix views `src.subarray(0, n)` of callers' arrays that are much longer than the batch
 * (pooled frames have a capacity), cached per array and per `n`: a stream of batches of recurring
 * sizes through the same frames copies with `set` and never allocates. Weak, so frames are not
 * kept alive by the cache.
 */
const prefixes = new WeakMap<Float64Array, Map<number, Float64Array>>();
/** Below this many values a loop costs less than the two cache look-ups of `prefix`. */
const PREFIX_MIN = 64;

function prefix(src: Float64Array, n: number): Float64Array {
  let byN = prefixes.get(src);
  if (byN === undefined) {
    byN = new Map();
    prefixes.set(src, byN);
  }
  let v = byN.get(n);
  if (v === undefined || v.length !== n) {
    if (byN.size >= VIEW_CACHE_MAX) byN.clear();
    v = src.subarray(0, n);
    byN.set(n, v);
  }
  return v;
}

/**
 * One scratch buffer inside the wasm memory (a kernel's input, output or operand buffer).
 *
 * Copies use `TypedArray.set` (several times faster than an element loop, even for 32 values),
 * into the heap directly (from a cached prefix view when the source is much longer than the
 * batch) and out of the heap through a view of exactly `n` values. Those views are cached per
 * `n` and dropped when the buffer moves or the memory grows, so a stream of batches of recurring
 * sizes never allocates.
 */
export class Scratch {
  /** Index (in f64 units) of the buffer in the heap. */
  private at = 0;
  /** Length of the buffer, in values. */
  private len = 0;
  private readonly views = new Map<number, Float64Array>();
  /** The last view used (the common case: the same batch size as last time). */
  private last: Float64Array = new Float64Array(0);

  place(bytePtr: number, len: number): void {
    this.at = bytePtr >>> 3;
    this.len = len;
    this.views.clear();
    this.last = new Float64Array(0);
  }

  /** Copies `src[0..n)` into the buffer. */
  write(src: ArrayLike<number>, n: number): void {
    const h = f64();
    const at = this.at;
    if (n > LOOP_MAX && src instanceof Float64Array) {
      const m = src.length;
      // Copying some values past n is harmless when the buffer has room, and far cheaper
      // than a loop as long as it is not much more than n.
      if (m === n || (m <= this.len && m <= 2 * n)) {
        h.set(src, at);
        return;
      }
      if (n >= PREFIX_MIN) {
        h.set(prefix(src, n), at);
        return;
      }
    }
    for (let i = 0; i < n; i++) h[at + i] = src[i] as number;
  }

  /** Value `i` of the buffer. */
  get(i: number): number {
    return f64()[this.at + i] as number;
  }

  /** Copies the first `n` values of the buffer into `dst[0..n)`. */
  read(dst: Float64Array, n: number): void {
    if (n > LOOP_MAX) {
      let v = this.last;
      if (v.length !== n || v.byteLength === 0) {
        v = this.views.get(n) ?? v;
        if (v.length !== n || v.byteLength === 0) {
          if (this.views.size >= VIEW_CACHE_MAX) this.views.clear();
          v = new Float64Array(f64().buffer, this.at * 8, n);
          this.views.set(n, v);
        }
        this.last = v;
      }
      dst.set(v);
      return;
    }
    const h = f64();
    const at = this.at;
    for (let i = 0; i < n; i++) dst[i] = h[at + i] as number;
  }
}

/** Views `HeapBlocks` keeps (one per address seen; a ring of R rows has R window addresses). */
const HEAP_BLOCKS_MAX = 4096;

/**
 * Copies blocks of `size` values that lie anywhere in the wasm memory (windows where they lie in
 * a ring, at a different address each time) into callers' arrays with `TypedArray.set`, through
 * views cached per address: nothing is allocated once every address has been seen. A view is
 * only an address and a length, so it stays right whatever lies there; the cache is dropped when
 * the memory grows (the old buffer is detached).
 */
export class HeapBlocks {
  private readonly views = new Map<number, Float64Array>();
  private buffer: ArrayBufferLike | null = null;

  constructor(private readonly size: number) {}

  /** Copies the `size` values at byte address `address` into `dst` from index `at`. */
  copy(address: number, dst: Float64Array, at: number): void {
    const h = f64();
    if (h.buffer !== this.buffer) {
      this.views.clear();
      this.buffer = h.buffer;
    }
    let v = this.views.get(address);
    if (v === undefined) {
      if (this.views.size >= HEAP_BLOCKS_MAX) this.views.clear();
      v = new Float64Array(h.buffer, address, this.size);
      this.views.set(address, v);
    }
    dst.set(v, at);
  }
}

export function disposed(what: string): Error {
  return new Error(`${what} was used after dispose()`);
}

/** Capacity to grow to: at least `needed`, at least double the current one (amortised). */
export function grownCapacity(current: number, needed: number): number {
  return Math.max(needed, current * 2);
}
