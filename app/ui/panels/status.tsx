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
import { useEffect, useMemo, type ReactNode } from "react";
import type { BlockInfo } from "../../engine/protocol";
import type { BlockTelemetry } from "../../engine/runtime/runtime";
import type { Status } from "../../engine/runtime/status";
import { useEngine } from "../client/hooks";
import { StatusIcon, STATUS_HELP, statusText } from "../graph/status";
import { formatValue } from "./channels";
import { latencyText } from "./latency";
import { STATUS_ORDER, StatusHistory } from "./status-history";
import { useStatusDrawing } from "./use-status-drawing";

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

const HEIGHT = 196;

export function StatusView({
  block,
  recorder,
  active,
}: {
  block: BlockInfo;
  recorder: StatusRecorder;
  active: boolean;
}): ReactNode {
  const { canvas, wrap } = useStatusDrawing(recorder, block.desiredRate, HEIGHT, active);
  const b = recorder.latest;
  const sum = recorder.history.summary();
  const status: Status = b?.status ?? "idle";
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
      <StatusLegend sum={sum} />
      {b ? (
        <StatusFigures b={b} sum={sum} desiredRate={block.desiredRate} late={lateMsOf(recorder)} />
      ) : (
        <p className="mp-muted">No telemetry yet: it arrives while the pipeline runs.</p>
      )}
    </div>
  );
}

type Summary = ReturnType<StatusHistory["summary"]>;

/** Each status's share of the last minute, and how much of it was recorded. */
function StatusLegend({ sum }: { sum: Summary }): ReactNode {
  return (
    <ul className="mp-status-legend" aria-label="Share of the last minute">
      {STATUS_ORDER.map((s) => (
        <li key={s} title={STATUS_HELP[s]}>
          <span className={`mp-swatch mp-st-bg-${s}`} aria-hidden="true" /> {statusText(s, false)}{" "}
          <strong>{Math.round(sum.fraction[s] * 100)} %</strong>
        </li>
      ))}
      <li className="mp-muted">last {Math.round(Math.min(60, sum.samples / 20))} s</li>
    </ul>
  );
}

/** The block's figures from its latest telemetry and the last minute. */
function StatusFigures({
  b,
  sum,
  desiredRate,
  late,
}: {
  b: BlockTelemetry;
  sum: Summary;
  desiredRate: number;
  late: number;
}): ReactNode {
  return (
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
      <Figure term="Period" value={desiredRate > 0 ? ms(1000 / desiredRate) : "—"} />
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
      {b.timer && <TimerFigures timer={b.timer} />}
      {b.lastError && (
        <div className="mp-figure mp-lasterror">
          <dt>Last error</dt>
          <dd role="alert">{b.lastError}</dd>
        </div>
      )}
    </dl>
  );
}

/** A timer's ticks, catch-up policy, batching and lateness. */
function TimerFigures({ timer }: { timer: NonNullable<BlockTelemetry["timer"]> }): ReactNode {
  return (
    <>
      <Figure
        term="Ticks"
        value={
          timer.catchUp === "skip"
            ? `${timer.fired} fired, ${timer.missed} skipped${timer.running ? "" : " (stopped)"}`
            : `${timer.fired} fired, none lost${timer.running ? "" : " (stopped)"}`
        }
        title={
          timer.catchUp === "skip"
            ? "CatchUp: skip — after a late wake-up only the newest due tick fires; the others are skipped"
            : "Lossless: every due tick fires, late ones together in one batch"
        }
        warn={timer.catchUp === "skip" && timer.missed > 0}
      />
      <Figure
        term="Catch-up · batching"
        value={`${timer.catchUp === "skip" ? "skip (newest tick only)" : "all ticks"} · ${timer.batchingMs > 0 ? delayMs(timer.batchingMs) : "none"}`}
        title="Catch-up policy after a late wake-up; batching: the worker wakes at most once per this interval"
      />
      <Figure
        term="Lateness"
        value={`p50 ${timer.latenessP50Us.toFixed(0)} µs, p99 ${timer.latenessP99Us.toFixed(0)} µs, max ${timer.latenessMaxUs.toFixed(0)} µs`}
      />
    </>
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
