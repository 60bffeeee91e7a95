import { describe, expect, test } from "vitest";
import type { BlockTelemetry, Telemetry } from "../engine/runtime/runtime";
import { renderTable } from "./table";

const block = (over: Partial<BlockTelemetry>): BlockTelemetry => ({
  name: "Timer",
  type: "ScheduledTimer",
  worker: "main",
  status: "ontime",
  lagging: false,
  stumbling: false,
  rate: 1926,
  desiredRate: 1926,
  events: 100,
  computeLastMs: 0.002,
  computeMeanMs: 0.002,
  computeMaxMs: 0.004,
  latencyMs: 0,
  delay: { p50Ms: 1.5, p99Ms: 1.7, maxMs: 3.2, windowMaxMs: 1.6, n: 50, lateMs: 55 },
  dropsIn: 0,
  text: "",
  errors: 0,
  lastError: "",
  finished: false,
  timing: { n: 99, meanDt: 1 / 1926, stdDt: 0, computeTotalMs: 0.2, calls: 50 },
  ...over,
});

describe("mosaic run's live table", () => {
  test("shows the delivery delay p99 / max of every block, '-' before any delivery", () => {
    const t: Telemetry = {
      t: 0,
      worker: "*",
      blocks: [
        block({}),
        block({
          name: "Idle",
          delay: { p50Ms: 0, p99Ms: 0, maxMs: 0, windowMaxMs: 0, n: 0, lateMs: 55 },
        }),
      ],
      edges: [],
      events: [],
      finished: false,
    };
    const lines = renderTable(t, { color: false });
    expect(lines[0]).toContain("delay (p99 / max)");
    expect(lines[1]).toContain("1.70 ms / 3.20 ms");
    expect(lines[2]).toMatch(/ - +0$/);
  });
});
