/**
 * DLR_ADCBT against the DLR ADC/BT simulator (app/devices/dlr-adcbt-simulator.ts, written from the
 * byte format) on a real pty pair (socat), through the real CLI and engine workers (dist/) with
 * the host's serial bridge: the block configures the board (channel count, start), every value it
 * logged is the simulator's frame k in volts exactly; malformed frames are counted in its status
 * and the stream resumes; the simulator closing its side (silence) is reported and recovered
 * when it comes back; an unplug (the pty pair disappears) is reported and the port reopened; a
 * missing port says so while the rest of the pipeline runs. Then `mosaic simulate dlr-adcbt` as a
 * child process with `mosaic run` of pipelines/devices/dlr-adcbt.yaml, and the example under
 * --simulate-devices.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import { createSocket } from "node:dgram";
import { existsSync, readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { afterEach, describe, expect, test } from "vitest";
import {
  dlrAdcBtVolts,
  startDlrAdcBtSimulator,
  type DlrAdcBtSimulator,
} from "../../app/devices/dlr-adcbt-simulator";
import { jsonLines, requireBuild, ROOT, runCli, startCli, tempDir } from "./helpers";

const haveSocat = spawnSync("socat", ["-V"]).status === 0;
const SEED = 7;
const CHANNELS = 4;

const children: ChildProcess[] = [];
const sims: DlrAdcBtSimulator[] = [];
afterEach(async () => {
  for (const s of sims.splice(0)) await s.close();
  for (const c of children.splice(0)) c.kill("SIGKILL");
});

const sleep = (ms: number) => new Promise((r) => setTimeout(r, ms));

async function waitFor(cond: () => boolean, ms: number, what: string): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await sleep(25);
  }
}

/** A socat pty pair: `dev` for the pipeline, `board` for the simulator. */
async function ptyPair(dir: string): Promise<ChildProcess> {
  const p = spawn("socat", [
    `pty,raw,echo=0,link=${join(dir, "dev")}`,
    `pty,raw,echo=0,link=${join(dir, "board")}`,
  ]);
  children.push(p);
  await waitFor(
    () => existsSync(join(dir, "dev")) && existsSync(join(dir, "board")),
    5000,
    "socat",
  );
  return p;
}

async function board(dir: string, first: number): Promise<DlrAdcBtSimulator> {
  const s = await startDlrAdcBtSimulator({
    path: join(dir, "board"),
    rate: 100,
    seed: SEED,
    first,
  });
  sims.push(s);
  return s;
}

function readLog(file: string): number[][] {
  if (!existsSync(file)) return [];
  return readFileSync(file, "utf8")
    .split("\n")
    .filter((l) => l !== "")
    .map((l) => l.split(",").map(Number));
}

/** The simulator's frame k as the block logs it: 5 · raw / 4000 V per channel. */
const frameVolts = (k: number): number[] =>
  Array.from({ length: CHANNELS }, (_, c) => dlrAdcBtVolts(SEED, c, k));

interface Telemetry {
  blocks: { name: string; text: string }[];
}

/** The block's status texts so far, from `run --json`'s telemetry lines. */
function statusTexts(out: string, name: string): string[] {
  return jsonLines(out)
    .filter((m) => m.type === "telemetry")
    .map((m) => (m as unknown as Telemetry).blocks.find((b) => b.name === name)?.text ?? "");
}

