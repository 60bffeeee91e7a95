import { beforeAll, describe, expect, test } from "vitest";
import { LearningModel, type LearningModelOptions } from "../../engine/dsp";
import { initDspForTests } from "../../../tests/support/wasm";
import {
  buildModel,
  formatR2,
  legacyMachine,
  listR2,
  loadModel,
  parseModelFile,
  serializeModel,
} from "./model-file";

beforeAll(() => initDspForTests());

const META = {
  block: "learn",
  blockType: "IncrementalPredictor",
  created: "2025-01-02T03:04:05.000Z",
};

/** A model trained on a small nonlinear data set, one sample at a time. */
function trained(o: LearningModelOptions, n = 60): LearningModel {
  const m = new LearningModel(o);
  const x = new Float64Array(o.inputs);
  const y = new Float64Array(o.outputs);
  const out = new Float64Array(o.outputs);
  for (let i = 0; i < n; i++) {
    for (let k = 0; k < o.inputs; k++) x[k] = Math.sin(0.3 * i + k) * (k + 1) + 2;
    for (let k = 0; k < o.outputs; k++) y[k] = Math.tanh(x[0]! - 2) + k * x[o.inputs - 1]!;
    m.trainPredict(x, y, out, 1);
  }
  return m;
}

function predict(m: LearningModel, rows: number): number[] {
  const x = Float64Array.from({ length: rows * m.inputs }, (_, i) => Math.cos(i) * 2 + 1);
  const out = new Float64Array(rows * m.outputs);
  m.predict(x, out, rows);
  return Array.from(out);
}

const OPTIONS: LearningModelOptions[] = [
  { kind: "ridge", inputs: 3, outputs: 2, lambda: 0.3 },
  { kind: "ridge", inputs: 3, outputs: 1, normalize: true, forgetting: 0.99, intercept: false },
  { kind: "rff", inputs: 2, outputs: 2, features: 12, gamma: 0.2, seed: 77 },
  { kind: "rff", inputs: 2, outputs: 1, features: 8, normalize: true, normalizeSamples: 20 },
];

