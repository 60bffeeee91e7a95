/**
 * The DLR ADC/BT's bytes (dlr-adcbt-frames.ts): the commands as the original wrote them, frames
 * decoded across any chunk boundary, malformed frames counted and skipped with the stream
 * resuming on the next start, no throw on any input; and the block where no serial bridge or no
 * port is there (its status says so, ticks give zeros). The link on a real pty against the
 * simulator is tests/integration/dlr-adcbt.test.ts.
 */
import { describe, expect, test } from "vitest";
import { EMPTY_SHAPE, Frame } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { DLR_ADCBT } from "./dlr-adcbt";
import { DlrFrameParser, dlrCommand, dlrFrameLength, dlrVolts } from "./dlr-adcbt-frames";

/** A frame as the format says (written here from docs/protocols.md, not with the parser's code). */
function frame(raw: number[], byte3 = 0, spare: [number, number] = [0, 0]): Uint8Array {
  const len = 4 + 2 * raw.length + 4;
  const b = new Uint8Array(len);
  const dv = new DataView(b.buffer);
  b.set([0xaa, 0x7a, len, byte3]);
  raw.forEach((r, c) => dv.setUint16(4 + 2 * c, r, false));
  b.set([spare[0], spare[1], 0xff, 0xff], len - 4);
  return b;
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

/** Feeds `bytes` in chunks of `size`; returns the decoded frames (copies). */
function parse(p: DlrFrameParser, bytes: Uint8Array, size = bytes.length): number[][] {
  const got: number[][] = [];
  for (let i = 0; i < bytes.length; i += size) {
    p.push(bytes.subarray(i, i + size), (v) => got.push([...v]));
  }
  return got;
}

/** A deterministic 12-bit test pattern: frame k, channel c. */
const raw = (k: number, c: number): number => (k * 131 + c * 977 + 7) % 4096;
const rawFrame = (k: number, channels: number): number[] =>
  Array.from({ length: channels }, (_, c) => raw(k, c));

describe("commands", () => {
  test("the channel count, start and stop: 19 bytes each, as the original's", () => {
    const tail = [0x01, 0x8f, 0xff, 0xef];
    const zeros = (n: number) => Array<number>(n).fill(0);
    expect([...dlrCommand("channels", 10)]).toEqual([
      0xaa,
      0x7a,
      0x03,
      0x01,
      10,
      ...zeros(10),
      ...tail,
    ]);
    expect([...dlrCommand("start")]).toEqual([0xaa, 0x7a, 0x01, 0x6a, ...zeros(11), ...tail]);
    expect([...dlrCommand("stop")]).toEqual([0xaa, 0x7a, 0x01, 0x6b, ...zeros(11), ...tail]);
    expect(() => dlrCommand("channels", 0)).toThrow(/1…255; got 0/);
    expect(() => dlrCommand("channels", 256)).toThrow(/one byte/);
  });
});

describe("frames", () => {
  test("length and scale: 4 + 2·channels + 4 bytes, big-endian, 5 · raw / 4000 V", () => {
    expect(dlrFrameLength(10)).toBe(28);
    expect(dlrFrameLength(123)).toBe(254);
    const p = new DlrFrameParser(3);
    expect(parse(p, frame([0, 4000, 0x1234]))).toEqual([[0, 5, (5 * 0x1234) / 4000]]);
    expect(parse(p, frame([0xffff, 1, 0x0100]))).toEqual([[81.91875, 0.00125, 0.32]]);
    expect(dlrVolts(2048)).toBe(2.56);
    expect(p.stats).toMatchObject({ frames: 2, malformed: 0, skipped: 0 });
  });

  test("bytes 3, L-4 and L-3 (never read by the original) do not matter", () => {
    const p = new DlrFrameParser(2);
    expect(parse(p, frame([100, 200], 0x55, [0xaa, 0x7a]))).toEqual([[0.125, 0.25]]);
    expect(p.stats.malformed).toBe(0);
  });

  test("the same values whatever the chunk boundaries", () => {
    const channels = 10;
    const want = Array.from({ length: 12 }, (_, k) => rawFrame(k, channels).map(dlrVolts));
    const bytes = concat(...Array.from({ length: 12 }, (_, k) => frame(rawFrame(k, channels))));
    for (let size = 1; size <= 2 * dlrFrameLength(channels) + 3; size++) {
      const p = new DlrFrameParser(channels);
      expect(parse(p, bytes, size), `chunks of ${size} bytes`).toEqual(want);
      expect(p.stats).toMatchObject({ frames: 12, malformed: 0, skipped: 0 });
    }
  });

  test("malformed frames are counted and skipped; the stream resumes on the next start", () => {
    const n = 4;
    const good = (k: number) => frame(rawFrame(k, n));
    const badEnd = frame(rawFrame(90, n));
    badEnd[badEnd.length - 1] = 0xfe;
    const wrongLength = frame(rawFrame(91, 6)); // a frame for 6 channels
    const truncated = good(92).subarray(0, 9); // cut off: the next frame starts inside it
    const stream = concat(
      Uint8Array.of(0x00, 0x13, 0xaa), // noise before the first start
      good(0),
      badEnd,
      good(1),
      wrongLength,
      good(2),
      truncated,
      good(3),
      Uint8Array.of(0xaa, 0x7a), // a start, then bytes that never finish it
      good(4),
    );
    for (const size of [1, 5, stream.length]) {
      const p = new DlrFrameParser(n);
      const got = parse(p, stream, size);
      expect(got, `chunks of ${size}`).toEqual(
        [0, 1, 2, 3, 4].map((k) => rawFrame(k, n).map(dlrVolts)),
      );
      expect(p.stats.frames).toBe(5);
      // The bad end, the wrong length byte, the truncated frame and the bare start (whose
      // length byte is the next frame's AA).
      expect(p.stats.badEnd).toBe(2);
      expect(p.stats.badLength).toBe(2);
      expect(p.stats.malformed).toBe(4);
      expect(p.stats.skipped).toBe(3 + badEnd.length + wrongLength.length + truncated.length + 2);
    }
  });

  test("a bad end mark is named with the bytes found", () => {
    const p = new DlrFrameParser(1);
    const f = frame([1]);
    f[f.length - 2] = 0x00;
    parse(p, concat(f, frame([2])));
    expect(p.stats.lastProblem).toBe("end mark 00 FF, expected FF FF (a short or corrupted frame)");
    const q = new DlrFrameParser(1);
    parse(q, frame([1, 2]));
    expect(q.stats.lastProblem).toBe("length byte 12, expected 10 (1 channel)");
  });

  test("never throws: random bytes with frames among them", () => {
    let s = 12345;
    const rnd = () => ((s = (Math.imul(s, 1103515245) + 12345) >>> 0) >>> 8) & 0xff;
    const parts: Uint8Array[] = [];
    for (let k = 0; k < 300; k++) {
      parts.push(Uint8Array.from({ length: rnd() % 40 }, rnd));
      parts.push(frame(rawFrame(k, 8)));
    }
    const bytes = concat(...parts);
    const p = new DlrFrameParser(8);
    const got = parse(p, bytes, 7);
    // Every embedded frame is found (noise cannot hide a whole valid frame after it once the
    // parser is past the noise), plus whatever noise happened to look like one.
    expect(got.length).toBeGreaterThanOrEqual(290);
    const wanted = new Set(Array.from({ length: 300 }, (_, k) => rawFrame(k, 8).join()));
    const found = got.filter((v) =>
      wanted.has(v.map((x) => Math.round((x * 4000) / 5)).join()),
    ).length;
    expect(found).toBeGreaterThanOrEqual(290);
    expect(p.stats.frames).toBe(got.length);
  });

  test("channel counts outside one length byte are refused", () => {
    expect(() => new DlrFrameParser(0)).toThrow(/1…123 channels, not 0/);
    expect(() => new DlrFrameParser(124)).toThrow(/1…123 channels, not 124/);
  });
});

describe("the block without a serial bridge or a port", () => {
  const timer = { shape: EMPTY_SHAPE, rate: 100, isTimer: true };
  const ticks = Frame.from(EMPTY_SHAPE, [0, 0.01, 0.02], [[], [], []]);

  test("no serial bridge (the browser build): the status says so, ticks give zeros", async () => {
    const h = await BlockHarness.create(
      DLR_ADCBT,
      { Port: "/dev/rfcomm0", Channels: 2 },
      {
        inputs: [timer],
      },
    );
    h.start();
    expect(h.text).toMatch(/serial ports are not available here \(browser build\)/);
    expect(h.warnings[0]).toMatch(/DLR ADC\/BT on serial port \/dev\/rfcomm0 at 115200 Bd/);
    h.push(ticks);
    expect(h.output("analog").v).toEqual([
      [0, 0],
      [0, 0],
      [0, 0],
    ]);
  });

  test("no Port: the status says to set it", async () => {
    const h = await BlockHarness.create(DLR_ADCBT, {}, { inputs: [timer] });
    h.start();
    expect(h.text).toMatch(/no serial port chosen: set Port/);
    expect(h.warnings).toHaveLength(1);
  });
});
