/** The scope's toolbar: pause, window, amplitude, layout, spectrum, zoom reset, exports, channels. */
import type { ReactNode } from "react";
import { ChannelPicker } from "./channel-picker";
import { PlayPauseIcon, RangeInputs } from "./controls";
import type { ScopeSettings } from "./scope";
import type { MatrixMode } from "./scope-buffer";
import type { OutputInfo } from "./view-props";

export const WINDOWS_S = [2, 5, 10, 30] as const;

export interface ToolbarProps {
  settings: ScopeSettings;
  onSettings: (p: Partial<ScopeSettings>) => void;
  output: OutputInfo;
  channels: number[];
  matrixMode: MatrixMode;
  zoomed: boolean;
  onResetZoom(): void;
  onCsv(): void;
  onPng(): void;
  suggestY(): [number, number];
  tools?: ReactNode;
}

function PauseButton({ paused, onToggle }: { paused: boolean; onToggle(): void }): ReactNode {
  return (
    <button
      type="button"
      className={`mp-btn${paused ? " mp-on" : ""}`}
      aria-pressed={paused}
      onClick={onToggle}
      title={
        paused
          ? "Resume: watch the data again"
          : "Pause: hold the picture (zoom, pan and read values; no data is watched)"
      }
    >
      <PlayPauseIcon paused={paused} /> {paused ? "Resume" : "Pause"}
    </button>
  );
}

function ViewFields({ settings, onSettings, output, matrixMode }: ToolbarProps): ReactNode {
  const { rows, cols } = output.shape;
  return (
    <>
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
      {cols > 1 && (
        <label className="mp-field" title="Channels over each other, or each in its own lane">
          Layout
          <select
            value={settings.layout}
            onChange={(e) => onSettings({ layout: e.target.value as ScopeSettings["layout"] })}
          >
            <option value="overlaid">overlaid</option>
            <option value="stacked">stacked</option>
          </select>
        </label>
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
    </>
  );
}

export function ScopeToolbar(props: ToolbarProps): ReactNode {
  const { settings, onSettings, output, channels } = props;
  return (
    <div className="mp-toolbar" role="toolbar" aria-label="Scope settings">
      {props.tools}
      <PauseButton
        paused={settings.paused}
        onToggle={() => onSettings({ paused: !settings.paused })}
      />
      <ViewFields {...props} />
      {settings.yMode === "fixed" && (
        <RangeInputs
          min={settings.yMin}
          max={settings.yMax}
          onChange={(yMin, yMax) => onSettings({ yMin, yMax })}
          suggest={props.suggestY}
        />
      )}
      <button
        type="button"
        className={`mp-btn${settings.spectrum ? " mp-on" : ""}`}
        aria-pressed={settings.spectrum}
        onClick={() => onSettings({ spectrum: !settings.spectrum })}
        title="Spectrum (Welch PSD) of the window in view, with the median frequency"
      >
        Spectrum
      </button>
      {props.zoomed && (
        <button
          type="button"
          className="mp-btn"
          onClick={props.onResetZoom}
          title="Back to the whole window and the automatic amplitude (or double-click the plot)"
        >
          Reset zoom
        </button>
      )}
      <button
        type="button"
        className="mp-btn"
        onClick={props.onCsv}
        title="Download the samples in view as CSV"
      >
        CSV
      </button>
      <button
        type="button"
        className="mp-btn"
        onClick={props.onPng}
        title="Download the picture as PNG"
      >
        PNG
      </button>
      <ChannelPicker
        count={output.shape.cols}
        selected={channels}
        output={output}
        onChange={(c) => onSettings({ channels: c })}
      />
    </div>
  );
}
