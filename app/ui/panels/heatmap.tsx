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
import type { ReactNode } from "react";
import type { Reduce } from "./channels";
import { HEIGHT } from "./heatmap-draw";
import { HeatmapToolbar } from "./heatmap-toolbar";
import { useHeatmapCanvas, useHeatmapGrid, useHeatmapHover, type HeatmapGrid } from "./use-heatmap";
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

/** The line under the picture: the cell pointed at, else what is drawn (or why nothing is). */
function footText(
  shape: { rows: number; cols: number },
  grid: HeatmapGrid,
  columnMajor: boolean,
  hasData: boolean,
  active: boolean,
): string {
  if (!hasData) return active ? "waiting for data…" : "hidden: no data is watched";
  if (grid.layout.matrix) return `[${shape.rows}, ${shape.cols}] matrix, row 0 at the top`;
  const order = columnMajor ? "along columns" : "along rows";
  return `${shape.cols} channels on a ${grid.gridRows} × ${grid.gridCols} grid, ${order} from the top left`;
}

export function Heatmap({
  block,
  output,
  active,
  settings,
  onSettings,
  tools,
}: ViewProps<HeatmapSettings>): ReactNode {
  const grid = useHeatmapGrid(block, output, settings);
  const { layout } = grid;
  const { canvas, wrap, live, smoother, hasData } = useHeatmapCanvas(
    block,
    output,
    active,
    settings,
    grid,
  );
  const { hover, onMove, onLeave } = useHeatmapHover(live, smoother, output);
  return (
    <div className="mp-heatmap" data-view="heatmap" data-block={block.name} data-port={output.name}>
      <HeatmapToolbar
        output={output}
        settings={settings}
        onSettings={onSettings}
        grid={grid}
        tools={tools}
        suggest={() => live.current.lohi}
      />
      <div ref={wrap} className="mp-canvas-wrap" style={{ height: HEIGHT }}>
        <canvas
          ref={canvas}
          role="img"
          aria-label={`Heatmap of ${block.name}.${output.name}: ${layout.rows} × ${layout.cols}`}
          onMouseMove={onMove}
          onMouseLeave={onLeave}
        />
      </div>
      <p className="mp-foot">
        {hover || footText(output.shape, grid, settings.columnMajor, hasData, active)}
      </p>
    </div>
  );
}
