import { describe, expect, test } from "vitest";
import { predictorMeta } from "./output-names";
import { targetColumnLabels } from "./trigger";

describe("names of target columns and predictor outputs (issue 17, defect 10)", () => {
  test("one-hot labels name their columns; rest (all zeros) names none", () => {
    const names = ["rest", "fist", "open", "pinch"];
    const targets = [
      [0, 0, 0],
      [1, 0, 0],
      [0, 1, 0],
      [0, 0, 1],
    ];
    expect(targetColumnLabels(names, targets)).toEqual(["fist", "open", "pinch"]);
  });

  test("no names unless every column has exactly one one-hot label", () => {
    expect(
      targetColumnLabels(
        ["a", "b"],
        [
          [1, 0],
          [0.5, 0.5],
        ],
      ),
    ).toBeUndefined();
    expect(
      targetColumnLabels(
        ["a", "b"],
        [
          [1, 0],
          [1, 0],
        ],
      ),
    ).toBeUndefined();
    expect(targetColumnLabels(["up", "down"], [[1], [-1]])).toEqual(["up"]);
    expect(targetColumnLabels([], [])).toBeUndefined();
  });

  test("a predictor's prediction and fit outputs take the target's names", () => {
    expect(predictorMeta(["fist", "open"], 2)).toEqual({
      prediction: { labels: ["fist", "open"] },
      fit: { labels: ["samples", "R² fist", "R² open"] },
    });
    // The pairs of a Buffer: targets first, then the data's names.
    expect(predictorMeta(["fist", "open", "EMG 1"], 2)?.prediction.labels).toEqual([
      "fist",
      "open",
    ]);
    expect(predictorMeta(undefined, 2)).toBeUndefined();
    expect(predictorMeta(["fist"], 2)).toBeUndefined();
  });
});
