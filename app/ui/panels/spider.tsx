/**
 * Spider plot (paper III-C, Fig. 3): one axis per channel, the latest value of each (optionally
 * smoothed: a moving mean, or a moving mean of |x| — the envelope of raw EMG), autoscaled (the
 * outer ring widens at once and narrows over ~3 s) or fixed. Drawn on a canvas, at most once per
 * animation frame and only when new data arrived. Matrices show their newest row.
 */
import { useCallback, useEffect, useMemo, useRef, useState, type ReactNode } from "react";
import type { DataMessage } from "../../engine/protocol";
import { useBlockData } from "../client/hooks";
import {
  Smoother,
  StickyRange,
  channelColor,
  channelLabel,
  finiteExtent,
  formatTick,
  niceTicks,
  type Reduce,
} from "./channels";
import { fitCanvas, readTheme, useWidth, type Theme } from "./canvas";
import { REDUCE_LABEL, RangeInputs, ReduceControls, withAlpha } from "./controls";
import { countDraw, onFrame, viewStats } from "./frame";
import type { OutputInfo, ViewProps } from "./view-props";

export interface SpiderSettings {
  /** undefined: latest below 100 Hz, envelope above (raw EMG). */
  reduce?: Reduce;
  tauS: number;
  scale: "auto" | "fixed";
  min: number;
  max: number;
}

export const SPIDER_DEFAULTS: SpiderSettings = {
  tauS: 0.3,
  scale: "auto",
  min: 0,
  max: 1,
};

/** Axes drawn at most (more channels: the first ones, with a note). */
export const SPIDER_MAX_AXES = 64;
const HEIGHT = 300;

export function SpiderPlot({
  block,
  output,
  active,
  settings,
  onSettings,
  tools,
}: ViewProps<SpiderSettings>): ReactNode {
  const { rows, cols } = output.shape;
  const n = Math.min(cols, SPIDER_MAX_AXES);
  const statsKey = `spider:${block.name}.${output.name}`;
  const canvas = useRef<HTMLCanvasElement>(null);
  const wrap = useRef<HTMLDivElement>(null);
  const reduce: Reduce = settings.reduce ?? (block.desiredRate > 100 ? "envelope" : "latest");
  const smoother = useMemo(() => new Smoother(n, reduce, settings.tauS), [n]);
  smoother.mode = reduce;
  smoother.tauS = settings.tauS;
  const live = useRef({
    dirty: false,
    width: 0,
    range: new StickyRange(3, 0),
    last: 0,
    settings,
    theme: null as Theme | null,
  });
  live.current.settings = settings;
  const [hasData, setHasData] = useState(false);

  useEffect(() => smoother.reset(), [reduce, smoother]);

  const onData = useCallback(
    (m: DataMessage) => {
      const stride = m.rows * m.cols;
      const rowOff = (m.rows - 1) * m.cols;
      for (let e = 0; e < m.t.length; e++) smoother.push(m.t[e]!, m.v, e * stride + rowOff);
      live.current.dirty = true;
      const s = viewStats(statsKey);
      s.messages++;
      s.events += m.t.length;
      s.skipped += m.skipped;
      if (!hasData) setHasData(true);
    },
    [smoother, statsKey, hasData],
  );
  useBlockData(block.name, output.name, onData, active && cols > 0, reduce === "latest" ? 30 : 200);

  const onResize = useCallback((w: number) => {
    const l = live.current;
    l.width = w;
    l.dirty = true;
    if (canvas.current) l.theme = readTheme(canvas.current);
  }, []);
  useWidth(wrap, onResize);

  useEffect(() => {
    if (!active) return undefined;
    const l = live.current;
    const stats = viewStats(statsKey);
    return onFrame((now) => {
      const c = canvas.current;
      if (!l.dirty || !c || l.width <= 0) return;
      l.dirty = false;
      const t0 = performance.now();
      const s = l.settings;
      let lo: number;
      let hi: number;
      if (s.scale === "fixed" && s.max > s.min) {
        lo = s.min;
        hi = s.max;
      } else {
        const [a, z] = finiteExtent(smoother.out);
        [lo, hi] = l.range.update(
          Math.min(0, a),
          Math.max(0, z),
          l.last ? (now - l.last) / 1000 : 0,
        );
      }
      l.last = now;
      l.theme ??= readTheme(c);
      const label = (k: number): string => channelLabel(output, k);
      if (n < 3) drawBars(c, l.theme, l.width, HEIGHT, smoother.out, lo, hi, label);
      else drawSpider(c, l.theme, l.width, HEIGHT, smoother.out, lo, hi, label);
      countDraw(stats, performance.now() - t0);
    });
  }, [active, smoother, statsKey, output, n]);

  return (
    <div className="mp-spider" data-view="spider" data-block={block.name} data-port={output.name}>
      <div className="mp-toolbar" role="toolbar" aria-label="Spider plot settings">
        {tools}
        <ReduceControls settings={{ reduce, tauS: settings.tauS }} onSettings={onSettings} />
        <label className="mp-field">
          Scale
          <select
            value={settings.scale}
            onChange={(e) => onSettings({ scale: e.target.value as "auto" | "fixed" })}
          >
            <option value="auto">auto</option>
            <option value="fixed">fixed</option>
          </select>
        </label>
        {settings.scale === "fixed" && (
          <RangeInputs
            min={settings.min}
            max={settings.max}
            onChange={(min, max) => onSettings({ min, max })}
          />
        )}
      </div>
      <div ref={wrap} className="mp-canvas-wrap" style={{ height: HEIGHT }}>
        <canvas
          ref={canvas}
          role="img"
          aria-label={`Spider plot of ${block.name}.${output.name}: ${n} axes (${axisNames(output, n)})`}
        />
      </div>
      <p className="mp-foot">
        {!hasData
          ? active
            ? "waiting for data…"
            : "hidden: no data is watched"
          : `${n < 3 ? `${n} bar${n > 1 ? "s" : ""} (a spider needs 3 axes)` : `${n} axes`}, ${REDUCE_LABEL[reduce]}`}
        {cols > SPIDER_MAX_AXES ? ` — the first ${SPIDER_MAX_AXES} of ${cols} channels` : ""}
        {rows > 1 ? ` · newest row of each [${rows}, ${cols}] event` : ""}
      </p>
    </div>
  );
}

