/**
 * The data of a predictor's Training view: its `versus` output ([prediction…, target…] per
 * feature event) watched while the view is open, kept as the recent traces (for the overlay) and
 * as the window of labelled samples its figures describe (./training-metrics.ts). Refreshed on
 * screen at most 4 times a second.
 */
import { useCallback, useEffect, useRef, useState } from "react";
import type { DataMessage } from "../../engine/protocol";
import { useBlockData } from "../client/hooks";
import { onFrame } from "./frame";
import { TrainingWindow, type TrainingSummary } from "./training-metrics";
import type { Traces } from "./training-plot";

/** Labelled samples the figures describe (a minute at 25 Hz). */
export const WINDOW_SAMPLES = 1500;
/** Events kept for the overlay. */
export const TRACE_EVENTS = 300;
const REFRESH_MS = 250;

export interface TrainingFeed {
  summary: TrainingSummary;
  traces: Traces;
  /** Forgets the samples seen so far (the figures start again). */
  clear(): void;
}

const emptyTraces = (m: number): Traces => ({
  m,
  t: new Float64Array(TRACE_EVENTS),
  pred: new Float64Array(TRACE_EVENTS * m),
  target: new Float64Array(TRACE_EVENTS * m),
  n: 0,
});

/** Appends one event to the traces (shifting the oldest out when full). */
function pushTrace(tr: Traces, t: number, v: Float64Array, at: number): void {
  const m = tr.m;
  if (tr.n === TRACE_EVENTS) {
    tr.t.copyWithin(0, 1);
    tr.pred.copyWithin(0, m);
    tr.target.copyWithin(0, m);
    tr.n--;
  }
  tr.t[tr.n] = t;
  for (let k = 0; k < m; k++) {
    tr.pred[tr.n * m + k] = v[at + k]!;
    tr.target[tr.n * m + k] = v[at + m + k]!;
  }
  tr.n++;
}

export function useTrainingFeed(block: string, m: number, active: boolean): TrainingFeed {
  // Made once (useState's initialiser), not on every render.
  const [win] = useState(() => ({ current: new TrainingWindow(m, WINDOW_SAMPLES) }));
  const [traces] = useState(() => ({ current: emptyTraces(m) }));
  const dirty = useRef(false);
  const [summary, setSummary] = useState<TrainingSummary>(() => win.current.summary());
  const [, setTick] = useState(0);
  const onData = useCallback(
    (msg: DataMessage) => {
      const w = 2 * m;
      for (let e = 0; e < msg.t.length; e++) {
        win.current.add(msg.v, e * w, msg.v, e * w + m);
        pushTrace(traces.current, msg.t[e]!, msg.v, e * w);
      }
      dirty.current = true;
    },
    [m],
  );
  useBlockData(block, "versus", onData, active, 100);
  useEffect(() => {
    if (!active) return undefined;
    let last = 0;
    return onFrame((now) => {
      if (!dirty.current || now - last < REFRESH_MS) return;
      dirty.current = false;
      last = now;
      setSummary(win.current.summary());
      setTick((x) => x + 1);
    });
  }, [active]);
  const clear = useCallback(() => {
    win.current.clear();
    traces.current = emptyTraces(m);
    setSummary(win.current.summary());
  }, [m]);
  return { summary, traces: traces.current, clear };
}
