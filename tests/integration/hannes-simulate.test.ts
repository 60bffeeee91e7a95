/**
 * The Hannes blocks against the Hannes simulators (app/devices/hannes-*-simulator.ts, written from
 * docs/protocols.md), through the real CLI and engine workers (dist/): HannesHand on a real pty
 * pair (socat) drives the simulated Rehab Dongle and hand through the original's whole sequence
 * (command mode, scan, con, EnterCMDMode, JOINT_SET, CONTROL_MODE, ExitCMDMode, the references
 * exactly as the block logged them, the neutral pose, command mode, $$$ and dct at stop);
 * HannesGUI's datagrams decoded exactly by the GUI simulator; the EMG simulator's values exactly
 * in HannesReceiver's log. Then `mosaic simulate hannes`, `hannes-gui` and `hannes-emg` as child
 * processes with `mosaic run` of pipelines/devices/hannes.yaml and hannes-receiver.yaml, their
 * option errors, and both examples under --simulate-devices.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { createSocket } from "node:dgram";
import { existsSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import {
  startHannesDongleSimulator,
  type HannesDongleSimulator,
} from "../../app/devices/hannes-dongle-simulator";
import { HannesEmgSimulator, hannesEmgValue } from "../../app/devices/hannes-emg-simulator";
import {
  startHannesGuiSimulator,
  type HannesGuiSimulator,
} from "../../app/devices/hannes-gui-simulator";
import { jsonLines, requireBuild, ROOT, runCli, startCli, tempDir } from "./helpers";

const haveSocat = spawnSync("socat", ["-V"]).status === 0;

const children: ChildProcess[] = [];
const closers: (() => Promise<void>)[] = [];
afterEach(async () => {
  for (const c of closers.splice(0)) await c();
  for (const c of children.splice(0)) c.kill("SIGKILL");
});

const sleep = (ms: number) => new Promise((r) => setTimeout(r, ms));

async function waitFor(
  cond: () => boolean,
  ms: number,
  what: string | (() => string),
): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) {
      throw new Error(`timed out waiting for ${typeof what === "string" ? what : what()}`);
    }
    await sleep(25);
  }
}

/** A socat pty pair: `dev` for the pipeline, `dongle` for the simulator. */
async function ptyPair(dir: string): Promise<ChildProcess> {
  const socat = spawn("socat", [
    `pty,raw,echo=0,link=${join(dir, "dev")}`,
    `pty,raw,echo=0,link=${join(dir, "dongle")}`,
  ]);
  children.push(socat);
  await waitFor(
    () => existsSync(join(dir, "dev")) && existsSync(join(dir, "dongle")),
    5000,
    "socat",
  );
  return socat;
}

async function freePort(): Promise<number> {
  const s = createSocket("udp4");
  await new Promise<void>((r) => s.bind(0, "127.0.0.1", r));
  const port = s.address().port;
  await new Promise<void>((r) => s.close(() => r()));
  return port;
}

function readLog(file: string): number[][] {
  if (!existsSync(file)) return [];
  return readFileSync(file, "utf8")
    .split("\n")
    .filter((l) => l !== "")
    .map((l) => l.split(",").map(Number));
}

/** `mosaic run FILE --json` as a child; resolves with its exit code and output. */
interface Run {
  child: ChildProcess;
  out: () => string;
  done: Promise<number | null>;
  exited: () => boolean;
}

function runAsync(args: string[], untilMs = 60_000): Run {
  const child = startCli(args);
  children.push(child);
  let out = "";
  let exited = false;
  child.stdout!.on("data", (d: Buffer) => (out += d.toString()));
  child.stderr!.on("data", (d: Buffer) => (out += d.toString()));
  const done = new Promise<number | null>((res) => {
    const t = setTimeout(() => child.kill("SIGKILL"), untilMs);
    child.on("exit", (c) => {
      exited = true;
      clearTimeout(t);
      res(c);
    });
  });
  return { child, out: () => out, done, exited: () => exited };
}

