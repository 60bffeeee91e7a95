import fc from "fast-check";
import { describe, expect, test } from "vitest";
import {
  counterGap,
  decodeRaw,
  decodeStreamlined,
  newHeader,
  RawEncoder,
  StreamlinedEncoder,
  streamlinedLength,
  typeByte,
  typeFromByte,
  VALUE_TYPES,
  type ValueType,
} from "./udp-format";

const hex = (b: Uint8Array): string => Buffer.from(b).toString("hex");
const bytes = (h: string): Uint8Array => new Uint8Array(Buffer.from(h.replace(/\s+/g, ""), "hex"));

describe("type byte (0x20 float flag, 0x10 signed flag, + element size)", () => {
  test("every value type", () => {
    const table = Object.fromEntries(VALUE_TYPES.map((t) => [t, typeByte(t)]));
    expect(table).toEqual({
      f64: 0x28,
      f32: 0x24,
      i8: 0x11,
      i16: 0x12,
      i32: 0x14,
      i64: 0x18,
      u8: 0x01,
      u16: 0x02,
      u32: 0x04,
      u64: 0x08,
    });
    for (const t of VALUE_TYPES) expect(typeFromByte(typeByte(t))).toBe(t);
    for (const b of [0x00, 0x03, 0x21, 0x22, 0x30, 0x38, 0x2c, 0xff]) {
      expect(typeFromByte(b)).toBeUndefined();
    }
  });
});

describe("streamlined encoder", () => {
  test("the exact bytes: | count | type | category | subcategory | f64 t | values | u16 counter |", () => {
    const enc = new StreamlinedEncoder(2, "f64");
    const d = enc.encode(1.5, 1, 3, [1, -2], 0);
    expect(hex(d)).toBe(
      "02" + // count
        "28" + // f64
        "01" + // category
        "03" + // subcategory
        "000000000000f83f" + // 1.5
        "000000000000f03f" + // 1
        "00000000000000c0" + // -2
        "0000", // counter 0
    );
    expect(d.length).toBe(streamlinedLength(2, "f64"));
    expect(hex(enc.encode(1.5, 1, 3, [1, -2], 0).subarray(28))).toBe("0100");
  });

  test("i16 values little-endian, from an offset, scaled", () => {
    const enc = new StreamlinedEncoder(2, "i16");
    const d = enc.encode(0, 0, 0, [9, 9, 1, -1], 2, 1000);
    expect(hex(d)).toBe("0212" + "0000" + "0000000000000000" + "e803" + "18fc" + "0000");
  });

  test("the counter wraps from 65535 to 0", () => {
    const enc = new StreamlinedEncoder(1, "u8");
    enc.counter = 65534;
    const counters = [0, 1, 2].map(() => hex(enc.encode(0, 0, 0, [1], 0).subarray(13)));
    expect(counters).toEqual(["feff", "ffff", "0000"]);
  });

  test("integers round and saturate; NaN sends 0 (MOSAIC's myo cast wrapped 1.0·128 to −128)", () => {
    const enc = new StreamlinedEncoder(6, "i8");
    const d = enc.encode(0, 1, 1, [1, -1, 0.5, NaN, 2, -0.004], 0, 128);
    expect(Array.from(new Int8Array(d.buffer, 12, 6))).toEqual([127, -128, 64, 0, 127, -1]);
    const u = new StreamlinedEncoder(3, "u16").encode(0, 0, 0, [-5, 70000, 2.5], 0);
    expect(hex(u.subarray(12, 18))).toBe("0000" + "ffff" + "0300");
  });

  test("count is one byte", () => {
    expect(() => new StreamlinedEncoder(256, "f64")).toThrow(/0 to 255/);
  });
});

