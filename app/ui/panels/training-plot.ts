/**
 * The geometry of the Training view's overlay (training-overlay.tsx), framework-free: an SVG
 * path per series with a gap wherever a value is missing, and the y range both series share.
 */
/** The overlay's recent events: times, predictions and targets (m each, row-major). */
export interface Traces {
  m: number;
  t: Float64Array;
  pred: Float64Array;
  target: Float64Array;
  /** Events held (the newest last). */
  n: number;
}

/** The plot's viewBox. */
export const OVERLAY_W = 320;
export const OVERLAY_H = 56;
const W = OVERLAY_W;

/** SVG path of one series of output `k` ("M x y L …", a gap wherever the value is NaN). */
export function seriesPath(
  tr: Traces,
  values: Float64Array,
  k: number,
  y: (v: number) => number,
): string {
  const t0 = tr.t[0]!;
  const span = Math.max(1e-9, tr.t[tr.n - 1]! - t0);
  let d = "";
  let pen = false;
  for (let e = 0; e < tr.n; e++) {
    const v = values[e * tr.m + k]!;
    if (!Number.isFinite(v)) {
      pen = false;
      continue;
    }
    const x = ((tr.t[e]! - t0) / span) * W;
    d += `${pen ? "L" : "M"}${x.toFixed(1)} ${y(v).toFixed(1)}`;
    pen = true;
  }
  return d;
}

/** The y range of output `k` in both series (at least 0…1, the targets' usual range). */
export function yRange(tr: Traces, k: number): [number, number] {
  let lo = 0;
  let hi = 1;
  for (let e = 0; e < tr.n; e++) {
    for (const v of [tr.pred[e * tr.m + k]!, tr.target[e * tr.m + k]!]) {
      if (!Number.isFinite(v)) continue;
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
  }
  return [lo, hi];
}