/** Waits until the block `name` says it listens; fails at once, with its output, if the run ended. */
async function listening(run: Run, name: string): Promise<void> {
  const ready = (): boolean =>
    statusTexts(run.out(), name).some((t) => t.startsWith("listening on"));
  await waitFor(
    () => ready() || run.exited(),
    40_000,
    () => `${name} listening: ${run.out().slice(-1500)}`,
  );
  if (!ready())
    throw new Error(`mosaic run ended before ${name} listened: ${run.out().slice(-1500)}`);
}

/** A child `mosaic simulate …`: its stdout lines. */
function simulate(args: string[]): { child: ChildProcess; lines: string[]; stderr: () => string } {
  const child = startCli(["simulate", ...args]);
  children.push(child);
  const lines: string[] = [];
  let err = "";
  createInterface({ input: child.stdout! }).on("line", (l) => lines.push(l));
  child.stderr!.on("data", (d: Buffer) => (err += d.toString()));
  return { child, lines, stderr: () => err };
}

interface Telemetry {
  blocks: { name: string; text: string }[];
}

/** The block's status texts in `run --json`'s telemetry so far (whole lines only). */
function statusTexts(out: string, name: string): string[] {
  return jsonLines(out.slice(0, out.lastIndexOf("\n") + 1))
    .filter((m) => m.type === "telemetry")
    .map((m) => (m as unknown as Telemetry).blocks.find((b) => b.name === name)?.text ?? "");
}

/** C#'s (byte) cast read back signed, as the simulator decodes it. */
const trunc = (x: number) => Math.trunc(x) + 0;

describe.skipIf(!haveSocat)("HannesHand and the dongle simulator on a socat pty pair", () => {
  test("the original's whole sequence; every reference exact; neutral pose and dct at stop", async () => {
    requireBuild();
    const dir = tempDir("mosaic-hannes-sim-");
    await ptyPair(dir);
    const sim: HannesDongleSimulator = await startHannesDongleSimulator({
      path: join(dir, "dongle"),
      names: ["HannesL", "HannesR"],
      record: true,
    });
    closers.push(() => sim.close());
    const file = join(dir, "hand.yaml");
    writeFileSync(
      file,
      `timer: { Type: ScheduledTimer, DesiredRate: 25 }
predictions: { Type: SinGenerator, Inputs: [ timer ], Params: [ 12, 1, 0.5 ] }
control: { Type: ControlAlgorithm, Inputs: [ predictions ], Params: [ algorithm:DirectControl ] }
hand: { Type: HannesHand, Inputs: [ control ], Params: { Port: ${JSON.stringify(join(dir, "dev"))}, Device: HannesR }, Path: logs }
`,
    );
    const run = runAsync(["run", file, "--duration", "7", "--json"]);
    expect(await run.done, run.out()).toBe(0);
    await sim.waitFor(() => sim.records.some((r) => "text" in r && r.text === "dct"), "dct", 5000);

    expect(sim.records.filter((r) => "error" in r)).toEqual([]);
    expect([sim.malformedTotal, sim.nacks]).toEqual([0, 0]);
    expect(sim.records.slice(0, 7)).toEqual([
      { text: "$$$" },
      { text: "scan" },
      { text: "con 2" },
      { packet: [0] },
      { packet: [14, 0, 0x64] },
      { packet: [14, 5, 3] },
      { packet: [1] },
    ]);
    // The end: the neutral pose, then the hand in command mode, the dongle's $$$ and dct.
    expect(sim.records.slice(-4)).toEqual([
      { packet: [30, 0, 0, 0, 80, 0, 3, 0, 0, 0, 0] },
      { packet: [0] },
      { text: "$$$" },
      { text: "dct" },
    ]);
    expect([sim.connected, sim.handMode, sim.jointMask, sim.controlMode]).toEqual([
      undefined,
      "command",
      0x64,
      3,
    ]);
    // Every reference streamed is what the block logged (its last rows), exactly.
    const streamed = sim.applied.slice(0, -1);
    expect(streamed.length).toBeGreaterThan(40);
    const logged = readLog(join(dir, "logs", "hand.txt"));
    const tail = logged.slice(logged.length - streamed.length);
    expect(streamed).toEqual(
      tail.map(([, hand, ps, fe, thumb]) => ({
        hand: trunc(hand!),
        ps: trunc(ps!),
        fe: trunc(fe!),
        thumb: trunc(thumb!),
      })),
    );
    // The values move (a sine per prediction), not one pose repeated.
    expect(new Set(streamed.map((r) => JSON.stringify(r))).size).toBeGreaterThan(10);
    expect(sim.applied.at(-1)).toEqual({ hand: 0, ps: 0, fe: 80, thumb: 0 });
  }, 90_000);
});

