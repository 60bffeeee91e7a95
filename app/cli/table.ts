/**
 * The live per-block table of `mosaic run` (name, type, rates, status, compute time, delivery
 * delay, drops).
 */
import type { Status } from "../engine/runtime/status";
import type { Telemetry } from "../engine/runtime/runtime";

const COLORS: Record<Status, string> = {
  ontime: "\x1b[32m",
  lagging: "\x1b[31m",
  stumbling: "\x1b[35m",
  idle: "\x1b[90m",
};
const RESET = "\x1b[0m";
const LABEL: Record<Status, string> = {
  ontime: "on time",
  lagging: "lagging",
  stumbling: "stumbling",
  idle: "idle",
};

export function statusLabel(s: Status, stumblingToo = false): string {
  return s === "lagging" && stumblingToo ? "lagging+stumbling" : LABEL[s];
}

function fmtRate(hz: number): string {
  if (!(hz > 0)) return "-";
  if (hz >= 100) return hz.toFixed(1);
  if (hz >= 10) return hz.toFixed(2);
  return hz.toFixed(3);
}

function fmtMs(ms: number): string {
  if (!(ms > 0)) return "0";
  if (ms < 0.01) return `${(ms * 1000).toFixed(1)} µs`;
  if (ms < 1) return `${Math.round(ms * 1000)} µs`;
  if (ms < 100) return `${ms.toFixed(2)} ms`;
  return `${Math.round(ms)} ms`;
}

function pad(s: string, w: number, right = false): string {
  const len = [...s].length;
  if (len >= w) return s;
  return right ? " ".repeat(w - len) + s : s + " ".repeat(w - len);
}

export interface TableOptions {
  color: boolean;
  width?: number;
}

export function renderTable(t: Telemetry, o: TableOptions): string[] {
  const header = [
    "block",
    "type",
    "desired Hz",
    "actual Hz",
    "status",
    "compute (mean / max)",
    "delay (p99 / max)",
    "drops",
    "",
  ];
  const rows = t.blocks.map((b) => [
    b.worker === "main" ? b.name : `${b.name} @${b.worker}`,
    b.type,
    fmtRate(b.desiredRate),
    fmtRate(b.rate),
    statusLabel(b.status, b.stumbling),
    `${fmtMs(b.computeMeanMs)} / ${fmtMs(b.computeMaxMs)}`,
    b.delay.n > 0 ? `${fmtMs(b.delay.p99Ms)} / ${fmtMs(b.delay.maxMs)}` : "-",
    String(b.dropsIn),
    [
      b.errors > 0 ? `error: ${b.lastError}${b.errors > 1 ? ` (×${b.errors})` : ""}` : "",
      b.timer && b.timer.missed > 0 ? `missed ${b.timer.missed}` : "",
      b.text,
    ]
      .filter((s) => s !== "")
      .join("; "),
  ]);
  const widths = header.map((h, i) =>
    Math.max([...h].length, ...rows.map((r) => [...r[i]!].length)),
  );
  const right = [false, false, true, true, false, true, true, true, false];
  const line = (cells: string[], status?: Status): string => {
    const padded = cells.map((c, i) => pad(c, widths[i]!, right[i]));
    const plain = padded.join("  ").trimEnd();
    const cut = o.width !== undefined && [...plain].length > o.width;
    if (status && o.color && !cut) {
      padded[4] = `${COLORS[status]}${padded[4]}${RESET}`;
      return padded.join("  ").trimEnd();
    }
    return cut ? [...plain].slice(0, o.width! - 1).join("") + "…" : plain;
  };
  return [line(header), ...rows.map((r, i) => line(r, t.blocks[i]!.status))];
}
