/**
 * Scope (paper III-C, Fig. 3): a time series of all or selected channels of a block output.
 * uPlot draws the axes and grid; the traces are rasterised into one image per frame
 * (trace-raster.ts: a min-max run per pixel column, as an oscilloscope draws) and blitted over
 * the plot area, which costs a fraction of stroking every segment. Samples go into per-channel
 * rings (ScopeBuffer) as data messages arrive (20 per second); the plot is redrawn at most once
 * per animation frame, with its right edge following an estimate of the engine's clock so that
 * it scrolls smoothly between messages.
 * Autoscale (widens at once, narrows over ~2 s) or a fixed Y range; pause (stops watching and
 * freezes the picture); time window; channel selection (at most 16 plotted by default).
 */
import { useCallback, useEffect, useMemo, useRef, useState, type ReactNode } from "react";
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";
import type { DataMessage } from "../../engine/protocol";
import { useBlockData } from "../client/hooks";
import {
  StickyRange,
  channelColor,
  channelLabel,
  defaultChannels,
  finiteExtent,
  formatTick,
} from "./channels";
import { ChannelPicker } from "./channel-picker";
import { PlayPauseIcon, RangeInputs } from "./controls";
import { countDraw, onFrame, viewStats } from "./frame";
import { ScopeBuffer, type MatrixMode } from "./scope-buffer";
import { rasterTraces, rgbaWord, traceScratch, type TraceScratch } from "./trace-raster";
import type { ViewProps } from "./view-props";

export interface ScopeSettings {
  /** Plotted channels (column indices); undefined: the first 16. */
  channels?: number[];
  windowS: number;
  yMode: "auto" | "fixed";
  yMin: number;
  yMax: number;
  matrixMode: MatrixMode;
  paused: boolean;
}

export const SCOPE_DEFAULTS: ScopeSettings = {
  windowS: 5,
  yMode: "auto",
  yMin: -1,
  yMax: 1,
  matrixMode: "newest",
  paused: false,
};

export const WINDOWS_S = [2, 5, 10, 30] as const;

/**
 * Events per second asked of the engine: about 1200 points across the window (2–3 per pixel
 * column of a docked panel), at most 1000/s. The engine keeps every n-th event (its watch
 * decimates), which is what the footer reports.
 */
export function scopeMaxRate(windowS: number): number {
  return Math.max(25, Math.min(1000, Math.round(1200 / windowS)));
}

const colourWords = new Map<string, number>();

/** A CSS colour as an ImageData word (parsed once by a 1 × 1 canvas, then cached). */
function colourWord(css: string): number {
  let w = colourWords.get(css);
  if (w === undefined) {
    const ctx = document.createElement("canvas").getContext("2d", { willReadFrequently: true });
    if (ctx) {
      ctx.fillStyle = "#000";
      ctx.fillStyle = css;
      ctx.fillRect(0, 0, 1, 1);
      const [r, g, b] = ctx.getImageData(0, 0, 1, 1).data;
      w = rgbaWord(r!, g!, b!);
    } else w = rgbaWord(0, 0, 0);
    colourWords.set(css, w);
  }
  return w;
}

/** The offscreen image the traces are drawn into, sized to the plot area (device pixels). */
interface TraceLayer {
  canvas: HTMLCanvasElement;
  ctx: CanvasRenderingContext2D;
  image: ImageData;
  words: Uint32Array;
  scratch: TraceScratch;
}

