/**
 * EmgSimulator: a simulated participant following cues. The cue inputs (every input after the
 * timer), the pending cue events in time order, and the mixture of gestures a cue asks for.
 */
import { BlockConfigError, type BlockContext } from "../../engine";
import { inputName, vectorInput } from "../shared/inputs";
import type { GestureSet } from "./emg-simulator-gestures";

/** Rows a queue of cue events has room for before it first grows. */
export const CUE_QUEUE_ROWS = 16;

/**
 * Checks that every cue input (every input after the timer) carries one value per cue gesture
 * (`cueMap`: the gesture of each value; `cueGestures`: the CueGestures param); returns how many
 * cue inputs there are.
 */
export function checkCueInputs(
  ctx: BlockContext,
  gestures: GestureSet,
  cueMap: Int32Array,
  cueGestures: readonly string[] | undefined,
): number {
  const names = gestures.names;
  const K = cueMap.length;
  const cueCount = ctx.inputs.length - 1;
  for (let i = 1; i <= cueCount; i++) {
    const c = vectorInput(ctx, i);
    if (c.size !== K) {
      throw new BlockConfigError(
        `cue input ${inputName(c.info)} carries ${c.size} values per event, but there are ${K} ` +
          `cue gestures (${names.length === K && cueGestures === undefined ? "every gesture" : "CueGestures"}: ` +
          `${Array.from(cueMap, (g) => names[g]).join(", ")}); set CueGestures to the ${c.size} ` +
          "gestures its values stand for",
        "CueGestures",
      );
    }
  }
  return cueCount;
}

/**
 * Pending cue events, sorted by time (events of several inputs may interleave): rows
 * [head, end) of their times and values (`width` values a row). It grows when full and is
 * reused, so a steady stream of cues allocates nothing.
 */
export class CueQueue {
  private times: Float64Array;
  private rows: Float64Array;
  private head = 0;
  private end = 0;

  constructor(
    private readonly width: number,
    capacity: number,
  ) {
    this.times = new Float64Array(capacity);
    this.rows = new Float64Array(capacity * width);
  }

  /** The events' values, `width` a row; a row that `takeDue` returns stays here until `push`. */
  get values(): Float64Array {
    return this.rows;
  }

  /** Forgets every pending event. */
  clear(): void {
    this.head = 0;
    this.end = 0;
  }

  /** Adds an event at time t with the values v[off, off + width), in time order. */
  push(t: number, v: Float64Array, off: number): void {
    if (this.end === this.times.length) this.makeRoom();
    const K = this.width;
    const times = this.times;
    const rows = this.rows;
    let i = this.end++;
    while (i > this.head && times[i - 1]! > t) {
      times[i] = times[i - 1]!;
      rows.copyWithin(i * K, (i - 1) * K, i * K);
      i--;
    }
    times[i] = t;
    for (let k = 0; k < K; k++) rows[i * K + k] = v[off + k]!;
  }

  /**
   * Takes every event due at time t (at or before it) and returns the row of the latest of them,
   * or -1 when none is due.
   */
  takeDue(t: number): number {
    const times = this.times;
    if (!(this.end > this.head && times[this.head]! <= t)) return -1;
    let row = this.head;
    while (this.head < this.end && times[this.head]! <= t) row = this.head++;
    if (this.head === this.end) this.head = this.end = 0;
    return row;
  }

  /** Room for one more row: the pending rows move to the front, or the capacity doubles. */
  private makeRoom(): void {
    if (this.head > 0) {
      const K = this.width;
      this.times.copyWithin(0, this.head, this.end);
      this.rows.copyWithin(0, this.head * K, this.end * K);
      this.end -= this.head;
      this.head = 0;
    } else {
      const times = new Float64Array(this.times.length * 2);
      times.set(this.times);
      const rows = new Float64Array(this.rows.length * 2);
      rows.set(this.rows);
      this.times = times;
      this.rows = rows;
    }
  }
}

/**
 * The mixture of gestures a cue asks for: the activation of every channel, rest + Σ w_k·(gesture_k
 * − rest) clipped to 0..1, and the weight of every gesture (the `gesture` output while following
 * cues: w_k at each cued gesture, 1 − Σ w at rest).
 */
export class CueMixer {
  /** The activation of every channel. */
  readonly activations: Float64Array;
  /** The weight of every gesture. */
  readonly weights: Float64Array;

  /** `cueMap`: the gesture that each value of a cue event stands for. */
  constructor(
    private readonly gestures: GestureSet,
    private readonly cueMap: Int32Array,
    channels: number,
  ) {
    this.activations = new Float64Array(channels);
    this.weights = new Float64Array(gestures.names.length);
  }

  /** Gesture g alone: weight 1, every other 0 (the activations are left as they are). */
  hold(g: number): void {
    this.weights.fill(0);
    this.weights[g] = 1;
  }

  /** Mixes the cue whose weights are v[off, off + cue gestures): new activations and weights. */
  mix(v: Float64Array, off: number): void {
    const { patterns, restPattern, restIndex } = this.gestures;
    const cueMap = this.cueMap;
    const weights = this.weights;
    const mix = this.activations;
    const channels = mix.length;
    weights.fill(0);
    mix.set(restPattern);
    let sum = 0;
    for (let k = 0; k < cueMap.length; k++) {
      let w = v[off + k]!;
      if (!(w > 0)) continue; // NaN and negative weights count as 0
      if (w > 1) w = 1;
      const g = cueMap[k]!;
      weights[g] = weights[g]! + w;
      sum += w;
      const pat = patterns[g]!;
      for (let c = 0; c < channels; c++) mix[c] = mix[c]! + w * (pat[c]! - restPattern[c]!);
    }
    for (let c = 0; c < channels; c++) {
      const a = mix[c]!;
      mix[c] = a < 0 ? 0 : a > 1 ? 1 : a;
    }
    if (restIndex >= 0 && sum < 1) weights[restIndex] = weights[restIndex]! + (1 - sum);
  }

  /** The gesture of the largest weight (the first of equal ones). */
  strongest(): number {
    const weights = this.weights;
    let best = 0;
    for (let g = 1; g < weights.length; g++) if (weights[g]! > weights[best]!) best = g;
    return best;
  }
}
