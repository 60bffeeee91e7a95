/**
 * UDP on real loopback sockets, through the real CLI and engine workers (dist/): a UdpSender's
 * datagrams come back through a UdpReceiver of the same pipeline, and an independent Python
 * decoder (standard `struct` only) reads what the sender wrote; both are compared, value by value,
 * with the sender's input as logged by `Path`. A receiver on a port already in use reports it
 * (block and port) while the other blocks keep running.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { createSocket, type Socket } from "node:dgram";
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import { jsonLines, KEEPING_UP, requireBuild, ROOT, runCli, tempDir } from "./helpers";

const cleanup: (() => void)[] = [];
afterEach(() => {
  for (const c of cleanup.splice(0)) c();
});

/** A free loopback UDP port (bound and released; a race is possible but harmless here). */
async function freePort(): Promise<number> {
  const s = createSocket("udp4");
  await new Promise<void>((r) => s.bind(0, "127.0.0.1", r));
  const port = s.address().port;
  await new Promise<void>((r) => s.close(() => r()));
  return port;
}

const hasPython = spawnSync("python3", ["--version"]).status === 0;

interface PyDecoder {
  port: number;
  proc: ChildProcess;
  result: Promise<Record<string, unknown>[]>;
}

/** Starts tests/integration/udp_decode.py; resolves once it listens. */
async function pythonDecoder(args: string[] = []): Promise<PyDecoder> {
  const proc = spawn("python3", [join(ROOT, "tests/integration/udp_decode.py"), ...args], {
    stdio: ["ignore", "pipe", "inherit"],
  });
  cleanup.push(() => proc.kill());
  const lines: string[] = [];
  const rl = createInterface({ input: proc.stdout! });
  let onPort: (p: number) => void = () => {};
  const portP = new Promise<number>((r) => (onPort = r));
  rl.on("line", (l) => {
    if (lines.length === 0) onPort((JSON.parse(l) as { port: number }).port);
    lines.push(l);
  });
  const result = new Promise<Record<string, unknown>[]>((res) =>
    proc.on("close", () =>
      res(lines.slice(1).map((l) => JSON.parse(l) as Record<string, unknown>)),
    ),
  );
  return { port: await portP, proc, result };
}

/** A `Path` log: [t, ...values] per line. */
const readLog = (file: string): number[][] =>
  readFileSync(file, "utf8")
    .trim()
    .split("\n")
    .filter((l) => l !== "")
    .map((l) => l.split(",").map(Number));

