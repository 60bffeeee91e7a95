/**
 * Heatmap (paper III-C): a matrix value as an image (row 0 at the top), or the channels of a
 * vector on an electrode grid — HD-EMG arrays of 8 × 8 or 16 × 16 — inferred near-square or
 * picked (rows × cols, along rows or along columns); a block that declares its electrode array
 * (PortMeta grid: Muovi, Quattrocento) is drawn on it unless another grid is picked. Viridis
 * colour scale with a legend, autoscaled (widens at once, narrows over ~3 s) or fixed. The value per cell is the latest one,
 * a moving mean, or a moving mean of |x| (the envelope: what an activation map of raw EMG shows;
 * the default for outputs faster than 100 Hz). One pixel per cell in an offscreen image, scaled
 * up without smoothing; redrawn at most once per frame, only when new data arrived.
 */
import {
  useCallback,
  useEffect,
  useMemo,
  useRef,
  useState,
  type MouseEvent,
  type ReactNode,
} from "react";
import type { ElectrodeGrid } from "../../engine/block";
import type { DataMessage } from "../../engine/protocol";
import { useBlockData } from "../client/hooks";
import {
  Smoother,
  StickyRange,
  VIRIDIS,
  cellOf,
  channelLabel,
  finiteExtent,
  formatTick,
  formatValue,
  gridChoices,
  inferGrid,
  niceTicks,
  type Reduce,
} from "./channels";
import { fitCanvas, readTheme, useWidth, type Theme } from "./canvas";
import { RangeInputs, ReduceControls } from "./controls";
import { countDraw, onFrame, viewStats } from "./frame";
import type { ViewProps } from "./view-props";

export interface HeatmapSettings {
  /** undefined: latest below 100 Hz, envelope above. */
  reduce?: Reduce;
  tauS: number;
  /** Vector outputs: the electrode grid (undefined: inferred). */
  gridRows?: number;
  gridCols?: number;
  columnMajor: boolean;
  scale: "auto" | "fixed";
  min: number;
  max: number;
}

export const HEATMAP_DEFAULTS: HeatmapSettings = {
  tauS: 0.3,
  columnMajor: false,
  scale: "auto",
  min: 0,
  max: 1,
};

const HEIGHT = 300;
const LEGEND_W = 64;

interface Layout {
  rows: number;
  cols: number;
  /** Cell of each value (row-major index into the image), -1 when not shown. */
  cellOfValue: Int32Array;
  /** Value index of each cell, -1 for an empty cell. */
  valueOfCell: Int32Array;
  matrix: boolean;
}

/** The layout of an electrode array the block declared (its PortMeta grid). */
function declaredLayout(n: number, grid: ElectrodeGrid): Layout {
  const cellOfValue = new Int32Array(n).fill(-1);
  const valueOfCell = Int32Array.from(grid.cells);
  grid.cells.forEach((k, cell) => {
    if (k >= 0 && k < n) cellOfValue[k] = cell;
  });
  return { rows: grid.rows, cols: grid.cols, cellOfValue, valueOfCell, matrix: false };
}

function layoutFor(
  shape: { rows: number; cols: number },
  gridRows: number,
  gridCols: number,
  columnMajor: boolean,
): Layout {
  const n = shape.rows * shape.cols;
  if (shape.rows > 1) {
    const id = Int32Array.from({ length: n }, (_x, i) => i);
    return { rows: shape.rows, cols: shape.cols, cellOfValue: id, valueOfCell: id, matrix: true };
  }
  const cells = gridRows * gridCols;
  const cellOfValue = new Int32Array(n).fill(-1);
  const valueOfCell = new Int32Array(cells).fill(-1);
  for (let k = 0; k < n; k++) {
    const [r, c] = cellOf(k, gridCols, gridRows, columnMajor);
    if (r < gridRows && c < gridCols) {
      cellOfValue[k] = r * gridCols + c;
      valueOfCell[r * gridCols + c] = k;
    }
  }
  return { rows: gridRows, cols: gridCols, cellOfValue, valueOfCell, matrix: false };
}

