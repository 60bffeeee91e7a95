/**
 * A Trigger's `Schedule` (trigger.ts): expanded once into start and stop events, then played on
 * the pipeline clock from a base time (the pipeline start, or a reset).
 */
import type { TriggerParams } from "./trigger";

/** The schedule as start/stop events, relative to its start: times ascending, label or -1 (stop). */
export function expandSchedule(
  p: TriggerParams,
  names: readonly string[],
): { t: number[]; label: number[] } {
  const s = p.Schedule;
  if (s === undefined) return { t: [], label: [] };
  const entries = Array.isArray(s) ? listedEntries(s, names) : protocolEntries(s, names);
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

type Schedule = NonNullable<TriggerParams["Schedule"]>;
type ScheduleList = Extract<Schedule, readonly unknown[]>;
type ScheduleProtocol = Exclude<Schedule, readonly unknown[]>;

/** One capture: its start, label index and duration. */
interface Entry {
  at: number;
  label: number;
  seconds: number;
}

/** A list of { Label, At, Seconds }, in time order. */
function listedEntries(list: ScheduleList, names: readonly string[]): Entry[] {
  const entries: Entry[] = [];
  for (const e of list)
    entries.push({ at: e.At, label: names.indexOf(e.Label), seconds: e.Seconds });
  entries.sort((a, b) => a.at - b.at); // stable: equal times keep the written order
  return entries;
}

/** A repeating protocol { Sequence, Seconds, Pause, Repetitions, Start }. */
function protocolEntries(s: ScheduleProtocol, names: readonly string[]): Entry[] {
  const entries: Entry[] = [];
  const seq = (s.Sequence ?? names).map((n) => names.indexOf(n));
  let t = s.Start;
  for (let r = 0; r < s.Repetitions; r++) {
    for (const label of seq) {
      entries.push({ at: t, label, seconds: s.Seconds });
      t += s.Seconds + s.Pause;
    }
  }
  return entries;
}

/** Plays the expanded schedule: its next event's time, then that event, in order. */
export class SchedulePlayer {
  private readonly times: Float64Array;
  private readonly labels: Int32Array;
  private base = NaN;
  private next = 0;
  /** Captures the schedule starts in all. */
  readonly starts: number;
  /** Captures started so far. */
  done = 0;

  constructor(events: { t: number[]; label: number[] }) {
    this.times = Float64Array.from(events.t);
    this.labels = Int32Array.from(events.label);
    let starts = 0;
    for (let i = 0; i < this.labels.length; i++) if (this.labels[i]! >= 0) starts++;
    this.starts = starts;
  }

  /** True when the schedule has no events (no Schedule param). */
  get empty(): boolean {
    return this.times.length === 0;
  }

  /** Plays it again from the start, its times counted from `from`. */
  play(from: number): void {
    this.base = from;
    this.next = 0;
    this.done = 0;
  }

  /** Clock time of the next event (Infinity after the last). */
  nextTime(): number {
    return this.next < this.times.length ? this.base + this.times[this.next]! : Infinity;
  }

  /** Takes the next event: the label to capture, or -1 (stop). */
  take(): number {
    const label = this.labels[this.next++]!;
    if (label >= 0) this.done++;
    return label;
  }
}
