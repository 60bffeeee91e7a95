/**
 * The Muovi/SyncStation wire formats: the CRC-8 against its catalogue check value and a
 * bit-by-bit reference, the start and stop commands byte for byte, and the stream parser across
 * every chunk size, after malformed bytes, over a counter that skips, and starting mid-sample.
 */
import { describe, expect, test } from "vitest";
import {
  crc8,
  MuoviStreamParser,
  probeCommand,
  slotOffsets,
  syncStationChannels,
  syncStationStart,
  syncStationStop,
} from "./muovi-protocol";

/** CRC-8 by polynomial long division of the bit-reversed message (x⁸ + x⁵ + x⁴ + 1). */
function crcReference(bytes: number[]): number {
  const bits: number[] = [];
  for (const b of bytes) for (let i = 0; i < 8; i++) bits.push((b >> i) & 1); // LSB first
  const poly = [1, 0, 0, 1, 1, 0, 0, 0, 1]; // x⁸ … x⁰ of 0x131
  const reg = [...bits, 0, 0, 0, 0, 0, 0, 0, 0];
  for (let i = 0; i < bits.length; i++) {
    if (reg[i]) for (let j = 0; j < 9; j++) reg[i + j] ^= poly[j]!;
  }
  // The remainder, read back reflected.
  let crc = 0;
  for (let j = 0; j < 8; j++) crc |= reg[bits.length + j]! << j;
  return crc;
}

describe("crc8", () => {
  test("is CRC-8/MAXIM: check value 0xA1 for '123456789', and equals long division", () => {
    expect(crc8([..."123456789"].map((c) => c.charCodeAt(0)))).toBe(0xa1);
    for (const msg of [[0], [3, 25], [9, 25, 41, 57, 73], [255, 1, 128, 7]]) {
      expect(crc8(msg)).toBe(crcReference(msg));
    }
    expect(crc8([0])).toBe(0);
    expect(crc8([1, 2, 3, 99], 3)).toBe(crc8([1, 2, 3]));
  });
});

describe("commands", () => {
  test("the SyncStation's start command: header, one byte per slot in slot order, CRC-8", () => {
    expect([...syncStationStart([0])]).toEqual([3, 9, crcReference([3, 9])]);
    // The original's example, Params [0, 1, 2]: slot·16 + EMG·8 + mode·2 + enable.
    expect([...syncStationStart([0, 1, 2])]).toEqual([7, 9, 25, 41, crcReference([7, 9, 25, 41])]);
    // Listed in any order, sent in slot order.
    expect([...syncStationStart([3, 1])]).toEqual([5, 25, 57, crcReference([5, 25, 57])]);
    expect(() => syncStationStart([4])).toThrow(/slot 4 is not a Muovi slot \(0…3\)/);
  });

  test("stop commands: the SyncStation's [0, 0]; the probe's byte 8 (start: 9)", () => {
    expect([...syncStationStop()]).toEqual([0, 0]);
    expect(probeCommand(true)).toBe(9);
    expect(probeCommand(false)).toBe(8);
  });

  test("the layout: 38 channels per probe then 6; listed slots map to their place on the wire", () => {
    expect(syncStationChannels(1)).toBe(44);
    expect(syncStationChannels(4)).toBe(158);
    expect(slotOffsets([2, 0, 3])).toEqual([38, 0, 76]);
  });
});

/** n samples of `ch` int16 big-endian channels, channel c of sample k = k·10 + c, counter last. */
function stream(k0: number, n: number, ch: number): Uint8Array {
  const b = new Uint8Array(n * ch * 2);
  const v = new DataView(b.buffer);
  for (let i = 0; i < n; i++) {
    const k = k0 + i;
    for (let c = 0; c < ch - 1; c++) v.setInt16((i * ch + c) * 2, ((k * 10 + c) % 60000) - 30000);
    v.setInt16((i * ch + ch - 1) * 2, ((k & 0xffff) << 16) >> 16);
  }
  return b;
}

function collect(ch: number) {
  const got: number[] = [];
  const p = new MuoviStreamParser(ch, (raw) => got.push(raw[ch - 1]! & 0xffff));
  return { p, got };
}

