/**
 * The scope's traces drawn straight into pixels (no DOM): for every channel, each pixel column
 * gets one vertical run from the lowest to the highest value the line takes in that column
 * (every sample in it and the segments that cross it), in the channel's colour, one pixel wide
 * and without antialiasing — what an oscilloscope shows. The work is O(samples + columns) per
 * channel, whatever the density, and the result is one image to blit: far cheaper than stroking
 * thousands of antialiased line segments per frame (the cost that kept three busy scopes from
 * 30 frames a second in a software-rendered browser).
 */

export interface TraceImage {
  /** Pixels. */
  width: number;
  height: number;
  /** RGBA words, row-major (the bytes of an ImageData). */
  words: Uint32Array;
}

/** Per-column scratch for `rasterTraces` (reused between frames). */
export interface TraceScratch {
  lo: Float32Array;
  hi: Float32Array;
}

export function traceScratch(width: number): TraceScratch {
  return { lo: new Float32Array(width), hi: new Float32Array(width) };
}

/** A colour as the RGBA word of a little-endian ImageData (r in the low byte). */
export function rgbaWord(r: number, g: number, b: number, a = 255): number {
  return ((a << 24) | (b << 16) | (g << 8) | r) >>> 0;
}

/**
 * Clears `img` (transparent) and draws channel c of `ys` (times `xs`, ascending) in colour
 * `colours[c]`, later channels on top. The x range [x0, x1] spans the image's width and the y
 * range [y0, y1] its height (y1 at the top row). Non-finite values leave a gap. With `clear`
 * false the image keeps what it holds (stacked lanes draw into bands of one image).
 */
export function rasterTraces(
  img: TraceImage,
  scratch: TraceScratch,
  xs: Float64Array,
  ys: readonly Float64Array[],
  colours: ArrayLike<number>,
  x0: number,
  x1: number,
  y0: number,
  y1: number,
  clear = true,
): void {
  const { width: W, height: H, words } = img;
  if (clear) words.fill(0);
  if (W <= 0 || H <= 0 || !(x1 > x0) || !(y1 > y0)) return;
  const lo = scratch.lo;
  const hi = scratch.hi;
  const sx = W / (x1 - x0);
  const sy = (H - 1) / (y1 - y0);
  const n = xs.length;
  for (let c = 0; c < ys.length; c++) {
    const y = ys[c]!;
    lo.fill(Infinity);
    hi.fill(-Infinity);
    let havePrev = false;
    let pa = 0;
    let qa = 0;
    for (let i = 0; i < n; i++) {
      const v = y[i]!;
      if (!Number.isFinite(v)) {
        havePrev = false;
        continue;
      }
      const p = (xs[i]! - x0) * sx;
      const q = (y1 - v) * sy;
      if (!havePrev || p <= pa) {
        // A first point (or one at the same x): just this value in its column.
        const k = Math.floor(p);
        if (k >= 0 && k < W) {
          if (q < lo[k]!) lo[k] = q;
          if (q > hi[k]!) hi[k] = q;
        }
      } else if (p >= 0 && pa < W) {
        // The segment (pa, qa) → (p, q), column by column over the part inside the image.
        const slope = (q - qa) / (p - pa);
        const kFrom = Math.max(0, Math.floor(pa));
        const kTo = Math.min(W - 1, Math.floor(p));
        for (let k = kFrom; k <= kTo; k++) {
          const xa = k > pa ? k : pa;
          const xb = k + 1 < p ? k + 1 : p;
          const qa2 = qa + (xa - pa) * slope;
          const qb2 = qa + (xb - pa) * slope;
          const a = qa2 < qb2 ? qa2 : qb2;
          const b = qa2 < qb2 ? qb2 : qa2;
          if (a < lo[k]!) lo[k] = a;
          if (b > hi[k]!) hi[k] = b;
        }
      }
      havePrev = true;
      pa = p;
      qa = q;
    }
    const colour = colours[c]! >>> 0;
    for (let k = 0; k < W; k++) {
      const a = lo[k]!;
      if (a === Infinity) continue;
      const r0 = Math.max(0, Math.round(a));
      const r1 = Math.min(H - 1, Math.round(hi[k]!));
      for (let r = r0, i = r0 * W + k; r <= r1; r++, i += W) words[i] = colour;
    }
  }
}
