/**
 * Status tab: the last minute of the block's timing status as a strip of colours (with the word
 * and share of each status: colour is never the only signal), its actual rate against the
 * desired one, its delivery delay (the largest of each telemetry window against the delay that
 * reads as late), and its figures — compute time (mean / max), delivery delay (p50 / p99 / max),
 * drops on its inputs, errors and the last error, its status text and, for timers, ticks, the
 * catch-up policy, the batching interval and lateness. The history is recorded from telemetry
 * (20 Hz) for as long as the panel exists, visible or not (telemetry flows anyway); drawing
 * happens only while the tab is shown.
 */
import { useCallback, useEffect, useMemo, useRef, useState, type ReactNode } from "react";
import type { BlockInfo } from "../../engine/protocol";
import type { BlockTelemetry } from "../../engine/runtime/runtime";
import type { Status } from "../../engine/runtime/status";
import { useEngine } from "../client/hooks";
import { StatusIcon, STATUS_HELP, statusText } from "../graph/status";
import { formatValue } from "./channels";
import { latencyText } from "./latency";
import { fitCanvas, readTheme, useWidth } from "./canvas";
import { onFrame } from "./frame";
import { STATUS_ORDER, StatusHistory } from "./status-history";

export interface StatusRecorder {
  history: StatusHistory;
  latest: BlockTelemetry | undefined;
  /** The delivery delay above which a batch reads as late, ms (NaN before any telemetry). */
  lateMs: number;
  version: number;
}

/** Records the block's telemetry while the calling component is mounted. */
export function useStatusRecorder(block: string): StatusRecorder {
  const client = useEngine();
  const rec = useMemo<StatusRecorder>(
    () => ({ history: new StatusHistory(60), latest: undefined, lateMs: NaN, version: 0 }),
    [block],
  );
  useEffect(
    () =>
      client.onTelemetry((t) => {
        const b = t.blocks.find((x) => x.name === block);
        if (!b) return;
        rec.latest = b;
        rec.lateMs = b.delay.lateMs;
        rec.history.push(
          t.t,
          b.status,
          b.rate,
          b.computeMeanMs,
          b.computeMaxMs,
          b.delay.windowMaxMs,
        );
        rec.version++;
      }),
    [client, block, rec],
  );
  return rec;
}

/** The block's late threshold as the engine says it (NaN before any telemetry). */
const lateMsOf = (r: StatusRecorder): number => r.lateMs;

const STATUS_FALLBACK: Record<Status, string> = {
  ontime: "#1a9850",
  lagging: "#d73027",
  stumbling: "#c51b7d",
  idle: "#8c8c8c",
};
const REFRESH_MS = 250;
const HEIGHT = 196;
const STRIP_H = 22;
/** Height of the delivery-delay band at the bottom of the history. */
const DELAY_H = 52;

