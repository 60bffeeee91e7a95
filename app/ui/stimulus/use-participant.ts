/**
 * The participant screen's view of the engine: watches the Stimulus block's `phase`, `cue` and
 * `progress` outputs and the held-out test Trigger's `label` output, reads both status texts
 * from telemetry, keeps an estimate of the engine's clock and re-renders ten times a second for
 * the countdown. Returns the screen model (participant-model.ts).
 */
import { useCallback, useEffect, useMemo, useRef, useState, useSyncExternalStore } from "react";
import type { BlockInfo, DataMessage } from "../../engine/protocol";
import type { EngineState } from "../../engine/protocol";
import { useBlockData, useEngine, useTelemetrySelector } from "../client/hooks";
import {
  participantModel,
  phaseOf,
  type ParticipantModel,
  type StimulusLive,
} from "./participant-model";
import { testCaptures } from "./test-schedule";

/** Data older than this means the protocol does not run (its outputs come at the timer's rate). */
const FRESH_MS = 1500;

const EMPTY: StimulusLive = {
  phase: undefined,
  phaseStart: NaN,
  cue: NaN,
  progress: undefined,
  text: "",
  lastT: NaN,
};

/** The engine's clock: the latest engine time seen and when it arrived here. */
interface Clock {
  t: number;
  at: number;
}

function useEngineClock(): { clock: React.MutableRefObject<Clock>; see(t: number): void } {
  const clock = useRef<Clock>({ t: NaN, at: 0 });
  const see = useCallback((t: number) => {
    const c = clock.current;
    const now = performance.now();
    if (!(t <= c.t + (now - c.at) / 1000)) clock.current = { t, at: now };
  }, []);
  const client = useEngine();
  useEffect(() => client.onTelemetry((tel) => see(tel.t)), [client, see]);
  return { clock, see };
}

/** Follows the phase, cue and progress outputs of a Stimulus block. */
function useStimulusData(block: string, see: (t: number) => void) {
  const [live, setLive] = useState<Omit<StimulusLive, "text">>(EMPTY);
  const arrived = useRef(0);
  useEffect(() => {
    setLive(EMPTY);
    arrived.current = 0;
  }, [block]);
  const onPhase = useCallback(
    (m: DataMessage) => {
      const n = m.t.length;
      if (n === 0) return;
      arrived.current = performance.now();
      see(m.t[n - 1]!);
      setLive((p) => {
        let { phase, phaseStart } = p;
        for (let i = 0; i < n; i++) {
          const ph = phaseOf(m.v[i * m.cols]!);
          if (ph !== phase) {
            // The first phase seen may have begun before we watched: its start is unknown.
            phaseStart = phase === undefined ? NaN : m.t[i]!;
            phase = ph;
          }
        }
        return { ...p, phase, phaseStart, lastT: m.t[n - 1]! };
      });
    },
    [see],
  );
  const onCue = useCallback((m: DataMessage) => {
    if (m.t.length === 0) return;
    const c = m.v[(m.t.length - 1) * m.cols]!;
    setLive((p) => (Object.is(p.cue, c) ? p : { ...p, cue: c }));
  }, []);
  const onProgress = useCallback((m: DataMessage) => {
    if (m.t.length === 0 || m.cols < 3) return;
    const o = (m.t.length - 1) * m.cols;
    const v: [number, number, number] = [m.v[o]!, m.v[o + 1]!, m.v[o + 2]!];
    setLive((p) =>
      p.progress && p.progress.every((x, i) => Object.is(x, v[i])) ? p : { ...p, progress: v },
    );
  }, []);
  useBlockData(block, "phase", onPhase, true, 50);
  useBlockData(block, "cue", onCue, true, 50);
  useBlockData(block, "progress", onProgress, true, 50);
  return { live, arrived };
}

/** The time of the held-out test Trigger's latest capture event (start or stop). */
function useTestEvents(trigger: BlockInfo | undefined, see: (t: number) => void): number {
  const [lastT, setLastT] = useState(NaN);
  const onLabel = useCallback(
    (m: DataMessage) => {
      const n = m.t.length;
      if (n === 0) return;
      see(m.t[n - 1]!);
      setLastT(m.t[n - 1]!);
    },
    [see],
  );
  useBlockData(trigger?.name ?? "", "label", onLabel, trigger !== undefined, 50);
  return lastT;
}

/** The engine's state, read again once subscribed (a state may come before an effect runs). */
function useEngineStateNow(): EngineState {
  const client = useEngine();
  const subscribe = useCallback((changed: () => void) => client.onState(changed), [client]);
  return useSyncExternalStore(subscribe, () => client.state);
}

/** Re-renders every 100 ms (the countdown between data messages). */
function useTick(): void {
  const [, tick] = useState(0);
  useEffect(() => {
    const id = window.setInterval(() => tick((n) => n + 1), 100);
    return () => window.clearInterval(id);
  }, []);
}

export function useParticipant(block: BlockInfo, trigger: BlockInfo | undefined): ParticipantModel {
  const engine = useEngineStateNow();
  const { clock, see } = useEngineClock();
  const { live, arrived } = useStimulusData(block.name, see);
  const testEventT = useTestEvents(trigger, see);
  const text = useTelemetrySelector(
    (t) => t?.blocks.find((b) => b.name === block.name)?.text ?? "",
    Object.is,
  );
  const testText = useTelemetrySelector(
    (t) => (trigger ? (t?.blocks.find((b) => b.name === trigger.name)?.text ?? "") : ""),
    Object.is,
  );
  const captures = useMemo(() => (trigger ? testCaptures(trigger.params) : []), [trigger]);
  useTick();
  const perf = performance.now();
  const c = clock.current;
  return participantModel({
    params: block.params,
    stimulus: { ...live, text },
    test: trigger ? { captures, text: testText, lastEventT: testEventT } : undefined,
    engine,
    now: c.t + (perf - c.at) / 1000,
    fresh: arrived.current > 0 && perf - arrived.current < FRESH_MS,
  });
}
