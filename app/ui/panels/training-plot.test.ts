import { describe, expect, test } from "vitest";
import { seriesPath, yRange, type Traces } from "./training-plot";

/** Four events of one output: predictions and targets (NaN: not learning). */
const traces: Traces = {
  m: 1,
  t: Float64Array.from([10, 11, 12, 14]),
  pred: Float64Array.from([0, 0.5, 1.5, 1]),
  target: Float64Array.from([NaN, 1, 1, NaN]),
  n: 4,
};

describe("the Training view's overlay", () => {
  test("x spans the events' times, a missing value breaks the line", () => {
    const y = (v: number) => 10 * v;
    // t 10…14 → x 0…320.
    expect(seriesPath(traces, traces.pred, 0, y)).toBe("M0.0 0.0L80.0 5.0L160.0 15.0L320.0 10.0");
    expect(seriesPath(traces, traces.target, 0, y)).toBe("M80.0 10.0L160.0 10.0");
    const gap = { ...traces, pred: Float64Array.from([1, NaN, 1, 1]) };
    expect(seriesPath(gap, gap.pred, 0, y)).toBe("M0.0 10.0M160.0 10.0L320.0 10.0");
  });

  test("the y range holds both series and at least 0…1", () => {
    expect(yRange(traces, 0)).toEqual([0, 1.5]);
    const small = { ...traces, pred: new Float64Array(4).fill(0.2), target: new Float64Array(4) };
    expect(yRange(small, 0)).toEqual([0, 1]);
    const negative = { ...traces, pred: Float64Array.from([-2, 0, 0, 0]) };
    expect(yRange(negative, 0)).toEqual([-2, 1]);
  });
});
