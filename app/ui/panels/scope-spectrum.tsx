/**
 * The scope's spectrum: Welch's PSD of each plotted channel over the window in view (what the
 * time plot shows: live, paused, zoomed or panned), on a log scale, with each channel's median
 * frequency (it falls as a muscle fatigues) marked and listed. Recomputed twice a second while the
 * data moves, once when it is held; nothing runs while the spectrum is off.
 */
import { useEffect, useRef, useState, type ReactNode, type RefObject } from "react";
import uPlot from "uplot";
import { channelColor, formatTick } from "./channels";
import { onFrame } from "./frame";
import { mountIn } from "./scope-plot";
import type { ScopeLive } from "./scope-draw";
import { indexRange } from "./scope-view";
import { medianFrequency, sampleRate, welch } from "./spectrum";

const HEIGHT = 200;
const REFRESH_MS = 500;

export interface SpectrumResult {
  f: Float64Array;
  /** One PSD per channel (null where it has no power: log scale). */
  p: (number | null)[][];
  mdf: number[];
  fs: number;
}

/** The spectrum of the samples in view (null with too few). */
export function spectrumOf(l: ScopeLive): SpectrumResult | null {
  const b = l.buffer;
  if (!b || b.count < 8) return null;
  // Exactly the samples in view (the view keeps one more on each side for the lines' ends).
  const all = b.view(l.x[0], l.x[1]);
  const [i0, i1] = indexRange(all[0]!, l.x[0], l.x[1]);
  const data = all.map((a) => a.subarray(i0, i1));
  const fs = sampleRate(data[0]!);
  let f: Float64Array | null = null;
  const p: (number | null)[][] = [];
  const mdf: number[] = [];
  for (let c = 1; c < data.length; c++) {
    const psd = welch(data[c]!, fs);
    if (!psd) return null;
    f = psd.f;
    p.push(Array.from(psd.p, (v) => (v > 0 ? v : null)));
    mdf.push(medianFrequency(psd));
  }
  return f ? { f, p, mdf, fs } : null;
}

function spectrumPlot(
  el: HTMLElement,
  channels: number[],
  unit: string,
  mdf: RefObject<number[]>,
): uPlot {
  const axis: Partial<uPlot.Axis> = {
    font: "11px system-ui, sans-serif",
    grid: { stroke: "rgba(31, 35, 40, 0.1)", width: 1 },
  };
  const opts: uPlot.Options = {
    width: Math.max(100, el.clientWidth),
    height: HEIGHT,
    legend: { show: false },
    cursor: { show: false },
    scales: { x: { time: false }, y: { distr: 3 } },
    axes: [
      {
        ...axis,
        values: (_u, s) => s.map((v) => `${formatTick(v, s.length > 1 ? s[1]! - s[0]! : 0)} Hz`),
      },
      {
        ...axis,
        size: 56,
        label: unit ? `${unit}²/Hz` : "per Hz",
        labelSize: 16,
        labelFont: "11px system-ui, sans-serif",
        // A log axis leaves some splits unlabelled (null).
        values: (_u, s) => s.map((v: number | null) => (v === null ? "" : v.toExponential(0))),
      },
    ],
    series: [
      {},
      ...channels.map((c) => ({ stroke: channelColor(c), width: 1, points: { show: false } })),
    ],
    hooks: {
      // Each channel's median frequency: a dashed line in its colour.
      draw: [
        (u) => {
          const ctx = u.ctx;
          ctx.save();
          ctx.setLineDash([4, 3]);
          mdf.current.forEach((m, k) => {
            if (!Number.isFinite(m)) return;
            const x = Math.round(u.valToPos(m, "x", true));
            ctx.strokeStyle = channelColor(channels[k] ?? k);
            ctx.beginPath();
            ctx.moveTo(x, u.bbox.top);
            ctx.lineTo(x, u.bbox.top + u.bbox.height);
            ctx.stroke();
          });
          ctx.restore();
        },
      ],
    },
  };
  return new uPlot(opts, [[0, 1], ...channels.map(() => [null, null])], mountIn(el));
}

export function ScopeSpectrum({
  live,
  channels,
  names,
  unit,
  active,
}: {
  live: RefObject<ScopeLive>;
  channels: number[];
  names: string[];
  unit: string;
  active: boolean;
}): ReactNode {
  const host = useRef<HTMLDivElement>(null);
  const plot = useRef<uPlot | null>(null);
  const mdf = useRef<number[]>([]);
  const [summary, setSummary] = useState<{ mdf: number[]; fs: number } | null>(null);

  useEffect(() => {
    const el = host.current;
    if (!el) return undefined;
    const u = spectrumPlot(el, channels, unit, mdf);
    plot.current = u;
    const ro = new ResizeObserver(() => {
      const w = Math.max(100, el.clientWidth);
      if (w !== u.width) u.setSize({ width: w, height: HEIGHT });
    });
    ro.observe(el);
    return () => {
      ro.disconnect();
      u.destroy();
      plot.current = null;
    };
  }, [channels, unit]);

  useEffect(() => {
    if (!active) return undefined;
    let last = -Infinity;
    let lastX: [number, number] = [NaN, NaN];
    return onFrame((now) => {
      const l = live.current;
      const moved = l.x[0] !== lastX[0] || l.x[1] !== lastX[1];
      if (!moved || now - last < REFRESH_MS || !plot.current) return;
      const s = spectrumOf(l);
      if (!s) return;
      last = now;
      lastX = [l.x[0], l.x[1]];
      mdf.current = s.mdf;
      plot.current.setData([Array.from(s.f), ...s.p] as uPlot.AlignedData);
      setSummary({ mdf: s.mdf, fs: s.fs });
    });
  }, [active, live, channels]);

  return (
    <div className="mp-spectrum" data-view="spectrum">
      <div ref={host} className="mp-plot" role="img" aria-label="Spectrum (Welch PSD, log scale)" />
      <p className="mp-foot mp-mdf" aria-label="Median frequency">
        {summary ? (
          <>
            Median frequency:{" "}
            {summary.mdf.map((m, k) => (
              <span key={k} className="mp-mdf-item" data-channel={names[k]} data-hz={m}>
                <span
                  className="mp-swatch"
                  style={{ background: channelColor(channels[k] ?? k) }}
                />
                {names[k]} {Number.isFinite(m) ? `${m.toFixed(1)} Hz` : "—"}
              </span>
            ))}
            <span className="mp-muted">
              {" "}
              · Welch PSD of the window in view, {summary.fs.toFixed(0)} samples/s
            </span>
          </>
        ) : (
          "waiting for data…"
        )}
      </p>
    </div>
  );
}
