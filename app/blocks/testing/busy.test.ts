import { describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { matrixShape, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { matrices, vectors } from "../../../tests/support/blocks";
import { Busy } from "./busy";

const time = async (fn: () => void): Promise<number> => {
  const t0 = performance.now();
  fn();
  return performance.now() - t0;
};

describe("Busy", () => {
  test("passes frames through unchanged (any shape)", async () => {
    const h = await BlockHarness.create(
      Busy,
      { Milliseconds: 0 },
      { inputs: [{ shape: matrixShape(2, 2) }] },
    );
    h.start();
    h.push(
      matrices(
        [1, 2],
        [
          [
            [1, 2],
            [3, 4],
          ],
          [
            [5, 6],
            [7, 8],
          ],
        ],
      ),
    );
    expect(h.output()).toEqual({
      t: [1, 2],
      v: [
        [1, 2, 3, 4],
        [5, 6, 7, 8],
      ],
      frames: [2],
    });
  });

  test("spins Milliseconds on every Every-th call; both are live", async () => {
    // (Only the spins are timed; a call without a spin takes microseconds, far below 40 ms.)
    const h = await BlockHarness.create(
      Busy,
      { Milliseconds: 40, Every: 2 },
      { inputs: [{ shape: vectorShape(1) }] },
    );
    h.start();
    const f = vectors([0], [[1]]);
    expect(await time(() => h.push(f))).toBeLessThan(40);
    expect(await time(() => h.push(f))).toBeGreaterThanOrEqual(40);
    h.instance.setParam!("Every", 1);
    h.instance.setParam!("Milliseconds", 5);
    expect(await time(() => h.push(f))).toBeGreaterThanOrEqual(5);
    h.instance.setParam!("Milliseconds", 0);
    expect(await time(() => h.push(f))).toBeLessThan(40);
  });

  test("a spin longer than the time its events span shows as stumbling", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: ScheduledTimer, DesiredRate: 200 }
S: { Type: SinGenerator, Inputs: [T] }
B: { Type: Busy, Inputs: [S], Params: { Milliseconds: 12, Every: 50 } }
`,
      { catalog, duration: 1 },
    );
    const b = run.telemetry.blocks.find((x) => x.name === "B")!;
    // Calls get two ticks (5 ms batching at 200 Hz): 12 ms is longer than the 10 ms they span.
    expect(b.computeMaxMs).toBeGreaterThanOrEqual(12);
    expect(b.status).toBe("stumbling");
  });
});
