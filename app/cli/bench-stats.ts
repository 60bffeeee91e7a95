/**
 * `mosaic bench`: the statistics of the samples (non-finite values left out).
 */

/** Median and percentile of a list (linear interpolation, as numpy's default). */
export function quantile(xs: readonly number[], q: number): number {
  const a = xs.filter((x) => Number.isFinite(x)).sort((x, y) => x - y);
  if (a.length === 0) return NaN;
  const pos = (a.length - 1) * q;
  const lo = Math.floor(pos);
  const hi = Math.ceil(pos);
  return a[lo]! + (a[hi]! - a[lo]!) * (pos - lo);
}

/** Arithmetic mean. */
export function mean(xs: readonly number[]): number {
  const a = xs.filter((x) => Number.isFinite(x));
  return a.length ? a.reduce((s, x) => s + x, 0) / a.length : NaN;
}

/** Sample standard deviation (n − 1). */
export function std(xs: readonly number[]): number {
  const a = xs.filter((x) => Number.isFinite(x));
  if (a.length < 2) return NaN;
  const m = mean(a);
  return Math.sqrt(a.reduce((s, x) => s + (x - m) ** 2, 0) / (a.length - 1));
}
