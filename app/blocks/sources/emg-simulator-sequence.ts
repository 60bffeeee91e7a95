/**
 * EmgSimulator: a Sequence of gestures, played by tick time from the pipeline start and cycled.
 */
import type { BlockContext } from "../../engine";
import type { GestureSet } from "./emg-simulator-gestures";

/** A step of the Sequence param. */
export interface SequenceStep {
  Gesture: string;
  Seconds: number;
}

/** A Sequence being played: its current step and when that step ends. */
export class GestureSequence {
  /** The current step, 0-based. */
  private step = 0;
  /** When the current step ends, clock time; NaN until the first tick after a restart. */
  private stepEnd = NaN;
  /** The gesture of every step. */
  private readonly gestures: Int32Array;
  /** How long every step lasts, s. */
  private readonly seconds: Float64Array;
  /** How long one pass through the steps lasts, s. */
  private readonly cycle: number;

  constructor(
    steps: readonly SequenceStep[],
    set: GestureSet,
    private readonly clock: Pick<BlockContext, "startTime" | "now">,
  ) {
    this.gestures = Int32Array.from(steps, (s) => set.indexOf(s.Gesture));
    this.seconds = Float64Array.from(steps, (s) => s.Seconds);
    this.cycle = this.seconds.reduce((a, b) => a + b, 0);
  }

  /** The gesture of the current step. */
  get gesture(): number {
    return this.gestures[this.step]!;
  }

  /** Back to the first step, timed from the pipeline start. */
  restart(): void {
    this.step = 0;
    this.stepEnd = NaN;
  }

  /** The gesture at tick time t: the steps that ended by then are passed (whole cycles at once). */
  gestureAt(t: number): number {
    if (Number.isNaN(this.stepEnd)) this.stepEnd = this.clock.startTime + this.seconds[0]!;
    const cycle = this.cycle;
    if (t - this.stepEnd >= cycle) this.stepEnd += Math.floor((t - this.stepEnd) / cycle) * cycle;
    while (t >= this.stepEnd) {
      this.nextStep();
      this.stepEnd += this.seconds[this.step]!;
    }
    return this.gestures[this.step]!;
  }

  /** Goes to the next step, which starts now; returns its gesture. */
  skip(): number {
    this.nextStep();
    this.stepEnd = this.clock.now() + this.seconds[this.step]!;
    return this.gestures[this.step]!;
  }

  /** The status text of a gesture played by the current step. */
  text(name: string): string {
    return `${name} (sequence step ${this.step + 1} of ${this.gestures.length})`;
  }

  private nextStep(): void {
    this.step = this.step + 1 === this.gestures.length ? 0 : this.step + 1;
  }
}
