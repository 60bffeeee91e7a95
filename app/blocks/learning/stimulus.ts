import { z } from "zod";
import {
  defineBlock,
  legacyNumber,
  LegacyParamsError,
  legacyVector,
  vectorShape,
  type Frame,
} from "../../engine";
import { timerInput } from "../shared/inputs";
import { publish } from "../shared/named";
import { SeededRandom } from "../shared/random";
import { plural, TextThrottle } from "../shared/text";
import {
  checkLabels,
  labelsSchema,
  seconds,
  targetColumnLabels,
  targetVector,
  unknownLabel,
} from "./labels";

/**
 * What a Stimulus offers by its name (shared/named.ts, kind "Stimulus"): its trigger frames (the
 * `trigger` output's events) as they are sent, for a StimTrigger wired to its default output.
 */
export interface StimulusTriggers {
  readonly targetWidth: number;
  /** Calls `fn` with every trigger frame (borrowed: copy what you keep) before it is emitted. */
  onTrigger(fn: (f: Frame) => void): () => void;
  /** Ends a capture phase in progress at time `t` (MOSAIC's TAC moved its Stimulus to fall). */
  endCapture(t: number): void;
}

/** Most cues in one protocol (Tasks × Repetitions). */
const MAX_CUES = 100_000;

/** Phases, in order; their numbers are the `phase` output. */
const REST = 0;
const RISE = 1;
// 2: hold
const CAPTURE = 3;
const FALL = 4;
const END = 5;
const PHASES = ["rest", "rise", "hold", "capture", "fall", "end"] as const;
const DURATION_PARAMS = ["Rest", "Rise", "Hold", "Capture", "Fall"] as const;

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
    const add = (i: { code: "custom"; path: (string | number)[]; message: string }) =>
      ctx.addIssue(i);
    if (p.Labels !== undefined) checkLabels(p.Labels, "Labels", add);
    const labels = p.Labels ?? {};
    const names = Object.keys(labels);
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
    let width = names.length > 0 ? labels[names[0]!]!.length : -1;
    const seen = new Map<string, number[]>();
    p.Tasks.forEach((t, i) => {
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
    const timer = timerInput(ctx, 0);
    const { names, targets, tasks } = resolveTasks(p);
    const T = targets[0]!.length;
    const N = tasks.length * p.Repetitions;
    // The order of the cues: label index per cue.
    const order = new Int32Array(N);
    const rng = new SeededRandom(p.Seed);
    for (let r = 0; r < p.Repetitions; r++) {
      const base = r * tasks.length;
      for (let i = 0; i < tasks.length; i++) order[base + i] = tasks[i]!;
      if (p.Shuffle) {
        for (let i = tasks.length - 1; i > 0; i--) {
          const j = Math.floor(rng.uniform() * (i + 1));
          const a = order[base + i]!;
          order[base + i] = order[base + j]!;
          order[base + j] = a;
        }
      }
    }
    const dur = Float64Array.of(p.Rest, p.Rise, p.Hold, p.Capture, p.Fall, 0);

    // One-hot targets name their columns (fist, open, …): panels and predictors show them.
    const columns = targetColumnLabels(names, targets);
    const target = ctx.output(vectorShape(T), "target", columns && { labels: columns });
    const phaseOut = ctx.output(vectorShape(1), "phase");
    const trigger = ctx.output(vectorShape(T), "trigger", columns && { labels: columns });
    const cueOut = ctx.output(vectorShape(1), "cue");
    const progressOut = ctx.output(vectorShape(3), "progress", { labels: ["cue", "cues", "next"] });

    // `-Timer` (MOSAIC's form): subscribed only while the protocol runs.
    const onDemand = !timer.subscribed;
    /** idle: not started; armed: starts at the next tick; running; ended. */
    let state: "idle" | "armed" | "running" | "ended" | "stopped" = "idle";
    let started = false; // the pipeline runs
    let cue = 0;
    let phase = REST;
    let phaseStart = 0;
    let phaseEnd = 0;
    let capturing = false;
    let lastT = 0;
    const throttle = new TextThrottle(0.1);

    // Trigger events of one process call (at most two per tick), sent as one frame.
    let trigT = new Float64Array(8);
    let trigStop = new Uint8Array(8);
    let trigLabel = new Int32Array(8);
    let trigN = 0;
    const queueTrigger = (t: number, label: number): void => {
      if (trigN === trigT.length) {
        const c = trigN * 2;
        const nt = new Float64Array(c);
        nt.set(trigT);
        const ns = new Uint8Array(c);
        ns.set(trigStop);
        const nl = new Int32Array(c);
        nl.set(trigLabel);
        trigT = nt;
        trigStop = ns;
        trigLabel = nl;
      }
      trigT[trigN] = t;
      trigStop[trigN] = label < 0 ? 1 : 0;
      trigLabel[trigN] = label;
      trigN++;
    };
    // Blocks that read this Stimulus by name (a StimTrigger wired to its default output, as
    // MOSAIC's files write it) get every trigger frame as it is sent.
    const triggerListeners = new Set<(f: Frame) => void>();
    const withdraw = publish(ctx, "Stimulus", {
      targetWidth: T,
      onTrigger(fn: (f: Frame) => void) {
        triggerListeners.add(fn);
        return () => triggerListeners.delete(fn);
      },
      endCapture: (t: number) => endCapture(t),
    } satisfies StimulusTriggers);
    const flushTrigger = (): void => {
      if (trigN === 0) return;
      const f = trigger.frame(trigN);
      for (let i = 0; i < trigN; i++) {
        f.t[i] = trigT[i]!;
        if (trigStop[i] === 1) f.v.fill(NaN, i * T, (i + 1) * T);
        else f.v.set(targets[trigLabel[i]!]!, i * T);
      }
      trigN = 0;
      for (const fn of triggerListeners) fn(f);
      trigger.emit(f);
    };

    const subscribe = (on: boolean): void => {
      if (onDemand) ctx.setSubscribed(0, on);
    };

    const describe = (t: number): void => {
      let s: string;
      if (state === "idle") s = `ready: ${plural(N, "cue")} (start to begin)`;
      else if (state === "armed") s = `starting: ${plural(N, "cue")}`;
      else if (state === "ended") s = `done: ${plural(N, "cue")}`;
      else if (state === "stopped")
        s = `stopped at ${names[order[Math.min(cue, N - 1)]!]} (${cue + 1} of ${N}), ${PHASES[phase]}`;
      else if (phase === END) s = `done: ${plural(N, "cue")}`;
      else {
        s =
          `${PHASES[phase]}: ${names[order[cue]!]} (${cue + 1} of ${N}), ` +
          `${seconds(Math.max(0, phaseEnd - t))} left`;
      }
      ctx.setText(s);
    };

    /** Leaves the current phase at time `at`; trigger events are stamped `stamp`. */
    const advance = (at: number, stamp: number): void => {
      if (phase === CAPTURE && capturing) {
        capturing = false;
        queueTrigger(stamp, -1);
      }
      phase++;
      if (phase > FALL) {
        phase = REST;
        cue++;
        if (cue === N) phase = END; // sent at the next tick, which ends the protocol
      }
      phaseStart = at;
      phaseEnd = phase === END ? Infinity : at + dur[phase]!;
      throttle.reset();
    };

    /** Ends the current capture phase at `t` (the skip input, a TAC's success). */
    const endCapture = (t: number): void => {
      if (state !== "running" || phase !== CAPTURE) return;
      advance(Math.max(t, phaseStart), t);
      flushTrigger();
      describe(t);
    };

    const begin = (): void => {
      state = "armed";
      cue = 0;
      subscribe(true);
      describe(lastT);
    };
    /** Ends the protocol now (stop action, reset): sends the stop of a capture in progress. */
    const halt = (next: "idle" | "stopped" | "armed"): void => {
      if (capturing) {
        capturing = false;
        queueTrigger(ctx.now(), -1);
        flushTrigger();
      }
      state = next;
      subscribe(next === "armed");
      describe(ctx.now());
    };

    /** The `progress` values at `off`: cue number, cue count, label of the next cue to start. */
    const writeProgress = (v: Float64Array, off: number): void => {
      v[off] = Math.min(cue + 1, N);
      v[off + 1] = N;
      const next = phase === REST ? cue : cue + 1;
      v[off + 2] = phase !== END && next < N ? order[next]! : NaN;
    };

    const processTicks = (f: Frame): void => {
      const n = f.n;
      let o: Frame | null = null;
      let ph: Frame | null = null;
      let cu: Frame | null = null;
      let pr: Frame | null = null;
      let k = 0;
      for (let e = 0; e < n; e++) {
        if (state !== "armed" && state !== "running") break;
        const t = f.t[e]!;
        lastT = t;
        if (state === "armed") {
          state = "running";
          cue = 0;
          phase = REST;
          phaseStart = t;
          phaseEnd = t + dur[REST]!;
          capturing = false;
          throttle.reset();
        }
        while (t >= phaseEnd) advance(phaseEnd, t);
        if (phase === CAPTURE && !capturing) {
          capturing = true;
          queueTrigger(t, order[cue]!);
        }
        if (o === null) {
          o = target.frame(n - e);
          ph = phaseOut.frame(n - e);
          cu = cueOut.frame(n - e);
          pr = progressOut.frame(n - e);
        }
        o.t[k] = t;
        ph!.t[k] = t;
        cu!.t[k] = t;
        pr!.t[k] = t;
        ph!.v[k] = phase;
        writeProgress(pr!.v, k * 3);
        const off = k * T;
        if (phase === REST || phase === END) {
          o.v.fill(0, off, off + T);
          cu!.v[k] = NaN;
        } else {
          const label = order[cue]!;
          const tg = targets[label]!;
          let gain = 1;
          if (phase === RISE || phase === FALL) {
            const x = (Math.PI / 2) * ((t - phaseStart) / dur[phase]!);
            const s = phase === RISE ? Math.sin(x) : Math.cos(x);
            gain = s * s;
          }
          for (let c = 0; c < T; c++) o.v[off + c] = tg[c]! * gain;
          cu!.v[k] = label;
        }
        k++;
        if (phase === END) {
          state = "ended";
          subscribe(false);
          throttle.reset();
        }
        if (throttle.due(t)) describe(t);
      }
      flushTrigger();
      if (o !== null) {
        o.n = k;
        ph!.n = k;
        cu!.n = k;
        pr!.n = k;
        target.emit(o);
        phaseOut.emit(ph!);
        cueOut.emit(cu!);
        progressOut.emit(pr!);
      }
    };

    describe(0);

    return {
      start() {
        started = true;
        if (p.Autostart) begin();
        else subscribe(false);
      },
      stop() {
        started = false;
      },
      process(f, port) {
        if (port === 0) {
          processTicks(f);
          return;
        }
        // Skip input: any event ends the current capture phase at its time.
        if (f.n > 0) endCapture(f.t[0]!);
      },
      dispose() {
        withdraw();
        triggerListeners.clear();
      },
      reset() {
        halt(started && p.Autostart ? "armed" : "idle");
        lastT = 0;
        throttle.reset();
      },
      setParam(name, value) {
        const i = DURATION_PARAMS.indexOf(name as (typeof DURATION_PARAMS)[number]);
        if (i < 0) return;
        dur[i] = value as number;
        if (state === "running" && phase === i) phaseEnd = phaseStart + dur[i]!;
      },
      actions: {
        start: {
          label: "Start",
          description:
            "Start the protocol from the first cue at the next tick (restarts it if running)",
          run() {
            if (state === "running" || state === "armed") halt("armed");
            else begin();
            return `starting: ${plural(N, "cue")}`;
          },
        },
        stop: {
          label: "Stop",
          description: "Stop the protocol (a capture in progress is stopped)",
          run() {
            if (state !== "running" && state !== "armed") return "not running";
            halt("stopped");
            return "stopped";
          },
        },
        skip: {
          label: "Skip",
          description:
            "End the current phase now (e.g. a capture the participant is not ready for)",
          run() {
            if (state !== "running") return "not running";
            if (phase === END) return "the protocol is ending";
            const t = Math.max(ctx.now(), phaseStart);
            const from = PHASES[phase];
            advance(t, t);
            flushTrigger();
            describe(t);
            return `skipped ${from}: now ${PHASES[phase]}`;
          },
        },
      },
    };
  },
});
