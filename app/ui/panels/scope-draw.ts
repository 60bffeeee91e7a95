/**
 * One picture of the scope (DOM canvas, no React): the ranges of the window in view (following
 * the engine's clock, or where a pause, zoom or pan left it), the traces rasterised overlaid or in
 * stacked lanes, and the lane labels (name, unit, range) drawn onto uPlot's canvas so that an
 * exported PNG carries them.
 */
import type uPlot from "uplot";
import { StickyRange, finiteExtent, formatValue } from "./channels";
import type { ScopeBuffer } from "./scope-buffer";
import { clampRight, lane } from "./scope-view";
import { rasterTraces, traceScratch, type TraceScratch } from "./trace-raster";

/** The offscreen image the traces are drawn into, sized to the plot area (device pixels). */
export interface TraceLayer {
  canvas: HTMLCanvasElement;
  ctx: CanvasRenderingContext2D;
  image: ImageData;
  words: Uint32Array;
  scratch: TraceScratch;
}

export function traceLayer(width: number, height: number): TraceLayer | null {
  const canvas = document.createElement("canvas");
  canvas.width = Math.max(1, width);
  canvas.height = Math.max(1, height);
  const ctx = canvas.getContext("2d");
  if (!ctx) return null;
  const image = ctx.createImageData(canvas.width, canvas.height);
  return {
    canvas,
    ctx,
    image,
    words: new Uint32Array(image.data.buffer),
    scratch: traceScratch(canvas.width),
  };
}

/** What the frame loop, the data callback, the pointer and the exports share (no React). */
export interface ScopeLive {
  buffer: ScopeBuffer | null;
  plot: uPlot | null;
  dirty: boolean;
  /** Engine time (plot x) minus performance.now() seconds, from the freshest data seen. */
  offset: number;
  /** The x and y ranges drawn last. */
  x: [number, number];
  y: [number, number];
  sticky: StickyRange;
  /** Stacked lanes: one autoscaled range each, and the ranges drawn last. */
  laneSticky: StickyRange[];
  laneY: [number, number][];
  lastDraw: number;
  /** Seconds shown: the window unless zoomed. */
  span: number;
  /** The right edge held (paused, zoomed or panned back); NaN follows the engine's clock. */
  right: number;
  /** The amplitude range chosen by zoom or pan (overlaid), or null. */
  yView: [number, number] | null;
  /** Stacked lanes: how far the amplitude is zoomed (1: each lane's autoscale). */
  laneGain: number;
  stacked: boolean;
  fixedY: [number, number] | null;
  colours: Uint32Array;
  names: string[];
  unit: string;
  layer: TraceLayer | null;
}

/** How far behind the newest data the right edge runs: a little over one 20 Hz flush. */
export const DELAY_S = 0.1;

/** The x range to draw at `nowMs` (performance.now()), or null when nothing changed. */
export function nextXRange(l: ScopeLive, b: ScopeBuffer, nowMs: number): [number, number] | null {
  const span = l.span;
  let right: number;
  if (Number.isFinite(l.right)) {
    if (!l.dirty) return null;
    right = l.right;
  } else {
    right = Math.min(nowMs / 1000 + l.offset - DELAY_S, b.newestX + 0.5);
    if (!l.dirty && Math.abs(right - l.x[1]) < span / 4000) return null;
  }
  return [right - span, right];
}

/** Keeps a held right edge over the data the buffer holds. */
export function holdRight(l: ScopeLive, right: number, b: ScopeBuffer): number {
  const data = b.view(-Infinity);
  const t = data[0]!;
  if (t.length === 0) return right;
  return clampRight(right, l.span, t[0]!, t[t.length - 1]!);
}

function overlaidY(l: ScopeLive, data: Float64Array[], dtS: number): [number, number] {
  if (l.yView) return l.yView;
  if (l.fixedY) {
    l.sticky.reset();
    return l.fixedY;
  }
  let lo = Infinity;
  let hi = -Infinity;
  for (let c = 1; c < data.length; c++) {
    const [a, z] = finiteExtent(data[c]!);
    if (a < lo) lo = a;
    if (z > hi) hi = z;
  }
  return l.sticky.update(lo, hi, dtS);
}

