/**
 * The Delsys block against the Trigno simulator (app/devices/trigno-simulator.ts) on loopback
 * TCP with ephemeral ports, through the real Node TCP bridge: values bit-exact (float32 on the
 * wire, f64 out), the native 1925.926 Hz, sensor selection and order, the timer-paced form, a
 * killed and restarted simulator, malformed and truncated data, an unreachable TCU. Then the CLI:
 * `mosaic simulate delsys` as a child process and `mosaic run` of pipelines/devices/delsys.yaml
 * against it.
 */
import { createSocket } from "node:dgram";
import { readFileSync, writeFileSync } from "node:fs";
import { createServer } from "node:net";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import { Delsys } from "../../app/blocks/devices/delsys";
import { TRIGNO_NATIVE_RATE } from "../../app/blocks/devices/delsys-protocol";
import {
  TrignoSimulator,
  trignoAuxValue,
  trignoEmgValue,
} from "../../app/devices/trigno-simulator";
import { EMPTY_SHAPE, Frame, vectorShape } from "../../app/engine";
import { BlockHarness } from "../../app/engine/testing";
import { nodeTcpBridge } from "../../native-bridges/tcp";
import {
  jsonLines,
  requireBuild,
  ROOT,
  runCli,
  startCli,
  tempDir,
  sleep,
  wall,
  until,
} from "./helpers";

const cleanup: (() => void | Promise<void>)[] = [];
afterEach(async () => {
  for (const c of cleanup.splice(0).reverse()) await c();
});

async function simulator(
  o: Parameters<typeof TrignoSimulator.start>[0] = {},
): Promise<TrignoSimulator> {
  const sim = await TrignoSimulator.start({ commandPort: 0, emgPort: 0, auxPort: 0, ...o });
  cleanup.push(() => sim.close());
  return sim;
}

/**
 * The block in a harness whose clock follows the wall clock and fires the block's one-shot (its
 * retry and reply deadlines) when due, as the engine's worker would.
 */
async function block(params: Record<string, unknown>, timerRate?: number) {
  const h = await BlockHarness.create(Delsys, params, {
    io: { tcp: nodeTcpBridge() },
    now: wall(),
    virtual: false,
    ...(timerRate ? { inputs: [{ shape: EMPTY_SHAPE, rate: timerRate, isTimer: true }] } : {}),
  });
  const ticker = setInterval(() => {
    h.clock = wall();
    if (h.oneShot && h.oneShot.t <= h.clock) h.fireOneShot();
  }, 2);
  cleanup.push(() => {
    clearInterval(ticker);
    h.instance.stop?.();
    h.instance.dispose?.();
  });
  return h;
}

const ports = (sim: TrignoSimulator) => ({ Port: sim.ports.command, EmgPort: sim.ports.emg });
const rows = (h: BlockHarness) => h.output("emg").v;
const counts = (h: BlockHarness) => String(h.instance.actions!.counts!.run());

/** Rows [from, to) are samples k0, k0 + 1, … of these sensors, bit for bit. */
function expectSamples(
  h: BlockHarness,
  sensors: number[],
  seed: number,
  from: number,
  to: number,
  k0: number,
): void {
  const v = rows(h);
  let bad = 0;
  for (let i = from; i < to; i++) {
    for (let j = 0; j < sensors.length; j++) {
      if (!Object.is(v[i]![j], trignoEmgValue(seed, sensors[j]!, k0 + i - from))) bad++;
    }
  }
  expect(bad).toBe(0);
}

