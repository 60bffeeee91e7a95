/**
 * The Sessantaquattro's command word and sample parser (sessantaquattro-protocol.ts) against the
 * protocol's bit layout, the public readers' channel counts, and bytes written here by hand
 * (big-endian, 2 or 3 bytes a value, the counter last): values exact, the counter's gaps and
 * restarts, malformed bytes and a stream cut anywhere. The simulator's encoder meets the parser
 * in tests/integration/sessantaquattro.test.ts.
 */
import { describe, expect, test } from "vitest";
import {
  commandWord,
  encodeCommand,
  readCommand,
  SessantaquattroStreamParser,
  wireLayout,
  type SessantaquattroConfig,
} from "./sessantaquattro-protocol";

const base: SessantaquattroConfig = {
  model: "Sessantaquattro+",
  mode: "monopolar",
  channels: 64,
  rate: 2000,
  highRes: false,
  hpf: true,
};

/**
 * Sample k as a test expects it: signed values over the whole range of the resolution (every
 * fifth channel at its most negative, or nearly), the buffer level, and the counter k (wrapped at
 * 16 bits). No other channel counts +1 per sample: one that did could be taken for the counter
 * by a stream that starts mid-sample (as the device's test mode, ramps on every channel, would).
 */
function expected(cfg: SessantaquattroConfig, k: number): number[] {
  const n = wireLayout(cfg).length;
  const bits = cfg.highRes ? 24 : 16;
  const half = 2 ** (bits - 1);
  return Array.from({ length: n }, (_, ch) => {
    if (ch === n - 1) return k & 0xffff;
    if (ch === n - 2) return (k >> 4) % 100;
    const x = Math.round(Math.sin(k * 0.37 + ch * 1.3) * (half - 1));
    return ch % 5 === 0 ? -half + ((3 * k + ch) % 7) : x;
  });
}

