import { describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { EMPTY_SHAPE, matrixShape, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { loadBlock, matrices, ticks, vectors } from "../../../tests/support/blocks";
import { Resampler } from "./resampler";

const timer = { shape: EMPTY_SHAPE, rate: 25, isTimer: true };
const signal = { shape: vectorShape(2), rate: 200 };

describe("Resampler", () => {
  test("hold: every tick emits the latest signal value with the tick's time", async () => {
    const h = await BlockHarness.create(Resampler, {}, { inputs: [signal, timer] });
    h.start();
    expect(h.text).toBe("waiting for in0");
    h.push(ticks(0.0), 1); // before any signal: nothing
    expect(h.output().t).toEqual([]);
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
    expect(h.text).toBe("");
    h.push(ticks(0.04, 0.08), 1);
    h.push(vectors([0.09], [[5, 6]]), 0);
    h.push(ticks(0.12), 1);
    expect(h.output().t).toEqual([0.04, 0.08, 0.12]);
    expect(h.output().v).toEqual([
      [3, 4],
      [3, 4],
      [5, 6],
    ]);
    expect(h.desiredRate).toBe(25);
  });

  test("mean: the mean since the previous tick, the latest value when none arrived", async () => {
    const h = await BlockHarness.create(Resampler, { Mode: "mean" }, { inputs: [timer, signal] });
    h.start();
    h.push(
      vectors(
        [1, 2, 3],
        [
          [1, 10],
          [2, 20],
          [6, 60],
        ],
      ),
      1,
    );
    h.push(ticks(4, 5), 0);
    h.push(vectors([6], [[8, 80]]), 1);
    h.push(ticks(7), 0);
    expect(h.output().t).toEqual([4, 5, 7]);
    expect(h.output().v).toEqual([
      [3, 30],
      [6, 60],
      [8, 80],
    ]);
  });

  test("keeps the signal's shape (matrices too); reset waits again", async () => {
    const h = await BlockHarness.create(
      Resampler,
      {},
      {
        inputs: [{ shape: matrixShape(2, 2) }, timer],
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
      0,
    );
    h.push(ticks(1), 1);
    expect(h.ports[0]!.shape).toEqual(matrixShape(2, 2));
    expect(h.output().v).toEqual([[1, 2, 3, 4]]);
    h.instance.reset!();
    expect(h.text).toBe("waiting for in0");
    h.push(ticks(2), 1);
    expect(h.output().t).toEqual([1]);
  });

  test("a tick takes the signal sample of its own time, however the step batches and orders them", async () => {
    const run = async (batchingMs: number, timerFirst: boolean) => {
      const inputs = timerFirst ? "[Slow, Sig]" : "[Sig, Slow]";
      const r = await runVirtualPipeline(
        `Pipeline: { BatchingMs: ${batchingMs} }\n` +
          "Timer: { Type: ScheduledTimer, DesiredRate: 1926 }\n" +
          "Slow: { Type: DecimatorTimer, DesiredRate: 25, Inputs: [Timer] }\n" +
          "Sig: { Type: SinGenerator, Inputs: [Timer], Params: { Frequency: 3 } }\n" +
          `R: { Type: Resampler, Inputs: ${inputs} }\n`,
        { catalog, duration: 2, start: 100 },
      );
      return { sig: r.outputs.get("Sig")!, r: r.outputs.get("R")!, timer: r.outputs.get("Timer")! };
    };
    const base = await run(0, false);
    expect(base.r.t.length).toBe(51);
    // Every tick holds exactly the signal sample stamped at its time (the sample of that tick).
    base.r.t.forEach((t, i) => {
      const k = base.sig.t.indexOf(t);
      expect(k).toBeGreaterThanOrEqual(0);
      expect(base.r.v[i]).toEqual(base.sig.v[k]);
    });
    for (const [ms, timerFirst] of [
      [0, true],
      [2, false],
      [5, true],
      [13.5, false],
    ] as const) {
      const other = await run(ms, timerFirst);
      expect(other.r.t).toEqual(base.r.t);
      expect(other.r.v).toEqual(base.r.v);
      if (ms > 0) expect(Math.max(...other.timer.frames)).toBeGreaterThan(1);
    }
  });

  test("exactly one input must be a timer", async () => {
    await expect(BlockHarness.create(Resampler, {}, { inputs: [signal, signal] })).rejects.toThrow(
      "neither of its inputs 'in0' and 'in1' is a timer; Resampler needs one signal and one timer",
    );
    await expect(BlockHarness.create(Resampler, {}, { inputs: [timer, timer] })).rejects.toThrow(
      "both of its inputs 'in0' and 'in1' are timers",
    );
  });

  test("MOSAIC's positional Params are accepted and ignored", () => {
    const r = loadBlock(
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
        "S: { Type: ScheduledTimer, DesiredRate: 50 }\n" +
        "R: { Type: Resampler, Inputs: [T, S], Params: [] }\n",
      "R",
    );
    expect(r.errors).toEqual([]);
    expect(r.params).toEqual({ Mode: "hold" });
  });
});
