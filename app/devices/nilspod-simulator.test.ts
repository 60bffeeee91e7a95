import { describe, expect, test } from "vitest";
import type { BlePeripheral } from "../engine/io";
import { NilsPodSimulator, nilsPodSimRaw } from "./nilspod-simulator";

const SERVICE = "6e400001-b5a3-f393-e0a9-e50e24dcca9e";
const COMMANDS = "6e400002-b5a3-f393-e0a9-e50e24dcca9e";
const SAMPLES = "6e400003-b5a3-f393-e0a9-e50e24dcca9e";
const settle = (): Promise<void> => new Promise((r) => setTimeout(r, 0));

describe("NilsPod simulator", () => {
  test("advertises, connects, streams the documented 14-byte samples on 0xC2, stops on 0xC1", async () => {
    let now = 5;
    const sim = new NilsPodSimulator({ now: () => now, rate: 100, samplesPerNotification: 2 });
    const found: BlePeripheral[] = [];
    sim.scan({ services: [SERVICE], onFound: (p) => found.push(p), onError: () => {} });
    await settle();
    expect(found).toEqual([
      {
        address: "d4:22:cd:00:4e:01",
        name: "NilsPod-4E01",
        rssi: -60,
        services: ["6e400001b5a3f393e0a9e50e24dcca9e"],
      },
    ]);
    const lost: string[] = [];
    const c = await sim.connect("D4-22-CD-00-4E-01", (r) => lost.push(r));
    const chars = await c.discover([SERVICE]);
    expect(chars.map((x) => [x.uuid, x.properties])).toEqual([
      ["6e400002b5a3f393e0a9e50e24dcca9e", ["write", "writeWithoutResponse"]],
      ["6e400003b5a3f393e0a9e50e24dcca9e", ["notify"]],
    ]);
    const got: Uint8Array[] = [];
    await c.subscribe(SERVICE, SAMPLES, (d) => got.push(d.slice()));
    expect(sim.pump()).toBe(0); // not streaming before the start command
    await c.write(SERVICE, COMMANDS, Uint8Array.of(0xc2));
    now = 5.015; // samples 0 and 1 are due (10 ms apart); the third only at 5.02
    expect(sim.pump()).toBe(2);
    expect(got).toHaveLength(1);
    const dv = new DataView(got[0]!.buffer);
    expect(got[0]!.length).toBe(28);
    for (const k of [0, 1]) {
      const axes = [0, 1, 2, 3, 4, 5].map((a) => dv.getInt16(14 * k + 2 * a, true));
      expect(axes).toEqual([0, 1, 2, 3, 4, 5].map((a) => nilsPodSimRaw(k, a, 100)));
      expect(dv.getUint16(14 * k + 12, true)).toBe(k);
    }
    // At rest at k = 0: gravity on z (2048 counts = 1 g at ±16 g), the roll rate on gyroscope x.
    expect(nilsPodSimRaw(0, 5, 100)).toBe(2048);
    expect(nilsPodSimRaw(0, 0, 100)).toBe(
      Math.round(((60 * Math.PI) / 180) * (Math.PI / 2) * (180 / Math.PI) * 16.384),
    );
    sim.skip(3);
    now = 5.035;
    sim.pump();
    expect(sim.sent).toEqual([0, 1, 5, 6]);
    await c.write(SERVICE, COMMANDS, Uint8Array.of(0xc1));
    now = 6;
    expect(sim.pump()).toBe(0);
    expect(sim.writes).toEqual([
      "6e400002b5a3f393e0a9e50e24dcca9e c2",
      "6e400002b5a3f393e0a9e50e24dcca9e c1",
    ]);
    sim.drop("out of range");
    expect(lost).toEqual(["out of range"]);
    await expect(c.write(SERVICE, COMMANDS, Uint8Array.of(0xc2))).rejects.toThrow(/disconnected/);
  });

  test("realtime: notifications on the wall clock at the device's rate, never ahead of it", async () => {
    const t0 = performance.now() / 1000;
    const sim = new NilsPodSimulator({ realtime: true, rate: 204.8 });
    try {
      const c = await sim.connect(sim.address, () => {});
      const got: number[] = [];
      await c.subscribe(SERVICE, SAMPLES, (d) =>
        got.push(new DataView(d.buffer).getUint16(12, true)),
      );
      await c.write(SERVICE, COMMANDS, Uint8Array.of(0xc2));
      await new Promise((r) => setTimeout(r, 300));
      const elapsed = performance.now() / 1000 - t0;
      // Pumped every 10 ms on a loaded machine: some samples, in order, none before its time.
      expect(got.length).toBeGreaterThan(0);
      expect(got.length).toBeLessThanOrEqual(Math.floor(elapsed * 204.8) + 1);
      expect(got).toEqual(got.map((_, k) => k));
    } finally {
      sim.close();
    }
  });
});
