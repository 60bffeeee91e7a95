/**
 * What the participant screen shows, as a pure function of what the engine sent: the Stimulus
 * block's phase, cue and progress outputs and its status text, the held-out test Trigger's status
 * text and capture times, the engine's clock and state. Screens: waiting (nothing runs yet, or
 * the engine stopped), rest (relax, with the next gesture), cue (rise, hold, capture, fall of a
 * gesture), test-ready / test-rest / test-cue (the held-out test, cued as such) and end.
 */
import type { EngineState } from "../../engine/protocol";
import { cueLabels, PHASES, type Phase } from "./cues";
import { parseTriggerText, type TestCapture } from "./test-schedule";

export type Screen = "waiting" | "rest" | "cue" | "test-ready" | "test-rest" | "test-cue" | "end";

export interface ParticipantModel {
  screen: Screen;
  /** The training phase (rest, rise, hold, capture, fall) on the rest and cue screens. */
  phase: Phase | undefined;
  /** The gesture to make now (cue, test-cue). */
  gesture: string | undefined;
  /** The gesture that comes next (rest, test-ready, test-rest). */
  next: string | undefined;
  /** What to do, in words. */
  instruction: string;
  /** "Cue 3 of 18", "Test 2 of 10". */
  count: string;
  /** "Repetition 1 of 3" (training with several repetitions). */
  repetition: string;
  /** Seconds left in this step (NaN: unknown). */
  left: number;
  /** How much of this step has passed, 0..1. */
  progress: number;
}

/** What the Stimulus block sent (its outputs and status text). */
export interface StimulusLive {
  phase: Phase | undefined;
  /** Engine time of the current phase's first event (NaN: it began before we watched). */
  phaseStart: number;
  /** Label index of the current cue (NaN at rest). */
  cue: number;
  /** The `progress` output: cue number (1-based), cue count, next cue's label index. */
  progress: readonly [number, number, number] | undefined;
  text: string;
  /** Engine time of the latest phase event (NaN: none yet). */
  lastT: number;
}

/** What the held-out test Trigger sent: its status text and the time of its latest capture event. */
export interface TestLive {
  captures: readonly TestCapture[];
  text: string;
  /** Engine time of its latest start (label) or stop (NaN) event. */
  lastEventT: number;
}

export interface ModelInput {
  params: Record<string, unknown>;
  stimulus: StimulusLive;
  test: TestLive | undefined;
  engine: EngineState;
  /** The engine's clock now (seconds, as event times). */
  now: number;
  /** The Stimulus's data is recent (it stops when the protocol does not run). */
  fresh: boolean;
}

const PHASE_PARAM: Partial<Record<Phase, string>> = {
  rest: "Rest",
  rise: "Rise",
  hold: "Hold",
  capture: "Capture",
  fall: "Fall",
};
const PHASE_DEFAULT: Record<Phase, number> = {
  rest: 2,
  rise: 1,
  hold: 2,
  capture: 5,
  fall: 1,
  end: 0,
};

const INSTRUCTION: Record<Phase, string> = {
  rest: "Relax",
  rise: "Get ready",
  hold: "Hold it",
  capture: "Hold it — recording",
  fall: "Release slowly",
  end: "Done",
};

/** The phase's length in seconds, from the block's params (their defaults when not given). */
export function phaseSeconds(params: Record<string, unknown>, phase: Phase): number {
  const p = params[PHASE_PARAM[phase] ?? ""];
  return typeof p === "number" ? p : PHASE_DEFAULT[phase];
}

/** Cues in one repetition: the Tasks, or every label when there are none. */
function tasksPerRepetition(params: Record<string, unknown>): number {
  if (Array.isArray(params.Tasks)) return params.Tasks.length;
  return cueLabels(params).length;
}

const leftText = /([\d.]+) s left/;
/** The Stimulus's status text while its protocol runs ("hold: fist (2 of 9), 1.0 s left"). */
const RUNNING_TEXT = /^(rest|rise|hold|capture|fall): /;
const restText = /^rest: (.+) \((\d+) of (\d+)\)/;

/** Seconds left and progress of a step of `duration` s that began at `start` (NaN: unknown). */
function timing(start: number, duration: number, now: number, fallback = NaN) {
  const left = Number.isFinite(start) ? Math.max(0, start + duration - now) : fallback;
  const progress =
    duration > 0 && Number.isFinite(left) ? Math.min(1, Math.max(0, 1 - left / duration)) : 0;
  return { left, progress };
}

