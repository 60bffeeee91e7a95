/**
 * The paper's record–replay promise, made exact (issue 16, item 4): a pipeline records its EMG
 * with an XdfRecorder (double64) while a filter, windowed features and an incremental predictor
 * process it; the same processing then replays the recording through a FilePlayer under the
 * virtual clock, and every downstream log is byte-identical to the recorded run's. Also: an EDF+
 * recording replays within one digital step at the recorded times; a FilePlayer refuses what it
 * cannot play with a message naming the param.
 */
import { readFileSync, readdirSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { jsonLines, requireBuild, runCli, tempDir } from "./helpers";

/** The processing both runs share: cues, envelope, features, a learning predictor. */
const CHAIN = `
Pace: { Type: ScheduledTimer, DesiredRate: 25 }
Cues:
  Type: Stimulus
  Inputs: [Pace]
  Params:
    Labels: { rest: [0, 0], fist: [1, 0], open: [0, 1] }
    Repetitions: 2
    Seed: 3
    Rest: 1
    Rise: 0.5
    Hold: 1
    Capture: 1
    Fall: 0.5
    Autostart: true
Rectified: { Type: Function, Inputs: [Emg], Params: { Operation: abs }, Path: logs/ }
LowPass:
  Type: Filter
  Inputs: [Rectified]
  Params:
    Numerator: [0.00094469, 0.0018894, 0.00094469]
    Denominator: [1, -1.9112, 0.91498]
  Path: logs/
Windows: { Type: SlidingWindow, Inputs: [Emg], Params: { Length: 50, Step: 25 } }
Features: { Type: FeatureSet, Inputs: [Windows], Params: { Features: [MAV, WL, ZC] }, Path: logs/ }
Envelope: { Type: Resampler, Inputs: [LowPass, Pace], Path: logs/ }
Predictor:
  Type: IncrementalPredictor
  Inputs: [Envelope, Cues.trigger]
  Params: { Model: ridge }
  Path: logs/
`;

const RECORD = `
Timer: { Type: ScheduledTimer, DesiredRate: 500 }
Emg:
  Type: EmgSimulator
  Inputs: [Timer, Cues.target]
  Params: { Channels: 4, Seed: 11, CueGestures: [fist, open] }
  Path: logs/
Rec: { Type: XdfRecorder, Inputs: [Emg], Params: { File: rec.xdf, Format: double64 } }
Edf:
  Type: EdfRecorder
  Inputs: [Emg]
  Params: { File: rec.edf, PhysicalRange: [-5, 5] }
${CHAIN}`;

const REPLAY = (file: string) => `
Emg: { Type: FilePlayer, Params: { File: ${file} }, Path: logs/ }
${CHAIN}`;

const DOWNSTREAM = ["Rectified", "LowPass", "Features", "Envelope", "Predictor", "Predictor.fit"];

let dir = "";
const read = (sub: string, name: string) =>
  readFileSync(join(dir, sub, "logs", `${name}.txt`), "utf8");

function run(file: string, logs: string, extra: string[] = []) {
  const r = runCli(
    ["run", file, "--clock", "virtual", "--duration", "8", "--log-dir", logs, "--json", ...extra],
    { cwd: dir, timeoutMs: 60_000 },
  );
  expect(r.code, r.stderr).toBe(0);
  return r;
}

beforeAll(() => {
  requireBuild();
  dir = tempDir("mosaic-replay-");
  writeFileSync(join(dir, "record.yaml"), RECORD);
  writeFileSync(join(dir, "replay-xdf.yaml"), REPLAY("rec.xdf"));
  writeFileSync(join(dir, "replay-edf.yaml"), REPLAY("rec.edf"));
  run("record.yaml", join(dir, "A"));
});

describe("record → replay", () => {
  test("XDF: the replayed run's downstream logs are byte-identical to the recorded run's", () => {
    run("replay-xdf.yaml", join(dir, "B"));
    // The replayed EMG is the recorded EMG, row for row (its timestamps exactly as recorded).
    expect(read("B", "Emg")).toBe(read("A", "Emg"));
    for (const name of DOWNSTREAM) {
      const a = read("A", name);
      expect(a.split("\n").length, name).toBeGreaterThan(40);
      expect(read("B", name), `${name}.txt`).toBe(a);
    }
    // The same logs in both runs, but the simulator's gesture port and the player's position.
    const a = readdirSync(join(dir, "A", "logs")).filter((f) => !f.startsWith("Emg.gesture"));
    const b = readdirSync(join(dir, "B", "logs")).filter((f) => !f.startsWith("Emg.position"));
    expect(b.sort()).toEqual(a.sort());
  });

  test("EDF+: the replayed EMG is the recorded one within one digital step, at the recorded times", () => {
    const r = run("replay-edf.yaml", join(dir, "C"));
    const rows = (text: string) =>
      text
        .trim()
        .split("\n")
        .map((l) => l.split(",").map(Number));
    const a = rows(read("A", "Emg"));
    const c = rows(read("C", "Emg"));
    // Whole records only: what the recorder held at the end may be missing.
    expect(c.length).toBeGreaterThan(a.length - 500 * 0.5);
    const step = 10 / 65535;
    let worst = 0;
    for (let i = 0; i < c.length; i++) {
      expect(c[i]![0]).toBeCloseTo(a[i]![0]!, 6);
      for (let k = 1; k <= 4; k++) worst = Math.max(worst, Math.abs(c[i]![k]! - a[i]![k]!));
    }
    expect(worst).toBeLessThanOrEqual(step);
    expect(r.stderr).not.toMatch(/error/);
  });

  test("what a FilePlayer cannot play is refused, naming the param", () => {
    writeFileSync(
      join(dir, "bad.yaml"),
      `Emg: { Type: FilePlayer, Params: { File: rec.xdf, Stream: Nope } }\n`,
    );
    const bad = runCli(["validate", "bad.yaml"], { cwd: dir });
    expect(bad.code).toBe(2);
    expect(bad.stderr + bad.stdout).toMatch(
      /has no stream "Nope" \(streams: 0: Emg \(double64\)\)/,
    );
    writeFileSync(
      join(dir, "cols.yaml"),
      `Emg: { Type: FilePlayer, Params: { File: rec.edf, Columns: [nope] } }\n`,
    );
    const cols = runCli(["validate", "cols.yaml"], { cwd: dir });
    expect(cols.code).toBe(2);
    expect(cols.stderr + cols.stdout).toMatch(/Columns: 'rec\.edf' has no channel 'nope'/);
    // A short replay runs and ends cleanly.
    const ok = runCli(
      ["run", "replay-xdf.yaml", "--clock", "virtual", "--duration", "0.1", "--json"],
      {
        cwd: dir,
      },
    );
    expect(ok.code, ok.stderr).toBe(0);
    expect(jsonLines(ok.stdout).some((l) => l.type === "summary")).toBe(true);
  });
});
