/**
 * The Sessantaquattro block against its simulator (app/devices/sessantaquattro-simulator.ts) on
 * loopback TCP, through the real Node TCP bridge: the block listens, the simulated device
 * connects, gets the command word and streams; values exact end to end (mV and raw, 16 and 24
 * bits, Sessantaquattro and Sessantaquattro+), stamps 1 / rate apart and the commanded rate, the
 * stop word, a simulator killed and restarted reported and recovered, malformed bytes, skipped
 * samples and a truncated sample counted, a taken port and no TCP said clearly. Then the CLI:
 * `mosaic simulate sessantaquattro --connect` against pipelines/devices/sessantaquattro.yaml, and
 * the example under --simulate-devices.
 */
import { readFileSync, writeFileSync } from "node:fs";
import { createServer } from "node:net";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import { Sessantaquattro } from "../../app/blocks/devices/sessantaquattro";
import {
  commandWord,
  SessantaquattroStreamParser,
  wireLayout,
} from "../../app/blocks/devices/sessantaquattro-protocol";
import {
  configOf,
  encodeSamples,
  sessantaquattroRaw,
  SessantaquattroSimulator,
  simLayout,
  type SimConfig,
} from "../../app/devices/sessantaquattro-simulator";
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

/** A loopback port nothing listens on now. */
async function freePort(): Promise<number> {
  const s = createServer();
  await new Promise<void>((r) => s.listen(0, "127.0.0.1", r));
  const port = (s.address() as { port: number }).port;
  await new Promise<void>((r) => s.close(() => r()));
  return port;
}

