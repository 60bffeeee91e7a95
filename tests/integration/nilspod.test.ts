/**
 * The NilsPod block (app/blocks/devices/nilspod.ts) against a simulated NilsPod GATT peripheral
 * (app/devices/nilspod-simulator.ts) behind the host's BleBridge interface — no Bluetooth adapter
 * exists here, so this is as far as it can be tested: values end to end, the device's rate,
 * counter gaps, malformed notifications, lost links and reconnection, the stop command, and the
 * engine worker's relay (native-bridges/ble-proxy.ts). Runs on the harness's virtual clock.
 */
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import {
  createCatalog,
  EMPTY_SHAPE,
  formatDiagnostic,
  Frame,
  loadPipeline,
  Runtime,
  VirtualClock,
  type BleBridge,
} from "../../app/engine";
import { withSimulatedDevices } from "../../app/engine/pipeline/simulate";
import { runVirtual } from "../../app/engine/runtime/virtual";
import { noResources } from "../../app/engine/testing";
import { BLOCKS } from "../../app/blocks/catalog";
import { initDspForTests } from "../support/wasm";
import { BlockHarness } from "../../app/engine/testing";
import { bleHub, bleProxy, type BleReply, type BleRequest } from "../../native-bridges/ble-proxy";
import { NilsPodSimulator, nilsPodSimRaw } from "../../app/devices/nilspod-simulator";
import { NilsPod } from "../../app/blocks/devices/nilspod";
import { jsonLines, requireBuild, runCli } from "./helpers";

const settle = async (): Promise<void> => {
  for (let i = 0; i < 3; i++) await new Promise((r) => setTimeout(r, 0));
};
const tick = (t: number) => Frame.from(EMPTY_SHAPE, [t], [[]]);
const timer = (rate: number) => ({ shape: EMPTY_SHAPE, rate, isTimer: true });

const COMMANDS = "6e400002b5a3f393e0a9e50e24dcca9e";
const ADDRESS = "d4:22:cd:00:4e:01";
const WHO = `NilsPod-4E01 (${ADDRESS})`;

/**
 * What the block must emit for the simulator's sample k, computed here from the raw counts:
 * accelerometer (wire axes 3–5) · 9.81 / 2048 (±16 g), gyroscope (wire axes 0–2) · 2000 / 32768.
 */
function expected(k: number, rate: number): number[] {
  const raw = (axis: number) => nilsPodSimRaw(k, axis, rate);
  return [
    (raw(3) * 9.81) / 2048,
    (raw(4) * 9.81) / 2048,
    (raw(5) * 9.81) / 2048,
    (raw(0) * 2000) / 32768,
    (raw(1) * 2000) / 32768,
    (raw(2) * 2000) / 32768,
  ];
}

/** A NilsPod block on a simulated NilsPod, both on the harness's virtual clock. */
async function setUp(
  params: Record<string, unknown> = { Address: ADDRESS },
  sim: Partial<ConstructorParameters<typeof NilsPodSimulator>[0]> = {},
  bridgeOf: (s: NilsPodSimulator) => BleBridge = (s) => s,
) {
  let clock = 0;
  const device = new NilsPodSimulator({ now: () => clock, ...sim });
  const h = await BlockHarness.create(NilsPod, params, {
    io: { ble: bridgeOf(device) },
    inputs: [timer(device.rate)],
  });
  const at = (t: number) => {
    clock = t;
    h.clock = t;
  };
  /** Ticks of the block's timer at these times, the device pumped before each. */
  const run = (times: number[]) => {
    for (const t of times) {
      at(t);
      device.pump();
      h.push(tick(t));
    }
  };
  /** Fires the link's heartbeat until the clock reaches `t` (the simulator's clock follows). */
  const until = async (t: number) => {
    while (h.oneShot && h.oneShot.t <= t + 1e-9) {
      at(h.oneShot.t);
      device.pump();
      h.fireOneShot();
      await settle();
    }
  };
  return { h, device, at, run, until };
}

