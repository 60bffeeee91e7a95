import { describe, expect, test } from "vitest";
import {
  DeviceClock,
  hzText,
  TRIGNO_NATIVE_RATE,
  TRIGNO_SAMPLE_BYTES,
  TrignoEmgParser,
} from "./delsys-protocol";

/** Samples as the TCU sends them: 16 float32 LE each. */
function wire(samples: number[][]): Uint8Array {
  const b = new Uint8Array(samples.length * TRIGNO_SAMPLE_BYTES);
  const dv = new DataView(b.buffer);
  samples.forEach((s, i) => s.forEach((v, j) => dv.setFloat32(i * 64 + 4 * j, v, true)));
  return b;
}

/** Sample i: sensors 1…8 carry small distinct values, 9…16 are unpaired (0). */
const sample = (i: number): number[] =>
  Array.from({ length: 16 }, (_, j) => (j < 8 ? Math.fround(1e-4 * Math.sin(i + j) + 1e-6) : 0));

function parse(chunks: Uint8Array[], unpaired: number[] = [9, 10, 11, 12, 13, 14, 15, 16]) {
  const got: number[][] = [];
  const p = new TrignoEmgParser((v) => got.push(Array.from(v)));
  p.setUnpaired(unpaired);
  for (const c of chunks) p.feed(c);
  return { got, p };
}

const concat = (...parts: Uint8Array[]): Uint8Array => {
  const out = new Uint8Array(parts.reduce((n, p) => n + p.length, 0));
  let at = 0;
  for (const p of parts) {
    out.set(p, at);
    at += p.length;
  }
  return out;
};

describe("TrignoEmgParser", () => {
  const samples = Array.from({ length: 20 }, (_, i) => sample(i));
  const bytes = wire(samples);

  test("samples come out whole and exact whatever the chunking", () => {
    for (const size of [1, 7, 63, 64, 65, 1000]) {
      const chunks: Uint8Array[] = [];
      for (let at = 0; at < bytes.length; at += size) chunks.push(bytes.subarray(at, at + size));
      const { got, p } = parse(chunks);
      expect(got).toEqual(samples);
      expect(p.malformed).toBe(0);
      expect(p.pending).toBe(0);
    }
  });

  test("stray bytes between samples: one malformed count, the stray bytes skipped, no sample lost", () => {
    const { got, p } = parse([
      concat(bytes.subarray(0, 5 * 64), new Uint8Array([1, 2, 3]), bytes.subarray(5 * 64)),
    ]);
    expect(got).toEqual(samples);
    expect(p.malformed).toBe(1);
    expect(p.skippedBytes).toBe(3);
  });

  test("a sample of NaNs is skipped whole; values beyond ±0.1 V and non-zero unpaired slots are refused", () => {
    const nan = new Uint8Array(64).fill(0xff);
    const a = parse([concat(bytes.subarray(0, 128), nan, bytes.subarray(128))]);
    expect(a.got).toEqual(samples);
    expect([a.p.malformed, a.p.skippedBytes, a.p.lastProblem]).toEqual([1, 64, "sensor 1: NaN"]);
    const big = wire([[...sample(0).slice(0, 15), 0]]);
    new DataView(big.buffer).setFloat32(4, 0.5, true);
    const b = parse([concat(big, bytes)]);
    expect(b.p.lastProblem).toBe("sensor 2: 0.500 V");
    expect(b.got).toEqual(samples);
    const c = parse([
      concat(wire([[...sample(0).slice(0, 8), 0.001, ...Array(7).fill(0)]]), bytes),
    ]);
    expect(c.p.lastProblem).toBe("unpaired sensor 9: 0.00100 V");
    expect(c.got).toEqual(samples);
  });

  test("a misaligned tail waits for more bytes; reset drops what is held", () => {
    const { got, p } = parse([bytes.subarray(0, 64 * 3 + 10)]);
    expect(got).toHaveLength(3);
    expect(p.pending).toBe(10);
    expect(p.reset()).toBe(10);
    expect(p.pending).toBe(0);
  });

  test("garbage for longer than the search window is skipped, and the stream found again", () => {
    const junk = new Uint8Array(64 * 40).fill(0x7f); // 3.39e38: beyond any sensor's range
    const { got, p } = parse([concat(junk, bytes)]);
    expect(got).toEqual(samples);
    expect(p.malformed).toBe(1);
    expect(p.skippedBytes).toBe(junk.length);
  });
});

describe("DeviceClock", () => {
  const period = 1 / TRIGNO_NATIVE_RATE;

  test("26 samples per batch: stamps 1 / rate apart, the first batch ending at its arrival", () => {
    const c = new DeviceClock(TRIGNO_NATIVE_RATE);
    const t = new Float64Array(26);
    c.stamp(100, t, 26);
    expect(t[25]).toBe(100);
    expect(t[1]! - t[0]!).toBeCloseTo(period, 12);
    const next = new Float64Array(26);
    c.stamp(100.0142, next, 26); // a little late: stamps keep the device's pace
    expect(next[0]! - t[25]!).toBeCloseTo(period, 12);
    expect(c.reanchors).toBe(0);
  });

  test("a batch far ahead is pulled back; a stall re-anchors; a reconnection counts its gap", () => {
    const c = new DeviceClock(TRIGNO_NATIVE_RATE);
    const t = new Float64Array(26);
    c.stamp(100, t, 26);
    c.stamp(100.0001, t, 26); // 13.4 ms ahead of arrival: within a frame, the pace is kept
    expect(t[0]!).toBeCloseTo(100 + period, 12);
    c.stamp(100.0002, t, 26); // would be 27 ms ahead: pulled back, no earlier than the last stamp
    expect(t[0]!).toBeCloseTo(100 + 26 * period, 9);
    expect(c.reanchors).toBe(0);
    c.stamp(102, t, 26); // 2 s of nothing, then a batch: re-anchored
    expect(t[25]).toBe(102);
    expect(c.reanchors).toBe(1);
    c.restart();
    c.stamp(103, t, 26);
    expect(t[25]).toBe(103);
    expect(c.gaps).toBe(1);
    expect(c.gapSeconds).toBeCloseTo(1 - 26 * period, 9);
    expect(c.gapSamples).toBe(Math.round((1 - 26 * period) * TRIGNO_NATIVE_RATE));
  });

  test("rates are written as the TCU's", () => {
    expect(hzText(TRIGNO_NATIVE_RATE)).toBe("1925.926 Hz");
    expect(hzText(2000)).toBe("2000.000 Hz");
  });
});
