import { readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { jsonLines, KEEPING_UP, requireBuild, ROOT, runCli, tempDir } from "./helpers";

beforeAll(requireBuild);

const PIPELINE = "pipelines/examples/fatigue-features.yaml";
const LENGTH = 200;
const STEP = 25;

/** Rail samples of the recording, by sample index, read independently of the pipeline. */
function railSamples(): number[] {
  const lines = readFileSync(join(ROOT, "pipelines/data/emg_fatigue_1000hz.csv"), "utf8")
    .trim()
    .split("\n")
    .slice(1);
  const out: number[] = [];
  lines.forEach((l, i) => {
    const v = Number(l.split(",")[1]);
    if (v === -1.5 || v === 1.499268) out.push(i);
  });
  return out;
}

const rows = (text: string) =>
  text
    .trim()
    .split("\n")
    .map((l) => l.split(",").map(Number));

describe("fatigue replay: windows, artifact rejection, features", () => {
  test("virtual clock: windows holding rail samples are rejected and their features read 0", () => {
    const dir = tempDir();
    const r = runCli(["run", PIPELINE, "--clock", "virtual", "--log-dir", dir, "--json"]);
    expect(r.code).toBe(0);
    const mask = rows(readFileSync(join(dir, "fatigue-features/Clean.mask.txt"), "utf8"));
    const features = rows(readFileSync(join(dir, "fatigue-features/Features.txt"), "utf8"));
    // 126,900 samples: the first window ends at sample 199, then one every 25 samples.
    const windows = Math.floor((126900 - LENGTH) / STEP) + 1;
    expect(mask).toHaveLength(windows);
    expect(features).toHaveLength(windows);
    const rails = railSamples();
    expect(rails).toHaveLength(38);
    const clipped = new Set<number>();
    for (let k = 0; k < windows; k++) {
      const end = LENGTH - 1 + k * STEP;
      if (rails.some((i) => i <= end && i > end - LENGTH)) clipped.add(k);
    }
    for (const k of clipped) expect(mask[k]![1]).toBe(0);
    const rejected = mask.filter((m) => m[1] === 0).length;
    // Every clipped window, plus a few impulsive jumps (reported by reason in the status).
    const summary = jsonLines(r.stdout).find((l) => l.type === "summary") as unknown as {
      blocks: { name: string; text: string }[];
    };
    const text = summary.blocks.find((b) => b.name === "Clean")!.text;
    const m = /clip (\d+), flat (\d+), jump (\d+)/.exec(text)!;
    expect(Number(m[1])).toBe(clipped.size);
    expect(rejected).toBe(Number(m[1]) + Number(m[2]) + Number(m[3]));
    // Features: rejected windows are zeroed (hard mode); kept ones are real EMG.
    features.forEach((f, k) => {
      expect(f[0]).toBeCloseTo(mask[k]![0]!, 9);
      if (mask[k]![1] === 0) expect(f.slice(1)).toEqual([0, 0, 0, 0]);
      else expect(f[1]!).toBeGreaterThan(0);
    });
  });

  test("real time: plays at 1000 Hz with features at 40 Hz, every block on time", () => {
    const dir = tempDir();
    const r = runCli(["run", PIPELINE, "--duration", "3", "--log-dir", dir, "--json"], {
      timeoutMs: 30_000,
    });
    expect(r.code).toBe(0);
    const tel = jsonLines(r.stdout)
      .filter((l) => l.type === "telemetry")
      .at(-1) as unknown as {
      blocks: { name: string; status: string; rate: number }[];
    };
    // Every block keeps up (a catch-up call on a loaded machine may make one stumble, never lag).
    expect(tel.blocks.map((b) => b.name)).toEqual([
      "Recording",
      "Windows",
      "Clean",
      "Features",
      "Rejected",
    ]);
    for (const b of tel.blocks) expect(KEEPING_UP, b.name).toContain(b.status);
    const lines = readFileSync(join(dir, "fatigue-features/Features.txt"), "utf8")
      .trim()
      .split("\n");
    expect(lines.length).toBeGreaterThan(80);
    expect(lines.length).toBeLessThan(125);
  });
});