describe("UDP on loopback, real host", () => {
  test.skipIf(!hasPython)(
    "sender → receiver and sender → Python decoder: the values that went in come out",
    async () => {
      requireBuild();
      const dir = tempDir("mosaic-udp-");
      const py = await pythonDecoder(["--idle", "1.5", "--timeout", "30"]);
      const rx = await freePort();
      const rxRaw = await freePort();
      const file = join(dir, "udp.yaml");
      writeFileSync(
        file,
        `
Timer: { Type: ScheduledTimer, DesiredRate: 100 }
Sin: { Type: SinGenerator, Inputs: [Timer], Params: { Components: 3, Frequency: 3 }, Path: logs }
# Streamlined f64 back into this pipeline, the sender's timestamps kept.
Tx: { Type: UdpSender, Inputs: [Sin], Params: { Port: ${rx}, Category: 2, Subcategory: 7 } }
Rx: { Type: UdpReceiver, Params: { Port: ${rx}, Channels: 3, Category: 2, Timestamps: sender }, Path: logs }
# Raw f32 vectors.
TxRaw: { Type: UdpSender, Inputs: [Sin], Params: { Port: ${rxRaw}, Format: f32 } }
RxRaw: { Type: UdpReceiver, Params: { Port: ${rxRaw}, Channels: 3, Format: f32 }, Path: logs }
# To the Python decoder: f32 values, and MOSAIC's Myo serializer (signed bytes).
TxPy: { Type: UdpSender, Inputs: [Sin], Params: { Port: ${py.port}, ValueType: f32, Subcategory: 3 } }
TxMyo: { Type: UdpSender, Inputs: [Sin], Params: { Host: localhost, Port: ${py.port}, Serializer: myo } }
`,
      );
      const r = runCli(["run", file, "--duration", "1.5", "--json"], { timeoutMs: 60_000 });
      expect(r.code, r.stderr).toBe(0);
      const out = jsonLines(r.stdout);
      expect(out.filter((l) => l.type === "event" || l.type === "fatal")).toEqual([]);

      const sin = readLog(join(dir, "logs", "Sin.txt"));
      expect(sin.length).toBeGreaterThan(100);
      const sinByT = new Map(sin.map((row) => [row[0]!.toFixed(6), row.slice(1)]));

      // Streamlined round trip: the same timestamps and the same f64 values, none lost.
      const back = readLog(join(dir, "logs", "Rx.txt"));
      expect(back.length).toBeGreaterThanOrEqual(sin.length - 3);
      for (const row of back) expect(row.slice(1)).toEqual(sinByT.get(row[0]!.toFixed(6)));
      expect(back.map((row) => row[0])).toEqual(sin.slice(0, back.length).map((row) => row[0]));

      // Raw f32: the nearest f32 of every value, in order (timestamps are arrival times).
      const raw = readLog(join(dir, "logs", "RxRaw.txt"));
      expect(raw.length).toBeGreaterThanOrEqual(sin.length - 3);
      raw.forEach((row, i) => expect(row.slice(1)).toEqual(sin[i]!.slice(1).map(Math.fround)));

      // The Python decoder's view of the same datagrams.
      const decoded = await py.result;
      expect(decoded.filter((d) => "error" in d)).toEqual([]);
      const vec = decoded.filter((d) => d.type === 0x24);
      const myo = decoded.filter((d) => d.type === 0x11);
      expect(vec.length).toBeGreaterThanOrEqual(sin.length - 3);
      expect(myo.length).toBe(vec.length);
      vec.forEach((d, i) => {
        expect(d).toMatchObject({ count: 3, category: 0, subcategory: 3, counter: i });
        expect((d.timestamp as number).toFixed(6)).toBe(sin[i]![0]!.toFixed(6));
        expect(d.values).toEqual(sin[i]!.slice(1).map(Math.fround));
      });
      myo.forEach((d, i) => {
        expect(d).toMatchObject({ count: 3, category: 1, subcategory: 1, counter: i });
        const bytes = sin[i]!.slice(1).map(
          (v) => Math.max(-128, Math.min(127, Math.round(v * 128))) + 0,
        );
        expect(d.values).toEqual(bytes);
      });
    },
    90_000,
  );

  test("a port already in use: the receiver says which block and port, the rest keeps running", async () => {
    requireBuild();
    const dir = tempDir("mosaic-udp-");
    const holder: Socket = createSocket("udp4");
    await new Promise<void>((r) => holder.bind(0, "127.0.0.1", r));
    cleanup.push(() => holder.close());
    const port = holder.address().port;
    const file = join(dir, "busy-port.yaml");
    writeFileSync(
      file,
      `
Timer: { Type: ScheduledTimer, DesiredRate: 100 }
Sin: { Type: SinGenerator, Inputs: [Timer] }
Out: { Type: Sink, Inputs: [Sin] }
Rx: { Type: UdpReceiver, Params: { Port: ${port}, Channels: 2 } }
`,
    );
    const r = runCli(["run", file, "--duration", "1.5", "--json"], { timeoutMs: 60_000 });
    expect(r.code, r.stderr).toBe(0);
    const out = jsonLines(r.stdout);
    const events = out.filter((l) => l.type === "event");
    expect(events).toContainEqual(
      expect.objectContaining({
        level: "warning",
        block: "Rx",
        message: expect.stringMatching(
          new RegExp(
            `^cannot listen on UDP 127\\.0\\.0\\.1:${port}: port ${port} is already in use`,
          ),
        ),
      }),
    );
    const tel = out.filter((l) => l.type === "telemetry") as unknown as {
      blocks: { name: string; status: string; text: string }[];
    }[];
    const last = tel.at(-1)!;
    const by = Object.fromEntries(last.blocks.map((b) => [b.name, b]));
    expect(KEEPING_UP).toContain(by.Sin!.status);
    expect(by.Out!.text).toMatch(/events received/);
    expect(by.Rx!.text).toMatch(new RegExp(`cannot listen on UDP 127\\.0\\.0\\.1:${port}`));
  }, 60_000);
});