/** The axes' names for the plot's text alternative ("fist, open, pinch", the first 32). */
function axisNames(output: OutputInfo, n: number): string {
  const names = Array.from({ length: Math.min(n, 32) }, (_, k) => channelLabel(output, k));
  return names.join(", ") + (n > 32 ? ", …" : "");
}

function drawSpider(
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
  const n = values.length;
  const cx = width / 2;
  const cy = height / 2;
  const labels = n <= 32;
  const R = Math.max(10, Math.min(width, height) / 2 - (labels ? 26 : 10));
  const angle = (k: number): number => -Math.PI / 2 + (2 * Math.PI * k) / n;
  const span = hi - lo || 1;
  // Rings at round values (and the outer edge).
  const ticks = niceTicks(lo, hi, 4).filter((t) => t > lo + span * 0.05 && t <= hi);
  const rings = ticks.map((t) => (R * (t - lo)) / span);
  if (!rings.length || rings[rings.length - 1]! < R - 1) rings.push(R);
  ctx.lineWidth = 1;
  ctx.strokeStyle = theme.grid;
  for (const rr of rings) {
    ctx.beginPath();
    if (n < 3) ctx.arc(cx, cy, rr, 0, 2 * Math.PI);
    else
      for (let k = 0; k <= n; k++) {
        const a = angle(k % n);
        const x = cx + rr * Math.cos(a);
        const y = cy + rr * Math.sin(a);
        if (k === 0) ctx.moveTo(x, y);
        else ctx.lineTo(x, y);
      }
    ctx.stroke();
  }
  // Spokes and labels.
  ctx.textAlign = "center";
  ctx.textBaseline = "middle";
  for (let k = 0; k < n; k++) {
    const a = angle(k);
    ctx.strokeStyle = theme.grid;
    ctx.beginPath();
    ctx.moveTo(cx, cy);
    ctx.lineTo(cx + R * Math.cos(a), cy + R * Math.sin(a));
    ctx.stroke();
    if (labels) {
      ctx.fillStyle = theme.fg;
      ctx.fillText(label(k), cx + (R + 14) * Math.cos(a), cy + (R + 12) * Math.sin(a));
    }
  }
  // The values.
  const radius = (v: number): number => {
    if (!Number.isFinite(v)) return 0;
    return R * Math.max(0, Math.min(1, (v - lo) / span));
  };
  ctx.beginPath();
  for (let k = 0; k <= n; k++) {
    const a = angle(k % n);
    const r = radius(values[k % n]!);
    const x = cx + r * Math.cos(a);
    const y = cy + r * Math.sin(a);
    if (k === 0) ctx.moveTo(x, y);
    else ctx.lineTo(x, y);
  }
  ctx.fillStyle = withAlpha(theme.accent, 0.22);
  ctx.fill();
  ctx.strokeStyle = theme.accent;
  ctx.lineWidth = 2;
  ctx.stroke();
  // Ring values on top, between the first two axes, on a light backing.
  const step = ticks.length > 1 ? ticks[1]! - ticks[0]! : span;
  const la = n >= 2 ? (angle(0) + angle(1)) / 2 : angle(0) + Math.PI / 4;
  ctx.font = "11px system-ui, sans-serif";
  ctx.textAlign = "center";
  ctx.textBaseline = "middle";
  ticks.forEach((t) => {
    const rr = (R * (t - lo)) / span;
    const x = cx + rr * Math.cos(la);
    const y = cy + rr * Math.sin(la);
    const text = formatTick(t, step);
    const w = ctx.measureText(text).width + 4;
    ctx.fillStyle = withAlpha(theme.bg, 0.85);
    ctx.fillRect(x - w / 2, y - 6, w, 12);
    ctx.fillStyle = theme.muted;
    ctx.fillText(text, x, y);
  });
  ctx.fillStyle = theme.muted;
  ctx.textAlign = "left";
  ctx.textBaseline = "top";
  ctx.fillText(`centre ${formatTick(lo, step)}`, 2, 2);
  if (n <= 32) {
    for (let k = 0; k < n; k++) {
      const a = angle(k);
      const r = radius(values[k]!);
      ctx.fillStyle = channelColor(k);
      ctx.beginPath();
      ctx.arc(cx + r * Math.cos(a), cy + r * Math.sin(a), 3, 0, 2 * Math.PI);
      ctx.fill();
    }
  }
}

/** One or two channels: horizontal bars on the same scale (a polygon needs three axes). */
function drawBars(
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
  const n = values.length;
  const bar = Math.min(48, (height - 60) / Math.max(1, n) - 12);
  const ticks = niceTicks(lo, hi, 5);
  const step = ticks.length > 1 ? ticks[1]! - ticks[0]! : span;
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
