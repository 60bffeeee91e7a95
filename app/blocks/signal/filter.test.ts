import { readFileSync } from "node:fs";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { EMPTY_SHAPE, matrixShape, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, loadBlock, matrices, vectors } from "../../../tests/support/blocks";
import { fsResources } from "../../../tests/support/fs-resources";
import { initDspForTests } from "../../../tests/support/wasm";
import { Filter } from "./filter";

beforeAll(() => initDspForTests());

const two = { shape: vectorShape(2), rate: 100 };

describe("Filter", () => {
  test("FIR: y[n] = Σ m_i x[n−i] per channel, zero initial state", async () => {
    const h = await BlockHarness.create(
      Filter,
      { Numerator: [0.5, 0.25, 0.25] },
      { inputs: [two] },
    );
    h.start();
    h.push(
      vectors(
        [0, 1, 2, 3],
        [
          [4, 8],
          [0, 16],
          [8, 0],
          [4, 4],
        ],
      ),
    );
    expect(h.output().t).toEqual([0, 1, 2, 3]);
    expect(h.output().v).toEqual([
      [2, 4], // 0.5·4, 0.5·8
      [1, 10], // 0.5·0 + 0.25·4, 0.5·16 + 0.25·8
      [5, 6], // 0.5·8 + 0.25·0 + 0.25·4, 0 + 0.25·16 + 0.25·8
      [4, 6], // 0.5·4 + 0.25·8 + 0.25·0, 0.5·4 + 0.25·0 + 0.25·16
    ]);
  });

  test("IIR: y[n] = x[n] − d_1 y[n−1] (impulse response 0.5^n), state carries across frames", async () => {
    const h = await BlockHarness.create(
      Filter,
      { Numerator: [1], Denominator: [1, -0.5] },
      { inputs: [two] },
    );
    h.start();
    h.push(vectors([0], [[1, 2]]));
    h.push(
      vectors(
        [1, 2, 3],
        [
          [0, 0],
          [0, 0],
          [0, 0],
        ],
      ),
    );
    expect(h.output().v).toEqual([
      [1, 2],
      [0.5, 1],
      [0.25, 0.5],
      [0.125, 0.25],
    ]);
    h.instance.reset!();
    h.push(vectors([4], [[0, 0]]));
    expect(h.output().v.at(-1)).toEqual([0, 0]);
    h.instance.dispose!();
  });

  test("a matrix input filters every element as its own channel", async () => {
    const h = await BlockHarness.create(
      Filter,
      { Numerator: [1, 1] },
      { inputs: [{ shape: matrixShape(2, 2) }] },
    );
    h.start();
    h.push(
      matrices(
        [0, 1],
        [
          [
            [1, 2],
            [3, 4],
          ],
          [
            [10, 20],
            [30, 40],
          ],
        ],
      ),
    );
    expect(h.ports[0]!.shape).toEqual(matrixShape(2, 2));
    expect(h.output().v).toEqual([
      [1, 2, 3, 4],
      [11, 22, 33, 44],
    ]);
  });

  test("errors: Denominator not starting with 1, a timer input", async () => {
    const base =
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\nS: { Type: SinGenerator, Inputs: [T] }\n";
    const r = loadBlock(
      `${base}F: { Type: Filter, Inputs: [S], Params: { Numerator: [1], Denominator: [2, 1] } }`,
      "F",
    );
    expect(r.errors).toHaveLength(1);
    expect(r.errors[0]!.param).toBe("Denominator");
    expect(r.errors[0]!.message).toContain("Denominator must start with 1");
    await expect(
      BlockHarness.create(
        Filter,
        { Numerator: [1] },
        { inputs: [{ shape: EMPTY_SHAPE, isTimer: true }] },
      ),
    ).rejects.toThrow(
      "input 'in0' is a timer (its events carry no values); Filter needs a signal there",
    );
  });

  test("legacy [b0;b1;b2, 1;a1;a2] (denominator optional)", () => {
    const base =
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\nS: { Type: SinGenerator, Inputs: [T] }\n";
    expect(
      convertLegacy(
        `${base}F: { Type: Filter, Inputs: [S], Params: ['0.0201;0.0402;0.0201', '1;-1.561;0.6414'] }`,
        "F",
      ),
    ).toEqual({ Numerator: [0.0201, 0.0402, 0.0201], Denominator: [1, -1.561, 0.6414] });
    expect(
      convertLegacy(`${base}F: { Type: Filter, Inputs: [S], Params: ['0.5;0.5'] }`, "F"),
    ).toEqual({
      Numerator: [0.5, 0.5],
      Denominator: [1],
    });
  });

  test("FilePlayer → Function abs → Filter on the real recording matches scipy.signal.lfilter (1e-12)", async () => {
    const text = readFileSync(new URL("./fixtures/envelope_5hz.csv", import.meta.url), "utf8");
    const lines = text.trim().split("\n");
    const coef = (key: string): number[] =>
      lines
        .find((l) => l.startsWith(`# ${key}=`))!
        .slice(key.length + 3)
        .split(";")
        .map(Number);
    const b = coef("b");
    const a = coef("a");
    const reference = lines
      .filter((l) => !l.startsWith("#") && !l.startsWith("index"))
      .map((l) => l.split(",").map(Number) as [number, number, number]);
    expect(reference.length).toBeGreaterThan(1000);

    const run = await runVirtualPipeline(
      `
Play: { Type: FilePlayer, Params: { File: pipelines/data/emg_bursts_1000hz.csv } }
Rectify: { Type: Function, Inputs: [Play], Params: { Operation: abs } }
Envelope: { Type: Filter, Inputs: [Rectify], Params: { Numerator: [${b.join(", ")}], Denominator: [${a.join(", ")}] } }
`,
      { catalog, duration: 60, start: 0, resources: fsResources(), record: ["Envelope"] },
    );
    const env = run.outputs.get("Envelope")!;
    expect(env.t).toHaveLength(28519);
    let worst = 0;
    for (const [i, t, y] of reference) {
      expect(env.t[i]).toBe(t);
      worst = Math.max(worst, Math.abs(env.v[i]![0]! - y) / Math.abs(y));
    }
    expect(worst).toBeLessThanOrEqual(1e-12);
  });
});
