import { z } from "zod";
import {
  BlockConfigError,
  closest,
  defineBlock,
  LegacyParamsError,
  legacyPair,
  legacyVector,
  vectorShape,
} from "../../engine";
import { indexArg } from "../shared/args";
import { inputName, signalInput } from "../shared/inputs";
import { index } from "../shared/params";
import { formatVector } from "../shared/text";

// ---------------------------------------------------------------------------------------------
// Labels, shared with the Stimulus

/** Most labels a Trigger or Stimulus may have, and most values in a label's target vector. */
export const MAX_LABELS = 1000;
export const MAX_TARGET = 4096;

/** A target vector: what a label means for a model (one value per output, e.g. a one-hot). */
export const targetVector = () => z.array(z.number()).min(1).max(MAX_TARGET);

/** `Labels`: a mapping from label name to target vector (in the order written). */
export const labelsSchema = () => z.record(z.string().min(1), targetVector());

type Issue = { code: "custom"; path: (string | number)[]; message: string };
type AddIssue = (issue: Issue) => void;

/** Checks a Labels mapping: at least one label, at most MAX_LABELS, all of the same width. */
export function checkLabels(
  labels: Record<string, number[]>,
  param: string,
  addIssue: AddIssue,
): void {
  const names = Object.keys(labels);
  if (names.length === 0) {
    addIssue({ code: "custom", path: [param], message: "needs at least one label" });
    return;
  }
  if (names.length > MAX_LABELS) {
    addIssue({
      code: "custom",
      path: [param],
      message: `has ${names.length} labels; at most ${MAX_LABELS} are allowed`,
    });
    return;
  }
  const width = labels[names[0]!]!.length;
  for (const n of names) {
    const w = labels[n]!.length;
    if (w !== width) {
      addIssue({
        code: "custom",
        path: [param, n],
        message:
          `label '${n}' has ${w} values, but '${names[0]}' has ${width}: every target vector ` +
          "must have the same length",
      });
    }
  }
}

/**
 * Names of a target vector's columns, for panels and recordings (PortMeta labels): column k is
 * named after the label whose target is one-hot at k (1 there, 0 elsewhere: fist [1, 0, 0] names
 * column 0 "fist"). Undefined unless every column has exactly one such label.
 */
export function targetColumnLabels(
  names: readonly string[],
  targets: readonly ArrayLike<number>[],
): string[] | undefined {
  const width = targets[0]?.length ?? 0;
  if (width === 0) return undefined;
  const cols: (string | null | undefined)[] = new Array<undefined>(width).fill(undefined);
  names.forEach((name, i) => {
    const v = targets[i]!;
    let hot = -1;
    for (let k = 0; k < v.length; k++) {
      if (v[k] === 1 && hot === -1) hot = k;
      else if (v[k] !== 0) return;
    }
    if (hot >= 0) cols[hot] = cols[hot] === undefined ? name : null;
  });
  return cols.every((c) => typeof c === "string") ? (cols as string[]) : undefined;
}

/** "unknown label 'fsit' (labels: rest, fist); did you mean 'fist'?" */
export function unknownLabel(name: string, names: readonly string[]): string {
  const s = closest(name, names);
  return (
    `unknown label '${name}' (labels: ${names.slice(0, 20).join(", ")}` +
    `${names.length > 20 ? ", …" : ""})` +
    (s !== undefined ? `; did you mean '${s}'?` : "")
  );
}

/** MOSAIC's `name:a;b;c` (a label and its target vector), argument `i` (0-based) of Params. */
export function legacyLabel(arg: string, i: number, param: string): [string, number[]] {
  if (!arg.includes(":")) {
    throw new LegacyParamsError(
      `argument ${i + 1} '${arg}' is not 'name:a;b;c' (a label and its target vector)`,
      param,
    );
  }
  const { key, value } = legacyPair(arg);
  if (key === "") {
    throw new LegacyParamsError(`argument ${i + 1} '${arg}' has no label name`, param);
  }
  return [key, legacyVector(value, `the target of label '${key}'`, param)];
}

/** Seconds for status texts: 2.4 → "2.4 s". */
export const seconds = (s: number): string => `${Number.isFinite(s) ? s.toFixed(1) : "∞"} s`;

// ---------------------------------------------------------------------------------------------
// Trigger

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

type Condition = z.output<typeof condition>;

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
    const s = p.Schedule;
    if (s === undefined) return;
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
    } else {
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
  });

type Params = z.output<typeof params>;

