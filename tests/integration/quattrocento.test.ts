/**
 * The Quattrocento block against the simulator (app/devices/quattrocento-simulator.ts) on
 * loopback TCP with ephemeral ports, through the real Node TCP bridge: the 40-byte command as the
 * device reads it, values exact end to end (raw and mV, the connectors in order, Select) at the
 * commanded rate, the stop command; a simulator killed and restarted on the same port (reported,
 * recovered), stray bytes, skipped samples and a truncated sample counted; refused, silent and
 * no-TCP statuses and configuration errors. The simulator alone on a raw socket: a bad CRC is
 * refused and nothing streams. Then the CLI: `mosaic simulate quattrocento` as a child process
 * with `mosaic run pipelines/devices/quattrocento.yaml` against it, and the example under
 * `--simulate-devices`.
 */
import { readFileSync, writeFileSync } from "node:fs";
import { createConnection, createServer, type Socket } from "node:net";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import { Quattrocento } from "../../app/blocks/devices/quattrocento";
import { crc8 } from "../../app/blocks/devices/muovi-protocol";
import {
  AUX_MV_PER_BIT,
  DEFAULT_INPUT,
  EMG_MV_PER_BIT,
  quattrocentoCommand,
} from "../../app/blocks/devices/quattrocento-protocol";
import {
  QuattrocentoSimulator,
  quattrocentoRaw,
  readQuattrocentoCommand,
} from "../../app/devices/quattrocento-simulator";
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
  until as waitUntil,
  expectDeviceStamps,
} from "./helpers";

/** Waits longer than the shared default: these devices take longer to connect under load. */
const until = (ok: () => boolean, what: string, ms = 8000) => waitUntil(ok, what, ms);

const cleanup: (() => void | Promise<void>)[] = [];
afterEach(async () => {
  for (const c of cleanup.splice(0).reverse()) await c();
});

async function simulator(seed = 1, port = 0): Promise<QuattrocentoSimulator> {
  const sim = await QuattrocentoSimulator.start({ port, seed });
  cleanup.push(() => sim.close());
  return sim;
}

/** A loopback port nothing listens on now. */
async function freePort(): Promise<number> {
  const s = createServer();
  await new Promise<void>((r) => s.listen(0, "127.0.0.1", r));
  const port = (s.address() as { port: number }).port;
  await new Promise<void>((r) => s.close(() => r()));
  return port;
}

