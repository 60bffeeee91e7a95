import { beforeAll, describe, expect, test } from "vitest";
import { matrixShape, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { loadBlock, matrices, vectors } from "../../../tests/support/blocks";
import { initDspForTests } from "../../../tests/support/wasm";
import { FunctionBlock } from "./function";
import { Amplification, Rectification } from "./presets";

beforeAll(() => initDspForTests());

const x = [
  [-2, 0.5, 3],
  [4, -1.5, -0],
];

async function out(def: typeof Amplification | typeof Rectification, params: object) {
  const h = await BlockHarness.create(def, params, { inputs: [{ shape: vectorShape(3) }] });
  h.start();
  h.push(vectors([1, 2], x));
  return h;
}

async function fn(params: object) {
  const h = await BlockHarness.create(FunctionBlock, params, {
    inputs: [{ shape: vectorShape(3) }],
  });
  h.start();
  h.push(vectors([1, 2], x));
  return h.output();
}

describe("Amplification and Rectification", () => {
  test("are exactly Function multiply and Function abs", async () => {
    const a = await out(Amplification, { Gain: 5 });
    expect(a.output()).toEqual(await fn({ Operation: "multiply", Value: 5 }));
    expect(a.output().v).toEqual([
      [-10, 2.5, 15],
      [20, -7.5, -0],
    ]);
    const per = await out(Amplification, { Gain: [1, 2, -1] });
    expect(per.output().v).toEqual((await fn({ Operation: "multiply", Value: [1, 2, -1] })).v);
    const r = await out(Rectification, {});
    expect(r.output()).toEqual(await fn({ Operation: "abs" }));
    expect(r.output().v).toEqual([
      [2, 0.5, 3],
      [4, 1.5, 0],
    ]);
  });

  test("Gain defaults to 1, applies per column of a matrix, and is live", async () => {
    const one = await out(Amplification, {});
    expect(one.output().v).toEqual(x);
    one.instance.setParam!("Gain", [0, 1, 10]);
    one.push(vectors([3], [[1, 1, 1]]));
    expect(one.output().v[2]).toEqual([0, 1, 10]);
    expect(() => one.instance.setParam!("Gain", [1, 2])).toThrow(
      "Gain has 2 numbers, but input 'in0' has shape [1, 3]; expected 1 or 3",
    );
    const m = await BlockHarness.create(
      Amplification,
      { Gain: [10, 100] },
      {
        inputs: [{ shape: matrixShape(2, 2) }],
      },
    );
    m.start();
    m.push(
      matrices(
        [0],
        [
          [
            [1, 2],
            [3, 4],
          ],
        ],
      ),
    );
    expect(m.output().v).toEqual([[10, 200, 30, 400]]);
  });

  test("a Gain of the wrong width is refused at load, naming Gain", async () => {
    await expect(out(Amplification, { Gain: [1, 2] })).rejects.toThrow(
      "Gain has 2 numbers, but input 'in0' has shape [1, 3]; expected 1 or 3",
    );
    const r = loadBlock(
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
        "S: { Type: SinGenerator, Inputs: [T] }\n" +
        "A: { Type: Amplification, Inputs: [S], Params: { Gain: five } }\n",
      "A",
    );
    expect(r.errors[0]!.param).toBe("Gain");
  });

  test("they have no positional form (MOSAIC wrote them as Function blocks)", () => {
    expect(Amplification.legacyParams).toBeUndefined();
    expect(Rectification.legacyParams).toBeUndefined();
    const r = loadBlock(
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
        "S: { Type: SinGenerator, Inputs: [T] }\n" +
        "A: { Type: Function, Inputs: [S], Params: [multiply:5] }\n" +
        "R: { Type: Function, Inputs: [A], Params: [abs:0] }\n",
      "A",
    );
    expect(r.errors).toEqual([]);
  });
});
