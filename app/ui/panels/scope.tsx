/**
 * Scope (paper III-C, Fig. 3): a time series of all or selected channels of a block output.
 * uPlot draws the axes and grid; the traces are rasterised into one image per frame
 * (trace-raster.ts: a min-max run per pixel column, as an oscilloscope draws) and blitted over
 * the plot area, which costs a fraction of stroking every segment. Samples go into per-channel
 * rings (ScopeBuffer) as data messages arrive (20 per second); the plot is redrawn at most once
 * per animation frame, with its right edge following an estimate of the engine's clock so that
 * it scrolls smoothly between messages (scope-plot.ts, scope-draw.ts).
 *
 * Channels overlaid (one amplitude axis in the output's unit) or stacked (a lane each, with its
 * name, range and unit). Autoscale (widens at once, narrows over ~2 s) or a fixed Y range. Pause
 * holds the picture; the wheel zooms time (Shift: amplitude), a drag pans (and pauses), a double
 * click resets; the readout gives the time and each channel's value under the cursor
 * (scope-pointer.ts). The spectrum (Welch PSD, median frequency) is of the window in view
 * (scope-spectrum.tsx); CSV and PNG export it (scope-export.ts).
 */
import {
  useCallback,
  useEffect,
  useMemo,
  useRef,
  useState,
  type ReactNode,
  type RefObject,
} from "react";
import type uPlot from "uplot";
import type { DataMessage } from "../../engine/protocol";
import { useBlockData } from "../client/hooks";
import { StickyRange, channelColor, channelLabel, defaultChannels } from "./channels";
import { viewStats } from "./frame";
import { ScopeBuffer, type MatrixMode } from "./scope-buffer";
import type { ScopeLive } from "./scope-draw";
import { downloadCsv, downloadPng } from "./scope-export";
import { defaultPlotHeight, useDrawLoop, usePlot } from "./scope-plot";
import { attachPointer, isZoomed, readoutLines, showReadout } from "./scope-pointer";
import { ScopeSpectrum } from "./scope-spectrum";
import { ScopeToolbar } from "./scope-toolbar";
import { rgbaWord } from "./trace-raster";
import type { OutputInfo, ViewProps } from "./view-props";

export { WINDOWS_S } from "./scope-toolbar";

export interface ScopeSettings {
  /** Plotted channels (column indices); undefined: the first 16. */
  channels?: number[];
  windowS: number;
  yMode: "auto" | "fixed";
  yMin: number;
  yMax: number;
  matrixMode: MatrixMode;
  paused: boolean;
  layout: "overlaid" | "stacked";
  spectrum: boolean;
}

export const SCOPE_DEFAULTS: ScopeSettings = {
  windowS: 5,
  yMode: "auto",
  yMin: -1,
  yMax: 1,
  matrixMode: "newest",
  paused: false,
  layout: "overlaid",
  spectrum: false,
};

/**
 * Events per second asked of the engine: about 1200 points across the window (2–3 per pixel
 * column of a docked panel), at most 1000/s; with the spectrum on, the source's rate up to
 * 1000/s (a decimated stream would alias). The engine keeps every n-th event (its watch
 * decimates), which is what the footer reports.
 */
