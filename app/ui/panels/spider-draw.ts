/**
 * The spider plot's drawing, without React: the polygon of the values on one axis per channel
 * (rings, spokes and names, the values, the ring values, the centre's value, a dot per value),
 * or bars for one or two channels. Each step draws on one context and leaves its state as the
 * next one expects.
 */
import { channelColor, formatTick, niceTicks } from "./channels";
import { fitCanvas, type Theme } from "./canvas";
import { withAlpha } from "./controls";

/** The plot's height, CSS pixels. */
export const HEIGHT = 300;
/** Up to this many axes, each is named at its spoke and its value gets a dot. */
const NAMED_AXES = 32;

/** What every step of the spider draws with: the context, colours, centre, radius and scale. */
interface Spider {
  ctx: CanvasRenderingContext2D;
  theme: Theme;
  values: Float64Array;
  n: number;
  cx: number;
  cy: number;
  /** The outer ring's radius. */
  R: number;
  lo: number;
  span: number;
  /** Round values between lo and hi, each drawn as a ring. */
  ticks: number[];
  /** The axes are named and the values dotted (NAMED_AXES at most). */
  named: boolean;
}

export function drawSpider(
  canvas: HTMLCanvasElement,
  theme: Theme,
  width: number,
  height: number,
  values: Float64Array,
  lo: number,
  hi: number,
  label: (k: number) => string,
): void {
  const ctx = fitCanvas(canvas, width, height);
  if (!ctx) return;
  ctx.clearRect(0, 0, width, height);
  const s = spiderGeometry(ctx, theme, width, height, values, lo, hi);
  drawRings(s);
  drawSpokes(s, label);
  drawValuePolygon(s);
  const step = tickStep(s.ticks, s.span);
  drawRingValues(s, step);
  drawCentreValue(s, step);
  if (s.named) drawValueDots(s);
}

function spiderGeometry(
  ctx: CanvasRenderingContext2D,
  theme: Theme,
  width: number,
  height: number,
  values: Float64Array,
  lo: number,
  hi: number,
): Spider {
  const n = values.length;
  const named = n <= NAMED_AXES;
  const R = Math.max(10, Math.min(width, height) / 2 - (named ? 26 : 10));
  const span = hi - lo || 1;
  const ticks = niceTicks(lo, hi, 4).filter((t) => t > lo + span * 0.05 && t <= hi);
  return { ctx, theme, values, n, cx: width / 2, cy: height / 2, R, lo, span, ticks, named };
}

/** Axis k's direction: the first one up, then clockwise. */
function angle(s: Spider, k: number): number {
  return -Math.PI / 2 + (2 * Math.PI * k) / s.n;
}

/** The radius of a ring at value t. */
function ringRadius(s: Spider, t: number): number {
  return (s.R * (t - s.lo)) / s.span;
}

/** The radius of a value: clamped to the rings, 0 when not finite. */
function valueRadius(s: Spider, v: number): number {
  if (!Number.isFinite(v)) return 0;
  return s.R * Math.max(0, Math.min(1, (v - s.lo) / s.span));
}

/** A closed path through one point on each axis, at `radius(k)` from the centre. */
function tracePolygon(s: Spider, radius: (k: number) => number): void {
  const { ctx, n, cx, cy } = s;
  for (let k = 0; k <= n; k++) {
    const a = angle(s, k % n);
    const r = radius(k % n);
    const x = cx + r * Math.cos(a);
    const y = cy + r * Math.sin(a);
    if (k === 0) ctx.moveTo(x, y);
    else ctx.lineTo(x, y);
  }
}

/** Rings at round values (and the outer edge). */
function drawRings(s: Spider): void {
  const { ctx, n, cx, cy, R } = s;
  const rings = s.ticks.map((t) => ringRadius(s, t));
  if (!rings.length || rings[rings.length - 1]! < R - 1) rings.push(R);
  ctx.lineWidth = 1;
  ctx.strokeStyle = s.theme.grid;
  for (const rr of rings) {
    ctx.beginPath();
    if (n < 3) ctx.arc(cx, cy, rr, 0, 2 * Math.PI);
    else tracePolygon(s, () => rr);
    ctx.stroke();
  }
}

/** A spoke per axis, named at its end when there are few. */
function drawSpokes(s: Spider, label: (k: number) => string): void {
  const { ctx, theme, cx, cy, R } = s;
  ctx.textAlign = "center";
  ctx.textBaseline = "middle";
  for (let k = 0; k < s.n; k++) {
    const a = angle(s, k);
    ctx.strokeStyle = theme.grid;
    ctx.beginPath();
    ctx.moveTo(cx, cy);
    ctx.lineTo(cx + R * Math.cos(a), cy + R * Math.sin(a));
    ctx.stroke();
    if (s.named) {
      ctx.fillStyle = theme.fg;
      ctx.fillText(label(k), cx + (R + 14) * Math.cos(a), cy + (R + 12) * Math.sin(a));
    }
  }
}

