import { z } from "zod";
import {
  defineBlock,
  legacyNumber,
  LegacyParamsError,
  legacyVector,
  type Frame,
} from "../../engine";
import { checkLabels, labelsSchema, targetVector, unknownLabel, type AddIssue } from "./labels";
import { CueCycle, cueOrder } from "./stimulus-cycle";
import { StimulusRun } from "./stimulus-run";

/**
 * What a Stimulus offers by its name (shared/named.ts, kind "Stimulus"): its trigger frames (the
 * `trigger` output's events) as they are sent, for a StimTrigger wired to its default output.
 */
export interface StimulusTriggers {
  readonly targetWidth: number;
  /** Cues in the protocol (Tasks × Repetitions): one capture phase each, so one TAC trial each. */
  readonly cues: number;
  /** Calls `fn` with every trigger frame (borrowed: copy what you keep) before it is emitted. */
  onTrigger(fn: (f: Frame) => void): () => void;
  /** Ends a capture phase in progress at time `t` (MOSAIC's TAC moved its Stimulus to fall). */
  endCapture(t: number): void;
}

/** Most cues in one protocol (Tasks × Repetitions). */
const MAX_CUES = 100_000;

const task = z.union([
  z.string().min(1),
  z.strictObject({
    Label: z.string().min(1).describe("Name of the cue (shown to the participant)"),
    Target: targetVector().describe("Its target vector"),
  }),
]);

const duration = (def: number, what: string) =>
  z
    .number()
    .min(0)
    .default(def)
    .describe(`${what}, in seconds (default ${def}); can be changed while running`);

const params = z
  .strictObject({
    Labels: labelsSchema()
      .optional()
      .describe(
        "Labels by name with their target vectors (as a Trigger's), e.g. { rest: [0, 0], fist: [1, 0] }; Tasks may name them",
      ),
    Tasks: z
      .array(task)
      .min(1)
      .max(MAX_CUES)
      .optional()
      .describe(
        "The cues in order: names of Labels, or { Label, Target } (default: every label once, in Labels order)",
      ),
    Repetitions: z
      .number()
      .int()
      .min(1)
      .max(MAX_CUES)
      .default(1)
      .describe("How many times the Tasks are played"),
    Shuffle: z
      .boolean()
      .default(false)
      .describe("Shuffle the Tasks within each repetition (seeded: the same Seed, the same order)"),
    Seed: z
      .number()
      .int()
      .min(0)
      .max(Number.MAX_SAFE_INTEGER)
      .default(1)
      .describe("Seed of the shuffle"),
    Rest: duration(2, "Rest before each cue (target: zeros)"),
    Rise: duration(1, "Ramp from rest to the target (sin²)"),
    Hold: duration(2, "Hold the target before capturing"),
    Capture: duration(5, "Hold the target while data is captured (MOSAIC's first param)"),
    Fall: duration(1, "Ramp from the target back to rest (cos²)"),
    Autostart: z
      .boolean()
      .default(false)
      .describe("Start the protocol when the pipeline starts (otherwise: the start action)"),
  })
  .superRefine((p, ctx) => {
    const add: AddIssue = (i) => ctx.addIssue(i);
    if (p.Labels !== undefined) checkLabels(p.Labels, "Labels", add);
    if (p.Tasks === undefined) {
      if (p.Labels === undefined) {
        add({
          code: "custom",
          path: ["Tasks"],
          message: "give Tasks (e.g. [{ Label: fist, Target: [1, 0] }]) or Labels",
        });
      }
      return;
    }
    checkTasks(p.Tasks, p.Labels ?? {}, add);
    if (p.Tasks.length * p.Repetitions > MAX_CUES) {
      add({
        code: "custom",
        path: ["Repetitions"],
        message:
          `${p.Tasks.length} tasks × ${p.Repetitions} repetitions make ` +
          `${p.Tasks.length * p.Repetitions} cues; at most ${MAX_CUES} are allowed`,
      });
    }
  });

/**
 * Every task names one of Labels or gives a { Label, Target } (a label given twice has one
 * target), and all targets have the same width.
 */
function checkTasks(
  tasks: readonly z.output<typeof task>[],
  labels: Record<string, number[]>,
  add: AddIssue,
): void {
  const names = Object.keys(labels);
  let width = names.length > 0 ? labels[names[0]!]!.length : -1;
  const seen = new Map<string, number[]>();
  tasks.forEach((t, i) => {
    if (typeof t === "string") {
      if (!Object.hasOwn(labels, t)) {
        add({
          code: "custom",
          path: ["Tasks", i],
          message:
            names.length > 0
              ? unknownLabel(t, names)
              : `task '${t}' names a label, but there are no Labels: write { Label: ${t}, Target: [...] } or give Labels`,
        });
      }
      return;
    }
    const known = Object.hasOwn(labels, t.Label) ? labels[t.Label] : seen.get(t.Label);
    if (known !== undefined && known.join() !== t.Target.join()) {
      add({
        code: "custom",
        path: ["Tasks", i, "Target"],
        message: `label '${t.Label}' already has the target [${known.join(", ")}]`,
      });
    }
    seen.set(t.Label, t.Target);
    if (width < 0) width = t.Target.length;
    else if (t.Target.length !== width) {
      add({
        code: "custom",
        path: ["Tasks", i, "Target"],
        message: `has ${t.Target.length} values, but the other targets have ${width}`,
      });
    }
  });
}

type Params = z.output<typeof params>;

