import { describe, expect, test } from "vitest";
import { decodeNilsPod, NilsPodCounter, nilsPodScales } from "./nilspod-protocol";

describe("NilsPod protocol", () => {
  test("a notification of two samples: int16 little-endian, gyroscope first on the wire, scaled", () => {
    const bytes = new Uint8Array(28);
    const dv = new DataView(bytes.buffer);
    [32767, -32768, 1, 2048, -2048, 0].forEach((v, i) => dv.setInt16(2 * i, v, true));
    dv.setUint16(12, 0xfffe, true);
    [-1, 0, 16384, 1, -1, 32767].forEach((v, i) => dv.setInt16(14 + 2 * i, v, true));
    dv.setUint16(26, 0xffff, true);
    const got: [number[], number][] = [];
    const err = decodeNilsPod(bytes, nilsPodScales(), new Float64Array(6), (v, c) =>
      got.push([Array.from(v), c]),
    );
    expect(err).toBeUndefined();
    expect(got).toEqual([
      [[9.81, -9.81, 0, (32767 * 2000) / 32768, -2000, 2000 / 32768], 0xfffe],
      [[9.81 / 2048, -9.81 / 2048, (32767 * 9.81) / 2048, -2000 / 32768, 0, 1000], 0xffff],
    ]);
    // ±2 g and ±125 deg/s: the same raw values, another scale.
    const small: number[][] = [];
    decodeNilsPod(bytes.subarray(0, 14), nilsPodScales(2, 125), new Float64Array(6), (v) =>
      small.push(Array.from(v)),
    );
    expect(small[0]).toEqual([
      (2048 * 2 * 9.81) / 32768,
      (-2048 * 2 * 9.81) / 32768,
      0,
      (32767 * 125) / 32768,
      -125,
      125 / 32768,
    ]);
  });

  test("anything but whole 14-byte samples is refused whole", () => {
    for (const n of [0, 1, 13, 15, 27]) {
      let samples = 0;
      const err = decodeNilsPod(
        new Uint8Array(n),
        nilsPodScales(),
        new Float64Array(6),
        () => samples++,
      );
      expect(err).toBe(`${n} bytes, not a whole number of 14-byte samples`);
      expect(samples).toBe(0);
    }
  });

  test("the counter: gaps are lost samples, it wraps at 2^16, a step back is a restart", () => {
    const c = new NilsPodCounter();
    expect([65533, 65534, 65535, 0, 1].map((x) => c.next(x))).toEqual([0, 0, 0, 0, 0]);
    expect(c.next(5)).toBe(3);
    expect(c.next(65530)).toBe(0); // backwards
    expect(c.next(65530)).toBe(0); // repeated
    expect(c.next(3)).toBe(8); // 65531 … 2 lost, across the wrap
    expect([c.lost, c.restarts]).toEqual([11, 2]);
    c.resync();
    expect(c.next(1000)).toBe(0);
  });
});
