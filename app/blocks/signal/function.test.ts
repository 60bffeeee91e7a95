import { beforeAll, describe, expect, test } from "vitest";
import { matrixShape, vectorShape } from "../../engine";
import { BlockHarness, type HarnessOptions } from "../../engine/testing";
import { convertLegacy, loadBlock, matrices, vectors } from "../../../tests/support/blocks";
import { initDspForTests } from "../../../tests/support/wasm";
import { FunctionBlock } from "./function";

beforeAll(() => initDspForTests());

const three = { shape: vectorShape(3), rate: 100 };
const x = [
  [-2, 0.5, 3],
  [4, -1.5, -0],
];

async function apply(params: object, input = x): Promise<number[][]> {
  const h = await BlockHarness.create(FunctionBlock, params, { inputs: [three] });
  h.start();
  h.push(vectors([1, 2], input));
  expect(h.output().t).toEqual([1, 2]);
  return h.output().v;
}

const base =
  "T: { Type: ScheduledTimer, DesiredRate: 10 }\nS: { Type: SinGenerator, Inputs: [T], Params: { Components: 3 } }\n";

describe("Function", () => {
  test("the Table 1 operations, element by element", async () => {
    expect(await apply({ Operation: "add", Value: 1 })).toEqual([
      [-1, 1.5, 4],
      [5, -0.5, 1],
    ]);
    expect(await apply({ Operation: "add", Value: [1, 2, 3] })).toEqual([
      [-1, 2.5, 6],
      [5, 0.5, 3],
    ]);
    expect(await apply({ Operation: "multiply", Value: -2 })).toEqual([
      [4, -1, -6],
      [-8, 3, 0],
    ]);
    expect(await apply({ Operation: "multiply", Value: [1, 0, 2] })).toEqual([
      [-2, 0, 6],
      [4, -0, -0],
    ]);
    expect(await apply({ Operation: "abs" })).toEqual([
      [2, 0.5, 3],
      [4, 1.5, 0],
    ]);
    expect(await apply({ Operation: "power" })).toEqual([
      [4, 0.25, 9],
      [16, 2.25, 0],
    ]);
    expect(await apply({ Operation: "power", Exponent: 3 })).toEqual([
      [-8, 0.125, 27],
      [64, -3.375, -0],
    ]);
    const sqrt = await apply({ Operation: "power", Exponent: 0.5 });
    expect(sqrt[0]![0]).toBeNaN(); // a negative base with a non-integer exponent, as in NumPy
    expect(sqrt[0]!.slice(1)).toEqual([Math.sqrt(0.5), Math.sqrt(3)]);
    expect(await apply({ Operation: "clip", Min: -1, Max: 1 })).toEqual([
      [-1, 0.5, 1],
      [1, -1, -0],
    ]);
    expect(await apply({ Operation: "clip", Min: 0 })).toEqual([
      [0, 0.5, 3],
      [4, 0, -0],
    ]);
  });

  test("clip bounds accept YAML .inf; Min > Max is rejected", () => {
    expect(
      loadBlock(
        `${base}F: { Type: Function, Inputs: [S], Params: { Operation: clip, Min: -.inf, Max: 2 } }`,
        "F",
      ).params,
    ).toEqual({ Operation: "clip", Min: -Infinity, Max: 2, Exponent: 2 });
    const r = loadBlock(
      `${base}F: { Type: Function, Inputs: [S], Params: { Operation: clip, Min: 3, Max: 2 } }`,
      "F",
    );
    expect(r.errors[0]!.message).toContain("Min must not be greater than Max");
    const bad = loadBlock(
      `${base}F: { Type: Function, Inputs: [S], Params: { Operation: clip, Max: big } }`,
      "F",
    );
    expect(bad.errors[0]!.message).toContain("expected a number (.inf and -.inf are allowed)");
  });

  test("matrices keep their shape; a Value per column applies to every row", async () => {
    const h = await BlockHarness.create(
      FunctionBlock,
      { Operation: "multiply", Value: [10, 100] },
      {
        inputs: [{ shape: matrixShape(2, 2) }],
      },
    );
    h.start();
    h.push(
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
    expect(h.ports[0]!.shape).toEqual(matrixShape(2, 2));
    expect(h.output().v).toEqual([[10, 200, 30, 400]]);
  });

  test("a second input is the operand: identity until it produces, then its latest value", async () => {
    const h = await BlockHarness.create(
      FunctionBlock,
      { Operation: "multiply" },
      {
        inputs: [three, { shape: vectorShape(3) }],
      },
    );
    h.start();
    h.push(vectors([0], [[1, 2, 3]]), 0);
    h.push(
      vectors(
        [1, 2],
        [
          [9, 9, 9],
          [2, 3, 4],
        ],
      ),
      1,
    );
    h.push(vectors([3], [[1, 2, 3]]), 0);
    expect(h.output().v).toEqual([
      [1, 2, 3],
      [2, 6, 12],
    ]);
    h.instance.reset!();
    h.push(vectors([4], [[1, 2, 3]]), 0);
    expect(h.output().v.at(-1)).toEqual([1, 2, 3]);

    const add = await BlockHarness.create(
      FunctionBlock,
      { Operation: "add" },
      {
        inputs: [three, { shape: vectorShape(1) }],
      },
    );
    add.start();
    add.push(vectors([0], [[1, 2, 3]]), 0);
    add.push(vectors([1], [[10]]), 1);
    add.push(vectors([2], [[1, 2, 3]]), 0);
    expect(add.output().v).toEqual([
      [1, 2, 3],
      [11, 12, 13],
    ]);
  });

  test("create-time errors name what is wrong and what was expected", async () => {
    const fail = (params: object, inputs: HarnessOptions["inputs"] = [three]) =>
      expect(BlockHarness.create(FunctionBlock, params, { inputs })).rejects;
    await fail({ Operation: "add" }).toThrow(
      "add needs Value (a number, or one per channel) or a second input giving the operand",
    );
    await fail({ Operation: "multiply", Value: [1, 2] }).toThrow(
      "Value has 2 numbers, but input 'in0' has shape [1, 3]; expected 1 or 3 numbers",
    );
    await fail({ Operation: "abs" }, [three, three]).toThrow(
      "a second input ('in1') is only used by add and multiply, not by abs; remove it",
    );
    await fail({ Operation: "add", Value: 1 }, [three, three]).toThrow(
      "Value is set, but the second input 'in1' provides the operand; remove one of them",
    );
    await fail({ Operation: "add" }, [three, { shape: vectorShape(2) }]).toThrow(
      "the operand input 'in1' has shape [1, 2]; expected a vector of width 1 or 3 to match input 'in0'",
    );
  });

  test("live Value, Exponent, Min and Max", async () => {
    const h = await BlockHarness.create(
      FunctionBlock,
      { Operation: "add", Value: 1 },
      { inputs: [three] },
    );
    h.start();
    h.instance.setParam!("Value", [0, 10, 20]);
    h.push(vectors([0], [[1, 1, 1]]));
    expect(h.output().v).toEqual([[1, 11, 21]]);
    expect(() => h.instance.setParam!("Value", [1, 2])).toThrow("Value has 2 numbers");

    const p = await BlockHarness.create(FunctionBlock, { Operation: "power" }, { inputs: [three] });
    p.start();
    p.instance.setParam!("Exponent", 3);
    p.push(vectors([0], [[2, 3, 4]]));
    expect(p.output().v).toEqual([[8, 27, 64]]);

    const c = await BlockHarness.create(FunctionBlock, { Operation: "clip" }, { inputs: [three] });
    c.start();
    c.instance.setParam!("Max", 2);
    c.instance.setParam!("Min", -1);
    c.push(vectors([0], [[-5, 1, 5]]));
    expect(c.output().v).toEqual([[-1, 1, 2]]);
  });

  test("legacy [op:value]: MOSAIC applied only the last listed op", () => {
    const conv = (args: string) =>
      convertLegacy(`${base}F: { Type: Function, Inputs: [S], Params: [${args}] }`, "F");
    expect(conv("multiply:5")).toEqual({ Operation: "multiply", Value: 5, Exponent: 2 });
    expect(conv("add:2")).toEqual({ Operation: "add", Value: 2, Exponent: 2 });
    expect(conv("'add:1;2;3'")).toEqual({ Operation: "add", Value: [1, 2, 3], Exponent: 2 });
    expect(conv("abs:0")).toEqual({ Operation: "abs", Exponent: 2 });
    expect(conv("power:3")).toEqual({ Operation: "power", Exponent: 3 });
    expect(conv("clip:0.8")).toEqual({ Operation: "clip", Min: 0, Max: 0.8, Exponent: 2 });
    expect(conv("abs:0, multiply:5, power:2")).toEqual({ Operation: "power", Exponent: 2 });
    const r = loadBlock(
      `${base}F: { Type: Function, Inputs: [S], Params: [multiply:5, abss:0] }`,
      "F",
    );
    expect(r.errors[0]!.message).toContain(
      "unknown operation 'abss' (expected one of add, multiply, abs, power, clip); did you mean 'abs'?",
    );
  });
});
