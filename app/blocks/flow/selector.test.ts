import { describe, expect, test } from "vitest";
import { matrixShape, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { convertLegacy, matrices, vectors } from "../../../tests/support/blocks";
import { Selector } from "./selector";

const window3x2 = [
  [1, 2],
  [3, 4],
  [5, 6],
];

async function select(params: object, shape = matrixShape(3, 2)) {
  const h = await BlockHarness.create(Selector, params, { inputs: [{ shape }] });
  h.start();
  return h;
}

describe("Selector", () => {
  test("without params it forwards its input (MOSAIC's Selector on a typed port)", async () => {
    const h = await select({});
    h.push(matrices([4], [window3x2]));
    expect(h.ports[0]!.shape).toEqual(matrixShape(3, 2));
    expect(h.output()).toMatchObject({ t: [4], v: [[1, 2, 3, 4, 5, 6]] });
  });

  test("Row picks one row as a vector; negative rows count from the end", async () => {
    const newest = await select({ Row: -1 });
    newest.push(matrices([0], [window3x2]));
    expect(newest.ports[0]!.shape).toEqual(vectorShape(2));
    expect(newest.output().v).toEqual([[5, 6]]);
    const first = await select({ Row: 0, Columns: [1] });
    first.push(matrices([0], [window3x2]));
    expect(first.output().v).toEqual([[2]]);
    newest.instance.setParam!("Row", -3);
    newest.push(matrices([1], [window3x2]));
    expect(newest.output().v[1]).toEqual([1, 2]);
  });

  test("Columns keeps and reorders columns of every row, or of a vector", async () => {
    const h = await select({ Columns: [1, 0, 1] });
    h.push(matrices([0], [window3x2]));
    expect(h.output().v).toEqual([[2, 1, 2, 4, 3, 4, 6, 5, 6]]);
    const v = await select({ Columns: [2] }, vectorShape(3));
    v.push(vectors([0], [[7, 8, 9]]));
    expect(v.output().v).toEqual([[9]]);
  });

  test("out-of-range rows and columns are refused at load; Row cannot appear while running", async () => {
    await expect(select({ Row: 3 })).rejects.toThrow(
      "Row 3 is out of range for input 'in0' with shape [3, 2] (valid: -3 to 2; -1 is the last row)",
    );
    await expect(select({ Row: -4 })).rejects.toThrow("out of range");
    await expect(select({ Columns: [2] })).rejects.toThrow("index 2 is out of range");
    const h = await select({});
    expect(() => h.instance.setParam!("Row", 1)).toThrow("only when it was set at load");
    const r = await select({ Row: 0 });
    expect(() => r.instance.setParam!("Row", 5)).toThrow("out of range");
  });

  test("legacy: no params", () => {
    expect(
      convertLegacy(
        "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
          "S: { Type: SinGenerator, Inputs: [T] }\n" +
          "X: { Type: Selector, Inputs: [S], Params: [''] }\n",
        "X",
      ),
    ).toEqual({});
  });
});
