/**
 * The held-out test phase of a training pipeline, as the participant screen shows it: a Trigger
 * with a `Schedule` that labels data no learning block trains on (in pipelines/examples/
 * training.yaml, `Session`: fist, open, … after the Stimulus's protocol, while the predictor only
 * predicts). Pure functions of the graph, the Trigger's params and its status text.
 */
import type { BlockInfo, GraphInfo } from "../../engine/protocol";

/** One capture of a Trigger's schedule: its label, how long it lasts and the pause after it. */
export interface TestCapture {
  label: string;
  seconds: number;
  /** Seconds from its end to the next capture's start (NaN after the last). */
  pauseAfter: number;
}

const isRecord = (v: unknown): v is Record<string, unknown> =>
  v !== null && typeof v === "object" && !Array.isArray(v);
const num = (v: unknown, fallback: number): number =>
  typeof v === "number" && Number.isFinite(v) ? v : fallback;

/** Blocks that learn from a trigger input: a capture they receive is training, not a test. */
const LEARNS = (b: BlockInfo): boolean => b.category === "Learning" || b.type === "Buffer";

/**
 * The Trigger that plays the held-out test: the first one with a Schedule whose outputs feed no
 * learning block (a predictor, a Buffer). Undefined when the pipeline has none.
 */
export function heldOutTrigger(graph: GraphInfo | undefined): BlockInfo | undefined {
  if (!graph) return undefined;
  return graph.blocks.find(
    (t) =>
      t.type === "Trigger" &&
      t.params.Schedule !== undefined &&
      !graph.blocks.some((b) => LEARNS(b) && b.inputs.some((i) => i.block === t.name)),
  );
}

/** The schedule of a Trigger's params as its captures, in the order they are played. */
export function testCaptures(params: Record<string, unknown>): TestCapture[] {
  const labels = isRecord(params.Labels) ? Object.keys(params.Labels) : [];
  const s = params.Schedule;
  const starts: { at: number; label: string; seconds: number }[] = [];
  if (Array.isArray(s)) {
    for (const e of s) {
      if (!isRecord(e) || typeof e.Label !== "string") continue;
      starts.push({ at: num(e.At, 0), label: e.Label, seconds: num(e.Seconds, 0) });
    }
    starts.sort((a, b) => a.at - b.at);
  } else if (isRecord(s)) {
    const seq = Array.isArray(s.Sequence)
      ? s.Sequence.filter((x): x is string => typeof x === "string")
      : labels;
    const seconds = num(s.Seconds, 0);
    const pause = num(s.Pause, 2);
    let at = num(s.Start, 0);
    for (let r = 0; r < Math.max(1, num(s.Repetitions, 1)); r++) {
      for (const label of seq) {
        starts.push({ at, label, seconds });
        at += seconds + pause;
      }
    }
  }
  return starts.map((e, i) => {
    const next = starts[i + 1];
    return {
      label: e.label,
      seconds: e.seconds,
      pauseAfter: next ? Math.max(0, next.at - (e.at + e.seconds)) : NaN,
    };
  });
}

/** What a Trigger's status text says: the label it captures (if any) and the schedule's count. */
export interface TriggerText {
  capturing: string | undefined;
  /** Captures of the schedule started so far, and how many it has (undefined: no schedule). */
  done: number | undefined;
  total: number | undefined;
}

/** Reads "capturing 'fist' (2/6); schedule 3/10" (app/blocks/learning/trigger.ts, describe). */
export function parseTriggerText(text: string): TriggerText {
  const c = /^capturing '(.*?)' \(\d+\/\d+\)/.exec(text);
  const s = /schedule (\d+)\/(\d+)/.exec(text);
  return {
    capturing: c ? c[1] : undefined,
    done: s ? Number(s[1]) : undefined,
    total: s ? Number(s[2]) : undefined,
  };
}
