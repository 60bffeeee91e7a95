/**
 * The Quattrocento's wire format: the 40-byte command bit by bit against the configuration
 * protocol's layout (docs/protocols.md), the CRC-8 against a public reader's command; the
 * parser over every chunk size, across the counter's wrap, after stray bytes, over a counter
 * that skips or restarts, and on data that never counts.
 */
import { describe, expect, test } from "vitest";
import { crc8 } from "./muovi-protocol";
import {
  acqSettByte,
  connectorOffset,
  DEFAULT_INPUT,
  inputBytes,
  nchFor,
  quattrocentoCommand,
  QuattrocentoStreamParser,
  type QuattrocentoConfig,
} from "./quattrocento-protocol";

const config = (o: Partial<QuattrocentoConfig> = {}): QuattrocentoConfig => ({
  rate: 2048,
  nch: 3,
  decimator: true,
  recording: false,
  analogOut: { source: "MULTIPLE IN2", channel: 0, gain: 1 },
  inputs: Array.from({ length: 12 }, () => DEFAULT_INPUT),
  ...o,
});

describe("the configuration command", () => {
  test("OTB's example's command, byte for byte, with the CRC a public reader sends", () => {
    // Read_Quattrocento.m: Decim 64, 2048 Hz (8), 408 channels (6), ACQ on; AN_OUT 9, 0; every
    // input 0, 0, 0b00010100. paubuyreu27/Python_Quattrocento_RealSense_Picoscope sends these 39
    // bytes with CRC 5.
    const want = [207, 9, 0];
    for (let i = 0; i < 12; i++) want.push(0, 0, 0b00010100);
    want.push(5);
    expect([...quattrocentoCommand(config(), true)]).toEqual(want);
    // Stop: ACQ_SETT 0b10000000, the rest as before, its CRC.
    const stop = [...quattrocentoCommand(config(), false)];
    expect(stop.slice(0, 39)).toEqual([0x80, ...want.slice(1, 39)]);
    expect(stop[39]).toBe(crc8(stop, 39));
  });

  test("ACQ_SETT: 1, DECIM, REC_ON, FSAMP<1:0>, NCH<1:0>, ACQ_ON", () => {
    const rates = [512, 2048, 5120, 10240] as const;
    rates.forEach((rate, f) => {
      for (let nch = 0; nch < 4; nch++) {
        for (const decimator of [false, true]) {
          for (const recording of [false, true]) {
            const c = config({ rate, nch, decimator, recording });
            const want = 0x80 + (decimator ? 64 : 0) + (recording ? 32 : 0) + f * 8 + nch * 2 + 1;
            expect(acqSettByte(c, true)).toBe(want);
            expect(acqSettByte(c, false)).toBe(want - 1);
          }
        }
      }
    });
  });

  test("AN_OUT and the per-input bytes", () => {
    const cmd = quattrocentoCommand(
      config({
        analogOut: { source: "AUX IN", channel: 63, gain: 16 },
        inputs: Array.from({ length: 12 }, (_, i) => ({
          muscle: 64 - i,
          sensor: 23 - i,
          adapter: i % 7,
          side: (["undefined", "left", "right", "none"] as const)[i % 4],
          highPass: ([0.7, 10, 100, 200] as const)[i % 4],
          lowPass: ([130, 500, 900, 4400] as const)[(i + 1) % 4],
          mode: (["monopolar", "differential", "bipolar"] as const)[i % 3],
        })),
      }),
      true,
    );
    expect(cmd[1]).toBe(0b0011_1100); // gain 16 (11), AUX IN (1100)
    expect(cmd[2]).toBe(63);
    for (let i = 0; i < 12; i++) {
      expect(cmd[3 + 3 * i]).toBe(64 - i);
      expect(cmd[4 + 3 * i]).toBe(((23 - i) << 3) | (i % 7));
      expect(cmd[5 + 3 * i]).toBe(((i % 4) << 6) | ((i % 4) << 4) | (((i + 1) % 4) << 2) | (i % 3));
    }
    expect(inputBytes({ ...DEFAULT_INPUT, side: "right", mode: "bipolar" })).toEqual([
      0, 0, 0b10_01_01_10,
    ]);
    expect(cmd[39]).toBe(crc8(cmd, 39));
  });

  test("a bad NCH code is refused", () => {
    expect(() => quattrocentoCommand(config({ nch: 4 }), true)).toThrow(/NCH code 4 is not 0…3/);
  });

  test("which channels each NCH carries, and where", () => {
    expect(nchFor(["IN1", "IN2", "MULTIPLE IN1", "AUX IN"])).toBe(0);
    expect(nchFor(["IN3"])).toBe(1);
    expect(nchFor(["MULTIPLE IN3"])).toBe(2);
    expect(nchFor(["IN8", "MULTIPLE IN1"])).toBe(3);
    // NCH 0 (120): IN1, IN2 (32), MULTIPLE IN1 (64), AUX (16), accessory (8).
    expect(connectorOffset("IN2", 0)).toBe(16);
    expect(connectorOffset("IN3", 0)).toBe(-1);
    expect(connectorOffset("MULTIPLE IN1", 0)).toBe(32);
    expect(connectorOffset("AUX IN", 0)).toBe(96);
    // NCH 3 (408): 8 INs (128), 4 MULTIPLE INs (256), AUX at 384.
    expect(connectorOffset("MULTIPLE IN4", 3)).toBe(128 + 192);
    expect(connectorOffset("AUX IN", 3)).toBe(384);
  });
});

