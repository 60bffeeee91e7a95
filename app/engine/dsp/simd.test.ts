// The SIMD128 paths of the wasm kernels against their scalar code, bit for bit. The module is
// built with `+simd128` (scripts/build-wasm.sh) and keeps the scalar code beside the SIMD paths;
// `setSimdEnabled(false)` selects it. The SIMD paths vectorise across channels only (two
// channels per instruction, every channel through the same operations in the same order, sums
// in sample order), so they must give the very same bits, NaN and signed zeros included. The
// native `cargo test` covers the scalar code against the NumPy/SciPy fixtures.
import { afterEach, beforeAll, describe, expect, it } from "vitest";

import { initDspForTests } from "../../../tests/support/wasm";
import {
  EmgSynth,
  FEATURE_NAMES,
  FeatureKernel,
  setSimdEnabled,
  SlidingWindowKernel,
  WindowedFeatureKernel,
  type FeatureRequest,
} from "./index";

beforeAll(() => {
  initDspForTests();
});

afterEach(() => {
  setSimdEnabled(true);
});

/** Index of the first value that differs in bits (Object.is: NaN equals NaN, 0 ≠ −0), or −1. */
function firstDifference(a: Float64Array, b: Float64Array): number {
  if (a.length !== b.length) return Math.min(a.length, b.length);
  for (let i = 0; i < a.length; i++) if (!Object.is(a[i], b[i])) return i;
  return -1;
}

/** Runs `f` with the SIMD paths and with the scalar code. */
function bothPaths(f: () => Float64Array): [Float64Array, Float64Array] {
  setSimdEnabled(true);
  const simd = f();
  setSimdEnabled(false);
  const scalar = f();
  setSimdEnabled(true);
  return [simd, scalar];
}

/** A seeded stream of doubles in (−1, 1) (a small LCG; the values only need to vary). */
function noise(seed: number): () => number {
  let s = seed >>> 0;
  return () => {
    s = (Math.imul(s, 1664525) + 1013904223) >>> 0;
    return s / 2 ** 31 - 1;
  };
}

