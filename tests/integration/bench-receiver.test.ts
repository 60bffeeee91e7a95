/**
 * The bench's UDP receiver (app/cli/bench-receiver.ts) decodes MOSAIC's streamlined datagrams on
 * its own; here it is checked against the product's encoder (app/blocks/io/udp-format.ts) and a
 * real socket on loopback.
 */
import { createSocket } from "node:dgram";
import { describe, expect, test } from "vitest";
import { StreamlinedEncoder } from "../../app/blocks/io/udp-format";
import { BenchReceiver, decodeHeader, rxFigures, type Arrival } from "../../app/cli/bench-receiver";

/** Arrivals of a control serializer: `dofs` datagrams per event, one event per period. */
function stream(events: number, rate: number, dofs: number, skip: (k: number) => boolean) {
  const out: Arrival[] = [];
  let counter = 0;
  for (let k = 0; k < events; k++) {
    const t = 1000 + k / rate;
    for (let d = 0; d < dofs; d++) {
      if (!skip(k * dofs + d)) {
        out.push({
          at: k * (1000 / rate) + d * 0.01,
          timestamp: t,
          counter,
          category: 1,
          subcategory: d,
          count: 1,
        });
      }
      counter = (counter + 1) & 0xffff;
    }
  }
  return out;
}

describe("bench receiver", () => {
  test("decodes what the product's UdpSender encodes (independent decoder, same layout)", () => {
    const enc = new StreamlinedEncoder(1, "f64");
    enc.counter = 65535;
    const a = decodeHeader(enc.encode(1795490570.25, 1, 2, [42], 0), 7);
    expect(a).toEqual({
      at: 7,
      count: 1,
      category: 1,
      subcategory: 2,
      timestamp: 1795490570.25,
      counter: 65535,
    });
    const b = decodeHeader(enc.encode(1, 1, 0, [1], 0), 8) as Arrival;
    expect(b.counter).toBe(0);
    const i8 = new StreamlinedEncoder(8, "i8");
    expect(decodeHeader(i8.encode(3, 1, 1, new Float64Array(8), 0), 0)).toMatchObject({
      count: 8,
      timestamp: 3,
    });
    expect(decodeHeader(new Uint8Array(5), 0)).toMatch(/shorter/);
    expect(decodeHeader(Uint8Array.of(1, 0x33, 0, 0, ...new Array(12).fill(0)), 0)).toMatch(
      /type byte 0x33/,
    );
    expect(decodeHeader(enc.encode(1, 1, 0, [1], 0).subarray(0, 21), 0)).toMatch(
      /need 22 bytes, got 21/,
    );
  });

  test("rate by arrival, gaps by counter and by timestamp, partial events at the window's edges", () => {
    const rate = 1926 / 77;
    const all = stream(100, rate, 3, () => false);
    const f = rxFigures(all, 0, 99 * (1000 / rate) + 1, rate, 50512);
    expect(f.perEvent).toBe(3);
    expect(f.events).toBe(100);
    expect(f.datagrams).toBe(300);
    expect(f.rateHz).toBeCloseTo(rate, 6);
    expect(f.timestampRateHz).toBeCloseTo(rate, 6);
    expect(Math.abs(f.rateErrorPct)).toBeLessThan(1e-6);
    expect([f.counterGaps, f.missingEvents, f.incompleteEvents]).toEqual([0, 0, 0]);
    // One datagram lost (counter gap, event incomplete); a whole event lost (both).
    const lossy = stream(100, rate, 3, (i) => i === 31 || (i >= 150 && i < 153));
    const g = rxFigures(lossy, 0, 1e9, rate, 50512);
    expect(g.counterGaps).toBe(4);
    expect(g.missingEvents).toBe(1);
    expect(g.incompleteEvents).toBe(1);
    expect(g.maxArrivalGapMs).toBeGreaterThan(79);
    // A window that cuts an event in two counts no incomplete event.
    const cut = rxFigures(all, 0.005, 10 * (1000 / rate) + 0.015, rate, 1);
    expect(cut.incompleteEvents).toBe(0);
    expect(cut.counterGaps).toBe(0);
    // The counter wraps at 65535 without counting a gap.
    const wrap = all.map((a, i) => ({ ...a, counter: (65500 + i) & 0xffff }));
    expect(rxFigures(wrap, 0, 1e9, rate, 1).counterGaps).toBe(0);
  });

  test("receives real datagrams on loopback", async () => {
    const rx = await BenchReceiver.open(0);
    expect(rx.port).toBeGreaterThan(0);
    const tx = createSocket("udp4");
    const enc = new StreamlinedEncoder(1, "f64");
    try {
      await expect(BenchReceiver.open(rx.port)).rejects.toThrow(/is in use/);
      for (let k = 0; k < 10; k++) {
        await new Promise<void>((r) =>
          tx.send(enc.encode(k / 25, 1, 0, [k], 0), rx.port, "127.0.0.1", () => r()),
        );
      }
      tx.send(Buffer.from([1, 2, 3]), rx.port, "127.0.0.1");
      for (let i = 0; i < 100 && rx.arrivals.length + rx.malformed < 11; i++) {
        await new Promise((r) => setTimeout(r, 10));
      }
      expect(rx.arrivals.length).toBe(10);
      expect(rx.malformed).toBe(1);
      const f = rx.figures(0, performance.now(), 25);
      expect(f.events).toBe(10);
      expect(f.counterGaps).toBe(0);
      expect(f.timestampRateHz).toBeCloseTo(25, 9);
      expect(f.firstMalformed).toMatch(/shorter/);
    } finally {
      tx.close();
      await rx.close();
    }
  });
});