export function Heatmap({
  block,
  output,
  active,
  settings,
  onSettings,
  tools,
}: ViewProps<HeatmapSettings>): ReactNode {
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
  const statsKey = `heatmap:${block.name}.${output.name}`;
  const canvas = useRef<HTMLCanvasElement>(null);
  const wrap = useRef<HTMLDivElement>(null);
  const smoother = useMemo(() => new Smoother(n, reduce, settings.tauS), [n]);
  smoother.mode = reduce;
  smoother.tauS = settings.tauS;
  useEffect(() => smoother.reset(), [reduce, smoother]);
  const live = useRef({
    dirty: false,
    width: 0,
    range: new StickyRange(3, 0),
    last: 0,
    settings,
    layout,
    theme: null as Theme | null,
    image: null as { canvas: HTMLCanvasElement; data: ImageData; words: Uint32Array } | null,
    lohi: [0, 1] as [number, number],
  });
  const l0 = live.current;
  l0.settings = settings;
  if (l0.layout !== layout) {
    l0.layout = layout;
    l0.image = null;
    l0.dirty = true;
  }
  const [hasData, setHasData] = useState(false);
  const [hover, setHover] = useState<string>("");

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
    [smoother, statsKey, hasData],
  );
  useBlockData(block.name, output.name, onData, active && n > 0, reduce === "latest" ? 30 : 200);

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
  }, [active, smoother, statsKey, output]);

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
      ? `[${Math.floor(k / cols)}, ${k % cols}]`
      : `channel ${channelLabel(output, k)}`;
    setHover(`${name} (row ${r}, col ${c}): ${formatValue(smoother.out[k]!)}`);
  };

  const choices = gridChoices(cols);
  const gridKey = declared ? "declared" : `${gridRows}x${gridCols}`;
  const known = gridKey === "declared" || choices.some((g) => `${g.rows}x${g.cols}` === gridKey);
  return (
    <div className="mp-heatmap" data-view="heatmap" data-block={block.name} data-port={output.name}>
      <div className="mp-toolbar" role="toolbar" aria-label="Heatmap settings">
        {tools}
        <ReduceControls settings={{ reduce, tauS: settings.tauS }} onSettings={onSettings} />
        {rows === 1 && (
          <>
            <label className="mp-field" title="Electrode grid: rows × columns">
              Grid
              <select
                value={known ? gridKey : "custom"}
                onChange={(e) => {
                  if (e.target.value === "declared") {
                    onSettings({ gridRows: undefined, gridCols: undefined });
                    return;
                  }
                  const [r, c] = e.target.value.split("x").map(Number);
                  if (r && c) onSettings({ gridRows: r, gridCols: c });
                }}
              >
                {output.grid && (
                  <option value="declared">
                    {output.grid.name ?? "electrode array"} ({output.grid.rows} × {output.grid.cols}
                    )
                  </option>
                )}
                {!known && (
                  <option value="custom">
                    {gridRows} × {gridCols}
                  </option>
                )}
                {choices.map((g) => (
                  <option key={`${g.rows}x${g.cols}`} value={`${g.rows}x${g.cols}`}>
                    {g.rows} × {g.cols}
                  </option>
                ))}
              </select>
            </label>
            {!declared && (
              <label className="mp-field" title="How channels fill the grid">
                Order
                <select
                  value={settings.columnMajor ? "col" : "row"}
                  onChange={(e) => onSettings({ columnMajor: e.target.value === "col" })}
                >
                  <option value="row">along rows</option>
                  <option value="col">along columns</option>
                </select>
              </label>
            )}
          </>
        )}
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
            suggest={() => live.current.lohi}
          />
        )}
      </div>
      <div ref={wrap} className="mp-canvas-wrap" style={{ height: HEIGHT }}>
        <canvas
          ref={canvas}
          role="img"
          aria-label={`Heatmap of ${block.name}.${output.name}: ${layout.rows} × ${layout.cols}`}
          onMouseMove={onMove}
          onMouseLeave={() => setHover("")}
        />
      </div>
      <p className="mp-foot">
        {hover ||
          (!hasData
            ? active
              ? "waiting for data…"
              : "hidden: no data is watched"
            : layout.matrix
              ? `[${rows}, ${cols}] matrix, row 0 at the top`
              : `${cols} channels on a ${gridRows} × ${gridCols} grid, ${settings.columnMajor ? "along columns" : "along rows"} from the top left`)}
      </p>
    </div>
  );
}

let legend: HTMLCanvasElement | null = null;

/** The colour scale as a 1 × 256 image, high values at the top (made once). */
function legendImage(): HTMLCanvasElement {
  if (legend) return legend;
  const c = document.createElement("canvas");
  c.width = 1;
  c.height = 256;
  const img = new ImageData(1, 256);
  const words = new Uint32Array(img.data.buffer);
  for (let y = 0; y < 256; y++) words[y] = VIRIDIS[255 - y]!;
  c.getContext("2d")?.putImageData(img, 0, 0);
  legend = c;
  return c;
}

function makeImage(
  cols: number,
  rows: number,
): { canvas: HTMLCanvasElement; data: ImageData; words: Uint32Array } {
  const canvas = document.createElement("canvas");
  canvas.width = cols;
  canvas.height = rows;
  const data = new ImageData(cols, rows);
  return { canvas, data, words: new Uint32Array(data.data.buffer) };
}