/** The block in a harness whose clock follows the wall clock. */
async function harness(params: Record<string, unknown>, io = true) {
  const h = await BlockHarness.create(Sessantaquattro, params, {
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

function device(port: number, seed: number, model?: SimConfig["model"]) {
  const sim = new SessantaquattroSimulator({
    host: "127.0.0.1",
    port,
    seed,
    retry: 0.2,
    ...(model ? { model } : {}),
  });
  cleanup.push(() => sim.close());
  return sim;
}

const emitted = (h: BlockHarness) => ({ v: h.output("emg").v, t: h.output("emg").t });
const counts = (h: BlockHarness) => String(h.instance.actions!.counts!.run());

/**
 * Sample k of `cfg` as the block must output it, written independently of the block: the
 * simulator's values times the protocol's mV per bit (bioelectrical 0.000286, AUX 0.14648 at 16
 * bits and 0.0005722 at 24, the others as sent), the accessory channels unsigned.
 */
function want(cfg: SimConfig, seed: number, k: number, unit: "mV" | "raw"): number[] {
  const seen: Record<string, number> = {};
  return simLayout(cfg).map((kind) => {
    const i = (seen[kind] = (seen[kind] ?? -1) + 1);
    let v = sessantaquattroRaw(seed, kind, i, k, cfg.highRes);
    if (kind === "buffer" || kind === "counter") v &= cfg.highRes ? 0xffffff : 0xffff;
    if (unit === "raw") return v;
    if (kind === "bio") return v * 0.000286;
    if (kind === "aux") return v * (cfg.highRes ? 0.0005722 : 0.14648);
    return v;
  });
}

/** The first sample k whose output is `row`, searching up to `upTo`. */
function findK(row: number[], f: (k: number) => number[], upTo: number): number {
  for (let k = 0; k <= upTo; k++) if (f(k).every((x, c) => x === row[c])) return k;
  return -1;
}

/** Every row from `from` is sample k0 + i, exactly, stamped 1 / rate apart. */
function expectExact(
  h: BlockHarness,
  f: (k: number) => number[],
  rate: number,
  upTo: number,
  n: number,
): number {
  const { v, t } = emitted(h);
  const k0 = findK(v[0]!, f, upTo);
  expect(k0, "the first output is a sample the device sent").toBeGreaterThanOrEqual(0);
  for (let i = 0; i < n; i++) {
    const w = f(k0 + i);
    const bad = w.flatMap((x, c) => (x === v[i]![c] ? [] : [`${c}: ${v[i]![c]} vs ${x}`]));
    expect(bad, `sample ${i}`).toEqual([]);
  }
  expectDeviceStamps(t, rate, n);
  return k0;
}

describe("the simulator's encoder and the block's parser, written apart", () => {
  test("the simulator reads the block's command words as the same layout and rate", () => {
    for (const model of ["Sessantaquattro", "Sessantaquattro+"] as const) {
      for (const mode of ["monopolar", "bipolar", "differential"] as const) {
        for (const channels of [8, 16, 32, 64] as const) {
          const cfg = { model, mode, channels, rate: 4000 as const, highRes: true, hpf: false };
          const r = configOf(commandWord(cfg, true), model);
          expect("config" in r && r.go).toBe(true);
          if (!("config" in r)) continue;
          expect(simLayout(r.config)).toEqual(wireLayout(cfg).map((c) => c.kind));
          expect(r.config).toMatchObject({ rate: 4000, highRes: true, hpf: false, mode });
        }
      }
    }
    expect(configOf(0x8000, "Sessantaquattro+")).toEqual({
      ignored: "a GET request (not simulated)",
    });
  });

  test.each([false, true])(
    "what it encodes the parser decodes exactly (24 bits: %s)",
    (highRes) => {
      const cfg = {
        model: "Sessantaquattro+" as const,
        mode: "monopolar" as const,
        channels: 32 as const,
        rate: 2000 as const,
        highRes,
        hpf: true,
      };
      const r = configOf(commandWord(cfg, true), cfg.model);
      if (!("config" in r)) throw new Error(r.ignored);
      const rows: number[][] = [];
      const p = new SessantaquattroStreamParser(wireLayout(cfg).length, highRes ? 3 : 2, (raw) =>
        rows.push(Array.from(raw)),
      );
      const bytes = encodeSamples(9, r.config, 65000, 1000);
      for (let i = 0; i < bytes.length; i += 1000) p.feed(bytes.subarray(i, i + 1000));
      expect(rows).toHaveLength(1000);
      rows.forEach((row, i) => expect(row).toEqual(want(r.config, 9, 65000 + i, "raw")));
      expect([p.malformed, p.lostSamples, p.counterJumps]).toEqual([0, 0, 0]);
    },
  );
});

describe("Sessantaquattro: the device connects to the block", () => {
  test("the command word, values exact in mV at the commanded rate, the stop word", async () => {
    const port = await freePort();
    const h = await harness({ Port: port, Channels: 16, Rate: 1000, Host: "127.0.0.1" });
    expect(h.desiredRate).toBe(1000);
    expect(String(h.instance.actions!.channels!.run())).toMatch(
      /^channel 1: EMG 1 \(mV\); .*channel 17: AUX 1 \(mV\); .*channel 19: IMU W \(as sent\); .*channel 24: counter \(as sent\)$/,
    );
    h.start();
    await until(
      () => /^waiting for a Sessantaquattro\+ to connect to port \d+…$/.test(h.text),
      "listening",
    );
    const sim = device(port, 7);
    await until(
      () =>
        /^streaming 24 channels \(monopolar, 16-bit\) at 1000 Hz from the Sessantaquattro\+ at 127\.0\.0\.1:\d+/.test(
          h.text,
        ),
      "streaming",
    );
    // FSAMP 1 (1000 Hz), NCH 1 (16), MODE 0, HRES 0, HPF 1, GO 1.
    expect(sim.received).toEqual([0x2841]);
    await until(() => emitted(h).v.length >= 300, "300 samples");
    const cfg = sim.config!;
    expectExact(h, (k) => want(cfg, 7, k, "mV"), 1000, sim.samples, 300);

    // The device streams at the commanded rate: never ahead of it (what it sent is due by the
    // wall clock since the start word), and not far behind however loaded the machine.
    await sleep(500);
    const since = (performance.now() - sim.startedAt) / 1000;
    expect(sim.samples).toBeLessThanOrEqual(since * 1000);
    expect(sim.samples).toBeGreaterThan(since * 1000 * 0.5);

    h.instance.stop!();
    await until(() => sim.received.length === 2, "the stop word");
    expect(sim.received[1]).toBe(0x2840);
  });

  test("a Sessantaquattro in bipolar mode at 24 bits, raw: every integer exact", async () => {
    const port = await freePort();
    const h = await harness({
      Port: port,
      Model: "Sessantaquattro",
      Mode: "bipolar",
      Channels: 32,
      Rate: 500,
      HighRes: true,
      HPF: false,
      Unit: "raw",
    });
    h.start();
    const sim = device(port, 3, "Sessantaquattro");
    await until(() => emitted(h).v.length >= 100, "100 samples");
    expect(h.text).toMatch(/^streaming 20 channels \(bipolar, 24-bit\) at 500 Hz/);
    // FSAMP 0, NCH 2 (32), MODE 1, HRES 1, HPF 0, GO 1.
    expect(sim.received).toEqual([(2 << 11) | (1 << 8) | (1 << 7) | 1]);
    const cfg = sim.config!;
    expect(cfg.bio).toBe(16);
    expectExact(h, (k) => want(cfg, 3, k, "raw"), 500, sim.samples, 100);
    const bio = emitted(h).v.flatMap((r) => r.slice(0, 16));
    expect(Math.max(...bio.map(Math.abs))).toBeGreaterThan(32768);
  });

  test("killed and restarted, malformed bytes, skipped samples, a truncated sample: counted, recovered", async () => {
    const port = await freePort();
    const h = await harness({ Port: port, Channels: 8, Rate: 2000, Extras: false });
    h.start();
    let sim = device(port, 5);
    await until(() => /^streaming 16 channels/.test(h.text), "streaming");

    sim.inject(Uint8Array.of(1, 2, 3, 4, 5, 6, 7));
    await until(() => /1 malformed \(7 bytes skipped/.test(counts(h)), "the malformed bytes");
    expect(h.warnings.some((w) => /malformed data from the Sessantaquattro\+ at/.test(w))).toBe(
      true,
    );

    sim.skip(40);
    await until(() => /, 40 skipped by the device/.test(counts(h)), "the skipped samples");
    expect(h.text).toMatch(/ · 40 samples skipped by the device/);

    // The simulator is killed: reported; a new one connects: streaming again, values exact.
    await sim.close();
    await until(
      () => /^lost the Sessantaquattro\+ at 127\.0\.0\.1:\d+: the connection ended/.test(h.text),
      "lost",
    );
    expect(h.text).toMatch(/; waiting for it to connect again to port \d+/);
    expect(
      h.warnings.some((w) =>
        /^lost the Sessantaquattro\+ at 127\.0\.0\.1:\d+: the connection ended.*; reconnecting$/.test(
          w,
        ),
      ),
    ).toBe(true);
    const before = emitted(h).v.length;
    sim = device(port, 6);
    await until(() => /^streaming .* · reconnected 1×/.test(h.text), "streaming again");
    await until(() => emitted(h).v.length >= before + 200, "200 samples more");
    const cfg = sim.config!;
    const f = (k: number) => want(cfg, 6, k, "mV").slice(0, 8);
    const k0 = findK(emitted(h).v[before]!, f, sim.samples);
    expect(k0).toBeGreaterThanOrEqual(0);
    emitted(h)
      .v.slice(before, before + 200)
      .forEach((row, i) => expect(row, `sample ${i} after the restart`).toEqual(f(k0 + i)));

    sim.truncate();
    await until(() => /1 truncated/.test(counts(h)), "the truncated sample");
    await until(() => /reconnected 2×/.test(h.text), "streaming after the truncation");
    expect(counts(h)).toMatch(
      /1 malformed \(7 bytes skipped, last: .*\), 1 truncated \(\d+ bytes\)$/,
    );
  });

  test("a new connection replaces the current one, which is closed", async () => {
    const port = await freePort();
    const h = await harness({ Port: port, Channels: 8, Rate: 500 });
    h.start();
    await until(() => /^waiting/.test(h.text), "listening");
    const { createConnection } = await import("node:net");
    const stale = createConnection({ host: "127.0.0.1", port });
    const got: number[] = [];
    let closed = false;
    stale.on("data", (d) => got.push(...d));
    stale.on("close", () => (closed = true));
    stale.on("error", () => {});
    cleanup.push(() => void stale.destroy());
    await until(() => got.length === 2, "the command word");
    expect(got).toEqual([0x00, 0x41]); // FSAMP 0, NCH 0, MODE 0, HPF, GO
    const sim = device(port, 2);
    await until(() => closed, "the stale connection closed by the block");
    await until(() => emitted(h).v.length >= 50, "samples from the new one");
    const cfg = sim.config!;
    const k0 = findK(emitted(h).v[0]!, (k) => want(cfg, 2, k, "mV"), sim.samples);
    expect(k0).toBeGreaterThanOrEqual(0);
    expect(sim.connections).toBe(1);
  });

  test("a taken port and no TCP say what happens and what to do", async () => {
    const taken = createServer();
    await new Promise<void>((r) => taken.listen(0, "0.0.0.0", r));
    cleanup.push(() => void taken.close());
    const port = (taken.address() as { port: number }).port;
    const h = await harness({ Port: port });
    h.start();
    await until(() => /^not reachable/.test(h.text), "cannot listen");
    expect(h.text).toBe(
      `not reachable: cannot listen at 0.0.0.0:${port}: the port is in use (EADDRINUSE) — another program (or another block) listens there; choose another Port or stop it; listening again in 0.5 s (attempt 2)`,
    );
    expect(h.warnings[0]).toMatch(
      new RegExp(
        `^a Sessantaquattro\\+ on TCP port ${port} not reachable: cannot listen at .*mosaic simulate sessantaquattro --connect HOST:PORT\\)$`,
      ),
    );

    const b = await harness({}, false);
    b.start();
    expect(b.text).toBe("TCP not available in the browser build; use --simulate-devices");
    expect(b.warnings[0]).toMatch(/a Sessantaquattro\+ on TCP port 45454 cannot be reached/);

    const fast = await harness({ Rate: 4000, Channels: 64 }, false);
    expect(fast.warnings[0]).toMatch(/4000 Hz only with a reduced number of channels/);
  });
});

describe("mosaic simulate sessantaquattro + mosaic run", () => {
  test("the example runs with the simulated device connecting to it", async () => {
    requireBuild();
    const port = await freePort();
    const dir = tempDir("mosaic-sessantaquattro-");
    const file = join(dir, "sessantaquattro.yaml");
    writeFileSync(
      file,
      readFileSync(join(ROOT, "pipelines/devices/sessantaquattro.yaml"), "utf8").replace(
        "Port: 45454",
        `Port: ${port}`,
      ),
    );
    const run = startCli(["run", file, "--duration", "8", "--json"]);
    cleanup.push(() => void run.kill("SIGINT"));
    const out: string[] = [];
    createInterface({ input: run.stdout! }).on("line", (l) => out.push(l));
    const sim = startCli([
      "simulate",
      "sessantaquattro",
      "--connect",
      `127.0.0.1:${port}`,
      "--seed",
      "4",
      "--verbose",
    ]);
    cleanup.push(() => void sim.kill("SIGINT"));
    const lines: string[] = [];
    createInterface({ input: sim.stdout! }).on("line", (l) => lines.push(l));
    const code = await new Promise<number | null>((res) => run.on("exit", (c) => res(c)));
    expect(code, out.slice(-5).join("\n")).toBe(0);
    const summary = jsonLines(out.join("\n")).find((l) => l.type === "summary") as {
      blocks: { name: string; events: number; text: string }[];
    };
    const amp = summary.blocks.find((b) => b.name === "Amplifier")!;
    // The simulator (a second CLI process, retrying every 0.5 s) connects within the first
    // seconds of the 8 s run, however slowly the two processes start on a loaded machine.
    expect(amp.events).toBeGreaterThan(2000 * 1.5);
    expect(summary.blocks.find((b) => b.name === "Envelope25")!.events).toBeGreaterThan(25);
    sim.kill("SIGINT");
    const simCode = await new Promise<number | null>((res) => sim.on("exit", (c) => res(c)));
    expect(simCode).toBe(0);
    expect(lines.join("\n")).toMatch(
      /command 0x5841: streaming 72 channels \(64 monopolar\) at 2000 Hz, 16-bit, HPF on/,
    );
  }, 90_000);

  test("the example runs under --simulate-devices; simulate's option errors are one line", () => {
    requireBuild();
    const r = runCli(
      [
        "run",
        "pipelines/devices/sessantaquattro.yaml",
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
      /block 'Amplifier' \(Sessantaquattro\) simulated by EmgSimulator, 64 channels at 2000 Hz/,
    );
    const bad = runCli(["simulate", "sessantaquattro"]);
    expect(bad.code).not.toBe(0);
    expect(bad.stderr).toMatch(/--connect HOST:PORT is required/);
  });
});
