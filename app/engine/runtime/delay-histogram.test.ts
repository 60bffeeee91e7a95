import { describe, expect, test } from "vitest";
import { DelayHistogram } from "./delay-histogram";

describe("DelayHistogram", () => {
  test("quantiles within the bin resolution (1 µs below 64 µs, ≤ 3.2 % above), never optimistic", () => {
    const h = new DelayHistogram();
    // 1 … 10 000 µs
    for (let us = 1; us <= 10_000; us++) h.add(us / 1e6);
    const q = (p: number) => h.quantile(p) * 1e6;
    expect(q(0.5)).toBeGreaterThanOrEqual(5000);
    expect(q(0.5)).toBeLessThan(5000 * 1.032);
    expect(q(0.99)).toBeGreaterThanOrEqual(9900);
    expect(q(0.99)).toBeLessThan(9900 * 1.032);
    expect(h.p50).toBe(h.quantile(0.5));
    expect(h.p99).toBe(h.quantile(0.99));
    expect(h.max).toBe(0.01);
    expect(h.count).toBe(10_000);
  });

  test("small delays are exact to the microsecond; the max caps the top bin; reset empties", () => {
    const h = new DelayHistogram();
    h.add(0.000012);
    h.add(0.0000125);
    h.add(-0.000001);
    expect(h.quantile(1) * 1e6).toBeCloseTo(12.5, 9);
    expect(h.p50 * 1e6).toBeCloseTo(12.5, 9); // the bin edge (13 µs) capped by the max
    h.add(100); // beyond the last bin
    expect(h.quantile(1)).toBe(100);
    h.reset();
    expect(h.count).toBe(0);
    expect(h.p99).toBeNaN();
  });

  test("the cached quantiles follow new delays", () => {
    const h = new DelayHistogram();
    h.add(0.001);
    expect(h.p99).toBeCloseTo(0.001, 9);
    for (let i = 0; i < 100; i++) h.add(0.005);
    expect(h.p99).toBeGreaterThanOrEqual(0.005);
  });
});
