import { readFileSync } from "node:fs";
import { describe, expect, test } from "vitest";
import { medianFrequency, sampleRate, welch } from "./spectrum";

/** scipy.signal.welch and the median frequency of its PSD (fixtures/gen_spectrum.py). */
interface Case {
  name: string;
  fs: number;
  x: number[];
  f: number[];
  p: number[];
  mdf: number;
}
const { cases } = JSON.parse(
  readFileSync(new URL("./fixtures/spectrum.json", import.meta.url), "utf8"),
) as { cases: Case[] };

describe("the scope's spectrum against scipy.signal.welch", () => {
  test.each(cases.map((c) => [c.name, c] as const))("%s: PSD and median frequency", (_n, c) => {
    const psd = welch(c.x, c.fs);
    expect(psd).not.toBeNull();
    expect(psd!.f.length).toBe(c.f.length);
    const peak = Math.max(...c.p);
    for (let k = 0; k < c.f.length; k++) {
      expect(psd!.f[k]).toBeCloseTo(c.f[k]!, 9);
      expect(Math.abs(psd!.p[k]! - c.p[k]!)).toBeLessThanOrEqual(1e-9 * peak);
    }
    expect(medianFrequency(psd!)).toBeCloseTo(c.mdf, 6);
  });

  test("two sines: the peaks are at 50 and 120 Hz", () => {
    const c = cases.find((x) => x.name === "sines")!;
    const psd = welch(c.x, c.fs)!;
    const peakBin = (lo: number, hi: number): number => {
      let best = -1;
      for (let k = 0; k < psd.f.length; k++)
        if (psd.f[k]! >= lo && psd.f[k]! <= hi && (best < 0 || psd.p[k]! > psd.p[best]!)) best = k;
      return psd.f[best]!;
    };
    expect(Math.abs(peakBin(30, 80) - 50)).toBeLessThan(4);
    expect(Math.abs(peakBin(100, 140) - 120)).toBeLessThan(4);
  });

  test("too few samples or no rate: no spectrum; no power: no median frequency", () => {
    expect(welch([1, 2, 3], 100)).toBeNull();
    expect(welch(new Float64Array(64), 0)).toBeNull();
    expect(medianFrequency(welch(new Float64Array(64).fill(3), 100)!)).toBeNaN();
    expect(sampleRate([0, 0.01, 0.02, 0.03])).toBeCloseTo(100, 9);
    expect(sampleRate([1])).toBeNaN();
  });
});
