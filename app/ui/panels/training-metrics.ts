/**
 * Training feedback of a predictor's panel, framework-free: R² of every output over the recent
 * labelled samples (as scikit-learn's `r2_score(multioutput="raw_values", force_finite=False)`),
 * and for gesture targets (one-hot vectors, all zeros for rest, as a Stimulus or Trigger cues
 * them) the confusion matrix, per-gesture accuracy (recall) and overall accuracy (as
 * `confusion_matrix`, `recall_score`, `accuracy_score`). Checked against scikit-learn in
 * training-metrics.test.ts (fixtures/gen_training_metrics.py).
 *
 * Classes are -1 (rest) and 0…m-1 (output k's gesture); matrix row/column i is class i - 1.
 */

/** Rest: no output above the threshold (a target of all zeros). */
export const REST = -1;
/** A prediction names a gesture when its largest output exceeds this (the held-out test's rule). */
export const CLASS_THRESHOLD = 0.5;

/**
 * R² of every output: 1 − Σ(y − p)² / Σ(y − ȳ)² over `n` samples of `m` values (row-major).
 * An output whose target never varies gives NaN when predicted exactly, else −∞.
 */
export function r2PerOutput(
  yTrue: ArrayLike<number>,
  yPred: ArrayLike<number>,
  n: number,
  m: number,
): Float64Array {
  const r2 = new Float64Array(m);
  for (let k = 0; k < m; k++) {
    let mean = 0;
    for (let i = 0; i < n; i++) mean += yTrue[i * m + k]!;
    mean /= n;
    let se = 0;
    let st = 0;
    for (let i = 0; i < n; i++) {
      const y = yTrue[i * m + k]!;
      se += (y - yPred[i * m + k]!) ** 2;
      st += (y - mean) ** 2;
    }
    r2[k] = st === 0 ? (se === 0 ? NaN : -Infinity) : 1 - se / st;
  }
  return r2;
}

/** The class a prediction names: its largest output when above CLASS_THRESHOLD, else rest. */
export function predictedClass(v: ArrayLike<number>, at: number, m: number): number {
  let best = 0;
  for (let k = 1; k < m; k++) if (v[at + k]! > v[at + best]!) best = k;
  return v[at + best]! > CLASS_THRESHOLD ? best : REST;
}

/**
 * The gesture a target cues: k for a one-hot vector (1 at k, 0 elsewhere), rest for all zeros,
 * undefined for anything else (a ramp, a continuous target: no gesture).
 */
export function targetClass(v: ArrayLike<number>, at: number, m: number): number | undefined {
  let hot = REST;
  for (let k = 0; k < m; k++) {
    const x = v[at + k]!;
    if (x === 0) continue;
    if (x !== 1 || hot !== REST) return undefined;
    hot = k;
  }
  return hot;
}

/** Counts[i][j]: samples of class i - 1 predicted as class j - 1 (classes -1…m-1). */
export function confusionMatrix(
  trueClass: ArrayLike<number>,
  predClass: ArrayLike<number>,
  m: number,
): number[][] {
  const cm = Array.from({ length: m + 1 }, () => new Array<number>(m + 1).fill(0));
  for (let i = 0; i < trueClass.length; i++) cm[trueClass[i]! + 1]![predClass[i]! + 1]!++;
  return cm;
}

/** Per-class accuracy (recall): the diagonal over each row's total; NaN for a class never cued. */
export function perClassAccuracy(cm: readonly (readonly number[])[]): number[] {
  return cm.map((row, i) => {
    const total = row.reduce((s, x) => s + x, 0);
    return total === 0 ? NaN : row[i]! / total;
  });
}

/** The share of samples on the diagonal (NaN without samples). */
export function overallAccuracy(cm: readonly (readonly number[])[]): number {
  let right = 0;
  let total = 0;
  cm.forEach((row, i) => {
    for (const x of row) total += x;
    right += row[i]!;
  });
  return total === 0 ? NaN : right / total;
}

/** What the panel shows for the samples in the window. */
export interface TrainingSummary {
  /** Labelled samples in the window. */
  samples: number;
  r2: Float64Array;
  /** Gesture classification of the samples whose target is a gesture (undefined: none is). */
  classes?: {
    confusion: number[][];
    perClass: number[];
    accuracy: number;
    /** Labelled samples whose target is no gesture (left out of the matrix). */
    leftOut: number;
  };
}

/**
 * The last `capacity` labelled samples (prediction and target, `m` values each), a ring: the
 * window the panel's figures describe. Samples without a target (NaN) are not added.
 */
export class TrainingWindow {
  private readonly pred: Float64Array;
  private readonly target: Float64Array;
  private head = 0;
  private count = 0;

  constructor(
    readonly m: number,
    readonly capacity: number,
  ) {
    this.pred = new Float64Array(m * capacity);
    this.target = new Float64Array(m * capacity);
  }

  get size(): number {
    return this.count;
  }

  /** Adds one sample from `p` at `pAt` and `y` at `yAt`; returns false when `y` has a NaN. */
  add(p: ArrayLike<number>, pAt: number, y: ArrayLike<number>, yAt: number): boolean {
    const m = this.m;
    for (let k = 0; k < m; k++) if (Number.isNaN(y[yAt + k]!)) return false;
    const at = this.head * m;
    for (let k = 0; k < m; k++) {
      this.pred[at + k] = p[pAt + k]!;
      this.target[at + k] = y[yAt + k]!;
    }
    this.head = (this.head + 1) % this.capacity;
    this.count = Math.min(this.count + 1, this.capacity);
    return true;
  }

  clear(): void {
    this.head = 0;
    this.count = 0;
  }

  /** R² per output and the gesture classification of the samples held. */
  summary(): TrainingSummary {
    const { m, count } = this;
    // Oldest first (the order does not change the figures; it keeps them reproducible).
    const start = count < this.capacity ? 0 : this.head;
    const y = new Float64Array(count * m);
    const p = new Float64Array(count * m);
    for (let i = 0; i < count; i++) {
      const from = ((start + i) % this.capacity) * m;
      y.set(this.target.subarray(from, from + m), i * m);
      p.set(this.pred.subarray(from, from + m), i * m);
    }
    const out: TrainingSummary = { samples: count, r2: r2PerOutput(y, p, count, m) };
    const trueClass: number[] = [];
    const predClass: number[] = [];
    for (let i = 0; i < count; i++) {
      const c = targetClass(y, i * m, m);
      if (c === undefined) continue;
      trueClass.push(c);
      predClass.push(predictedClass(p, i * m, m));
    }
    if (trueClass.length > 0) {
      const confusion = confusionMatrix(trueClass, predClass, m);
      out.classes = {
        confusion,
        perClass: perClassAccuracy(confusion),
        accuracy: overallAccuracy(confusion),
        leftOut: count - trueClass.length,
      };
    }
    return out;
  }
}
