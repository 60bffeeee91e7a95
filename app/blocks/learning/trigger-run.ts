/**
 * One Trigger's run (trigger.ts): the selected label and the capture in progress, the target and
 * label events that start and stop captures, and what starts them — the actions, the Schedule
 * (trigger-schedule.ts), a pulse's stop and the condition input (trigger-condition.ts).
 */
import {
  vectorShape,
  type BlockAction,
  type BlockContext,
  type BlockInstance,
  type Frame,
  type OutputPort,
} from "../../engine";
import { indexArg } from "../shared/args";
import { formatVector } from "../shared/text";
import { conditionGate, type Condition, type ConditionGate } from "./trigger-condition";
import { expandSchedule, SchedulePlayer } from "./trigger-schedule";
import { seconds, targetColumnLabels, unknownLabel, writeTarget } from "./labels";
import type { TriggerParams } from "./trigger";

/** A pulse's duration: the argument in seconds, or `otherwise` when none is given. */
function secondsArg(arg: unknown, otherwise: number): number {
  if (arg === undefined || arg === null || arg === "") return otherwise;
  const v = typeof arg === "string" ? Number(arg) : arg;
  if (typeof v !== "number" || !Number.isFinite(v) || v < 0 || v > 86_400) {
    throw new Error(
      `expected a duration in seconds from 0 to 86400, got ${typeof arg === "string" ? `'${arg}'` : String(arg)}`,
    );
  }
  return v;
}

export class TriggerRun {
  private readonly names: string[];
  private readonly targets: Float64Array[];
  /** Values per target. */
  private readonly T: number;
  private readonly initial: number;
  private readonly gate: ConditionGate | null;
  private readonly target: OutputPort;
  private readonly labelOut: OutputPort;
  private readonly schedule: SchedulePlayer;
  private readonly deadline = (t: number): void => this.onDeadline(t);
  private selected: number;
  private capturing = false;
  /** The label whose target was sent last (-1 after a stop). */
  private lastSent = -1;
  private pulseStop = NaN;
  private pulseLength = 0;
  private pulseSeconds: number;
  private running = false;

  constructor(
    private readonly ctx: BlockContext,
    p: TriggerParams,
  ) {
    const names = Object.keys(p.Labels);
    this.names = names;
    this.T = p.Labels[names[0]!]!.length;
    this.targets = names.map((n) => Float64Array.from(p.Labels[n]!));
    this.initial = p.Initial !== undefined ? names.indexOf(p.Initial) : 0;
    this.selected = this.initial;
    this.pulseSeconds = p.Pulse;
    if (ctx.declaredRate === undefined) ctx.setDesiredRate(0);
    this.gate = conditionGate(ctx, p.Condition);
    const columns = targetColumnLabels(names, this.targets);
    this.target = ctx.output(vectorShape(this.T), "target", columns && { labels: columns });
    this.labelOut = ctx.output(vectorShape(1), "label");
    this.schedule = new SchedulePlayer(expandSchedule(p, names));
    this.describe();
  }

  instance(): BlockInstance {
    return {
      start: () => this.start(),
      stop: () => {
        this.running = false;
      },
      process: (f) => this.process(f),
      reset: () => this.reset(),
      setParam: (name, value) => this.setParam(name, value),
      actions: this.actions(),
    };
  }

  private start(): void {
    this.running = true;
    if (!this.schedule.empty) this.playSchedule(this.ctx.startTime);
    this.describe();
  }

  /** Condition input: captures start and stop as the condition starts and stops holding. */
  private process(f: Frame): void {
    if (this.gate === null) return;
    const changed = this.gate.changes(f, (t, on) => {
      if (on) this.startCapture(t, this.selected);
      else this.stopCapture(t);
    });
    if (changed) this.describe();
  }

  private reset(): void {
    this.stopCapture(this.ctx.now());
    this.selected = this.initial;
    this.gate?.reset();
    this.pulseStop = NaN;
    if (this.running && !this.schedule.empty) this.playSchedule(this.ctx.now());
    this.describe();
  }

  private setParam(name: string, value: unknown): void {
    if (name === "Pulse") this.pulseSeconds = value as number;
    else if (name === "Condition") {
      if (this.gate === null) {
        throw new Error("this Trigger has no input: a Condition has nothing to compare");
      }
      this.gate.set(value as Condition | undefined);
    }
  }

  private describe(): void {
    const { selected, names } = this;
    const name = `'${names[selected]}' (${selected + 1}/${names.length})`;
    let s = this.capturing ? `capturing ${name}` : `${name} selected, not capturing`;
    if (this.capturing && !Number.isNaN(this.pulseStop)) {
      s += `, pulse of ${seconds(this.pulseLength)}`;
    }
    if (this.schedule.starts > 0) s += `; schedule ${this.schedule.done}/${this.schedule.starts}`;
    this.ctx.setText(s);
  }

  // -------------------------------------------------------------------------------------------
  // Captures

