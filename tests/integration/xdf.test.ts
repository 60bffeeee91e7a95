/**
 * XDF recordings read by an independent reader, pyxdf 1.17.5 (tests/reference's environment,
 * through tests/integration/xdf_check.py), written by the real CLI and engine workers (dist/):
 *
 * - a virtual-clock run: every timestamp and value exactly as the pipeline produced them (double64
 *   exact, float32 the float32 rounding of each value), the stream headers, labels and markers;
 * - kill -9 at five random moments of a real-time recording (32 channels at 2 kHz): each file
 *   opens in pyxdf without its footers, holds every sample up to at most 1 s before the kill with
 *   no hole, and after `mosaic repair` has footers that agree with its samples.
 */
import { spawnSync } from "node:child_process";
import { existsSync, mkdirSync, readdirSync, readFileSync, statSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { runVirtualPipeline } from "../../app/engine/testing";
import { bytesSource, XdfChunkReader, type XdfChunk } from "../../app/blocks/recording/xdf-reader";
import { requireBuild, ROOT, runCli, startCli, tempDir } from "./helpers";

const PYTHON = join(ROOT, "tests/reference/.venv/bin/python");
const CHECK = join(ROOT, "tests/integration/xdf_check.py");

interface PyStream {
  name: string;
  type: string;
  channel_count: number;
  nominal_srate: number;
  channel_format: string;
  source_id: string;
  labels: string[];
  footer: { first_timestamp: number; last_timestamp: number; sample_count: number } | null;
  n: number;
  first: number | null;
  last: number | null;
  clock_times: number[];
  time_stamps?: number[];
  values?: (number | string)[][];
}
interface PyFile {
  version: string;
  default_counts: number[];
  streams: PyStream[];
}

function pyxdf(file: string, full = false): PyFile {
  const r = spawnSync(PYTHON, [CHECK, file, ...(full ? ["--full"] : [])], {
    encoding: "utf8",
    maxBuffer: 256 * 1024 * 1024,
    timeout: 60_000,
  });
  if (r.status !== 0) throw new Error(`pyxdf could not read ${file}:\n${r.stderr}`);
  return JSON.parse(r.stdout) as PyFile;
}

beforeAll(() => {
  requireBuild();
  if (!existsSync(PYTHON)) {
    throw new Error("tests/reference/.venv is missing: run scripts/setup.sh (it installs pyxdf)");
  }
});

const START = 1_700_000_000;
const EXACT = `
Timer: { Type: ScheduledTimer, DesiredRate: 500 }
Sin: { Type: SinGenerator, Inputs: [Timer], Params: { Components: 3, Frequency: 7, Amplitude: 1000 } }
Marks:
  Type: Trigger
  Params:
    Labels: { rest: [0, 0], "fist ✊": [1, 0.25] }
    Schedule: [{ Label: "fist ✊", At: 0.3, Seconds: 0.5 }, { Label: rest, At: 1.2, Seconds: 0.1 }]
Rec64:
  Type: XdfRecorder
  Inputs: [Sin, Marks.label, Marks.target]
  Params: { File: exact64.xdf, Format: double64, Streams: { Sin: { Type: EMG, Labels: [a, b, c] } } }
Rec32: { Type: XdfRecorder, Inputs: [Sin], Params: { File: exact32.xdf } }
`;

describe("XDF recordings read by pyxdf", () => {
  test("timestamps and values exact, headers, labels and markers (virtual clock)", async () => {
    const dir = tempDir("mosaic-xdf-");
    writeFileSync(join(dir, "p.yaml"), EXACT);
    const r = runCli([
      "run",
      join(dir, "p.yaml"),
      "--clock",
      "virtual",
      "--duration",
      "2",
      "--start",
      String(START),
    ]);
    expect(r.stderr).toBe("");
    expect(r.code).toBe(0);
    // The same pipeline in this process: what the blocks produced.
    const ref = await runVirtualPipeline(EXACT, { catalog, duration: 2, start: START });
    const sin = ref.outputs.get("Sin")!;
    const label = ref.outputs.get("Marks")!;
    expect(sin.t).toHaveLength(1001);

    const x64 = pyxdf(join(dir, "exact64.xdf"), true);
    expect(x64.version).toBe("1.0");
    expect(x64.default_counts).toEqual([1001, 4, 4]);
    const [s, l, tg] = x64.streams;
    expect(s).toMatchObject({
      name: "Sin",
      type: "EMG",
      channel_count: 3,
      nominal_srate: 500,
      channel_format: "double64",
      source_id: "MOSAIC/Rec64/Sin",
      labels: ["a", "b", "c"],
      footer: { sample_count: 1001, first_timestamp: START, last_timestamp: sin.t[1000] },
    });
    expect(s!.time_stamps).toEqual(sin.t);
    expect(s!.values).toEqual(sin.v);
    // Markers: one string channel, irregular rate; label events, then the target vectors.
    expect(l).toMatchObject({
      name: "Marks.label",
      type: "Markers",
      channel_count: 1,
      nominal_srate: 0,
      channel_format: "string",
      labels: ["Marks.label"],
    });
    expect(l!.time_stamps).toEqual(label.t);
    expect(l!.values).toEqual([["1"], ["NaN"], ["0"], ["NaN"]]);
    expect(tg!.values).toEqual([["1,0.25"], ["NaN,NaN"], ["0,0"], ["NaN,NaN"]]);
    expect(tg!.time_stamps).toEqual(label.t);
    // Clock offsets every 5 s from the start, and one at the close.
    expect(s!.clock_times[0]).toBe(START);

    const x32 = pyxdf(join(dir, "exact32.xdf"), true);
    const s32 = x32.streams[0]!;
    expect(s32).toMatchObject({ channel_format: "float32", labels: ["ch1", "ch2", "ch3"] });
    expect(s32.time_stamps).toEqual(sin.t);
    expect(s32.values).toEqual(sin.v.map((row) => row.map((v) => Math.fround(v))));
  }, 60_000);
});

describe("pipelines/examples/record-xdf.yaml", () => {
  test("records the EMG, the envelope and the Stimulus's captures as pyxdf reads them", () => {
    const dir = tempDir("mosaic-xdf-example-");
    writeFileSync(
      join(dir, "record-xdf.yaml"),
      readFileSync(join(ROOT, "pipelines/examples/record-xdf.yaml"), "utf8"),
    );
    const args = ["--clock", "virtual", "--duration", "14", "--start", String(START)];
    const r = runCli(["run", join(dir, "record-xdf.yaml"), ...args]);
    expect(r.code, r.stderr).toBe(0);
    const made = readdirSync(join(dir, "recordings"));
    expect(made).toHaveLength(1);
    expect(made[0]).toMatch(/^\d{4}-\d\d-\d\d_\d\d-\d\d-\d\d\.xdf$/);
    const x = pyxdf(join(dir, "recordings", made[0]!), true);
    const [emg, env, cues] = x.streams;
    expect(emg).toMatchObject({ name: "Emg", type: "EMG", channel_count: 32, n: 28001 });
    expect(env).toMatchObject({ name: "Envelope", channel_count: 32, nominal_srate: 50, n: 701 });
    // fist, rest, fist: each capture's start (the label's target) and its stop.
    expect(cues).toMatchObject({ name: "Cues.trigger", type: "Markers", channel_format: "string" });
    expect(cues!.values).toEqual([["1"], ["NaN"], ["0"], ["NaN"], ["1"], ["NaN"]]);
    for (const s of x.streams) expect(s.footer?.sample_count).toBe(s.n);
  }, 60_000);
});

const KILLED = `
Timer: { Type: ScheduledTimer, DesiredRate: 2000 }
Emg: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 32, Seed: 5 } }
Rec: { Type: XdfRecorder, Inputs: [Emg], Params: { File: rec.xdf } }
`;

/** Waits until `file` exists with more than its header part. */
async function waitForData(file: string, timeoutMs = 20_000): Promise<void> {
  const until = Date.now() + timeoutMs;
  while (Date.now() < until) {
    if ((statSync(file, { throwIfNoEntry: false })?.size ?? 0) > 20_000) return;
    await new Promise((r) => setTimeout(r, 50));
  }
  throw new Error(`${file} did not grow within ${timeoutMs} ms`);
}

describe("kill -9 while recording", () => {
  test("five random kills: each file opens in pyxdf, ≤ 1 s lost, mosaic repair adds the footers", async () => {
    const base = tempDir("mosaic-xdf-kill-");
    const delays = Array.from({ length: 5 }, () => 300 + Math.random() * 2200);
    for (const [i, delay] of delays.entries()) {
      const dir = join(base, `k${i}`);
      mkdirSync(dir);
      writeFileSync(join(dir, "p.yaml"), KILLED);
      const file = join(dir, "rec.xdf");
      const proc = startCli(["run", join(dir, "p.yaml"), "--duration", "60"]);
      const exited = new Promise((r) => proc.on("exit", r));
      await waitForData(file);
      await new Promise((r) => setTimeout(r, delay));
      const killedAt = Date.now() / 1000;
      proc.kill("SIGKILL");
      await exited;
      const what = `kill ${i + 1} (${delay.toFixed(0)} ms after the first data)`;

      const x = pyxdf(file);
      const s = x.streams[0]!;
      expect(s.footer, what).toBeNull();
      expect(s.channel_count).toBe(32);
      expect(x.default_counts, what).toEqual([s.n]);
      // At most 1 s lost, and no hole: every tick from the first to the last is there.
      expect(killedAt - s.last!, what).toBeLessThanOrEqual(1);
      expect(s.n, what).toBe(Math.round((s.last! - s.first!) * 2000) + 1);

      // Repaired copy: the footers agree with the samples.
      const inPlace = i === 0;
      const rep = runCli(["repair", file, ...(inPlace ? ["--in-place"] : [])]);
      expect(rep.code, rep.stderr).toBe(0);
      expect(rep.stdout).toMatch(/added its footer/);
      const repaired = inPlace ? file : join(dir, "rec.repaired.xdf");
      const y = pyxdf(repaired);
      const r = y.streams[0]!;
      expect(r.n, what).toBe(s.n);
      expect(r.footer, what).toEqual({
        first_timestamp: s.first,
        last_timestamp: s.last,
        sample_count: s.n,
      });
      // A repaired file is whole: a second repair has nothing to do.
      const again = runCli(["repair", repaired, "--check"]);
      expect(again.code, again.stdout).toBe(0);
      expect(again.stdout).toMatch(/nothing to repair/);
    }
  }, 180_000);
});

describe("mosaic repair", () => {
  test("a file torn inside a Samples chunk: pyxdf reads what is whole, the repair cuts and adds footers", () => {
    const dir = tempDir("mosaic-xdf-torn-");
    writeFileSync(join(dir, "p.yaml"), EXACT);
    const args = ["--clock", "virtual", "--duration", "1", "--start", String(START)];
    expect(runCli(["run", join(dir, "p.yaml"), ...args]).code).toBe(0);
    // Our file without its last chunks, cut in the middle of the last Samples chunk of Sin.
    const whole = readFileSync(join(dir, "exact64.xdf"));
    const reader = new XdfChunkReader(bytesSource(whole));
    let last: XdfChunk | null = null;
    for (let c = reader.next(); c !== null; c = reader.next()) {
      if (c.tag === 3 && c.streamId === 1) last = c;
    }
    const cut = Math.floor((last!.offset + last!.end) / 2);
    const torn = join(dir, "torn.xdf");
    writeFileSync(torn, whole.subarray(0, cut));
    const x = pyxdf(torn);
    expect(x.streams[0]!.footer).toBeNull();
    const kept = x.streams[0]!.n;
    expect(kept).toBeGreaterThan(400);
    expect(kept).toBeLessThan(501);

    const rep = runCli(["repair", torn, "--out", join(dir, "fixed.xdf")]);
    expect(rep.code, rep.stderr).toBe(0);
    expect(rep.stdout).toMatch(
      new RegExp(
        `torn.xdf: dropped the last ${cut - last!.offset} bytes: byte ${last!.offset}: the file ends inside a chunk`,
      ),
    );
    const y = pyxdf(join(dir, "fixed.xdf"));
    const s = y.streams[0]!;
    expect(s.n).toBe(kept);
    expect(s.footer).toEqual({
      first_timestamp: START,
      last_timestamp: s.last,
      sample_count: kept,
    });
    // Never over an existing file.
    const again = runCli(["repair", torn, "--out", join(dir, "fixed.xdf")]);
    expect(again.code).toBe(1);
    expect(again.stderr).toMatch(/exists already/);
  }, 60_000);

  test("usage errors and unknown formats exit 2 with a message", () => {
    const dir = tempDir("mosaic-repair-");
    writeFileSync(join(dir, "a.txt"), "x");
    const unknown = runCli(["repair", join(dir, "a.txt")]);
    expect(unknown.code).toBe(2);
    expect(unknown.stderr).toMatch(/unknown format '.txt' \(repairs: .xdf, .edf, .bdf\)/);
    const none = runCli(["repair"]);
    expect(none.code).toBe(2);
    const notXdf = join(dir, "b.xdf");
    writeFileSync(notXdf, "not xdf at all");
    const bad = runCli(["repair", notXdf]);
    expect(bad.code).toBe(1);
    expect(bad.stderr).toMatch(/not an XDF file/);
    expect(runCli(["repair", "--help"]).stdout).toMatch(/--in-place/);
  });
});
