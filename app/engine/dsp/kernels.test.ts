// The windowing, feature, adaptive-filter and artifact kernels through the wasm module, checked
// against the same NumPy/SciPy fixtures as the Rust crate (core-wasm/dsp/tests/fixtures/), with the
// same tolerances. Needs the built module: `npm run build:wasm`.
import { readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { beforeAll, describe, expect, it } from "vitest";

import {
  AdaptiveFilterKernel,
  ArtifactKernel,
  FEATURE_NAMES,
  FeatureKernel,
  initDsp,
  SlidingWindowKernel,
  WindowedFeatureKernel,
  type DerivativeOrderName,
  type FeatureRequest,
  type WindowFunctionName,
} from "./index";

const ROOT = join(dirname(fileURLToPath(import.meta.url)), "..", "..", "..");
const FIXTURES = join(ROOT, "core-wasm", "dsp", "tests", "fixtures");

type Num = number | "nan" | "inf" | "-inf";
const num = (v: Num): number =>
  v === "nan" ? NaN : v === "inf" ? Infinity : v === "-inf" ? -Infinity : v;
const nums = (a: readonly Num[]): Float64Array => Float64Array.from(a, num);
const fixture = <T>(name: string): T => JSON.parse(readFileSync(join(FIXTURES, name), "utf8")) as T;

interface FeaturesFixture {
  features: string[];
  streams: { name: string; channels: number; data: Num[] }[];
  cases: {
    stream: string;
    length: number;
    step: number;
    thresholds: { ZC: number; SSC: number; WAMP: number };
    ends: number[];
    expected: Num[];
  }[];
}

interface WindowFixture {
  coefficients: { name: WindowFunctionName; size: number; values: number[] }[];
  stream: { channels: number; data: number[] };
  tapered: {
    name: WindowFunctionName;
    length: number;
    step: number;
    ends: number[];
    expected: number[];
  }[];
}

interface AdaptiveFixture {
  inputs: { name: string; channels: number; data: number[]; times?: number[] }[];
  cases: {
    name: string;
    input: string;
    fs: number;
    G1: number;
    G2: number;
    B1: number;
    B2: number;
    order: DerivativeOrderName;
    timed: boolean;
    y: number[];
    cutoff?: Num[];
  }[];
}

interface ArtifactFixture {
  stream: { channels: number; data: Num[] };
  cases: {
    name: string;
    config: {
      RailLow: number | null;
      RailHigh: number | null;
      ClipTolerance: number;
      ClipFraction: number;
      FlatThreshold: number;
      JumpFactor: Num;
      DriftThreshold: number | null;
      Mode: "hard" | "soft";
    };
    length: number;
    step: number;
    ends: number[];
    flags: number[];
    counters: number[];
  }[];
}

function requests(f: FeaturesFixture, c: FeaturesFixture["cases"][number]): FeatureRequest[] {
  return f.features.map((name) => {
    const key = name === "SSC_MOSAIC" ? "SSC" : (name as "ZC" | "SSC" | "WAMP");
    const threshold = (c.thresholds as Record<string, number>)[key] ?? 0;
    return { feature: name as FeatureRequest["feature"], threshold };
  });
}

const COUNTS = new Set(["ZC", "SSC", "SSC_MOSAIC", "WAMP"]);

function compareFeatures(
  names: readonly string[],
  channels: number,
  got: Float64Array,
  expected: Float64Array,
  what: string,
): void {
  expect(got.length, what).toBe(expected.length);
  for (let i = 0; i < got.length; i++) {
    const e = expected[i]!;
    const g = got[i]!;
    const name = names[Math.floor(i / channels) % names.length]!;
    const where = `${what}: value ${i} (${name})`;
    if (Number.isNaN(e)) expect(g, where).toBeNaN();
    else if (COUNTS.has(name)) expect(g, where).toBe(e);
    else if (Math.abs(g - e) > 1e-12 * Math.abs(e)) expect.fail(`${where}: ${g} vs ${e}`);
  }
}

/** Pushes `input` in chunks of the given sizes (cycled) and concatenates what comes out. */
function pushSplit(
  k: SlidingWindowKernel | WindowedFeatureKernel,
  input: Float64Array,
  sizes: readonly number[],
): { out: number[]; ends: number[] } {
  const c = k.channels;
  const events = input.length / c;
  const out: number[] = [];
  const ends: number[] = [];
  const x = new Float64Array(input.length);
  let at = 0;
  for (let i = 0; at < events; i++) {
    const n = Math.min(sizes[i % sizes.length]!, events - at);
    x.set(input.subarray(at * c, (at + n) * c));
    const w = k.push(x, n);
    const buf = new Float64Array(Math.max(1, w * k.width));
    k.read(buf, w);
    out.push(...buf.subarray(0, w * k.width));
    for (let j = 0; j < w; j++) ends.push(at + k.end(j));
    at += n;
  }
  return { out, ends };
}

beforeAll(() => {
  initDsp(readFileSync(join(ROOT, "core-wasm", "pkg", "mosaic_core_bg.wasm")));
});

describe("FeatureKernel, WindowedFeatureKernel, SlidingWindowKernel", () => {
  const fx = fixture<FeaturesFixture>("features.json");

  it("match the NumPy definitions (sums 1e-12 relative, counts exact, NaN where NaN)", () => {
    for (const c of fx.cases) {
      const s = fx.streams.find((x) => x.name === c.stream)!;
      const data = nums(s.data);
      const expected = nums(c.expected);
      const what = `${c.stream} L=${c.length} S=${c.step}`;
      const req = requests(fx, c);

      const wf = new WindowedFeatureKernel(req, c.length, c.step, s.channels);
      const a = pushSplit(wf, data, [1_000_000]);
      expect(a.ends, what).toEqual(c.ends);
      compareFeatures(fx.features, s.channels, Float64Array.from(a.out), expected, what);
      // Any split gives the same bits.
      wf.reset();
      const b = pushSplit(wf, data, [1, 7, 0, 64, 3]);
      expect(b.out).toEqual(a.out);
      expect(b.ends).toEqual(a.ends);
      wf.dispose();

      const sw = new SlidingWindowKernel(c.length, c.step, s.channels);
      const w = pushSplit(sw, data, [13, 1, 200]);
      expect(w.ends, what).toEqual(c.ends);
      const fk = new FeatureKernel(req, c.length, s.channels);
      const out = new Float64Array(c.ends.length * fk.width);
      fk.process(Float64Array.from(w.out), out, c.ends.length);
      compareFeatures(fx.features, s.channels, out, expected, `${what} (window + kernel)`);
      sw.dispose();
      fk.dispose();
    }
  });

  it("reject bad arguments with clear messages", () => {
    expect(() => new FeatureKernel([], 10, 1)).toThrow("give at least one feature");
    expect(() => new FeatureKernel([{ feature: "NOPE" as "MAV" }], 10, 1)).toThrow(
      "unknown feature 'NOPE'",
    );
    expect(() => new FeatureKernel([{ feature: "MAV" }], 1, 1)).toThrow(
      "rows must be an integer of at least 2",
    );
    expect(() => new SlidingWindowKernel(4, 0, 1)).toThrow("step must be an integer of at least 1");
    expect(FEATURE_NAMES).toHaveLength(10);
  });
});

describe("SlidingWindowKernel window functions", () => {
  const fx = fixture<WindowFixture>("window.json");

  it("tapers like scipy.signal.get_window(name, L, fftbins=False) (|err| <= 1e-15)", () => {
    const data = Float64Array.from(fx.stream.data);
    for (const t of fx.tapered) {
      const sw = new SlidingWindowKernel(t.length, t.step, 2, t.name);
      const r = pushSplit(sw, data, [5, 50, 1]);
      expect(r.ends).toEqual(t.ends);
      let worst = 0;
      for (let i = 0; i < r.out.length; i++) {
        worst = Math.max(worst, Math.abs(r.out[i]! - t.expected[i]!));
      }
      expect(worst, t.name).toBeLessThanOrEqual(1e-15);
      sw.dispose();
    }
  });

  it("gives the window coefficients themselves on a stream of ones", () => {
    for (const c of fx.coefficients) {
      const sw = new SlidingWindowKernel(c.size, 1, 1, c.name);
      const k = sw.push(new Float64Array(c.size).fill(1), c.size);
      expect(k).toBe(1);
      const w = new Float64Array(c.size);
      sw.read(w, 1);
      for (let i = 0; i < c.size; i++) {
        expect(Math.abs(w[i]! - c.values[i]!), `${c.name}(${c.size})[${i}]`).toBeLessThanOrEqual(
          1e-15,
        );
      }
      sw.dispose();
    }
  });
});

describe("AdaptiveFilterKernel", () => {
  const fx = fixture<AdaptiveFixture>("adaptive.json");

  it("matches the reference loop of eqs. 2–4 (|err| <= 1e-12 · max|ref| per channel)", () => {
    for (const c of fx.cases) {
      const inp = fx.inputs.find((i) => i.name === c.input)!;
      const ch = inp.channels;
      const x = Float64Array.from(inp.data);
      const n = x.length / ch;
      const k = new AdaptiveFilterKernel({
        channels: ch,
        sampleRate: c.fs,
        g1: c.G1,
        g2: c.G2,
        b1: c.B1,
        b2: c.B2,
        order: c.order,
      });
      const times = c.timed ? Float64Array.from(inp.times!) : null;
      // Event by event, reading the cut-off after each.
      const y = new Float64Array(x.length);
      const fc = new Float64Array(x.length);
      const xe = new Float64Array(ch);
      const ye = new Float64Array(ch);
      const te = new Float64Array(1);
      for (let e = 0; e < n; e++) {
        xe.set(x.subarray(e * ch, (e + 1) * ch));
        if (times) {
          te[0] = times[e]!;
          k.processTimed(xe, te, ye, 1);
        } else k.process(xe, ye, 1);
        y.set(ye, e * ch);
        for (let j = 0; j < ch; j++) fc[e * ch + j] = k.cutoff(j);
      }
      const check = (got: Float64Array, ref: Float64Array, what: string) => {
        for (let j = 0; j < ch; j++) {
          let scale = 0;
          for (let e = 0; e < n; e++) {
            const r = ref[e * ch + j]!;
            if (Number.isFinite(r)) scale = Math.max(scale, Math.abs(r));
          }
          for (let e = 0; e < n; e++) {
            const r = ref[e * ch + j]!;
            const g = got[e * ch + j]!;
            if (!Number.isFinite(r)) expect(g).toBe(r);
            else if (Math.abs(g - r) > 1e-12 * scale) {
              expect.fail(`${c.name} ${what}[${e}, ${j}]: ${g} vs ${r}`);
            }
          }
        }
      };
      check(y, Float64Array.from(c.y), "y");
      if (c.cutoff) check(fc, nums(c.cutoff), "cutoff");
      // One call of n events = n calls of one; reset repeats.
      k.reset();
      const whole = new Float64Array(x.length);
      if (times) k.processTimed(x, times, whole, n);
      else k.process(x, whole, n);
      expect(Array.from(whole)).toEqual(Array.from(y));
      k.dispose();
    }
  });

  it("reports bad parameters", () => {
    const base = { channels: 1, sampleRate: 100, g1: 1, g2: 1, b1: 1, b2: 0 };
    expect(() => new AdaptiveFilterKernel({ ...base, sampleRate: 0 })).toThrow("sampling rate");
    expect(() => new AdaptiveFilterKernel({ ...base, b1: -1 })).toThrow("B1");
    expect(() => new AdaptiveFilterKernel({ ...base, order: "x" as DerivativeOrderName })).toThrow(
      "unknown derivative order 'x'",
    );
  });
});

describe("ArtifactKernel", () => {
  const fx = fixture<ArtifactFixture>("artifact.json");

  it("matches the NumPy rules exactly (flags, masks, counters, clean windows)", () => {
    const c = fx.stream.channels;
    const data = nums(fx.stream.data);
    for (const k of fx.cases) {
      const sw = new SlidingWindowKernel(k.length, k.step, c);
      const w = pushSplit(sw, data, [1000]);
      expect(w.ends).toEqual(k.ends);
      const n = k.ends.length;
      const cfg = k.config;
      const ar = new ArtifactKernel({
        rows: k.length,
        channels: c,
        ...(cfg.RailLow !== null ? { railLow: cfg.RailLow } : {}),
        ...(cfg.RailHigh !== null ? { railHigh: cfg.RailHigh } : {}),
        clipTolerance: cfg.ClipTolerance,
        clipFraction: cfg.ClipFraction,
        flatThreshold: cfg.FlatThreshold,
        jumpFactor: num(cfg.JumpFactor),
        ...(cfg.DriftThreshold !== null ? { driftThreshold: cfg.DriftThreshold } : {}),
        hard: cfg.Mode === "hard",
      });
      const windows = Float64Array.from(w.out);
      const clean = new Float64Array(windows.length);
      const mask = new Float64Array(n * c);
      const flags = new Float64Array(n * c);
      // Window by window (state carries), then compare.
      for (let i = 0; i < n; i++) {
        const size = k.length * c;
        const cl = new Float64Array(size);
        const m = new Float64Array(c);
        const f = new Float64Array(c);
        ar.process(windows.subarray(i * size, (i + 1) * size), 1, cl, m, f);
        clean.set(cl, i * size);
        mask.set(m, i * c);
        flags.set(f, i * c);
      }
      expect(Array.from(flags), k.name).toEqual(k.flags);
      expect(Array.from(mask)).toEqual(k.flags.map((f) => (f === 0 ? 1 : 0)));
      const counters: number[] = [];
      for (let ch = 0; ch < c; ch++) for (let r = 0; r < 6; r++) counters.push(ar.counter(ch, r));
      expect(counters, k.name).toEqual(k.counters);
      expect(ar.windows()).toBe(n);
      for (let i = 0; i < clean.length; i++) {
        const good = mask[Math.floor(i / (k.length * c)) * c + (i % c)] === 1;
        const want = cfg.Mode === "hard" && !good ? 0 : windows[i]!;
        expect(Object.is(clean[i], want) || (Number.isNaN(want) && Number.isNaN(clean[i]))).toBe(
          true,
        );
      }
      // All windows in one call give the same; reset and resetCounters.
      ar.reset();
      const f2 = new Float64Array(n * c);
      ar.process(windows, n, new Float64Array(windows.length), new Float64Array(n * c), f2);
      expect(Array.from(f2)).toEqual(k.flags);
      ar.resetCounters();
      expect(ar.windows()).toBe(0);
      expect(ar.counter(0, 5)).toBe(0);
      ar.dispose();
      sw.dispose();
    }
  });
});
