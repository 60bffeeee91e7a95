import type { PortMeta } from "../../engine";

/**
 * The names of a predictor's outputs, from the target it learns (a Stimulus's or a Trigger's
 * one-hot targets name their columns fist, open, …): `prediction` gets them, `fit` gets
 * "samples" and "R² <name>" (PortMeta for panels and recordings). Undefined without names for
 * all `m` outputs.
 */
export function predictorMeta(
  targetLabels: readonly string[] | undefined,
  m: number,
): { prediction: PortMeta; fit: PortMeta } | undefined {
  if (targetLabels === undefined || targetLabels.length < m || m === 0) return undefined;
  const names = targetLabels.slice(0, m);
  return {
    prediction: { labels: names },
    fit: { labels: ["samples", ...names.map((n) => `R² ${n}`)] },
  };
}
