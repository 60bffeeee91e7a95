/**
 * The Heatmap's hooks: which grid the values are drawn on, the values it receives (smoothed),
 * drawing them once per frame when new data arrived, and what the pointer is over.
 */
import {
  useCallback,
  useEffect,
  useMemo,
  useRef,
  useState,
  type MouseEvent,
  type RefObject,
} from "react";
import type { ElectrodeGrid } from "../../engine/block";
import type { BlockInfo, DataMessage } from "../../engine/protocol";
import { useBlockData } from "../client/hooks";
import {
  Smoother,
  StickyRange,
  channelLabel,
  finiteExtent,
  formatValue,
  inferGrid,
  type Reduce,
} from "./channels";
import { readTheme, useWidth, type Theme } from "./canvas";
import { countDraw, onFrame, viewStats } from "./frame";
import type { HeatmapSettings } from "./heatmap";
import {
  HEIGHT,
  declaredLayout,
  drawHeatmap,
  geometry,
  layoutFor,
  makeImage,
  type CellImage,
  type Layout,
} from "./heatmap-draw";
import { useSmoother } from "./use-smoother";
import type { OutputInfo } from "./view-props";

export interface HeatmapGrid {
  reduce: Reduce;
  /** The block's own electrode array, when drawn on it (no other grid picked). */
  declared: ElectrodeGrid | undefined;
  gridRows: number;
  gridCols: number;
  layout: Layout;
}

/** What the frame loop reads and writes between renders. */
interface HeatmapLive {
  dirty: boolean;
  width: number;
  range: StickyRange;
  last: number;
  settings: HeatmapSettings;
  layout: Layout;
  theme: Theme | null;
  image: CellImage | null;
  lohi: [number, number];
}

export type HeatmapLiveRef = RefObject<HeatmapLive>;

/** The reduction and the grid (declared, picked or inferred) and the layout of the values. */
export function useHeatmapGrid(
  block: BlockInfo,
  output: OutputInfo,
  settings: HeatmapSettings,
): HeatmapGrid {
  const { rows, cols } = output.shape;
  const n = rows * cols;
  const reduce: Reduce = settings.reduce ?? (block.desiredRate > 100 ? "envelope" : "latest");
  const inferred = inferGrid(cols);
  // The block's own electrode array, unless another grid was picked.
  const declared = rows === 1 && settings.gridRows === undefined ? output.grid : undefined;
  const gridRows = settings.gridRows ?? declared?.rows ?? inferred.rows;
  const gridCols = settings.gridCols ?? declared?.cols ?? inferred.cols;
  const layout = useMemo(
    () =>
      declared
        ? declaredLayout(n, declared)
        : layoutFor(output.shape, gridRows, gridCols, settings.columnMajor),
    [output.shape, declared, n, gridRows, gridCols, settings.columnMajor],
  );
  return { reduce, declared, gridRows, gridCols, layout };
}

/** The frame loop's state, told the latest settings and layout (a new layout redraws). */
function useHeatmapLiveState(settings: HeatmapSettings, layout: Layout): HeatmapLiveRef {
  const live = useRef<HeatmapLive>({
    dirty: false,
    width: 0,
    range: new StickyRange(3, 0),
    last: 0,
    settings,
    layout,
    theme: null,
    image: null,
    lohi: [0, 1],
  });
  const l0 = live.current;
  l0.settings = settings;
  if (l0.layout !== layout) {
    l0.layout = layout;
    l0.image = null;
    l0.dirty = true;
  }
  return live;
}

/** Feeds the block output's data into the smoother while active; true once data arrived. */
function useHeatmapData(
  block: BlockInfo,
  output: OutputInfo,
  active: boolean,
  reduce: Reduce,
  smoother: Smoother,
  live: HeatmapLiveRef,
  statsKey: string,
): boolean {
  const n = output.shape.rows * output.shape.cols;
  const [hasData, setHasData] = useState(false);
  const onData = useCallback(
    (m: DataMessage) => {
      const stride = m.rows * m.cols;
      for (let e = 0; e < m.t.length; e++) smoother.push(m.t[e]!, m.v, e * stride);
      live.current.dirty = true;
      const s = viewStats(statsKey);
      s.messages++;
      s.events += m.t.length;
      s.skipped += m.skipped;
      if (!hasData) setHasData(true);
    },
    [smoother, statsKey, hasData, live],
  );
  useBlockData(block.name, output.name, onData, active && n > 0, reduce === "latest" ? 30 : 200);
  return hasData;
}

