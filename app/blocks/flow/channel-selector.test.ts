import { describe, expect, test } from "vitest";
import { matrixShape, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { convertLegacy, matrices, vectors } from "../../../tests/support/blocks";
import { ChannelSelector } from "./channel-selector";

async function selector(params: object, shape = vectorShape(4)) {
  const h = await BlockHarness.create(ChannelSelector, params, { inputs: [{ shape }] });
  h.start();
  return h;
}

const run = (h: BlockHarness, action: string, arg?: unknown) =>
  h.instance.actions![action]!.run(arg);

describe("ChannelSelector", () => {
  test("all channels pass by default; Active zeroes the others and keeps the shape", async () => {
    const all = await selector({});
    all.push(vectors([1], [[1, 2, 3, 4]]));
    expect(all.output().v).toEqual([[1, 2, 3, 4]]);
    expect(all.text).toBe("all 4 channels active");
    const h = await selector({ Active: [0, 2] });
    h.push(
      vectors(
        [1, 2],
        [
          [1, 2, 3, 4],
          [5, 6, 7, 8],
        ],
      ),
    );
    expect(h.output().t).toEqual([1, 2]);
    expect(h.output().v).toEqual([
      [1, 0, 3, 0],
      [5, 0, 7, 0],
    ]);
    expect(h.text).toBe("2/4 channels active (1, 3 zeroed)");
  });

  test("Inactive: hold keeps the last active value, nan gives NaN", async () => {
    const h = await selector({ Inactive: "hold" });
    h.push(vectors([0], [[1, 2, 3, 4]]));
    run(h, "deactivate", [1, 3]);
    h.push(vectors([1], [[5, 6, 7, 8]]));
    run(h, "activate", 3);
    h.push(vectors([2], [[9, 10, 11, 12]]));
    expect(h.output().v).toEqual([
      [1, 2, 3, 4],
      [5, 2, 7, 4],
      [9, 2, 11, 12],
    ]);
    h.instance.setParam!("Inactive", "nan");
    h.push(vectors([3], [[1, 1, 1, 1]]));
    expect(h.output().v[3]).toEqual([1, NaN, 1, 1]);
    // a channel never active holds 0
    const never = await selector({ Active: [0], Inactive: "hold" });
    never.push(vectors([0], [[1, 2, 3, 4]]));
    expect(never.output().v).toEqual([[1, 0, 0, 0]]);
  });

  test("actions toggle, all, none; invalid channels are refused with the valid range", async () => {
    const h = await selector({});
    expect(run(h, "toggle", "0;2")).toBe("active channels: 1, 3");
    expect(run(h, "toggle", 0)).toBe("active channels: 0, 1, 3");
    expect(run(h, "none")).toBe("active channels: none");
    expect(h.text).toBe("0/4 channels active (0, 1, 2, 3 zeroed)");
    expect(run(h, "all")).toBe("active channels: 0, 1, 2, 3");
    expect(() => run(h, "deactivate", 4)).toThrow("a whole number from 0 to 3, got 4");
    expect(() => run(h, "deactivate", [])).toThrow("got an empty list");
    expect(() => run(h, "activate")).toThrow("got nothing");
  });

  test("Active is live and reset returns to it", async () => {
    const h = await selector({ Active: [3] });
    h.instance.setParam!("Active", [1]);
    run(h, "activate", 2);
    h.push(vectors([0], [[1, 2, 3, 4]]));
    h.instance.reset!();
    h.push(vectors([1], [[1, 2, 3, 4]]));
    expect(h.output().v).toEqual([
      [0, 2, 3, 0],
      [0, 2, 0, 0],
    ]);
    expect(() => h.instance.setParam!("Active", [7])).toThrow("index 7 is out of range");
  });

  test("on a matrix, a channel is a column of every row", async () => {
    const h = await selector({ Active: [1] }, matrixShape(2, 2));
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
    expect(h.output().v).toEqual([[0, 2, 0, 4]]);
  });

  test("indices are checked against the input width at load", async () => {
    await expect(selector({ Active: [0, 4] })).rejects.toThrow(
      "index 4 is out of range for input 'in0' with 4 channels (valid: 0–3)",
    );
  });

  test("legacy: no params", () => {
    expect(
      convertLegacy(
        "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
          "S: { Type: SinGenerator, Inputs: [T], Params: { Components: 8 } }\n" +
          "C: { Type: ChannelSelector, Inputs: [S], Params: [''] }\n",
        "C",
      ),
    ).toEqual({ Inactive: "zero" });
  });
});