describe.skipIf(!haveSocat)("HannesHand when the dongle is unplugged and plugged in again", () => {
  test("reported, the port reopened, the handshake run again, the references exact", async () => {
    requireBuild();
    const dir = tempDir("mosaic-hannes-sim-");
    let socat = await ptyPair(dir);
    const dongle = () => startHannesDongleSimulator({ path: join(dir, "dongle"), record: true });
    const first = await dongle();
    closers.push(() => first.close());
    const file = join(dir, "hand.yaml");
    writeFileSync(
      file,
      `timer: { Type: ScheduledTimer, DesiredRate: 25 }
predictions: { Type: SinGenerator, Inputs: [ timer ], Params: [ 12, 1, 0.5 ] }
control: { Type: ControlAlgorithm, Inputs: [ predictions ], Params: [ algorithm:DirectControl ] }
hand: { Type: HannesHand, Inputs: [ control ], Params: { Port: ${JSON.stringify(join(dir, "dev"))} }, Path: logs }
`,
    );
    const run = runAsync(["run", file, "--duration", "60", "--json"]);
    const last = (): string => statusTexts(run.out(), "hand").at(-1) ?? "";
    await first.waitFor(() => first.references >= 25, "25 references", 30_000);

    // The unplug: the pty pair disappears; the block says so and tries again every second.
    socat.kill("SIGTERM");
    await waitFor(
      () => /^opening .*retrying every 1 s/.test(last()),
      10_000,
      () => `the unplug (${last()})`,
    );
    await first.close();
    await waitFor(() => !existsSync(join(dir, "dev")), 5000, "socat's links removed");
    const second = await (async () => {
      socat = await ptyPair(dir);
      return dongle();
    })();
    closers.push(() => second.close());
    await second.waitFor(() => second.references >= 25, "25 references after the reopen", 30_000);
    await waitFor(
      () => /^Hannes on .*: [\d,]+ references sent/.test(last()),
      5000,
      () => `streaming (${last()})`,
    );
    run.child.kill("SIGINT");
    expect(await run.done, run.out().slice(-2000)).toBe(0);
    await second.waitFor(
      () => second.records.some((r) => "text" in r && r.text === "dct"),
      "dct",
      5000,
    );

    // The whole handshake again on the new port, and the whole end.
    for (const sim of [first, second]) {
      expect(sim.records.slice(0, 7)).toEqual([
        { text: "$$$" },
        { text: "scan" },
        { text: "con 1" },
        { packet: [0] },
        { packet: [14, 0, 0x64] },
        { packet: [14, 5, 3] },
        { packet: [1] },
      ]);
      expect(sim.malformedTotal).toBe(0);
    }
    expect(second.records.slice(-4)).toEqual([
      { packet: [30, 0, 0, 0, 80, 0, 3, 0, 0, 0, 0] },
      { packet: [0] },
      { text: "$$$" },
      { text: "dct" },
    ]);
    // The references the second dongle got are the block's last logged rows, exactly.
    const streamed = second.applied.slice(0, -1);
    const logged = readLog(join(dir, "logs", "hand.txt"));
    expect(streamed).toEqual(
      logged.slice(logged.length - streamed.length).map(([, hand, ps, fe, thumb]) => ({
        hand: trunc(hand!),
        ps: trunc(ps!),
        fe: trunc(fe!),
        thumb: trunc(thumb!),
      })),
    );
  }, 120_000);
});

