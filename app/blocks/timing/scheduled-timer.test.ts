import { describe, expect, test } from "vitest";
import { BlockHarness } from "../../engine/testing";
import { convertLegacy } from "../../../tests/support/blocks";
import { ScheduledTimer } from "./scheduled-timer";

describe("ScheduledTimer", () => {
  test("ticks at its rate from start, stamped with the tick time", async () => {
    const h = await BlockHarness.create(ScheduledTimer, {}, { desiredRate: 200 });
    expect(h.timers[0]!.hz).toBe(200);
    h.start();
    h.tick(1);
    h.tick(1.005);
    expect(h.output().t).toEqual([1, 1.005]);
    expect(h.output().v).toEqual([[], []]);
  });

  test("Autostart: false waits for the start action; stop stops it", async () => {
    const h = await BlockHarness.create(ScheduledTimer, { Autostart: false }, { desiredRate: 10 });
    h.start();
    expect(h.text).toBe("stopped");
    h.tick(0);
    expect(h.output().t).toEqual([]);
    expect(h.instance.actions!.start!.run()).toBe("timer started");
    h.tick(0.1);
    expect(h.instance.actions!.stop!.run()).toBe("timer stopped");
    h.tick(0.2);
    expect(h.output().t).toEqual([0.1]);
  });

  test("MOSAIC's empty positional Params", () => {
    expect(
      convertLegacy("T: { Type: ScheduledTimer, DesiredRate: 200, Params: [x] }", "T"),
    ).toEqual({
      Autostart: true,
      CatchUp: "all",
    });
  });
});