describe("Delsys ↔ Trigno simulator on loopback", () => {
  test("native: 8 of 16 sensors in the order listed, bit-exact, stamped at 1925.926 Hz, STOP on stop", async () => {
    const sim = await simulator({ sensors: 16, seed: 7 });
    const sensors = [8, 1, 16, 2, 9, 3, 12, 4];
    const h = await block({ Sensors: sensors, ...ports(sim) });
    expect(h.ports[0]!.shape).toEqual(vectorShape(8));
    expect(h.desiredRate).toBeCloseTo(1925.926, 3);
    const t0 = wall();
    h.start();
    await until(() => rows(h).length >= 2000, "2000 samples");
    const elapsed = wall() - t0;
    h.instance.stop!();
    await until(() => sim.commands.includes("STOP"), "STOP");
    expect(sim.commands.slice(0, 4)).toEqual([
      "BACKWARDS COMPATIBILITY OFF",
      "UPSAMPLE OFF",
      "SENSOR 8 PAIRED?",
      "SENSOR 8 TYPE?",
    ]);
    expect(sim.commands).toContain("MAX SAMPLES EMG?");
    expect(sim.commands.indexOf("START")).toBeLessThan(sim.commands.indexOf("STOP"));
    const n = rows(h).length;
    expectSamples(h, sensors, 7, 0, n, 0);
    // Stamps on the device's clock: 1 / 1925.926 s apart (a batch that came more than a frame
    // early pulls them back a little), at most one frame ahead of now; frames as the chunks came.
    const t = h.output("emg").t;
    const period = 0.0135 / 26;
    let exact = 0;
    for (let i = 1; i < n; i++) {
      expect(t[i]!).toBeGreaterThanOrEqual(t[i - 1]!);
      // f64 UNIX seconds hold ~0.24 µs at today's dates.
      if (Math.abs(t[i]! - t[i - 1]! - period) < 1e-6) exact++;
    }
    expect(exact / (n - 1)).toBeGreaterThan(0.99);
    expect((t[n - 1]! - t[0]!) / (n - 1) / period).toBeCloseTo(1, 2);
    expect(t[n - 1]!).toBeLessThanOrEqual(wall() + 0.0135);
    expect(h.output("emg").frames.length).toBeLessThan(n / 10);
    // The device's pace: 2000 samples take ~1.04 s (+ connecting), far from 2000 Hz × elapsed.
    expect(n / elapsed).toBeGreaterThan(1925.926 * 0.6);
    expect(n / elapsed).toBeLessThan(1925.926 * 1.1);
    expect(h.text).toMatch(/^stopped · [\d,]+ samples/);
    expect(String(h.instance.actions!.channels!.run())).toMatch(
      /^channel 1: sensor 8 EMG \(V\); channel 2: sensor 1 .*channel 8: sensor 4/,
    );
    expect(TRIGNO_NATIVE_RATE).toBeCloseTo(1925.926, 3);
  });

  test("Aux acc: the paper's 32 channels (8 sensors × EMG + accelerometer x, y, z), bit-exact, each AUX sample held for its 13 EMG samples", async () => {
    const sim = await simulator({ sensors: 16, seed: 3 });
    const sensors = [1, 2, 3, 4, 5, 6, 7, 8];
    const h = await block({ Sensors: sensors, Aux: "acc", AuxPort: sim.ports.aux, ...ports(sim) });
    expect(h.ports[0]!.shape).toEqual(vectorShape(32));
    expect(h.metas.get("emg")!.labels!.slice(0, 5)).toEqual([
      "sensor 1 EMG (V)",
      "sensor 1 acc x (g)",
      "sensor 1 acc y (g)",
      "sensor 1 acc z (g)",
      "sensor 2 EMG (V)",
    ]);
    h.start();
    await until(() => rows(h).length >= 1500, "1500 joined samples");
    // Malformed AUX bytes are counted and skipped; the join goes on.
    sim.injectAux(Uint8Array.of(0xff, 0xff, 0xff, 0x7f, 1, 2, 3));
    await until(
      () => /AUX: [\d]+ samples, [1-9]\d* malformed/.test(counts(h)),
      "the malformed AUX count",
    );
    await until(() => rows(h).length >= 3000, "3000 joined samples");
    h.instance.stop!();
    expect(sim.commands).toContain("MAX SAMPLES AUX?");
    const v = rows(h);
    let bad = 0;
    let heldOrLost = 0;
    for (let i = 0; i < v.length; i++) {
      for (let j = 0; j < sensors.length; j++) {
        const s = sensors[j]!;
        if (!Object.is(v[i]![4 * j], trignoEmgValue(3, s, i))) bad++;
        for (let c = 0; c < 3; c++) {
          if (!Object.is(v[i]![4 * j + 1 + c], trignoAuxValue(3, s, c, Math.floor(i / 13)))) {
            heldOrLost++;
          }
        }
      }
    }
    expect(bad).toBe(0);
    // Only the AUX samples the malformed bytes cost (the realignment skips a few) may differ:
    // their EMG samples carry the previous AUX values, held.
    expect(heldOrLost).toBeLessThan(3 * 8 * 13 * 8);
    expect(String(h.instance.actions!.channels!.run())).toMatch(
      /^channel 1: sensor 1 EMG \(V\); channel 2: sensor 1 acc x \(g\); channel 3: sensor 1 acc y \(g\); channel 4: sensor 1 acc z \(g\); channel 5: sensor 2 EMG \(V\)/,
    );
  });

  test("Aux: ports must differ; the timer-paced form carries the joined channels too", async () => {
    await expect(
      BlockHarness.create(Delsys, { Aux: "imu", EmgPort: 50044 }, { io: {} }),
    ).rejects.toThrow(/AuxPort 50044 is the EmgPort too/);
    const sim = await simulator({ sensors: 2, seed: 5 });
    const h = await block(
      { Sensors: 2, Aux: "imu", AuxPort: sim.ports.aux, ...ports(sim) },
      1925.926,
    );
    expect(h.ports[0]!.shape).toEqual(vectorShape(20));
    h.start();
    await until(() => /streaming 2 sensors with IMUs/.test(h.text), "streaming with IMUs");
    await sleep(60); // a few frames wait in the queue
    const times = Array.from({ length: 40 }, (_, i) => 1000 + i / 1925.926);
    h.push(
      Frame.from(
        EMPTY_SHAPE,
        times,
        times.map(() => []),
      ),
    );
    const v = rows(h);
    expect(v).toHaveLength(40);
    // The 40 rows are consecutive samples k0 … k0 + 39: EMG then the 9 IMU values per sensor.
    let k0 = -1;
    for (let k = 0; k < sim.emgSamples && k0 < 0; k++) {
      if (Object.is(v[0]![0], trignoEmgValue(5, 1, k))) k0 = k;
    }
    expect(k0).toBeGreaterThanOrEqual(0);
    let bad = 0;
    v.forEach((r, i) => {
      for (let s = 1; s <= 2; s++) {
        if (!Object.is(r[10 * (s - 1)], trignoEmgValue(5, s, k0 + i))) bad++;
        for (let c = 0; c < 9; c++) {
          const want = trignoAuxValue(5, s, c, Math.floor((k0 + i) / 13));
          if (!Object.is(r[10 * (s - 1) + 1 + c], want)) bad++;
        }
      }
    });
    expect(bad).toBe(0);
  });

  test("an unpaired selected sensor is reported once and stays 0", async () => {
    const sim = await simulator({ sensors: 4, seed: 3 });
    const h = await block({ Sensors: [2, 6], ...ports(sim) });
    h.start();
    await until(() => rows(h).length >= 300, "300 samples");
    expect(
      h.warnings.filter((w) => /sensor 6 not paired: its channel stays 0/.test(w)),
    ).toHaveLength(1);
    expect(rows(h).every((r) => r[1] === 0)).toBe(true);
    expectSamples(h, [2], 3, 0, rows(h).length, 0);
    expect(h.text).toMatch(
      /^streaming 2 sensors at 1925\.926 Hz from the Trigno Control Utility at 127\.0\.0\.1:\d+/,
    );
  });

  test("timer-paced (the original's form): each tick takes the oldest waiting sample, in sequence; zeros while lost", async () => {
    const sim = await simulator({ sensors: 2, seed: 5 });
    const h = await block({ Sensors: [2, 1], ...ports(sim) }, 1925.926);
    h.start();
    await until(() => /^streaming/.test(h.text), "streaming");
    await sleep(60); // a few frames wait in the queue
    const times = Array.from({ length: 40 }, (_, i) => 1000 + i / 1925.926);
    h.push(
      Frame.from(
        EMPTY_SHAPE,
        times,
        times.map(() => []),
      ),
    );
    const v = rows(h);
    expect(v).toHaveLength(40);
    expect(h.output("emg").t).toEqual(times);
    // The first emitted row is some sample k0; the 40 rows are k0 … k0 + 39.
    let k0 = -1;
    for (let k = 0; k < sim.emgSamples && k0 < 0; k++) {
      if (v[0]![0] === trignoEmgValue(5, 2, k) && v[0]![1] === trignoEmgValue(5, 1, k)) k0 = k;
    }
    expect(k0).toBeGreaterThanOrEqual(0);
    expectSamples(h, [2, 1], 5, 0, 40, k0);
    // While the link is lost, ticks give zeros (as the original while not streaming).
    sim.dropConnections();
    await until(() => /^lost/.test(h.text), "lost");
    h.push(Frame.from(EMPTY_SHAPE, [1001, 1002], [[], []]));
    expect(rows(h).slice(40)).toEqual([
      [0, 0],
      [0, 0],
    ]);
    await until(() => /^streaming/.test(h.text), "streaming again");
  });

  test("a killed simulator is reported; a restarted one is found again and the stream goes on", async () => {
    const sim = await simulator({ sensors: 8, seed: 11 });
    const p = ports(sim);
    const h = await block({ Sensors: [1, 2, 3], ...p });
    h.start();
    await until(() => rows(h).length >= 500, "500 samples");
    await sim.close();
    await until(() => /^lost the Trigno Control Utility/.test(h.text), "lost");
    const before = rows(h).length;
    expect(h.text).toMatch(/; retrying in 0\.5 s \(attempt 2\)/);
    expect(
      h.warnings.some((w) => /lost the Trigno Control Utility at .*; reconnecting/.test(w)),
    ).toBe(true);
    await sleep(1200); // a few refused attempts (backoff 0.5, 1 s)
    expect(h.text).toMatch(/nothing is listening at 127\.0\.0\.1:\d+ \(ECONNREFUSED\)/);
    const again = await TrignoSimulator.start({
      commandPort: p.Port,
      emgPort: p.EmgPort,
      auxPort: 0,
      sensors: 8,
      seed: 11,
    });
    cleanup.push(() => again.close());
    await until(() => rows(h).length >= before + 500, "500 samples after the restart", 10_000);
    expect(h.text).toMatch(/^streaming 3 sensors .* · 1 reconnection/);
    expect(
      h.warnings.some((w) =>
        /reconnected to the Trigno Control Utility at .* after \d+ failed attempts?; streaming again/.test(
          w,
        ),
      ),
    ).toBe(true);
    // Both streams exactly; the restarted one from its sample 0, after a gap in the stamps.
    expectSamples(h, [1, 2, 3], 11, 0, before, 0);
    expectSamples(h, [1, 2, 3], 11, before, rows(h).length, 0);
    const t = h.output("emg").t;
    expect(t[before]! - t[before - 1]!).toBeGreaterThan(0.5);
    expect(h.text).toMatch(/ · [\d,]+ samples lost in gaps/);
    expect(counts(h)).toMatch(/, 1 reconnections,/);
  });

  test("dropped connections (the TCU crashed and came back) are recovered within a second", async () => {
    const sim = await simulator({ sensors: 2, seed: 2 });
    const h = await block({ Sensors: 2, ...ports(sim) });
    h.start();
    await until(() => rows(h).length >= 200, "200 samples");
    sim.dropConnections();
    await until(() => /^lost/.test(h.text), "lost");
    const before = rows(h).length;
    const t0 = Date.now();
    await until(() => rows(h).length > before + 100, "data again");
    expect(Date.now() - t0).toBeLessThan(1500);
    expectSamples(h, [1, 2], 2, before, rows(h).length, 0);
  });

  test("malformed bytes are counted and skipped without losing a sample; a truncated sample is counted", async () => {
    const sim = await simulator({ sensors: 8, seed: 4 });
    const h = await block({ Sensors: [1, 2, 3, 4, 5, 6, 7, 8], ...ports(sim) });
    h.start();
    await until(() => rows(h).length >= 200, "200 samples");
    sim.injectEmg(new Uint8Array([1, 2, 3])); // three stray bytes between two samples
    await until(() => rows(h).length >= 600, "600 samples");
    sim.injectEmg(new Uint8Array(64).fill(0xff)); // a sample's worth of NaNs
    await until(() => rows(h).length >= 1000, "1000 samples");
    expect(counts(h)).toMatch(/ 2 malformed \(67 bytes skipped, last: sensor 1: NaN\)/);
    expect(h.warnings.filter((w) => /malformed EMG data/.test(w))).toHaveLength(2);
    expectSamples(h, [1, 2, 3, 4, 5, 6, 7, 8], 4, 0, rows(h).length, 0);
    expect(rows(h).flat().every(Number.isFinite)).toBe(true);
    sim.truncate();
    await until(() => /^lost/.test(h.text), "lost after the truncated sample");
    expect(counts(h)).toMatch(/1 truncated \(32 bytes\)/);
    expect(
      h.warnings.some((w) => /ended inside a sample \(32 of 64 bytes\): dropped/.test(w)),
    ).toBe(true);
    await until(() => /^streaming/.test(h.text), "streaming again");
  });

  test("an unreachable TCU, a silent server and a host without TCP give clear statuses", async () => {
    // Nothing listens: refused, retried with a growing wait.
    const free = createServer();
    await new Promise<void>((r) => free.listen(0, "127.0.0.1", r));
    const port = (free.address() as { port: number }).port;
    await new Promise<void>((r) => free.close(() => r()));
    const h = await block({ Sensors: 1, Port: port, EmgPort: port + 1 });
    h.start();
    await until(() => /^not reachable/.test(h.text), "not reachable");
    expect(h.text).toBe(
      `not reachable: nothing is listening at 127.0.0.1:${port} (ECONNREFUSED): start the server there, or check Host and Port; retrying in 0.5 s (attempt 2)`,
    );
    expect(h.warnings).toEqual([
      `Delsys Trigno: the Trigno Control Utility at 127.0.0.1:${port} not reachable: nothing is listening at 127.0.0.1:${port} (ECONNREFUSED): start the server there, or check Host and Port; retrying until it answers (without the device: mosaic run --simulate-devices, or a simulated TCU: mosaic simulate delsys)`,
    ]);
    await until(() => /retrying in 1 s \(attempt 3\)/.test(h.text), "the second retry");
    expect(rows(h)).toHaveLength(0);

    // A server that accepts and says nothing: the banner's deadline.
    const silent = createServer(() => {});
    await new Promise<void>((r) => silent.listen(0, "127.0.0.1", r));
    cleanup.push(() => void silent.close());
    const s = await block({ Sensors: 1, Port: (silent.address() as { port: number }).port });
    s.start();
    await until(() => /^not reachable/.test(s.text), "the banner's deadline", 5000);
    expect(s.text).toMatch(/^not reachable: no banner on the command port within 3 s; retrying/);

    // No TCP bridge (the browser build).
    const b = await BlockHarness.create(Delsys, {}, {});
    b.start();
    expect(b.text).toBe("TCP not available in the browser build; use --simulate-devices");
    expect(b.warnings[0]).toMatch(/Trigno Control Utility at 127\.0\.0\.1:50040 cannot be reached/);
  });
});

