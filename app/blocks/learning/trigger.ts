import { z } from "zod";
import { defineBlock, LegacyParamsError } from "../../engine";
import { index } from "../shared/params";
import {
  checkLabels,
  labelsSchema,
  legacyLabel,
  unknownLabel,
  type AddIssue,
  type Issue,
} from "./labels";
import { TriggerRun } from "./trigger-run";

// Label helpers the TAC and tests import from here (they live in labels.ts).
export { seconds, targetColumnLabels } from "./labels";

const MAX_SCHEDULED = 100_000;

const scheduleEntry = z.strictObject({
  Label: z.string().min(1).describe("Label to capture (a name of Labels)"),
  At: z.number().min(0).describe("Start of the capture, in seconds after the pipeline started"),
  Seconds: z.number().positive().describe("Duration of the capture, in seconds"),
});

const scheduleProtocol = z.strictObject({
  Sequence: z
    .array(z.string().min(1))
    .min(1)
    .max(MAX_SCHEDULED)
    .optional()
    .describe("Labels in the order they are captured (default: every label, in Labels order)"),
  Seconds: z.number().positive().describe("Duration of each capture, in seconds"),
  Pause: z.number().min(0).default(2).describe("Seconds between two captures"),
  Repetitions: z
    .number()
    .int()
    .min(1)
    .max(MAX_SCHEDULED)
    .default(1)
    .describe("How many times the Sequence is played"),
  Start: z
    .number()
    .min(0)
    .default(0)
    .describe("Start of the first capture, in seconds after the pipeline started"),
});

const condition = z
  .strictObject({
    Channel: index()
      .default(0)
      .describe("0-based value of the condition input that is compared (e.g. a foot switch)"),
    Above: z.number().optional().describe("The condition holds while the value is above this"),
    Below: z.number().optional().describe("The condition holds while the value is below this"),
  })
  .refine((c) => c.Above !== undefined || c.Below !== undefined, {
    message: "give Above, Below or both (e.g. { Channel: 0, Above: 0.5 })",
  })
  .refine((c) => c.Above === undefined || c.Below === undefined || c.Above < c.Below, {
    message: "with both, Above must be below Below (the condition holds between them)",
  });

const params = z
  .strictObject({
    Labels: labelsSchema().describe(
      "Labels by name, each with its target vector (all of one length T), e.g. " +
        "{ rest: [0, 0, 0], power: [1, 1, 1] }; MOSAIC's positional form is [rest:0;0;0, power:1;1;1]",
    ),
    Initial: z
      .string()
      .min(1)
      .optional()
      .describe("Label selected at the start (default: the first label)"),
    Schedule: z
      .union([z.array(scheduleEntry).min(1).max(MAX_SCHEDULED), scheduleProtocol])
      .optional()
      .describe(
        "Captures played on the pipeline clock: a list of { Label, At, Seconds }, or a " +
          "repeating protocol { Sequence, Seconds, Pause, Repetitions, Start }",
      ),
    Condition: condition
      .optional()
      .describe(
        "With an input: capture the selected label while the input's value at Channel is above " +
          "Above (and/or below Below), stop when it is not (default with an input: " +
          "{ Channel: 0, Above: 0.5 }); can be changed while running",
      ),
    Pulse: z
      .number()
      .positive()
      .max(86_400)
      .default(3)
      .describe(
        "Seconds a `pulse` captures when no duration is given (MOSAIC's number keys); can be " +
          "changed while running",
      ),
  })
  .superRefine((p, ctx) => {
    const add = (i: Issue) => ctx.addIssue(i);
    checkLabels(p.Labels, "Labels", add);
    const names = Object.keys(p.Labels);
    if (names.length === 0) return;
    if (p.Initial !== undefined && !names.includes(p.Initial)) {
      add({ code: "custom", path: ["Initial"], message: unknownLabel(p.Initial, names) });
    }
    if (p.Schedule !== undefined) checkSchedule(p.Schedule, names, add);
  });

export type TriggerParams = z.output<typeof params>;

