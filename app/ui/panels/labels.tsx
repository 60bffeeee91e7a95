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

interface Latest {
  t: number;
  rows: number;
  cols: number;
  v: Float64Array;
  events: number;
}

function OutputValues({
  block,
  output,
  active,
}: {
  block: BlockInfo;
  output: OutputInfo;
  active: boolean;
}): ReactNode {
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

  const l = latest.current;
  const has = Number.isFinite(l.t);
  const shown = Math.min(stride, LABELS_MAX);
  let summary: ReactNode = null;
  if (has && stride > LABELS_MAX) {
    let lo = Infinity;
    let hi = -Infinity;
    let sum = 0;
    for (let i = 0; i < stride; i++) {
      const x = l.v[i]!;
      if (x < lo) lo = x;
      if (x > hi) hi = x;
      sum += x;
    }
    summary = (
      <p className="mp-muted">
        all {stride}: min {formatValue(lo)}, mean {formatValue(sum / stride)}, max {formatValue(hi)}{" "}
        — the first {LABELS_MAX} below
      </p>
    );
  }
  return (
    <section className="mp-output" aria-label={`Output ${output.name}`}>
      <h4 className="mp-output-name">
        {output.name}{" "}
        <span className="mp-muted">
          [{rows}, {cols}]
        </span>
      </h4>
      {stride === 0 ? (
        <p className="mp-muted">
          events without values (a timer): {has ? `${l.events} ticks seen` : "no tick seen yet"}
        </p>
      ) : !has ? (
        <p className="mp-muted">{active ? "waiting for data…" : "hidden: no data is watched"}</p>
      ) : (
        <>
          {summary}
          <dl className="mp-values">
            {Array.from({ length: shown }, (_x, i) => (
              <div key={i} className="mp-value">
                <dt>
                  {rows > 1 ? `[${Math.floor(i / cols)}, ${i % cols}]` : channelLabel(output, i)}
                </dt>
                <dd>{formatValue(l.v[i]!)}</dd>
              </div>
            ))}
          </dl>
        </>
      )}
    </section>
  );
}