/** n samples of `channels` int16 LE from counter c0: value(ch, k), the counter at channels − 8. */
function stream(channels: number, c0: number, n: number, skipAt = -1, skip = 0): Uint8Array {
  const b = Buffer.alloc(n * channels * 2);
  for (let k = 0; k < n; k++) {
    const count = (c0 + k + (skipAt >= 0 && k >= skipAt ? skip : 0)) & 0xffff;
    for (let ch = 0; ch < channels; ch++) {
      const v = ch === channels - 8 ? count : ch === channels - 5 ? 20000 : value(ch, k);
      b.writeUInt16LE(v & 0xffff, 2 * (k * channels + ch));
    }
  }
  return new Uint8Array(b);
}
const value = (ch: number, k: number): number => (((ch * 7919 + k * 104729) % 65536) - 32768) | 0;

function parse(channels: number, chunks: Uint8Array[]) {
  const rows: number[][] = [];
  const p = new QuattrocentoStreamParser(channels, (raw) => rows.push([...raw]));
  for (const c of chunks) p.feed(c);
  return { p, rows };
}

/** The bytes in pieces of `size`. */
const pieces = (b: Uint8Array, size: number): Uint8Array[] =>
  Array.from({ length: Math.ceil(b.length / size) }, (_, i) =>
    b.subarray(i * size, (i + 1) * size),
  );

describe("QuattrocentoStreamParser", () => {
  const C = 120;
  const rowOf = (k: number, count: number): number[] =>
    Array.from({ length: C }, (_, ch) =>
      ch === C - 8 ? (count << 16) >> 16 : ch === C - 5 ? 20000 : value(ch, k),
    );

  test("every chunk size gives the same samples, values exact, across the counter's wrap", () => {
    const b = stream(C, 65530, 20);
    for (const size of [1, 2, 3, 7, 239, 240, 241, 1000, b.length]) {
      const { p, rows } = parse(C, pieces(b, size));
      expect(rows, `chunks of ${size}`).toEqual(
        Array.from({ length: 20 }, (_, k) => rowOf(k, (65530 + k) & 0xffff)),
      );
      expect([p.samples, p.malformed, p.skippedBytes, p.lostSamples]).toEqual([20, 0, 0, 0]);
    }
  });

  test("stray bytes: one malformed, exactly those bytes skipped, no sample lost", () => {
    const b = stream(C, 100, 30);
    const cut = 10 * 2 * C;
    const withJunk = Buffer.concat([
      b.subarray(0, cut),
      Buffer.from([1, 2, 3, 4, 5]),
      b.subarray(cut),
    ]);
    for (const size of [1, 64, withJunk.length]) {
      const { p, rows } = parse(C, pieces(new Uint8Array(withJunk), size));
      // Values exact on both sides of the junk (after it, samples sit at odd offsets).
      expect(rows).toEqual(Array.from({ length: 30 }, (_, k) => rowOf(k, 100 + k)));
      expect([p.malformed, p.skippedBytes, p.lostSamples]).toEqual([1, 5, 0]);
      expect(p.lastProblem).toMatch(/sample counter \d+ where 110 was due/);
    }
  });

  test("a counter that skips is samples lost; one that restarts is a counter jump", () => {
    const { p, rows } = parse(C, [stream(C, 7, 20, 10, 300)]);
    expect(rows.length).toBe(20);
    expect([p.lostSamples, p.counterJumps, p.malformed]).toEqual([300, 0, 0]);
    const restart = Buffer.concat([stream(C, 5000, 10), stream(C, 0, 10)]);
    const r = parse(C, [new Uint8Array(restart)]);
    expect(r.rows.length).toBe(20);
    expect([r.p.lostSamples, r.p.counterJumps, r.p.malformed]).toEqual([0, 1, 0]);
  });

  test("joined in the middle of a sample; bytes that never count; reset", () => {
    const b = stream(C, 0, 10);
    const { p, rows } = parse(C, [b.subarray(37)]);
    expect(rows.length).toBe(9);
    expect(rows[0]).toEqual(rowOf(1, 1));
    expect([p.malformed, p.skippedBytes]).toEqual([1, 2 * C - 37]);

    const zeros = parse(C, [new Uint8Array(10 * 2 * C)]);
    expect(zeros.rows).toEqual([]);
    expect(zeros.p.malformed).toBe(1);
    expect(zeros.p.lastProblem).toMatch(/^no sample counter \(channel 113 of 120/);
    // What could still start an aligned run is kept; reset drops it.
    expect(zeros.p.held).toBe(3 * 2 * C - 1);
    expect(zeros.p.reset()).toBe(3 * 2 * C - 1);
    expect(zeros.p.held).toBe(0);
    expect(() => new QuattrocentoStreamParser(8, () => {})).toThrow(/more than 8 channels/);
  });
});
