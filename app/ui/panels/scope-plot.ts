/**
 * The scope's uPlot: created per channel set and layout, resized with its box (the user can drag
 * its height; a wider panel widens it), drawn once per animation frame while there is news
 * (new data, the window scrolling, a zoom or pan), and nothing when nothing changed.
 */
import { useEffect, type RefObject } from "react";
import uPlot from "uplot";
import "uplot/dist/uPlot.min.css";
import { formatTick } from "./channels";
import { countDraw, onFrame, viewStats } from "./frame";
import { blitTraces, drawTraces, holdRight, nextXRange, type ScopeLive } from "./scope-draw";

/**
 * uPlot's target as a function: uPlot tests `el instanceof HTMLElement`, which is false for an
 * element of another window (a panel popped out into its own window).
 */
type Mount = Exclude<ConstructorParameters<typeof uPlot>[2], HTMLElement | undefined>;

export function mountIn(el: HTMLElement): Mount {
  return (u, init) => {
    el.appendChild(u.root);
    (init as () => void)();
  };
}

/** The plot's height when nobody resized it: taller when channels are stacked. */
export function defaultPlotHeight(stacked: boolean, channels: number): number {
  return stacked ? Math.max(220, Math.min(640, 40 * channels)) : 220;
}

function axes(el: HTMLElement, l: ScopeLive): uPlot.Axis[] {
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
  const step = (splits: number[]): number =>
    splits.length > 1 ? Math.abs(splits[1]! - splits[0]!) : 0;
  return [
    axis({
      size: 28,
      values: (_u, splits) => splits.map((v) => `${formatTick(v, step(splits))} s`),
    }),
    axis({
      show: !l.stacked,
      ...(l.unit ? { label: l.unit, labelSize: 16, labelFont: "11px system-ui, sans-serif" } : {}),
      size: (_u, values) => (values ? Math.max(3, ...values.map((v) => v.length)) * 6.6 + 12 : 40),
      values: (_u, splits) => splits.map((v) => formatTick(v, step(splits))),
    }),
  ];
}

function createPlot(el: HTMLElement, l: ScopeLive): uPlot {
  const opts: uPlot.Options = {
    width: Math.max(100, el.clientWidth),
    height: Math.max(80, el.clientHeight),
    legend: { show: false },
    cursor: { show: false },
    // After the axes and grid: the traces, as one image over the plot area.
    hooks: { draw: [(u) => blitTraces(l, u)] },
    scales: {
      x: { time: false, range: () => [l.x[0], l.x[1]] },
      y: { range: () => [l.y[0], l.y[1]] },
    },
    axes: axes(el, l),
    // One placeholder series on the y scale (so that uPlot ranges it and draws its axis); the
    // channels are drawn by rasterTraces.
    series: [{}, { label: "y", stroke: "transparent", points: { show: false } }],
  };
  const data: uPlot.AlignedData = [
    [0, 1],
    [null, null],
  ];
  return new uPlot(opts, data, mountIn(el));
}

/** Creates the plot in `host` for as long as `key` (channels, layout, output) stays the same. */
export function usePlot(
  host: RefObject<HTMLDivElement | null>,
  live: RefObject<ScopeLive>,
  attach: (plot: uPlot) => () => void,
  keys: readonly unknown[],
): void {
  useEffect(() => {
    const el = host.current;
    if (!el) return undefined;
    const l = live.current;
    const plot = createPlot(el, l);
    l.plot = plot;
    l.dirty = true;
    const ro = new ResizeObserver(() => {
      const w = Math.max(100, el.clientWidth);
      const h = Math.max(80, el.clientHeight);
      if (w !== plot.width || h !== plot.height) {
        plot.setSize({ width: w, height: h });
        l.dirty = true;
      }
    });
    ro.observe(el);
    const detach = attach(plot);
    return () => {
      detach();
      ro.disconnect();
      plot.destroy();
      if (l.plot === plot) l.plot = null;
    };
  }, keys);
}

/**
 * Redraws once per frame while something changed (new data, the clock scrolling the window, a
 * zoom or pan). `after` runs after each picture (the readout, the footer's numbers).
 */
export function useDrawLoop(
  live: RefObject<ScopeLive>,
  active: boolean,
  statsKey: string,
  after: (now: number) => void,
): void {
  useEffect(() => {
    if (!active) return undefined;
    const l = live.current;
    const stats = viewStats(statsKey);
    return onFrame((now) => {
      const b = l.buffer;
      const plot = l.plot;
      if (!b || !plot || b.count === 0) return;
      const x = nextXRange(l, b, now);
      if (!x) return;
      const t0 = performance.now();
      if (Number.isFinite(l.right)) {
        l.right = holdRight(l, l.right, b);
        l.x = [l.right - l.span, l.right];
      } else l.x = x;
      const data = b.view(l.x[0], l.x[1]);
      drawTraces(l, plot, data, l.lastDraw ? (now - l.lastDraw) / 1000 : 0);
      plot.batch(() => plot.setData([l.x, [null, null]]));
      l.dirty = false;
      l.lastDraw = now;
      countDraw(stats, performance.now() - t0);
      after(now);
    });
  }, [active, statsKey, live, after]);
}
