import { describe, expect, test } from "vitest";
import {
  learnMarkdown,
  pipelineMarkdown,
  type BlockRow,
  type LearnResult,
  type PipelineResult,
} from "./bench-report";

const row = (name: string, type: string, rate: number): BlockRow => ({
  name,
  type,
  desiredRate: rate,
  n: 100,
  meanDt: 1 / rate,
  freq: rate,
  stdDt: 1e-4,
  computeMeanUs: 2,
  calls: 101,
  dropsIn: 0,
  shares: { ontime: 100, idle: 0, lagging: 0, stumbling: 0 },
});

describe("bench report", () => {
  test("the Myo pipeline's tables follow the paper's row order, extra blocks last", () => {
    const r: PipelineResult = {
      kind: "pipeline",
      id: "myo",
      title: "(a) Myo",
      paper: "myo",
      file: "pipelines/bench/myo.yaml",
      args: ["run", "pipelines/bench/myo.yaml"],
      ok: true,
      warmupSeconds: 5,
      steadySeconds: 30,
      measuredSeconds: 30.5,
      cpu: null,
      blocksComputePct: 0.2,
      memory: null,
      // The runtime's creation order: the Stimulus and the decimator come early.
      blocks: [
        row("Timer", "ScheduledTimer", 200),
        row("Decimator", "DecimatorTimer", 25),
        row("Cues", "Stimulus", 25),
        row("Myo", "EmgSimulator", 200),
        row("Amplification", "Function", 200),
        row("Rectification", "Function", 200),
        row("LowPass", "Filter", 200),
        row("Resampler", "Resampler", 25),
        row("Predictor", "IncrementalPredictor", 25),
        row("Control", "ControlAlgorithm", 25),
        row("Sender", "Sink", 25),
      ],
      timers: [],
      drops: 0,
      dropsAllTime: 0,
      telemetryLines: 600,
      loadAvgBefore: [0.1, 0.1, 0.1],
      loadAvgAfter: [0.1, 0.1, 0.1],
      loadSeconds: 0.2,
      lingerSeconds: 0,
      killedAfterSummary: false,
      warnings: [],
    };
    const md = pipelineMarkdown(r);
    const table5 = md.slice(md.findIndex((l) => l.startsWith("| Block | Type")) + 2);
    const names = table5.slice(0, 11).map((l) => l.split(" | ")[0]!.slice(2));
    expect(names).toEqual([
      "Timer",
      "Myo",
      "Amplification",
      "Rectification",
      "LowPass",
      "Resampler",
      "Predictor",
      "Control",
      "Sender",
      "Decimator",
      "Cues",
    ]);
    expect(table5[7]).toContain("| Control Algorithm | 24.9997 | 0.0004755 |");
    expect(table5[10]).toMatch(/^\| Cues \| Stimulus .*\| - \| - \| - \|$/);
  });

  test("the learning micro-benchmark table: ns per update and prediction, CPU at 25 Hz", () => {
    const r: LearnResult = {
      kind: "learn",
      id: "learn",
      title: "Learning kernels",
      ok: true,
      secondsPerFigure: 0.5,
      figures: [
        { kind: "ridge", dim: 8, inputs: 8, outputs: 12, updateNs: 1800, predictNs: 170 },
        { kind: "rff", dim: 256, inputs: 8, outputs: 12, updateNs: 124000, predictNs: 9400 },
      ],
      loadAvgBefore: [0.1, 0.1, 0.1],
      loadAvgAfter: [0.2, 0.1, 0.1],
      killedAfterSummary: false,
    };
    const md = learnMarkdown(r);
    expect(md).toContain("| ridge | 8 | 8 → 12 | 1800 | 170 | 555.6 k | 0.0045 |");
    expect(md).toContain("| rff | 256 | 8 → 12 | 124000 | 9400 | 8.1 k | 0.3100 |");
    expect(learnMarkdown({ ...r, ok: false, error: "no wasm" })).toContain("**Failed:** no wasm");
  });
});