describe("MuoviStreamParser", () => {
  test("every chunk size gives every sample, values exact, across the counter's wrap", () => {
    const ch = 44;
    const bytes = stream(65500, 100, ch);
    for (let size = 1; size <= ch * 2 + 5; size++) {
      const values: number[][] = [];
      const p = new MuoviStreamParser(ch, (raw) => values.push([...raw]));
      for (let at = 0; at < bytes.length; at += size) p.feed(bytes.subarray(at, at + size));
      expect(values.length, `chunks of ${size}`).toBe(100);
      expect(values[37]![5]).toBe(((65537 * 10 + 5) % 60000) - 30000);
      expect(values.map((v) => v[ch - 1]! & 0xffff)).toEqual(
        Array.from({ length: 100 }, (_, i) => (65500 + i) & 0xffff),
      );
      expect([p.malformed, p.skippedBytes, p.lostSamples, p.held]).toEqual([0, 0, 0, 0]);
    }
  });

  test("malformed bytes between samples: one episode, exactly those bytes skipped, no sample lost", () => {
    const ch = 38;
    const { p, got } = collect(ch);
    p.feed(stream(0, 10, ch));
    p.feed(Uint8Array.of(1, 2, 3, 4, 5, 6, 7));
    p.feed(stream(10, 10, ch));
    expect(got).toEqual(Array.from({ length: 20 }, (_, i) => i));
    expect(p.malformed).toBe(1);
    expect(p.skippedBytes).toBe(7);
    expect(p.lostSamples).toBe(0);
    expect(p.lastProblem).toMatch(
      /sample counter \d+ where 10 was due and no count follows: misaligned/,
    );
  });

  test("a counter that jumps and counts on is samples the device skipped, not misalignment", () => {
    const { p, got } = collect(44);
    p.feed(stream(0, 5, 44));
    p.feed(stream(105, 5, 44));
    expect(got).toEqual([0, 1, 2, 3, 4, 105, 106, 107, 108, 109]);
    expect([p.lostSamples, p.malformed, p.skippedBytes]).toEqual([100, 0, 0]);
  });

  test("a counter that restarts (back, or further than 2000 ahead) and counts on is a restart, not misalignment", () => {
    const { p, got } = collect(44);
    p.feed(stream(0, 5, 44));
    p.feed(stream(0, 5, 44));
    p.feed(stream(30000, 5, 44));
    expect(got).toEqual([0, 1, 2, 3, 4, 0, 1, 2, 3, 4, 30000, 30001, 30002, 30003, 30004]);
    expect([p.counterJumps, p.lostSamples, p.malformed, p.skippedBytes]).toEqual([2, 0, 0, 0]);
  });

  test("a stream starting inside a sample locks onto the first whole one; reset returns what was held", () => {
    const { p, got } = collect(44);
    const s = stream(7, 10, 44);
    p.feed(s.subarray(31));
    expect(got[0]).toBe(8);
    expect(got).toHaveLength(9);
    expect(p.skippedBytes).toBe(88 - 31);
    expect(p.malformed).toBe(1);
    p.feed(stream(17, 1, 44).subarray(0, 50));
    expect(p.reset()).toBe(50);
    expect(p.held).toBe(0);
  });

  test("seeded fuzz: junk of 1–60 bytes at random sample boundaries, random chunks: every sample, junk counted exactly", () => {
    let seed = 12345;
    const rnd = (n: number): number => {
      seed = (Math.imul(seed, 1103515245) + 12345) >>> 0;
      return (seed >>> 8) % n;
    };
    for (let round = 0; round < 40; round++) {
      const ch = 38 + 6 * rnd(3);
      const parts: Uint8Array[] = [];
      let junkBytes = 0;
      let junks = 0;
      for (let k = 0; k < 300; k += 10) {
        parts.push(stream(k, 10, ch));
        if (k + 10 < 300 && rnd(3) === 0) {
          const junk = Uint8Array.from({ length: 1 + rnd(60) }, () => rnd(256));
          parts.push(junk);
          junkBytes += junk.length;
          junks++;
        }
      }
      const all = new Uint8Array(parts.reduce((a, p) => a + p.length, 0));
      parts.reduce((at, p) => (all.set(p, at), at + p.length), 0);
      const { p, got } = collect(ch);
      for (let at = 0; at < all.length;) {
        const n = 1 + rnd(300);
        p.feed(all.subarray(at, at + n));
        at += n;
      }
      expect(got, `round ${round}`).toEqual(Array.from({ length: 300 }, (_, i) => i));
      expect([p.malformed, p.skippedBytes, p.lostSamples], `round ${round}`).toEqual([
        junks,
        junkBytes,
        0,
      ]);
    }
  });

  test("bytes that never count (no Muovi there) are skipped and counted, nothing emitted", () => {
    const { p, got } = collect(38);
    const junk = Uint8Array.from({ length: 5000 }, (_, i) => (i * 7919) & 255);
    p.feed(junk);
    expect(got).toEqual([]);
    expect(p.skippedBytes).toBe(5000 - (3 * 76 - 1));
    expect(p.malformed).toBe(1);
    expect(p.lastProblem).toMatch(/no sample counter/);
    expect(() => new MuoviStreamParser(1, () => {})).toThrow(/at least 2 channels/);
  });
});
