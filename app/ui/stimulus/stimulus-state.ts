/**
 * What the Stimulus view shows, from what it knows of the block's data and its status text
 * ("hold: fist (2 of 10), 1.5 s left"): data stops when the protocol is not running, and then
 * the status text says what is going on.
 */
import type { Phase } from "./cues";
import type { Live } from "./use-stimulus-live";

const PHASE_PARAM: Record<Phase, string | undefined> = {
  rest: "Rest",
  rise: "Rise",
  hold: "Hold",
  capture: "Capture",
  fall: "Fall",
  end: undefined,
};
const PHASE_DEFAULT: Record<Phase, number> = {
  rest: 2,
  rise: 1,
  hold: 2,
  capture: 5,
  fall: 1,
  end: 0,
};

const parseLeft = (text: string): number => {
  const m = /([\d.]+) s left/.exec(text);
  return m ? Number(m[1]) : NaN;
};
/** The cue's label from the status text ("hold: fist (2 of 10), 1.5 s left"). */
const parseLabel = (text: string): string => {
  const m = /^(?:rise|hold|capture|fall): (.+) \(\d+ of \d+\)/.exec(text);
  return m ? m[1]! : "";
};
const parseCount = (text: string): string => {
  const m = /\((\d+ of \d+)\)/.exec(text);
  return m ? m[1]! : "";
};

export interface StimulusState {
  /** Data arrives and the protocol is in a phase before its end. */
  running: boolean;
  phase: Phase | undefined;
  label: string;
  /** Seconds left in the phase (NaN: unknown or not running). */
  left: number;
  /** The phase's progress, 0..1. */
  progress: number;
  /** "2 of 10", from the status text. */
  count: string;
}

export function stimulusState(
  live: Live,
  text: string,
  labels: readonly string[],
  params: Readonly<Record<string, unknown>>,
): StimulusState {
  // Data stops when the protocol is not running: then the status text says what is going on.
  const stale = live.arrived === 0 || performance.now() - live.arrived > 600;
  const running = !stale && live.phase !== undefined && live.phase !== "end";
  const phase = running ? live.phase : stale ? undefined : live.phase;
  // The cue and phase streams arrive as separate messages: until the cue of a new phase is in,
  // the status text names it.
  const label = Number.isFinite(live.cue)
    ? (labels[live.cue] ?? `cue ${live.cue + 1}`)
    : parseLabel(text);
  const param = phase ? PHASE_PARAM[phase] : undefined;
  const p = params[param ?? ""];
  const duration = typeof p === "number" ? p : phase ? PHASE_DEFAULT[phase] : 0;
  const now = live.lastT + (performance.now() - live.arrived) / 1000;
  let left = Number.isNaN(live.phaseStart)
    ? parseLeft(text)
    : Math.max(0, live.phaseStart + duration - now);
  if (!running) left = NaN;
  const progress =
    duration > 0 && Number.isFinite(left) ? Math.min(1, Math.max(0, 1 - left / duration)) : 0;
  return { running, phase, label, left, progress, count: parseCount(text) };
}