function traceLayer(width: number, height: number): TraceLayer | null {
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

/** How far behind the newest data the right edge runs: a little over one 20 Hz flush. */
const DELAY_S = 0.1;
const PLOT_HEIGHT = 220;

export function Scope({
  block,
  output,
  active,
  settings,
  onSettings,
  tools,
}: ViewProps<ScopeSettings>): ReactNode {
  const { rows, cols } = output.shape;
  const channels = useMemo(
    () => (settings.channels ?? defaultChannels(cols)).filter((c) => c < cols),
    [settings.channels, cols],
  );
  const matrixMode: MatrixMode = rows > 1 ? settings.matrixMode : "newest";
  const maxRate = scopeMaxRate(settings.windowS);
  const statsKey = `scope:${block.name}.${output.name}`;
  const host = useRef<HTMLDivElement>(null);
  const [info, setInfo] = useState({ received: 0, skipped: 0 });

  // Everything the frame loop and the data callback share, without React renders.
  const live = useRef({
    buffer: null as ScopeBuffer | null,
    plot: null as uPlot | null,
    dirty: false,
    /** Engine time (plot x) minus performance.now() seconds, from the freshest data seen. */
    offset: NaN,
    x: [0, 1] as [number, number],
    y: [-1, 1] as [number, number],
    sticky: new StickyRange(2),
    lastDraw: 0,
    settings,
    received: 0,
    skipped: 0,
    lastInfo: 0,
    /** The traces to blit (drawn in the frame loop, blitted by uPlot's draw hook). */
    layer: null as TraceLayer | null,
    colours: new Uint32Array(0),
  });
  live.current.settings = settings;

  // A new channel set or matrix mode: new rings (capacity for the window at the expected rate).
  const expected =
    Math.min(block.desiredRate > 0 ? block.desiredRate : maxRate, maxRate) *
    (matrixMode === "flatten" ? rows : 1);
  // (The window and rate are read at creation only: the rings grow when they hold too little.)
  const buffer = useMemo(
    () =>
      new ScopeBuffer(
        channels,
        Math.ceil(expected * settings.windowS * 1.25) + 64,
        settings.windowS,
      ),
    [channels, matrixMode],
  );
  buffer.windowS = settings.windowS;
  live.current.buffer = buffer;

  const onData = useCallback(
    (m: DataMessage) => {
      const l = live.current;
      const b = l.buffer;
      if (!b || l.settings.paused) return;
      b.append(m.t, m.v, m.rows, m.cols, l.settings.matrixMode);
      const nowS = performance.now() / 1000;
      const cand = b.newestX - nowS;
      if (!Number.isFinite(l.offset) || cand > l.offset || cand < l.offset - 2) l.offset = cand;
      else l.offset += (cand - l.offset) * 0.02;
      l.dirty = true;
      const s = viewStats(statsKey);
      s.messages++;
      s.events += m.t.length;
      s.skipped += m.skipped;
      l.received += m.t.length;
      l.skipped += m.skipped;
    },
    [statsKey],
  );
  useBlockData(block.name, output.name, onData, active && !settings.paused && cols > 0, maxRate);

  // The plot: created per channel set, destroyed on unmount.
  useEffect(() => {
    const el = host.current;
    if (!el) return undefined;
    const l = live.current;
    const css = getComputedStyle(el);
    const fg = css.getPropertyValue("--mp-fg").trim() || "#1d2430";
    const grid = css.getPropertyValue("--mp-grid").trim() || "rgba(0,0,0,0.08)";
    const axis = (extra: Partial<uPlot.Axis>): uPlot.Axis => ({
      stroke: fg,
      grid: { stroke: grid, width: 1 },
      ticks: { stroke: grid, width: 1, size: 4 },
      font: "11px system-ui, sans-serif",
      ...extra,
    });
    l.colours = Uint32Array.from(channels, (c) => colourWord(channelColor(c)));
    const opts: uPlot.Options = {
      width: Math.max(100, el.clientWidth),
      height: PLOT_HEIGHT,
      legend: { show: false },
      cursor: { show: false },
      hooks: {
        // After the axes and grid: the traces, as one image over the plot area.
        draw: [
          (u) => {
            const t = l.layer;
            if (t && t.canvas.width === Math.round(u.bbox.width))
              u.ctx.drawImage(t.canvas, Math.round(u.bbox.left), Math.round(u.bbox.top));
          },
        ],
      },
      scales: {
        x: { time: false, range: () => [l.x[0], l.x[1]] },
        y: { range: () => [l.y[0], l.y[1]] },
      },
      axes: [
        axis({
          size: 28,
          values: (_u, splits) => {
            const step = splits.length > 1 ? Math.abs(splits[1]! - splits[0]!) : 0;
            return splits.map((v) => `${formatTick(v, step)} s`);
          },
        }),
        axis({
          size: (_u, values) =>
            values ? Math.max(3, ...values.map((v) => v.length)) * 6.6 + 12 : 40,
          values: (_u, splits) => {
            const step = splits.length > 1 ? Math.abs(splits[1]! - splits[0]!) : 0;
            return splits.map((v) => formatTick(v, step));
          },
        }),
      ],
      // One placeholder series on the y scale (so that uPlot ranges it and draws its axis);
      // the channels are drawn by rasterTraces.
      series: [{}, { label: "y", stroke: "transparent", points: { show: false } }],
    };
    const plot = new uPlot(
      opts,
      [
        [0, 1],
        [null, null],
      ],
      el,
    );
    l.plot = plot;
    l.dirty = true;
    const ro = new ResizeObserver(() => {
      const w = Math.max(100, el.clientWidth);
      if (w !== plot.width) {
        plot.setSize({ width: w, height: PLOT_HEIGHT });
        l.dirty = true;
      }
    });
    ro.observe(el);
    return () => {
      ro.disconnect();
      plot.destroy();
      if (l.plot === plot) l.plot = null;
    };
  }, [buffer, channels, output]);

  // Redraw once per frame while there is data or the window scrolls.
  useEffect(() => {
    if (!active || settings.paused) return undefined;
    const l = live.current;
    const stats = viewStats(statsKey);
    return onFrame((now) => {
      const b = l.buffer;
      const plot = l.plot;
      if (!b || !plot || b.count === 0) return;
      const nowS = now / 1000;
      const w = l.settings.windowS;
      const right = Math.min(nowS + l.offset - DELAY_S, b.newestX + 0.5);
      if (!l.dirty && Math.abs(right - l.x[1]) < w / 4000) return;
      const t0 = performance.now();
      const data = b.view(right - w, right);
      l.x = [right - w, right];
      if (l.settings.yMode === "fixed") {
        l.y = [l.settings.yMin, l.settings.yMax];
        l.sticky.reset();
      } else {
        let lo = Infinity;
        let hi = -Infinity;
        for (let c = 1; c < data.length; c++) {
          const [a, z] = finiteExtent(data[c]!);
          if (a < lo) lo = a;
          if (z > hi) hi = z;
        }
        l.y = l.sticky.update(lo, hi, l.lastDraw ? (now - l.lastDraw) / 1000 : 0);
      }
      const bw = Math.round(plot.bbox.width);
      const bh = Math.round(plot.bbox.height);
      if (bw > 0 && bh > 0) {
        if (!l.layer || l.layer.canvas.width !== bw || l.layer.canvas.height !== bh)
          l.layer = traceLayer(bw, bh);
        const t = l.layer;
        if (t) {
          rasterTraces(
            { width: bw, height: bh, words: t.words },
            t.scratch,
            data[0]!,
            data.slice(1),
            l.colours,
            l.x[0],
            l.x[1],
            l.y[0],
            l.y[1],
          );
          t.ctx.putImageData(t.image, 0, 0);
        }
      }
      plot.batch(() => plot.setData([l.x, [null, null]]));
      l.dirty = false;
      l.lastDraw = now;
      countDraw(stats, performance.now() - t0);
      // The numbers under the plot: 2 renders a second.
      if (now - l.lastInfo > 500) {
        l.lastInfo = now;
        setInfo({ received: l.received, skipped: l.skipped });
        l.received = 0;
        l.skipped = 0;
      }
    });
  }, [active, settings.paused, statsKey]);

  const shownPerS = info.received * 2;
  const totalPerS = (info.received + info.skipped) * 2;
  return (
    <div className="mp-scope" data-view="scope" data-block={block.name} data-port={output.name}>
      <div className="mp-toolbar" role="toolbar" aria-label="Scope settings">
        {tools}
        <button
          type="button"
          className={`mp-btn${settings.paused ? " mp-on" : ""}`}
          aria-pressed={settings.paused}
          onClick={() => onSettings({ paused: !settings.paused })}
          title={
            settings.paused
              ? "Resume: watch the data again"
              : "Pause: freeze the picture (stops the data)"
          }
        >
          <PlayPauseIcon paused={settings.paused} /> {settings.paused ? "Resume" : "Pause"}
        </button>
        <label className="mp-field">
          Window
          <select
            value={settings.windowS}
            onChange={(e) => onSettings({ windowS: Number(e.target.value) })}
          >
            {WINDOWS_S.map((w) => (
              <option key={w} value={w}>
                {w} s
              </option>
            ))}
          </select>
        </label>
        <label className="mp-field">
          Y
          <select
            value={settings.yMode}
            onChange={(e) => onSettings({ yMode: e.target.value as "auto" | "fixed" })}
          >
            <option value="auto">auto</option>
            <option value="fixed">fixed</option>
          </select>
        </label>
        {settings.yMode === "fixed" && (
          <RangeInputs
            min={settings.yMin}
            max={settings.yMax}
            onChange={(yMin, yMax) => onSettings({ yMin, yMax })}
            suggest={() => live.current.y}
          />
        )}
        {rows > 1 && (
          <label
            className="mp-field"
            title={`Each event is a [${rows}, ${cols}] matrix (e.g. a window)`}
          >
            Rows
            <select
              value={matrixMode}
              onChange={(e) => onSettings({ matrixMode: e.target.value as MatrixMode })}
            >
              <option value="newest">newest row</option>
              <option value="flatten">all rows, in time order</option>
            </select>
          </label>
        )}
        <ChannelPicker
          count={cols}
          selected={channels}
          output={output}
          onChange={(c) => onSettings({ channels: c })}
        />
      </div>
      <div
        className="mp-plot"
        ref={host}
        style={{ height: PLOT_HEIGHT }}
        aria-label={`Scope of ${block.name}.${output.name}`}
        role="img"
      />
      <div className="mp-legend" aria-label="Channels">
        {channels.length <= 32 ? (
          channels.map((c) => (
            <button
              type="button"
              key={c}
              className="mp-chip"
              title={`Hide channel ${channelLabel(output, c)}`}
              onClick={() => onSettings({ channels: channels.filter((x) => x !== c) })}
            >
              <span
                className="mp-swatch"
                style={{ background: channelColor(c) }}
                aria-hidden="true"
              />
              {channelLabel(output, c)}
            </button>
          ))
        ) : (
          <span className="mp-muted">{channels.length} channels (colours repeat in hue)</span>
        )}
      </div>
      <p className="mp-foot">
        {settings.paused ? (
          "paused — the picture is frozen and no data is watched"
        ) : totalPerS > 0 ? (
          <>
            {totalPerS.toFixed(0)} events/s
            {info.skipped > 0
              ? `, plotting 1 in ${Math.round(totalPerS / Math.max(1, shownPerS))} (${shownPerS.toFixed(0)}/s)`
              : ""}
            {" · "}
            {channels.length} of {cols} channels
            {rows > 1
              ? ` · ${matrixMode === "newest" ? "newest row" : "all rows"} of each [${rows}, ${cols}] event`
              : ""}
          </>
        ) : active ? (
          "waiting for data…"
        ) : (
          "hidden: no data is watched"
        )}
      </p>
    </div>
  );
}