describe("HannesGUI and HannesReceiver against the UDP simulators", () => {
  test("HannesGUI → the GUI simulator: every datagram decoded exactly", async () => {
    requireBuild();
    const dir = tempDir("mosaic-hannes-sim-");
    const gui: HannesGuiSimulator = await startHannesGuiSimulator({ port: 0, record: true });
    closers.push(() => gui.close());
    const file = join(dir, "gui.yaml");
    writeFileSync(
      file,
      `timer: { Type: ScheduledTimer, DesiredRate: 25 }
predictions: { Type: SinGenerator, Inputs: [ timer ], Params: [ 12, 1, 0.5 ] }
control: { Type: ControlAlgorithm, Inputs: [ predictions ], Params: [ algorithm:DirectControl ], Path: logs }
raw: { Type: SinGenerator, Inputs: [ timer ], Params: [ 8, 0.9, 3 ], Path: logs }
arv: { Type: SinGenerator, Inputs: [ timer ], Params: [ 8, 2, 1 ], Path: logs }
gui: { Type: HannesGUI, Inputs: [ control, raw, arv ], Params: [ 127.0.0.1, ${gui.port}, 8, 64 ] }
`,
    );
    const run = runAsync(["run", file, "--duration", "3", "--json"]);
    expect(await run.done, run.out()).toBe(0);
    const control = readLog(join(dir, "logs", "control.txt"));
    const raw = readLog(join(dir, "logs", "raw.txt"));
    const arv = readLog(join(dir, "logs", "arv.txt"));
    const expected = 3 * control.length + raw.length + arv.length;
    await gui.waitFor(() => gui.received.length >= expected, `${expected} datagrams`, 5000);

    expect(gui.malformedTotal).toBe(0);
    const acts = gui.received.filter((d) => d.kind === "activation");
    expect(acts.length).toBe(3 * control.length);
    expect(acts).toEqual(
      control.flatMap((row) => {
        const c = row.slice(1);
        // hand ← thumb flexion, wrist P/S, wrist F/E (the actuation vector's 0, 8, 6)
        return [
          { kind: "activation", joint: 0, value: trunc(c[0]!) },
          { kind: "activation", joint: 1, value: trunc(c[8]!) },
          { kind: "activation", joint: 2, value: trunc(c[6]!) },
        ];
      }),
    );
    expect(gui.received.filter((d) => d.kind === "raw")).toEqual(
      raw.map((row) => ({
        kind: "raw",
        values: row.slice(1).map((x) => Math.max(-128, Math.min(127, trunc(128 * x)))),
      })),
    );
    expect(gui.received.filter((d) => d.kind === "arv")).toEqual(
      arv.map((row) => ({ kind: "arv", values: row.slice(1) })),
    );
    const last = control.at(-1)!.slice(1);
    expect(gui.state.activation).toEqual([trunc(last[0]!), trunc(last[8]!), trunc(last[6]!)]);
  }, 60_000);

  test("the EMG simulator → HannesReceiver: every value exact, in order", async () => {
    requireBuild();
    const dir = tempDir("mosaic-hannes-sim-");
    const port = await freePort();
    const file = join(dir, "emg.yaml");
    writeFileSync(
      file,
      `emg: { Type: HannesReceiver, Params: { Host: 127.0.0.1, Port: ${port}, Channels: 6 }, Path: logs }\n`,
    );
    const run = runAsync(["run", file, "--duration", "60", "--json"]);
    await listening(run, "emg");
    const sim = new HannesEmgSimulator({ host: "127.0.0.1", port, rate: 100, count: 200 });
    closers.push(() => sim.close());
    await sim.waitFor(() => sim.done, "end of the stream", 20_000);
    const log = join(dir, "logs", "emg.txt");
    await waitFor(() => readLog(log).length >= 200, 5000, "200 logged rows");
    run.child.kill("SIGINT");
    expect(await run.done).toBe(0);

    const rows = readLog(log).map((r) => r.slice(1));
    expect(rows).toEqual(
      Array.from({ length: 200 }, (_, i) =>
        Array.from({ length: 6 }, (_, k) => hannesEmgValue(i, k)),
      ),
    );
    expect(sim.failed).toBe(0);
  }, 90_000);

  test("the EMG simulator stopped and started again: repeats counted, the new stream read exactly", async () => {
    requireBuild();
    const dir = tempDir("mosaic-hannes-sim-");
    const port = await freePort();
    const file = join(dir, "paced.yaml");
    writeFileSync(
      file,
      `timer: { Type: ScheduledTimer, DesiredRate: 100 }
emg: { Type: HannesReceiver, Inputs: [ timer ], Params: { Host: 127.0.0.1, Port: ${port}, Channels: 6 }, Path: logs }
`,
    );
    const run = runAsync(["run", file, "--duration", "60", "--json"]);
    const last = (): string => statusTexts(run.out(), "emg").at(-1) ?? "";
    await listening(run, "emg");
    const stream = async (first: number): Promise<void> => {
      const sim = new HannesEmgSimulator({ host: "127.0.0.1", port, count: 150, first });
      closers.push(() => sim.close());
      await sim.waitFor(() => sim.done, "end of the stream", 20_000);
      await sim.close();
    };
    await stream(0);
    await waitFor(
      () => /150 datagrams/.test(last()),
      5000,
      () => `150 datagrams (${last()})`,
    );
    await sleep(1000); // silence: every tick repeats the last sample
    await stream(5000);
    await waitFor(
      () => /300 datagrams/.test(last()),
      5000,
      () => `300 datagrams (${last()})`,
    );
    await sleep(300);
    run.child.kill("SIGINT");
    expect(await run.done).toBe(0);
    const status = last().startsWith("stopped") ? statusTexts(run.out(), "emg").at(-2)! : last();
    const repeated = Number(/(\d+) ticks without a new sample/.exec(status)?.[1] ?? 0);
    const dropped = Number(/(\d+) dropped/.exec(status)?.[1] ?? 0);
    expect(repeated, status).toBeGreaterThanOrEqual(80); // the 1 s of silence, at least

    // Every row logged is a datagram sent (or zeros before the first), in order; a datagram is
    // missing only where the block says it dropped one (more than MaxDelay waiting).
    const byRow = new Map<string, number>();
    for (const first of [0, 5000]) {
      for (let i = first; i < first + 150; i++) {
        byRow.set(Array.from({ length: 6 }, (_, k) => hannesEmgValue(i, k)).join(), i);
      }
    }
    const rows = readLog(join(dir, "logs", "emg.txt")).map((r) => r.slice(1));
    const unknown = rows.filter((r) => r.some((x) => x !== 0) && !byRow.has(r.join()));
    expect(unknown).toEqual([]);
    const seq: number[] = [];
    for (const r of rows) {
      const i = byRow.get(r.join());
      if (i !== undefined && i !== seq.at(-1)) seq.push(i);
    }
    let gaps = 0;
    for (let j = 1; j < seq.length; j++) {
      expect(seq[j]).toBeGreaterThan(seq[j - 1]!);
      if (seq[j - 1]! < 5000 && seq[j]! >= 5000) continue; // the restart
      gaps += seq[j]! - seq[j - 1]! - 1;
    }
    expect(seq[0]).toBe(0);
    expect(seq.at(-1)).toBe(5149);
    expect(seq.filter((i) => i < 5000).at(-1)).toBe(149);
    expect(seq.find((i) => i >= 5000)).toBe(5000);
    expect(gaps).toBeLessThanOrEqual(dropped);
  }, 90_000);
});

