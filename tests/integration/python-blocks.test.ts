/**
 * The blocks that the original MOSAIC ran through Python.NET (PythonNetFiltUC, PythonNetLearning,
 * iNMF, SimplePyTorch), with a real sidecar process, through the real CLI: their logged outputs
 * are checked against SciPy and scikit-learn computed by tests/integration/python_blocks_check.py
 * in the sidecar's environment. Skipped where uv or that environment is missing.
 */
import { spawnSync } from "node:child_process";
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { jsonLines, requireBuild, ROOT, runCli, tempDir } from "./helpers";

const PY = [
  "-m",
  "uv",
  "run",
  "--quiet",
  "--frozen",
  "--project",
  join(ROOT, "native-bridges", "python"),
  "--python",
  "python3.11",
  "python",
];
const ENV = { ...process.env, UV_PYTHON_DOWNLOADS: "never" };
const havePython =
  spawnSync("python3", [...PY, "-c", "import scipy, sklearn"], { env: ENV, timeout: 120_000 })
    .status === 0;

function check(args: string[]): Record<string, unknown> {
  const r = spawnSync(
    "python3",
    [...PY, join(ROOT, "tests", "integration", "python_blocks_check.py"), ...args],
    { env: ENV, encoding: "utf8", timeout: 120_000 },
  );
  expect(r.status, r.stderr).toBe(0);
  return JSON.parse(r.stdout.trim().split("\n").at(-1)!) as Record<string, unknown>;
}

function run(dir: string, yaml: string, seconds: number, extra: string[] = []) {
  const file = join(dir, "p.yaml");
  writeFileSync(file, yaml);
  const r = runCli(["run", file, "--duration", String(seconds), "--json", ...extra], {
    timeoutMs: 120_000,
  });
  expect(r.code, r.stderr).toBe(0);
  return jsonLines(r.stdout);
}

