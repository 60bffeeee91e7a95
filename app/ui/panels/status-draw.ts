/**
 * The Status tab's history plot, drawn in named steps on one canvas context (each step leaves the
 * context's state as the next one expects): the status strip, the rate against the desired one,
 * the delivery delay against late, and the time axis.
 */
import type { Status } from "../../engine/runtime/status";
import { formatValue } from "./channels";
import { fitCanvas, readTheme } from "./canvas";
import { STATUS_ORDER, type StatusHistory } from "./status-history";

const STATUS_FALLBACK: Record<Status, string> = {
  ontime: "#1a9850",
  lagging: "#d73027",
  stumbling: "#c51b7d",
  idle: "#8c8c8c",
};
const STRIP_H = 22;
/** Height of the delivery-delay band at the bottom of the history. */
const DELAY_H = 52;

function statusColors(el: Element): Record<Status, string> {
  const css = getComputedStyle(el);
  const out = { ...STATUS_FALLBACK };
  for (const s of STATUS_ORDER)
    out[s] = css.getPropertyValue(`--status-${s}`).trim() || STATUS_FALLBACK[s];
  return out;
}

/** What every step draws with: the context, colours, the plot's horizontal extent and scale. */
interface Plot {
  ctx: CanvasRenderingContext2D;
  theme: ReturnType<typeof readTheme>;
  colors: Record<Status, string>;
  h: StatusHistory;
  height: number;
  left: number;
  right: number;
  w: number;
  xOf(t: number): number;
}

export function drawHistory(
  canvas: HTMLCanvasElement,
  width: number,
  height: number,
  h: StatusHistory,
  desired: number,
  lateMs: number,
): void {
  const ctx = fitCanvas(canvas, width, height);
  if (!ctx) return;
  const theme = readTheme(canvas);
  const colors = statusColors(canvas);
  ctx.clearRect(0, 0, width, height);
  const left = 44;
  const right = width - 6;
  const w = Math.max(10, right - left);
  const newest = h.newestT;
  const from = newest - h.seconds;
  const xOf = (t: number): number => left + ((t - from) / h.seconds) * w;
  const plot: Plot = { ctx, theme, colors, h, height, left, right, w, xOf };
  drawStrip(plot);
  drawRate(plot, desired);
  drawDelay(plot, lateMs);
  drawTimeAxis(plot);
}

/** The status strip: one colour per telemetry sample. */
function drawStrip({ ctx, theme, colors, h, left, w, xOf }: Plot): void {
  ctx.fillStyle = theme.grid;
  ctx.fillRect(left, 0, w, STRIP_H);
  let prevX = NaN;
  h.forEach((t, s) => {
    const x = xOf(t);
    const x0 = Number.isFinite(prevX) && x - prevX < 4 ? prevX : x - w / (h.seconds * 20);
    ctx.fillStyle = colors[s];
    ctx.fillRect(x0, 0, Math.max(1, x - x0 + 0.5), STRIP_H);
    prevX = x;
  });
  ctx.fillStyle = theme.muted;
  ctx.font = "11px system-ui, sans-serif";
  ctx.textBaseline = "middle";
  ctx.textAlign = "right";
  ctx.fillText("status", left - 4, STRIP_H / 2);
}

