/** Small controls shared by the panels' toolbars. */
import { useEffect, useState, type ReactNode } from "react";
import type { Reduce } from "./channels";

export const REDUCE_LABEL: Record<Reduce, string> = {
  latest: "latest value",
  smooth: "smoothed",
  envelope: "envelope |x|",
};
export const TAUS_S = [0.1, 0.3, 1] as const;

/** The latest / smoothed / envelope choice shared by the spider plot and the heatmap. */
export function ReduceControls({
  settings,
  onSettings,
}: {
  settings: { reduce: Reduce; tauS: number };
  onSettings: (p: { reduce?: Reduce; tauS?: number }) => void;
}): ReactNode {
  return (
    <>
      <label className="mp-field">
        Value
        <select
          value={settings.reduce}
          onChange={(e) => onSettings({ reduce: e.target.value as Reduce })}
        >
          {(Object.keys(REDUCE_LABEL) as Reduce[]).map((r) => (
            <option key={r} value={r}>
              {REDUCE_LABEL[r]}
            </option>
          ))}
        </select>
      </label>
      {settings.reduce !== "latest" && (
        <label className="mp-field" title="Time constant of the moving mean">
          over
          <select
            value={settings.tauS}
            onChange={(e) => onSettings({ tauS: Number(e.target.value) })}
          >
            {TAUS_S.map((t) => (
              <option key={t} value={t}>
                {t} s
              </option>
            ))}
          </select>
        </label>
      )}
    </>
  );
}

/** Two numbers, min below max, applied on Enter or leaving a box; "from view" copies `suggest`. */
export function RangeInputs({
  min,
  max,
  onChange,
  suggest,
}: {
  min: number;
  max: number;
  onChange: (min: number, max: number) => void;
  suggest?: () => [number, number];
}): ReactNode {
  const [a, setA] = useState(String(min));
  const [b, setB] = useState(String(max));
  useEffect(() => {
    setA(String(min));
    setB(String(max));
  }, [min, max]);
  const na = Number(a);
  const nb = Number(b);
  const error =
    a.trim() === "" || b.trim() === "" || !Number.isFinite(na) || !Number.isFinite(nb)
      ? "numbers needed"
      : !(na < nb)
        ? "min must be below max"
        : "";
  const apply = (): void => {
    if (!error) onChange(na, nb);
  };
  return (
    <span className="mp-field mp-range">
      <input
        aria-label="minimum"
        value={a}
        inputMode="decimal"
        aria-invalid={!!error}
        onChange={(e) => setA(e.target.value)}
        onBlur={apply}
        onKeyDown={(e) => e.key === "Enter" && apply()}
      />
      to
      <input
        aria-label="maximum"
        value={b}
        inputMode="decimal"
        aria-invalid={!!error}
        onChange={(e) => setB(e.target.value)}
        onBlur={apply}
        onKeyDown={(e) => e.key === "Enter" && apply()}
      />
      {suggest && (
        <button
          type="button"
          className="mp-btn mp-small"
          title="Use the range shown now"
          onClick={() => {
            const [x, y] = suggest();
            const fx = +x.toPrecision(3);
            const fy = +y.toPrecision(3);
            if (fx < fy) onChange(fx, fy);
          }}
        >
          from view
        </button>
      )}
      {error && <span className="mp-error">{error}</span>}
    </span>
  );
}

/** `#rrggbb` → rgba with alpha (other colour forms are returned as they are). */
export function withAlpha(color: string, alpha: number): string {
  if (/^#fff$/i.test(color)) color = "#ffffff";
  const m = /^#([0-9a-f]{6})$/i.exec(color);
  if (!m) return color;
  const v = parseInt(m[1]!, 16);
  return `rgba(${(v >> 16) & 255}, ${(v >> 8) & 255}, ${v & 255}, ${alpha})`;
}

/** Pause / play as an inline SVG (no font needed). */
export function PlayPauseIcon({ paused }: { paused: boolean }): ReactNode {
  return (
    <svg width="10" height="10" viewBox="0 0 10 10" aria-hidden="true" focusable="false">
      {paused ? (
        <path d="M2 1l7 4-7 4z" fill="currentColor" />
      ) : (
        <path d="M2 1h2v8H2zM6 1h2v8H6z" fill="currentColor" />
      )}
    </svg>
  );
}
