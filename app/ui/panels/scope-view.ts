/**
 * The scope's view arithmetic (no DOM): zoom and pan of the time and amplitude ranges, the lanes
 * of stacked channels, the sample under the cursor, and the visible window as CSV.
 */

export type Range = readonly [number, number];

/** `r` scaled by `factor` (< 1 zooms in) around `anchor`, which stays where it is. */
export function zoomRange(r: Range, factor: number, anchor: number): [number, number] {
  const f = Number.isFinite(factor) && factor > 0 ? factor : 1;
  return [anchor - (anchor - r[0]) * f, anchor + (r[1] - anchor) * f];
}

/** `r` moved by `delta`. */
export function panRange(r: Range, delta: number): [number, number] {
  return [r[0] + delta, r[1] + delta];
}

/** The right edge of a window `span` wide kept over the data [oldest, newest]. */
export function clampRight(right: number, span: number, oldest: number, newest: number): number {
  if (!(newest > oldest)) return newest;
  const lo = Math.min(newest, oldest + span);
  return Math.max(lo, Math.min(newest, right));
}

/** The band of stacked channel k of n in a plot `height` pixels high (top and height, pixels). */
export function lane(k: number, n: number, height: number): { top: number; height: number } {
  const h = height / Math.max(1, n);
  return {
    top: Math.round(k * h),
    height: Math.max(1, Math.round((k + 1) * h) - Math.round(k * h)),
  };
}

/** Index of the sample of `t` (ascending) nearest to `x`; -1 when there is none. */
export function nearestIndex(t: ArrayLike<number>, x: number): number {
  const n = t.length;
  if (n === 0 || !Number.isFinite(x)) return -1;
  let a = 0;
  let b = n;
  while (a < b) {
    const m = (a + b) >> 1;
    if (t[m]! < x) a = m + 1;
    else b = m;
  }
  if (a === 0) return 0;
  if (a === n) return n - 1;
  return x - t[a - 1]! <= t[a]! - x ? a - 1 : a;
}

/** The indices [from, to) of the samples of `t` (ascending) with x0 ≤ t ≤ x1. */
export function indexRange(t: ArrayLike<number>, x0: number, x1: number): [number, number] {
  let a = 0;
  while (a < t.length && t[a]! < x0) a++;
  let b = t.length;
  while (b > a && t[b - 1]! > x1) b--;
  return [a, b];
}

/** Numbers in a CSV cell: shortest round-trip form, empty for NaN. */
function cell(v: number): string {
  return Number.isNaN(v) ? "" : String(v);
}

/** A CSV field, quoted when it needs to be. */
function field(s: string): string {
  return /[",\n\r]/.test(s) ? `"${s.replaceAll('"', '""')}"` : s;
}

/**
 * The samples with x0 ≤ t ≤ x1 as CSV: a header `time_s,<name>,…` and one line per sample (time
 * in the plot's seconds, then each channel's value).
 */
export function visibleCsv(
  t: ArrayLike<number>,
  ys: readonly ArrayLike<number>[],
  names: readonly string[],
  x0: number,
  x1: number,
): string {
  const lines = [["time_s", ...names].map(field).join(",")];
  for (let i = 0; i < t.length; i++) {
    const x = t[i]!;
    if (x < x0 || x > x1) continue;
    let line = cell(x);
    for (const y of ys) line += `,${cell(y[i]!)}`;
    lines.push(line);
  }
  return `${lines.join("\n")}\n`;
}
