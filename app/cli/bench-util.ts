/**
 * `mosaic bench`: small helpers shared by the workloads — output, progress, rounding, load.
 */
import { loadavg } from "node:os";

/** A line of the report on stdout. */
export function out(s = ""): void {
  process.stdout.write(s + "\n");
}

/** What the bench is doing, on stderr. */
export function progress(s: string): void {
  process.stderr.write(`bench: ${s}\n`);
}

/** `x` rounded to `d` decimals for latest.json (non-finite values as they are). */
export const round = (x: number, d = 3): number => (Number.isFinite(x) ? Number(x.toFixed(d)) : x);

/** The 1/5/15-min load averages now, two decimals. */
export const loadAvg = (): number[] => loadavg().map((x) => round(x, 2));

export const sleep = (ms: number): Promise<void> => new Promise((r) => setTimeout(r, ms));
