import { describe, expect, test } from "vitest";
import type { BlockInfo, GraphInfo } from "../../engine/protocol";
import { predictorOutputNames } from "./training-names";

const block = (over: Partial<BlockInfo>): BlockInfo =>
  ({
    name: "Predictor",
    type: "IncrementalPredictor",
    inputs: [],
    outputs: [{ name: "prediction", shape: { rows: 1, cols: 3 } }],
    params: {},
    ...over,
  }) as unknown as BlockInfo;

describe("predictorOutputNames", () => {
  const cues = block({
    name: "Cues",
    type: "Stimulus",
    params: { Labels: { rest: [0, 0, 0], fist: [1, 0, 0], pinch: [0, 0, 1], both: [1, 1, 0] } },
  });
  const graph = { file: "t.yaml", blocks: [cues] } as GraphInfo;
  const predictor = block({
    inputs: [
      { source: "Env", block: "Env", port: "out", subscribed: true },
      { source: "Cues.trigger", block: "Cues", port: "trigger", subscribed: true },
    ],
  });

  test("the target source's one-hot labels name the outputs; the others are numbered", () => {
    expect(predictorOutputNames(predictor, graph, 3)).toEqual(["fist", "output 2", "pinch"]);
  });

  test("the prediction output's own labels come first", () => {
    const named = block({
      ...predictor,
      outputs: [{ name: "prediction", shape: { rows: 1, cols: 3 }, labels: ["a", "b", "c"] }],
    });
    expect(predictorOutputNames(named, graph, 3)).toEqual(["a", "b", "c"]);
  });

  test("without a target input, numbers", () => {
    expect(predictorOutputNames(block({}), graph, 2)).toEqual(["output 1", "output 2"]);
  });
});