describe.skipIf(!havePython)("Python-backed blocks with a real sidecar", () => {
  test("PythonNetFiltUC: MOSAIC's notch and a low-pass on windows, bit for bit as scipy.signal", () => {
    requireBuild();
    const dir = tempDir("mosaic-pyblocks-");
    const lines = run(
      dir,
      `
timer: { Type: ScheduledTimer, DesiredRate: 50 }
sinusoidSignal: { Type: SinGenerator, Inputs: [ timer ], Params: [ 3, 1, 3 ], Path: logs }
notch: { Type: PythonNetFiltUC, Inputs: [ sinusoidSignal ], Params: [ 1, 2, 3, 'unused.py', 50 ], Path: logs }
fast: { Type: ScheduledTimer, DesiredRate: 200 }
sig: { Type: SinGenerator, Inputs: [ fast ], Params: { Components: 2, Frequency: 7 }, Path: logs }
chunks: { Type: SlidingWindow, Inputs: [ sig ], Params: { Length: 10, Step: 10 } }
low: { Type: PythonNetFiltUC, Inputs: [ chunks ], Params: { Order: 4, Frequency: 5, SampleRate: 200 }, Path: logs }
`,
      3,
      // Bit for bit needs every input filtered: in real time a call still running when the next
      // input comes makes the block skip it (counted), which a loaded CI machine did once.
      ["--clock", "virtual"],
    );
    expect(lines.filter((l) => l.type === "fatal")).toEqual([]);
    const notch = check([
      "filt",
      ...["--input", join(dir, "logs", "sinusoidSignal.txt")],
      ...["--output", join(dir, "logs", "notch.txt")],
      ...["--kind", "notch", "--n", "2", "--frequency", "3", "--fs", "50", "--channels", "3"],
    ]);
    expect(notch).toMatchObject({ ok: true });
    expect(notch.rows as number).toBeGreaterThan(100);
    const low = check([
      "filt",
      ...["--input", join(dir, "logs", "sig.txt")],
      ...["--output", join(dir, "logs", "low.txt")],
      ...["--kind", "lowpass", "--n", "4", "--frequency", "5", "--fs", "200", "--channels", "2"],
    ]);
    expect(low).toMatchObject({ ok: true });
    expect(low.rows as number).toBeGreaterThan(400);
  }, 120_000);

  test("PythonNetLearning: PCA fitted on the named Buffer's rows when its cluster ends", () => {
    requireBuild();
    const dir = tempDir("mosaic-pyblocks-");
    run(
      dir,
      `
timer: { Type: ScheduledTimer, DesiredRate: 25 }
sinusoidSignal: { Type: SinGenerator, Inputs: [ timer ], Params: [ 4 ], Path: logs }
capture_data: { Type: Trigger, Params: { Labels: { rest: [1], flex: [2] }, Schedule: [ { Label: flex, At: 0.2, Seconds: 1 } ] } }
cluster_storage: { Type: Buffer, Inputs: [ capture_data, -sinusoidSignal ] }
model: { Type: PythonNetLearning, Inputs: [ sinusoidSignal ], Params: { Buffer: cluster_storage, Method: pca, Components: 2, AutoTrain: true }, Path: logs }
`,
      4,
    );
    const r = check([
      "pca",
      ...["--training", join(dir, "model.training.csv")],
      ...["--targets", "1", "--components", "2", "--after", "2.5"],
      ...["--input", join(dir, "logs", "sinusoidSignal.txt")],
      ...["--output", join(dir, "logs", "model.txt")],
    ]);
    expect(r).toMatchObject({ ok: true });
    expect(r.training_rows as number).toBeGreaterThan(20);
  }, 120_000);

  test("iNMF: synergies learnt online, the activations of every sample as the example module computes them", () => {
    requireBuild();
    const dir = tempDir("mosaic-pyblocks-");
    run(
      dir,
      `
timer: { Type: ScheduledTimer, DesiredRate: 25 }
sig: { Type: SinGenerator, Inputs: [ timer ], Params: { Components: 5, Frequency: 0.7 } }
envelope: { Type: Function, Inputs: [ sig ], Params: { Operation: abs }, Path: logs }
syn: { Type: iNMF, Inputs: [ envelope ], Params: { Synergies: 2, Forgetting: 0.95, Seed: 3 }, Path: logs }
`,
      3,
    );
    const r = check([
      "inmf",
      ...["--input", join(dir, "logs", "envelope.txt")],
      ...["--output", join(dir, "logs", "syn.txt")],
      ...["--synergies", "2", "--forgetting", "0.95", "--seed", "3"],
    ]);
    expect(r).toMatchObject({ ok: true });
    expect(r.rows as number).toBeGreaterThan(50);
  }, 120_000);

  test("SimplePyTorch without torch: the pipeline runs, the block says why (the ONNX route) and stays out", () => {
    requireBuild();
    const dir = tempDir("mosaic-pyblocks-");
    const file = join(dir, "torch.yaml");
    writeFileSync(
      file,
      `timerSlow: { Type: ScheduledTimer, DesiredRate: 200 }
sinusoidSignal: { Type: SinGenerator, Inputs: [ timerSlow ], Params: [ 5 ] }
SimplePyTorch: { Type: SimplePyTorch, Inputs: [ sinusoidSignal ] }
`,
    );
    const r = runCli(["run", file, "--duration", "1", "--json"], { timeoutMs: 120_000 });
    expect(r.code, r.stderr).toBe(0);
    const lines = jsonLines(r.stdout);
    const warnings = lines.filter((l) => l.type === "event" && l.block === "SimplePyTorch");
    expect(warnings.map((w) => `${String(w.level)}: ${String(w.message)}`).join("\n")).toMatch(
      /warning: PyTorch \(torch\) is not installed.*ONNX.*pipelines\/python\/onnx_cnn\.py/s,
    );
    const summary = lines.find((l) => l.type === "summary") as unknown as {
      blocks: { name: string; errors: number; events: number; text: string; status: string }[];
    };
    const block = summary.blocks.find((b) => b.name === "SimplePyTorch")!;
    expect(block).toMatchObject({ errors: 0, events: 0 });
    expect(block.text).toMatch(/not running: torch is not installed/);
    expect(summary.blocks.find((b) => b.name === "sinusoidSignal")!.events).toBeGreaterThan(150);
  }, 120_000);
});
