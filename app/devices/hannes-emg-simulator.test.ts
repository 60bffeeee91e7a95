/**
 * The Hannes EMG simulator: the value function (range, determinism, one datagram told from
 * another), the datagram bytes as docs/protocols.md ("Hannes", HannesReceiver) gives them, every
 * datagram received exactly over real loopback UDP, and the options. HannesReceiver against it
 * is tests/integration/hannes-simulate.test.ts.
 */
import { createSocket } from "node:dgram";
import { describe, expect, test } from "vitest";
import {
  HannesEmgSimulator,
  hannesEmgDatagram,
  hannesEmgRaw,
  hannesEmgSimulatorOptions,
  hannesEmgValue,
} from "./hannes-emg-simulator";

describe("values and datagrams", () => {
  test("16-bit, deterministic, EMG-like around mid-scale, every datagram distinct", () => {
    const seen = new Set<string>();
    let lo = 65535;
    let hi = 0;
    for (let i = 0; i < 4000; i++) {
      const row = [0, 1, 2, 3, 4, 5].map((k) => hannesEmgRaw(i, k));
      for (const v of row) {
        expect(Number.isInteger(v) && v >= 0 && v <= 65535).toBe(true);
        lo = Math.min(lo, v);
        hi = Math.max(hi, v);
      }
      seen.add(row.join());
    }
    expect(seen.size).toBe(4000);
    expect(lo).toBeLessThan(32768 - 10000);
    expect(hi).toBeGreaterThan(32768 + 10000);
    expect(hannesEmgRaw(123, 4)).toBe(hannesEmgRaw(123, 4));
    expect(hannesEmgValue(123, 4)).toBe(hannesEmgRaw(123, 4) / 65536);
  });

  test("a datagram: two header bytes, then little-endian u16 values", () => {
    const d = hannesEmgDatagram(7, 3);
    expect(d.length).toBe(8);
    expect([d[0], d[1]]).toEqual([0x25, 0x10]);
    for (let k = 0; k < 3; k++)
      expect(d[2 + 2 * k]! | (d[3 + 2 * k]! << 8)).toBe(hannesEmgRaw(7, k));
  });
});

test("on loopback UDP: the datagrams arrive as value(i, k), in order, `count` of them", async () => {
  const rx = createSocket("udp4");
  const got: number[][] = [];
  rx.on("message", (m: Buffer) => {
    const row: number[] = [];
    for (let k = 0; 2 + 2 * k + 1 < m.length; k++) row.push(m.readUInt16LE(2 + 2 * k));
    got.push(row);
  });
  await new Promise<void>((r) => rx.bind(0, "127.0.0.1", r));
  const log: string[] = [];
  const sim = new HannesEmgSimulator({
    host: "127.0.0.1",
    port: rx.address().port,
    rate: 500,
    channels: 4,
    count: 300,
    first: 1000,
    log: (l) => log.push(l),
  });
  await sim.waitFor(() => sim.done, "end");
  const end = Date.now() + 5000;
  while (got.length < 300 && Date.now() < end) await new Promise((r) => setTimeout(r, 10));
  await sim.close();
  rx.close();
  expect(got).toEqual(
    Array.from({ length: 300 }, (_, j) => [0, 1, 2, 3].map((k) => hannesEmgRaw(1000 + j, k))),
  );
  expect(log.at(-1)).toBe("300 datagrams sent · done");
});

describe("mosaic simulate hannes-emg's options", () => {
  test("checked, with what is wrong", () => {
    expect(hannesEmgSimulatorOptions({ to: "127.0.0.1:11000" })).toEqual({
      host: "127.0.0.1",
      port: 11000,
    });
    expect(
      hannesEmgSimulatorOptions({ to: "[::1]:5000", rate: "250", channels: "8", count: "10" }),
    ).toEqual({ host: "::1", port: 5000, rate: 250, channels: 8, count: 10 });
    expect(() => hannesEmgSimulatorOptions({})).toThrow(/^--to HOST:PORT is required/);
    expect(() => hannesEmgSimulatorOptions({ to: "localhost" })).toThrow(
      "--to takes HOST:PORT with a port 1…65535, e.g. 127.0.0.1:11000; not 'localhost'",
    );
    expect(() => hannesEmgSimulatorOptions({ to: "h:1", rate: "fast" })).toThrow(
      "--rate must be a number (0.1…10000 Hz), not 'fast'",
    );
    expect(() => hannesEmgSimulatorOptions({ to: "h:1", channels: "0" })).toThrow(
      "--channels must be a whole number in 1…1000, not '0'",
    );
  });
});