export function StatusView({
  block,
  recorder,
  active,
}: {
  block: BlockInfo;
  recorder: StatusRecorder;
  active: boolean;
}): ReactNode {
  const [, setTick] = useState(0);
  const canvas = useRef<HTMLCanvasElement>(null);
  const wrap = useRef<HTMLDivElement>(null);
  const width = useRef(0);
  const seen = useRef(-1);
  const draw = useCallback(() => {
    const c = canvas.current;
    if (c && width.current > 0)
      drawHistory(
        c,
        width.current,
        HEIGHT,
        recorder.history,
        block.desiredRate,
        lateMsOf(recorder),
      );
  }, [recorder, block.desiredRate]);
  const onResize = useCallback(
    (w: number) => {
      width.current = w;
      draw();
    },
    [draw],
  );
  useWidth(wrap, onResize);
  useEffect(() => {
    if (!active) return undefined;
    let last = 0;
    return onFrame((now) => {
      if (recorder.version === seen.current || now - last < REFRESH_MS) return;
      seen.current = recorder.version;
      last = now;
      draw();
      setTick((x) => x + 1);
    });
  }, [active, recorder, draw]);

  const b = recorder.latest;
  const sum = recorder.history.summary();
  const status: Status = b?.status ?? "idle";
  const late = lateMsOf(recorder);
  return (
    <div className="mp-statusview" data-view="status" data-block={block.name}>
      <div className="mp-status-now">
        <span className={`mp-status-badge mp-st-${status}`} title={STATUS_HELP[status]}>
          <StatusIcon status={status} /> {statusText(status, b?.stumbling ?? false)}
        </span>
        <span>
          <strong>{b ? b.rate.toFixed(b.rate >= 100 ? 0 : 1) : "—"}</strong> Hz of{" "}
          {formatHz(block.desiredRate)}
        </span>
        {b?.text ? <span className="mp-status-text-inline">{b.text}</span> : null}
      </div>
      <div ref={wrap} className="mp-canvas-wrap" style={{ height: HEIGHT }}>
        <canvas
          ref={canvas}
          role="img"
          aria-label={`Status of ${block.name} over the last minute: ${STATUS_ORDER.map((s) => `${statusText(s, false)} ${Math.round(sum.fraction[s] * 100)} %`).join(", ")}; largest delivery delay ${delayMs(sum.delayMaxMs)}`}
        />
      </div>
      <ul className="mp-status-legend" aria-label="Share of the last minute">
        {STATUS_ORDER.map((s) => (
          <li key={s} title={STATUS_HELP[s]}>
            <span className={`mp-swatch mp-st-bg-${s}`} aria-hidden="true" /> {statusText(s, false)}{" "}
            <strong>{Math.round(sum.fraction[s] * 100)} %</strong>
          </li>
        ))}
        <li className="mp-muted">last {Math.round(Math.min(60, sum.samples / 20))} s</li>
      </ul>
      {b ? (
        <dl className="mp-figures">
          <Figure
            term="Compute (last 50 ms)"
            value={`mean ${ms(b.computeMeanMs)}, max ${ms(b.computeMaxMs)}`}
          />
          <Figure
            term="Compute (last minute)"
            value={`mean ${ms(sum.computeMeanMs)}, max ${ms(sum.computeMaxMs)}`}
          />
          <Figure
            term="Delivery delay"
            value={
              b.delay.n > 0
                ? `p50 ${delayMs(b.delay.p50Ms)}, p99 ${delayMs(b.delay.p99Ms)}, max ${delayMs(b.delay.maxMs)}`
                : "—"
            }
            title="Time of processing − timestamp of the oldest event of each batch"
            warn={b.delay.p99Ms > late}
          />
          <Figure
            term="Delivery delay (last minute)"
            value={`max ${delayMs(sum.delayMaxMs)} (late above ${delayMs(late)})`}
            warn={sum.delayMaxMs > late}
          />
          <Figure
            term="Period"
            value={block.desiredRate > 0 ? ms(1000 / block.desiredRate) : "—"}
          />
          <Figure
            term="Rate (last minute)"
            value={`${formatValue(sum.rateMin)}–${formatValue(sum.rateMax)} Hz`}
          />
          <Figure term="Events" value={String(b.events)} />
          <Figure
            term="Latency"
            value={latencyText(b.latencyMs)}
            title="Mean of (emission time − timestamp of the newest event of each output); a few µs below zero is the clock's resolution and reads 0"
          />
          <Figure term="Dropped on inputs" value={String(b.dropsIn)} warn={b.dropsIn > 0} />
          <Figure term="Errors" value={String(b.errors)} warn={b.errors > 0} />
          {b.timer && (
            <>
              <Figure
                term="Ticks"
                value={
                  b.timer.catchUp === "skip"
                    ? `${b.timer.fired} fired, ${b.timer.missed} skipped${b.timer.running ? "" : " (stopped)"}`
                    : `${b.timer.fired} fired, none lost${b.timer.running ? "" : " (stopped)"}`
                }
                title={
                  b.timer.catchUp === "skip"
                    ? "CatchUp: skip — after a late wake-up only the newest due tick fires; the others are skipped"
                    : "Lossless: every due tick fires, late ones together in one batch"
                }
                warn={b.timer.catchUp === "skip" && b.timer.missed > 0}
              />
              <Figure
                term="Catch-up · batching"
                value={`${b.timer.catchUp === "skip" ? "skip (newest tick only)" : "all ticks"} · ${b.timer.batchingMs > 0 ? delayMs(b.timer.batchingMs) : "none"}`}
                title="Catch-up policy after a late wake-up; batching: the worker wakes at most once per this interval"
              />
              <Figure
                term="Lateness"
                value={`p50 ${b.timer.latenessP50Us.toFixed(0)} µs, p99 ${b.timer.latenessP99Us.toFixed(0)} µs, max ${b.timer.latenessMaxUs.toFixed(0)} µs`}
              />
            </>
          )}
          {b.lastError && (
            <div className="mp-figure mp-lasterror">
              <dt>Last error</dt>
              <dd role="alert">{b.lastError}</dd>
            </div>
          )}
        </dl>
      ) : (
        <p className="mp-muted">No telemetry yet: it arrives while the pipeline runs.</p>
      )}
    </div>
  );
}

