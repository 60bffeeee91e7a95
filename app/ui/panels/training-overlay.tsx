/**
 * Prediction versus target, one small plot per output over the recent events: the prediction a
 * solid line, the target it is compared with dashed (absent where nothing was learnt).
 */
import type { ReactNode } from "react";
import type { Traces } from "./training-feed";

const W = 320;
const H = 56;

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
function range(tr: Traces, k: number): [number, number] {
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

function OutputPlot({ tr, k, name }: { tr: Traces; k: number; name: string }): ReactNode {
  const [lo, hi] = range(tr, k);
  const y = (v: number) => H - 4 - ((v - lo) / (hi - lo)) * (H - 8);
  return (
    <figure className="mp-versus" data-output={name}>
      <figcaption>{name}</figcaption>
      <svg viewBox={`0 0 ${W} ${H}`} preserveAspectRatio="none" role="img" aria-label={name}>
        <line className="mp-versus__zero" x1={0} x2={W} y1={y(0)} y2={y(0)} />
        {tr.n > 1 && (
          <>
            <path className="mp-versus__target" d={seriesPath(tr, tr.target, k, y)} />
            <path className="mp-versus__pred" d={seriesPath(tr, tr.pred, k, y)} />
          </>
        )}
      </svg>
    </figure>
  );
}

export function VersusOverlay({ traces, names }: { traces: Traces; names: string[] }): ReactNode {
  return (
    <div className="mp-versus-list" aria-label="Prediction versus target">
      <p className="mp-legend mp-muted">
        <span className="mp-key mp-key--pred" /> prediction{" "}
        <span className="mp-key mp-key--target" /> target (while learning)
      </p>
      {names.map((n, k) => (
        <OutputPlot key={n + k} tr={traces} k={k} name={n} />
      ))}
    </div>
  );
}
