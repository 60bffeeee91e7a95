import fc from "fast-check";
import { describe, expect, test } from "vitest";
import { base64ToBytes, bytesToBase64, decodeWire, encodeWire } from "./protocol-wire";

describe("wire codec (UI protocol over WebSocket)", () => {
  test("base64 matches Node's Buffer for every length", () => {
    fc.assert(
      fc.property(fc.uint8Array({ maxLength: 64 }), (bytes) => {
        const b64 = bytesToBase64(bytes);
        expect(b64).toBe(Buffer.from(bytes).toString("base64"));
        expect(Array.from(base64ToBytes(b64))).toEqual(Array.from(bytes));
      }),
    );
    expect(() => base64ToBytes("A")).toThrow(/length/);
    expect(() => base64ToBytes("AB!=")).toThrow(/character/);
  });

  test("a data message keeps its Float64Arrays exactly (NaN, -0, subnormals, ±Infinity)", () => {
    const v = new Float64Array([1.5, NaN, -0, 5e-324, Infinity, -Infinity, Math.PI]);
    const msg = {
      type: "data",
      block: "B",
      port: "out",
      rows: 1,
      cols: 7,
      t: new Float64Array([1795459310.115]),
      v,
      skipped: 0,
    };
    const back = decodeWire(encodeWire(msg)) as typeof msg;
    expect(back.v).toBeInstanceOf(Float64Array);
    expect(Object.is(back.v[2], -0)).toBe(true);
    expect(Array.from(back.v)).toEqual(Array.from(v));
    expect(back.t[0]).toBe(1795459310.115);
    // A view into a larger buffer sends only its own elements.
    const big = new Float64Array([9, 8, 7, 6]);
    expect(
      Array.from((decodeWire(encodeWire({ v: big.subarray(1, 3) })) as { v: Float64Array }).v),
    ).toEqual([8, 7]);
  });

  test("non-finite numbers survive in ordinary fields (telemetry)", () => {
    const tel = {
      type: "telemetry",
      telemetry: { blocks: [{ r2: NaN, rate: Infinity, dt: -Infinity, ok: 1, none: null }] },
    };
    expect(decodeWire(encodeWire(tel))).toEqual(tel);
    // Objects that merely look like the markers but carry more keys are left alone.
    expect(decodeWire(encodeWire({ a: { $n: "NaN", x: 1 } }))).toEqual({ a: { $n: "NaN", x: 1 } });
  });
});
