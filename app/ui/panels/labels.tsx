/**
 * Label display (paper III-C): the latest value of every channel of every output, with the
 * output's name, and the block's live status text ("trained on 340 samples"). Numbers are
 * refreshed at most 5 times a second so that they can be read.
 */
import { useCallback, useEffect, useRef, useState, type ReactNode } from "react";
import type { BlockInfo, DataMessage } from "../../engine/protocol";
import type { Telemetry } from "../../engine/runtime/runtime";
import { useBlockData, useTelemetrySelector } from "../client/hooks";
import { channelLabel, formatValue } from "./channels";
import { onFrame } from "./frame";
import type { OutputInfo } from "./view-props";

/** Values listed one by one at most; beyond, the first ones and a summary. */
export const LABELS_MAX = 64;
const REFRESH_MS = 200;

const selectText = (t: Telemetry | undefined, block: string): string =>
  t?.blocks.find((b) => b.name === block)?.text ?? "";

/** The block's live status text (from telemetry). */
export function StatusText({ block }: { block: string }): ReactNode {
  const text = useTelemetrySelector((t) => selectText(t, block), Object.is);
  return (
    <p className="mp-status-text" aria-live="polite">
      {text || <span className="mp-muted">no status text</span>}
    </p>
  );
}

export function LabelDisplay({ block, active }: { block: BlockInfo; active: boolean }): ReactNode {
  return (
    <div className="mp-labels" data-view="label" data-block={block.name}>
      <StatusText block={block.name} />
      {block.outputs.map((o) => (
        <OutputValues key={o.name} block={block} output={o} active={active} />
      ))}
    </div>
  );
}

/** What an output sent last: its latest event's values and how many events it sent. */
interface Latest {
  t: number;
  rows: number;
  cols: number;
  v: Float64Array;
  events: number;
}

/**
 * Watches the output while `active` and keeps its latest event; re-renders at most every
 * REFRESH_MS, on an animation frame, when something new came.
 */
function useLatestEvent(block: BlockInfo, output: OutputInfo, active: boolean): Latest {
  const { rows, cols } = output.shape;
  const stride = rows * cols;
  const latest = useRef<Latest>({ t: NaN, rows, cols, v: new Float64Array(stride), events: 0 });
  const dirty = useRef(false);
  const [, setTick] = useState(0);
  const onData = useCallback(
    (m: DataMessage) => {
      const n = m.t.length;
      if (n === 0) return;
      const l = latest.current;
      l.t = m.t[n - 1]!;
      l.events += n + m.skipped;
      if (stride > 0) l.v.set(m.v.subarray((n - 1) * stride, n * stride));
      dirty.current = true;
    },
    [stride],
  );
  useBlockData(block.name, output.name, onData, active, 20);
  useEffect(() => {
    if (!active) return undefined;
    let last = 0;
    return onFrame((now) => {
      if (!dirty.current || now - last < REFRESH_MS) return;
      dirty.current = false;
      last = now;
      setTick((x) => x + 1);
    });
  }, [active]);
  return latest.current;
}

/** The smallest, largest and sum of the first `stride` values. */
function valueRange(v: Float64Array, stride: number): { lo: number; hi: number; sum: number } {
  let lo = Infinity;
  let hi = -Infinity;
  let sum = 0;
  for (let i = 0; i < stride; i++) {
    const x = v[i]!;
    if (x < lo) lo = x;
    if (x > hi) hi = x;
    sum += x;
  }
  return { lo, hi, sum };
}

/** Min, mean and max of all the values when there are more than are listed (else nothing). */
function ValuesSummary({ latest, stride }: { latest: Latest; stride: number }): ReactNode {
  if (stride <= LABELS_MAX) return null;
  const { lo, hi, sum } = valueRange(latest.v, stride);
  return (
    <p className="mp-muted">
      all {stride}: min {formatValue(lo)}, mean {formatValue(sum / stride)}, max {formatValue(hi)} —
      the first {LABELS_MAX} below
    </p>
  );
}

/** The first LABELS_MAX values, each by its channel label (or [row, col] for a matrix). */
function ValueList({ latest, output }: { latest: Latest; output: OutputInfo }): ReactNode {
  const { rows, cols } = output.shape;
  const shown = Math.min(rows * cols, LABELS_MAX);
  return (
    <dl className="mp-values">
      {Array.from({ length: shown }, (_x, i) => (
        <div key={i} className="mp-value">
          <dt>{rows > 1 ? `[${Math.floor(i / cols)}, ${i % cols}]` : channelLabel(output, i)}</dt>
          <dd>{formatValue(latest.v[i]!)}</dd>
        </div>
      ))}
    </dl>
  );
}

/** The output's name and shape. */
function OutputHeading({ output }: { output: OutputInfo }): ReactNode {
  return (
    <h4 className="mp-output-name">
      {output.name}{" "}
      <span className="mp-muted">
        [{output.shape.rows}, {output.shape.cols}]
      </span>
    </h4>
  );
}

/** One output: its heading and its latest values (or why there are none). */
function OutputValues({
  block,
  output,
  active,
}: {
  block: BlockInfo;
  output: OutputInfo;
  active: boolean;
}): ReactNode {
  const l = useLatestEvent(block, output, active);
  const stride = output.shape.rows * output.shape.cols;
  const has = Number.isFinite(l.t);
  return (
    <section className="mp-output" aria-label={`Output ${output.name}`}>
      <OutputHeading output={output} />
      {stride === 0 ? (
        <p className="mp-muted">
          events without values (a timer): {has ? `${l.events} ticks seen` : "no tick seen yet"}
        </p>
      ) : !has ? (
        <p className="mp-muted">{active ? "waiting for data…" : "hidden: no data is watched"}</p>
      ) : (
        <>
          <ValuesSummary latest={l} stride={stride} />
          <ValueList latest={l} output={output} />
        </>
      )}
    </section>
  );
}
