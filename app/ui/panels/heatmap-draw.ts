/**
 * The Heatmap's pictures, without React: where each value goes on the grid (its Layout), the
 * geometry of the cells on the canvas, and drawing one frame (cells, borders, channel names, the
 * colour legend).
 */
import type { ElectrodeGrid } from "../../engine/block";
import { VIRIDIS, cellOf, formatTick, niceTicks } from "./channels";
import { fitCanvas, type Theme } from "./canvas";

export const HEIGHT = 300;
const LEGEND_W = 64;

export interface Layout {
  rows: number;
  cols: number;
  /** Cell of each value (row-major index into the image), -1 when not shown. */
  cellOfValue: Int32Array;
  /** Value index of each cell, -1 for an empty cell. */
  valueOfCell: Int32Array;
  matrix: boolean;
}

/** One pixel per cell, scaled up when drawn. */
export interface CellImage {
  canvas: HTMLCanvasElement;
  data: ImageData;
  words: Uint32Array;
}

/** Where the cells lie on the canvas: the top left corner of the grid and a cell's side. */
interface Geometry {
  x: number;
  y: number;
  cell: number;
}

/** The layout of an electrode array the block declared (its PortMeta grid). */
export function declaredLayout(n: number, grid: ElectrodeGrid): Layout {
  const cellOfValue = new Int32Array(n).fill(-1);
  const valueOfCell = Int32Array.from(grid.cells);
  grid.cells.forEach((k, cell) => {
    if (k >= 0 && k < n) cellOfValue[k] = cell;
  });
  return { rows: grid.rows, cols: grid.cols, cellOfValue, valueOfCell, matrix: false };
}

export function layoutFor(
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

export function makeImage(cols: number, rows: number): CellImage {
  const canvas = document.createElement("canvas");
  canvas.width = cols;
  canvas.height = rows;
  const data = new ImageData(cols, rows);
  return { canvas, data, words: new Uint32Array(data.data.buffer) };
}

export function geometry(width: number, height: number, layout: Layout): Geometry {
  const pad = 8;
  const availW = Math.max(10, width - LEGEND_W - 2 * pad);
  const availH = Math.max(10, height - 2 * pad);
  const cell = Math.max(1, Math.min(availW / layout.cols, availH / layout.rows));
  const w = cell * layout.cols;
  const h = cell * layout.rows;
  return { x: pad + (availW - w) / 2, y: pad + (availH - h) / 2, cell };
}

/** The colour of every cell into the image's words (transparent where there is no value). */
function fillCells(
  words: Uint32Array,
  values: Float64Array,
  layout: Layout,
  lo: number,
  span: number,
): void {
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
}

/** Cell borders (drawn when the cells are big enough). */
function drawBorders(ctx: CanvasRenderingContext2D, theme: Theme, g: Geometry, layout: Layout) {
  const w = g.cell * layout.cols;
  const h = g.cell * layout.rows;
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

/** Channel names in their cells, dark on light colours and light on dark ones. */
function drawLabels(
  ctx: CanvasRenderingContext2D,
  g: Geometry,
  values: Float64Array,
  layout: Layout,
  lo: number,
  span: number,
  label: (k: number) => string,
): void {
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

/** The colour legend at the right, with its ticks. */
function drawLegend(
  ctx: CanvasRenderingContext2D,
  theme: Theme,
  width: number,
  height: number,
  lo: number,
  hi: number,
): void {
  const span = hi - lo || 1;
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

export function drawHeatmap(
  canvas: HTMLCanvasElement,
  theme: Theme,
  width: number,
  height: number,
  values: Float64Array,
  layout: Layout,
  image: CellImage,
  lo: number,
  hi: number,
  label: (k: number) => string,
): void {
  const ctx = fitCanvas(canvas, width, height);
  if (!ctx) return;
  ctx.clearRect(0, 0, width, height);
  const span = hi - lo || 1;
  fillCells(image.words, values, layout, lo, span);
  image.canvas.getContext("2d")?.putImageData(image.data, 0, 0);
  const g = geometry(width, height, layout);
  const w = g.cell * layout.cols;
  const h = g.cell * layout.rows;
  ctx.fillStyle = theme.grid;
  ctx.fillRect(g.x, g.y, w, h);
  ctx.imageSmoothingEnabled = false;
  ctx.drawImage(image.canvas, g.x, g.y, w, h);
  // Cell borders and channel names when the cells are big enough.
  if (g.cell >= 8) drawBorders(ctx, theme, g, layout);
  // Channel labels only where they can be 11 px or more (readable on screen).
  if (g.cell >= 33 && !layout.matrix) drawLabels(ctx, g, values, layout, lo, span, label);
  drawLegend(ctx, theme, width, height, lo, hi);
}
