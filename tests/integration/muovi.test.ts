/**
 * The Muovi (SyncStation) and MuoviSingleProbe blocks against the simulators
 * (app/devices/muovi-simulator.ts) on loopback TCP with ephemeral ports, through the real Node TCP
 * bridge: values exact end to end (the original's raw / 32768 averages, and mV matrices), the start
 * and stop commands as the device gets them, a dropped connection reported and recovered, malformed
 * bytes, a counter that skips and a truncated sample counted, refused/silent/no-TCP statuses. Then
 * the CLI: `mosaic simulate syncstation` as a child process and `mosaic run` of
 * pipelines/devices/muovi.yaml against it, and `mosaic simulate muovi --connect` against a
 * MuoviSingleProbe pipeline.
 */
import { readFileSync, writeFileSync } from "node:fs";
import { connect, createServer } from "node:net";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import { Muovi } from "../../app/blocks/devices/muovi";
import { MuoviSingleProbe } from "../../app/blocks/devices/muovi-single-probe";
import { crc8 } from "../../app/blocks/devices/muovi-protocol";
import {
  crc8Table,
  MuoviProbeSimulator,
  muoviRaw,
  SyncStationSimulator,
} from "../../app/devices/muovi-simulator";
import { EMPTY_SHAPE, Frame } from "../../app/engine";
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
  expectDeviceStamps,
} from "./helpers";

const cleanup: (() => void | Promise<void>)[] = [];
afterEach(async () => {
  for (const c of cleanup.splice(0).reverse()) await c();
});