/** The schedule as start/stop events, relative to its start: times ascending, label or -1 (stop). */
function expandSchedule(p: Params, names: readonly string[]): { t: number[]; label: number[] } {
  const entries: { at: number; label: number; seconds: number }[] = [];
  const s = p.Schedule;
  if (s === undefined) return { t: [], label: [] };
  if (Array.isArray(s)) {
    for (const e of s)
      entries.push({ at: e.At, label: names.indexOf(e.Label), seconds: e.Seconds });
    entries.sort((a, b) => a.at - b.at); // stable: equal times keep the written order
  } else {
    const seq = (s.Sequence ?? names).map((n) => names.indexOf(n));
    let t = s.Start;
    for (let r = 0; r < s.Repetitions; r++) {
      for (const label of seq) {
        entries.push({ at: t, label, seconds: s.Seconds });
        t += s.Seconds + s.Pause;
      }
    }
  }
  const t: number[] = [];
  const label: number[] = [];
  entries.forEach((e, i) => {
    t.push(e.at);
    label.push(e.label);
    const end = e.at + e.seconds;
    const next = entries[i + 1];
    // A capture that runs into the next one is switched by it, without a stop in between.
    if (next === undefined || next.at > end) {
      t.push(end);
      label.push(-1);
    }
  });
  return { t, label };
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
  create(ctx, p: Params) {
    const names = Object.keys(p.Labels);
    const L = names.length;
    const T = p.Labels[names[0]!]!.length;
    const targets = names.map((n) => Float64Array.from(p.Labels[n]!));
    const initial = p.Initial !== undefined ? names.indexOf(p.Initial) : 0;
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);

    // Condition input
    const cond = ctx.inputs.length > 0 ? signalInput(ctx, 0) : null;
    if (cond === null && p.Condition !== undefined) {
      throw new BlockConfigError(
        "Condition needs an input to compare (e.g. Inputs: [FootSwitch]); without one, leave it out",
        "Condition",
      );
    }
    const checkCondition = (c: Condition): Condition => {
      if (cond && c.Channel >= cond.size) {
        throw new BlockConfigError(
          `Condition.Channel ${c.Channel} is out of range for input ${inputName(cond.info)} with ` +
            `${cond.size} value${cond.size === 1 ? "" : "s"} (valid: 0–${cond.size - 1})`,
          "Condition",
        );
      }
      return c;
    };
    let condParams: Condition = checkCondition(p.Condition ?? { Channel: 0, Above: 0.5 });
    let condOn = false;

    const columns = targetColumnLabels(names, targets);
    const target = ctx.output(vectorShape(T), "target", columns && { labels: columns });
    const labelOut = ctx.output(vectorShape(1), "label");

    const sched = expandSchedule(p, names);
    const schedT = Float64Array.from(sched.t);
    const schedLabel = Int32Array.from(sched.label);
    let schedBase = NaN;
    let schedNext = 0;
    let schedStarts = 0;
    let schedDone = 0;
    for (let i = 0; i < schedLabel.length; i++) if (schedLabel[i]! >= 0) schedStarts++;

    let selected = initial;
    let capturing = false;
    /** The label whose target was sent last (-1 after a stop). */
    let lastSent = -1;
    let pulseStop = NaN;
    let pulseLength = 0;
    let pulseSeconds = p.Pulse;
    let running = false;

    const describe = (): void => {
      const name = `'${names[selected]}' (${selected + 1}/${L})`;
      let s = capturing ? `capturing ${name}` : `${name} selected, not capturing`;
      if (capturing && !Number.isNaN(pulseStop)) s += `, pulse of ${seconds(pulseLength)}`;
      if (schedStarts > 0) s += `; schedule ${schedDone}/${schedStarts}`;
      ctx.setText(s);
    };

    const send = (t: number, label: number): void => {
      const f = target.frame(1);
      f.t[0] = t;
      if (label >= 0) f.v.set(targets[label]!);
      else f.v.fill(NaN, 0, T);
      target.emit(f);
      const g = labelOut.frame(1);
      g.t[0] = t;
      g.v[0] = label >= 0 ? label : NaN;
      labelOut.emit(g);
    };
    const startCapture = (t: number, label: number): void => {
      pulseStop = NaN;
      selected = label;
      if (capturing && label === lastSent) return;
      capturing = true;
      lastSent = label;
      send(t, label);
    };
    const stopCapture = (t: number): void => {
      pulseStop = NaN;
      if (!capturing) return;
      capturing = false;
      lastSent = -1;
      send(t, -1);
    };

    /** Arms the one-shot for the earliest pending deadline (the schedule's next event or a pulse's stop). */
    const arm = (): void => {
      let next = Number.isNaN(pulseStop) ? Infinity : pulseStop;
      if (running && schedNext < schedT.length)
        next = Math.min(next, schedBase + schedT[schedNext]!);
      if (next < Infinity) ctx.at(next, onDeadline);
    };
    const onDeadline = (t: number): void => {
      for (;;) {
        const ts = running && schedNext < schedT.length ? schedBase + schedT[schedNext]! : Infinity;
        const tp = Number.isNaN(pulseStop) ? Infinity : pulseStop;
        if (ts <= t && ts <= tp) {
          const label = schedLabel[schedNext++]!;
          if (label >= 0) {
            schedDone++;
            startCapture(t, label);
          } else stopCapture(t);
        } else if (tp <= t) {
          stopCapture(t);
        } else break;
      }
      describe();
      arm();
    };
    const playSchedule = (from: number): void => {
      schedBase = from;
      schedNext = 0;
      schedDone = 0;
      arm();
    };

    const labelArg = (arg: unknown): number => {
      if (arg === undefined || arg === null || arg === "") return selected;
      if (typeof arg === "string" && !/^\s*\d+\s*$/.test(arg)) {
        const i = names.indexOf(arg.trim());
        if (i < 0) throw new Error(unknownLabel(arg.trim(), names));
        return i;
      }
      return indexArg(arg, L, "a label name or index");
    };
    const secondsArg = (arg: unknown): number => {
      if (arg === undefined || arg === null || arg === "") return pulseSeconds;
      const v = typeof arg === "string" ? Number(arg) : arg;
      if (typeof v !== "number" || !Number.isFinite(v) || v < 0 || v > 86_400) {
        throw new Error(
          `expected a duration in seconds from 0 to 86400, got ${typeof arg === "string" ? `'${arg}'` : String(arg)}`,
        );
      }
      return v;
    };
    const move = (step: number): string => {
      selected = (selected + step + L) % L;
      if (capturing) startCapture(ctx.now(), selected);
      describe();
      return capturing ? `capturing '${names[selected]}'` : `selected '${names[selected]}'`;
    };

    describe();

    return {
      start() {
        running = true;
        if (schedT.length > 0) playSchedule(ctx.startTime);
        describe();
      },
      stop() {
        running = false;
      },
      process(f) {
        if (cond === null) return;
        const n = f.n;
        const stride = f.stride;
        const ch = condParams.Channel;
        const above = condParams.Above;
        const below = condParams.Below;
        let changed = false;
        for (let e = 0; e < n; e++) {
          const x = f.v[e * stride + ch]!;
          const on = (above === undefined || x > above) && (below === undefined || x < below);
          if (on === condOn) continue;
          condOn = on;
          changed = true;
          if (on) startCapture(f.t[e]!, selected);
          else stopCapture(f.t[e]!);
        }
        if (changed) describe();
      },
      reset() {
        stopCapture(ctx.now());
        selected = initial;
        condOn = false;
        pulseStop = NaN;
        if (running && schedT.length > 0) playSchedule(ctx.now());
        describe();
      },
      setParam(name, value) {
        if (name === "Pulse") pulseSeconds = value as number;
        else if (name === "Condition") {
          if (cond === null) {
            throw new Error("this Trigger has no input: a Condition has nothing to compare");
          }
          const c = (value as Condition | undefined) ?? { Channel: 0, Above: 0.5 };
          if (c.Channel >= cond.size) {
            throw new Error(
              `Condition.Channel ${c.Channel} is out of range for input ${inputName(cond.info)} ` +
                `with ${cond.size} value${cond.size === 1 ? "" : "s"} (valid: 0–${cond.size - 1})`,
            );
          }
          condParams = c;
        }
      },
      actions: {
        start: {
          label: "Start",
          description:
            "Start capturing a label (a name or 0-based index; default: the selected label)",
          run(arg) {
            const i = labelArg(arg);
            startCapture(ctx.now(), i);
            describe();
            return `capturing '${names[i]}' ${formatVector(targets[i]!)}`;
          },
        },
        stop: {
          label: "Stop",
          description: "Stop capturing (sends all NaN)",
          run() {
            const was = capturing;
            stopCapture(ctx.now());
            describe();
            return was ? `stopped '${names[selected]}'` : "not capturing";
          },
        },
        select: {
          label: "Select",
          description: "Select a label (a name or index); while capturing, switch to it",
          run(arg) {
            const i = labelArg(arg);
            return move(i - selected);
          },
        },
        next: {
          label: "Next label",
          description: "Select the next label (after the last, the first)",
          run() {
            return move(1);
          },
        },
        previous: {
          label: "Previous label",
          description: "Select the previous label (before the first, the last)",
          run() {
            return move(-1);
          },
        },
        pulse: {
          label: "Pulse",
          description:
            "Capture the selected label now and stop after N seconds (default: Pulse), like MOSAIC's number keys",
          run(arg) {
            const s = secondsArg(arg);
            const t = ctx.now();
            startCapture(t, selected);
            pulseStop = t + s;
            pulseLength = s;
            describe();
            arm();
            return `capturing '${names[selected]}' for ${seconds(s)}`;
          },
        },
      },
    };
  },
});
