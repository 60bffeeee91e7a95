/**
 * What a predictor's outputs stand for, for its Training view: the prediction output's labels
 * when it has them, else the gesture whose target vector of the target's source block (a
 * Stimulus's or a Trigger's `Labels: { fist: [1, 0, …], … }`) is one-hot at that output, else
 * "output k". Framework-free.
 */
import type { BlockInfo, GraphInfo } from "../../engine/protocol";

/** The gesture name of each one-hot target vector in a `Labels` param, by the output it lights. */
function oneHotNames(labels: unknown, m: number): (string | undefined)[] {
  const names = new Array<string | undefined>(m).fill(undefined);
  if (labels === null || typeof labels !== "object" || Array.isArray(labels)) return names;
  for (const [name, v] of Object.entries(labels as Record<string, unknown>)) {
    if (!Array.isArray(v) || v.length !== m) continue;
    const ones = v.flatMap((x, k) => (x === 1 ? [k] : []));
    const zeros = v.filter((x) => x === 0).length;
    if (ones.length === 1 && zeros === m - 1) names[ones[0]!] ??= name;
  }
  return names;
}

/** One name per predicted value (m of them). */
export function predictorOutputNames(
  block: BlockInfo,
  graph: GraphInfo | undefined,
  m: number,
): string[] {
  const own = block.outputs.find((o) => o.name === "prediction")?.labels;
  if (own && own.length === m) return [...own];
  const source = block.inputs[1]?.block;
  const from = source !== undefined ? graph?.blocks.find((b) => b.name === source) : undefined;
  const named = oneHotNames(from?.params.Labels, m);
  return named.map((n, k) => n ?? `output ${k + 1}`);
}
