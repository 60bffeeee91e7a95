/**
 * A Stimulus's protocol (stimulus.ts) as a schedule: the order of the cues, and for the cue in
 * progress its phase (rest → rise → hold → capture → fall), when that phase started and ends, and
 * what the participant should do at a time within it.
 */
import { SeededRandom } from "../shared/random";

/** Phases, in order; their numbers are the `phase` output. */
export const REST = 0;
export const RISE = 1;
// 2: hold
export const CAPTURE = 3;
export const FALL = 4;
export const END = 5;
export const PHASES = ["rest", "rise", "hold", "capture", "fall", "end"] as const;

/** The label index of each cue: `tasks` played `repetitions` times, shuffled within each with a seed. */
export function cueOrder(
  tasks: readonly number[],
  repetitions: number,
  shuffle: boolean,
  seed: number,
): Int32Array {
  const order = new Int32Array(tasks.length * repetitions);
  const rng = new SeededRandom(seed);
  for (let r = 0; r < repetitions; r++) {
    const base = r * tasks.length;
    for (let i = 0; i < tasks.length; i++) order[base + i] = tasks[i]!;
    if (shuffle) {
      for (let i = tasks.length - 1; i > 0; i--) {
        const j = Math.floor(rng.uniform() * (i + 1));
        const a = order[base + i]!;
        order[base + i] = order[base + j]!;
        order[base + j] = a;
      }
    }
  }
  return order;
}

export class CueCycle {
  /** The number of cues. */
  readonly N: number;
  /** Seconds of each phase, REST … FALL (END: 0). */
  private readonly dur: Float64Array;
  /** The cue in progress (N after the last). */
  cue = 0;
  phase = REST;
  phaseStart = 0;
  phaseEnd = 0;

  constructor(
    /** Label index per cue. */
    readonly order: Int32Array,
    durations: readonly [number, number, number, number, number],
  ) {
    this.N = order.length;
    this.dur = Float64Array.of(...durations, 0);
  }

  /** The label index of the cue in progress. */
  get label(): number {
    return this.order[this.cue]!;
  }

  /** True at rest and after the last cue (the target is zeros, there is no cue). */
  get resting(): boolean {
    return this.phase === REST || this.phase === END;
  }

  /** Back to the first cue (its phase is set when the protocol starts). */
  rewind(): void {
    this.cue = 0;
  }

  /** The protocol starts at `t`: the first cue's rest. */
  begin(t: number): void {
    this.cue = 0;
    this.phase = REST;
    this.phaseStart = t;
    this.phaseEnd = t + this.dur[REST]!;
  }

  /** Goes to the next phase (after a fall, the next cue's rest; after the last cue, END) at `at`. */
  advance(at: number): void {
    this.phase++;
    if (this.phase > FALL) {
      this.phase = REST;
      this.cue++;
      if (this.cue === this.N) this.phase = END; // sent at the next tick, which ends the protocol
    }
    this.phaseStart = at;
    this.phaseEnd = this.phase === END ? Infinity : at + this.dur[this.phase]!;
  }

  /** Sets phase `i`'s duration; with `now`, a phase `i` in progress ends at its new time. */
  setDuration(i: number, seconds: number, now: boolean): void {
    this.dur[i] = seconds;
    if (now && this.phase === i) this.phaseEnd = this.phaseStart + seconds;
  }

  /** The gain of the target at `t`: sin² while rising, cos² while falling, 1 otherwise. */
  gain(t: number): number {
    if (this.phase !== RISE && this.phase !== FALL) return 1;
    const x = (Math.PI / 2) * ((t - this.phaseStart) / this.dur[this.phase]!);
    const s = this.phase === RISE ? Math.sin(x) : Math.cos(x);
    return s * s;
  }

  /** The `progress` values at `off`: cue number, cue count, label of the next cue to start. */
  writeProgress(v: Float64Array, off: number): void {
    const N = this.N;
    v[off] = Math.min(this.cue + 1, N);
    v[off + 1] = N;
    const next = this.phase === REST ? this.cue : this.cue + 1;
    v[off + 2] = this.phase !== END && next < N ? this.order[next]! : NaN;
  }
}