describe("streamlined decoder", () => {
  test("round trip of every value type", () => {
    const values = [0, 1, -1, 100, -100, 127];
    for (const t of VALUE_TYPES) {
      const signed = !t.startsWith("u");
      const v = signed ? values : values.map(Math.abs);
      const enc = new StreamlinedEncoder(v.length, t);
      enc.counter = 7;
      const d = enc.encode(1700000000.123456, 2, 5, v, 0);
      const h = newHeader();
      const out = new Float64Array(255);
      expect(decodeStreamlined(d, h, out, 0, 255)).toBeUndefined();
      expect(h).toEqual({
        count: v.length,
        type: t,
        category: 2,
        subcategory: 5,
        timestamp: 1700000000.123456,
        counter: 7,
      });
      expect(Array.from(out.subarray(0, v.length)), t).toEqual(v);
    }
  });

  test("f32 values come back as the nearest f32", () => {
    const d = new StreamlinedEncoder(2, "f32").encode(0, 0, 0, [0.1, -1e-3], 0);
    const out = new Float64Array(2);
    expect(decodeStreamlined(d, newHeader(), out, 0, 2)).toBeUndefined();
    expect(Array.from(out)).toEqual([Math.fround(0.1), Math.fround(-1e-3)]);
  });

  test("a datagram written by hand (as MOSAIC's C# BitConverter writes it)", () => {
    // count 1, double, category 1, subcategory 8 (WristPronationSupination), t = 2.0, 0.25, counter 258
    const d = bytes("01 28 01 08 0000000000000040 000000000000d03f 0201");
    const h = newHeader();
    const out = new Float64Array(1);
    expect(decodeStreamlined(d, h, out, 0, 1)).toBeUndefined();
    expect(h).toMatchObject({ count: 1, type: "f64", category: 1, subcategory: 8, timestamp: 2 });
    expect(h.counter).toBe(258);
    expect(out[0]).toBe(0.25);
  });

  test("malformed datagrams are refused with a reason, never thrown", () => {
    const good = new StreamlinedEncoder(3, "f32").encode(1, 0, 0, [1, 2, 3], 0).slice();
    const out = new Float64Array(255);
    const h = newHeader();
    const refuse = (d: Uint8Array, max = 255) => decodeStreamlined(d, h, out, 0, max);
    expect(refuse(new Uint8Array(0))).toMatch(/0 bytes is shorter than the 14-byte header/);
    expect(refuse(good.subarray(0, 13))).toMatch(/shorter/);
    expect(refuse(good.subarray(0, good.length - 1))).toMatch(
      /3 values of f32 need 26 bytes, got 25/,
    );
    expect(refuse(new Uint8Array([...good, 0]))).toMatch(/need 26 bytes, got 27/);
    const badType = good.slice();
    badType[1] = 0x23;
    expect(refuse(badType)).toMatch(/unknown type byte 0x23/);
    const badCount = good.slice();
    badCount[0] = 4;
    expect(refuse(badCount)).toMatch(/4 values of f32 need 30 bytes, got 26/);
    expect(refuse(good, 2)).toMatch(/3 values, more than the 2 expected/);
    expect(refuse(good)).toBeUndefined();
  });

  test("random bytes never throw", () => {
    const out = new Float64Array(255);
    const h = newHeader();
    fc.assert(
      fc.property(fc.uint8Array({ maxLength: 600 }), (d) => {
        const r = decodeStreamlined(d, h, out, 0, 255);
        expect(r === undefined || typeof r === "string").toBe(true);
      }),
      { numRuns: 2000, seed: 6 },
    );
  });
});

describe("raw vectors", () => {
  test("f64 and f32, several vectors in one datagram", () => {
    const e64 = new RawEncoder(2, "f64");
    expect(hex(e64.encode([0, 1, -2], 1))).toBe("000000000000f03f" + "00000000000000c0");
    const two = new Uint8Array([...e64.encode([1, 2], 0), ...e64.encode([3, 4], 0)]);
    const out = new Float64Array(8);
    expect(decodeRaw(two, "f64", 2, out, 4)).toBe(2);
    expect(Array.from(out.subarray(0, 4))).toEqual([1, 2, 3, 4]);
    const e32 = new RawEncoder(3, "f32");
    expect(decodeRaw(e32.encode([0.5, -1, 1e-7], 0), "f32", 3, out, 2, 2)).toBe(1);
    expect(Array.from(out.subarray(0, 3))).toEqual([1, -2, 2 * Math.fround(1e-7)]);
  });

  test("malformed: empty, not whole vectors, too many", () => {
    const out = new Float64Array(4);
    expect(decodeRaw(new Uint8Array(0), "f64", 2, out, 2)).toMatch(/0 bytes is not a whole number/);
    expect(decodeRaw(new Uint8Array(12), "f64", 2, out, 2)).toMatch(
      /12 bytes is not a whole number of 2-value f64 vectors \(16 bytes each\)/,
    );
    expect(decodeRaw(new Uint8Array(48), "f64", 2, out, 2)).toMatch(/3 vectors in one datagram/);
  });
});

test("counter gaps, wrapping at 65536", () => {
  expect(counterGap(10, 11)).toBe(0);
  expect(counterGap(10, 13)).toBe(2);
  expect(counterGap(65535, 0)).toBe(0);
  expect(counterGap(65534, 1)).toBe(2);
  expect(counterGap(10, 10)).toBe(-1); // a repeat
  expect(counterGap(10, 5)).toBe(-6); // late
});

test("types list", () => {
  const types: ValueType[] = ["f64", "f32", "i8", "i16", "i32", "i64", "u8", "u16", "u32", "u64"];
  expect([...VALUE_TYPES].sort()).toEqual([...types].sort());
});
