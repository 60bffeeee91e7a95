/**
 * Spider plot (paper III-C, Fig. 3): one axis per channel, the latest value of each (optionally
 * smoothed: a moving mean, or a moving mean of |x| — the envelope of raw EMG), autoscaled (the
 * outer ring widens at once and narrows over ~3 s) or fixed. Drawn on a canvas, at most once per
 * animation frame and only when new data arrived. Matrices show their newest row.
 */
import type { ReactNode } from "react";
import { channelLabel, type Reduce } from "./channels";
import { REDUCE_LABEL, RangeInputs, ReduceControls } from "./controls";
import { HEIGHT } from "./spider-draw";
import { useSpiderCanvas } from "./use-spider";
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
  const reduce: Reduce = settings.reduce ?? (block.desiredRate > 100 ? "envelope" : "latest");
  const { canvas, wrap, hasData } = useSpiderCanvas(block, output, active, settings, n, reduce);
  return (
    <div className="mp-spider" data-view="spider" data-block={block.name} data-port={output.name}>
      <SpiderToolbar reduce={reduce} settings={settings} onSettings={onSettings} tools={tools} />
      <div ref={wrap} className="mp-canvas-wrap" style={{ height: HEIGHT }}>
        <canvas
          ref={canvas}
          role="img"
          aria-label={`Spider plot of ${block.name}.${output.name}: ${n} axes (${axisNames(output, n)})`}
        />
      </div>
      <p className="mp-foot">
        {footText(n, reduce, hasData, active)}
        {cols > SPIDER_MAX_AXES ? ` — the first ${SPIDER_MAX_AXES} of ${cols} channels` : ""}
        {rows > 1 ? ` · newest row of each [${rows}, ${cols}] event` : ""}
      </p>
    </div>
  );
}

/** The output picker (`tools`), the reduction, and the scale: auto, or fixed with its range. */
function SpiderToolbar({
  reduce,
  settings,
  onSettings,
  tools,
}: {
  reduce: Reduce;
  settings: SpiderSettings;
  onSettings: (patch: Partial<SpiderSettings>) => void;
  tools: ReactNode;
}): ReactNode {
  return (
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
  );
}

/** The line under the plot: what is drawn (axes, or bars below 3) and how, or why nothing is. */
function footText(n: number, reduce: Reduce, hasData: boolean, active: boolean): string {
  if (!hasData) return active ? "waiting for data…" : "hidden: no data is watched";
  const drawn = n < 3 ? `${n} bar${n > 1 ? "s" : ""} (a spider needs 3 axes)` : `${n} axes`;
  return `${drawn}, ${REDUCE_LABEL[reduce]}`;
}

/** The axes' names for the plot's text alternative ("fist, open, pinch", the first 32). */
function axisNames(output: OutputInfo, n: number): string {
  const names = Array.from({ length: Math.min(n, 32) }, (_, k) => channelLabel(output, k));
  return names.join(", ") + (n > 32 ? ", …" : "");
}
