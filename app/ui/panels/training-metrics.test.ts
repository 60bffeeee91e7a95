import { readFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import {
  confusionMatrix,
  overallAccuracy,
  perClassAccuracy,
  predictedClass,
  r2PerOutput,
  REST,
  targetClass,
  TrainingWindow,
} from "./training-metrics";

type Num = number | string | null;
interface R2Case {
  n: number;
  m: number;
  yTrue: number[];
  yPred: number[];
  r2: Num[];
}
interface ClassCase extends R2Case {
  trueClass: number[];
  predClass: number[];
  confusion: number[][];
  recall: Num[];
  accuracy: number;
}
const fx = JSON.parse(
  readFileSync(join(__dirname, "fixtures", "training_metrics.json"), "utf8"),
) as { r2: R2Case[]; classes: ClassCase[] };

/** The fixture's numbers: null is NaN, "-inf"/"inf" the infinities. */
const num = (x: Num): number =>
  x === null ? NaN : x === "-inf" ? -Infinity : x === "inf" ? Infinity : Number(x);

/** Equal within 1e-12, NaN and the infinities exactly. */
function expectClose(got: ArrayLike<number>, want: readonly Num[]): void {
  expect(got.length).toBe(want.length);
  want.forEach((w, i) => {
    const x = num(w);
    const g = got[i]!;
    if (!Number.isFinite(x)) expect(g).toBe(x);
    else expect(Math.abs(g - x)).toBeLessThan(1e-12);
  });
}

describe("training feedback figures equal scikit-learn's", () => {
  test.each(fx.r2)("r2_score raw_values, $n samples × $m outputs", (c) => {
    expectClose(r2PerOutput(c.yTrue, c.yPred, c.n, c.m), c.r2);
  });

  test.each(fx.classes)(
    "confusion_matrix, recall_score, accuracy_score: $n gestures of $m",
    (c) => {
      const truth = c.trueClass.map((_, i) => targetClass(c.yTrue, i * c.m, c.m));
      expect(truth).toEqual(c.trueClass);
      const pred = c.predClass.map((_, i) => predictedClass(c.yPred, i * c.m, c.m));
      expect(pred).toEqual(c.predClass);
      const cm = confusionMatrix(c.trueClass, c.predClass, c.m);
      expect(cm).toEqual(c.confusion);
      expectClose(perClassAccuracy(cm), c.recall);
      expect(overallAccuracy(cm)).toBeCloseTo(c.accuracy, 14);
    },
  );

  test("the window gives the same figures from the samples it holds", () => {
    const c = fx.classes[0]!;
    const w = new TrainingWindow(c.m, 1000);
    for (let i = 0; i < c.n; i++) expect(w.add(c.yPred, i * c.m, c.yTrue, i * c.m)).toBe(true);
    const s = w.summary();
    expect(s.samples).toBe(c.n);
    expectClose(s.r2, Array.from(r2PerOutput(c.yTrue, c.yPred, c.n, c.m)));
    expect(s.classes?.confusion).toEqual(c.confusion);
    expect(s.classes?.leftOut).toBe(0);
    expect(s.classes?.accuracy).toBeCloseTo(c.accuracy, 14);
  });
});

describe("TrainingWindow", () => {
  test("keeps the last samples only, skips unlabelled ones and counts non-gesture targets", () => {
    const w = new TrainingWindow(2, 3);
    expect(w.add([0.9, 0], 0, [NaN, NaN], 0)).toBe(false);
    w.add([0.1, 0.1], 0, [0, 0], 0); // rest, right (pushed out later)
    w.add([0.9, 0.2], 0, [1, 0], 0); // gesture 0, right
    w.add([0.2, 0.7], 0, [1, 0], 0); // gesture 0 predicted as 1
    w.add([0.4, 0.3], 0, [0.5, 0], 0); // a ramp: no gesture
    const s = w.summary();
    expect(s.samples).toBe(3);
    expect(s.classes?.leftOut).toBe(1);
    // Rows: rest, gesture 0, gesture 1; the rest sample left the window.
    expect(s.classes?.confusion).toEqual([
      [0, 0, 0],
      [0, 1, 1],
      [0, 0, 0],
    ]);
    expect(s.classes?.accuracy).toBe(0.5);
    expect(perClassAccuracy(s.classes!.confusion)[1]).toBe(0.5);
    w.clear();
    expect(w.summary().samples).toBe(0);
    expect(w.summary().classes).toBeUndefined();
  });

  test("a continuous target gives R² and no classification", () => {
    const w = new TrainingWindow(1, 10);
    for (const [p, y] of [
      [0.2, 0.25],
      [0.5, 0.4],
      [0.8, 0.9],
    ] as const)
      w.add([p], 0, [y], 0);
    const s = w.summary();
    expect(s.classes).toBeUndefined();
    // ȳ = 0.5166…; Σe² = 0.0025 + 0.01 + 0.01; Σ(y − ȳ)² = 0.231666…
    expect(s.r2[0]).toBeCloseTo(1 - 0.0225 / 0.2316666666666667, 12);
    expect(targetClass([0, 0, 0], 0, 3)).toBe(REST);
    expect(targetClass([0, 2, 0], 0, 3)).toBeUndefined();
    expect(targetClass([1, 1, 0], 0, 3)).toBeUndefined();
  });
});
