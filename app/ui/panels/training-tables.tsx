/**
 * The figures of a predictor's Training view: R² per output over the recent labelled samples,
 * and for gesture targets the accuracy, per-gesture accuracy and the confusion matrix (rows: the
 * cued gesture, columns: the predicted one).
 */
import type { ReactNode } from "react";
import type { TrainingSummary } from "./training-metrics";

const fixed = (x: number, digits: number): string => (Number.isFinite(x) ? x.toFixed(digits) : "–");
const percent = (x: number): string => (Number.isFinite(x) ? `${(x * 100).toFixed(1)} %` : "–");

/** R² of every output; `label` names the table (the window, or the block's own fit). */
export function R2Table({
  r2,
  names,
  label = "R² per output",
  className = "mp-r2",
}: {
  r2: ArrayLike<number>;
  names: string[];
  label?: string;
  className?: string;
}) {
  return (
    <table className={`mp-table ${className}`} aria-label={label}>
      <thead>
        <tr>
          <th scope="col">Output</th>
          <th scope="col">R²</th>
        </tr>
      </thead>
      <tbody>
        {names.map((n, k) => (
          <tr key={n + k} data-output={n}>
            <th scope="row">{n}</th>
            <td data-r2={r2[k]}>{fixed(r2[k]!, 3)}</td>
          </tr>
        ))}
      </tbody>
    </table>
  );
}

export function GestureFigures({
  classes,
  names,
}: {
  classes: NonNullable<TrainingSummary["classes"]>;
  names: string[];
}): ReactNode {
  const labels = ["rest", ...names];
  return (
    <section className="mp-gestures" aria-label="Gesture classification">
      <p>
        Accuracy <strong data-accuracy={classes.accuracy}>{percent(classes.accuracy)}</strong>
        {classes.leftOut > 0 && (
          <span className="mp-muted"> ({classes.leftOut} samples without a gesture left out)</span>
        )}
      </p>
      <table className="mp-table mp-confusion" aria-label="Confusion matrix">
        <thead>
          <tr>
            <th scope="col">cued ↓ / predicted →</th>
            {labels.map((l) => (
              <th key={l} scope="col">
                {l}
              </th>
            ))}
            <th scope="col">accuracy</th>
          </tr>
        </thead>
        <tbody>
          {classes.confusion.map((row, i) => (
            <tr key={labels[i]} data-gesture={labels[i]}>
              <th scope="row">{labels[i]}</th>
              {row.map((c, j) => (
                <td key={j} className={i === j ? "is-diagonal" : c > 0 ? "is-off" : undefined}>
                  {c}
                </td>
              ))}
              <td data-accuracy={classes.perClass[i]}>{percent(classes.perClass[i]!)}</td>
            </tr>
          ))}
        </tbody>
      </table>
    </section>
  );
}