/** Draws the heatmap at most once per frame while active, when new data (or a new size) came. */
function useHeatmapFrames(
  canvas: RefObject<HTMLCanvasElement | null>,
  live: HeatmapLiveRef,
  smoother: Smoother,
  output: OutputInfo,
  active: boolean,
  statsKey: string,
): void {
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
        [lo, hi] = l.range.update(a, z, l.last ? (now - l.last) / 1000 : 0);
      }
      l.last = now;
      l.lohi = [lo, hi];
      l.theme ??= readTheme(c);
      l.image ??= makeImage(l.layout.cols, l.layout.rows);
      drawHeatmap(c, l.theme, l.width, HEIGHT, smoother.out, l.layout, l.image, lo, hi, (k) =>
        channelLabel(output, k),
      );
      countDraw(stats, performance.now() - t0);
    });
  }, [active, smoother, statsKey, output, canvas, live]);
}

export interface HeatmapCanvas {
  canvas: RefObject<HTMLCanvasElement | null>;
  wrap: RefObject<HTMLDivElement | null>;
  live: HeatmapLiveRef;
  smoother: Smoother;
  hasData: boolean;
}

/** The canvas and its wrapper, the data watched and the frames drawn. */
export function useHeatmapCanvas(
  block: BlockInfo,
  output: OutputInfo,
  active: boolean,
  settings: HeatmapSettings,
  grid: HeatmapGrid,
): HeatmapCanvas {
  const n = output.shape.rows * output.shape.cols;
  const statsKey = `heatmap:${block.name}.${output.name}`;
  const canvas = useRef<HTMLCanvasElement>(null);
  const wrap = useRef<HTMLDivElement>(null);
  const smoother = useSmoother(n, grid.reduce, settings.tauS);
  const live = useHeatmapLiveState(settings, grid.layout);
  const hasData = useHeatmapData(block, output, active, grid.reduce, smoother, live, statsKey);

  const onResize = useCallback((w: number) => {
    const l = live.current;
    l.width = w;
    l.dirty = true;
    if (canvas.current) l.theme = readTheme(canvas.current);
  }, []);
  useWidth(wrap, onResize);
  useHeatmapFrames(canvas, live, smoother, output, active, statsKey);
  return { canvas, wrap, live, smoother, hasData };
}

/** The text of the cell under the pointer ("" when none): its channel, place and value. */
export function useHeatmapHover(
  live: HeatmapLiveRef,
  smoother: Smoother,
  output: OutputInfo,
): { hover: string; onMove(e: MouseEvent<HTMLCanvasElement>): void; onLeave(): void } {
  const [hover, setHover] = useState<string>("");
  const onMove = (e: MouseEvent<HTMLCanvasElement>): void => {
    const l = live.current;
    const g = geometry(l.width, HEIGHT, l.layout);
    const rect = e.currentTarget.getBoundingClientRect();
    const x = e.clientX - rect.left - g.x;
    const y = e.clientY - rect.top - g.y;
    const c = Math.floor(x / g.cell);
    const r = Math.floor(y / g.cell);
    if (c < 0 || r < 0 || c >= l.layout.cols || r >= l.layout.rows) {
      setHover("");
      return;
    }
    const k = l.layout.valueOfCell[r * l.layout.cols + c]!;
    if (k < 0) {
      setHover(`row ${r}, col ${c}: no channel`);
      return;
    }
    const name = l.layout.matrix
      ? `[${Math.floor(k / output.shape.cols)}, ${k % output.shape.cols}]`
      : `channel ${channelLabel(output, k)}`;
    setHover(`${name} (row ${r}, col ${c}): ${formatValue(smoother.out[k]!)}`);
  };
  return { hover, onMove, onLeave: () => setHover("") };
}
