/**
 * Run-time action arguments (what a user, the CLI or the UI passes to `invoke`): channel indices,
 * index lists and numeric vectors, parsed with messages that say what was expected. Actions throw
 * plain `Error`s (the runtime reports them to whoever invoked the action).
 */

const describeArg = (arg: unknown): string => {
  if (arg === undefined) return "nothing";
  if (typeof arg === "string") return `'${arg.length > 40 ? arg.slice(0, 40) + "…" : arg}'`;
  if (Array.isArray(arg)) return "a list";
  if (arg === null) return "null";
  return typeof arg === "object" ? "an object" : String(arg);
};

/** Splits "1;2;3", "1, 2, 3" or "1 2 3" into number strings. */
const splitList = (s: string): string[] =>
  s
    .trim()
    .replace(/^\[|\]$/g, "")
    .split(/[;,\s]+/)
    .filter((x) => x !== "");

/** One 0-based index below `count` (a number, or a string holding one). */
export function indexArg(arg: unknown, count: number, what: string): number {
  const v = typeof arg === "string" && arg.trim() !== "" ? Number(arg) : arg;
  if (typeof v !== "number" || !Number.isInteger(v) || v < 0 || v >= count) {
    throw new Error(
      `expected ${what}: a whole number from 0 to ${count - 1}, got ${describeArg(arg)}`,
    );
  }
  return v;
}

/**
 * One index or a list of them (a number, a number[], or a string such as "1;3" or "1,3"), each
 * checked against `count`.
 */
export function indexListArg(arg: unknown, count: number, what: string): number[] {
  let items: unknown[];
  if (Array.isArray(arg)) items = arg;
  else if (typeof arg === "string") items = splitList(arg);
  else items = [arg];
  if (items.length === 0) {
    throw new Error(`expected ${what}: an index or a list of indices, got an empty list`);
  }
  return items.map((x) => indexArg(x, count, what));
}

/** A list of finite numbers (a number[], or a string such as "1;0;0"); `length` when given. */
export function vectorArg(arg: unknown, what: string, length?: number): number[] {
  let items: unknown[] | undefined;
  if (Array.isArray(arg)) items = arg;
  else if (typeof arg === "string") items = splitList(arg).map(Number);
  const ok =
    items !== undefined &&
    items.length > 0 &&
    items.every((x) => typeof x === "number" && Number.isFinite(x)) &&
    (length === undefined || items.length === length);
  if (!ok) {
    throw new Error(
      `expected ${what}: ${length === undefined ? "a list of" : `${length}`} finite numbers, got ` +
        describeArg(arg),
    );
  }
  return items as number[];
}
