/** Function block branches that function.test.ts leaves out: operand expansion, live errors. */
import { afterEach, beforeAll, describe, expect, test, vi } from "vitest";
import { Frame, matrixShape, vectorShape } from "../../engine";
import { FunctionKernel } from "../../engine/dsp";
import { BlockHarness } from "../../engine/testing";
import { matrices, vectors } from "../../../tests/support/blocks";
import { initDspForTests } from "../../../tests/support/wasm";
import { FunctionBlock } from "./function";

beforeAll(() => initDspForTests());
afterEach(() => {
  vi.restoreAllMocks();
});

const three = { shape: vectorShape(3), rate: 100 };
const square = { shape: matrixShape(2, 2), rate: 100 };
const m = [
  [1, 2],
  [3, 4],
];

describe("Function (branches)", () => {
  test("a matrix Value of one per element is used as is", async () => {
    const h = await BlockHarness.create(
      FunctionBlock,
      { Operation: "add", Value: [10, 20, 30, 40] },
      { inputs: [square] },
    );
    h.start();
    h.push(matrices([0], [m]));
    expect(h.output().v).toEqual([[11, 22, 33, 44]]);
  });

  test("an operand input of one per column applies to every row of a matrix", async () => {
    const h = await BlockHarness.create(
      FunctionBlock,
      { Operation: "multiply" },
      { inputs: [square, { shape: vectorShape(2) }] },
    );
    h.start();
    h.push(
      vectors(
        [0, 1],
        [
          [7, 7],
          [10, 100],
        ],
      ),
      1,
    );
    h.push(matrices([2], [m]));
    expect(h.output().v).toEqual([[10, 200, 30, 400]]);
    expect(h.output().t).toEqual([2]);
  });

  test("a matrix operand input is refused", async () => {
    await expect(
      BlockHarness.create(FunctionBlock, { Operation: "add" }, { inputs: [square, square] }),
    ).rejects.toThrow(
      "the operand input 'in1' has shape [2, 2]; expected a vector of width 1, 2 (one per column) or 4 (one per element) to match input 'in0'",
    );
    await expect(
      BlockHarness.create(
        FunctionBlock,
        { Operation: "add", Value: [1, 2, 3] },
        { inputs: [square] },
      ),
    ).rejects.toThrow(
      "Value has 3 numbers, but input 'in0' has shape [2, 2]; expected 1, 2 (one per column) or 4 (one per element) numbers",
    );
  });

  test("an empty frame emits nothing; reset brings add's operand back to 0", async () => {
    const h = await BlockHarness.create(
      FunctionBlock,
      { Operation: "add" },
      { inputs: [three, { shape: vectorShape(1) }] },
    );
    h.start();
    h.push(Frame.from(vectorShape(3), [], []), 0);
    h.push(Frame.from(vectorShape(1), [], []), 1);
    expect(h.output().frames).toEqual([]);
    h.push(vectors([0], [[5]]), 1);
    h.push(vectors([1], [[1, 2, 3]]), 0);
    h.instance.reset!();
    h.push(vectors([2], [[1, 2, 3]]), 0);
    expect(h.output().v).toEqual([
      [6, 7, 8],
      [1, 2, 3],
    ]);
  });

  test("live errors leave the block as it was", async () => {
    const w = await BlockHarness.create(
      FunctionBlock,
      { Operation: "add" },
      { inputs: [three, { shape: vectorShape(1) }] },
    );
    expect(() => w.instance.setParam!("Value", 1)).toThrow(
      "Value is not used while a second input provides the operand",
    );

    const c = await BlockHarness.create(
      FunctionBlock,
      { Operation: "clip", Min: 0, Max: 1 },
      { inputs: [three] },
    );
    c.start();
    expect(() => c.instance.setParam!("Min", 2)).toThrow("Min 2 would be greater than Max 1");
    c.push(vectors([0], [[-1, 0.5, 3]]));
    expect(c.output().v).toEqual([[0, 0.5, 1]]);

    const p = await BlockHarness.create(FunctionBlock, { Operation: "power" }, { inputs: [three] });
    p.start();
    expect(() => p.instance.setParam!("Exponent", Infinity)).toThrow(
      /^cannot create the power kernel: /,
    );
    p.push(vectors([0], [[2, 3, 4]]));
    expect(p.output().v).toEqual([[4, 9, 16]]);
    p.instance.setParam!("Exponent", 3);
    p.push(vectors([1], [[2, 3, 4]]));
    expect(p.output().v.at(-1)).toEqual([8, 27, 64]);
  });

  test("a live change builds the new kernel before disposing the old; dispose frees the last", async () => {
    const spy = vi.spyOn(FunctionKernel.prototype, "dispose");
    const disposed = spy.mock.contexts;
    const h = await BlockHarness.create(
      FunctionBlock,
      { Operation: "multiply", Value: 2 },
      { inputs: [three] },
    );
    h.instance.setParam!("Value", 3);
    expect(disposed).toHaveLength(1);
    expect(() => h.instance.setParam!("Value", [1, 2])).toThrow("Value has 2 numbers");
    expect(disposed).toHaveLength(1);
    h.instance.dispose!();
    expect(disposed).toHaveLength(2);
    expect(disposed[1]).not.toBe(disposed[0]);
  });
});