/** The bytes of samples k0…k0+n-1 of `expected`, big-endian. */
function encode(cfg: SessantaquattroConfig, k0: number, n: number): Uint8Array {
  const bytes = cfg.highRes ? 3 : 2;
  const per = wireLayout(cfg).length;
  const b = new Uint8Array(n * per * bytes);
  let at = 0;
  for (let k = k0; k < k0 + n; k++) {
    for (const v of expected(cfg, k)) {
      for (let i = bytes - 1; i >= 0; i--) b[at++] = (v >> (8 * i)) & 0xff;
    }
  }
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

/** All samples a parser gives for `bytes`, fed in pieces of `step` bytes. */
function parse(cfg: SessantaquattroConfig, bytes: Uint8Array, step = bytes.length) {
  const rows: number[][] = [];
  const p = new SessantaquattroStreamParser(
    wireLayout(cfg).length,
    cfg.highRes ? 3 : 2,
    (raw) => void rows.push(Array.from(raw)),
  );
  for (let i = 0; i < bytes.length; i += step) p.feed(bytes.subarray(i, i + step));
  return { rows, p };
}

describe("the command word", () => {
  test("64 monopolar channels, 2000 Hz, HPF, 16-bit, GO: 0x5841, as a public report of a real device", () => {
    expect(commandWord(base, true)).toBe(0x5841);
    expect(Array.from(encodeCommand(0x5841))).toEqual([0x58, 0x41]);
    expect(commandWord(base, false)).toBe(0x5840);
  });

  test("every field in its bits and back", () => {
    const w = commandWord(
      { ...base, mode: "differential", channels: 16, rate: 500, highRes: true, hpf: false },
      true,
    );
    expect(readCommand(w)).toEqual({
      getset: 0,
      fsamp: 0,
      nch: 1,
      mode: 2,
      hres: 1,
      hpf: 0,
      gain: 0,
      trig: 0,
      rec: 0,
      go: 1,
    });
    expect(readCommand(0xffff)).toMatchObject({ getset: 1, fsamp: 3, nch: 3, mode: 7, gain: 3 });
  });
});

describe("the channels per sample", () => {
  test("NCH + 4 on the Sessantaquattro, NCH + 8 on the +, half the bioelectrical in bipolar mode", () => {
    const count = (model: SessantaquattroConfig["model"], mode: SessantaquattroConfig["mode"]) =>
      ([8, 16, 32, 64] as const).map((channels) => wireLayout({ model, mode, channels }).length);
    expect(count("Sessantaquattro", "monopolar")).toEqual([12, 20, 36, 68]);
    expect(count("Sessantaquattro", "bipolar")).toEqual([8, 12, 20, 36]);
    expect(count("Sessantaquattro+", "monopolar")).toEqual([16, 24, 40, 72]);
    expect(count("Sessantaquattro+", "bipolar")).toEqual([12, 16, 24, 40]);
    expect(count("Sessantaquattro+", "differential")).toEqual([16, 24, 40, 72]);
    expect(
      wireLayout(base)
        .slice(62)
        .map((c) => c.name),
    ).toEqual([
      "EMG 63",
      "EMG 64",
      "AUX 1",
      "AUX 2",
      "IMU W",
      "IMU X",
      "IMU Y",
      "IMU Z",
      "buffer",
      "counter",
    ]);
  });
});

describe("the parser", () => {
  test.each([false, true])("values exact, highRes %s, however the stream is cut", (highRes) => {
    const cfg = { ...base, highRes, channels: 16 as const };
    const bytes = encode(cfg, 100, 50);
    for (const step of [bytes.length, 7, 1]) {
      const { rows, p } = parse(cfg, bytes, step);
      expect(rows).toHaveLength(50);
      rows.forEach((r, i) => expect(r, `sample ${i}`).toEqual(expected(cfg, 100 + i)));
      expect([p.malformed, p.lostSamples, p.counterJumps, p.skippedBytes]).toEqual([0, 0, 0, 0]);
    }
  });

  test("24-bit values keep their sign and size", () => {
    const cfg = { ...base, highRes: true, channels: 8 as const, model: "Sessantaquattro" as const };
    const { rows } = parse(cfg, encode(cfg, 0, 200));
    rows.forEach((r, k) => expect(r).toEqual(expected(cfg, k)));
    const bio = rows.flatMap((r) => r.slice(0, 8));
    expect(Math.max(...bio)).toBeGreaterThan(32767);
    expect(Math.min(...bio)).toBe(-(2 ** 23));
  });

  test("a counter that wraps at 16 bits, or at 24, counts on", () => {
    const cfg = { ...base, channels: 8 as const };
    const { rows, p } = parse(cfg, encode(cfg, 65530, 12));
    expect(rows.map((r) => r.at(-1))).toEqual([
      65530, 65531, 65532, 65533, 65534, 65535, 0, 1, 2, 3, 4, 5,
    ]);
    expect(p.counterJumps + p.lostSamples + p.malformed).toBe(0);
    // A 24-bit counter past 2^16: its 16 low bits count on all the same.
    const hi = { ...cfg, highRes: true };
    const bytes = encode(hi, 0, 6);
    const S = wireLayout(hi).length * 3;
    for (let i = 0; i < 6; i++) bytes[i * S + S - 3] = 0x01;
    const r = parse(hi, bytes);
    expect(r.rows.map((x) => x.at(-1))).toEqual([0, 1, 2, 3, 4, 5].map((k) => 0x10000 + k));
    expect(r.p.malformed).toBe(0);
  });

  test("skipped samples are counted; a restarted counter is a jump", () => {
    const cfg = { ...base, channels: 8 as const };
    const bytes = concat(encode(cfg, 0, 10), encode(cfg, 25, 10), encode(cfg, 9000, 10));
    const { rows, p } = parse(cfg, bytes, 5);
    expect(rows).toHaveLength(30);
    expect(p.lostSamples).toBe(15);
    expect(p.counterJumps).toBe(1);
    expect(p.malformed).toBe(0);
    expect(rows[10]).toEqual(expected(cfg, 25));
    expect(rows[20]).toEqual(expected(cfg, 9000));
  });

  test("malformed bytes are counted once, skipped, and every whole sample around them kept", () => {
    const cfg = { ...base, channels: 16 as const };
    const bytes = concat(encode(cfg, 0, 10), Uint8Array.of(1, 2, 3, 4, 5), encode(cfg, 10, 10));
    for (const step of [bytes.length, 3]) {
      const { rows, p } = parse(cfg, bytes, step);
      expect(rows.map((r) => r.at(-1))).toEqual(Array.from({ length: 20 }, (_, k) => k));
      rows.forEach((r, k) => expect(r).toEqual(expected(cfg, k)));
      expect(p.malformed).toBe(1);
      expect(p.skippedBytes).toBe(5);
      expect(p.lostSamples).toBe(0);
    }
  });

  test("garbage is counted and never crashes; a stream that starts mid-sample finds its samples", () => {
    const cfg = { ...base, channels: 8 as const };
    const junk = Uint8Array.from({ length: 5000 }, (_, i) => (i * 7919) & 255);
    const { rows, p } = parse(cfg, junk, 64);
    expect(rows).toHaveLength(0);
    expect(p.malformed).toBe(1);
    expect(p.skippedBytes).toBeGreaterThan(4900);
    const whole = encode(cfg, 0, 20);
    const cut = parse(cfg, whole.subarray(7));
    expect(cut.rows[0]).toEqual(expected(cfg, 1));
    expect(cut.rows).toHaveLength(19);
    expect(cut.p.malformed).toBe(1);
    expect(cut.p.lastProblem).toMatch(/bytes before the first whole sample/);
  });

  test("reset drops what is held (a connection that ended inside a sample)", () => {
    const cfg = { ...base, channels: 8 as const };
    const bytes = encode(cfg, 0, 5);
    const { p } = parse(cfg, bytes.subarray(0, bytes.length - 3));
    expect(p.reset()).toBeGreaterThan(0);
    expect(p.reset()).toBe(0);
  });
});
