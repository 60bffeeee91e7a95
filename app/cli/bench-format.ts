/**
 * `mosaic bench`: how the report writes numbers, load averages and Markdown tables.
 */

/** `x` with `digits` decimals; "-" when missing or not finite. */
export function fmt(x: number | null | undefined, digits: number): string {
  return x === null || x === undefined || !Number.isFinite(x) ? "-" : x.toFixed(digits);
}

/** A CPU or status share in %: two decimals below 10 %, one above. */
export function fmtPct(x: number): string {
  return !Number.isFinite(x) ? "-" : x < 10 ? `${x.toFixed(2)} %` : `${x.toFixed(1)} %`;
}

/** A Table 6 share (%, three decimals); "-" for none, as the paper writes a zero share. */
export function fmtShare(x: number | null | undefined): string {
  return x === null || x === undefined || !(x > 0) ? "-" : x.toFixed(3);
}

/** A desired rate: whole rates as they are, others (1926 / 77) with four decimals. */
export function fmtRate(x: number): string {
  if (!Number.isFinite(x)) return "-";
  return Number.isInteger(x) ? String(x) : x.toFixed(4);
}

/** A large rate with an SI prefix (21.35 M, 667.3 k). */
export function fmtRateSI(x: number): string {
  if (!Number.isFinite(x)) return "-";
  if (x >= 1e6) return `${(x / 1e6).toFixed(2)} M`;
  if (x >= 1e3) return `${(x / 1e3).toFixed(1)} k`;
  return x.toFixed(0);
}

/** The 1/5/15-min load averages, "a / b / c". */
export function load(l: number[]): string {
  return l.length ? l.map((x) => x.toFixed(2)).join(" / ") : "-";
}

/** A Markdown table: the head, its rule and the rows. */
export function table(head: string[], rows: string[][]): string[] {
  const line = (cells: string[]) => `| ${cells.join(" | ")} |`;
  return [line(head), line(head.map(() => "---")), ...rows.map(line)];
}

/** A workload's section heading and the blank line after it. */
export function section(heading: string, title: string): string[] {
  return [`${heading} ${title}`, ""];
}

/** The paragraph of a workload that did not run to the end. */
export function failed(why: string): string[] {
  return [`**Failed:** ${why}`, ""];
}
