/**
 * What the Stimulus view knows of its block's data: the phase and when it started, the cue and
 * the effort (|target| relative to the largest seen), from the `phase`, `cue` and `target`
 * outputs watched while visible.
 */
import { useCallback, useEffect, useRef, useState } from "react";
import type { DataMessage } from "../../engine/protocol";
import { useBlockData } from "../client/hooks";
import { PHASES, type Phase } from "./cues";

export interface Live {
  phase: Phase | undefined;
  cue: number;
  /** Event time of the phase's first event seen (NaN: the phase started before we watched). */
  phaseStart: number;
  /** Latest event time, and when it arrived (performance.now()). */
  lastT: number;
  arrived: number;
  /** |target| relative to the cue's full target, 0..1. */
  effort: number;
}

/** The phase after a `phase` message, with the event time it started at. */
function nextPhase(p: Live, m: DataMessage): Live {
  let { phase, phaseStart } = p;
  for (let i = 0; i < m.t.length; i++) {
    const ph = PHASES[m.v[i * m.cols]!] ?? undefined;
    if (ph !== phase) {
      // The first phase we see may have started before we watched: its start is unknown.
      phaseStart = phase === undefined ? NaN : m.t[i]!;
      phase = ph;
    }
  }
  return {
    ...p,
    phase,
    phaseStart,
    lastT: m.t[m.t.length - 1]!,
    arrived: performance.now(),
  };
}

export function useStimulusLive(block: string, visible: boolean): Live {
  const [live, setLive] = useState<Live>({
    phase: undefined,
    cue: NaN,
    phaseStart: NaN,
    lastT: NaN,
    arrived: 0,
    effort: 0,
  });
  const peak = useRef(1e-12);

  const onPhase = useCallback((m: DataMessage) => {
    setLive((p) => nextPhase(p, m));
  }, []);
  const onCue = useCallback((m: DataMessage) => {
    const c = m.v[(m.t.length - 1) * m.cols]!;
    setLive((p) => (Object.is(p.cue, c) ? p : { ...p, cue: c }));
  }, []);
  const onTarget = useCallback((m: DataMessage) => {
    const n = m.t.length;
    const off = (n - 1) * m.cols;
    let mx = 0;
    for (let k = 0; k < m.cols; k++) mx = Math.max(mx, Math.abs(m.v[off + k]!));
    for (let i = 0; i < n * m.cols; i++) peak.current = Math.max(peak.current, Math.abs(m.v[i]!));
    const effort = mx / peak.current;
    setLive((p) => (Math.abs(p.effort - effort) < 0.005 ? p : { ...p, effort }));
  }, []);
  useBlockData(block, "phase", onPhase, visible, 50);
  useBlockData(block, "cue", onCue, visible, 50);
  useBlockData(block, "target", onTarget, visible, 20);
  return live;
}

/** Smooth countdown between data messages: renders again at 10 Hz while a phase runs. */
export function useCountdownTick(visible: boolean, phase: Phase | undefined): void {
  const [, tick] = useState(0);
  useEffect(() => {
    if (!visible || phase === undefined || phase === "end") return undefined;
    const id = window.setInterval(() => tick((n) => n + 1), 100);
    return () => window.clearInterval(id);
  }, [visible, phase]);
}