describe("NilsPod block on a simulated NilsPod", () => {
  test("scan, connect, subscribe, start; every sample arrives with the values the device encoded", async () => {
    const { h, device, run, at } = await setUp();
    h.start();
    expect(h.text).toMatch(/^searching for the NilsPod d4:22:cd:00:4e:01…/);
    await settle();
    expect(device.isConnected).toBe(true);
    expect(device.writes).toEqual([`${COMMANDS} c2`]);
    expect(h.text).toBe(`streaming from ${WHO}`);
    const rate = device.rate;
    const times = Array.from({ length: 300 }, (_, i) => i / rate);
    run(times);
    // One sample per tick at the device's rate: sample k on tick k.
    const out = h.output("imu");
    expect(out.t).toEqual(times);
    expect(device.sent).toEqual(Array.from({ length: 300 }, (_, k) => k));
    expect(out.v).toEqual(device.sent.map((k) => expected(k, rate)));
    expect(h.warnings).toEqual([]);

    // Stop: the stop command, then the link is closed.
    at(3);
    h.instance.stop?.();
    await settle();
    expect(device.writes).toEqual([`${COMMANDS} c2`, `${COMMANDS} c1`]);
    expect(device.isConnected).toBe(false);
    expect(h.text).toMatch(/^stopped/);
    h.instance.dispose?.();
  });

  test("several samples per notification, the device's rate over 60 s of irregular ticks", async () => {
    const { h, device, at } = await setUp({}, { samplesPerNotification: 3, rate: 204.8 });
    h.start();
    expect(h.text).toMatch(/^searching for a NilsPod…/);
    await settle();
    // The clock moves in uneven steps; the device sends what fell due (3 per notification).
    let t = 0;
    for (let i = 0; t < 60; i++) {
      t = Math.min(60, t + [0.013, 0.007, 0.021][i % 3]!);
      at(t);
      device.pump();
    }
    const sent = device.sent.length;
    // 204.8 Hz for 60 s: sample 12288 falls due at t = 60; whole notifications of 3 → 12288.
    expect(sent).toBe(12288);
    expect(device.notifications).toBe(4096);
    // The queue keeps the newest 15; they are exactly the last 15 samples sent.
    const ticks = Array.from({ length: 15 }, (_, i) => 60 + i / 204.8);
    for (const x of ticks) h.push(tick(x));
    expect(h.output("imu").v).toEqual(device.sent.slice(-15).map((k) => expected(k, 204.8)));
    expect(h.text).toMatch(/ · 12,288 samples · 12273 dropped \(queue of 15\)$/);
  });

  test("AccRange and GyroRange: the same raw counts scaled to the ranges the NilsPod was set to", async () => {
    const { h, device, run } = await setUp({ Address: ADDRESS, AccRange: 4, GyroRange: 500 });
    h.start();
    await settle();
    const rate = device.rate;
    run([0, 1 / rate, 2 / rate]);
    const raw = (k: number, axis: number) => nilsPodSimRaw(k, axis, rate);
    expect(h.output("imu").v).toEqual(
      [0, 1, 2].map((k) => [
        ...[3, 4, 5].map((a) => (raw(k, a) * 9.81) / 8192),
        ...[0, 1, 2].map((a) => (raw(k, a) * 500) / 32768),
      ]),
    );
  });

  test("a counter gap is counted as lost samples; a malformed notification is counted, never fatal", async () => {
    const { h, device, run } = await setUp();
    h.start();
    await settle();
    const rate = device.rate;
    run([0, 1 / rate, 2 / rate]);
    device.skip(5);
    run([3 / rate, 4 / rate]);
    expect(device.sent).toEqual([0, 1, 2, 8, 9]);
    expect(h.text).toMatch(/^streaming from .* · 5 samples lost \(counter gaps\)/);
    device.malformed(15);
    device.malformed(13);
    run([5 / rate, 6 / rate]);
    expect(h.text).toMatch(
      / · 5 samples lost \(counter gaps\) · 2 malformed notifications \(last: 13 bytes, not a whole number of 14-byte samples\)/,
    );
    expect(h.warnings).toEqual([
      `NilsPod: malformed notification from ${WHO} (15 bytes, not a whole number of 14-byte samples): dropped`,
      `NilsPod: malformed notification from ${WHO} (13 bytes, not a whole number of 14-byte samples): dropped`,
    ]);
    // Still streaming, still exact.
    expect(device.sent).toEqual([0, 1, 2, 8, 9, 10, 11]);
    expect(h.output("imu").v).toEqual(device.sent.map((k) => expected(k, rate)));
  });

  test("a lost link is reported, zeros follow, and the NilsPod is found again with backoff", async () => {
    const { h, device, run, until } = await setUp();
    h.start();
    await settle();
    const rate = device.rate;
    run([0, 1 / rate]);
    device.drop("connection timeout");
    expect(h.text).toBe(
      `${WHO}: disconnected (connection timeout); searching again in 0.5 s (attempt 2) · 1 disconnection · 2 samples`,
    );
    expect(h.warnings).toEqual([
      `NilsPod: lost ${WHO}: disconnected (connection timeout); reconnecting`,
    ]);
    run([0.1, 0.2]);
    expect(h.output("imu").v.slice(-2)).toEqual([
      [0, 0, 0, 0, 0, 0],
      [0, 0, 0, 0, 0, 0],
    ]);
    // Out of range: the search after 0.5 s finds nothing; still nothing 10 s later.
    await until(11);
    expect(h.text).toMatch(/^searching for the NilsPod d4:22:cd:00:4e:01… · 1 disconnection/);
    // Back in range, but the next two connections fail: the waits go on doubling (1 s, 2 s)
    // until the NilsPod streams again.
    device.failNextConnect("no answer within 10 s");
    device.recover();
    await settle();
    expect(h.text).toBe(
      `${WHO}: connection failed: no answer within 10 s; searching again in 1 s (attempt 3) · 1 disconnection · 2 samples`,
    );
    device.failNextConnect("no answer within 10 s");
    const failedAt = h.clock;
    await until(failedAt + 1.15); // the heartbeat looks every 0.1 s
    expect(h.text).toMatch(/searching again in 2 s \(attempt 4\)/);
    const second = h.clock;
    await until(second + 1.95);
    expect(device.isConnected).toBe(false);
    await until(second + 2.15);
    expect(device.isConnected).toBe(true);
    expect(h.text).toBe(`streaming from ${WHO} · 1 disconnection · reconnected 1× · 2 samples`);
    expect(h.warnings.at(-1)).toBe(`NilsPod: reconnected to ${WHO}; streaming again`);
    expect(device.writes).toEqual([`${COMMANDS} c2`, `${COMMANDS} c2`]);
    // The counter goes on from where the device is: no samples counted lost across the gap.
    const t0 = h.clock;
    run([t0, t0 + 1 / rate, t0 + 2 / rate]);
    expect(h.text).not.toMatch(/lost/);
    const k = device.sent.slice(-3);
    expect(h.output("imu").v.slice(-3)).toEqual(k.map((x) => expected(x, rate)));
    h.instance.dispose?.();
  });

  test("a NilsPod that stops sending is dropped after 2 s and set up again", async () => {
    const { h, device, until, at } = await setUp();
    h.start();
    await settle();
    at(1);
    device.pump();
    device.stall();
    await until(3.15);
    expect(h.text).toMatch(/^NilsPod-4E01 \(d4:22:cd:00:4e:01\): no data for 2 s; searching again/);
    expect(device.isConnected).toBe(false);
    device.stall(false);
    await until(4);
    expect(device.isConnected).toBe(true);
    expect(device.connections).toBe(2);
    expect(h.text).toMatch(/^streaming from .* · 1 disconnection · reconnected 1×/);
  });

  test("without Address only a peripheral named NilsPod… is taken; two blocks take two NilsPods", async () => {
    const other = new NilsPodSimulator({ name: "Myo", now: () => 0 });
    const h = await BlockHarness.create(
      NilsPod,
      {},
      {
        io: { ble: other },
        inputs: [timer(100)],
      },
    );
    h.start();
    await settle();
    expect(other.connections).toBe(0);
    expect(h.text).toMatch(/^searching for a NilsPod…/);
    // A scan without a match starts again every 5 s (a name can come after the first report).
    expect(other.scansStarted).toBe(1);
    while (h.oneShot && h.oneShot.t < 5.25) h.fireOneShot();
    expect(other.scansStarted).toBe(2);
    h.instance.dispose?.();

    const pod = new NilsPodSimulator({ now: () => 0 });
    const one = await BlockHarness.create(NilsPod, {}, { io: { ble: pod }, inputs: [timer(100)] });
    const two = await BlockHarness.create(NilsPod, {}, { io: { ble: pod }, inputs: [timer(100)] });
    one.start();
    two.start();
    await settle();
    expect(pod.connections).toBe(1);
    expect(one.text).toMatch(/^streaming/);
    expect(two.text).toMatch(/^searching for a NilsPod…/);
    one.instance.dispose?.();
    two.instance.dispose?.();
  });

  test("no adapter, then the adapter switched on; no BLE at all", async () => {
    const { h, device } = await setUp({ Address: ADDRESS }, { adapter: "unavailable" });
    h.start();
    expect(h.text).toMatch(/^no Bluetooth adapter \(sending zeros\)/);
    expect(h.warnings).toEqual([
      "NilsPod: no Bluetooth adapter: the NilsPod d4:22:cd:00:4e:01 over Bluetooth LE cannot be reached, the block sends zeros (without the device: mosaic run --simulate-devices)",
    ]);
    device.setAdapter("poweredOn");
    await settle();
    expect(h.text).toBe(`streaming from ${WHO}`);
    device.setAdapter("poweredOff");
    expect(h.text).toMatch(/^Bluetooth is off .* · 1 disconnection/);

    const none = await BlockHarness.create(NilsPod, {}, { inputs: [timer(100)] });
    none.start();
    expect(none.text).toMatch(/^Bluetooth LE is not available here \(browser build\)/);
    expect(none.warnings[0]).toMatch(/the first NilsPod found over Bluetooth LE is not reachable/);
  });

  test("through the engine worker's relay (ble-proxy) as the host runs it: the same values", async () => {
    let hub: ReturnType<typeof bleHub> | undefined;
    const { h, device, at } = await setUp({ Address: ADDRESS }, {}, (sim) => {
      const proxy = bleProxy((m: BleRequest) =>
        queueMicrotask(() => hub!.receive(structuredClone(m))),
      );
      hub = bleHub((m: BleReply) => queueMicrotask(() => proxy.receive(structuredClone(m))), sim);
      return proxy.bridge;
    });
    h.start();
    await settle();
    expect(h.text).toBe(`streaming from ${WHO}`);
    const rate = device.rate;
    const times = Array.from({ length: 50 }, (_, i) => i / rate);
    for (const t of times) {
      at(t);
      device.pump();
      await settle();
      h.push(tick(t));
    }
    expect(h.output("imu").v).toEqual(device.sent.map((k) => expected(k, rate)));
    expect(device.sent).toHaveLength(50);
    h.instance.stop?.();
    await settle();
    expect(device.writes.at(-1)).toBe(`${COMMANDS} c1`);
    expect(device.isConnected).toBe(false);
    hub!.closeAll();
  });
});

