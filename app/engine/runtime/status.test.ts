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

describe("status: a device that delivers packets", () => {
  // A Trigno base: 26 samples at 1925.926 Hz every 13.5 ms, each packet processed when it arrives.
  const rate = 26 / 0.0135;
  const packet = (k: number) =>
    Frame.from(
      vectorShape(1),
      Array.from({ length: 26 }, (_, i) => (k * 26 + i) / rate),
      Array.from({ length: 26 }, () => [0]),
    );

  test("reads on time between packets (10 periods are 5 ms), idle after 50 ms of silence", () => {
    const s = new StatusTracker(rate);
    let now = 0;
    for (let k = 0; k < 40; k++) {
      now = (k + 1) * 0.0135;
      s.record(packet(k), now);
      // Just before the next packet: 13 ms without output (was idle after 10 periods, 5.2 ms).
      expect(s.evaluate(now + 0.013).status).toBe("ontime");
    }
    expect(s.evaluate(now + 0.049).status).toBe("ontime");
    expect(s.evaluate(now + 0.051).status).toBe("idle");
  });
});

describe("status: a block that emits on request (no desired rate)", () => {
  // A Buffer recording rows (Stream: false) or a recorder: it consumes its inputs at 25 Hz and
  // emits nothing until asked.
  test("reads on time while it consumes, idle a second after its inputs stop", () => {
    const s = new StatusTracker(0);
    expect(s.evaluate(0).status).toBe("idle");
    for (let k = 0; k < 50; k++) s.consumed(k / 25);
    const last = 49 / 25;
    expect(s.evaluate(last + 0.04).status).toBe("ontime");
    expect(s.evaluate(last + 0.9).status).toBe("ontime");
    expect(s.evaluate(last + 1.1).status).toBe("idle");
  });

  test("a block with a desired rate is still idle when it consumes without output", () => {
    const s = new StatusTracker(25);
    for (let k = 0; k < 50; k++) s.consumed(k / 25);
    expect(s.evaluate(49 / 25 + 0.01).status).toBe("idle");
  });
});