/** The block in a harness whose clock follows the wall clock and fires its one-shot when due. */
async function harness(params: Record<string, unknown>, io = true) {
  const h = await BlockHarness.create(Quattrocento, params, {
    ...(io ? { io: { tcp: nodeTcpBridge() } } : {}),
    now: wall(),
    virtual: false,
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

const emitted = (h: BlockHarness) => ({ v: h.output("emg").v, t: h.output("emg").t });
const counts = (h: BlockHarness) => String(h.instance.actions!.counts!.run());

/** The sample k whose first output value is `first` (channel `wire` × scale), up to `upTo`. */
function findK(row: number[], want: (k: number) => number[], upTo: number): number {
  for (let k = 0; k <= upTo; k++) {
    const w = want(k);
    if (w.every((x, i) => x === row[i])) return k;
  }
  return -1;
}

describe("Quattrocento against the simulator", () => {
  test("the command as the device reads it, then every sample exact (raw) at 2048 Hz; stop on close", async () => {
    const sim = await simulator(7);
    const h = await harness({
      Host: "127.0.0.1",
      Port: sim.port,
      Connectors: ["IN2", "MULTIPLE IN1", "AUX IN"],
      Unit: "raw",
      Settings: { IN2: { Muscle: 16, Side: "left", HighPass: 0.7 } },
    });
    expect(h.desiredRate).toBe(2048);
    h.start();
    await until(() => emitted(h).v.length >= 300, "300 samples");
    expect(sim.commands).toHaveLength(1);
    expect(sim.commands[0]).toMatchObject({
      acquire: true,
      decimator: true,
      recording: false,
      rate: 2048,
      nch: 0,
      channels: 120,
    });
    // IN2's bytes: muscle 16; sensor/adapter 0; left (01), 0.7 Hz (00), 500 Hz (01), monopolar.
    expect(sim.commands[0]!.settings.slice(5, 8)).toEqual([16, 0, 0b01_00_01_00]);
    expect(h.text).toMatch(
      /^streaming 96 of 120 channels at 2048 Hz from the Quattrocento at 127\.0\.0\.1:\d+ · [\d,]+ samples$/,
    );
    // Output: IN2 (wire 16…31), MULTIPLE IN1 (32…95), AUX IN (96…111): 96 channels.
    const wires = [
      ...Array.from({ length: 16 }, (_, i) => 16 + i),
      ...Array.from({ length: 64 }, (_, i) => 32 + i),
      ...Array.from({ length: 16 }, (_, i) => 96 + i),
    ];
    const want = (k: number) => wires.map((w) => quattrocentoRaw(7, 0, w, k));
    const { v, t } = emitted(h);
    const k0 = findK(v[0]!, want, sim.samples);
    expect(k0).toBeGreaterThanOrEqual(0);
    for (let i = 0; i < 300; i++) {
      expect(v[i], `sample ${i}`).toEqual(want(k0 + i));
    }
    expectDeviceStamps(t, 2048, 300);
    expect(String(h.instance.actions!.channels!.run())).toMatch(
      /^channel 1: IN2\/1 \(int16\); .*channel 17: MULTIPLE IN1\/1 \(int16\); .*channel 96: AUX IN\/16 \(int16\)$/,
    );
    h.instance.stop!();
    await until(() => sim.stops === 1, "the stop command");
    expect(sim.refused).toEqual([]);
  });

  test("408 channels at 10240 Hz: Select picks channels in mV, exact; the commanded rate", async () => {
    const sim = await simulator(3);
    const h = await harness({
      Host: "127.0.0.1",
      Port: sim.port,
      Rate: 10240,
      Decimator: false,
      Connectors: ["IN8", "MULTIPLE IN4", "AUX IN"],
      Select: [1, 16, 17, 80, 81, 96],
      Trigger: true,
    });
    expect(h.desiredRate).toBe(10240);
    h.start();
    await until(() => emitted(h).v.length >= 2000, "2000 samples");
    expect(sim.commands[0]).toMatchObject({
      rate: 10240,
      nch: 3,
      channels: 408,
      decimator: false,
      recording: true,
    });
    // IN8 at 112, MULTIPLE IN4 at 128 + 192 = 320, AUX IN at 384.
    const picks: [number, number][] = [
      [112, EMG_MV_PER_BIT],
      [127, EMG_MV_PER_BIT],
      [320, EMG_MV_PER_BIT],
      [383, EMG_MV_PER_BIT],
      [384, AUX_MV_PER_BIT],
      [399, AUX_MV_PER_BIT],
    ];
    const want = (k: number) => picks.map(([w, s]) => quattrocentoRaw(3, 3, w, k, true) * s);
    const { v, t } = emitted(h);
    const k0 = findK(v[0]!, want, sim.samples);
    expect(k0).toBeGreaterThanOrEqual(0);
    for (let i = 0; i < 2000; i++) {
      expect(v[i], `sample ${i}`).toEqual(want(k0 + i));
    }
    expectDeviceStamps(t, 10240, 2000);
    // Every sample the simulator sent arrives, none skipped or malformed.
    const sent = sim.samples;
    await until(() => emitted(h).v.length + k0 >= sent, "the samples sent so far");
    expect(counts(h)).toMatch(/, 0 skipped by the device, .*0 malformed \(0 bytes skipped\)/);
  });

  test("a simulator killed and restarted on the same port: reported, reconnected, streaming again", async () => {
    const first = await QuattrocentoSimulator.start({ port: 0, seed: 5 });
    const port = first.port;
    const h = await harness({ Host: "127.0.0.1", Port: port, Connectors: ["IN1"] });
    h.start();
    await until(() => /^streaming/.test(h.text), "streaming");
    await first.close();
    await until(
      () => /^lost the Quattrocento at 127\.0\.0\.1:\d+: the connection ended/.test(h.text),
      "lost",
    );
    expect(h.warnings.some((w) => /lost the Quattrocento at .*; reconnecting/.test(w))).toBe(true);
    await until(() => /^(still lost|connecting)/.test(h.text), "retrying");
    const again = await simulator(5, port);
    const before = emitted(h).v.length;
    await until(() => /^streaming .* · reconnected 1×/.test(h.text), "streaming again");
    await until(() => emitted(h).v.length > before + 500, "500 samples more");
    expect(again.commands).toHaveLength(1);
    // The restarted device counts from 0 again: its samples are exact too.
    const v = emitted(h).v;
    const last = v[v.length - 1]!;
    const want = (k: number) =>
      Array.from({ length: 16 }, (_, c) => quattrocentoRaw(5, 0, c, k) * EMG_MV_PER_BIT);
    expect(findK(last, want, again.samples)).toBeGreaterThan(0);
  });

  test("stray bytes, skipped samples and a truncated sample: counted, never a crash, recovered", async () => {
    const sim = await simulator(9);
    const h = await harness({ Host: "127.0.0.1", Port: sim.port, Connectors: ["MULTIPLE IN1"] });
    h.start();
    await until(() => /^streaming/.test(h.text), "streaming");

    sim.inject(Uint8Array.of(1, 2, 3, 4, 5));
    await until(() => /1 malformed \(5 bytes skipped/.test(counts(h)), "the malformed bytes");
    await until(() => / · 1 malformed \(5 bytes skipped\)/.test(h.text), "the status");
    expect(h.warnings.some((w) => /malformed data from the Quattrocento/.test(w))).toBe(true);

    sim.skip(100);
    await until(() => /, 100 skipped by the device/.test(counts(h)), "the skipped samples");
    await until(() => / · 100 samples skipped by the device/.test(h.text), "the status");

    sim.truncate();
    await until(() => /1 truncated/.test(counts(h)), "the truncated sample");
    await until(() => /reconnected 1×/.test(h.text), "streaming after the truncation");
    const n = emitted(h).v.length;
    await until(() => emitted(h).v.length > n + 200, "samples after the truncation");
    expect(counts(h)).toMatch(
      /1 malformed \(5 bytes skipped, last: .*\), 1 truncated \(\d+ bytes\)$/,
    );
  });

  test("unreachable, silent and no-TCP statuses; configuration errors name the param", async () => {
    const port = await freePort();
    const h = await harness({ Host: "127.0.0.1", Port: port });
    h.start();
    await until(() => /^not reachable/.test(h.text), "refused");
    expect(h.text).toBe(
      `not reachable: nothing is listening at 127.0.0.1:${port} (ECONNREFUSED): start the server there, or check Host and Port; retrying in 0.5 s (attempt 2)`,
    );
    expect(h.warnings[0]).toMatch(
      /the Quattrocento at 127\.0\.0\.1:\d+ not reachable: .*; retrying until it answers \(connect this computer to the Quattrocento's Ethernet port.*mosaic simulate quattrocento\)$/,
    );

    const silent = createServer(() => {});
    await new Promise<void>((r) => silent.listen(0, "127.0.0.1", r));
    cleanup.push(() => void silent.close());
    const port2 = (silent.address() as { port: number }).port;
    const s = await harness({ Host: "127.0.0.1", Port: port2 });
    s.start();
    await until(() => /^configured/.test(s.text), "configured");
    await until(() => /^not reachable: no data for 2 s/.test(s.text), "silence");

    const b = await harness({}, false);
    b.start();
    expect(b.text).toBe("TCP not available in the browser build; use --simulate-devices");
    expect(b.warnings[0]).toMatch(/the Quattrocento at 169\.254\.1\.10:23456 cannot be reached/);

    await expect(harness({ Connectors: ["IN5"], Channels: 216 })).rejects.toThrow(
      /216 channels do not carry IN5: they need 312 or more/,
    );
    await expect(harness({ Connectors: ["IN1"], Select: [17] })).rejects.toThrow(
      /channel 17 is not among the 16 channels of IN1/,
    );
    await expect(harness({ Rate: 1000 })).rejects.toThrow(/Rate/);
  });
});

describe("the simulator alone", () => {
  test("reads what the block sends; a bad CRC or fixed bit is refused", () => {
    const c = {
      rate: 10240 as const,
      nch: 1,
      decimator: true,
      recording: true,
      analogOut: { source: "IN1" as const, channel: 0, gain: 1 as const },
      inputs: Array.from({ length: 12 }, () => DEFAULT_INPUT),
    };
    const cmd = quattrocentoCommand(c, true);
    const r = readQuattrocentoCommand(cmd);
    expect("request" in r && r.request).toMatchObject({
      acquire: true,
      decimator: true,
      recording: true,
      rate: 10240,
      nch: 1,
      channels: 216,
    });
    const bad = Uint8Array.from(cmd);
    bad[39]! ^= 0x10;
    expect(readQuattrocentoCommand(bad)).toEqual({
      error: `CRC-8 ${bad[39]} where ${cmd[39]} was due`,
    });
    const fixed = Uint8Array.from(cmd);
    fixed[0] = cmd[0]! & 0x7f;
    fixed[39] = crc8(fixed, 39);
    expect(readQuattrocentoCommand(fixed)).toEqual({
      error: `ACQ_SETT ${fixed[0]}: bit 7 must be 1`,
    });
  });

  test("a bad CRC is refused and nothing streams; a good command streams; acquisition off stops", async () => {
    const sim = await simulator(2);
    const got: number[] = [];
    const s: Socket = createConnection({ host: "127.0.0.1", port: sim.port });
    s.on("data", (d) => got.push(...d));
    cleanup.push(() => void s.destroy());
    await new Promise<void>((r) => s.once("connect", () => r()));
    const c = {
      rate: 512 as const,
      nch: 0,
      decimator: false,
      recording: false,
      analogOut: { source: "IN1" as const, channel: 0, gain: 1 as const },
      inputs: Array.from({ length: 12 }, () => DEFAULT_INPUT),
    };
    const bad = quattrocentoCommand(c, true);
    bad[39]! ^= 1;
    s.write(bad);
    await until(() => sim.refused.length === 1, "the refusal");
    expect(sim.refused[0]).toMatch(/^CRC-8 \d+ where \d+ was due$/);
    await sleep(50);
    expect(got).toEqual([]);

    s.write(quattrocentoCommand(c, true));
    const S = 120 * 2;
    await until(() => got.length >= 20 * S, "20 samples");
    const b = Buffer.from(got);
    for (let k = 0; k < 20; k++) {
      for (let ch = 0; ch < 120; ch++) {
        expect(b.readInt16LE(k * S + 2 * ch)).toBe(quattrocentoRaw(2, 0, ch, k));
      }
    }
    expect(b.readUInt16LE(19 * S + 2 * 112)).toBe(19);
    s.write(quattrocentoCommand(c, false));
    await until(() => sim.stops === 1, "the stop");
    await sleep(30);
    const n = got.length;
    await sleep(60);
    expect(got.length).toBe(n);
    expect(n % S).toBe(0);
  });
});

describe("mosaic simulate quattrocento + mosaic run", () => {
  test("pipelines/devices/quattrocento.yaml runs against the simulator as a child process", async () => {
    requireBuild();
    const sim = startCli(["simulate", "quattrocento", "--port", "0", "--seed", "4", "--verbose"]);
    cleanup.push(() => void sim.kill("SIGINT"));
    const lines: string[] = [];
    createInterface({ input: sim.stdout! }).on("line", (l) => lines.push(l));
    await until(() => lines.length >= 2, "the simulator's banner", 15_000);
    const m = /Quattrocento simulator listening on 127\.0\.0\.1:(\d+)/.exec(lines[0]!);
    expect(m, lines.join("\n")).not.toBeNull();
    const dir = tempDir("mosaic-quattrocento-");
    const file = join(dir, "quattrocento.yaml");
    writeFileSync(
      file,
      readFileSync(join(ROOT, "pipelines/devices/quattrocento.yaml"), "utf8")
        .replace("Host: 169.254.1.10", "Host: 127.0.0.1")
        .replace("Port: 23456", `Port: ${m![1]}`),
    );
    const r = runCli(["run", file, "--duration", "3", "--json"], { timeoutMs: 60_000 });
    expect(r.code, r.stderr).toBe(0);
    const out = jsonLines(r.stdout);
    const summary = out.find((l) => l.type === "summary") as
      { blocks: { name: string; events: number; text: string }[] } | undefined;
    expect(summary, r.stdout.slice(-2000)).toBeDefined();
    const warnings = out.filter((l) => l.type === "event" && l.level === "warning");
    expect(warnings.filter((w) => /not reachable|malformed/.test(String(w.message)))).toEqual([]);
    const amp = summary!.blocks.find((b) => b.name === "Amplifier")!;
    // 3 s at 2048 Hz, less the connection's first moments.
    expect(amp.events).toBeGreaterThan(2048 * 2.5);
    expect(summary!.blocks.find((b) => b.name === "Envelope25")!.events).toBeGreaterThan(50);
    sim.kill("SIGINT");
    const code = await new Promise<number | null>((res) => sim.on("exit", (c) => res(c)));
    expect(code).toBe(0);
    expect(lines.join("\n")).toMatch(/acquisition on: streaming 120 channels at 2048 Hz/);
    expect(lines.join("\n")).toMatch(/acquisition off: streaming stopped/);
  }, 90_000);

  test("the example runs under --simulate-devices; simulate's option errors are one line", () => {
    requireBuild();
    const r = runCli(
      [
        "run",
        "pipelines/devices/quattrocento.yaml",
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
      /block 'Amplifier' \(Quattrocento\) simulated by EmgSimulator, 96 channels at 2048 Hz/,
    );
    const port = runCli(["simulate", "quattrocento", "--port", "x"]);
    expect([port.code, port.stderr.trim()]).toEqual([
      2,
      "mosaic simulate quattrocento: --port must be a port number (0 for any free port), not 'x'",
    ]);
  }, 60_000);
});