/** The values: a filled polygon in the accent colour. */
function drawValuePolygon(s: Spider): void {
  const { ctx, theme, values } = s;
  ctx.beginPath();
  tracePolygon(s, (k) => valueRadius(s, values[k]!));
  ctx.fillStyle = withAlpha(theme.accent, 0.22);
  ctx.fill();
  ctx.strokeStyle = theme.accent;
  ctx.lineWidth = 2;
  ctx.stroke();
}

/** The distance between round values (the whole span when there is one or none). */
function tickStep(ticks: number[], span: number): number {
  return ticks.length > 1 ? ticks[1]! - ticks[0]! : span;
}

/** Ring values on top, between the first two axes, on a light backing. */
function drawRingValues(s: Spider, step: number): void {
  const { ctx, theme, cx, cy } = s;
  const la = s.n >= 2 ? (angle(s, 0) + angle(s, 1)) / 2 : angle(s, 0) + Math.PI / 4;
  ctx.font = "11px system-ui, sans-serif";
  ctx.textAlign = "center";
  ctx.textBaseline = "middle";
  s.ticks.forEach((t) => {
    const rr = ringRadius(s, t);
    const x = cx + rr * Math.cos(la);
    const y = cy + rr * Math.sin(la);
    const text = formatTick(t, step);
    const w = ctx.measureText(text).width + 4;
    ctx.fillStyle = withAlpha(theme.bg, 0.85);
    ctx.fillRect(x - w / 2, y - 6, w, 12);
    ctx.fillStyle = theme.muted;
    ctx.fillText(text, x, y);
  });
}

/** The value at the centre, top left. */
function drawCentreValue(s: Spider, step: number): void {
  const { ctx } = s;
  ctx.fillStyle = s.theme.muted;
  ctx.textAlign = "left";
  ctx.textBaseline = "top";
  ctx.fillText(`centre ${formatTick(s.lo, step)}`, 2, 2);
}

/** A dot in the channel's colour on each value. */
function drawValueDots(s: Spider): void {
  const { ctx, cx, cy } = s;
  for (let k = 0; k < s.n; k++) {
    const a = angle(s, k);
    const r = valueRadius(s, s.values[k]!);
    ctx.fillStyle = channelColor(k);
    ctx.beginPath();
    ctx.arc(cx + r * Math.cos(a), cy + r * Math.sin(a), 3, 0, 2 * Math.PI);
    ctx.fill();
  }
}

/** What the bars' steps draw with: the context, colours, the scale and where a value goes. */
interface Bars {
  ctx: CanvasRenderingContext2D;
  theme: Theme;
  height: number;
  lo: number;
  hi: number;
  span: number;
  /** The bars' left end (their names are left of it). */
  left: number;
  xOf(v: number): number;
}

/** One or two channels: horizontal bars on the same scale (a polygon needs three axes). */
export function drawBars(
  canvas: HTMLCanvasElement,
  theme: Theme,
  width: number,
  height: number,
  values: Float64Array,
  lo: number,
  hi: number,
  label: (k: number) => string,
): void {
  const ctx = fitCanvas(canvas, width, height);
  if (!ctx) return;
  ctx.clearRect(0, 0, width, height);
  const left = 48;
  const right = width - 16;
  const span = hi - lo || 1;
  const xOf = (v: number): number =>
    left + ((Math.max(lo, Math.min(hi, v)) - lo) / span) * (right - left);
  const b: Bars = { ctx, theme, height, lo, hi, span, left, xOf };
  drawBarTicks(b);
  drawBarValues(b, values, label);
}

/** A vertical line at each round value, its value below. */
function drawBarTicks({ ctx, theme, height, lo, hi, span, xOf }: Bars): void {
  const ticks = niceTicks(lo, hi, 5);
  const step = tickStep(ticks, span);
  ctx.font = "11px system-ui, sans-serif";
  ctx.textAlign = "center";
  ctx.textBaseline = "top";
  for (const t of ticks) {
    const x = xOf(t);
    ctx.strokeStyle = theme.grid;
    ctx.beginPath();
    ctx.moveTo(x, 16);
    ctx.lineTo(x, height - 28);
    ctx.stroke();
    ctx.fillStyle = theme.muted;
    ctx.fillText(formatTick(t, step), x, height - 24);
  }
}

/** A bar per channel from 0 (or the nearer end of the scale) to its value, named on its left. */
function drawBarValues(
  { ctx, theme, height, lo, hi, left, xOf }: Bars,
  values: Float64Array,
  label: (k: number) => string,
): void {
  const n = values.length;
  const bar = Math.min(48, (height - 60) / Math.max(1, n) - 12);
  for (let k = 0; k < n; k++) {
    const y = 24 + k * (bar + 16);
    const v = values[k]!;
    const x0 = xOf(Math.max(lo, Math.min(0, hi)));
    const x1 = Number.isFinite(v) ? xOf(v) : x0;
    ctx.fillStyle = channelColor(k);
    ctx.fillRect(Math.min(x0, x1), y, Math.max(1, Math.abs(x1 - x0)), bar);
    ctx.fillStyle = theme.fg;
    ctx.textAlign = "right";
    ctx.textBaseline = "middle";
    ctx.fillText(label(k), left - 6, y + bar / 2);
  }
}
