/**
 * The Hannes blocks against peers played by Python processes written from the original MOSAIC's
 * code (tests/integration/hannes_peer.py), through the real CLI and engine workers (dist/):
 * HannesHand on a real pty pair (socat) with a simulated Rehab Dongle and hand — the handshake,
 * then every reference packet checked against what the block logged; HannesGUI and
 * HannesReceiver on real loopback UDP.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { createSocket } from "node:dgram";
import { existsSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import { jsonLines, requireBuild, ROOT, runCli, tempDir } from "./helpers";

const PEER = join(ROOT, "tests/integration/hannes_peer.py");
const hasPython = spawnSync("python3", ["--version"]).status === 0;
const haveSocat = spawnSync("socat", ["-V"]).status === 0;

const children: ChildProcess[] = [];
afterEach(() => {
  for (const c of children.splice(0)) c.kill("SIGKILL");
});

const sleep = (ms: number) => new Promise((r) => setTimeout(r, ms));

async function freePort(): Promise<number> {
  const s = createSocket("udp4");
  await new Promise<void>((r) => s.bind(0, "127.0.0.1", r));
  const port = s.address().port;
  await new Promise<void>((r) => s.close(() => r()));
  return port;
}

const readLog = (file: string): number[][] =>
  readFileSync(file, "utf8")
    .trim()
    .split("\n")
    .filter((l) => l !== "")
    .map((l) => l.split(",").map(Number));

/** Starts a peer; resolves with its stdout lines once it exits. */
function peer(args: string[]): { proc: ChildProcess; lines: string[]; done: Promise<string[]> } {
  const proc = spawn("python3", [PEER, ...args], { stdio: ["ignore", "pipe", "inherit"] });
  children.push(proc);
  const lines: string[] = [];
  createInterface({ input: proc.stdout! }).on("line", (l) => lines.push(l));
  const done = new Promise<string[]>((res) => proc.on("close", () => res(lines)));
  return { proc, lines, done };
}

/** C#'s (byte) cast, read back as the peer reads it (signed for P/S and thumb). */
const trunc = (x: number) => Math.trunc(x) + 0;

