/**
 * The SerialPort block against a device played by a real Python process (pyserial) on a real
 * pty pair (socat): values arrive exactly in both framings, malformed input is counted, an unplug
 * (the pty pair disappears) is reported in the block's status, the port is reopened when the
 * device is back, and data resumes. Runs the real CLI (`mosaic run --json`) with the host's
 * native serial bridge.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { existsSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { afterEach, describe, expect, test } from "vitest";
import { jsonLines, requireBuild, ROOT, startCli, tempDir } from "./helpers";

const haveSocat = spawnSync("socat", ["-V"]).status === 0;
const UV = ["-m", "uv", "run", "--frozen", "--quiet", "--project", join(ROOT, "tests/reference")];
const havePyserial =
  spawnSync("python3", [...UV, "--python", "python3.11", "python", "-c", "import serial"], {
    env: { ...process.env, UV_PYTHON_DOWNLOADS: "never" },
  }).status === 0;

const children: ChildProcess[] = [];
afterEach(() => {
  for (const c of children.splice(0)) c.kill("SIGKILL");
});

function sleep(ms: number): Promise<void> {
  return new Promise((r) => setTimeout(r, ms));
}

async function waitFor(cond: () => boolean, ms: number, what: string): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await sleep(25);
  }
}

/** A socat pty pair: `dev` for MOSAIC, `peer` for the device script. */
async function ptyPair(dir: string): Promise<ChildProcess> {
  const p = spawn("socat", [
    `pty,raw,echo=0,link=${join(dir, "dev")}`,
    `pty,raw,echo=0,link=${join(dir, "peer")}`,
  ]);
  children.push(p);
  await waitFor(() => existsSync(join(dir, "dev")) && existsSync(join(dir, "peer")), 5000, "socat");
  return p;
}

function device(dir: string, mode: string, first: number, count: number): Promise<number> {
  const p = spawn(
    "python3",
    [
      ...UV,
      "--python",
      "python3.11",
      "python",
      join(ROOT, "tests/integration/serial_device.py"),
      "--port",
      join(dir, "peer"),
      "--mode",
      mode,
      "--first",
      String(first),
      "--count",
      String(count),
      "--rate",
      "250",
      "--received",
      join(dir, "received.jsonl"),
    ],
    {
      env: { ...process.env, UV_PYTHON_DOWNLOADS: "never" },
      stdio: ["ignore", "inherit", "inherit"],
    },
  );
  children.push(p);
  return new Promise((resolve) => p.on("exit", (code) => resolve(code ?? -1)));
}

function frameValues(k: number): number[] {
  return [k - 50, k * 0.25, (k * 7) % 65536];
}

function readLog(file: string): number[][] {
  if (!existsSync(file)) return [];
  return readFileSync(file, "utf8")
    .split("\n")
    .filter((l) => l !== "")
    .map((l) => l.split(",").slice(1).map(Number));
}

function pipeline(dir: string, mode: "lines" | "binary"): string {
  const framing =
    mode === "lines"
      ? "Framing: lines\n    Channels: 3"
      : "Framing: binary\n    Fields: [i16, f32, u16]\n    Sync: [170, 85]\n    Checksum: crc16";
  const file = join(dir, `serial-${mode}.yaml`);
  writeFileSync(
    file,
    `Timer: { Type: ScheduledTimer, DesiredRate: 20 }
Command:
  Type: SinGenerator
  Inputs: [Timer]
  Params: { Components: 3, Amplitude: 100, Frequency: 0.5 }
  Path: ${join(dir, "logs")}
Device:
  Type: SerialPort
  Inputs: [Command]
  Params:
    Path: ${join(dir, "dev")}
    Reconnect: 0.3
    ${framing}
  Path: ${join(dir, "logs")}
`,
  );
  return file;
}

interface Telemetry {
  blocks: { name: string; text: string }[];
}

describe.skipIf(!haveSocat || !havePyserial)(
  "SerialPort with a pyserial device on a socat pty pair",
  () => {
    requireBuild();

    for (const mode of ["lines", "binary"] as const) {
      test(`${mode}: exact values both ways, malformed input counted, unplug reported, reconnect resumes`, async () => {
        const dir = tempDir("mosaic-serial-");
        let socat = await ptyPair(dir);
        const run = startCli(["run", pipeline(dir, mode), "--json", "--duration", "30"]);
        children.push(run);
        let out = "";
        run.stdout!.on("data", (d: Buffer) => (out += d.toString()));
        run.stderr!.on("data", (d: Buffer) => (out += d.toString()));
        const texts = (): string[] =>
          jsonLines(out)
            .filter((m) => m.type === "telemetry")
            .map(
              (m) =>
                (m as unknown as Telemetry).blocks.find((b) => b.name === "Device")?.text ?? "",
            );
        const log = join(dir, "logs", "Device.txt");

        // First connection: 60 frames, then the device exits and the pty pair disappears.
        expect(await device(dir, mode, 0, 60)).toBe(0);
        await waitFor(() => readLog(log).length >= 60, 5000, "the first 60 frames in the log");
        await waitFor(() => texts().some((t) => /malformed/.test(t)), 3000, "malformed count");
        socat.kill("SIGTERM");
        await waitFor(
          () => texts().some((t) => /disconnected|no such device/.test(t)),
          5000,
          "the unplug",
        );
        const unplugged = texts()
          .filter((t) => /disconnected|no such device/.test(t))
          .at(-1)!;
        expect(unplugged).toMatch(/retrying every 0\.3 s/);

        // The device comes back (same path): data resumes without restarting the pipeline.
        await sleep(800);
        socat = await ptyPair(dir);
        await waitFor(() => texts().at(-1)!.includes(" open @ "), 5000, "the reopen");
        expect(await device(dir, mode, 1000, 40)).toBe(0);
        await waitFor(() => readLog(log).length >= 100, 5000, "the next 40 frames");
        run.kill("SIGINT");
        await new Promise((r) => run.on("exit", r));

        const got = readLog(log);
        const want = [...Array.from({ length: 60 }, (_, k) => frameValues(k))];
        for (let k = 1000; k < 1040; k++) want.push(frameValues(k));
        expect(got).toEqual(want);
        console.log(`serial ${mode}: ${got.length} frames exact; unplug status: "${unplugged}"`);

        // The outgoing direction: every frame the device decoded is one MOSAIC logged for Command.
        const sent = readLog(join(dir, "logs", "Command.txt"));
        const received = readFileSync(join(dir, "received.jsonl"), "utf8")
          .split("\n")
          .filter((l) => l !== "")
          .map((l) => JSON.parse(l) as number[]);
        expect(received.length).toBeGreaterThan(5);
        const fmt = (v: number[]): string =>
          mode === "lines"
            ? v.join(",")
            : [
                Math.round(v[0]!),
                Math.fround(v[1]!),
                Math.min(65535, Math.max(0, Math.round(v[2]!))),
              ].join(",");
        const sentSet = new Set(sent.map(fmt));
        expect(received.map((r) => r.join(",")).filter((r) => !sentSet.has(r))).toEqual([]);
      }, 60_000);
    }
  },
);
