import { describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { matrixShape, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, matrices, vectors } from "../../../tests/support/blocks";
import { Sink } from "./sink";

describe("Sink", () => {
  test("counts the events of all its inputs and emits nothing", async () => {
    const h = await BlockHarness.create(
      Sink,
      {},
      {
        inputs: [{ shape: vectorShape(2) }, { shape: matrixShape(2, 2) }],
      },
    );
    expect(h.text).toBe("0 events received");
    h.start();
    h.push(
      vectors(
        [1, 2, 3],
        [
          [1, 2],
          [3, 4],
          [5, 6],
        ],
      ),
      0,
    );
    h.push(
      matrices(
        [4],
        [
          [
            [1, 2],
            [3, 4],
          ],
        ],
      ),
      1,
    );
    h.instance.stop!();
    expect(h.text).toBe("4 events received");
    expect(h.ports).toEqual([]);
    h.instance.reset!();
    expect(h.text).toBe("0 events received");
  });

  test("in a pipeline", async () => {
    const run = await runVirtualPipeline(
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\nOut: { Type: Sink, Inputs: [T] }\n",
      { catalog, duration: 1 },
    );
    // 11 ticks; the text is refreshed at most every 0.25 s of pipeline time: at the ticks
    // 0, 0.3, 0.6 and 0.9 s, the last time with 10 events.
    expect(run.telemetry.blocks.find((b) => b.name === "Out")!.text).toBe("10 events received");
  });

  test("accepts MOSAIC's empty positional Params", () => {
    expect(
      convertLegacy(
        "T: { Type: ScheduledTimer, DesiredRate: 10 }\nOut: { Type: Sink, Inputs: [T], Params: [x] }\n",
        "Out",
      ),
    ).toEqual({});
  });
});