describe("Hannes, real host", () => {
  test.skipIf(!hasPython || !haveSocat)(
    "HannesHand: the original's handshake with a simulated dongle on a pty, then the logged references as packets",
    async () => {
      requireBuild();
      const dir = tempDir("mosaic-hannes-");
      const socat = spawn("socat", [
        `pty,raw,echo=0,link=${join(dir, "dev")}`,
        `pty,raw,echo=0,link=${join(dir, "peer")}`,
      ]);
      children.push(socat);
      for (
        let i = 0;
        i < 200 && !(existsSync(join(dir, "dev")) && existsSync(join(dir, "peer")));
        i++
      )
        await sleep(25);
      const dongle = peer([
        "dongle",
        "--port",
        join(dir, "peer"),
        "--log",
        join(dir, "dongle.jsonl"),
        "--names",
        "HannesL,HannesR",
      ]);
      const file = join(dir, "hand.yaml");
      writeFileSync(
        file,
        `
timer: { Type: ScheduledTimer, DesiredRate: 25 }
predictions: { Type: SinGenerator, Inputs: [ timer ], Params: [ 12, 1, 0.5 ] }
control: { Type: ControlAlgorithm, Inputs: [ predictions ], Params: [ algorithm:DirectControl ] }
hand: { Type: HannesHand, Inputs: [ control ], Params: { Port: ${JSON.stringify(join(dir, "dev"))}, Device: HannesR }, Path: logs }
`,
      );
      const r = runCli(["run", file, "--duration", "7", "--json"], { timeoutMs: 60_000 });
      expect(r.code, r.stderr).toBe(0);
      await Promise.race([dongle.done, sleep(5000)]);
      const log = readFileSync(join(dir, "dongle.jsonl"), "utf8")
        .trim()
        .split("\n")
        .map((l) => JSON.parse(l) as { text?: string; packet?: number[]; error?: string });
      expect(log.filter((e) => e.error !== undefined)).toEqual([]);
      // The handshake, in the original's order.
      expect(log.slice(0, 7)).toEqual([
        { text: "$$$" },
        { text: "scan" },
        { text: "con 2" },
        { packet: [0] },
        { packet: [14, 0, 0x64] },
        { packet: [14, 5, 3] },
        { packet: [1] },
      ]);
      const refs = log.slice(7).filter((e) => e.packet?.[0] === 30);
      // The end: the neutral pose, then command mode and the dongle's disconnect — all of it,
      // though the host exits right after: the serial bridge drains a port before closing it.
      const neutral = log.findIndex((e) => e.packet?.join() === "30,0,0,0,80,0,3,0,0,0,0");
      expect(neutral).toBeGreaterThan(7);
      expect(log.slice(neutral + 1)).toEqual([{ packet: [0] }, { text: "$$$" }, { text: "dct" }]);
      // Every reference sent once streaming is what the block logged (the last ones).
      const logged = readLog(join(dir, "logs", "hand.txt"));
      const streamed = refs.slice(0, -1); // without the neutral pose
      expect(streamed.length).toBeGreaterThan(40);
      const tail = logged.slice(logged.length - streamed.length);
      const s8 = (b: number) => (b > 127 ? b - 256 : b);
      streamed.forEach((e, i) => {
        const [, hand, ps, fe, thumb] = tail[i]!;
        const p = e.packet!;
        expect([p[2], s8(p[3]!), p[4], s8(p[7]!)]).toEqual([
          trunc(hand!),
          trunc(ps!),
          trunc(fe!),
          trunc(thumb!),
        ]);
        expect([p[1], p[5], p[6], p[8], p[9], p[10]]).toEqual([0, 0, 3, 0, 0, 0]);
      });
      const events = jsonLines(r.stdout).filter((l) => l.type === "fatal");
      expect(events).toEqual([]);
    },
    90_000,
  );

  test.skipIf(!hasPython)(
    "HannesGUI datagrams and HannesReceiver's EMG on loopback UDP",
    async () => {
      requireBuild();
      const dir = tempDir("mosaic-hannes-");
      const gui = peer(["gui", "--idle", "1.5", "--timeout", "30"]);
      for (let i = 0; i < 200 && gui.lines.length === 0; i++) await sleep(25);
      const guiPort = (JSON.parse(gui.lines[0]!) as { port: number }).port;
      const rx = await freePort();
      const emg = peer(["emg", "--to", String(rx), "--count", "40", "--delay", "1.5"]);
      const file = join(dir, "gui.yaml");
      writeFileSync(
        file,
        `
timer: { Type: ScheduledTimer, DesiredRate: 25 }
predictions: { Type: SinGenerator, Inputs: [ timer ], Params: [ 12, 1, 0.5 ] }
control: { Type: ControlAlgorithm, Inputs: [ predictions ], Params: [ algorithm:DirectControl ], Path: logs }
raw: { Type: SinGenerator, Inputs: [ timer ], Params: [ 8, 0.9, 3 ], Path: logs }
arv: { Type: SinGenerator, Inputs: [ timer ], Params: [ 8, 2, 1 ], Path: logs }
gui: { Type: HannesGUI, Inputs: [ control, raw, arv ], Params: [ 127.0.0.1, ${guiPort}, 8, 64 ] }
emg: { Type: HannesReceiver, Params: { Host: 127.0.0.1, Port: ${rx}, Channels: 6 }, Path: logs }
`,
      );
      const r = runCli(["run", file, "--duration", "3.5", "--json"], { timeoutMs: 60_000 });
      expect(r.code, r.stderr).toBe(0);
      const decoded = (await gui.done)
        .slice(1)
        .map((l) => JSON.parse(l) as Record<string, unknown>);
      const sentEmg = (await emg.done).map((l) => JSON.parse(l) as number[]);

      expect(decoded.filter((d) => "error" in d)).toEqual([]);
      const control = readLog(join(dir, "logs", "control.txt"));
      const acts = decoded.filter((d) => d.kind === "activation");
      expect(acts.length).toBe(3 * control.length);
      control.forEach((row, i) => {
        const c = row.slice(1);
        // hand ← thumb flexion, P/S, F/E (DOAs order: 0, 8, 6)
        expect(acts.slice(3 * i, 3 * i + 3)).toEqual([
          { kind: "activation", joint: 0, value: trunc(c[0]!) },
          { kind: "activation", joint: 1, value: trunc(c[8]!) },
          { kind: "activation", joint: 2, value: trunc(c[6]!) },
        ]);
      });
      const raw = readLog(join(dir, "logs", "raw.txt"));
      const raws = decoded.filter((d) => d.kind === "raw");
      expect(raws.map((d) => d.values)).toEqual(
        raw.map((row) => row.slice(1).map((x) => Math.max(-128, Math.min(127, trunc(128 * x))))),
      );
      const arv = readLog(join(dir, "logs", "arv.txt"));
      expect(decoded.filter((d) => d.kind === "arv").map((d) => d.values)).toEqual(
        arv.map((row) => row.slice(1)),
      );

      const got = readLog(join(dir, "logs", "emg.txt"));
      expect(sentEmg.length).toBe(40);
      expect(got.map((row) => row.slice(1))).toEqual(sentEmg.map((v) => v.map((x) => x / 65536)));
    },
    90_000,
  );
});