describe("model files", () => {
  test.each(OPTIONS.map((o) => [`${o.kind}${o.normalize ? " normalized" : ""}`, o] as const))(
    "%s: save → load gives the same model",
    (_, o) => {
      const m = trained(o);
      const text = serializeModel(m, META);
      const f = parseModelFile(text, "m.json");
      expect(f.options).toEqual(m.options);
      expect(f.samplesSeen).toBe(60);
      expect(f.created).toBe(META.created);
      const back = buildModel(f, "m.json");
      const a = predict(m, 5);
      const b = predict(back, 5);
      for (let i = 0; i < a.length; i++) expect(b[i]).toBeCloseTo(a[i]!, 12);
      // Saving the loaded model gives the same file, up to rounding of the re-solved weights.
      expect(serializeModel(back, META).length).toBeGreaterThan(text.length * 0.9);
      m.dispose();
      back.dispose();
    },
  );

  test("the layout is readable: header first, one matrix row per line", () => {
    const m = trained({ kind: "rff", inputs: 2, outputs: 2, features: 3, seed: 1 }, 10);
    const text = serializeModel(m, { ...META, featureNames: ["MAV", "RMS"] });
    const lines = text.split("\n");
    expect(lines.slice(0, 10)).toEqual([
      "{",
      '  "format": "mosaic-model",',
      '  "version": 1,',
      '  "kind": "rff",',
      '  "inputs": 2,',
      '  "outputs": 2,',
      '  "lambda": 1,',
      '  "gamma": 0.5,',
      '  "D": 3,',
      '  "seed": 1,',
    ]);
    expect(text).toContain('  "featureNames": ["MAV","RMS"],');
    expect(text).toContain('  "created": "2025-01-02T03:04:05.000Z",');
    expect(text).toMatch(
      / {4}"weights": \[\n {6}\[-?\d[^\n]*\],\n {6}\[[^\n]*\],\n {6}\[[^\n]*\]\n {4}\],/,
    );
    expect(text).toMatch(/ {4}"omega": \[\n( {6}\[[^\n,]+, [^\n,]+\],?\n){3} {4}\],/);
    expect(JSON.parse(text)).toMatchObject({
      kind: "rff",
      D: 3,
      samplesSeen: 10,
      normalizer: null,
    });
  });

  test("a hand-written model: W = (XᵀX + λI)⁻¹XᵀY for one sample", () => {
    const text = JSON.stringify({
      format: "mosaic-model",
      version: 1,
      kind: "ridge",
      inputs: 2,
      outputs: 1,
      lambda: 1,
      forgetting: 1,
      intercept: false,
      normalize: false,
      samplesSeen: 1,
      lambdaEffective: 1,
      model: { weights: [[0.5], [1]], intercept: [0], penalty: [1, 1] },
      state: {
        weightSum: 1,
        xMean: [0, 0],
        yMean: [0],
        scatter: [
          [1, 2],
          [2, 4],
        ],
        cross: [[3], [6]],
        fitStats: { weight: 0, mean: [0], m2: [0], sse: [0] },
      },
    });
    const { model } = loadModel(text, "hand.json", {
      inputs: 2,
      outputs: 1,
      inputName: "F",
      targetName: null,
    });
    const out = new Float64Array(1);
    model.predict(Float64Array.of(2, 3), out, 1);
    expect(out[0]).toBeCloseTo(4, 12);
    model.dispose();
  });

  /** The parsed JSON of a model file (what the mutations below touch). */
  interface FileJson {
    model: Record<string, unknown>;
    state: Record<string, unknown> & { scatter: number[][] };
    [key: string]: unknown;
  }
  const good = (): FileJson =>
    JSON.parse(serializeModel(trained({ kind: "ridge", inputs: 2, outputs: 2 }), META)) as FileJson;
  const cases: [string, (f: FileJson) => unknown, string][] = [
    ["not JSON", () => "{", "model file 'm.json': not a MOSAIC model file: invalid JSON"],
    [
      "another format",
      (f) => ({ ...f, format: "onnx" }),
      'not a MOSAIC model file: "format" is "onnx"; expected "mosaic-model"',
    ],
    [
      "a newer version",
      (f) => ({ ...f, version: 2 }),
      "format version 2 is newer than this MOSAIC reads (1)",
    ],
    ["an unknown kind", (f) => ({ ...f, kind: "svm" }), 'kind is "svm"; expected "ridge" or "rff"'],
    [
      "a bad lambda",
      (f) => ({ ...f, lambda: -1 }),
      "lambda is -1; expected a number from 1e-50 to 1e50",
    ],
    [
      "a missing array",
      (f) => ({ ...f, model: { ...f.model, weights: undefined } }),
      "model.weights is missing; expected 2 rows of 2 numbers",
    ],
    [
      "too few rows",
      (f) => ({ ...f, model: { ...f.model, weights: [[1, 2]] } }),
      "model.weights has 1 rows; expected 2 (one per input)",
    ],
    [
      "a short row",
      (f) => ({ ...f, state: { ...f.state, scatter: [[1, 2], [3]] } }),
      "state.scatter[1] has 1 values; expected 2 (one per input)",
    ],
    [
      "a null value",
      (f) => ({ ...f, state: { ...f.state, yMean: [0, null] } }),
      "state.yMean[1] is null; expected a finite number",
    ],
    [
      "edited weights",
      (f) => ({
        ...f,
        model: {
          ...f.model,
          weights: [
            [9, 9],
            [9, 9],
          ],
        },
      }),
      "saved state: weights differ by up to",
    ],
    [
      "an asymmetric scatter",
      (f) => ({
        ...f,
        state: {
          ...f.state,
          scatter: [
            [f.state.scatter[0]![0]!, 1e3],
            [0, f.state.scatter[1]![1]!],
          ],
        },
      }),
      "scatter[1][0] differs from scatter[0][1]",
    ],
    [
      "a negative count",
      (f) => ({ ...f, samplesSeen: -3 }),
      "samplesSeen is -3; expected a whole number >= 0",
    ],
  ];
  test.each(cases)("refuses %s, naming the file and the problem", (_, mutate, message) => {
    const changed = mutate(good());
    const text = typeof changed === "string" ? changed : JSON.stringify(changed);
    expect(() =>
      loadModel(text, "m.json", { inputs: 2, outputs: 2, inputName: "F", targetName: "T" }),
    ).toThrow(message);
    try {
      loadModel(text, "m.json", { inputs: 2, outputs: 2, inputName: "F", targetName: "T" });
    } catch (e) {
      expect((e as Error).message.startsWith("model file 'm.json': ")).toBe(true);
    }
  });

  test("MOSAIC's learning machines by name", () => {
    const inc = ["IncrementalRidgeRegression", "IncrementalRFF"];
    expect(legacyMachine("IncrementalRFF", ["8", "12"], ["2", "0.5", "100"], inc)).toEqual({
      Model: "rff",
      Inputs: 8,
      Outputs: 12,
      Lambda: 0.04,
      Gamma: 0.125,
      Features: 100,
      Intercept: false,
    });
    expect(() => legacyMachine("IncrementalLDA", ["8", "12"], [], inc)).toThrow(
      "unknown learning machine 'IncrementalLDA'; expected one of IncrementalRidgeRegression, IncrementalRFF",
    );
    expect(() => legacyMachine("IncrementalRFF", ["8"], [], inc)).toThrow(/input and output sizes/);
    expect(() => legacyMachine("IncrementalRidgeRegression", ["8", "x"], [], inc)).toThrow(
      /output size 'x' is not a number/,
    );
  });

  test("R² texts", () => {
    expect(formatR2(Float64Array.of(0.9, NaN, 0.7))).toBe("R² 0.80");
    expect(formatR2(Float64Array.of(NaN))).toBe("R² –");
    expect(listR2(Float64Array.of(0.91234, NaN))).toBe("[0.912, –]");
  });
});