/** Every label the Schedule names is one of Labels, and a protocol is not too long. */
function checkSchedule(
  s: NonNullable<TriggerParams["Schedule"]>,
  names: readonly string[],
  add: AddIssue,
): void {
  if (Array.isArray(s)) {
    s.forEach((e, i) => {
      if (!names.includes(e.Label)) {
        add({
          code: "custom",
          path: ["Schedule", i, "Label"],
          message: unknownLabel(e.Label, names),
        });
      }
    });
    return;
  }
  const seq = s.Sequence ?? names;
  seq.forEach((n, i) => {
    if (!names.includes(n)) {
      add({
        code: "custom",
        path: ["Schedule", "Sequence", i],
        message: unknownLabel(n, names),
      });
    }
  });
  if (seq.length * s.Repetitions > MAX_SCHEDULED) {
    add({
      code: "custom",
      path: ["Schedule", "Repetitions"],
      message:
        `${seq.length} labels × ${s.Repetitions} repetitions make ` +
        `${seq.length * s.Repetitions} captures; at most ${MAX_SCHEDULED} are allowed`,
    });
  }
}

export const Trigger = defineBlock({
  type: "Trigger",
  category: "Learning",
  summary:
    "Start/stop/label events for a Buffer or a predictor's training input: by hand, on a schedule or from an input condition.",
  help:
    "Labels data for supervised learning with the participant in the loop (paper III-G, IV-A). " +
    "`Labels` maps names to target vectors (all of one length T). The `target` output follows " +
    "the Buffer's trigger protocol: when a capture starts (or switches to another label) it " +
    "sends that label's target vector [1, T]; when it stops it sends all NaN. The `label` output " +
    "sends, with every target event, the 0-based index of the capturing label (NaN when " +
    "stopped). Captures come from three sources, the latest event winning: (a) actions — " +
    "`start` (a label name or index; default the selected one), `stop`, `select`, `next` and " +
    "`previous` (cycle the selected label; while capturing they switch the capture to it), and " +
    "`pulse` (start now, stop after N seconds, default `Pulse`: MOSAIC's number keys); (b) a " +
    "`Schedule` played on the pipeline clock from the pipeline start: a list of " +
    "`{ Label, At, Seconds }` or a repeating protocol `{ Sequence, Seconds, Pause, Repetitions, " +
    "Start }` (a capture that runs into the next one switches to it without a stop); (c) an " +
    "optional input and a `Condition` such as `{ Channel: 0, Above: 0.5 }` (a foot switch, a " +
    "button over serial): the selected label is captured while the condition holds and stopped " +
    "when it no longer does (a NaN value does not hold). A pulse's stop is cancelled by any " +
    "start or stop in the meantime. Action and schedule events carry the pipeline clock's time, " +
    "condition events their input event's time. `reset` stops a capture in progress (sending " +
    "the stop), selects `Initial` again and replays the Schedule from that moment. Aperiodic. " +
    "MOSAIC's `[rest:0;0;0, power:1;1;1, …]` loads as Labels.",
  params,
  legacyParams: (args) => {
    const used = args.filter((a) => a.trim() !== "");
    if (used.length === 0) {
      throw new LegacyParamsError(
        "expected at least one label such as rest:0;0;0 (a name and its target vector)",
        "Labels",
      );
    }
    const labels: Record<string, number[]> = {};
    used.forEach((a, i) => {
      const [name, v] = legacyLabel(a, i, "Labels");
      if (Object.hasOwn(labels, name)) {
        throw new LegacyParamsError(`label '${name}' is given twice`, "Labels");
      }
      labels[name] = v;
    });
    return { Labels: labels };
  },
  legacyForm:
    "[name:a;b;c, …]: one label per argument with its target vector, e.g. [rest:0;0, fist:1;0]",
  inputs: { min: 0, max: 1, labels: ["condition"] },
  outputs: ["target", "label"],
  live: ["Pulse", "Condition"],
  views: ["label"],
  panel:
    "The selected label and whether it is capturing, with start, stop, previous, next and pulse buttons and the schedule's progress.",
  create(ctx, p: TriggerParams) {
    return new TriggerRun(ctx, p).instance();
  },
});