async function syncStation(seed = 1): Promise<SyncStationSimulator> {
  const sim = await SyncStationSimulator.start({ port: 0, seed });
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

/** A block in a harness whose clock follows the wall clock and fires its one-shot when due. */
async function harness(
  def: typeof Muovi | typeof MuoviSingleProbe,
  params: Record<string, unknown>,
  timerRate: number | undefined,
  io = true,
) {
  const h = await BlockHarness.create(def, params, {
    ...(io ? { io: { tcp: nodeTcpBridge() } } : {}),
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

let tickAt = 1000;
/** n timer ticks into the block; returns the rows it emitted for them. */
function ticks(h: BlockHarness, n: number): number[][] {
  const before = h.output("emg").v.length;
  const times = Array.from({ length: n }, () => (tickAt += 0.0005));
  h.push(
    Frame.from(
      EMPTY_SHAPE,
      times,
      times.map(() => []),
    ),
  );
  return h.output("emg").v.slice(before);
}

const counts = (h: BlockHarness) => String(h.instance.actions!.counts!.run());

/** The samples a paced device's status text reports ("stopped · 5,960 samples"). */
const samplesIn = (text: string): number =>
  Number((/([\d,]+) samples?/.exec(text)?.[1] ?? "0").replace(/,/g, ""));

/** The sample k whose 32 EMG values of `slot` divided by 32768 are `row` (the first 32 values). */
function findK(row: number[], seed: number, slot: number, upTo: number): number {
  for (let k = 0; k <= upTo; k++) {
    let ok = true;
    for (let c = 0; c < 32 && ok; c++) ok = row[c] === muoviRaw(seed, slot, c, k) / 32768 / 1;
    if (ok) return k;
  }
  return -1;
}

describe("Muovi through a SyncStation", () => {
  test("the start command, then values exact at 2 kHz in the order of Probes; stop on close", async () => {
    const sim = await syncStation(7);
    const h = await harness(Muovi, { Probes: [2, 0], Host: "127.0.0.1", Port: sim.port }, 2000);
    h.start();
    await until(() => /^streaming 2 Muovi probes/.test(h.text), "streaming");
    expect(sim.commands).toEqual([
      {
        go: true,
        probes: [
          { slot: 0, emg: true, mode: 0 },
          { slot: 2, emg: true, mode: 0 },
        ],
      },
    ]);
    // Enough samples queued for 60 ticks (the newest 81 wait), however loaded the machine.
    await until(() => sim.samples >= 120, "120 samples sent");
    await sleep(20);
    const rows = ticks(h, 60);
    expect(rows).toHaveLength(60);
    const k0 = findK(rows[0]!, 7, 2, sim.samples);
    expect(k0).toBeGreaterThanOrEqual(0);
    for (let i = 0; i < 60; i++) {
      const expected = [
        ...Array.from({ length: 32 }, (_, c) => muoviRaw(7, 2, c, k0 + i) / 32768 / 1),
        ...Array.from({ length: 32 }, (_, c) => muoviRaw(7, 0, c, k0 + i) / 32768 / 1),
      ];
      expect(rows[i], `row ${i}`).toEqual(expected);
    }
    h.instance.stop!();
    await until(() => sim.stops === 1, "the stop command");
    expect(sim.refused).toEqual([]);
  });

  test("at 200 Hz each tick is the mean of 10 raw samples, as the original computed it", async () => {
    const sim = await syncStation(3);
    const h = await harness(Muovi, { Probes: [1], Host: "127.0.0.1", Port: sim.port }, 200);
    h.start();
    await until(() => /^streaming 1 Muovi probe /.test(h.text), "streaming");
    await until(() => sim.samples >= 100, "100 samples sent");
    await sleep(20);
    const rows = ticks(h, 5);
    const mean = (k: number, c: number): number => {
      let acc = 0;
      for (let z = 0; z < 10; z++) acc += muoviRaw(3, 1, c, k + z) / 32768 / 10;
      return acc;
    };
    let k0 = -1;
    for (let k = 0; k <= sim.samples && k0 < 0; k++) {
      if (rows[0]![0] === mean(k, 0) && rows[0]![31] === mean(k, 31)) k0 = k;
    }
    expect(k0 % 10).toBe(0);
    for (let i = 0; i < 5; i++) {
      expect(rows[i]).toEqual(Array.from({ length: 32 }, (_, c) => mean(k0 + 10 * i, c)));
    }
  });

  test("dropped connection, malformed bytes, skipped samples and a truncated sample: counted, recovered", async () => {
    const sim = await syncStation(5);
    const h = await harness(Muovi, { Probes: [0], Host: "127.0.0.1", Port: sim.port }, 2000);
    h.start();
    await until(() => /^streaming/.test(h.text), "streaming");

    sim.inject(Uint8Array.of(1, 2, 3, 4, 5, 6, 7));
    await until(() => /1 malformed \(7 bytes skipped/.test(counts(h)), "the malformed bytes");
    expect(h.text).toMatch(/ · 1 malformed \(7 bytes skipped\)/);
    expect(h.warnings.some((w) => /malformed data from the SyncStation/.test(w))).toBe(true);

    sim.skip(50);
    await until(() => /, 50 skipped by the device/.test(counts(h)), "the skipped samples");
    expect(h.text).toMatch(/ · 50 samples skipped by the device/);

    sim.dropConnections();
    await until(() => /^lost the SyncStation at 127\.0\.0\.1:\d+: /.test(h.text), "lost");
    expect(h.text).toMatch(/; retrying in 0\.5 s \(attempt 2\)( · |$)/);
    expect(ticks(h, 2)).toEqual([new Array(32).fill(0), new Array(32).fill(0)]);
    await until(() => /^streaming/.test(h.text), "streaming again");
    expect(h.text).toMatch(/reconnected 1×/);
    expect(sim.commands).toHaveLength(2);

    sim.truncate();
    await until(() => /1 truncated/.test(counts(h)), "the truncated sample");
    await until(() => /reconnected 2×/.test(h.text), "streaming after the truncation");
    await sleep(30);
    const after = ticks(h, 20);
    expect(after.every((r) => r.some((v) => v !== 0))).toBe(true);
    expect(counts(h)).toMatch(
      /1 malformed \(7 bytes skipped, last: .*\), 1 truncated \(\d+ bytes\)$/,
    );
  });

  test("refused, silent and no-TCP statuses say what happens and what to do", async () => {
    const port = await freePort();
    const h = await harness(Muovi, { Probes: [0], Host: "127.0.0.1", Port: port }, 100);
    h.start();
    await until(() => /^not reachable/.test(h.text), "refused");
    expect(h.text).toBe(
      `not reachable: nothing is listening at 127.0.0.1:${port} (ECONNREFUSED): start the server there, or check Host and Port; retrying in 0.5 s (attempt 2)`,
    );
    expect(h.warnings).toEqual([
      `Muovi: the SyncStation at 127.0.0.1:${port} not reachable: nothing is listening at 127.0.0.1:${port} (ECONNREFUSED): start the server there, or check Host and Port; retrying until it answers (join the SyncStation's Wi-Fi; without the device: mosaic run --simulate-devices, or a simulated SyncStation: mosaic simulate syncstation)`,
    ]);
    await until(() => /retrying in 1 s \(attempt 3\)/.test(h.text), "the second retry");

    // A server that accepts and sends nothing: lost after 2 s of silence.
    const silent = createServer(() => {});
    await new Promise<void>((r) => silent.listen(0, "127.0.0.1", r));
    cleanup.push(() => void silent.close());
    const port2 = (silent.address() as { port: number }).port;
    const s = await harness(Muovi, { Probes: [0], Host: "127.0.0.1", Port: port2 }, 100);
    s.start();
    await until(() => /^configured/.test(s.text), "configured");
    await until(() => /^not reachable/.test(s.text), "silence", 4000);
    expect(s.text).toBe("not reachable: no data for 2 s; retrying in 0.5 s (attempt 2)");

    // No TCP bridge (the browser build); a slot that is not a Muovi's.
    const b = await harness(Muovi, { Probes: [0] }, 100, false);
    b.start();
    expect(b.text).toBe("TCP not available in the browser build; use --simulate-devices");
    expect(b.warnings[0]).toMatch(/the SyncStation at 192\.168\.76\.1:54320 cannot be reached/);
    await expect(harness(Muovi, { Probes: [4] }, 100)).rejects.toThrow(
      /probe index 4 is not a Muovi slot of the SyncStation \(0…3/,
    );
  });

  test("the simulator reads the command with a table CRC that equals the block's bitwise one", () => {
    for (let n = 0; n < 300; n++) {
      const msg = Array.from({ length: 1 + (n % 6) }, (_, i) => (n * 31 + i * 97) & 255);
      expect(crc8Table(msg)).toBe(crc8(msg));
    }
  });
});

describe("without an input: the device's 2000 Hz, as it delivers", () => {
  /** Rows and stamps emitted so far. */
  const emitted = (h: BlockHarness) => ({ v: h.output("emg").v, t: h.output("emg").t });

  test("Muovi: every sample in order, raw / 32768, stamped 1 / 2000 s apart", async () => {
    const sim = await syncStation(2);
    const h = await harness(
      Muovi,
      { Probes: [1, 3], Host: "127.0.0.1", Port: sim.port },
      undefined,
    );
    expect(h.desiredRate).toBe(2000);
    h.start();
    await until(() => emitted(h).v.length >= 200, "200 samples");
    const { v, t } = emitted(h);
    const k0 = findK(v[0]!, 2, 1, sim.samples);
    expect(k0).toBeGreaterThanOrEqual(0);
    for (let i = 0; i < 200; i++) {
      const want = [
        ...Array.from({ length: 32 }, (_, c) => muoviRaw(2, 1, c, k0 + i) / 32768),
        ...Array.from({ length: 32 }, (_, c) => muoviRaw(2, 3, c, k0 + i) / 32768),
      ];
      const bad = want.flatMap((w, c) => (w === v[i]![c] ? [] : [`${c}: ${v[i]![c]} vs ${w}`]));
      expect(bad, `sample ${i}`).toEqual([]);
    }
    expectDeviceStamps(t, 2000, 200);
    expect(h.text).toMatch(/^streaming 2 Muovi probes .* · [\d,]+ samples$/);
  });

  test("MuoviSingleProbe: every sample in order, in mV; a reconnection re-anchors the clock", async () => {
    const port = await freePort();
    const h = await harness(MuoviSingleProbe, { Probes: [0], Port: port }, undefined);
    h.start();
    await until(() => /^waiting/.test(h.text), "listening");
    const p = new MuoviProbeSimulator({ host: "127.0.0.1", port, seed: 4, retry: 0.2 });
    cleanup.push(() => p.close());
    await until(() => emitted(h).v.length >= 100, "100 samples");
    const { v, t } = emitted(h);
    let k0 = -1;
    for (let k = 0; k <= p.samples && k0 < 0; k++) {
      if (
        v[0]![0] === muoviRaw(4, 0, 0, k) * 0.000286 &&
        v[0]![5] === muoviRaw(4, 0, 5, k) * 0.000286
      )
        k0 = k;
    }
    expect(k0).toBeGreaterThanOrEqual(0);
    for (let i = 0; i < 100; i++) {
      expect(v[i]).toEqual(
        Array.from({ length: 32 }, (_, c) => muoviRaw(4, 0, c, k0 + i) * 0.000286),
      );
    }
    expectDeviceStamps(t, 2000, 100);
    p.dropConnection();
    await until(() => /^lost/.test(h.text), "lost");
    const before = emitted(h).v.length;
    await until(() => emitted(h).v.length > before + 50, "samples again");
    expect(h.text).toMatch(/reconnected 1×/);
  });
});

describe("MuoviSingleProbe (the probe connects to this computer)", () => {
  async function probe(port: number, seed = 9) {
    const p = new MuoviProbeSimulator({ host: "127.0.0.1", port, seed, retry: 0.2 });
    cleanup.push(() => p.close());
    return p;
  }

  test("a new connection replaces the current one: the old socket is closed, what it sent is dropped", async () => {
    const port = await freePort();
    const h = await harness(MuoviSingleProbe, { Probes: [0], Port: port }, 200);
    h.start();
    await until(() => /^waiting for a Muovi probe/.test(h.text), "listening");
    // An old connection that sent half a sample and stays open.
    const old = connect({ host: "127.0.0.1", port });
    cleanup.push(() => void old.destroy());
    let oldClosed = false;
    old.on("data", () => {});
    old.on("end", () => (oldClosed = true));
    old.on("close", () => (oldClosed = true));
    old.on("error", () => (oldClosed = true));
    await new Promise<void>((r) => old.once("connect", () => r()));
    await until(() => /connected; started it/.test(h.text), "the old connection started");
    old.write(Buffer.alloc(10));
    await sleep(50);
    const p = await probe(port);
    await until(() => oldClosed, "the old connection closed by the block");
    await until(() => /^streaming 32 EMG channels/.test(h.text), "streaming from the new probe");
    expect(h.warnings.join("\n")).toMatch(/was replaced by a new connection from 127\.0\.0\.1:/);
    await until(() => p.samples >= 60, "60 samples sent");
    await sleep(20);
    const m = ticks(h, 1)[0]!;
    let k0 = -1;
    for (let k = 0; k <= p.samples && k0 < 0; k++) {
      if (m[0] === muoviRaw(9, 0, 0, k) * 0.000286 && m[1] === muoviRaw(9, 0, 1, k) * 0.000286) {
        k0 = k;
      }
    }
    expect(k0).toBeGreaterThanOrEqual(0);
  });

  test("listens, starts the probe with byte 9, matrices of exact mV; reconnection; stop byte 8", async () => {
    const port = await freePort();
    const h = await harness(MuoviSingleProbe, { Probes: [0], Port: port }, 200);
    h.start();
    await until(
      () => /^waiting for a Muovi probe to connect to port \d+/.test(h.text),
      "listening",
    );
    const p = await probe(port);
    await until(
      () =>
        /^streaming 32 EMG channels at 2000 Hz from the Muovi probe at 127\.0\.0\.1:\d+( · |$)/.test(
          h.text,
        ),
      "streaming",
    );
    expect(p.received).toEqual([9]);
    await until(() => p.samples >= 60, "60 samples sent");
    await sleep(20);
    const mats = ticks(h, 3);
    expect(mats).toHaveLength(3);
    expect(mats[0]).toHaveLength(10 * 32);
    let k0 = -1;
    for (let k = 0; k <= p.samples && k0 < 0; k++) {
      if (
        mats[0]![0] === muoviRaw(9, 0, 0, k) * 0.000286 &&
        mats[0]![1] === muoviRaw(9, 0, 1, k) * 0.000286
      )
        k0 = k;
    }
    expect(k0).toBeGreaterThanOrEqual(0);
    for (let m = 0; m < 3; m++) {
      const want: number[] = [];
      for (let r = 0; r < 10; r++) {
        for (let c = 0; c < 32; c++) want.push(muoviRaw(9, 0, c, k0 + 10 * m + r) * 0.000286);
      }
      expect(mats[m], `matrix ${m}`).toEqual(want);
    }

    p.inject(Uint8Array.of(0xde, 0xad, 0xbe));
    await until(() => /1 malformed \(3 bytes skipped/.test(counts(h)), "the malformed bytes");

    p.dropConnection();
    await until(
      () =>
        /^lost the Muovi probe at 127\.0\.0\.1:\d+: .*; waiting for it to connect again to port \d+( · |$)/.test(
          h.text,
        ),
      "lost",
    );
    await until(() => /^streaming .* · reconnected 1×/.test(h.text), "streaming again");
    expect(p.received).toEqual([9, 9]);
    expect(p.connections).toBe(2);

    h.instance.stop!();
    await until(() => p.received.length === 3, "the stop byte");
    expect(p.received[2]).toBe(8);
  });

  test("a port already in use, a probe that falls silent, further indices and no TCP", async () => {
    const taken = createServer();
    await new Promise<void>((r) => taken.listen(0, "0.0.0.0", r));
    cleanup.push(() => void taken.close());
    const port = (taken.address() as { port: number }).port;
    const h = await harness(MuoviSingleProbe, { Probes: [0, 1], Port: port }, 2000);
    expect(h.warnings).toEqual([
      "Muovi probe: one probe streams to this block; the 1 further index in Probes gives columns of zeros",
    ]);
    h.start();
    await until(() => /^not reachable/.test(h.text), "cannot listen");
    expect(h.text).toBe(
      `not reachable: cannot listen at 0.0.0.0:${port}: the port is in use (EADDRINUSE) — another program (or another block) listens there; choose another Port or stop it; listening again in 0.5 s (attempt 2)`,
    );

    // A peer that connects and sends nothing: dropped after 2 s, the block waits again.
    const port2 = await freePort();
    const s = await harness(MuoviSingleProbe, { Probes: [0], Port: port2 }, 2000);
    s.start();
    await until(() => /^waiting/.test(s.text), "listening");
    const { createConnection } = await import("node:net");
    const quiet = createConnection({ host: "127.0.0.1", port: port2 });
    const got: number[] = [];
    quiet.on("data", (d) => got.push(...d));
    quiet.on("error", () => {});
    cleanup.push(() => void quiet.destroy());
    await until(() => got.length === 1, "the start byte");
    expect(got).toEqual([9]);
    await until(
      () => /^not reachable: no data for 2 s; waiting for it to connect again/.test(s.text),
      "silence",
      4000,
    );

    const b = await harness(MuoviSingleProbe, { Probes: [0] }, 2000, false);
    b.start();
    expect(b.text).toBe("TCP not available in the browser build; use --simulate-devices");
  });
});

describe("mosaic simulate syncstation|muovi + mosaic run", () => {
  test("pipelines/devices/muovi.yaml runs against the SyncStation simulator as a child process", async () => {
    requireBuild();
    const sim = startCli(["simulate", "syncstation", "--port", "0", "--seed", "4", "--verbose"]);
    cleanup.push(() => void sim.kill("SIGINT"));
    const lines: string[] = [];
    createInterface({ input: sim.stdout! }).on("line", (l) => lines.push(l));
    await until(() => lines.length >= 2, "the simulator's banner", 15_000);
    const m = /SyncStation simulator listening on 127\.0\.0\.1:(\d+)/.exec(lines[0]!);
    expect(m, lines.join("\n")).not.toBeNull();
    const dir = tempDir("mosaic-muovi-");
    const file = join(dir, "muovi.yaml");
    writeFileSync(
      file,
      readFileSync(join(ROOT, "pipelines/devices/muovi.yaml"), "utf8")
        .replace("Host: 192.168.76.1", "Host: 127.0.0.1")
        .replace("Port: 54320", `Port: ${m![1]}`),
    );
    const r = runCli(["run", file, "--duration", "3", "--json"], { timeoutMs: 60_000 });
    expect(r.code, r.stderr).toBe(0);
    const out = jsonLines(r.stdout);
    const summary = out.find((l) => l.type === "summary") as
      { blocks: { name: string; events: number; text: string }[] } | undefined;
    expect(summary, r.stdout.slice(-2000)).toBeDefined();
    const warnings = out.filter((l) => l.type === "event" && l.level === "warning");
    expect(warnings.filter((w) => /not reachable|malformed/.test(String(w.message)))).toEqual([]);
    const probes = summary!.blocks.find((b) => b.name === "Probes")!;
    expect(probes.events).toBeGreaterThan(2000 * 2.8);
    // Samples received (not only ticks, which come with or without data): 3 s at 2 kHz, less
    // the connection's first moments.
    expect(samplesIn(probes.text)).toBeGreaterThan(2000 * 2.5);
    expect(summary!.blocks.find((b) => b.name === "Envelope25")!.events).toBeGreaterThan(50);
    sim.kill("SIGINT");
    const code = await new Promise<number | null>((res) => sim.on("exit", (c) => res(c)));
    expect(code).toBe(0);
    expect(lines.join("\n")).toMatch(/start command: Muovi slots 0, 1; streaming 82 channels/);
  }, 90_000);

  test("mosaic simulate muovi --connect: the probe connects to a MuoviSingleProbe pipeline", async () => {
    requireBuild();
    const port = await freePort();
    const dir = tempDir("mosaic-muovi-probe-");
    const file = join(dir, "probe.yaml");
    writeFileSync(
      file,
      [
        "Clock: { Type: ScheduledTimer, DesiredRate: 100 }",
        `Probe: { Type: MuoviSingleProbe, Inputs: [Clock], Params: { Probes: [0], Port: ${port} } }`,
        "",
      ].join("\n"),
    );
    const run = startCli(["run", file, "--duration", "4", "--json"]);
    cleanup.push(() => void run.kill("SIGINT"));
    const out: string[] = [];
    createInterface({ input: run.stdout! }).on("line", (l) => out.push(l));
    await sleep(1000);
    const sim = startCli(["simulate", "muovi", "--connect", `127.0.0.1:${port}`, "--verbose"]);
    cleanup.push(() => void sim.kill("SIGINT"));
    const lines: string[] = [];
    createInterface({ input: sim.stdout! }).on("line", (l) => lines.push(l));
    const code = await new Promise<number | null>((res) => run.on("exit", (c) => res(c)));
    expect(code, out.slice(-5).join("\n")).toBe(0);
    const summary = jsonLines(out.join("\n")).find((l) => l.type === "summary") as {
      blocks: { name: string; events: number; text: string }[];
    };
    const probe = summary.blocks.find((b) => b.name === "Probe")!;
    expect(probe.events).toBeGreaterThan(300);
    // The probe connects about 1 s into the 4 s run; the status counts matrices of 20 samples.
    expect(samplesIn(probe.text) * 20).toBeGreaterThan(2000 * 2);
    expect(lines.join("\n")).toMatch(/connected to 127\.0\.0\.1:\d+|Muovi probe simulator/);
    sim.kill("SIGINT");
    await new Promise<number | null>((res) => sim.on("exit", (c) => res(c)));
    expect(lines.join("\n")).toMatch(/command 9: streaming 38 channels at 2000 Hz/);
  }, 90_000);

  test("the example runs under --simulate-devices; simulate's option errors are one line", () => {
    requireBuild();
    const r = runCli(
      [
        "run",
        "pipelines/devices/muovi.yaml",
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
      /block 'Probes' \(Muovi\) simulated by EmgSimulator, 64 channels at 2000 Hz/,
    );
    // The native forms (no timer) become EmgSimulators on a new 2000 Hz timer.
    const dir = tempDir("mosaic-muovi-native-");
    const file = join(dir, "native.yaml");
    writeFileSync(
      file,
      "Probes: { Type: Muovi, Params: { Probes: [0, 1] } }\nProbe: { Type: MuoviSingleProbe }\n",
    );
    const v = runCli(["validate", "--simulate-devices", file]);
    expect(v.code, v.stderr).toBe(0);
    expect(v.stdout + v.stderr).toMatch(
      /block 'Probes' \(Muovi\) simulated by EmgSimulator, 64 channels at 2000 Hz \(a new ScheduledTimer/,
    );
    expect(v.stdout + v.stderr).toMatch(
      /block 'Probe' \(MuoviSingleProbe\) simulated by EmgSimulator, 32 channels at 2000 Hz \(a new ScheduledTimer/,
    );
    const bad = runCli(["simulate", "muovi"]);
    expect([bad.code, bad.stderr.trim()]).toEqual([
      2,
      "mosaic simulate muovi: --connect HOST:PORT is required (where a MuoviSingleProbe block listens, e.g. --connect 127.0.0.1:54321)",
    ]);
    const port = runCli(["simulate", "syncstation", "--port", "x"]);
    expect([port.code, port.stderr.trim()]).toEqual([
      2,
      "mosaic simulate syncstation: --port must be a port number (0 for any free port), not 'x'",
    ]);
  }, 60_000);
});
