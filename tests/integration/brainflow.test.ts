/**
 * The BrainFlow block with a real Python sidecar and real BrainFlow sessions, through the real
 * CLI, on BrainFlow's own simulators: the synthetic board (every sample once, at its rate: its
 * package numbers consecutive, its count matching BrainFlow's own arrival timestamps) and the
 * playback board (a file recorded from the synthetic board by tests/integration/brainflow_record.py
 * comes out value for value); a board on a serial port that does not exist (one clear error,
 * then retries); the sidecar killed mid-run (reported, restarted, streaming again). Skipped where
 * uv or the sidecar's environment is missing (scripts/setup.sh installs them).
 */
import { spawnSync } from "node:child_process";
import { readFileSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { jsonLines, requireBuild, ROOT, runCli, startCli, tempDir } from "./helpers";

const SIDECAR = join(ROOT, "native-bridges", "python");

/** Runs Python in the sidecar's environment (native-bridges/python on PYTHONPATH). */
function python(args: string[], cwd = ROOT) {
  return spawnSync(
    "python3",
    [
      "-m",
      "uv",
      "run",
      "--quiet",
      "--frozen",
      "--project",
      SIDECAR,
      "--python",
      "python3.11",
    ].concat(["python", ...args]),
    {
      cwd,
      encoding: "utf8",
      env: { ...process.env, UV_PYTHON_DOWNLOADS: "never", PYTHONPATH: SIDECAR },
      timeout: 120_000,
    },
  );
}

const haveBrainFlow = python(["-c", "import brainflow, numpy"]).status === 0;

interface BlockTel {
  name: string;
  status: string;
  events: number;
  text: string;
  errors: number;
}

const telemetry = (stdout: string): { blocks: BlockTel[] }[] =>
  jsonLines(stdout).filter((l) => l.type === "telemetry") as unknown as { blocks: BlockTel[] }[];

const blockEvents = (stdout: string, block: string) =>
  jsonLines(stdout).filter((l) => l.type === "event" && l.block === block);

/** The log's rows: [timestamp, values…]. */
const logRows = (path: string): number[][] =>
  readFileSync(path, "utf8")
    .split("\n")
    .filter((l) => l)
    .map((l) => l.split(",").map(Number));

/** A file written by DataFilter.write_file: one row per sample, tab-separated, all channels. */
const brainflowFile = (path: string): number[][] =>
  readFileSync(path, "utf8")
    .split("\n")
    .filter((l) => l.trim())
    .map((l) => l.trim().split("\t").map(Number));

/** BrainFlow's synthetic board: 16 EXG channels in rows 1…16, its package number in row 0. */
const SYNTHETIC_EXG = Array.from({ length: 16 }, (_, i) => i + 1);
const SYNTHETIC_PACKAGE = 0;

describe.skipIf(!haveBrainFlow)("BrainFlow block with a real sidecar", () => {
  test("synthetic board: every sample once (package numbers consecutive), at 250 Hz by BrainFlow's own clock", () => {
    requireBuild();
    const dir = tempDir("mosaic-brainflow-");
    writeFileSync(
      join(dir, "synthetic.yaml"),
      `
Board:
  Type: BrainFlow
  Path: board.txt
  Params: { Board: synthetic, Channels: [exg, package, timestamp] }
`,
    );
    const r = runCli(["run", join(dir, "synthetic.yaml"), "--duration", "5", "--json"], {
      cwd: dir,
      timeoutMs: 90_000,
    });
    expect(r.code, r.stderr).toBe(0);
    const rows = logRows(join(dir, "board.txt"));
    expect(rows.length).toBeGreaterThan(250); // at least a second of the 5 s streamed
    const width = 1 + 16 + 2;
    expect(rows.every((row) => row.length === width)).toBe(true);
    // The package number counts 0…255 and wraps: +1 (mod 256) from each sample to the next
    // means no sample lost and none repeated, across every poll's batch.
    const pkg = rows.map((row) => row[17]!);
    const steps = pkg.slice(1).map((p, i) => (((p - pkg[i]!) % 256) + 256) % 256);
    expect(steps.filter((s) => s !== 1)).toEqual([]);
    // The count against BrainFlow's own arrival stamps: never more than 250 Hz × the time it
    // streamed (no repeats), and near it (the synthetic board paces itself with a 4 ms sleep per
    // sample, so a loaded machine slows it: a loose lower bound; the package numbers above are
    // the exact check that nothing was lost).
    const ts = rows.map((row) => row[18]!);
    const streamed = ts.at(-1)! - ts[0]!;
    expect(rows.length - 1).toBeLessThanOrEqual(250 * streamed + 3);
    expect(rows.length - 1).toBeGreaterThan(0.8 * 250 * streamed);
    // Our stamps (logged to the µs) run on the board's sample clock: 4 ms apart (re-anchored to
    // the arrival time when the board falls behind its nominal rate by more than 0.5 s).
    const on4ms = rows.slice(1).filter((row, i) => Math.abs(row[0]! - rows[i]![0]! - 0.004) < 2e-6);
    expect(on4ms.length).toBeGreaterThan(0.95 * (rows.length - 1));
    const last = telemetry(r.stdout)
      .at(-1)!
      .blocks.find((b) => b.name === "Board")!;
    expect(last.text).toMatch(/^streaming from board synthetic/);
    expect(last.text).not.toMatch(/lost/);
    expect(last.events).toBe(rows.length);
  }, 120_000);

  test("playback board: the recorded file comes out value for value, and the run ends with it", () => {
    requireBuild();
    const dir = tempDir("mosaic-brainflow-");
    const file = join(dir, "recording.csv");
    const rec = python([join(ROOT, "tests", "integration", "brainflow_record.py"), file, "1.5"]);
    expect(rec.status, rec.stderr).toBe(0);
    const recorded = brainflowFile(file);
    expect(recorded.length).toBe(Number(rec.stdout.trim()));
    writeFileSync(
      join(dir, "playback.yaml"),
      `
Board:
  Type: BrainFlow
  Path: board.txt
  Params:
    Board: PLAYBACK_FILE_BOARD
    MasterBoard: SYNTHETIC_BOARD
    File: recording.csv
    Channels: [exg, package]
    Silence: 1
`,
    );
    const r = runCli(["run", join(dir, "playback.yaml"), "--duration", "60", "--json"], {
      cwd: dir,
      timeoutMs: 90_000,
    });
    expect(r.code, r.stderr).toBe(0);
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary")!;
    expect(summary.reason).toBe("finished");
    const rows = logRows(join(dir, "board.txt"));
    const expected = recorded.map((line) => [
      ...SYNTHETIC_EXG.map((c) => line[c]!),
      line[SYNTHETIC_PACKAGE]!,
    ]);
    // Every sample of the file, in order, exactly (f64 parsed from the file's text both ways).
    expect(rows.map((row) => row.slice(1))).toEqual(expected);
    const last = telemetry(r.stdout)
      .at(-1)!
      .blocks.find((b) => b.name === "Board")!;
    expect(last.text).toMatch(/the playback file ended/);
  }, 120_000);

  test("a serial port that does not exist: one clear error, then retries", () => {
    requireBuild();
    const dir = tempDir("mosaic-brainflow-");
    writeFileSync(
      join(dir, "cyton.yaml"),
      `
Board:
  Type: BrainFlow
  Params: { Board: CYTON_BOARD, SerialPort: /dev/ttyMOSAIC_NONE, Retry: 0.2 }
`,
    );
    const r = runCli(["run", join(dir, "cyton.yaml"), "--duration", "6", "--json"], {
      cwd: dir,
      timeoutMs: 90_000,
    });
    // A failing board is an error (the run exits 1), reported once, and retried meanwhile.
    expect(r.code, r.stderr).toBe(1);
    const errors = blockEvents(r.stdout, "Board").filter((e) => e.level === "error");
    expect(errors.map((e) => String(e.message))).toEqual([
      expect.stringMatching(/UNABLE_TO_OPEN_PORT_ERROR.*check the serial port's name/),
    ]);
    const last = telemetry(r.stdout)
      .at(-1)!
      .blocks.find((b) => b.name === "Board")!;
    const attempt = /attempt (\d+)/.exec(last.text);
    expect(attempt, last.text).not.toBeNull();
    expect(Number(attempt![1])).toBeGreaterThanOrEqual(4);
    expect(last.text).toMatch(/\/dev\/ttyMOSAIC_NONE/);
  }, 120_000);

  test("an unknown board is a load error with a did-you-mean", () => {
    requireBuild();
    const dir = tempDir("mosaic-brainflow-");
    writeFileSync(
      join(dir, "typo.yaml"),
      "Board: { Type: BrainFlow, Params: { Board: GFORCE_PR_BOARD } }\n",
    );
    const r = runCli(["run", join(dir, "typo.yaml"), "--duration", "1"], {
      cwd: dir,
      timeoutMs: 90_000,
    });
    expect(r.code).toBe(2);
    expect(r.stdout + r.stderr).toMatch(
      /Board.*no board named 'GFORCE_PR_BOARD'; did you mean GFORCE_PRO_BOARD/s,
    );
  }, 120_000);

  test("pipelines/devices/mindrove.yaml under --simulate-devices: the synthetic board in the armband's 8 channels at 500 Hz", () => {
    requireBuild();
    const dir = tempDir("mosaic-brainflow-");
    const yaml = readFileSync(join(ROOT, "pipelines/devices/mindrove.yaml"), "utf8").replace(
      "Type: BrainFlow\n",
      "Type: BrainFlow\n  Path: armband.txt\n",
    );
    writeFileSync(join(dir, "mindrove.yaml"), yaml);
    const r = runCli(
      ["run", join(dir, "mindrove.yaml"), "--simulate-devices", "--duration", "5", "--json"],
      {
        cwd: dir,
        timeoutMs: 90_000,
      },
    );
    expect(r.code, r.stderr).toBe(0);
    expect(r.stderr).toMatch(
      /block 'Armband' \(BrainFlow\) simulated by BrainFlow's synthetic board in MINDROVE_WIFI_BOARD's channels and at its rate/,
    );
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as unknown as {
      blocks: { name: string; desiredRate: number; events: number; text: string }[];
    };
    const armband = summary.blocks.find((b) => b.name === "Armband")!;
    // The armband's shape and rate (mindrove 5.3.0: 8 EXG channels at 500 Hz), as on the device.
    expect(armband.desiredRate).toBe(500);
    const rows = logRows(join(dir, "armband.txt"));
    expect(rows.length).toBeGreaterThan(100); // streaming (the sidecar takes a second or two to start)
    expect(rows.every((row) => row.length === 1 + 8)).toBe(true);
    expect(armband.text).toMatch(/BrainFlow's synthetic board as MINDROVE_WIFI_BOARD/);
    expect(summary.blocks.find((b) => b.name === "Use")!.events).toBe(armband.events);
  }, 120_000);

  test("the sidecar killed mid-run: reported, restarted, the board streams again", async () => {
    requireBuild();
    const dir = tempDir("mosaic-brainflow-");
    writeFileSync(
      join(dir, "kill.yaml"),
      "Board: { Type: BrainFlow, Params: { Board: synthetic, Channels: [exg, package] } }\n",
    );
    const cli = startCli(["run", join(dir, "kill.yaml"), "--duration", "10", "--json"], dir);
    let stdout = "";
    let stderr = "";
    cli.stdout!.on("data", (d: Buffer) => (stdout += d.toString()));
    cli.stderr!.on("data", (d: Buffer) => (stderr += d.toString()));
    const board = () =>
      telemetry(stdout)
        .at(-1)
        ?.blocks.find((b) => b.name === "Board");
    const pidOf = (): number | undefined => {
      const m = /pid (\d+)/.exec(board()?.text ?? "");
      return m ? Number(m[1]) : undefined;
    };
    const wait = (ms: number) => new Promise((r) => setTimeout(r, ms));
    let first: number | undefined;
    for (let i = 0; i < 400 && first === undefined; i++) {
      await wait(50);
      if ((board()?.events ?? 0) > 250) first = pidOf();
    }
    expect(first, stderr).toBeDefined();
    const before = board()!.events;
    process.kill(first!, "SIGKILL");
    const code = await new Promise<number | null>((r) => cli.on("exit", r));
    expect(code, stderr).toBe(1); // the crash is a block error
    const messages = blockEvents(stdout, "Board").map((e) => String(e.message));
    expect(messages.join("\n")).toMatch(new RegExp(`pid ${first}\\).*restarting`));
    const last = board()!;
    expect(last.text).toMatch(/sidecar restarted 1×/);
    expect(last.text).toMatch(/^streaming from board synthetic/);
    expect(pidOf()).not.toBe(first);
    // Streaming again after the restart: at least another second of samples.
    expect(last.events).toBeGreaterThan(before + 250);
  }, 120_000);
});
