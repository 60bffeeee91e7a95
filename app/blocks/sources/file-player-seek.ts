/** FilePlayer: the `seek` action's argument, the row it finds and its refusals. */
import { FILE_LIMITS } from "./delimited-text";
import type { RowSource } from "./row-source";

export const SEEK_USAGE = "seek: give the seconds from the recording's first row, e.g. 12.5";

/** Seconds for messages: at most 3 decimals. */
export const fmtSeconds = (x: number): string => String(Math.round(x * 1000) / 1000);

/** The seconds a seek's argument gives (a number or a numeric string, finite, ≥ 0), or undefined. */
export function seekSeconds(arg: unknown): number | undefined {
  const s = typeof arg === "string" ? Number(arg) : arg;
  if (typeof s !== "number" || !Number.isFinite(s) || s < 0) return undefined;
  return s;
}

/** Why `src` cannot seek (it streams, or has no times), or undefined. */
export function seekRefusal(src: RowSource): string | undefined {
  if (src.whole && src.hasTimes) return undefined;
  return src.hasTimes
    ? `seek needs a recording read whole (text up to ${FILE_LIMITS.wholeBytes} bytes, XDF or EDF+)`
    : "seek needs a time column";
}

/**
 * The first of `total` rows in time order whose `time` is at or after `want`, or `total` when
 * none is (a binary search).
 */
export function firstRowAtOrAfter(
  time: (r: number) => number,
  total: number,
  want: number,
): number {
  let lo = 0;
  let hi = total;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (time(mid) < want) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

/** The first row of `src` at or after `s` seconds from its first row, or undefined after its end. */
export function rowAt(src: RowSource, s: number): number | undefined {
  const total = src.total ?? 0;
  const r = firstRowAtOrAfter((i) => src.time(i), total, src.time(0) + s);
  return r < total ? r : undefined;
}
