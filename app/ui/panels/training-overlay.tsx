/**
 * Prediction versus target, one small plot per output over the recent events: the prediction a
 * solid line, the target it is compared with dashed (absent where nothing was learnt).
 */
import type { ReactNode } from "react";
import { OVERLAY_H as H, OVERLAY_W as W, seriesPath, yRange, type Traces } from "./training-plot";

function OutputPlot({ tr, k, name }: { tr: Traces; k: number; name: string }): ReactNode {
  const [lo, hi] = yRange(tr, k);
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
