/**
 * The SyncStation and Muovi simulators on their own, over raw loopback sockets: a command with a
 * bad CRC is refused (nothing streams), a good one streams whole samples whose values are
 * `muoviRaw`/`syncStationRaw`, the stop command stops; the probe connects, streams after byte 9,
 * stops after 8; the CLI's option checks.
 */
import { createConnection, createServer, type Socket } from "node:net";
import { afterEach, describe, expect, test } from "vitest";
import {
  crc8Table,
  MuoviProbeSimulator,
  muoviProbeSimulatorOptions,
  muoviRaw,
  readSyncStationCommand,
  SyncStationSimulator,
  syncStationRaw,
  syncStationSimulatorOptions,
} from "./muovi-simulator";

const cleanup: (() => unknown)[] = [];
afterEach(async () => {
  for (const c of cleanup.splice(0).reverse()) await c();
});
const sleep = (ms: number) => new Promise((r) => setTimeout(r, ms));
async function until(ok: () => boolean, what: string, ms = 3000): Promise<void> {
  const t0 = Date.now();
  while (!ok()) {
    if (Date.now() - t0 > ms) throw new Error(`timed out waiting for ${what}`);
    await sleep(5);
  }
}

/** A start command for these slots, with its CRC (computed here by the table). */
function start(slots: number[]): number[] {
  const cmd = [slots.length * 2 + 1, ...slots.map((s) => s * 16 + 9)];
  return [...cmd, crc8Table(cmd)];
}

describe("SyncStationSimulator", () => {
  test("refuses a bad CRC, streams after a good command, stops on [0, 0]", async () => {
    const sim = await SyncStationSimulator.start({ port: 0, seed: 3 });
    cleanup.push(() => sim.close());
    const got: number[] = [];
    const s: Socket = createConnection({ host: "127.0.0.1", port: sim.port });
    s.on("data", (d) => got.push(...d));
    cleanup.push(() => s.destroy());
    await new Promise<void>((r) => s.once("connect", () => r()));

    const bad = start([0]);
    bad[2]! ^= 1;
    s.write(Uint8Array.from(bad));
    await until(() => sim.refused.length === 1, "the refusal");
    expect(sim.refused[0]).toMatch(/^CRC-8 \d+ where \d+ was due \(command of 3 bytes\)$/);
    await sleep(30);
    expect(got).toEqual([]);

    s.write(Uint8Array.from(start([2])));
    const S = (38 + 6) * 2;
    await until(() => got.length >= 40 * S, "40 samples");
    expect(sim.commands).toEqual([{ go: true, probes: [{ slot: 2, emg: true, mode: 0 }] }]);
    const b = Buffer.from(got);
    for (let k = 0; k < 40; k++) {
      for (let c = 0; c < 38; c++) expect(b.readInt16BE(k * S + 2 * c)).toBe(muoviRaw(3, 2, c, k));
      for (let c = 0; c < 6; c++) {
        expect(b.readInt16BE(k * S + 76 + 2 * c)).toBe(syncStationRaw(3, c, k));
      }
    }
    s.write(Uint8Array.of(0, 0));
    await until(() => sim.stops === 1, "the stop");
    await sleep(20);
    const n = got.length;
    await sleep(40);
    expect(got.length).toBe(n);
    expect(n % S).toBe(0);
  });

  test("reads commands byte by byte: needs, lengths and errors", () => {
    expect(readSyncStationCommand(Uint8Array.of())).toEqual({ need: 1 });
    expect(readSyncStationCommand(Uint8Array.of(5, 9))).toEqual({ need: 2 });
    expect(readSyncStationCommand(Uint8Array.of(0, 0))).toEqual({
      used: 2,
      request: { go: false, probes: [] },
    });
    const off = [3, 8];
    expect(readSyncStationCommand(Uint8Array.from([...off, crc8Table(off)]))).toEqual({
      error: "probe byte 8 has its enable bit off",
    });
    expect(crc8Table([..."123456789"].map((c) => c.charCodeAt(0)))).toBe(0xa1);
  });
});

describe("MuoviProbeSimulator", () => {
  test("connects, streams 38 channels after byte 9, stops after 8, connects again when dropped", async () => {
    const peers: Socket[] = [];
    const got: number[] = [];
    const srv = createServer((s) => {
      peers.push(s);
      s.on("data", (d) => got.push(...d));
      s.on("error", () => {});
    });
    await new Promise<void>((r) => srv.listen(0, "127.0.0.1", r));
    cleanup.push(() => new Promise((r) => srv.close(r)));
    const port = (srv.address() as { port: number }).port;
    const probe = new MuoviProbeSimulator({ host: "127.0.0.1", port, seed: 8, retry: 0.05 });
    cleanup.push(() => probe.close());
    await until(() => peers.length === 1 && probe.connected, "the probe");
    peers[0]!.write(Uint8Array.of(9));
    await until(() => got.length >= 20 * 76, "20 samples");
    const b = Buffer.from(got);
    for (let c = 0; c < 38; c++) expect(b.readInt16BE(19 * 76 + 2 * c)).toBe(muoviRaw(8, 0, c, 19));
    peers[0]!.write(Uint8Array.of(8));
    await until(() => !probe.streaming, "the stop");
    expect(probe.received).toEqual([9, 8]);
    peers[0]!.destroy();
    await until(() => peers.length === 2, "the second connection");
    expect(probe.connections).toBe(2);
  });

  test("the CLI's options: --connect required and checked, ports and seeds are integers", () => {
    expect(() => muoviProbeSimulatorOptions({})).toThrow(
      "--connect HOST:PORT is required (where a MuoviSingleProbe block listens, e.g. --connect 127.0.0.1:54321)",
    );
    expect(() => muoviProbeSimulatorOptions({ connect: "localhost" })).toThrow(
      "--connect takes HOST:PORT (e.g. 127.0.0.1:54321), not 'localhost'",
    );
    expect(muoviProbeSimulatorOptions({ connect: "[::1]:6000", slot: "2" })).toEqual({
      host: "::1",
      port: 6000,
      slot: 2,
      seed: 1,
    });
    expect(() => muoviProbeSimulatorOptions({ connect: "h:1", slot: "4" })).toThrow(
      "--slot must be an integer from 0 to 3, not '4'",
    );
    expect(syncStationSimulatorOptions({})).toEqual({ host: "127.0.0.1", port: 54320, seed: 1 });
    expect(() => syncStationSimulatorOptions({ port: "70000" })).toThrow(
      "--port must be a port number (0 for any free port), not '70000'",
    );
  });
});
