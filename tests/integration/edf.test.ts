/**
 * EdfRecorder end to end (issue 16, item 3): the real CLI writes EDF+/BDF+ files and three
 * independent readers (pyedflib, edfio, MNE: tests/integration/edf_check.py) read them back —
 * exact digital values for integer-step data, values within one digital step of what the
 * pipeline sent, labels, rates and annotations; recordings killed with SIGKILL at five random
 * moments open in all three and lose at most a second; `repairEdf` fixes a torn, uncounted file.
 */
import { spawn, spawnSync, type ChildProcess } from "node:child_process";
import {
  closeSync,
  copyFileSync,
  ftruncateSync,
  openSync,
  readdirSync,
  readFileSync,
  readSync,
  statSync,
  writeFileSync,
  writeSync,
} from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { repairEdf } from "../../app/blocks/recording/edf-repair";
import { CLI, requireBuild, ROOT, tempDir, type CliResult } from "./helpers";

/** The CLI bundle: dist/ (npm test builds it), or a private build named by MOSAIC_CLI. */
const BUNDLE = process.env.MOSAIC_CLI ?? CLI;

function runCli(args: string[], opts: { timeoutMs?: number } = {}): CliResult {
  const r = spawnSync(process.execPath, [BUNDLE, ...args], {
    cwd: ROOT,
    encoding: "utf8",
    timeout: opts.timeoutMs ?? 60_000,
    env: { ...process.env, NO_COLOR: "1" },
  });
  return { code: r.status, stdout: r.stdout, stderr: r.stderr };
}

const startCli = (args: string[]): ChildProcess =>
  spawn(process.execPath, [BUNDLE, ...args], {
    cwd: ROOT,
    env: { ...process.env, NO_COLOR: "1" },
    stdio: "ignore",
  });

const PYTHON = join(ROOT, "tests/reference/.venv/bin/python");
const CHECK = join(ROOT, "tests/integration/edf_check.py");
const START = 1_790_000_000; // virtual clock start: 2026-09-21 14:13:20 UTC

interface Checked {
  path: string;
  start: number;
  records: number;
  duration: number;
  failures: string[];
}

function check(dir: string, job: Record<string, unknown>): Checked[] {
  const jobFile = join(dir, `job-${Math.random().toString(36).slice(2)}.json`);
  writeFileSync(jobFile, JSON.stringify(job));
  const r = spawnSync(PYTHON, [CHECK, jobFile], {
    encoding: "utf8",
    timeout: 300_000,
    maxBuffer: 64 * 1024 * 1024,
  });
  if (r.status !== 0) throw new Error(`edf_check.py failed (${r.status}): ${r.stderr}`);
  return (JSON.parse(r.stdout) as { files: Checked[] }).files;
}

/** Lines `t,v1,…` of a Logger file. */
function readLog(path: string): { t: number[]; v: number[][] } {
  const t: number[] = [];
  const v: number[][] = [];
  for (const line of readFileSync(path, "utf8").split("\n")) {
    if (line === "") continue;
    const f = line.split(",").map(Number);
    t.push(f[0]!);
    v.push(f.slice(1));
  }
  return { t, v };
}

const columns = (v: number[][], n: number): number[][] =>
  Array.from({ length: n }, (_, c) => v.map((row) => row[c]!));

/** Seeded integer steps k (digital values) in [lo, hi]. */
function steps(count: number, channels: number, lo: number, hi: number, seed: number): number[][] {
  let s = seed;
  const next = () => {
    s = (s * 1103515245 + 12345) % 2147483648;
    return s / 2147483648;
  };
  return Array.from({ length: count }, (_, i) =>
    Array.from({ length: channels }, (_, c) =>
      c === 0 ? lo + (i % (hi - lo + 1)) : Math.floor(lo + next() * (hi - lo + 1)),
    ),
  );
}