describe("mosaic simulate delsys + mosaic run pipelines/devices/delsys.yaml", () => {
  test("the example runs against the simulator as a child process for 3 s", async () => {
    requireBuild();
    const sim = startCli([
      "simulate",
      "delsys",
      "--sensors",
      "8",
      "--command-port",
      "0",
      "--emg-port",
      "0",
      "--aux-port",
      "0",
    ]);
    cleanup.push(() => void sim.kill("SIGINT"));
    const lines: string[] = [];
    createInterface({ input: sim.stdout! }).on("line", (l) => lines.push(l));
    await until(() => lines.length >= 3, "the simulator's banner", 15_000);
    const m = /command port (\d+), EMG port (\d+), AUX port (\d+)/.exec(lines[0]!);
    expect(m, lines.join("\n")).not.toBeNull();
    expect(lines[1]).toMatch(
      /^8 Avanti sensors paired \(1, 2, 3, 4, 5, 6, 7, 8\); after START it streams EMG at 1925\.926 Hz \(26 samples × 16 float32 every 13\.5 ms/,
    );

    // A receiver for the Sender, so that nothing is refused.
    const rx = createSocket("udp4");
    let datagrams = 0;
    rx.on("message", () => datagrams++);
    await new Promise<void>((r) => rx.bind(0, "127.0.0.1", r));
    cleanup.push(() => void rx.close());
    const dir = tempDir("mosaic-delsys-");
    const file = join(dir, "delsys.yaml");
    writeFileSync(
      file,
      readFileSync(join(ROOT, "pipelines/devices/delsys.yaml"), "utf8")
        .replace("Port: 50040", `Port: ${m![1]}`)
        .replace("EmgPort: 50043", `EmgPort: ${m![2]}`)
        .replace("AuxPort: 50044", `AuxPort: ${m![3]}`)
        .replace("Port: 50514", `Port: ${rx.address().port}`),
    );
    const r = runCli(["run", file, "--duration", "3", "--json"], { timeoutMs: 60_000 });
    expect(r.code, r.stderr).toBe(0);
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as
      { blocks: { name: string; events: number; rate?: number }[] } | undefined;
    expect(summary, r.stdout.slice(-2000)).toBeDefined();
    const delsys = summary!.blocks.find((b) => b.name === "Delsys")!;
    // 3 s at 1925.926 Hz, less the connection's first moments.
    expect(delsys.events).toBeGreaterThan(1925.926 * 2);
    expect(delsys.events).toBeLessThan(1925.926 * 3.2);
    expect(summary!.blocks.find((b) => b.name === "Control")!.events).toBeGreaterThan(40);
    // The receiver's datagrams waited in its socket while runCli blocked this process.
    await until(() => datagrams > 100, "the Sender's datagrams");
    sim.kill("SIGINT");
    const code = await new Promise<number | null>((res) => sim.on("exit", (c) => res(c)));
    expect(code).toBe(0);
  }, 90_000);

  test("mosaic simulate: a missing or unknown device, a bad option and a taken port are one line each", async () => {
    requireBuild();
    const none = runCli(["simulate"]);
    expect(none.code).toBe(2);
    expect(none.stderr.trim()).toMatch(
      /^usage: mosaic simulate DEVICE \[options\] \(devices: delsys(, [a-z-]+)+\)$/,
    );
    const other = runCli(["simulate", "myo"]);
    expect(other.code).toBe(2);
    expect(other.stderr.trim()).toMatch(
      /^mosaic simulate: no simulator for 'myo' \(devices: delsys(, [a-z-]+)+\)$/,
    );
    const bad = runCli(["simulate", "delsys", "--sensors", "1,17"]);
    expect([bad.code, bad.stderr.trim()]).toEqual([
      2,
      "mosaic simulate delsys: sensor 17 is not a Trigno sensor number (1…16)",
    ]);
    const taken = createServer();
    await new Promise<void>((r) => taken.listen(0, "127.0.0.1", r));
    cleanup.push(() => void taken.close());
    const port = (taken.address() as { port: number }).port;
    const busy = runCli(["simulate", "delsys", "--command-port", String(port)]);
    expect(busy.code).toBe(1);
    expect(busy.stderr.trim()).toBe(
      `mosaic simulate delsys: port ${port} on 127.0.0.1 is already in use (EADDRINUSE): is a Trigno Control Utility or another simulator running? Choose other ports`,
    );
    expect(runCli(["--help"]).stdout).toMatch(/mosaic simulate delsys \[--sensors N\|LIST\]/);
  }, 60_000);

  test("the example runs under --simulate-devices (the Trigno becomes an EmgSimulator at 1925.926 Hz)", () => {
    requireBuild();
    const r = runCli(
      [
        "run",
        "pipelines/devices/delsys.yaml",
        "--simulate-devices",
        "--clock",
        "virtual",
        "--duration",
        "2",
        "--json",
      ],
      { timeoutMs: 60_000 },
    );
    expect(r.code, r.stderr).toBe(0);
    expect(r.stderr + r.stdout).toMatch(
      /block 'Delsys' \(Delsys\) simulated by EmgSimulator, 32 channels at 1925\.926 Hz \(a new ScheduledTimer at the Trigno's native rate\)/,
    );
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as {
      blocks: { name: string; events: number }[];
    };
    const events = summary.blocks.find((b) => b.name === "Delsys")!.events;
    expect(Math.abs(events - 2 * 1925.926)).toBeLessThan(2);
  }, 90_000);
});