function Figure({
  term,
  value,
  warn,
  title,
}: {
  term: string;
  value: string;
  warn?: boolean;
  title?: string;
}): ReactNode {
  return (
    <div className={`mp-figure${warn ? " mp-warn" : ""}`} title={title}>
      <dt>{term}</dt>
      <dd>{value}</dd>
    </div>
  );
}

/** A delay, to the precision that matters (2 significant digits). */
const delayMs = (x: number): string =>
  x >= 10 ? `${x.toFixed(0)} ms` : x >= 1 ? `${x.toFixed(1)} ms` : `${(x * 1000).toFixed(0)} µs`;
const ms = (x: number): string =>
  x >= 100 ? `${x.toFixed(0)} ms` : x >= 1 ? `${x.toFixed(2)} ms` : `${(x * 1000).toFixed(0)} µs`;
const formatHz = (x: number): string => (x > 0 ? `${formatValue(x)} Hz` : "— (event-driven)");

function statusColors(el: Element): Record<Status, string> {
  const css = getComputedStyle(el);
  const out = { ...STATUS_FALLBACK };
  for (const s of STATUS_ORDER)
    out[s] = css.getPropertyValue(`--status-${s}`).trim() || STATUS_FALLBACK[s];
  return out;
}

function drawHistory(
  canvas: HTMLCanvasElement,
  width: number,
  height: number,
  h: StatusHistory,
  desired: number,
  lateMs: number,
): void {
  const ctx = fitCanvas(canvas, width, height);
  if (!ctx) return;
  const theme = readTheme(canvas);
  const colors = statusColors(canvas);
  ctx.clearRect(0, 0, width, height);
  const left = 44;
  const right = width - 6;
  const w = Math.max(10, right - left);
  const newest = h.newestT;
  const from = newest - h.seconds;
  const xOf = (t: number): number => left + ((t - from) / h.seconds) * w;
  // The strip.
  ctx.fillStyle = theme.grid;
  ctx.fillRect(left, 0, w, STRIP_H);
  let prevX = NaN;
  h.forEach((t, s) => {
    const x = xOf(t);
    const x0 = Number.isFinite(prevX) && x - prevX < 4 ? prevX : x - w / (h.seconds * 20);
    ctx.fillStyle = colors[s];
    ctx.fillRect(x0, 0, Math.max(1, x - x0 + 0.5), STRIP_H);
    prevX = x;
  });
  ctx.fillStyle = theme.muted;
  ctx.font = "11px system-ui, sans-serif";
  ctx.textBaseline = "middle";
  ctx.textAlign = "right";
  ctx.fillText("status", left - 4, STRIP_H / 2);
  // The rate.
  const top = STRIP_H + 8;
  const bottom = height - 14 - DELAY_H - 8;
  let seen = 0;
  h.forEach((_t, _s, rate) => {
    if (rate > seen) seen = rate;
  });
  // Up to twice the desired rate: a momentary burst must not flatten the line.
  let maxRate =
    desired > 0 ? Math.min(Math.max(desired * 1.2, seen * 1.05), desired * 2) : seen * 1.05;
  if (!(maxRate > 0)) maxRate = 1;
  const clipped = seen > maxRate;
  const yOf = (r: number): number => Math.max(top, bottom - (r / maxRate) * (bottom - top));
  ctx.strokeStyle = theme.grid;
  ctx.lineWidth = 1;
  ctx.strokeRect(left + 0.5, top + 0.5, w, bottom - top);
  if (desired > 0) {
    ctx.setLineDash([4, 3]);
    ctx.strokeStyle = theme.muted;
    ctx.beginPath();
    ctx.moveTo(left, yOf(desired));
    ctx.lineTo(right, yOf(desired));
    ctx.stroke();
    ctx.strokeStyle = colors.lagging;
    ctx.beginPath();
    ctx.moveTo(left, yOf(desired * 0.95));
    ctx.lineTo(right, yOf(desired * 0.95));
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = theme.muted;
    ctx.fillText(formatValue(desired), left - 4, yOf(desired));
  }
  ctx.fillText("0", left - 4, bottom);
  ctx.strokeStyle = theme.accent;
  ctx.lineWidth = 1.5;
  ctx.beginPath();
  let first = true;
  h.forEach((t, _s, rate) => {
    const x = xOf(t);
    const y = yOf(rate);
    if (first) ctx.moveTo(x, y);
    else ctx.lineTo(x, y);
    first = false;
  });
  ctx.stroke();
  ctx.fillStyle = theme.muted;
  ctx.textAlign = "left";
  ctx.fillText(
    `rate, Hz (dashed: desired and 95 %)${clipped ? `; peaks above ${formatValue(maxRate)} clipped` : ""}`,
    left + 4,
    top + 8,
  );
  // The delivery delay: the largest of each telemetry window, as bars (red above late).
  const dTop = height - 14 - DELAY_H;
  const dBottom = height - 14;
  let seenDelay = 0;
  h.forEach((_t, _s, _r, _cm, _cx, d) => {
    if (d > seenDelay) seenDelay = d;
  });
  // Late shows two thirds up; a stall far beyond it is clipped (and said so).
  const maxDelay = Math.max(lateMs * 1.5, Math.min(seenDelay * 1.05, lateMs * 4));
  const dClipped = seenDelay > maxDelay;
  const dyOf = (d: number): number => Math.max(dTop, dBottom - (d / maxDelay) * (dBottom - dTop));
  ctx.strokeStyle = theme.grid;
  ctx.lineWidth = 1;
  ctx.strokeRect(left + 0.5, dTop + 0.5, w, DELAY_H);
  const barW = Math.max(1, w / (h.seconds * 20));
  h.forEach((t, _s, _r, _cm, _cx, d) => {
    if (!(d > 0)) return;
    const y = dyOf(d);
    ctx.fillStyle = d > lateMs ? colors.lagging : theme.accent;
    ctx.fillRect(xOf(t) - barW, y, barW, dBottom - y);
  });
  ctx.setLineDash([4, 3]);
  ctx.strokeStyle = colors.lagging;
  ctx.beginPath();
  ctx.moveTo(left, dyOf(lateMs));
  ctx.lineTo(right, dyOf(lateMs));
  ctx.stroke();
  ctx.setLineDash([]);
  ctx.fillStyle = theme.muted;
  ctx.textAlign = "right";
  ctx.fillText(String(Math.round(lateMs)), left - 4, dyOf(lateMs));
  ctx.fillText("0", left - 4, dBottom);
  ctx.textAlign = "left";
  ctx.fillText(
    `delivery delay, ms (largest per 50 ms; dashed: late)${dClipped ? `; up to ${formatValue(Math.round(seenDelay))} clipped` : ""}`,
    left + 4,
    dTop + 8,
  );
  ctx.textAlign = "right";
  ctx.textBaseline = "top";
  ctx.fillText("now", right, dBottom + 2);
  ctx.textAlign = "left";
  ctx.fillText(`−${h.seconds} s`, left, dBottom + 2);
}