describe("EdfRecorder through the CLI", () => {
  beforeAll(() => {
    if (process.env.MOSAIC_CLI === undefined) requireBuild();
  });

  for (const format of ["edf", "bdf"] as const) {
    test(`${format}: integer steps are the exact digital values in pyedflib, edfio and MNE`, () => {
      const dir = tempDir("mosaic-edf-");
      const dmax = format === "edf" ? 32767 : 8388607;
      // EDF: step 0.1, value k/10 is digital k; BDF: step 1 (its range in 8 characters).
      // 2000 Hz and the Trigno's 1925.926 Hz in one file.
      const scale = format === "edf" ? 10 : 1;
      const a = steps(3000, 3, -dmax - 1, dmax, 7);
      const b = steps(2889, 2, -dmax - 1, dmax, 8);
      writeFileSync(join(dir, "a.csv"), a.map((r) => r.map((k) => k / scale).join(",")).join("\n"));
      writeFileSync(join(dir, "b.csv"), b.map((r) => r.map((k) => k / scale).join(",")).join("\n"));
      const range = `[${-(dmax + 1) / scale}, ${dmax / scale}]`;
      writeFileSync(
        join(dir, "p.yaml"),
        `
A: { Type: ScheduledTimer, DesiredRate: 2000 }
B: { Type: ScheduledTimer, DesiredRate: 1925.926 }
Steps: { Type: FilePlayer, Inputs: [A], Params: { File: a.csv, Header: false, TimeColumn: false } }
Trigno: { Type: FilePlayer, Inputs: [B], Params: { File: b.csv, Header: false, TimeColumn: false } }
Marks:
  Type: Trigger
  Params:
    Labels: { rest: [0], fist: [1], pinch: [2] }
    Schedule: [ { Label: fist, At: 0.25, Seconds: 0.5 }, { Label: pinch, At: 1.0, Seconds: 0.2 } ]
Rec:
  Type: EdfRecorder
  Inputs: [Steps, Trigno, Marks.label]
  Params: { File: out.${format}, PhysicalRange: ${range}, Labels: [s1, s2, s3, t1, t2], Dimension: mV }
`,
      );
      const run = runCli([
        "run",
        join(dir, "p.yaml"),
        "--clock",
        "virtual",
        "--duration",
        "1.5",
        "--start",
        String(START),
      ]);
      expect(run.stderr).toBe("");
      expect(run.code).toBe(0);
      const [r] = check(dir, {
        files: [join(dir, `out.${format}`)],
        labels: ["s1", "s2", "s3", "t1", "t2"],
        rates: [2000, 2000, 2000, 52000 / 27, 52000 / 27],
        dimension: "mV",
        digital: {
          s1: a.map((x) => x[0]),
          s2: a.map((x) => x[1]),
          s3: a.map((x) => x[2]),
          t1: b.map((x) => x[0]),
          t2: b.map((x) => x[1]),
        },
        annotations: [
          [0.25, "Marks.label=1"],
          [0.75, "Marks.label=NaN"],
          [1.0, "Marks.label=2"],
          [1.2, "Marks.label=NaN"],
        ],
      });
      expect(r!.failures).toEqual([]);
      // 1.5 s of 2000 Hz and 1925.926 Hz: records of 0.4995 s (2 × 999 + … ): whole records only.
      expect(r!.start).toBe(START);
      expect(r!.duration).toBeGreaterThan(1);
      expect(r!.duration).toBeLessThanOrEqual(1.5);
    });
  }

  describe("the example pipeline (32 ch at 2 kHz, 8 ch at 1925.926 Hz, Stimulus markers)", () => {
    let dir = "";
    let reference = "";

    beforeAll(() => {
      dir = tempDir("mosaic-edf-example-");
      const yaml = readFileSync(join(ROOT, "pipelines/examples/record-edf.yaml"), "utf8");
      writeFileSync(
        join(dir, "record-edf.yaml"),
        `${yaml}\nLog: { Type: Logger, Inputs: [Emg, Trigno, Cues.phase], Params: { Folder: logs } }\n`,
      );
      const run = runCli(
        [
          "run",
          join(dir, "record-edf.yaml"),
          "--clock",
          "virtual",
          "--duration",
          "4",
          "--start",
          String(START),
        ],
        { timeoutMs: 120_000 },
      );
      expect(run.code, run.stderr).toBe(0);
      reference = join(dir, "recordings", readdirSync(join(dir, "recordings"))[0]!);
    }, 180_000);

    const labels = [
      ...Array.from({ length: 32 }, (_, c) => `Emg EMG ${c + 1}`),
      ...Array.from({ length: 8 }, (_, c) => `Trigno EMG ${c + 1}`),
    ];
    const rates = [...labels.map((l) => (l.startsWith("Emg") ? 2000 : 52000 / 27))];

    test("virtual clock: every value within one digital step of what the Logger saw; phase changes as annotations", () => {
      const emg = readLog(join(dir, "logs", "Emg.txt"));
      const trigno = readLog(join(dir, "logs", "Trigno.txt"));
      const phase = readLog(join(dir, "logs", "Cues.phase.txt"));
      const t0 = emg.t[0]!;
      expect(t0).toBe(START);
      const physical: Record<string, number[]> = {};
      columns(emg.v, 32).forEach((c, k) => (physical[`Emg EMG ${k + 1}`] = c));
      columns(trigno.v, 8).forEach((c, k) => (physical[`Trigno EMG ${k + 1}`] = c));
      const annotations: [number, string][] = [];
      phase.v.forEach((v, i) => {
        if (i === 0 || v[0] !== phase.v[i - 1]![0]) {
          annotations.push([Number((phase.t[i]! - t0).toFixed(6)), `Cues.phase=${v[0]}`]);
        }
      });
      expect(annotations.length).toBeGreaterThan(4);
      const [r] = check(dir, {
        files: [reference],
        labels,
        rates,
        dimension: "mV",
        physical,
        annotations,
      });
      expect(r!.failures).toEqual([]);
      expect(r!.start).toBe(START);
      // 4 s in records of 0.378 s: 10 complete records.
      expect(r!.records).toBe(10);
    });

    test("kill -9 at five random moments: every file opens in all three readers, at most 1 s lost", async () => {
      let seed = 20261124;
      const random = () => {
        seed = (seed * 1103515245 + 12345) % 2147483648;
        return seed / 2147483648;
      };
      const digital = await referenceDigital(dir, reference, labels);
      const results: { file: string; killedAt: number }[] = [];
      for (let k = 0; k < 5; k++) {
        const kdir = join(dir, `kill${k}`);
        const yaml = readFileSync(join(ROOT, "pipelines/examples/record-edf.yaml"), "utf8");
        writeFileSync(
          join(dir, `kill${k}.yaml`),
          yaml.replace(`File: "recordings/`, `File: "kill${k}/`),
        );
        const child = startCli(["run", join(dir, `kill${k}.yaml`)]);
        // Wait for the first record (the header goes out with it), then a random 0.1–3 s.
        const file = await waitForFile(kdir, 20_000);
        await sleep(100 + random() * 2900);
        const killedAt = Date.now() / 1000;
        child.kill("SIGKILL");
        await new Promise((r) => child.once("exit", r));
        results.push({ file, killedAt });
      }
      const checked = check(dir, {
        files: results.map((r) => r.file),
        labels,
        rates,
        digital,
        killed: true,
      });
      checked.forEach((c, k) => {
        expect(c.failures, c.path).toEqual([]);
        const lost = results[k]!.killedAt - (c.start + c.duration);
        expect(
          lost,
          `${c.path}: ${c.records} records from ${c.start}, killed at ${results[k]!.killedAt}`,
        ).toBeLessThanOrEqual(1);
        expect(lost).toBeGreaterThan(-0.5);
      });
    }, 240_000);

    test("repairEdf: an uncounted file with a torn last record is cut to whole records and counted", () => {
      const damaged = join(dir, "damaged.edf");
      copyFileSync(reference, damaged);
      // As an older recorder leaves it: count -1, half a record more.
      const fd = openSync(damaged, "r+");
      writeSync(fd, Buffer.from("-1      "), 0, 8, 236);
      writeSync(fd, Buffer.alloc(30_000, 7), 0, 30_000, statSync(damaged).size);
      closeSync(fd);
      expect(repairFile(damaged)).toBe(
        "repaired: cut a torn last record (30000 bytes), set the number of data records from -1 to 10; 10 data records (3.780 s)",
      );
      expect(statSync(damaged).size).toBe(statSync(reference).size);
      expect(readFileSync(damaged).equals(readFileSync(reference))).toBe(true);
      expect(repairFile(damaged)).toBe("intact: 10 data records (3.780 s)");
    });
  });
});