  /** Sends a target event (the label's target, or all NaN when `label` is -1) and its label. */
  private send(t: number, label: number): void {
    const f = this.target.frame(1);
    f.t[0] = t;
    writeTarget(f.v, 0, this.targets, label, this.T);
    this.target.emit(f);
    const g = this.labelOut.frame(1);
    g.t[0] = t;
    g.v[0] = label >= 0 ? label : NaN;
    this.labelOut.emit(g);
  }

  /** Captures `label` from `t` (cancels a pending pulse stop); nothing is sent if it already is. */
  private startCapture(t: number, label: number): void {
    this.pulseStop = NaN;
    this.selected = label;
    if (this.capturing && label === this.lastSent) return;
    this.capturing = true;
    this.lastSent = label;
    this.send(t, label);
  }

  /** Stops the capture in progress at `t` (cancels a pending pulse stop). */
  private stopCapture(t: number): void {
    this.pulseStop = NaN;
    if (!this.capturing) return;
    this.capturing = false;
    this.lastSent = -1;
    this.send(t, -1);
  }

  // -------------------------------------------------------------------------------------------
  // Deadlines: the schedule's events and a pulse's stop

  /** The next schedule event's time while running, else Infinity. */
  private scheduleTime(): number {
    return this.running ? this.schedule.nextTime() : Infinity;
  }

  /** A pending pulse's stop time, else Infinity. */
  private pulseTime(): number {
    return Number.isNaN(this.pulseStop) ? Infinity : this.pulseStop;
  }

  /** Arms the one-shot for the earliest pending deadline (the schedule's next event or a pulse's stop). */
  private arm(): void {
    const next = Math.min(this.pulseTime(), this.scheduleTime());
    if (next < Infinity) this.ctx.at(next, this.deadline);
  }

  /** Runs every deadline due by `t`, in time order (a schedule event before a pulse stop at the same time). */
  private onDeadline(t: number): void {
    for (;;) {
      const ts = this.scheduleTime();
      const tp = this.pulseTime();
      if (ts <= t && ts <= tp) {
        const label = this.schedule.take();
        if (label >= 0) this.startCapture(t, label);
        else this.stopCapture(t);
      } else if (tp <= t) {
        this.stopCapture(t);
      } else break;
    }
    this.describe();
    this.arm();
  }

  private playSchedule(from: number): void {
    this.schedule.play(from);
    this.arm();
  }

  // -------------------------------------------------------------------------------------------
  // Actions

  /** A label name or 0-based index; none: the selected label. */
  private labelArg(arg: unknown): number {
    if (arg === undefined || arg === null || arg === "") return this.selected;
    if (typeof arg === "string" && !/^\s*\d+\s*$/.test(arg)) {
      const i = this.names.indexOf(arg.trim());
      if (i < 0) throw new Error(unknownLabel(arg.trim(), this.names));
      return i;
    }
    return indexArg(arg, this.names.length, "a label name or index");
  }

  /** Selects the label `step` places on (cyclically); while capturing, switches to it. */
  private move(step: number): string {
    const L = this.names.length;
    this.selected = (this.selected + step + L) % L;
    if (this.capturing) this.startCapture(this.ctx.now(), this.selected);
    this.describe();
    const name = this.names[this.selected];
    return this.capturing ? `capturing '${name}'` : `selected '${name}'`;
  }

  private startAction(arg: unknown): string {
    const i = this.labelArg(arg);
    this.startCapture(this.ctx.now(), i);
    this.describe();
    return `capturing '${this.names[i]}' ${formatVector(this.targets[i]!)}`;
  }

  private stopAction(): string {
    const was = this.capturing;
    this.stopCapture(this.ctx.now());
    this.describe();
    return was ? `stopped '${this.names[this.selected]}'` : "not capturing";
  }

  private pulse(arg: unknown): string {
    const s = secondsArg(arg, this.pulseSeconds);
    const t = this.ctx.now();
    this.startCapture(t, this.selected);
    this.pulseStop = t + s;
    this.pulseLength = s;
    this.describe();
    this.arm();
    return `capturing '${this.names[this.selected]}' for ${seconds(s)}`;
  }

  private actions(): Record<string, BlockAction> {
    return {
      start: {
        label: "Start",
        description:
          "Start capturing a label (a name or 0-based index; default: the selected label)",
        run: (arg) => this.startAction(arg),
      },
      stop: {
        label: "Stop",
        description: "Stop capturing (sends all NaN)",
        run: () => this.stopAction(),
      },
      select: {
        label: "Select",
        description: "Select a label (a name or index); while capturing, switch to it",
        run: (arg) => this.move(this.labelArg(arg) - this.selected),
      },
      next: {
        label: "Next label",
        description: "Select the next label (after the last, the first)",
        run: () => this.move(1),
      },
      previous: {
        label: "Previous label",
        description: "Select the previous label (before the first, the last)",
        run: () => this.move(-1),
      },
      pulse: {
        label: "Pulse",
        description:
          "Capture the selected label now and stop after N seconds (default: Pulse), like MOSAIC's number keys",
        run: (arg) => this.pulse(arg),
      },
    };
  }
}
