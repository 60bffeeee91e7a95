// The TypeScript wrapper over the wasm DSP core, checked against the same SciPy/NumPy fixtures as
// the Rust crate (core-wasm/dsp/tests/fixtures/), with the same tolerances.
// Needs the built module: `npm run build:wasm` (scripts/build-wasm.sh).
import { readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";
import { beforeAll, describe, expect, it } from "vitest";

import {
  dspReady,
  dspVersion,
  EmgSynth,
  FilterBank,
  FunctionKernel,
  initDsp,
  type FunctionKernelOptions,
  type FunctionOperation,
} from "./index";

const ROOT = join(dirname(fileURLToPath(import.meta.url)), "..", "..", "..");
const WASM = join(ROOT, "core-wasm", "pkg", "mosaic_core_bg.wasm");
const FIXTURES = join(ROOT, "core-wasm", "dsp", "tests", "fixtures");

type Num = number | "nan" | "inf" | "-inf";
const num = (v: Num): number =>
  v === "nan" ? NaN : v === "inf" ? Infinity : v === "-inf" ? -Infinity : v;
const nums = (a: readonly Num[]): Float64Array => Float64Array.from(a, num);

function fixture<T>(name: string): T {
  return JSON.parse(readFileSync(join(FIXTURES, name), "utf8")) as T;
}

interface LfilterFixture {
  filters: { name: string; num: number[]; den: number[] }[];
  inputs: { name: string; channels: number; data: number[] }[];
  cases: { filter: string; input: string; expected: number[] }[];
}

interface FunctionFixture {
  channels: number;
  inputs: { name: string; data: Num[] }[];
  cases: {
    op: FunctionOperation;
    params: { operand?: Num[]; exponent?: Num; min?: Num; max?: Num };
    input: string;
    expected: Num[];
  }[];
}

function maxAbsDiff(a: Float64Array, b: Float64Array): number {
  let m = 0;
  for (let i = 0; i < a.length; i++) m = Math.max(m, Math.abs((a[i] as number) - (b[i] as number)));
  return m;
}

function maxAbs(a: Float64Array): number {
  let m = 0;
  for (const v of a) m = Math.max(m, Math.abs(v));
  return m;
}

/** Bit-for-bit equality (NaN equals NaN, 0 and -0 differ). */
function expectSameBits(a: Float64Array, b: Float64Array, what: string): void {
  expect(a.length, what).toBe(b.length);
  const x = new BigUint64Array(a.buffer, a.byteOffset, a.length);
  const y = new BigUint64Array(b.buffer, b.byteOffset, b.length);
  for (let i = 0; i < x.length; i++) {
    if (x[i] !== y[i]) expect.fail(`${what}: value ${i} differs: ${a[i]} vs ${b[i]}`);
  }
}

/** Deterministic test signal (xorshift32). */
function signal(length: number, seed: number): Float64Array {
  let s = seed >>> 0 || 1;
  const out = new Float64Array(length);
  for (let i = 0; i < length; i++) {
    s ^= s << 13;
    s >>>= 0;
    s ^= s >>> 17;
    s ^= s << 5;
    s >>>= 0;
    out[i] = (s / 2 ** 32 - 0.5) * 4;
  }
  return out;
}

/** Runs `run(input, output, nEvents)` over `input` in chunks of the given sizes (cycled). */
function runSplit(
  input: Float64Array,
  channels: number,
  sizes: readonly number[],
  run: (x: Float64Array, y: Float64Array, n: number) => void,
): Float64Array {
  const events = input.length / channels;
  const out = new Float64Array(input.length);
  const x = new Float64Array(input.length);
  const y = new Float64Array(input.length);
  let at = 0;
  for (let i = 0; at < events; i++) {
    const n = Math.min(sizes[i % sizes.length] as number, events - at);
    // Arrays longer than needed, data from index 0: like pooled frames.
    x.set(input.subarray(at * channels, (at + n) * channels));
    run(x, y, n);
    out.set(y.subarray(0, n * channels), at * channels);
    at += n;
  }
  return out;
}

beforeAll(() => {
  initDsp(readFileSync(WASM));
});

describe("initDsp", () => {
  it("is ready and reports the crate version", () => {
    expect(dspReady()).toBe(true);
    expect(dspVersion()).toMatch(/^\d+\.\d+\.\d+/);
    initDsp(readFileSync(WASM)); // a second call is harmless
    expect(dspReady()).toBe(true);
  });
});

describe("FilterBank", () => {
  const fx = fixture<LfilterFixture>("lfilter.json");

  it("matches scipy.signal.lfilter on every fixture case (|err| <= 1e-12 · max(1, max|ref|))", () => {
    expect(fx.cases.length).toBe(20);
    for (const c of fx.cases) {
      const f = fx.filters.find((x) => x.name === c.filter)!;
      const x = fx.inputs.find((i) => i.name === c.input)!;
      const input = Float64Array.from(x.data);
      const expected = Float64Array.from(c.expected);
      const bank = new FilterBank(f.num, f.den, x.channels);
      const out = new Float64Array(input.length);
      bank.process(input, out, input.length / x.channels);
      const err = maxAbsDiff(out, expected);
      expect(err, `${c.filter} on ${c.input}`).toBeLessThanOrEqual(
        1e-12 * Math.max(1, maxAbs(expected)),
      );
      // In place (same array) gives the same numbers.
      bank.reset();
      const data = input.slice();
      bank.process(data, data, input.length / x.channels);
      expectSameBits(data, out, `${c.filter} on ${c.input}, in place`);
      bank.dispose();
    }
  });

  it("gives the same bits whatever the batch size", () => {
    const lp = fx.filters.find((f) => f.name === "mosaic_lowpass_2hz_fs200")!;
    const bp = fx.filters.find((f) => f.name === "butter4_bandpass_20_450_fs1000")!;
    for (const [f, channels] of [
      [lp, 32],
      [bp, 8],
      [lp, 1],
    ] as const) {
      const input = signal(1000 * channels, channels);
      const runner = () => {
        const bank = new FilterBank(f.num, f.den, channels);
        return (x: Float64Array, y: Float64Array, n: number) => bank.process(x, y, n);
      };
      const whole = runSplit(input, channels, [1000], runner());
      expectSameBits(runSplit(input, channels, [1], runner()), whole, `${f.name} 1 by 1`);
      expectSameBits(
        runSplit(input, channels, [3, 0, 200, 1, 65, 7], runner()),
        whole,
        `${f.name} irregular`,
      );
    }
  });

  it("repeats its output after reset()", () => {
    const bank = new FilterBank([0.2, 0.3], [1, -0.5, 0.1], 4);
    const x = signal(400, 9);
    const a = new Float64Array(400);
    const b = new Float64Array(400);
    bank.process(x, a, 100);
    bank.reset();
    bank.process(x, b, 100);
    expectSameBits(a, b, "after reset");
  });

  it("reports bad coefficients with the Rust message", () => {
    expect(() => new FilterBank([1], [0, 1], 2)).toThrow(
      "Denominator[0] must be non-zero (it is the a0 coefficient that the others are divided by)",
    );
    expect(() => new FilterBank([1, NaN], [1], 2)).toThrow(
      "Numerator[1] is NaN; every value of Numerator must be a finite number",
    );
    expect(() => new FilterBank([], [1], 2)).toThrow(/Numerator must have at least one/);
    expect(() => new FilterBank([1], [], 2)).toThrow(/use \[1\] for an FIR/);
    expect(() => new FilterBank([1], [1, Infinity], 2)).toThrow(/Denominator\[1\] is inf;/);
    expect(() => new FilterBank([1], [1], 0)).toThrow(/channels must be an integer from 1/);
    expect(() => new FilterBank([1], [1], 2.5)).toThrow(/channels must be an integer from 1/);
    try {
      new FilterBank([1], [0], 1);
      expect.fail("no error");
    } catch (e) {
      expect(e).toBeInstanceOf(Error);
    }
  });

  it("rejects short arrays, bad event counts and use after dispose", () => {
    const bank = new FilterBank([1], [1], 3);
    expect(() => bank.process(new Float64Array(5), new Float64Array(6), 2)).toThrow(
      /input has 5 values but 2 events × 3 channels need 6/,
    );
    expect(() => bank.process(new Float64Array(6), new Float64Array(6), -1)).toThrow(/nEvents/);
    expect(() => bank.process(new Float64Array(6), new Float64Array(6), 1.5)).toThrow(/nEvents/);
    bank.process(new Float64Array(6), new Float64Array(6), 0); // zero events is fine
    bank.dispose();
    bank.dispose();
    expect(() => bank.process(new Float64Array(6), new Float64Array(6), 2)).toThrow(
      /after dispose/,
    );
  });

  it("stays correct when other kernels grow the wasm memory", () => {
    const fxCase = fx.cases.find(
      (c) => c.filter === "butter4_bandpass_20_450_fs1000" && c.input === "random8",
    )!;
    const f = fx.filters.find((x) => x.name === fxCase.filter)!;
    const input = Float64Array.from(fx.inputs.find((i) => i.name === "random8")!.data);
    const expected = Float64Array.from(fxCase.expected);
    const channels = 8;
    const events = input.length / channels;
    const half = Math.floor(events / 2);

    const bank = new FilterBank(f.num, f.den, channels);
    const synth = new EmgSynth({ channels: 2, sampleRate: 1000, seed: 77 });
    const synthRef = new EmgSynth({ channels: 2, sampleRate: 1000, seed: 77 });
    synth.setTargets([1, 0.5]);
    synthRef.setTargets([1, 0.5]);
    const out = new Float64Array(input.length);
    const x = new Float64Array(input.length);
    const y = new Float64Array(input.length);
    x.set(input.subarray(0, half * channels));
    bank.process(x, y, half);
    out.set(y.subarray(0, half * channels));
    const s1 = new Float64Array(200);
    synth.generate(s1, 100);

    // Many large banks: the memory grows several times (every old view is detached).
    const big: FilterBank[] = [];
    const bigIn = signal(50_000 * 8, 3);
    const bigOut = new Float64Array(bigIn.length);
    for (let i = 0; i < 24; i++) {
      const b = new FilterBank(f.num, f.den, 8);
      b.process(bigIn, bigOut, 50_000);
      big.push(b);
    }
    x.set(input.subarray(half * channels));
    bank.process(x, y, events - half);
    out.set(y.subarray(0, (events - half) * channels), half * channels);
    expect(maxAbsDiff(out, expected)).toBeLessThanOrEqual(1e-12 * Math.max(1, maxAbs(expected)));

    const s2 = new Float64Array(200);
    synth.generate(s2, 100);
    const sRef = new Float64Array(400);
    synthRef.generate(sRef, 200);
    const sAll = new Float64Array(400);
    sAll.set(s1);
    sAll.set(s2, 200);
    expectSameBits(sAll, sRef, "EmgSynth across memory growth");

    // The big banks still work, and freeing them leaves the others intact.
    const check = new Float64Array(bigIn.length);
    const ref = new FilterBank(f.num, f.den, 8);
    ref.process(bigIn, check, 50_000);
    const last = big[big.length - 1]!;
    last.reset();
    last.process(bigIn, bigOut, 50_000);
    expectSameBits(bigOut, check, "big bank after growth");
    for (const b of big) b.dispose();
    bank.reset();
    bank.process(input, out, events);
    expect(maxAbsDiff(out, expected)).toBeLessThanOrEqual(1e-12 * Math.max(1, maxAbs(expected)));
    for (const k of [bank, ref, synth, synthRef]) k.dispose();
  });
});

describe("FunctionKernel", () => {
  const fx = fixture<FunctionFixture>("function.json");

  function optionsOf(p: FunctionFixture["cases"][number]["params"]): FunctionKernelOptions {
    return {
      operand: p.operand?.map(num),
      exponent: p.exponent === undefined ? undefined : num(p.exponent),
      min: p.min === undefined ? undefined : num(p.min),
      max: p.max === undefined ? undefined : num(p.max),
    };
  }

  it("matches the NumPy formulas (|err| <= 1e-12 · max(1, |ref|); NaN and ±inf exact)", () => {
    expect(fx.cases.length).toBeGreaterThanOrEqual(40);
    const c = fx.channels;
    for (const k of fx.cases) {
      const input = nums(fx.inputs.find((i) => i.name === k.input)!.data);
      const expected = nums(k.expected);
      const opts = optionsOf(k.params);
      const label = `${k.op} ${JSON.stringify(k.params)} on ${k.input}`;
      const kernel = new FunctionKernel(k.op, opts, c);
      const out = new Float64Array(input.length);
      kernel.process(input, out, input.length / c);
      for (let i = 0; i < out.length; i++) {
        const y = out[i] as number;
        const r = expected[i] as number;
        const ok = Number.isNaN(r)
          ? Number.isNaN(y)
          : !Number.isFinite(r)
            ? y === r
            : Math.abs(y - r) <= 1e-12 * Math.max(1, Math.abs(r));
        if (!ok) expect.fail(`${label}: value ${i} (x = ${input[i]}) is ${y}, numpy gives ${r}`);
      }
      if (opts.operand !== undefined && opts.operand.length === c) {
        const out2 = new Float64Array(input.length);
        kernel.processWithOperand(input, Float64Array.from(opts.operand), out2, input.length / c);
        expectSameBits(out2, out, `${label} with operand`);
      }
      kernel.dispose();
    }
  });

  it("gives the same bits whatever the batch size, and processWithOperand broadcasts", () => {
    const ops: [FunctionOperation, FunctionKernelOptions][] = [
      ["add", { operand: [0.5, -1, 2] }],
      ["multiply", { operand: [3] }],
      ["abs", {}],
      ["power", { exponent: 1.7 }],
      ["power", { exponent: -2 }],
      ["clip", { min: -0.5, max: 1 }],
    ];
    const input = signal(3 * 500, 4);
    for (const [op, opts] of ops) {
      const runner = () => {
        const k = new FunctionKernel(op, opts, 3);
        return (x: Float64Array, y: Float64Array, n: number) => k.process(x, y, n);
      };
      const whole = runSplit(input, 3, [500], runner());
      expectSameBits(runSplit(input, 3, [1], runner()), whole, `${op} 1 by 1`);
      expectSameBits(runSplit(input, 3, [7, 0, 130, 2], runner()), whole, `${op} irregular`);
    }
    const k = new FunctionKernel("multiply", { operand: [1] }, 2);
    const out = new Float64Array(4);
    k.processWithOperand(Float64Array.of(1, 2, 3, 4), Float64Array.of(10, -1), out, 2);
    expect(Array.from(out)).toEqual([10, -2, 30, -4]);
  });

  it("reports bad options", () => {
    expect(() => new FunctionKernel("clip", { min: 1, max: 0 }, 2)).toThrow(/expected min <= max/);
    expect(() => new FunctionKernel("add", { operand: [1, 2] }, 3)).toThrow(
      "Operand has 2 values; expected 1 (the same value for every channel) or 3 (one per channel)",
    );
    expect(() => new FunctionKernel("add", {}, 3)).toThrow(/needs options.operand/);
    expect(() => new FunctionKernel("power", {}, 3)).toThrow(/needs options.exponent/);
    expect(() => new FunctionKernel("power", { exponent: NaN }, 3)).toThrow(
      /Exponent is NaN; expected a finite number/,
    );
    expect(() => new FunctionKernel("sqrt" as FunctionOperation, {}, 3)).toThrow(
      /expected one of add, multiply, abs, power, clip/,
    );
    const abs = new FunctionKernel("abs", {}, 1);
    expect(() =>
      abs.processWithOperand(new Float64Array(1), new Float64Array(1), new Float64Array(1), 1),
    ).toThrow(/takes no operand/);
    const add = new FunctionKernel("add", { operand: [0] }, 3);
    expect(() =>
      add.processWithOperand(new Float64Array(3), new Float64Array(2), new Float64Array(3), 1),
    ).toThrow(/operand has 2 values; expected 3/);
  });
});

describe("EmgSynth", () => {
  const gen = (seed: number, events: number, targets = [1, 0.2, 0]): Float64Array => {
    const s = new EmgSynth({ channels: 3, sampleRate: 1000, seed });
    s.setTargets(targets);
    const out = new Float64Array(events * 3);
    s.generate(out, events);
    s.dispose();
    return out;
  };

  it("is deterministic per seed and differs between seeds (also above 2^32)", () => {
    expectSameBits(gen(5, 500), gen(5, 500), "same seed");
    const a = gen(0, 500);
    for (const other of [gen(1, 500), gen(2 ** 32, 500), gen(2 ** 53 - 1, 500)]) {
      let same = 0;
      for (let i = 0; i < a.length; i++) if (a[i] === other[i]) same++;
      expect(same).toBe(0);
    }
  });

  it("gives the same bits whatever the batch size, and repeats after reset()", () => {
    const runner = () => {
      const s = new EmgSynth({ channels: 3, sampleRate: 2000, seed: 11, modulation: 0.3 });
      s.setTargets([0.3, 1, 0.7]);
      return (_x: Float64Array, y: Float64Array, n: number) => s.generate(y, n);
    };
    const zeros = new Float64Array(3 * 700);
    const whole = runSplit(zeros, 3, [700], runner());
    expectSameBits(runSplit(zeros, 3, [1], runner()), whole, "1 by 1");
    expectSameBits(runSplit(zeros, 3, [100, 0, 3, 250], runner()), whole, "irregular");

    const s = new EmgSynth({ channels: 3, sampleRate: 2000, seed: 11, modulation: 0.3 });
    s.setTargets([0.3, 1, 0.7]);
    const a = new Float64Array(3 * 700);
    s.generate(a, 700);
    s.reset();
    const b = new Float64Array(3 * 700);
    s.generate(b, 700);
    expectSameBits(a, b, "after reset");
    expectSameBits(a, whole, "fresh instance");
  });

  it("reaches the configured RMS at full activation", () => {
    const fs = 2000;
    const s = new EmgSynth({ channels: 1, sampleRate: fs, seed: 3, amplitudeMv: 0.8 });
    s.setTargets([1]);
    const out = new Float64Array(fs * 2.5);
    s.generate(out, out.length);
    let sum = 0;
    for (let i = fs / 2; i < out.length; i++) sum += (out[i] as number) ** 2;
    const rms = Math.sqrt(sum / (out.length - fs / 2));
    expect(Math.abs(rms - 0.8)).toBeLessThan(0.08);
  });

  it("reports bad configuration and targets", () => {
    expect(() => new EmgSynth({ channels: 2, sampleRate: 1000, seed: 1, modulation: 2 })).toThrow(
      "modulation is 2; expected a number from 0 to 1",
    );
    expect(() => new EmgSynth({ channels: 2, sampleRate: -5, seed: 1 })).toThrow(
      /sample_rate is -5/,
    );
    expect(() => new EmgSynth({ channels: 2, sampleRate: 1000, seed: -1 })).toThrow(/seed/);
    expect(() => new EmgSynth({ channels: 2, sampleRate: 1000, seed: 0.5 })).toThrow(/seed/);
    const s = new EmgSynth({ channels: 2, sampleRate: 1000, seed: 1 });
    expect(() => s.setTargets([1])).toThrow(/expected 2/);
    expect(() => s.setTargets([1, NaN])).toThrow(/targets\[1\] is NaN/);
  });
});
