import { z } from "zod";
import {
  BlockConfigError,
  defineBlock,
  legacyNumber,
  LegacyParamsError,
  vectorShape,
} from "../../engine";
import { vectorInput, inputName } from "../shared/inputs";
import { extendedNumber } from "../shared/params";
import { SeededRandom } from "../shared/random";
import { plural, TextThrottle } from "../shared/text";
import { lookup } from "../shared/named";
import type { StimulusTriggers } from "./stimulus";
import { seconds } from "./trigger";

/** Most trials, and most target values (trials × DoFs) a TAC keeps. */
const MAX_TRIALS = 10_000;
const MAX_TARGET_VALUES = 1_000_000;

const numberOrVector = () => z.union([z.number(), z.array(z.number()).min(1).max(4096)]);

const params = z.strictObject({
  Targets: z
    .union([
      z.array(z.array(z.number()).min(1).max(4096)).min(1).max(MAX_TRIALS),
      z.strictObject({
        Random: z
          .strictObject({
            Count: z.number().int().min(1).max(MAX_TRIALS).describe("Number of targets (trials)"),
            Seed: z
              .number()
              .int()
              .min(0)
              .max(Number.MAX_SAFE_INTEGER)
              .default(1)
              .describe("Seed: the same seed gives the same targets"),
            Low: numberOrVector()
              .default(0)
              .describe("Lowest value of every DoF (a number, or one per DoF)"),
            High: numberOrVector()
              .default(1)
              .describe("Highest value of every DoF (a number, or one per DoF)"),
          })
          .describe("Targets drawn uniformly between Low and High, one value per DoF"),
      }),
    ])
    .optional()
    .describe(
      "The trials' targets: a list of target vectors (one value per DoF of the control input), " +
        "or { Random: { Count, Seed, Low, High } }; leave out when targets come from the target input",
    ),
  Tolerance: z
    .union([z.number().positive(), z.array(z.number().positive()).min(1).max(4096)])
    .default(0.2)
    .describe(
      "How close counts as inside the target, in the control's units: a number, or one per DoF " +
        "(see Metric); can be changed while running",
    ),
  Metric: z
    .enum(["euclidean", "box"])
    .default("euclidean")
    .describe(
      "euclidean: inside when Σ((x_i − t_i)/tol_i)² ≤ 1 (with one Tolerance, the distance " +
        "‖x − t‖ ≤ Tolerance, as MOSAIC); box: inside when |x_i − t_i| ≤ tol_i for every DoF",
    ),
  Dwell: z
    .number()
    .min(0)
    .default(1)
    .describe(
      "Seconds the control must stay inside the target to succeed; can be changed while running",
    ),
  TimeLimit: extendedNumber()
    .refine((v) => v > 0, { message: "must be positive (.inf for no limit)" })
    .default(15)
    .describe(
      "Seconds a trial may last before it fails (.inf: no limit, e.g. when the target input ends trials); can be changed while running",
    ),
  Pause: z
    .number()
    .min(0)
    .default(1)
    .describe(
      "Seconds between two trials of Targets (no target shown); can be changed while running",
    ),
  Order: z
    .enum(["control-target", "target-control"])
    .default("control-target")
    .describe(
      "Which input is which: [control, target] (default) or [target, control] (MOSAIC's TAC, " +
        "whose first input was the target)",
    ),
  Autostart: z
    .boolean()
    .default(false)
    .describe("Start the test when the pipeline starts (otherwise: the start action)"),
  Stimulus: z
    .string()
    .min(1)
    .optional()
    .describe(
      "MOSAIC's form: the Stimulus whose capture phases are the trials, read by name (on the " +
        "same worker): a trial starts with a capture and ends with it, and a success ends the " +
        "capture (the Stimulus moves on to fall); the target input then only feeds displays",
    ),
});

type Params = z.output<typeof params>;

