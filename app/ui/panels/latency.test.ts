import { describe, expect, test } from "vitest";
import { durationText, latencyText } from "./latency";

describe("the Status tab's latency", () => {
  test("positive latencies read to the precision that matters", () => {
    expect(latencyText(250)).toBe("250 ms");
    expect(latencyText(1.234)).toBe("1.23 ms");
    expect(latencyText(0.35)).toBe("350 µs");
    expect(latencyText(0)).toBe("0 µs");
  });

  test("a tick emitted a few µs before its own deadline reads 0, never −5 µs", () => {
    expect(latencyText(-0.005)).toBe("0 µs");
    expect(latencyText(-0.0002)).toBe("0 µs");
    expect(latencyText(-0.9)).toBe("0 µs");
    for (const x of [-0.005, -0.5, -3, -1500]) expect(latencyText(x)).not.toMatch(/[−-]\s*\d/);
  });

  test("timestamps well ahead of the clock are said to be, not shown as negative latency", () => {
    expect(latencyText(-3)).toBe("0 (timestamps 3.00 ms ahead of the clock)");
  });

  test("no measurement yet", () => {
    expect(latencyText(NaN)).toBe("—");
    expect(durationText(12.5)).toBe("12.50 ms");
  });
});
