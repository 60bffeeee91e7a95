import { describe, expect, test } from "vitest";
import { matrixShape, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { convertLegacy, matrices, vectors } from "../../../tests/support/blocks";
import { Projector } from "./projector";

describe("Projector", () => {
  test("picks, reorders and repeats elements of a vector", async () => {
    const h = await BlockHarness.create(
      Projector,
      { Indices: [4, 5, 6, 0, 1, 2, 0] },
      {
        inputs: [{ shape: vectorShape(8) }],
      },
    );
    h.start();
    h.push(
      vectors(
        [3, 4],
        [
          [0, 1, 2, 3, 4, 5, 6, 7],
          [10, 11, 12, 13, 14, 15, 16, 17],
        ],
      ),
    );
    expect(h.output().t).toEqual([3, 4]);
    expect(h.output().v).toEqual([
      [4, 5, 6, 0, 1, 2, 0],
      [14, 15, 16, 10, 11, 12, 10],
    ]);
  });

  test("on a matrix, picks the same columns of every row", async () => {
    const h = await BlockHarness.create(
      Projector,
      { Indices: [2, 0] },
      { inputs: [{ shape: matrixShape(2, 3) }] },
    );
    h.start();
    h.push(
      matrices(
        [1],
        [
          [
            [1, 2, 3],
            [4, 5, 6],
          ],
        ],
      ),
    );
    expect(h.ports[0]!.shape).toEqual(matrixShape(2, 2));
    expect(h.output().v).toEqual([[3, 1, 6, 4]]);
  });

  test("an index beyond the input width is an error naming the range", async () => {
    await expect(
      BlockHarness.create(Projector, { Indices: [0, 9] }, { inputs: [{ shape: vectorShape(8) }] }),
    ).rejects.toThrow("index 9 is out of range for input 'in0' with 8 channels (valid: 0–7)");
  });

  test("legacy ['4;5;6;0;1;2']", () => {
    expect(
      convertLegacy(
        "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
          "S: { Type: SinGenerator, Inputs: [T], Params: { Components: 8 } }\n" +
          "P: { Type: Projector, Inputs: [S], Params: ['4;5;6;0;1;2'] }\n",
        "P",
      ),
    ).toEqual({ Indices: [4, 5, 6, 0, 1, 2] });
  });
});