describe.skipIf(!haveSocat)("mosaic simulate hannes, hannes-gui, hannes-emg", () => {
  test("the simulators as child processes with mosaic run of pipelines/devices/hannes.yaml", async () => {
    requireBuild();
    const dir = tempDir("mosaic-hannes-sim-");
    await ptyPair(dir);
    const guiPort = await freePort();
    const dongle = simulate(["hannes", "--port", join(dir, "dongle")]);
    const gui = simulate(["hannes-gui", "--port", String(guiPort)]);
    await waitFor(() => dongle.lines.length >= 2 && gui.lines.length >= 2, 20_000, "banners");
    expect(dongle.lines[0]).toBe(
      `Hannes simulator on ${join(dir, "dongle")}: a Rehab Dongle listing Hannes (con 1); it prints each step of the handshake and the hand's references as they change`,
    );
    expect(gui.lines[0]).toBe(
      `Hannes GUI simulator listening on UDP 127.0.0.1:${guiPort}: prints hand, wrist P/S and wrist F/E activations, raw EMG and ARVs as they change`,
    );
    const file = join(dir, "hannes.yaml");
    const example = readFileSync(join(ROOT, "pipelines/devices/hannes.yaml"), "utf8");
    expect(example).toContain("Params: { Port: /tmp/hannes } }");
    expect(example).toContain("Params: { Host: 127.0.0.1, Port: 8889 } }");
    writeFileSync(
      file,
      example
        .replace("Port: /tmp/hannes }", `Port: ${JSON.stringify(join(dir, "dev"))} }`)
        .replace("Port: 8889 }", `Port: ${guiPort} }`),
    );
    const run = runAsync(["run", file, "--duration", "8", "--json"]);
    expect(await run.done, run.out()).toBe(0);
    await waitFor(
      () => dongle.lines.some((l) => l.includes("dct: disconnected from Hannes")),
      5000,
      "the disconnect",
    );
    dongle.child.kill("SIGINT");
    gui.child.kill("SIGINT");
    const codes = await Promise.all(
      [dongle.child, gui.child].map(
        (c) => new Promise<number | null>((res) => c.on("exit", (code) => res(code))),
      ),
    );
    expect(codes).toEqual([0, 0]);
    const steps = dongle.lines.filter((l) => !/ references$/.test(l)).slice(2);
    expect(steps).toEqual([
      "  dongle: command mode",
      "  scan: Hannes (con 1)",
      "  con 1: connected to Hannes (0CEC800010A)",
      "  Hannes: command mode",
      "  joints activated: thumb, wrist F/E, wrist P/S (0x64)",
      "  control mode 3 (UNITY_CONTROL)",
      "  Hannes: stream mode",
      "  Hannes: command mode",
      "  dongle: command mode",
      "  dct: disconnected from Hannes",
    ]);
    const final =
      /^ {2}no hand connected: hand 0 · wrist P\/S 0 · wrist F\/E 80 · thumb 0 · (\d+) references$/.exec(
        dongle.lines.at(-1)!,
      );
    expect(final, dongle.lines.at(-1)).not.toBeNull();
    expect(Number(final![1])).toBeGreaterThan(50);
    const summary = jsonLines(run.out()).find((l) => l.type === "summary") as
      { blocks: { name: string; events: number }[] } | undefined;
    const guiEvents = summary!.blocks.find((b) => b.name === "Gui")!.events;
    expect(guiEvents).toBeGreaterThan(1000);
    const guiState = gui.lines.at(-1)!;
    expect(guiState).toMatch(
      /^ {2}hand \d+ · wrist P\/S \d+ · wrist F\/E \d+ · raw EMG \[8\] .* · ARV \[8\] .* · (\d+) datagrams$/,
    );
    expect(Number(/(\d+) datagrams$/.exec(guiState)![1])).toBeGreaterThan(1000);
  }, 90_000);

  test("mosaic simulate hannes-emg + hannes-gui with pipelines/devices/hannes-receiver.yaml", async () => {
    requireBuild();
    const dir = tempDir("mosaic-hannes-sim-");
    const [emgPort, guiPort] = [await freePort(), await freePort()];
    const gui = simulate(["hannes-gui", "--port", String(guiPort)]);
    await waitFor(() => gui.lines.length >= 2, 20_000, "the GUI simulator's banner");
    const file = join(dir, "receiver.yaml");
    const example = readFileSync(join(ROOT, "pipelines/devices/hannes-receiver.yaml"), "utf8");
    writeFileSync(
      file,
      example
        .replace("Port: 11000,", `Port: ${emgPort},`)
        .replace("Port: 8889 }", `Port: ${guiPort} }`)
        .replace("Channels: 6 } }", "Channels: 6 }, Path: logs }"),
    );
    const run = runAsync(["run", file, "--duration", "60", "--json"]);
    await listening(run, "Hannes");
    const emg = simulate(["hannes-emg", "--to", `127.0.0.1:${emgPort}`, "--count", "150"]);
    await waitFor(
      () => emg.lines.some((l) => l.endsWith("150 datagrams sent · done")),
      20_000,
      "the stream",
    );
    expect(emg.lines[0]).toBe(
      `Hannes EMG simulator sending to UDP 127.0.0.1:${emgPort}: 6 channels at 100 Hz, 150 datagrams`,
    );
    const log = join(dir, "logs", "Hannes.txt");
    await waitFor(() => readLog(log).length >= 150, 5000, "150 logged rows");
    run.child.kill("SIGINT");
    expect(await run.done).toBe(0);
    expect(readLog(log).map((r) => r.slice(1))).toEqual(
      Array.from({ length: 150 }, (_, i) =>
        Array.from({ length: 6 }, (_, k) => hannesEmgValue(i, k)),
      ),
    );
    // 3 activations per control value (450), and then the ControlAlgorithm's watchdog puts the
    // arm at rest once the stream stopped.
    const rest = /^ {2}hand 0 · wrist P\/S 50 · wrist F\/E 50 · (\d+) datagrams$/;
    await waitFor(() => rest.test(gui.lines.at(-1) ?? ""), 5000, "the arm at rest");
    expect(Number(rest.exec(gui.lines.at(-1)!)![1])).toBeGreaterThanOrEqual(450);
    expect(gui.lines.filter((l) => l.includes("malformed"))).toEqual([]);
    for (const c of [emg.child, gui.child]) c.kill("SIGINT");
  }, 90_000);

  test("option errors: one line, 2 for a bad option, 1 for a missing device or a taken port", async () => {
    requireBuild();
    const dir = tempDir("mosaic-hannes-sim-");
    const noPort = runCli(["simulate", "hannes"]);
    expect(noPort.code).toBe(2);
    expect(noPort.stderr.trim()).toMatch(/^mosaic simulate hannes: --port PATH is required: /);
    const missing = runCli(["simulate", "hannes", "--port", join(dir, "nothing")]);
    expect([missing.code, missing.stderr.trim()]).toEqual([
      1,
      `mosaic simulate hannes: cannot open ${join(dir, "nothing")}: no such device (is socat running?)`,
    ]);
    const badTo = runCli(["simulate", "hannes-emg", "--to", "somewhere"]);
    expect([badTo.code, badTo.stderr.trim()]).toEqual([
      2,
      "mosaic simulate hannes-emg: --to takes HOST:PORT with a port 1…65535, e.g. 127.0.0.1:11000; not 'somewhere'",
    ]);
    const taken = createSocket("udp4");
    await new Promise<void>((r) => taken.bind(0, "127.0.0.1", r));
    const port = taken.address().port;
    const busy = runCli(["simulate", "hannes-gui", "--port", String(port)]);
    taken.close();
    expect([busy.code, busy.stderr.trim()]).toEqual([
      1,
      `mosaic simulate hannes-gui: UDP 127.0.0.1:${port} is in use (another Hannes GUI?)`,
    ]);
  }, 60_000);
});

describe("the examples under --simulate-devices", () => {
  test.each(["hannes", "hannes-receiver"])(
    "pipelines/devices/%s.yaml",
    (name) => {
      requireBuild();
      const r = runCli(
        ["run", `pipelines/devices/${name}.yaml`, "--simulate-devices", "--duration", "2"],
        { timeoutMs: 60_000 },
      );
      expect(r.code, r.stderr).toBe(0);
      if (name === "hannes") {
        expect(r.stderr).toMatch(/block 'Hand' \(HannesHand\) replaced by SimulatedOutput/);
        expect(r.stderr).toMatch(/block 'Gui' \(HannesGUI\) replaced by SimulatedOutput/);
      } else {
        expect(r.stderr).toMatch(
          /block 'Hannes' \(HannesReceiver\) simulated by EmgSimulator, 6 channels/,
        );
      }
    },
    60_000,
  );
});
