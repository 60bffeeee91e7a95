/**
 * The Heatmap's toolbar: the value per cell (latest, smoothed, envelope), the electrode grid and
 * the order channels fill it (vector outputs), and the colour scale (auto or a fixed range).
 */
import type { ReactNode } from "react";
import { gridChoices } from "./channels";
import { RangeInputs, ReduceControls } from "./controls";
import type { HeatmapSettings } from "./heatmap";
import type { HeatmapGrid } from "./use-heatmap";
import type { OutputInfo } from "./view-props";

type OnSettings = (patch: Partial<HeatmapSettings>) => void;

/** The grid picker: the declared array, a custom size, or the sizes that hold every channel. */
function GridSelect({
  output,
  grid,
  onSettings,
}: {
  output: OutputInfo;
  grid: HeatmapGrid;
  onSettings: OnSettings;
}): ReactNode {
  const { declared, gridRows, gridCols } = grid;
  const choices = gridChoices(output.shape.cols);
  const gridKey = declared ? "declared" : `${gridRows}x${gridCols}`;
  const known = gridKey === "declared" || choices.some((g) => `${g.rows}x${g.cols}` === gridKey);
  return (
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
            {output.grid.name ?? "electrode array"} ({output.grid.rows} × {output.grid.cols})
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
  );
}

/** Along rows or along columns (not for a declared array: it says where each channel is). */
function OrderSelect({
  columnMajor,
  onSettings,
}: {
  columnMajor: boolean;
  onSettings: OnSettings;
}): ReactNode {
  return (
    <label className="mp-field" title="How channels fill the grid">
      Order
      <select
        value={columnMajor ? "col" : "row"}
        onChange={(e) => onSettings({ columnMajor: e.target.value === "col" })}
      >
        <option value="row">along rows</option>
        <option value="col">along columns</option>
      </select>
    </label>
  );
}

function ScaleSelect({
  settings,
  onSettings,
  suggest,
}: {
  settings: HeatmapSettings;
  onSettings: OnSettings;
  suggest: () => [number, number];
}): ReactNode {
  return (
    <>
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
          suggest={suggest}
        />
      )}
    </>
  );
}

export function HeatmapToolbar({
  output,
  settings,
  onSettings,
  grid,
  tools,
  suggest,
}: {
  output: OutputInfo;
  settings: HeatmapSettings;
  onSettings: OnSettings;
  grid: HeatmapGrid;
  tools: ReactNode;
  /** The range last drawn (what a fixed scale is first offered). */
  suggest: () => [number, number];
}): ReactNode {
  return (
    <div className="mp-toolbar" role="toolbar" aria-label="Heatmap settings">
      {tools}
      <ReduceControls
        settings={{ reduce: grid.reduce, tauS: settings.tauS }}
        onSettings={onSettings}
      />
      {output.shape.rows === 1 && (
        <>
          <GridSelect output={output} grid={grid} onSettings={onSettings} />
          {!grid.declared && (
            <OrderSelect columnMajor={settings.columnMajor} onSettings={onSettings} />
          )}
        </>
      )}
      <ScaleSelect settings={settings} onSettings={onSettings} suggest={suggest} />
    </div>
  );
}