/** The rate as a line, with the desired rate and 95 % of it dashed. */
function drawRate(
  { ctx, theme, colors, h, height, left, right, w, xOf }: Plot,
  desired: number,
): void {
  const top = STRIP_H + 8;
  const bottom = height - 14 - DELAY_H - 8;
  let seen = 0;
  h.forEach((_t, _s, rate) => {
    if (rate > seen) seen = rate;
  });
  // Up to twice the desired rate: a momentary burst must not flatten the line.
  let maxRate =
    desired > 0 ? Math.min(Math.max(desired * 1.2, seen * 1.05), desired * 2) : seen * 1.05;
  if (!(maxRate > 0)) maxRate = 1;
  const clipped = seen > maxRate;
  const yOf = (r: number): number => Math.max(top, bottom - (r / maxRate) * (bottom - top));
  ctx.strokeStyle = theme.grid;
  ctx.lineWidth = 1;
  ctx.strokeRect(left + 0.5, top + 0.5, w, bottom - top);
  if (desired > 0) {
    ctx.setLineDash([4, 3]);
    ctx.strokeStyle = theme.muted;
    ctx.beginPath();
    ctx.moveTo(left, yOf(desired));
    ctx.lineTo(right, yOf(desired));
    ctx.stroke();
    ctx.strokeStyle = colors.lagging;
    ctx.beginPath();
    ctx.moveTo(left, yOf(desired * 0.95));
    ctx.lineTo(right, yOf(desired * 0.95));
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = theme.muted;
    ctx.fillText(formatValue(desired), left - 4, yOf(desired));
  }
  ctx.fillText("0", left - 4, bottom);
  ctx.strokeStyle = theme.accent;
  ctx.lineWidth = 1.5;
  ctx.beginPath();
  let first = true;
  h.forEach((t, _s, rate) => {
    const x = xOf(t);
    const y = yOf(rate);
    if (first) ctx.moveTo(x, y);
    else ctx.lineTo(x, y);
    first = false;
  });
  ctx.stroke();
  ctx.fillStyle = theme.muted;
  ctx.textAlign = "left";
  ctx.fillText(
    `rate, Hz (dashed: desired and 95 %)${clipped ? `; peaks above ${formatValue(maxRate)} clipped` : ""}`,
    left + 4,
    top + 8,
  );
}

/** The delivery delay: the largest of each telemetry window, as bars (red above late). */
function drawDelay(
  { ctx, theme, colors, h, height, left, right, w, xOf }: Plot,
  lateMs: number,
): void {
  const dTop = height - 14 - DELAY_H;
  const dBottom = height - 14;
  let seenDelay = 0;
  h.forEach((_t, _s, _r, _cm, _cx, d) => {
    if (d > seenDelay) seenDelay = d;
  });
  // Late shows two thirds up; a stall far beyond it is clipped (and said so).
  const maxDelay = Math.max(lateMs * 1.5, Math.min(seenDelay * 1.05, lateMs * 4));
  const dClipped = seenDelay > maxDelay;
  const dyOf = (d: number): number => Math.max(dTop, dBottom - (d / maxDelay) * (dBottom - dTop));
  ctx.strokeStyle = theme.grid;
  ctx.lineWidth = 1;
  ctx.strokeRect(left + 0.5, dTop + 0.5, w, DELAY_H);
  const barW = Math.max(1, w / (h.seconds * 20));
  h.forEach((t, _s, _r, _cm, _cx, d) => {
    if (!(d > 0)) return;
    const y = dyOf(d);
    ctx.fillStyle = d > lateMs ? colors.lagging : theme.accent;
    ctx.fillRect(xOf(t) - barW, y, barW, dBottom - y);
  });
  ctx.setLineDash([4, 3]);
  ctx.strokeStyle = colors.lagging;
  ctx.beginPath();
  ctx.moveTo(left, dyOf(lateMs));
  ctx.lineTo(right, dyOf(lateMs));
  ctx.stroke();
  ctx.setLineDash([]);
  ctx.fillStyle = theme.muted;
  ctx.textAlign = "right";
  ctx.fillText(String(Math.round(lateMs)), left - 4, dyOf(lateMs));
  ctx.fillText("0", left - 4, dBottom);
  ctx.textAlign = "left";
  ctx.fillText(
    `delivery delay, ms (largest per 50 ms; dashed: late)${dClipped ? `; up to ${formatValue(Math.round(seenDelay))} clipped` : ""}`,
    left + 4,
    dTop + 8,
  );
}

/** "now" at the right, the history's length at the left. */
function drawTimeAxis({ ctx, h, height, left, right }: Plot): void {
  const dBottom = height - 14;
  ctx.textAlign = "right";
  ctx.textBaseline = "top";
  ctx.fillText("now", right, dBottom + 2);
  ctx.textAlign = "left";
  ctx.fillText(`−${h.seconds} s`, left, dBottom + 2);
}