describe.skipIf(!haveSocat)("DLR_ADCBT with the simulated board on a socat pty pair", () => {
  test("exact values; malformed frames counted; silence and unplug reported and recovered", async () => {
    requireBuild();
    const dir = tempDir("mosaic-dlr-");
    let socat = await ptyPair(dir);
    const first = await board(dir, 0);
    const file = join(dir, "dlr.yaml");
    writeFileSync(
      file,
      `Timer: { Type: ScheduledTimer, DesiredRate: 200 }
Board:
  Type: DLR_ADCBT
  Inputs: [Timer]
  Params: { Port: ${JSON.stringify(join(dir, "dev"))}, Channels: ${CHANNELS} }
  Path: ${JSON.stringify(join(dir, "logs"))}
`,
    );
    const run = startCli(["run", file, "--json", "--duration", "60"]);
    children.push(run);
    let out = "";
    run.stdout!.on("data", (d: Buffer) => (out += d.toString()));
    run.stderr!.on("data", (d: Buffer) => (out += d.toString()));
    const texts = (): string[] => statusTexts(out, "Board");
    const last = (): string => texts().at(-1) ?? "";
    const log = join(dir, "logs", "Board.txt");

    // The original's configuration, then frames; four faults between frames.
    await waitFor(() => first.streaming, 10_000, "the channel count and start commands");
    expect(first.commands.slice(0, 2)).toEqual([`channels ${CHANNELS}`, "start"]);
    await first.waitForFrames(100);
    await waitFor(() => /^streaming from /.test(last()), 5000, "streaming in the status");
    for (const kind of ["badEnd", "badLength", "truncated", "noise"] as const) {
      first.inject(kind);
      await first.waitForFrames(first.sent + 10);
    }
    await first.waitForFrames(first.sent + 50);
    // 16 + 18 + 8 bytes of the three malformed frames (4 channels), 7 of noise.
    await waitFor(
      () => /3 malformed frames .* · 49 bytes skipped/.test(last()),
      5000,
      `the malformed count (status: ${last()})`,
    );
    const malformedText = last();
    const sent1 = first.sent;

    // The simulator closes its side: silence, reported; a new one on the same pty is
    // configured by the block (it sends the configuration every second) and streams.
    await first.close();
    await waitFor(() => /^lost .*no frames for 1 s/.test(last()), 5000, "the silence");
    const silentText = last();
    const second = await board(dir, 5000);
    await waitFor(() => second.streaming, 5000, "the configuration sent again");
    await second.waitForFrames(100);
    await waitFor(() => /reconnected 1×/.test(last()), 5000, "the recovery");

    // The unplug: the pty pair disappears, the port is reopened once it is back.
    socat.kill("SIGTERM");
    await waitFor(
      () => /^lost .*(disconnected|no such device).*reconnecting every 1 s/.test(last()),
      5000,
      `the unplug (status: ${last()})`,
    );
    const unplugText = last();
    await second.close();
    const sent2 = second.sent;
    await sleep(500);
    socat = await ptyPair(dir);
    const third = await board(dir, 9000);
    await waitFor(() => third.streaming, 8000, "the configuration after the reopen");
    await third.waitForFrames(100);
    await waitFor(() => /reconnected 2×/.test(last()), 5000, "the second recovery");
    await sleep(300);
    run.kill("SIGINT");
    await new Promise((r) => run.on("exit", r));
    const sent3 = third.sent;
    const finalText =
      texts()
        .filter((t) => !t.startsWith("stopped"))
        .at(-1) ?? "";

    // Every value logged is a frame the simulator sent, exactly, in order.
    const byValues = new Map<string, number>();
    for (const [from, n] of [
      [0, sent1],
      [5000, sent2],
      [9000, sent3],
    ] as const) {
      for (let k = from; k < from + n; k++) byValues.set(frameVolts(k).join(), k);
    }
    const rows = readLog(log);
    expect(rows.length).toBeGreaterThan(400);
    const unknown = rows
      .map((r) => r.slice(1))
      .filter((v) => v.some((x) => x !== 0) && !byValues.has(v.join()));
    expect(unknown, "logged rows that are no frame the simulator sent").toEqual([]);
    const ks: number[] = [];
    for (const r of rows) {
      const k = byValues.get(r.slice(1).join());
      if (k !== undefined && k !== ks.at(-1)) ks.push(k);
    }
    const dropped = Number(/(\d+) dropped/.exec(finalText)?.[1] ?? 0);
    const segment = (from: number, to: number) => ks.filter((k) => k >= from && k < to);
    const s1 = segment(0, 5000);
    const s2 = segment(5000, 9000);
    const s3 = segment(9000, Infinity);
    for (const [s, from] of [
      [s1, 0],
      [s2, 5000],
      [s3, 9000],
    ] as const) {
      expect(s[0]).toBe(from);
      // Increasing; gaps only where the block says it dropped samples (its queue was full).
      let gaps = 0;
      for (let i = 1; i < s.length; i++) {
        expect(s[i]).toBeGreaterThan(s[i - 1]!);
        gaps += s[i]! - s[i - 1]! - 1;
      }
      expect(gaps).toBeLessThanOrEqual(dropped);
    }
    // Before the silence every frame arrived; before the unplug and the stop, nearly all.
    expect(s1.at(-1)).toBe(sent1 - 1);
    expect(s2.length).toBeGreaterThanOrEqual(90);
    expect(s3.length).toBeGreaterThanOrEqual(90);
    console.log(
      `DLR_ADCBT: ${ks.length} frames exact (${s1.length}/${sent1}, ${s2.length}/${sent2}, ${s3.length}/${sent3}); ` +
        `statuses: "${malformedText}" | "${silentText}" | "${unplugText}" | "${finalText}"`,
    );
  }, 90_000);

  test("a missing port: the status says so, the rest of the pipeline runs", () => {
    requireBuild();
    const dir = tempDir("mosaic-dlr-");
    const file = join(dir, "missing.yaml");
    const port = join(dir, "no-such-board");
    writeFileSync(
      file,
      `Timer: { Type: ScheduledTimer, DesiredRate: 100 }
Board: { Type: DLR_ADCBT, Inputs: [Timer], Params: [${JSON.stringify(port)}, 3], Path: ${JSON.stringify(join(dir, "logs"))} }
Sine: { Type: SinGenerator, Inputs: [Timer], Params: [2], Path: ${JSON.stringify(join(dir, "logs"))} }
`,
    );
    const r = runCli(["run", file, "--json", "--duration", "2.5"], { timeoutMs: 60_000 });
    expect(r.code, r.stderr).toBe(0);
    // The first reports may still say "connecting…" or "opening…" (the main thread loads the
    // serial module on the first open; under load that takes a few reports); then the failure, and
    // nothing else until the end.
    const transient = [`connecting to the DLR ADC/BT on serial port ${port} `, `opening ${port}…`];
    const texts = statusTexts(r.stdout, "Board").filter(
      (t) => t !== "stopped" && !transient.some((x) => t.startsWith(x)),
    );
    const text = texts[0] ?? "";
    expect(new Set(texts).size, texts.join(" | ")).toBe(1);
    expect(text).toMatch(
      new RegExp(
        `^cannot open ${port.replace(/[.*+?^${}()|[\]\\/]/g, "\\$&")}: no such device \\(unplugged\\?\\) — reconnecting every 1 s \\(sending zeros\\)`,
      ),
    );
    const sine = readLog(join(dir, "logs", "Sine.txt"));
    expect(sine.length).toBeGreaterThan(150);
    const zeros = readLog(join(dir, "logs", "Board.txt"));
    expect(zeros.length).toBeGreaterThan(150);
    expect(zeros.every((row) => row.slice(1).every((x) => x === 0))).toBe(true);
    const warnings = jsonLines(r.stdout).filter(
      (m) =>
        m.type === "event" &&
        m.level === "warning" &&
        m.block === "Board" &&
        String(m.message).includes("cannot open"),
    );
    expect(warnings.length).toBeGreaterThan(0);
  }, 60_000);

  test("mosaic simulate dlr-adcbt + mosaic run pipelines/devices/dlr-adcbt.yaml", async () => {
    requireBuild();
    const dir = tempDir("mosaic-dlr-");
    await ptyPair(dir);
    const sim = startCli(["simulate", "dlr-adcbt", "--port", join(dir, "board"), "--verbose"]);
    children.push(sim);
    const lines: string[] = [];
    createInterface({ input: sim.stdout! }).on("line", (l) => lines.push(l));
    await waitFor(() => lines.length >= 2, 15_000, "the simulator's banner");
    expect(lines[0]).toBe(
      `DLR ADC/BT simulator on ${join(dir, "board")}: waits for the channel count and start, then streams 100 frames/s (10 channels until told otherwise), seed 1`,
    );
    const rx = createSocket("udp4");
    let datagrams = 0;
    rx.on("message", () => datagrams++);
    await new Promise<void>((r) => rx.bind(0, "127.0.0.1", r));
    const file = join(dir, "example.yaml");
    writeFileSync(
      file,
      readFileSync(join(ROOT, "pipelines/devices/dlr-adcbt.yaml"), "utf8")
        .replace("Port: /tmp/dlr,", `Port: ${JSON.stringify(join(dir, "dev"))},`)
        .replace("Port: 5005", `Port: ${rx.address().port}`),
    );
    const r = runCli(["run", file, "--duration", "3", "--json"], { timeoutMs: 60_000 });
    expect(r.code, r.stderr).toBe(0);
    expect(statusTexts(r.stdout, "Forces").some((t) => /^streaming from /.test(t))).toBe(true);
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as
      { blocks: { name: string; events: number }[] } | undefined;
    expect(summary!.blocks.find((b) => b.name === "ToScene")!.events).toBeGreaterThan(250);
    await waitFor(() => datagrams > 100, 5000, "the Sender's datagrams");
    rx.close();
    expect(lines.some((l) => l.includes("channel count: 4 (frames of 16 bytes)"))).toBe(true);
    sim.kill("SIGINT");
    const code = await new Promise<number | null>((res) => sim.on("exit", (c) => res(c)));
    expect(code).toBe(0);

    const missing = runCli(["simulate", "dlr-adcbt"]);
    expect(missing.code).toBe(2);
    expect(missing.stderr.trim()).toMatch(/^mosaic simulate dlr-adcbt: --port PATH is required: /);
    const bad = runCli(["simulate", "dlr-adcbt", "--port", join(dir, "board"), "--rate", "fast"]);
    expect([bad.code, bad.stderr.trim()]).toEqual([
      2,
      "mosaic simulate dlr-adcbt: --rate must be a number, not 'fast'",
    ]);
    const none = runCli(["simulate", "dlr-adcbt", "--port", join(dir, "nothing")]);
    expect(none.code).toBe(2);
    expect(none.stderr.trim()).toMatch(
      new RegExp(`^mosaic simulate dlr-adcbt: cannot open ${join(dir, "nothing")}: `),
    );
  }, 90_000);

  test("the example under --simulate-devices", () => {
    requireBuild();
    const r = runCli(
      ["run", "pipelines/devices/dlr-adcbt.yaml", "--simulate-devices", "--duration", "1.5"],
      { timeoutMs: 60_000 },
    );
    expect(r.code, r.stderr).toBe(0);
    expect(r.stderr).toMatch(/block 'Forces' \(DLR_ADCBT\) simulated by SinGenerator, 4 channels/);
  }, 60_000);
});
