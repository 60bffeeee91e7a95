/**
 * The bench's wake-up floors (app/cli/bench-side-procs.ts) run in child processes: the floor with
 * a pipeline's output must really send what it claims, as valid streamlined datagrams that the
 * bench's receiver decodes, in complete events at the pipeline's event rate.
 */
import { describe, expect, test } from "vitest";
import { measureIoFloor, measureWakeFloor } from "../../app/cli/bench-side-procs";

describe("bench wake-up floors", () => {
  test("the floor with a pipeline's datagrams sends them: complete events, no gap, the event rate", async () => {
    const { pct, udp } = await measureIoFloor(100, { eventHz: 25, perEvent: 3 }, 2);
    expect(pct).toBeGreaterThan(0);
    expect(udp.malformed).toBe(0);
    expect(udp.perEvent).toBe(3);
    expect(udp.datagrams).toBeGreaterThan(0);
    expect(udp.counterGaps).toBe(0);
    expect(udp.incompleteEvents).toBe(0);
    expect(udp.missingEvents).toBe(0);
    // The worker stamps event k with k / 25 s: the timestamps say the rate exactly.
    expect(udp.timestampRateHz).toBeCloseTo(25, 6);
  });

  test("the bare floor measures its child's CPU", async () => {
    const pct = await measureWakeFloor(100, 1);
    expect(Number.isFinite(pct)).toBe(true);
    expect(pct).toBeGreaterThan(0);
  });
});