describe("pipelines/devices/nilspod.yaml", () => {
  beforeAll(() => initDspForTests());
  const catalog = createCatalog(BLOCKS);
  const file = join(__dirname, "../../pipelines/devices/nilspod.yaml");
  const yaml = readFileSync(file, "utf8");

  test("loads as written, and under --simulate-devices runs with an ImuSimulator in its place", async () => {
    const real = loadPipeline(yaml, file, catalog);
    expect(real.diagnostics.filter((d) => d.severity === "error").map(formatDiagnostic)).toEqual(
      [],
    );
    expect(real.spec!.blocks.find((b) => b.name === "Imu")!.type).toBe("NilsPod");
    const sim = withSimulatedDevices(loadPipeline(yaml, file, catalog), catalog, {});
    expect(sim.diagnostics.map((d) => d.message)).toContain(
      "block 'Imu' (NilsPod) simulated by ImuSimulator, 6 values at 102.4 Hz (its timer's)",
    );
    const clock = new VirtualClock(0);
    const created = await Runtime.create({
      spec: sim.spec!,
      catalog,
      clock,
      virtual: true,
      resources: noResources,
      ignorePlacement: true,
    });
    expect(created.diagnostics.filter((d) => d.severity === "error").map(formatDiagnostic)).toEqual(
      [],
    );
    const rt = created.runtime!;
    const imu: number[][] = [];
    rt.tap("Imu", undefined, (f) => {
      for (let i = 0; i < f.n; i++) imu.push(Array.from(f.v.subarray(i * 6, i * 6 + 6)));
    });
    rt.start();
    runVirtual(rt, clock, 2);
    rt.dispose();
    // 2 s at 102.4 Hz; gravity (≈ 9.8 m/s²) on the simulated forearm's y–z plane.
    expect(Math.abs(imu.length - 205)).toBeLessThanOrEqual(1);
    expect(Math.hypot(imu[0]![1]!, imu[0]![2]!)).toBeGreaterThan(9);
  });
});