function geometry(
  width: number,
  height: number,
  layout: Layout,
): { x: number; y: number; cell: number } {
  const pad = 8;
  const availW = Math.max(10, width - LEGEND_W - 2 * pad);
  const availH = Math.max(10, height - 2 * pad);
  const cell = Math.max(1, Math.min(availW / layout.cols, availH / layout.rows));
  const w = cell * layout.cols;
  const h = cell * layout.rows;
  return { x: pad + (availW - w) / 2, y: pad + (availH - h) / 2, cell };
}

function drawHeatmap(
  canvas: HTMLCanvasElement,
  theme: Theme,
  width: number,
  height: number,
  values: Float64Array,
  layout: Layout,
  image: { canvas: HTMLCanvasElement; data: ImageData; words: Uint32Array },
  lo: number,
  hi: number,
  label: (k: number) => string,
): void {
  const ctx = fitCanvas(canvas, width, height);
  if (!ctx) return;
  ctx.clearRect(0, 0, width, height);
  const span = hi - lo || 1;
  const words = image.words;
  const empty = 0; // transparent: the background shows through
  for (let cell = 0; cell < words.length; cell++) {
    const k = layout.valueOfCell[cell]!;
    if (k < 0) {
      words[cell] = empty;
      continue;
    }
    const v = values[k]!;
    if (!Number.isFinite(v)) {
      words[cell] = empty;
      continue;
    }
    const i = Math.round(((v - lo) / span) * 255);
    words[cell] = VIRIDIS[i < 0 ? 0 : i > 255 ? 255 : i]!;
  }
  image.canvas.getContext("2d")?.putImageData(image.data, 0, 0);
  const g = geometry(width, height, layout);
  const w = g.cell * layout.cols;
  const h = g.cell * layout.rows;
  ctx.fillStyle = theme.grid;
  ctx.fillRect(g.x, g.y, w, h);
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(image.canvas, g.x, g.y, w, h);
  // Cell borders and channel names when the cells are big enough.
  if (g.cell >= 8) {
    ctx.strokeStyle = theme.bg;
    ctx.lineWidth = 1;
    ctx.beginPath();
    for (let r = 0; r <= layout.rows; r++) {
      ctx.moveTo(g.x, g.y + r * g.cell);
      ctx.lineTo(g.x + w, g.y + r * g.cell);
    }
    for (let c = 0; c <= layout.cols; c++) {
      ctx.moveTo(g.x + c * g.cell, g.y);
      ctx.lineTo(g.x + c * g.cell, g.y + h);
    }
    ctx.stroke();
  }
  // Channel labels only where they can be 11 px or more (readable on screen).
  if (g.cell >= 33 && !layout.matrix) {
    ctx.font = `${Math.min(13, Math.floor(g.cell / 3))}px system-ui, sans-serif`;
    ctx.textAlign = "center";
    ctx.textBaseline = "middle";
    for (let cell = 0; cell < layout.valueOfCell.length; cell++) {
      const k = layout.valueOfCell[cell]!;
      if (k < 0) continue;
      const v = values[k]!;
      const i = Number.isFinite(v) ? ((v - lo) / span) * 255 : 0;
      ctx.fillStyle = i > 150 ? "#111" : "#fff";
      const r = Math.floor(cell / layout.cols);
      const c = cell % layout.cols;
      ctx.fillText(label(k), g.x + (c + 0.5) * g.cell, g.y + (r + 0.5) * g.cell);
    }
  }
  // The colour legend.
  const lx = width - LEGEND_W + 6;
  const ly = 14;
  const lh = height - 28;
  ctx.imageSmoothingEnabled = true;
  ctx.drawImage(legendImage(), lx, ly, 12, lh);
  ctx.strokeStyle = theme.grid;
  ctx.strokeRect(lx + 0.5, ly + 0.5, 12, lh);
  ctx.fillStyle = theme.fg;
  ctx.font = "11px system-ui, sans-serif";
  ctx.textAlign = "left";
  ctx.textBaseline = "middle";
  const ticks = niceTicks(lo, hi, 4);
  const step = ticks.length > 1 ? ticks[1]! - ticks[0]! : span;
  for (const t of ticks) {
    const y = ly + (1 - (t - lo) / span) * lh;
    if (y < ly - 1 || y > ly + lh + 1) continue;
    ctx.fillRect(lx + 12, y, 3, 1);
    ctx.fillText(formatTick(t, step), lx + 17, y);
  }
}