/** repairEdf on a real file (node:fs), as `mosaic repair` runs it. */
function repairFile(path: string): string {
  const fd = openSync(path, "r+");
  try {
    let size = statSync(path).size;
    return repairEdf({
      get size() {
        return size;
      },
      read: (into, pos) => readSync(fd, into, 0, into.length, pos),
      writeAt: (b, pos) => void writeSync(fd, b, 0, b.length, pos),
      truncate: (len) => {
        ftruncateSync(fd, len);
        size = len;
      },
    });
  } finally {
    closeSync(fd);
  }
}

const sleep = (ms: number) => new Promise((r) => setTimeout(r, ms));

/** The recording's path once its header and first record are there. */
async function waitForFile(folder: string, timeoutMs: number): Promise<string> {
  const until = Date.now() + timeoutMs;
  while (Date.now() < until) {
    try {
      const f = readdirSync(folder).find((n) => n.endsWith(".edf"));
      if (f && statSync(join(folder, f)).size > 256 * 42) return join(folder, f);
    } catch {
      // not created yet
    }
    await sleep(50);
  }
  throw new Error(`no recording in ${folder} after ${timeoutMs} ms`);
}

/** The digital values of the reference file, by label (pyedflib), for the killed files' prefixes. */
async function referenceDigital(
  dir: string,
  file: string,
  labels: string[],
): Promise<Record<string, number[]>> {
  const out = join(dir, "digital.json");
  const r = spawnSync(
    PYTHON,
    [
      "-c",
      "import json,sys,pyedflib\nr=pyedflib.EdfReader(sys.argv[1])\n" +
        "json.dump({l.strip(): r.readSignal(k, digital=True).tolist() for k, l in enumerate(r.getSignalLabels())}, open(sys.argv[2], 'w'))",
      file,
      out,
    ],
    { encoding: "utf8" },
  );
  if (r.status !== 0) throw new Error(r.stderr);
  const all = JSON.parse(readFileSync(out, "utf8")) as Record<string, number[]>;
  expect(Object.keys(all)).toEqual(labels);
  return all;
}
