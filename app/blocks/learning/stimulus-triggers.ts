/**
 * A Stimulus's `trigger` output (stimulus.ts): the starts and stops of its capture phases within
 * one process call (at most two per tick), sent as one frame to the output and to the blocks that
 * read the Stimulus by name (a StimTrigger wired to its default output).
 */
import type { Frame, OutputPort } from "../../engine";
import { writeTarget } from "./labels";

export class TriggerQueue {
  private times = new Float64Array(8);
  /** Label index per event; -1: a stop (all NaN). */
  private labels = new Int32Array(8);
  private n = 0;
  private readonly listeners = new Set<(f: Frame) => void>();

  constructor(
    private readonly out: OutputPort,
    private readonly targets: readonly Float64Array[],
    /** Values per target. */
    private readonly T: number,
  ) {}

  /** Queues a capture's start (`label` ≥ 0) or stop (-1) at `t`. */
  push(t: number, label: number): void {
    if (this.n === this.times.length) this.grow();
    this.times[this.n] = t;
    this.labels[this.n] = label;
    this.n++;
  }

  /** Calls `fn` with every trigger frame (borrowed) before it is emitted; returns its removal. */
  listen(fn: (f: Frame) => void): () => void {
    this.listeners.add(fn);
    return () => this.listeners.delete(fn);
  }

  /** Sends the queued events as one frame, if any. */
  flush(): void {
    const n = this.n;
    if (n === 0) return;
    const f = this.out.frame(n);
    for (let i = 0; i < n; i++) {
      f.t[i] = this.times[i]!;
      writeTarget(f.v, i * this.T, this.targets, this.labels[i]!, this.T);
    }
    this.n = 0;
    for (const fn of this.listeners) fn(f);
    this.out.emit(f);
  }

  dispose(): void {
    this.listeners.clear();
  }

  private grow(): void {
    const times = new Float64Array(this.n * 2);
    times.set(this.times);
    const labels = new Int32Array(this.n * 2);
    labels.set(this.labels);
    this.times = times;
    this.labels = labels;
  }
}