export function scopeMaxRate(windowS: number, spectrumOfRate = 0): number {
  const base = Math.max(25, Math.min(1000, Math.round(1200 / windowS)));
  return Math.max(base, Math.min(1000, Math.round(spectrumOfRate)));
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

function newLive(settings: ScopeSettings): ScopeLive {
  return {
    buffer: null,
    plot: null,
    dirty: false,
    offset: NaN,
    x: [0, 1],
    y: [-1, 1],
    sticky: new StickyRange(2),
    laneSticky: [],
    laneY: [],
    lastDraw: 0,
    span: settings.windowS,
    right: NaN,
    yView: null,
    laneGain: 1,
    stacked: false,
    fixedY: null,
    colours: new Uint32Array(0),
    names: [],
    unit: "",
    layer: null,
  };
}

/** The rings, and the callback that fills them from data messages. */
function useScopeData(
  props: ViewProps<ScopeSettings>,
  channels: number[],
  matrixMode: MatrixMode,
  live: { current: ScopeLive },
  statsKey: string,
  counts: { current: { received: number; skipped: number } },
): void {
  const { block, output, active, settings } = props;
  const rows = output.shape.rows;
  const maxRate = scopeMaxRate(settings.windowS, settings.spectrum ? block.desiredRate : 0);
  const expected =
    Math.min(block.desiredRate > 0 ? block.desiredRate : maxRate, maxRate) *
    (matrixMode === "flatten" ? rows : 1);
  // A new channel set or matrix mode: new rings (capacity for the window at the expected rate;
  // the window and rate are read at creation only: the rings grow when they hold too little).
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
  const paused = settings.paused;
  const onData = useCallback(
    (m: DataMessage) => {
      const l = live.current;
      const b = l.buffer;
      if (!b || paused) return;
      b.append(m.t, m.v, m.rows, m.cols, matrixMode);
      const nowS = performance.now() / 1000;
      const cand = b.newestX - nowS;
      if (!Number.isFinite(l.offset) || cand > l.offset || cand < l.offset - 2) l.offset = cand;
      else l.offset += (cand - l.offset) * 0.02;
      l.dirty = true;
      const s = viewStats(statsKey);
      s.messages++;
      s.events += m.t.length;
      s.skipped += m.skipped;
      counts.current.received += m.t.length;
      counts.current.skipped += m.skipped;
    },
    [statsKey, paused, matrixMode, live, counts],
  );
  useBlockData(
    block.name,
    output.name,
    onData,
    active && !paused && output.shape.cols > 0,
    maxRate,
  );
}

/** The view's settings copied where the frame loop reads them (no React render per frame). */
function syncLive(l: ScopeLive, s: ScopeSettings, output: OutputInfo, channels: number[]): void {
  l.stacked = s.layout === "stacked" && channels.length > 1;
  l.fixedY = s.yMode === "fixed" ? [s.yMin, s.yMax] : null;
  l.names = channels.map((c) => channelLabel(output, c));
  l.unit = output.unit ?? "";
}

/** Pause holds the picture's right edge; resume follows the data again. */
function usePauseHold(live: { current: ScopeLive }, paused: boolean, windowS: number): void {
  useEffect(() => {
    const l = live.current;
    l.right = paused ? l.x[1] : NaN;
    l.dirty = true;
  }, [paused, live]);
  useEffect(() => {
    const l = live.current;
    l.span = windowS;
    l.dirty = true;
  }, [windowS, live]);
}

function Footer({
  props,
  channels,
  matrixMode,
  info,
}: {
  props: ViewProps<ScopeSettings>;
  channels: number[];
  matrixMode: MatrixMode;
  info: { received: number; skipped: number };
}): ReactNode {
  const { settings, active, output } = props;
  const { rows, cols } = output.shape;
  const shownPerS = info.received * 2;
  const totalPerS = (info.received + info.skipped) * 2;
  if (settings.paused)
    return (
      <p className="mp-foot">
        paused — no data is watched: wheel zooms (Shift: amplitude), drag pans, double-click resets
      </p>
    );
  if (!(totalPerS > 0))
    return <p className="mp-foot">{active ? "waiting for data…" : "hidden: no data is watched"}</p>;
  return (
    <p className="mp-foot">
      {totalPerS.toFixed(0)} events/s
      {info.skipped > 0
        ? `, plotting 1 in ${Math.round(totalPerS / Math.max(1, shownPerS))} (${shownPerS.toFixed(0)}/s)`
        : ""}
      {" · "}
      {channels.length} of {cols} channels
      {rows > 1
        ? ` · ${matrixMode === "newest" ? "newest row" : "all rows"} of each [${rows}, ${cols}] event`
        : ""}
    </p>
  );
}

function Legend({
  output,
  channels,
  onSettings,
}: {
  output: OutputInfo;
  channels: number[];
  onSettings: (p: Partial<ScopeSettings>) => void;
}): ReactNode {
  return (
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
      {output.unit ? <span className="mp-muted mp-unit">values in {output.unit}</span> : null}
    </div>
  );
}

/**
 * The pointer's part (wired once per plot, reading the latest settings through a ref): the
 * readout, zoom and pan, and the zoom's reset.
 */
function useScopePointer(
  live: { current: ScopeLive },
  windowS: number,
  onSettings: (p: Partial<ScopeSettings>) => void,
) {
  const readout = useRef<HTMLDivElement>(null);
  const cursor = useRef<HTMLDivElement>(null);
  const pointer = useRef<number | null>(null);
  const [zoomed, setZoomed] = useState(false);
  const latest = useRef({ windowS, onSettings });
  latest.current = { windowS, onSettings };
  const updateReadout = useCallback(() => {
    const l = live.current;
    const px = pointer.current;
    if (!readout.current || !cursor.current || !l.plot) return;
    const lines = px === null ? null : readoutLines(l, l.plot, px);
    showReadout(readout.current, cursor.current, lines, px ?? 0, l.plot.over.offsetLeft);
  }, [live]);
  const resetZoom = useCallback(() => {
    const l = live.current;
    l.span = latest.current.windowS;
    l.yView = null;
    l.laneGain = 1;
    l.dirty = true;
    setZoomed(false);
  }, [live]);
  const attach = useCallback(
    (u: uPlot) =>
      attachPointer(
        u,
        live.current,
        () => Math.max(latest.current.windowS, live.current.span),
        (px) => {
          pointer.current = px;
          updateReadout();
        },
        {
          onView: () => setZoomed(isZoomed(live.current, latest.current.windowS)),
          onHold: () => latest.current.onSettings({ paused: true }),
          onReset: resetZoom,
        },
      ),
    [live, resetZoom, updateReadout],
  );
  return { readout, cursor, pointer, zoomed, updateReadout, resetZoom, attach };
}

/** The plot's box: the plot (its height drags), the cursor line and the readout over it. */
function PlotBox({
  host,
  cursor,
  readout,
  height,
  label,
}: {
  host: RefObject<HTMLDivElement | null>;
  cursor: RefObject<HTMLDivElement | null>;
  readout: RefObject<HTMLDivElement | null>;
  height: number;
  label: string;
}): ReactNode {
  return (
    <div className="mp-plot-box">
      <div
        className="mp-plot mp-resizable"
        ref={host}
        style={{ height }}
        aria-label={label}
        role="img"
      />
      <div ref={cursor} className="mp-cursor" hidden aria-hidden="true" />
      <div
        ref={readout}
        className="mp-readout"
        hidden
        aria-live="off"
        aria-label="Values under the cursor"
      />
    </div>
  );
}

export function Scope(props: ViewProps<ScopeSettings>): ReactNode {
  const { block, output, active, settings, onSettings, tools } = props;
  const { rows, cols } = output.shape;
  const channels = useMemo(
    () => (settings.channels ?? defaultChannels(cols)).filter((c) => c < cols),
    [settings.channels, cols],
  );
  const matrixMode: MatrixMode = rows > 1 ? settings.matrixMode : "newest";
  const statsKey = `scope:${block.name}.${output.name}`;
  const host = useRef<HTMLDivElement>(null);
  const [info, setInfo] = useState({ received: 0, skipped: 0 });
  const counts = useRef({ received: 0, skipped: 0, lastInfo: 0 });
  const live = useRef<ScopeLive>(newLive(settings));
  syncLive(live.current, settings, output, channels);
  useScopeData(props, channels, matrixMode, live, statsKey, counts);
  usePauseHold(live, settings.paused, settings.windowS);
  const stacked = live.current.stacked;
  const ptr = useScopePointer(live, settings.windowS, onSettings);
  useEffect(() => {
    live.current.colours = Uint32Array.from(channels, (c) => colourWord(channelColor(c)));
    live.current.dirty = true;
  }, [channels]);
  usePlot(host, live, ptr.attach, [channels, output, stacked, output.unit, ptr.attach]);
  const { pointer, updateReadout } = ptr;
  const afterDraw = useCallback(
    (now: number) => {
      if (pointer.current !== null) updateReadout();
      const c = counts.current;
      // The numbers under the plot: 2 renders a second.
      if (now - c.lastInfo > 500) {
        c.lastInfo = now;
        setInfo({ received: c.received, skipped: c.skipped });
        c.received = 0;
        c.skipped = 0;
      }
    },
    [pointer, updateReadout],
  );
  useDrawLoop(live, active, statsKey, afterDraw);
  const l = live.current;
  return (
    <div
      className="mp-scope"
      data-view="scope"
      data-block={block.name}
      data-port={output.name}
      data-layout={stacked ? "stacked" : "overlaid"}
    >
      <ScopeToolbar
        settings={settings}
        onSettings={onSettings}
        output={output}
        channels={channels}
        matrixMode={matrixMode}
        zoomed={ptr.zoomed}
        onResetZoom={ptr.resetZoom}
        onCsv={() => downloadCsv(l, block.name, output.name)}
        onPng={() => {
          const c = l.plot?.ctx.canvas;
          if (c) downloadPng(c, l.names, channels, block.name, output.name);
        }}
        suggestY={() => l.y}
        tools={tools}
      />
      <PlotBox
        host={host}
        cursor={ptr.cursor}
        readout={ptr.readout}
        height={defaultPlotHeight(stacked, channels.length)}
        label={`Scope of ${block.name}.${output.name}`}
      />
      <Legend output={output} channels={channels} onSettings={onSettings} />
      {settings.spectrum && (
        <ScopeSpectrum
          live={live}
          channels={channels}
          names={l.names}
          unit={l.unit}
          active={active}
        />
      )}
      <Footer props={props} channels={channels} matrixMode={matrixMode} info={info} />
    </div>
  );
}
