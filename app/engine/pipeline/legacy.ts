/**
 * Helpers for MOSAIC's positional `Params`: a list of strings where vectors are written `a;b;c`
 * and named values `name:value` (e.g. `[multiply:5]`, `[b0;b1;b2, 1;a1;a2]`, `['4;5;6']`).
 * A block's `legacyParams` uses these to build its named params; errors say which argument.
 */

export class LegacyParamsError extends Error {
  constructor(
    message: string,
    readonly param?: string,
  ) {
    super(message);
    this.name = "LegacyParamsError";
  }
}

/** Parses a number the way MOSAIC's C# `double.Parse` (invariant culture) accepted it. */
export function legacyNumber(s: string, what: string, param?: string): number {
  const t = s.trim();
  const v = t === "" ? NaN : Number(t);
  if (!Number.isFinite(v)) throw new LegacyParamsError(`${what} '${s}' is not a number`, param);
  return v;
}

/** Parses `a;b;c` into numbers. */
export function legacyVector(s: string, what: string, param?: string): number[] {
  const parts = s.split(";").map((p) => p.trim());
  if (parts.length > 0 && parts[parts.length - 1] === "") parts.pop();
  if (parts.length === 0) throw new LegacyParamsError(`${what} is empty`, param);
  return parts.map((p, i) => legacyNumber(p, `${what} element ${i + 1}`, param));
}

/** Parses `name:value` (value may be empty). */
export function legacyPair(s: string): { key: string; value: string } {
  const i = s.indexOf(":");
  if (i < 0) return { key: s.trim(), value: "" };
  return { key: s.slice(0, i).trim(), value: s.slice(i + 1).trim() };
}

export function legacyInteger(s: string, what: string, param?: string): number {
  const v = legacyNumber(s, what, param);
  if (!Number.isInteger(v))
    throw new LegacyParamsError(`${what} '${s}' is not a whole number`, param);
  return v;
}
