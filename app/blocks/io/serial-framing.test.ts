import { describe, expect, test } from "vitest";
import {
  checksumOf,
  lineDecoder,
  lineEncoder,
  structDecoder,
  structEncoder,
  structSize,
  type StructOptions,
} from "./serial-framing";

const ascii = (s: string): Uint8Array => Uint8Array.from(s, (c) => c.charCodeAt(0));

function decodeAll(d: ReturnType<typeof lineDecoder>, chunks: Uint8Array[]): number[][] {
  const got: number[][] = [];
  for (const c of chunks) d.push(c, (v) => got.push(Array.from(v)));
  return got;
}

describe("line framing", () => {
  test("numbers separated by commas, semicolons, tabs or spaces; CRLF; split anywhere", () => {
    const text = "1,2,3\r\n4;5;6\n7\t8\t9\n  -1.5  2e3 0.1 \n\n";
    const whole = decodeAll(lineDecoder({ channels: 3 }), [ascii(text)]);
    expect(whole).toEqual([
      [1, 2, 3],
      [4, 5, 6],
      [7, 8, 9],
      [-1.5, 2000, 0.1],
    ]);
    // Byte by byte gives the same frames.
    const bytes = ascii(text);
    const split = decodeAll(
      lineDecoder({ channels: 3 }),
      Array.from(bytes, (_, i) => bytes.subarray(i, i + 1)),
    );
    expect(split).toEqual(whole);
  });

  test("malformed lines are counted with the reason, never thrown, and the next line decodes", () => {
    const d = lineDecoder({ channels: 2 });
    const got = decodeAll(d, [ascii("1,2\n1,2,3\nx,1\n1,\n3,4\n")]);
    expect(got).toEqual([
      [1, 2],
      [3, 4],
    ]);
    expect(d.stats).toMatchObject({ frames: 2, malformed: 3 });
    expect(d.stats.lastProblem).toBe('"" is not a number in the line "1,"');
  });

  test("an over-long line is dropped as one malformed line", () => {
    const d = lineDecoder({ channels: 1, maxLineBytes: 8 });
    const got = decodeAll(d, [ascii("1234"), ascii("56789012"), ascii("345\n7\n")]);
    expect(got).toEqual([[7]]);
    expect(d.stats.malformed).toBe(1);
    expect(d.stats.lastProblem).toMatch(/longer than 8 bytes/);
  });

  test("the encoder writes what the decoder reads back exactly", () => {
    const values = [0.1, -2.5e-7, 123456789.125, 3];
    const bytes = lineEncoder().encode(values);
    expect(String.fromCharCode(...bytes)).toBe("0.1,-2.5e-7,123456789.125,3\n");
    expect(decodeAll(lineDecoder({ channels: 4 }), [bytes])).toEqual([values]);
  });
});

describe("binary framing", () => {
  const o: StructOptions = {
    fields: ["i16", "f32", "u16"],
    sync: [0xaa, 0x55],
    checksum: "crc16",
    littleEndian: true,
  };

  test("checksums: CRC-16/CCITT-FALSE check value, xor8, sum8", () => {
    // The standard check input "123456789" gives 0x29B1 for CRC-16/CCITT-FALSE.
    expect(checksumOf("crc16", ascii("123456789"))).toBe(0x29b1);
    expect(checksumOf("xor8", Uint8Array.of(0x01, 0x02, 0x04))).toBe(0x07);
    expect(checksumOf("sum8", Uint8Array.of(0xff, 0x02))).toBe(0x01);
  });

  test("a frame laid out by hand (as Python's struct.pack('<hfH')) decodes", () => {
    const payload = new Uint8Array(8);
    const view = new DataView(payload.buffer);
    view.setInt16(0, -50, true);
    view.setFloat32(2, 1.25, true);
    view.setUint16(6, 700, true);
    const cs = checksumOf("crc16", payload);
    const frame = Uint8Array.of(0xaa, 0x55, ...payload, cs & 0xff, cs >> 8);
    expect(structSize(o)).toBe(12);
    expect(structEncoder(o).encode([-50, 1.25, 700])).toEqual(frame);
    const got: number[][] = [];
    structDecoder(o).push(frame, (v) => got.push(Array.from(v)));
    expect(got).toEqual([[-50, 1.25, 700]]);
  });

  test("garbage, a torn frame and a bad checksum cost only themselves; split anywhere", () => {
    const enc = structEncoder(o);
    const good = (k: number) => enc.encode([k, k / 4, k * 3]);
    const bad = good(99);
    bad[bad.length - 1]! ^= 0xff;
    const stream = Uint8Array.from([
      0x00,
      0x13,
      ...good(1),
      ...good(2).subarray(0, 5), // torn: the rest never came
      ...good(3),
      ...bad,
      ...good(4),
    ]);
    for (const step of [stream.length, 1, 5, 7]) {
      const d = structDecoder(o);
      const got: number[][] = [];
      for (let i = 0; i < stream.length; i += step) {
        d.push(stream.subarray(i, i + step), (v) => got.push(Array.from(v)));
      }
      expect(got).toEqual([
        [1, 0.25, 3],
        [3, 0.75, 9],
        [4, 1, 12],
      ]);
      expect(d.stats.frames).toBe(3);
      expect(d.stats.malformed).toBeGreaterThanOrEqual(1);
    }
  });

  test("big endian, every field type, no sync and no checksum; integers clamp when encoding", () => {
    const all: StructOptions = {
      fields: ["i8", "u8", "i16", "u16", "i32", "u32", "f32", "f64"],
      sync: [],
      checksum: "none",
      littleEndian: false,
    };
    const enc = structEncoder(all);
    const bytes = enc.encode([-1, 300, -40000, 1.6, -5, 7, 0.5, Math.PI]);
    expect(bytes.length).toBe(1 + 1 + 2 + 2 + 4 + 4 + 4 + 8);
    expect(bytes[1]).toBe(255);
    expect([bytes[4], bytes[5]]).toEqual([0, 2]); // u16 2, big endian
    const got: number[][] = [];
    structDecoder(all).push(bytes, (v) => got.push(Array.from(v)));
    expect(got).toEqual([[-1, 255, -32768, 2, -5, 7, 0.5, Math.PI]]);
  });
});
