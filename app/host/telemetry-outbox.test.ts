import { describe, expect, it } from "vitest";
import { TelemetryOutbox, telemetryGroup } from "./telemetry-outbox";
import type { TelemetryReport } from "./worker-protocol";

const report = (t: number): TelemetryReport => ({
  t,
  worker: "main",
  blocks: "[]",
  edges: "[]",
  events: [],
  finished: false,
});

describe("TelemetryOutbox", () => {
  it("sends a group once it is complete, oldest first", () => {
    const sent: number[][] = [];
    const box = new TelemetryOutbox((rs) => sent.push(rs.map((r) => r.t)), 3);
    for (let t = 1; t <= 7; t++) box.add(report(t));
    expect(sent).toEqual([
      [1, 2, 3],
      [4, 5, 6],
    ]);
    expect(box.waiting).toBe(1);
  });

  it("flush sends what waits (before another message, at the end) and nothing when empty", () => {
    const sent: number[][] = [];
    const box = new TelemetryOutbox((rs) => sent.push(rs.map((r) => r.t)), 5);
    box.add(report(1));
    box.add(report(2));
    box.flush();
    box.flush();
    expect(sent).toEqual([[1, 2]]);
    expect(box.waiting).toBe(0);
  });

  it("a group of 1 sends each report at once", () => {
    const sent: number[][] = [];
    const box = new TelemetryOutbox((rs) => sent.push(rs.map((r) => r.t)));
    box.add(report(1));
    box.add(report(2));
    expect(sent).toEqual([[1], [2]]);
  });

  it("telemetryGroup: a quarter second at 20 Hz is 5 reports; never fewer than 1", () => {
    expect(telemetryGroup(0.25, 20)).toBe(5);
    expect(telemetryGroup(0.25, 2)).toBe(1);
    expect(telemetryGroup(0, 20)).toBe(1);
    expect(telemetryGroup(0.25, 100)).toBe(25);
  });
});
