/**
 * EmgSimulator: its gestures. The default set (smooth patterns around the forearm), the names of
 * a block's set, and the set one simulator plays: names in output order, activation patterns.
 */
import { closest } from "../../engine";

/** Names of the default gesture set, in output (one-hot) order. */
export const DEFAULT_GESTURES = [
  "rest",
  "fist",
  "open",
  "pinch",
  "flexion",
  "extension",
  "pronation",
  "supination",
] as const;

/** Resting activation of every channel. */
const REST = 0.02;

/**
 * Spatial patterns of the default gestures around the forearm: activation of channel k (at angle
 * θ_k = 2πk/C) is `base + peak · exp(κ (cos(θ_k − μ) − 1))` (a von Mises bump, 1 at μ), capped at 1.
 */
const PATTERNS: Record<
  Exclude<(typeof DEFAULT_GESTURES)[number], "rest">,
  [number, number, number, number]
> = {
  //            base  peak  μ (rad)          κ
  fist: [0.45, 0.4, 0, 1.5],
  open: [0.05, 0.7, (3 * Math.PI) / 4, 2],
  pinch: [0.05, 0.55, Math.PI / 4, 4],
  flexion: [0.05, 0.85, 0, 3],
  extension: [0.05, 0.85, Math.PI, 3],
  pronation: [0.05, 0.7, Math.PI / 2, 3],
  supination: [0.05, 0.7, (3 * Math.PI) / 2, 3],
};

/** The default gesture set for `channels` electrodes evenly spaced around the forearm. */
export function defaultGestures(channels: number): Record<string, number[]> {
  const out: Record<string, number[]> = { rest: new Array<number>(channels).fill(REST) };
  for (const [name, [base, peak, mu, kappa]] of Object.entries(PATTERNS)) {
    out[name] = Array.from({ length: channels }, (_, k) => {
      const theta = (2 * Math.PI * k) / channels;
      return Math.min(1, base + peak * Math.exp(kappa * (Math.cos(theta - mu) - 1)));
    });
  }
  return out;
}

/** The params that choose the gesture set. */
interface GestureParams {
  Channels: number;
  Gestures?: Record<string, number[]> | undefined;
}

/** The gesture names of a block: those of its `Gestures` param, or the default set. */
export const gestureNames = (p: { Gestures?: Record<string, number[]> | undefined }): string[] =>
  p.Gestures !== undefined ? Object.keys(p.Gestures) : [...DEFAULT_GESTURES];

/** The message for a gesture name that is not one of `names` (with the closest, if any). */
export const unknownGesture = (name: string, names: readonly string[]): string => {
  const s = closest(name, names);
  return (
    `unknown gesture '${name}' (gestures: ${names.join(", ")})` +
    (s !== undefined ? `; did you mean '${s}'?` : "")
  );
};

/** The gestures of one simulator: their names (in output order) and per-channel activations. */
export class GestureSet {
  readonly names: string[];
  /** Activation of every channel, 0..1, per gesture. */
  readonly patterns: Float64Array[];
  /** Index of the `rest` gesture; -1 without one. */
  readonly restIndex: number;
  /** Activations at rest: the `rest` gesture's pattern, zeros without one. */
  readonly restPattern: Float64Array;

  constructor(p: GestureParams) {
    this.names = gestureNames(p);
    const table = p.Gestures ?? defaultGestures(p.Channels);
    this.patterns = this.names.map((n) => Float64Array.from(table[n]!));
    this.restIndex = this.names.indexOf("rest");
    this.restPattern =
      this.restIndex >= 0 ? this.patterns[this.restIndex]! : new Float64Array(p.Channels);
  }

  /** The index of gesture `name` (throws for an unknown one). */
  indexOf(name: string): number {
    const i = this.names.indexOf(name);
    if (i < 0) throw new Error(unknownGesture(name, this.names));
    return i;
  }
}