describe("mosaic run --simulate-ble nilspod", () => {
  test("the example's NilsPod block finds the simulated peripheral through the host's BLE hub and streams", () => {
    requireBuild();
    const r = runCli(
      [
        "run",
        "pipelines/devices/nilspod.yaml",
        "--simulate-ble",
        "nilspod",
        "--duration",
        "2",
        "--json",
      ],
      { timeoutMs: 30_000 },
    );
    expect(r.code, r.stderr).toBe(0);
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as unknown as {
      blocks: { name: string; events: number; text: string; errors: number }[];
    };
    const imu = summary.blocks.find((b) => b.name === "Imu")!;
    expect(imu.errors).toBe(0);
    // 102.4 Hz for 2 s, less the scan and connection at the start.
    expect(Number(/([\d,]+) samples/.exec(imu.text)?.[1]?.replace(/,/g, ""))).toBeGreaterThan(100);
    const bad = runCli(["run", "pipelines/devices/nilspod.yaml", "--simulate-ble", "myo"]);
    expect([bad.code, bad.stderr.trim()]).toEqual([
      2,
      "mosaic run: --simulate-ble: no simulated peripheral 'myo' (peripherals: nilspod)",
    ]);
    // A refused command line starts no peripheral: the CLI exits at once.
    const late = runCli([
      "run",
      "pipelines/devices/nilspod.yaml",
      "--simulate-ble",
      "nilspod",
      "--clock",
      "x",
    ]);
    expect([late.code, late.stderr.trim()]).toEqual([
      2,
      "mosaic run: --clock must be realtime or virtual, not 'x'",
    ]);
  });
});