const BLANK: Omit<ParticipantModel, "screen" | "instruction"> = {
  phase: undefined,
  gesture: undefined,
  next: undefined,
  count: "",
  repetition: "",
  left: NaN,
  progress: 0,
};

/** The training screens: rest (with the next gesture) and a cue's rise, hold, capture, fall. */
function trainingModel(input: ModelInput, phase: Phase): ParticipantModel {
  const { params, stimulus: s, now } = input;
  const labels = cueLabels(params);
  const rest = restText.exec(s.text);
  const [k, n, nextIndex] = s.progress ?? [Number(rest?.[2] ?? NaN), Number(rest?.[3] ?? NaN), NaN];
  const name = (i: number): string | undefined =>
    Number.isFinite(i) ? (labels[i] ?? `cue ${i + 1}`) : undefined;
  const perRep = tasksPerRepetition(params);
  const reps = typeof params.Repetitions === "number" ? params.Repetitions : 1;
  const duration = phaseSeconds(params, phase);
  const fallback = Number(leftText.exec(s.text)?.[1] ?? NaN);
  const { left, progress } = timing(s.phaseStart, duration, now, fallback);
  const common = {
    ...BLANK,
    phase,
    count: Number.isFinite(k) && Number.isFinite(n) ? `Cue ${k} of ${n}` : "",
    repetition:
      reps > 1 && perRep > 0 && Number.isFinite(k)
        ? `Repetition ${Math.ceil(k / perRep)} of ${reps}`
        : "",
    left,
    progress,
  };
  if (phase === "rest") {
    return {
      ...common,
      screen: "rest",
      next: name(nextIndex) ?? rest?.[1],
      instruction: INSTRUCTION.rest,
    };
  }
  return { ...common, screen: "cue", gesture: name(s.cue), instruction: INSTRUCTION[phase] };
}

/** The held-out test after the protocol, or the end when there is none (or it is over). */
function testModel(input: ModelInput): ParticipantModel {
  const test = input.test;
  const end: ParticipantModel = { ...BLANK, screen: "end", instruction: "Thank you!" };
  if (!test || test.captures.length === 0) return end;
  const t = parseTriggerText(test.text);
  const done = t.done ?? 0;
  const total = t.total ?? test.captures.length;
  if (t.capturing === undefined && done >= total) return end;
  if (input.engine !== "running") return end;
  if (t.capturing !== undefined) {
    const c = test.captures[Math.max(0, done - 1)];
    const { left, progress } = timing(test.lastEventT, c?.seconds ?? NaN, input.now);
    return {
      ...BLANK,
      screen: "test-cue",
      gesture: t.capturing,
      instruction: "Make this gesture and hold it",
      count: `Test ${Math.max(1, done)} of ${total}`,
      left,
      progress,
    };
  }
  const next = test.captures[done]?.label;
  if (done === 0) {
    return {
      ...BLANK,
      screen: "test-ready",
      next,
      instruction: "Relax — the test begins soon",
      count: `Test: ${total} gestures`,
    };
  }
  const pause = test.captures[done - 1]?.pauseAfter ?? NaN;
  const { left, progress } = timing(test.lastEventT, pause, input.now);
  return {
    ...BLANK,
    screen: "test-rest",
    next,
    instruction: "Relax",
    count: `Test ${done + 1} of ${total} next`,
    left,
    progress,
  };
}

/** The screen for what the engine last sent. */
export function participantModel(input: ModelInput): ParticipantModel {
  const s = input.stimulus;
  const ended = s.phase === "end" || s.text.startsWith("done:");
  if (ended) return testModel(input);
  if (input.engine !== "running") {
    return {
      ...BLANK,
      screen: "waiting",
      instruction: input.engine === "stopped" ? "Paused" : "Please wait",
    };
  }
  // Data that stopped coming means the protocol stopped, unless the block says it runs (a
  // moment without data on a busy machine).
  const runs = input.fresh || RUNNING_TEXT.test(s.text);
  if (!runs || s.phase === undefined) {
    return {
      ...BLANK,
      screen: "waiting",
      instruction: s.phase === undefined ? "The session starts soon" : "Please wait",
    };
  }
  return trainingModel(input, s.phase);
}

/** The phase of a `phase` output value (0 rest … 5 end). */
export function phaseOf(v: number): Phase | undefined {
  return PHASES[v];
}