export const TAC = defineBlock({
  type: "TAC",
  category: "Learning",
  summary:
    "Target Achievement Control test: trials of reaching and holding targets, with success, completion time and path efficiency.",
  help:
    "The Target Achievement Control test (Simon, Hargrove, Lock & Kuiken, 'Target Achievement " +
    "Control Test: evaluating real-time myoelectric pattern-recognition control of " +
    "multifunctional upper-limb prostheses', J. Rehabil. Res. Dev. 48(6):619–627, 2011; paper " +
    "IV-A). " +
    "Inputs are `[control, target?]`: the controlled position vector (e.g. a ControlAlgorithm's " +
    "output, D DoFs) and optionally a stream of targets. A trial shows a target; it succeeds " +
    "when the control stays inside the target's tolerance for `Dwell` seconds and fails after " +
    "`TimeLimit` seconds. Inside: with `Metric: euclidean` (default, as MOSAIC's TAC), " +
    "Σ((x_i − t_i)/tol_i)² ≤ 1, i.e. ‖x − t‖ ≤ Tolerance with one number; with `box`, " +
    "|x_i − t_i| ≤ tol_i in every DoF (a per-DoF acceptance window, as in Simon et al.). " +
    "Targets come from `Targets` (a list, or `{ Random: { Count, Seed, Low, High } }`): trial k " +
    "starts at the first control event after `Pause` seconds. With a target input, its events " +
    "follow the Buffer's trigger protocol — a target vector starts a trial (a different one ends " +
    "the current trial as a failure first; the same one again changes nothing), all NaN ends " +
    "the current trial (a failure unless it already succeeded) — so a Stimulus's `trigger` output " +
    "runs one trial per capture phase (and the TAC's `trial` output, fed back into the " +
    "Stimulus's second input, ends the capture on success, as MOSAIC did). On output `trial`, " +
    "each finished trial sends [1, 5]: its 0-based index, success 0/1, completion time (seconds " +
    "from the trial's start until the dwell completed, the dwell included; NaN on failure), path " +
    "efficiency (the straight-line distance from the position at the trial's start to the " +
    "position where the successful dwell began, divided by the length of the path travelled " +
    "until then: 1 on a straight path, 1 when it started inside; NaN on failure) and the final " +
    "Euclidean distance to the target. Output `target` sends the active target when a trial " +
    "starts and all NaN when it ends (for a display, or a Buffer). Time is the events' " +
    "timestamps (deterministic under the virtual clock); the test advances on control events, " +
    "so the control input must be periodic. Actions: `start` (a new test: clears the results), " +
    "`stop` (the trial in progress is dropped), `summary`. The status shows the trial and the " +
    "time inside; when finished, the success rate, mean completion time and mean path " +
    "efficiency (over successful trials). MOSAIC's `[stimulusBlock, dwell, tolerance]` loads " +
    "with Order target-control, Autostart and `Stimulus`: as MOSAIC's TAC, it reads the named " +
    "Stimulus's capture phases (trials are the captures, a success ends the capture), whatever " +
    "its target input carries (MOSAIC's files wire the cue shown, a Selector of the Stimulus).",
  params,
  legacyParams: (args) => {
    if (args.length !== 3) {
      throw new LegacyParamsError(
        `expected [stimulusBlock, dwellSeconds, tolerance], got ${args.length} argument${args.length === 1 ? "" : "s"}`,
      );
    }
    return {
      Stimulus: args[0]!.trim(),
      Dwell: legacyNumber(args[1]!, "the dwell time", "Dwell"),
      Tolerance: legacyNumber(args[2]!, "the tolerance", "Tolerance"),
      TimeLimit: Infinity,
      Order: "target-control",
      Autostart: true,
    };
  },
  legacyForm:
    "[stimulusBlock, dwellSeconds, tolerance]: the Stimulus whose captures are the trials (read by name), the dwell and the tolerance",
  inputs: { min: 1, max: 2, labels: ["control", "target"] },
  outputs: ["trial", "target"],
  live: ["Tolerance", "Dwell", "TimeLimit", "Pause"],
  views: ["stimulus", "label", "scope"],
  panel:
    "The target and the controlled position, the time inside and left, start/stop buttons and the table of finished trials with the summary.",
  create(ctx, p: Params) {
    const ci = p.Order === "control-target" ? 0 : 1;
    const ti = 1 - ci;
    if (ci >= ctx.inputs.length) {
      throw new BlockConfigError(
        "Order target-control needs two inputs: [target, control]",
        "Order",
      );
    }
    const control = vectorInput(ctx, ci);
    const D = control.size;
    const targetIn = ti < ctx.inputs.length ? vectorInput(ctx, ti) : null;
    if (targetIn !== null && targetIn.size !== D) {
      throw new BlockConfigError(
        `the target input ${inputName(targetIn.info)} has ${targetIn.size} values, but the control ` +
          `input ${inputName(control.info)} has ${D}: they must match`,
      );
    }
    if (targetIn !== null && p.Targets !== undefined) {
      throw new BlockConfigError(
        "give Targets or a target input, not both (targets come from one of them)",
        "Targets",
      );
    }
    if (targetIn === null && p.Targets === undefined && p.Stimulus === undefined) {
      throw new BlockConfigError(
        "give Targets (a list of target vectors or { Random: { Count } }) or a second input with targets",
        "Targets",
      );
    }
    const perDof = (v: number | number[], what: string, param: string): Float64Array => {
      if (typeof v === "number") return new Float64Array(D).fill(v);
      if (v.length !== D) {
        throw new BlockConfigError(
          `${what} has ${v.length} values, but the control input ${inputName(control.info)} has ${D} DoFs`,
          param,
        );
      }
      return Float64Array.from(v);
    };

    // The list of targets (Targets mode).
    let list: Float64Array[] = [];
    const t = p.Targets;
    if (t !== undefined) {
      if (Array.isArray(t)) {
        if (t.length * D > MAX_TARGET_VALUES) {
          throw new BlockConfigError(
            `too many target values (at most ${MAX_TARGET_VALUES})`,
            "Targets",
          );
        }
        list = t.map((v, i) => perDof(v, `Targets[${i}]`, "Targets"));
      } else {
        const r = t.Random;
        if (r.Count * D > MAX_TARGET_VALUES) {
          throw new BlockConfigError(
            `${r.Count} random targets of ${D} DoFs are too many values (at most ${MAX_TARGET_VALUES})`,
            "Targets",
          );
        }
        const lo = perDof(r.Low, "Targets.Random.Low", "Targets");
        const hi = perDof(r.High, "Targets.Random.High", "Targets");
        const rng = new SeededRandom(r.Seed);
        for (let k = 0; k < r.Count; k++) {
          const v = new Float64Array(D);
          for (let i = 0; i < D; i++) v[i] = lo[i]! + (hi[i]! - lo[i]!) * rng.uniform();
          list.push(v);
        }
      }
    }
    const total = targetIn === null ? list.length : 0;

    let tol = perDof(p.Tolerance, "Tolerance", "Tolerance");
    let dwell = p.Dwell;
    let timeLimit = p.TimeLimit;
    let pause = p.Pause;
    const euclidean = p.Metric === "euclidean";

    const trialOut = ctx.output(vectorShape(5), "trial");
    const targetOut = ctx.output(vectorShape(D), "target");
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);

    // State
    let running = false;
    let started = false;
    /** Index of the next trial (Targets mode) or of the current/next one (input mode). */
    let k = 0;
    let inTrial = false;
    let nextStart = -Infinity;
    const goal = new Float64Array(D);
    /** Input mode: a target that arrived before any control position; the trial starts at the next control event. */
    let pending = false;
    let pendingT = 0;
    /** Input mode: the last target received (NaN after a stop), so that a repeated one changes nothing. */
    const lastTarget = new Float64Array(D).fill(NaN);
    let t0 = 0;
    const startPos = new Float64Array(D);
    const prev = new Float64Array(D);
    const pos = new Float64Array(D);
    let havePos = false;
    let path = 0;
    let inside = false;
    let entryT = 0;
    let entryPath = 0;
    const entryPos = new Float64Array(D);
    let lastDistance = NaN;
    // Results so far (the summary): trials, successes, sums over successful trials.
    let trials = 0;
    let successes = 0;
    let sumTime = 0;
    let sumEfficiency = 0;
    const throttle = new TextThrottle(0.1);

    const distance = (x: Float64Array, y: Float64Array): number => {
      let s = 0;
      for (let i = 0; i < D; i++) {
        const d = x[i]! - y[i]!;
        s += d * d;
      }
      return Math.sqrt(s);
    };
    const isInside = (x: Float64Array): boolean => {
      if (euclidean) {
        let s = 0;
        for (let i = 0; i < D; i++) {
          const d = (x[i]! - goal[i]!) / tol[i]!;
          s += d * d;
        }
        return s <= 1;
      }
      for (let i = 0; i < D; i++) if (!(Math.abs(x[i]! - goal[i]!) <= tol[i]!)) return false;
      return true;
    };

    const summary = (): string => {
      const n = trials;
      const ok = successes;
      if (n === 0) return "no trials finished";
      const rate = Math.round((100 * ok) / n);
      const means =
        ok > 0
          ? `, mean completion ${(sumTime / ok).toFixed(2)} s, ` +
            `mean path efficiency ${(sumEfficiency / ok).toFixed(2)}`
          : "";
      return `${ok}/${n} succeeded (${rate} %)${means}`;
    };
    const trialName = (): string => (total > 0 ? `trial ${k + 1}/${total}` : `trial ${k + 1}`);
    const describe = (now: number): void => {
      let s: string;
      if (!running) {
        s = trials > 0 ? `stopped: ${summary()}` : "ready (start to begin)";
      } else if (total > 0 && k >= total) {
        s = `finished: ${summary()}`;
      } else if (inTrial) {
        s = inside
          ? `${trialName()}: inside ${(now - entryT).toFixed(1)} s`
          : `${trialName()}: distance ${lastDistance.toPrecision(3)}` +
            (Number.isFinite(timeLimit)
              ? `, ${seconds(Math.max(0, t0 + timeLimit - now))} left`
              : "");
      } else if (total > 0) {
        s = `${trialName()} in ${seconds(Math.max(0, nextStart - now))}`;
        if (trials > 0) s += ` (${summary()})`;
      } else {
        s = trials > 0 ? `waiting for a target (${summary()})` : "waiting for a target";
      }
      ctx.setText(s);
    };

    const showTarget = (time: number, v: Float64Array | null): void => {
      const f = targetOut.frame(1);
      f.t[0] = time;
      if (v) f.v.set(v);
      else f.v.fill(NaN, 0, D);
      targetOut.emit(f);
    };

    const beginTrial = (time: number, from: Float64Array): void => {
      inTrial = true;
      t0 = time;
      startPos.set(from);
      prev.set(from);
      path = 0;
      inside = false;
      lastDistance = distance(from, goal);
      showTarget(time, goal);
      throttle.reset();
    };
    /** Ends the current trial at `time`, reports it and schedules the next one. */
    const endTrial = (time: number, success: boolean): void => {
      const completion = success ? time - t0 : NaN;
      // Straight line from the start to the entry that led to success, over the path until then.
      const efficiency = success
        ? entryPath > 0
          ? distance(entryPos, startPos) / entryPath
          : 1
        : NaN;
      trials++;
      if (success) {
        successes++;
        sumTime += completion;
        sumEfficiency += efficiency;
      }
      const f = trialOut.frame(1);
      f.t[0] = time;
      f.v[0] = k;
      f.v[1] = success ? 1 : 0;
      f.v[2] = completion;
      f.v[3] = efficiency;
      f.v[4] = havePos ? distance(pos, goal) : NaN;
      trialOut.emit(f);
      showTarget(time, null);
      inTrial = false;
      inside = false;
      k++;
      nextStart = time + pause;
      throttle.reset();
      // MOSAIC's TAC moved its Stimulus on to fall when the target was reached.
      if (success) stim?.endCapture(time);
    };

    /** One control event at `time` with the position in `pos`. */
    const step = (time: number): void => {
      if (!inTrial) {
        if (targetIn === null && p.Stimulus === undefined) {
          if (k >= total || time < nextStart) return;
          goal.set(list[k]!);
          beginTrial(time, pos);
        } else {
          if (!pending) return;
          pending = false;
          beginTrial(Math.min(pendingT, time), pos);
        }
      }
      path += distance(pos, prev);
      prev.set(pos);
      lastDistance = distance(pos, goal);
      if (isInside(pos)) {
        if (!inside) {
          inside = true;
          entryT = time;
          entryPath = path;
          entryPos.set(pos);
        }
        if (time - entryT >= dwell) {
          endTrial(time, true);
          return;
        }
      } else inside = false;
      if (time - t0 >= timeLimit) endTrial(time, false);
    };

    /** A target event (input mode). */
    const onTarget = (time: number, v: Float64Array, off: number): void => {
      let nan = 0;
      for (let i = 0; i < D; i++) if (Number.isNaN(v[off + i]!)) nan++;
      if (nan > 0 && nan < D) {
        ctx.warn(
          `ignored a target event with ${nan} NaN of ${D} values: a target must be all numbers, ` +
            "and the end of a trial all NaN",
        );
        return;
      }
      if (nan === D) {
        lastTarget.fill(NaN);
        pending = false;
        if (inTrial) endTrial(time, false);
        return;
      }
      let same = true;
      for (let i = 0; i < D; i++) if (lastTarget[i] !== v[off + i]) same = false;
      if (same) return;
      for (let i = 0; i < D; i++) lastTarget[i] = v[off + i]!;
      if (inTrial) endTrial(time, false);
      goal.set(lastTarget);
      if (havePos) beginTrial(time, pos);
      else {
        pending = true;
        pendingT = time;
      }
    };

    // MOSAIC's form: the named Stimulus's capture phases are the trials.
    let stim: StimulusTriggers | undefined;
    let unlisten: (() => void) | undefined;
    const listen = (): void => {
      if (p.Stimulus === undefined || unlisten) return;
      const s = lookup<StimulusTriggers>(ctx, p.Stimulus, "Stimulus");
      if (typeof s === "string") {
        ctx.warn(`Stimulus '${p.Stimulus}': ${s}; trials follow the target input instead`);
        return;
      }
      if (s.targetWidth !== D) {
        ctx.warn(
          `Stimulus '${p.Stimulus}' has targets of ${s.targetWidth} values, the control ${D}: ` +
            "trials follow the target input instead",
        );
        return;
      }
      stim = s;
      unlisten = s.onTrigger((f) => {
        if (!running) return;
        for (let e = 0; e < f.n; e++) onTarget(f.t[e]!, f.v, e * D);
        describe(f.t[f.n - 1]!);
      });
    };

    const begin = (): void => {
      running = true;
      trials = successes = 0;
      sumTime = sumEfficiency = 0;
      k = 0;
      inTrial = false;
      pending = false;
      lastTarget.fill(NaN);
      nextStart = -Infinity;
      throttle.reset();
    };
    /** Ends the test now: a shown target is withdrawn, the trial in progress dropped. */
    const halt = (): void => {
      if (inTrial) showTarget(ctx.now(), null);
      inTrial = false;
      pending = false;
      running = false;
    };

    describe(0);

    return {
      start() {
        started = true;
        listen();
        if (p.Autostart) begin();
        describe(ctx.now());
      },
      stop() {
        started = false;
      },
      process(f, port) {
        const n = f.n;
        if (n === 0) return;
        if (port === ti) {
          // Trials come from the named Stimulus: the target input only feeds displays.
          if (!running || stim !== undefined) return;
          for (let e = 0; e < n; e++) onTarget(f.t[e]!, f.v, e * D);
          describe(f.t[n - 1]!);
          return;
        }
        const v = f.v;
        let last = 0;
        for (let e = 0; e < n; e++) {
          const time = f.t[e]!;
          last = time;
          let finite = true;
          for (let i = 0; i < D; i++) if (!Number.isFinite(v[e * D + i]!)) finite = false;
          if (!finite) {
            // No position: neither inside nor moving, but the clock runs.
            inside = false;
            if (running && inTrial && time - t0 >= timeLimit) endTrial(time, false);
            continue;
          }
          for (let i = 0; i < D; i++) pos[i] = v[e * D + i]!;
          havePos = true;
          if (running) step(time);
        }
        if (running && throttle.due(last)) describe(last);
      },
      reset() {
        halt();
        trials = successes = 0;
        sumTime = sumEfficiency = 0;
        k = 0;
        havePos = false;
        lastTarget.fill(NaN);
        if (started && p.Autostart) begin();
        describe(ctx.now());
      },
      dispose() {
        unlisten?.();
        unlisten = undefined;
        stim = undefined;
      },
      setParam(name, value) {
        if (name === "Tolerance")
          tol = perDof(value as number | number[], "Tolerance", "Tolerance");
        else if (name === "Dwell") dwell = value as number;
        else if (name === "TimeLimit") timeLimit = value as number;
        else if (name === "Pause") pause = value as number;
      },
      actions: {
        start: {
          label: "Start",
          description: "Start a new test from the first target (clears the results)",
          run() {
            halt();
            begin();
            describe(ctx.now());
            return total > 0
              ? `started: ${plural(total, "trial")}`
              : "started: waiting for targets";
          },
        },
        stop: {
          label: "Stop",
          description: "Stop the test (the trial in progress is not counted)",
          run() {
            if (!running) return "not running";
            halt();
            describe(ctx.now());
            return `stopped: ${summary()}`;
          },
        },
        summary: {
          label: "Summary",
          description: "Success rate, mean completion time and mean path efficiency so far",
          run() {
            return summary();
          },
        },
      },
    };
  },
});
