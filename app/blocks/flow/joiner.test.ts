import { describe, expect, test } from "vitest";
import { EMPTY_SHAPE, matrixShape, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { convertLegacy, ticks, vectors } from "../../../tests/support/blocks";
import { Joiner } from "./joiner";

const timer = { shape: EMPTY_SHAPE, rate: 50, isTimer: true };
const a = { shape: vectorShape(2), rate: 200 };
const b = { shape: vectorShape(1), rate: 100 };

describe("Joiner", () => {
  test("concatenates the latest values in input order on every tick, once all have produced", async () => {
    const h = await BlockHarness.create(Joiner, {}, { inputs: [a, timer, b] });
    h.start();
    expect(h.text).toBe("waiting for in0, in2");
    expect(h.ports[0]!.shape).toEqual(vectorShape(3));
    expect(h.desiredRate).toBe(50);
    h.push(
      vectors(
        [0.001, 0.002],
        [
          [1, 2],
          [3, 4],
        ],
      ),
      0,
    );
    expect(h.text).toBe("waiting for in2");
    h.push(ticks(0.01), 1); // b has not produced yet
    expect(h.output().t).toEqual([]);
    h.push(vectors([0.011], [[9]]), 2);
    expect(h.text).toBe("");
    h.push(ticks(0.02, 0.03), 1);
    h.push(vectors([0.031], [[5, 6]]), 0);
    h.push(ticks(0.04), 1);
    expect(h.output().t).toEqual([0.02, 0.03, 0.04]);
    expect(h.output().v).toEqual([
      [3, 4, 9],
      [3, 4, 9],
      [5, 6, 9],
    ]);
  });

  test("a data input as trigger: its slot holds each triggering event's value", async () => {
    const h = await BlockHarness.create(Joiner, { Trigger: "in1" }, { inputs: [b, a] });
    h.start();
    h.push(vectors([0], [[7]]), 0);
    h.push(
      vectors(
        [1, 2],
        [
          [1, 2],
          [3, 4],
        ],
      ),
      1,
    );
    expect(h.output().t).toEqual([1, 2]);
    expect(h.output().v).toEqual([
      [7, 1, 2],
      [7, 3, 4],
    ]);
    h.push(vectors([3], [[8]]), 0); // not the trigger: no output
    expect(h.output().t).toEqual([1, 2]);
    h.instance.reset!();
    h.push(vectors([4], [[5, 6]]), 1); // waits for in0 again
    expect(h.output().t).toEqual([1, 2]);
    expect(h.text).toBe("waiting for in0");
  });

  test("without a timer the first input triggers", async () => {
    const h = await BlockHarness.create(Joiner, {}, { inputs: [b, a] });
    h.start();
    h.push(vectors([0], [[1, 2]]), 1);
    h.push(vectors([1], [[7]]), 0);
    expect(h.output().v).toEqual([[7, 1, 2]]);
  });

  test("errors: unknown trigger (with a suggestion), matrix input, only timers", async () => {
    await expect(
      BlockHarness.create(Joiner, { Trigger: "inn1" }, { inputs: [a, b] }),
    ).rejects.toThrow("Trigger 'inn1' is not one of its inputs (in0, in1); did you mean 'in1'?");
    await expect(
      BlockHarness.create(Joiner, {}, { inputs: [a, { shape: matrixShape(3, 2) }] }),
    ).rejects.toThrow("input 'in1' has shape [3, 2] (a matrix); Joiner needs a vector [1, C]");
    await expect(BlockHarness.create(Joiner, {}, { inputs: [timer, timer] })).rejects.toThrow(
      "all of its inputs ('in0', 'in1') are timers",
    );
  });

  test("legacy [timerBlockName:X]", () => {
    expect(
      convertLegacy(
        "Timer: { Type: ScheduledTimer, DesiredRate: 50 }\n" +
          "A: { Type: SinGenerator, Inputs: [Timer] }\n" +
          "J: { Type: Joiner, Inputs: [A, Timer], Params: [timerBlockName:Timer] }\n",
        "J",
      ),
    ).toEqual({ Trigger: "Timer" });
  });
});
