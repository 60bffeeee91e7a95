import { describe, expect, test } from "vitest";
import { EMPTY_SHAPE, vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { ticks } from "../../../tests/support/blocks";
import { DecimatorTimer } from "./decimator-timer";

const timer = { shape: EMPTY_SHAPE, rate: 200, isTimer: true };

describe("DecimatorTimer", () => {
  test("forwards every N-th tick (N = input rate / DesiredRate), the first one included", async () => {
    const h = await BlockHarness.create(DecimatorTimer, {}, { inputs: [timer], desiredRate: 25 });
    expect(h.text).toBe("every 8th tick");
    h.start();
    const t = Array.from({ length: 17 }, (_, k) => k / 200);
    h.push(ticks(...t.slice(0, 5)));
    h.push(ticks(...t.slice(5)));
    expect(h.output().t).toEqual([t[0], t[8], t[16]]);
    h.instance.reset!();
    h.push(ticks(1));
    expect(h.output().t.at(-1)).toBe(1);
  });

  test("a rate that does not divide the input's is rounded, with a warning", async () => {
    const h = await BlockHarness.create(DecimatorTimer, {}, { inputs: [timer], desiredRate: 30 });
    expect(h.warnings).toEqual([
      "200 Hz / 30 Hz is not a whole number; forwarding every 7th tick gives 28.5714 Hz",
    ]);
    expect(h.desiredRate).toBeCloseTo(200 / 7, 12);
  });

  test("errors: a non-timer input, a rate above the input's", async () => {
    await expect(
      BlockHarness.create(
        DecimatorTimer,
        {},
        { inputs: [{ shape: vectorShape(1), rate: 200 }], desiredRate: 25 },
      ),
    ).rejects.toThrow("its input 'in0' must be a timer");
    await expect(
      BlockHarness.create(DecimatorTimer, {}, { inputs: [timer], desiredRate: 400 }),
    ).rejects.toThrow("DesiredRate 400 Hz is faster than its input timer's 200 Hz");
  });
});
