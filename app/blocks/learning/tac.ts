import { z } from "zod";
import { defineBlock, legacyNumber, LegacyParamsError } from "../../engine";
import { extendedNumber } from "../shared/params";
import { TacRun } from "./tac-run";
import { MAX_TRIALS, tacPorts, targetList } from "./tac-setup";

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
        "capture (the Stimulus moves on to fall); the target input then only feeds displays " +
        "(not with Targets)",
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
    "`stop` (the trial in progress is dropped), `summary`. The status shows the trial (k/N with Targets or a Stimulus: its cues) and the " +
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
    const ports = tacPorts(ctx, p.Order, p.Targets, p.Stimulus);
    const list = targetList(p.Targets, ports.D, ports.perDof);
    return new TacRun(ctx, ports, {
      list,
      tolerance: ports.perDof(p.Tolerance, "Tolerance", "Tolerance"),
      euclidean: p.Metric === "euclidean",
      dwell: p.Dwell,
      timeLimit: p.TimeLimit,
      pause: p.Pause,
      autostart: p.Autostart,
      stimulus: p.Stimulus,
    }).instance();
  },
});