describe("SIMD128 paths", () => {
  it("are in the module", () => {
    expect(setSimdEnabled(true)).toBe(true);
  });

  it("EmgSynth: the same bits as the scalar code (channel counts, batch sizes, targets, phasor resync)", () => {
    for (const channels of [1, 2, 3, 8, 33, 256]) {
      const events = 2600; // crosses the modulation phasor's exact recomputation (every 1024) twice
      const sizes = [1, 5, 32, 33, 100, 7];
      const [simd, scalar] = bothPaths(() => {
        const synth = new EmgSynth({ channels, sampleRate: 2048, seed: 11 + channels });
        const targets = Float64Array.from({ length: channels }, (_, c) => (c % 5) / 4);
        synth.setTargets(targets);
        const out = new Float64Array(events * channels);
        const buf = new Float64Array(100 * channels);
        for (let at = 0, i = 0; at < events; i++) {
          const n = Math.min(sizes[i % sizes.length]!, events - at);
          synth.generate(buf, n);
          out.set(buf.subarray(0, n * channels), at * channels);
          at += n;
          // New targets half-way (attack and release both run).
          if (at >= events / 2 && at - n < events / 2) {
            synth.setTargets(targets.map((t) => 1 - t));
          }
        }
        synth.dispose();
        return out;
      });
      expect(firstDifference(simd, scalar), `${channels} channels`).toBe(-1);
    }
  });

  it("EmgSynth: the two-lane logarithm equals the scalar ln over two million Gaussian pairs", () => {
    // Every channel-sample draws one pair of deviates by the polar method: one ln each.
    const channels = 64;
    const events = 32_768;
    const [simd, scalar] = bothPaths(() => {
      const synth = new EmgSynth({ channels, sampleRate: 2000, seed: 2024 });
      synth.setTargets(new Float64Array(channels).fill(1));
      const out = new Float64Array(events * channels);
      synth.generate(out, events);
      synth.dispose();
      return out;
    });
    expect(firstDifference(simd, scalar)).toBe(-1);
  });

  it("FeatureKernel: every feature, the same bits as the scalar code (NaN, ±∞, zeros, thresholds)", () => {
    const requests: FeatureRequest[] = FEATURE_NAMES.map((feature, i) => ({
      feature,
      threshold: [0, 0.1, 0, 0.05, 0.2, -0.1, 0, 0, 0, 0.3][i]!,
    }));
    const special = [NaN, Infinity, -Infinity, 0, -0, 1e300, -1e-300];
    for (const rows of [2, 3, 50, 410]) {
      for (const channels of [1, 2, 3, 7, 8, 9, 16, 17, 256]) {
        const windows = 3;
        const next = noise(rows * 1000 + channels);
        const x = Float64Array.from({ length: windows * rows * channels }, (_, i) =>
          i % 97 === 5 ? special[i % special.length]! : i % 11 === 0 ? 0 : next(),
        );
        const [simd, scalar] = bothPaths(() => {
          const k = new FeatureKernel(requests, rows, channels);
          const out = new Float64Array(windows * k.width);
          k.process(x, out, windows);
          k.dispose();
          return out;
        });
        expect(firstDifference(simd, scalar), `${rows} rows × ${channels} channels`).toBe(-1);
      }
    }
  });

  it("FeatureKernel: Hudgins' set (MAV, WL, ZC, SSC in one pass), the same bits as the scalar code", () => {
    const special = [NaN, Infinity, -Infinity, 0, -0, 1e300, -1e-300];
    // Any order of the four features; thresholds 0 and not (SSC's test is rewritten in that pass).
    const sets: FeatureRequest[][] = [
      [
        { feature: "MAV" },
        { feature: "WL" },
        { feature: "ZC", threshold: 0 },
        { feature: "SSC", threshold: 0 },
      ],
      [
        { feature: "SSC", threshold: 0.05 },
        { feature: "ZC", threshold: 0.1 },
        { feature: "MAV" },
        { feature: "WL" },
      ],
      [
        { feature: "ZC", threshold: -0.1 },
        { feature: "MAV" },
        { feature: "SSC", threshold: -0.02 },
        { feature: "WL" },
      ],
    ];
    for (const requests of sets) {
      for (const rows of [2, 3, 4, 50, 410]) {
        for (const channels of [1, 2, 3, 5, 8, 9, 256]) {
          const windows = 2;
          const next = noise(rows * 7 + channels);
          const x = Float64Array.from({ length: windows * rows * channels }, (_, i) =>
            i % 89 === 3 ? special[i % special.length]! : i % 13 === 0 ? 0 : next(),
          );
          const [simd, scalar] = bothPaths(() => {
            const k = new FeatureKernel(requests, rows, channels);
            const out = new Float64Array(windows * k.width);
            k.process(x, out, windows);
            k.dispose();
            return out;
          });
          const what = `${requests.map((r) => r.feature).join(",")}: ${rows} × ${channels}`;
          expect(firstDifference(simd, scalar), what).toBe(-1);
        }
      }
    }
  });

  it("WindowedFeatureKernel and SlidingWindowKernel + FeatureKernel: the same bits either way", () => {
    const requests: FeatureRequest[] = [
      { feature: "MAV" },
      { feature: "WL" },
      { feature: "ZC", threshold: 0.01 },
      { feature: "SSC" },
    ];
    const channels = 19;
    const events = 700;
    const next = noise(7);
    const x = Float64Array.from({ length: events * channels }, next);
    const [simd, scalar] = bothPaths(() => {
      const wf = new WindowedFeatureKernel(requests, 64, 9, channels);
      const sw = new SlidingWindowKernel(64, 9, channels);
      const fk = new FeatureKernel(requests, 64, channels);
      const out: number[] = [];
      const windows = new Float64Array(sw.maxWindows(50) * sw.width);
      const a = new Float64Array(wf.maxWindows(50) * wf.width);
      const b = new Float64Array(sw.maxWindows(50) * fk.width);
      for (let at = 0; at < events; at += 50) {
        const chunk = x.subarray(at * channels, (at + 50) * channels);
        const k = wf.push(chunk, 50);
        wf.read(a, k);
        const kw = sw.push(chunk, 50);
        sw.read(windows, kw);
        fk.process(windows, b, kw);
        expect(kw).toBe(k);
        out.push(...a.subarray(0, k * wf.width), ...b.subarray(0, kw * fk.width));
      }
      wf.dispose();
      sw.dispose();
      fk.dispose();
      return Float64Array.from(out);
    });
    expect(simd.length).toBeGreaterThan(0);
    expect(firstDifference(simd, scalar)).toBe(-1);
  });
});
