/**
 * Labels shared by the Trigger and the Stimulus (trigger.ts, stimulus.ts): the `Labels` param
 * (names with their target vectors), its checks, the names of a target's columns, and the target
 * event both blocks send (a label's target vector to start a capture, all NaN to stop it).
 */
import { z } from "zod";
import { closest, LegacyParamsError, legacyPair, legacyVector } from "../../engine";

/** Most labels a Trigger or Stimulus may have, and most values in a label's target vector. */
export const MAX_LABELS = 1000;
export const MAX_TARGET = 4096;

/** A target vector: what a label means for a model (one value per output, e.g. a one-hot). */
export const targetVector = () => z.array(z.number()).min(1).max(MAX_TARGET);

/** `Labels`: a mapping from label name to target vector (in the order written). */
export const labelsSchema = () => z.record(z.string().min(1), targetVector());

export type Issue = { code: "custom"; path: (string | number)[]; message: string };
export type AddIssue = (issue: Issue) => void;

/** Checks a Labels mapping: at least one label, at most MAX_LABELS, all of the same width. */
export function checkLabels(
  labels: Record<string, number[]>,
  param: string,
  addIssue: AddIssue,
): void {
  const names = Object.keys(labels);
  if (names.length === 0) {
    addIssue({ code: "custom", path: [param], message: "needs at least one label" });
    return;
  }
  if (names.length > MAX_LABELS) {
    addIssue({
      code: "custom",
      path: [param],
      message: `has ${names.length} labels; at most ${MAX_LABELS} are allowed`,
    });
    return;
  }
  const width = labels[names[0]!]!.length;
  for (const n of names) {
    const w = labels[n]!.length;
    if (w !== width) {
      addIssue({
        code: "custom",
        path: [param, n],
        message:
          `label '${n}' has ${w} values, but '${names[0]}' has ${width}: every target vector ` +
          "must have the same length",
      });
    }
  }
}

/**
 * Names of a target vector's columns, for panels and recordings (PortMeta labels): column k is
 * named after the label whose target is one-hot at k (1 there, 0 elsewhere: fist [1, 0, 0] names
 * column 0 "fist"). Undefined unless every column has exactly one such label.
 */
export function targetColumnLabels(
  names: readonly string[],
  targets: readonly ArrayLike<number>[],
): string[] | undefined {
  const width = targets[0]?.length ?? 0;
  if (width === 0) return undefined;
  const cols: (string | null | undefined)[] = new Array<undefined>(width).fill(undefined);
  names.forEach((name, i) => {
    const v = targets[i]!;
    let hot = -1;
    for (let k = 0; k < v.length; k++) {
      if (v[k] === 1 && hot === -1) hot = k;
      else if (v[k] !== 0) return;
    }
    if (hot >= 0) cols[hot] = cols[hot] === undefined ? name : null;
  });
  return cols.every((c) => typeof c === "string") ? (cols as string[]) : undefined;
}

/** "unknown label 'fsit' (labels: rest, fist); did you mean 'fist'?" */
export function unknownLabel(name: string, names: readonly string[]): string {
  const s = closest(name, names);
  return (
    `unknown label '${name}' (labels: ${names.slice(0, 20).join(", ")}` +
    `${names.length > 20 ? ", …" : ""})` +
    (s !== undefined ? `; did you mean '${s}'?` : "")
  );
}

/** MOSAIC's `name:a;b;c` (a label and its target vector), argument `i` (0-based) of Params. */
export function legacyLabel(arg: string, i: number, param: string): [string, number[]] {
  if (!arg.includes(":")) {
    throw new LegacyParamsError(
      `argument ${i + 1} '${arg}' is not 'name:a;b;c' (a label and its target vector)`,
      param,
    );
  }
  const { key, value } = legacyPair(arg);
  if (key === "") {
    throw new LegacyParamsError(`argument ${i + 1} '${arg}' has no label name`, param);
  }
  return [key, legacyVector(value, `the target of label '${key}'`, param)];
}

/** Seconds for status texts: 2.4 → "2.4 s". */
export const seconds = (s: number): string => `${Number.isFinite(s) ? s.toFixed(1) : "∞"} s`;

/**
 * Writes one target event's values at `v[off…off + T)`: the target vector of `label` (a capture
 * starts or switches to it), or all NaN when `label` is negative (the capture stops).
 */
export function writeTarget(
  v: Float64Array,
  off: number,
  targets: readonly Float64Array[],
  label: number,
  T: number,
): void {
  if (label >= 0) v.set(targets[label]!, off);
  else v.fill(NaN, off, off + T);
}