/** The labels (names and targets, in cue-index order) and the task list as label indices. */
function resolveTasks(p: Params): { names: string[]; targets: Float64Array[]; tasks: number[] } {
  const names: string[] = [];
  const targets: Float64Array[] = [];
  const indexOf = (name: string, target: readonly number[]): number => {
    const i = names.indexOf(name);
    if (i >= 0) return i;
    names.push(name);
    targets.push(Float64Array.from(target));
    return names.length - 1;
  };
  for (const [n, v] of Object.entries(p.Labels ?? {})) indexOf(n, v);
  const list = p.Tasks ?? names.map((n) => n);
  const tasks = list.map((t) =>
    typeof t === "string" ? names.indexOf(t) : indexOf(t.Label, t.Target),
  );
  return { names, targets, tasks };
}

/** MOSAIC's task vectors, named: all zeros "rest", the others task1, task2… in order of appearance. */
function nameLegacyTasks(vectors: number[][]): { Label: string; Target: number[] }[] {
  const names = new Map<string, string>();
  let k = 0;
  return vectors.map((v) => {
    const key = v.join(";");
    let name = names.get(key);
    if (name === undefined) {
      name = v.every((x) => x === 0) ? "rest" : `task${++k}`;
      names.set(key, name);
    }
    return { Label: name, Target: v };
  });
}

export const Stimulus = defineBlock({
  type: "Stimulus",
  category: "Learning",
  summary:
    "A timed protocol of labelled cues for the participant (rest, rise, hold, capture, fall), with a trigger for recording.",
  help:
    "Guides the participant through a training protocol (paper III-G, IV-A; MOSAIC's Stimulus " +
    "and StimTrigger). Each cue (task) goes through the phases rest → rise → hold → capture → " +
    "fall, then the next cue starts; after the last, the protocol ends. Durations are `Rest`, " +
    "`Rise`, `Hold`, `Capture` and `Fall` seconds (MOSAIC's 2, 1, 2, 5, 1; a phase of 0 s is " +
    "skipped). Outputs, on every tick of the timer input while the protocol runs: `target` [1, T] " +
    "is what the participant should do — zeros at rest, the task's target t·sin²(π/2·τ/Rise) while " +
    "rising (τ: seconds into the phase), t while holding and capturing, t·cos²(π/2·τ/Fall) while " +
    "falling; `phase` [1, 1] is 0 rest, 1 rise, 2 hold, 3 capture, 4 fall, 5 end (sent once, on " +
    "the first tick after the last fall, with zeros); `cue` [1, 1] is the 0-based index of the task's label (NaN at rest and at " +
    "the end). `progress` [1, 3] is the protocol's position for a participant screen: the 1-based number of the current cue (at rest: of the cue about to start), the number of cues, and the label index of the next cue to start (at rest: the one about to start; NaN after the last). `trigger` [1, T] follows the Buffer's trigger protocol for steady contractions " +
    "only: the task's target at the first tick of its capture phase and all NaN when the capture " +
    "ends; plug it into a Buffer or a predictor's training input. Tasks are names of `Labels` or " +
    "`{ Label, Target }`; labels are numbered in Labels order, then in order of appearance. " +
    "`Repetitions` plays the list several times; `Shuffle` shuffles it within each repetition " +
    "(seeded). Time is the ticks' timestamps: the protocol starts at the first tick after " +
    "`start` (or the pipeline start with `Autostart`), and phases end on a fixed schedule from " +
    "there (no drift), so the virtual clock gives the same protocol every run. As in MOSAIC, a " +
    "timer input written `-Timer` is subscribed only while the protocol runs; written `Timer`, " +
    "ticks outside a protocol are ignored. An optional second input ends the current capture " +
    "phase at the time of any event it receives, e.g. a TAC's `trial` output (MOSAIC's TAC " +
    "moved its Stimulus to fall on success). Actions: `start` (from the first cue; restarts a " +
    "running protocol), `stop`, `skip` (ends the current phase now). `reset` stops a capture in " +
    "progress (sending the stop) and returns to the state after the pipeline start. Phase " +
    "durations can be changed while running (the current phase included). MOSAIC's " +
    "`[captureSeconds, a;b;c, …]` loads as Capture and Tasks (a zero vector is named rest, the " +
    "others task1, task2, …).",
  params,
  legacyParams: (args) => {
    const used = args.filter((a) => a.trim() !== "");
    if (used.length < 2) {
      throw new LegacyParamsError(
        "expected [captureSeconds, task1, task2, …]: a capture duration and at least one task vector a;b;c",
        "Tasks",
      );
    }
    const capture = legacyNumber(used[0]!, "the capture duration", "Capture");
    const vectors = used.slice(1).map((a, i) => legacyVector(a, `task ${i + 1}`, "Tasks"));
    return { Capture: capture, Tasks: nameLegacyTasks(vectors) };
  },
  legacyForm:
    "[captureSeconds, task1, task2, …]: the capture duration, then one target vector a;b;c per task",
  inputs: { min: 1, max: 2, labels: ["timer", "skip"] },
  outputs: ["target", "phase", "trigger", "cue", "progress"],
  live: ["Rest", "Rise", "Hold", "Capture", "Fall"],
  views: ["stimulus", "scope", "label"],
  panel:
    "The participant's cue (the label in large type, the target ramp and a countdown) with start, stop and skip buttons and the protocol's progress.",
  create(ctx, p: Params) {
    const { names, targets, tasks } = resolveTasks(p);
    const order = cueOrder(tasks, p.Repetitions, p.Shuffle, p.Seed);
    const cycle = new CueCycle(order, [p.Rest, p.Rise, p.Hold, p.Capture, p.Fall]);
    return new StimulusRun(ctx, { names, targets, cycle, autostart: p.Autostart }).instance();
  },
});