function laneRanges(l: ScopeLive, data: Float64Array[], dtS: number): void {
  const n = data.length - 1;
  while (l.laneSticky.length < n) l.laneSticky.push(new StickyRange(2));
  l.laneY.length = n;
  for (let c = 0; c < n; c++) {
    let r: [number, number];
    if (l.fixedY) r = l.fixedY;
    else {
      const [a, z] = finiteExtent(data[c + 1]!);
      r = l.laneSticky[c]!.update(a, z, dtS);
    }
    const mid = (r[0] + r[1]) / 2;
    const half = ((r[1] - r[0]) / 2) * l.laneGain;
    l.laneY[c] = [mid - half, mid + half];
  }
}

/** Rasterises the traces of `data` (times, then channels) into the layer for the plot's area. */
export function drawTraces(l: ScopeLive, plot: uPlot, data: Float64Array[], dtS: number): void {
  if (l.stacked) laneRanges(l, data, dtS);
  else l.y = overlaidY(l, data, dtS);
  const bw = Math.round(plot.bbox.width);
  const bh = Math.round(plot.bbox.height);
  if (bw <= 0 || bh <= 0) return;
  if (!l.layer || l.layer.canvas.width !== bw || l.layer.canvas.height !== bh)
    l.layer = traceLayer(bw, bh);
  const t = l.layer;
  if (!t) return;
  const img = { width: bw, height: bh, words: t.words };
  if (!l.stacked) {
    rasterTraces(
      img,
      t.scratch,
      data[0]!,
      data.slice(1),
      l.colours,
      l.x[0],
      l.x[1],
      l.y[0],
      l.y[1],
    );
  } else {
    t.words.fill(0);
    const n = data.length - 1;
    for (let c = 0; c < n; c++) {
      const band = lane(c, n, bh);
      const sub = t.words.subarray(band.top * bw, (band.top + band.height) * bw);
      const [y0, y1] = l.laneY[c]!;
      rasterTraces(
        { width: bw, height: band.height, words: sub },
        t.scratch,
        data[0]!,
        [data[c + 1]!],
        [l.colours[c]!],
        l.x[0],
        l.x[1],
        y0,
        y1,
        false,
      );
    }
  }
  t.ctx.putImageData(t.image, 0, 0);
}

/** uPlot's draw hook: the traces over the plot area, then (stacked) the lane labels. */
export function blitTraces(l: ScopeLive, u: uPlot): void {
  const t = l.layer;
  if (!t || t.canvas.width !== Math.round(u.bbox.width)) return;
  const left = Math.round(u.bbox.left);
  const top = Math.round(u.bbox.top);
  u.ctx.drawImage(t.canvas, left, top);
  if (l.stacked) drawLaneLabels(l, u.ctx, left, top, t.canvas.width, t.canvas.height);
}

function drawLaneLabels(
  l: ScopeLive,
  ctx: CanvasRenderingContext2D,
  left: number,
  top: number,
  width: number,
  height: number,
): void {
  const n = l.laneY.length;
  const dpr = typeof devicePixelRatio === "number" ? devicePixelRatio : 1;
  ctx.save();
  ctx.font = `${Math.round(11 * dpr)}px system-ui, sans-serif`;
  ctx.textBaseline = "top";
  ctx.strokeStyle = "rgba(31, 35, 40, 0.15)";
  for (let c = 0; c < n; c++) {
    const band = lane(c, n, height);
    const y = top + band.top;
    if (c > 0) {
      ctx.beginPath();
      ctx.moveTo(left, y + 0.5);
      ctx.lineTo(left + width, y + 0.5);
      ctx.stroke();
    }
    if (band.height < 12 * dpr) continue;
    const [y0, y1] = l.laneY[c]!;
    const unit = l.unit ? ` ${l.unit}` : "";
    const text = `${l.names[c] ?? ""}  ${formatValue(y0)} … ${formatValue(y1)}${unit}`;
    ctx.fillStyle = "rgba(255, 255, 255, 0.8)";
    ctx.fillRect(left + 2, y + 1, ctx.measureText(text).width + 6, 14 * dpr);
    ctx.fillStyle = "#1f2328";
    ctx.fillText(text, left + 5, y + 2);
  }
  ctx.restore();
}
