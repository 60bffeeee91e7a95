import { describe, expect, test } from "vitest";
import { Frame, vectorShape } from "../frame";
import { StatusTracker } from "./status";

describe("status: ticks a CatchUp: skip timer skipped", () => {
  test("lagging for as long as they span, at least 100 ms; the count is a running total", () => {
    const s = new StatusTracker(100);
    for (let i = 0; i < 100; i++) s.record(Frame.from(vectorShape(1), [i / 100], [[0]]), i / 100);
    const now = 0.995;
    expect(s.evaluate(now).status).toBe("ontime");
    s.missed(0, now);
    expect(s.evaluate(now).status).toBe("ontime");
    s.missed(3, now); // 30 ms of ticks: held 100 ms
    expect(s.evaluate(now)).toMatchObject({ status: "lagging", lagging: true });
    expect(s.lateUntil).toBeCloseTo(now + 0.1, 12);
    s.missed(3, now + 0.2); // nothing new
    expect(s.lateUntil).toBeCloseTo(now + 0.1, 12);
    s.missed(53, now + 0.2); // 50 more: 500 ms
    expect(s.lateUntil).toBeCloseTo(now + 0.7, 12);
  });
});
