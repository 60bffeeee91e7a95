import { describe, expect, test } from "vitest";
import { batchingMarkdown, learnMarkdown } from "./bench-report";
import { pipelineMarkdown, udpRxLine } from "./bench-report-pipeline";
import { targets } from "./bench-targets";
import type {
  BatchingResult,
  BatchingRow,
  BlockRow,
  LearnResult,
  PipelineResult,
  UdpRxFigures,
} from "./bench-types";
import { selects, type BatchingDef } from "./bench-workloads";
import { sweepVariants } from "./bench-batching";

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
  delay: { p50Ms: 0.1, p99Ms: 1.5, maxMs: 2.25, n: 100 },
  shares: { ontime: 100, idle: 0, lagging: 0, stumbling: 0 },
});

function myo(): PipelineResult {
  return {
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
      row("Sender", "UdpSender", 25),
    ],
    timers: [],
    drops: 0,
    dropsAllTime: 0,
    batchingMs: 2,
    acquisition: "Myo",
    acquisitionChain: ["Timer", "Myo", "Amplification", "Rectification", "LowPass"],
    samplesLost: { missedTicks: 0, acquisitionDrops: 0, total: 0 },
    acquisitionOnTimePct: 100,
    telemetryLines: 600,
    loadAvgBefore: [0.1, 0.1, 0.1],
    loadAvgAfter: [0.1, 0.1, 0.1],
    loadSeconds: 0.2,
    lingerSeconds: 0,
    killedAfterSummary: false,
    warnings: [],
  };
}

const rx: UdpRxFigures = {
  port: 50512,
  expectedRateHz: 1926 / 77,
  windowSeconds: 30,
  datagrams: 2250,
  datagramsPerSecond: 75,
  perEvent: 3,
  events: 750,
  rateHz: 25.0125,
  rateErrorPct: -0.0019,
  timestampRateHz: 25.01299,
  expectedDatagrams: 2251,
  counterGaps: 0,
  missingEvents: 0,
  incompleteEvents: 0,
  maxArrivalGapMs: 44.2,
  datagramsAll: 2700,
  malformed: 0,
};

/** A Myo run of a sweep at 5 ms, with `over` for what the test varies. */
function myoSweepRun(over: Partial<BatchingRow>): BatchingRow {
  return {
    pipeline: "myo",
    batchingMs: 5,
    ok: true,
    cpuMedianPct: NaN,
    engineWakeupsPerS: 100,
    sender: null,
    acquisition: null,
    udpRateHz: 25,
    samplesLost: 0,
    loadAvgBefore: [0.5, 0.4, 0.3],
    ...over,
  };
}

describe("bench report", () => {
  test("the Myo pipeline's tables follow the paper's row order, extra blocks last", () => {
    const r = myo();
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
    expect(table5[7]).toContain(
      "| 2.00 | 0.100 | 1.500 | 2.25 | Control Algorithm | 24.9997 | 0.0004755 |",
    );
    expect(table5[8]).toMatch(/^\| Sender \| UdpSender \|.*\| UDP Sender \|/);
    expect(table5[10]).toMatch(/^\| Cues \| Stimulus .*\| - \| - \| - \|$/);
    expect(md.join("\n")).toContain("Samples lost after the warm-up: **0**");
  });

  test("the Sender's datagrams, the loaded run and the delay rows reach the targets table", () => {
    const delsys: PipelineResult = {
      ...myo(),
      id: "delsys",
      acquisition: "Delsys",
      blocks: [
        {
          ...row("Delsys", "EmgSimulator", 1926),
          delay: { p50Ms: 1.6, p99Ms: 2.9, maxMs: 4, n: 9 },
        },
        { ...row("Sender", "UdpSender", 25), delay: { p50Ms: 1.1, p99Ms: 3.2, maxMs: 4, n: 9 } },
      ],
      udp: rx,
    };
    const loaded: PipelineResult = {
      ...delsys,
      id: "delsys-loaded",
      neighbour: { command: 'node -e "for(;;){}"', cpuPct: 98 },
      samplesLost: { missedTicks: 0, acquisitionDrops: 2, total: 2 },
      udp: { ...rx, rateHz: 25.05, rateErrorPct: 0.148 },
    };
    const rows = targets([myo(), delsys, loaded]);
    const by = (id: string) => rows.find((r) => r.id === id)!;
    expect(by("delay-delsys-acquisition")).toMatchObject({ limit: 3, value: 2.9, pass: true });
    expect(by("delay-delsys-sender")).toMatchObject({ limit: 3, value: 3.2, pass: false });
    expect(by("cpu-myo").limit).toBe(1.5);
    expect(by("cpu-delsys").limit).toBe(3);
    expect(by("cpu-hdemg-features").limit).toBe(8);
    expect(by("ontime-delsys")).toMatchObject({ value: 100, pass: true });
    expect(by("lost-quiet")).toMatchObject({ value: 0, pass: true });
    expect(by("lost-quiet").note).toBe(
      "myo 0 (0 missed, 0 dropped), delsys 0 (0 missed, 0 dropped)",
    );
    expect(by("lost-delsys-loaded")).toMatchObject({ value: 2, pass: false });
    expect(by("udp-rate-delsys-loaded")).toMatchObject({ limit: 0.1, pass: false });
    expect(by("udp-rate-delsys-loaded").display).toBe("25.0500 Hz (+0.148 %)");
    expect(udpRxLine(rx)).toContain(
      "750 events at **25.0125 Hz** by arrival (−0.002 % vs 25.0130 Hz",
    );
    expect(pipelineMarkdown(loaded).join("\n")).toContain("burned 98.0 % of a core");
  });

  test("the batching sweep prints one row per pipeline and interval", () => {
    const r: BatchingResult = {
      kind: "batching",
      id: "batching",
      title: "Batching sweep",
      ok: false,
      error: "1 of 2 runs failed",
      warmupSeconds: 5,
      steadySeconds: 15,
      intervalsMs: [0, 2],
      rows: [
        {
          pipeline: "delsys",
          batchingMs: 0,
          telemetryHz: 20,
          ok: true,
          cpuMedianPct: 6.5,
          engineWakeupsPerS: 1931,
          sender: { p50Ms: 0.1, p99Ms: 0.4, maxMs: 1 },
          acquisition: { name: "Delsys", p50Ms: 0.05, p99Ms: 0.3, maxMs: 1 },
          udpRateHz: 25.013,
          samplesLost: 0,
          loadAvgBefore: [0.5, 0.4, 0.3],
        },
        {
          pipeline: "delsys",
          batchingMs: 2,
          telemetryHz: 20,
          ok: false,
          error: "boom",
          cpuMedianPct: NaN,
          engineWakeupsPerS: NaN,
          sender: null,
          acquisition: null,
          udpRateHz: NaN,
          samplesLost: null,
          loadAvgBefore: [0.5, 0.4, 0.3],
        },
      ],
      loadAvgBefore: [0.5, 0.4, 0.3],
      loadAvgAfter: [0.5, 0.4, 0.3],
      killedAfterSummary: false,
    };
    const md = batchingMarkdown(r);
    expect(md).toContain(
      "| delsys | 0 | 20 | 6.50 | 1931 | 0.100 / 0.400 | Delsys: 0.050 / 0.300 | 25.0130 | 0 | 0.50 / 0.40 / 0.30 |",
    );
    expect(md).toContain(
      "| delsys | 2 | 20 | failed: boom | - | - | - | - | - | 0.50 / 0.40 / 0.30 |",
    );
  });

  test("the telemetry sweep: runs in turn at each rate, the cost is the median of the pairs' differences", () => {
    const row = (hz: number, cpu: number) => myoSweepRun({ telemetryHz: hz, cpuMedianPct: cpu });
    const r: BatchingResult = {
      kind: "batching",
      id: "telemetry",
      title: "Telemetry cost",
      ok: true,
      warmupSeconds: 15,
      steadySeconds: 15,
      intervalsMs: [5],
      telemetryHz: [20, 2, 20, 2, 20, 2],
      rows: [row(20, 5), row(2, 3.5), row(20, 4), row(2, 4.5), row(20, 3), row(2, 2)],
      loadAvgBefore: [0.5, 0.4, 0.3],
      loadAvgAfter: [0.5, 0.4, 0.3],
      killedAfterSummary: false,
    };
    const md = batchingMarkdown(r).join("\n");
    expect(md).toContain("`--batching-ms` 5 and `--telemetry-hz` 20, 2, 20, 2, 20, 2 in turn");
    expect(md).toContain("| myo | 5 | 2 | 2.00 | 100 |");
    // Pairs: 5 − 3.5, 4 − 4.5, 3 − 2 (a pair may come out below 0 when the load drifts).
    expect(md).toContain(
      "- myo, batching 5 ms: telemetry at 20 Hz instead of 2 Hz costs 1.50, -0.50, 1.00 % of one core in 3 pair(s) of runs (mean 0.67 %, median 1.00 %)",
    );
    // The sweep's order now: pairs alternate (20, 2), (2, 20), …; each pair reads 20 Hz − 2 Hz. A
    // load falling by 0.5 % per run and a true cost of 1 %: the pairs read 1 ± 0.5, the mean 1.
    const abba: BatchingResult = {
      ...r,
      telemetryHz: [20, 2, 2, 20, 20, 2, 2, 20],
      rows: [20, 2, 2, 20, 20, 2, 2, 20].map((hz, i) => row(hz, 5 - 0.5 * i + (hz === 20 ? 1 : 0))),
    };
    expect(batchingMarkdown(abba).join("\n")).toContain(
      "costs 1.50, 0.50, 1.50, 0.50 % of one core in 4 pair(s) of runs (mean 1.00 %, median 1.00 %)",
    );
    expect(batchingMarkdown(abba).join("\n")).toContain("cancels in the mean");
    expect(md).toContain("every pair ran the higher rate first");
  });

  test("the tiering sweep: runs in turn with V8's thresholds and the engine's, the saving per pair", () => {
    const row = (engine: boolean, cpu: number) =>
      myoSweepRun({ telemetryHz: 20, v8Tiering: engine, cpuMedianPct: cpu });
    const order = [false, true, true, false];
    const r: BatchingResult = {
      kind: "batching",
      id: "tiering",
      title: "V8 tiering",
      ok: true,
      warmupSeconds: 15,
      steadySeconds: 15,
      intervalsMs: [5],
      v8Tiering: order,
      // V8's own thresholds cost 0.6 % more; the load falls by 0.2 % per run.
      rows: order.map((engine, i) => row(engine, 3 - 0.2 * i + (engine ? 0 : 0.6))),
      loadAvgBefore: [0.5, 0.4, 0.3],
      loadAvgAfter: [0.5, 0.4, 0.3],
      killedAfterSummary: false,
    };
    const md = batchingMarkdown(r).join("\n");
    expect(md).toContain(
      "with V8's own, the engine's, the engine's, V8's own V8 tier-up thresholds in turn",
    );
    expect(md).toContain("| myo (V8's own tiering) | 5 | 20 | 3.60 | 100 |");
    expect(md).toContain("| myo | 5 | 20 | 2.80 | 100 |");
    // Pairs: 3.6 − 2.8, 3.0 − 2.6 (V8's own minus the engine's, whichever ran first).
    expect(md).toContain(
      "- myo, batching 5 ms: the engine's tier-up thresholds save 0.80, 0.40 % of one core against V8's own in 2 pair(s) of runs (mean 0.60 %, median 0.60 %)",
    );
    expect(md).not.toContain("telemetry at 20 Hz instead of");
  });

  test("a sweep's runs: every interval × telemetry rate × tiering, in order", () => {
    const def = (extra: Partial<BatchingDef>): BatchingDef => ({
      kind: "batching",
      id: "x",
      title: "x",
      pipelines: ["myo"],
      intervalsMs: [0, 5],
      ...extra,
    });
    expect(sweepVariants(def({}))).toEqual([{ batchingMs: 0 }, { batchingMs: 5 }]);
    expect(sweepVariants(def({ intervalsMs: [5], v8Tiering: [false, true] }))).toEqual([
      { batchingMs: 5, v8Tiering: false },
      { batchingMs: 5, v8Tiering: true },
    ]);
    expect(sweepVariants(def({ intervalsMs: [5], telemetryHz: [20, 2] }))).toEqual([
      { batchingMs: 5, telemetryHz: 20 },
      { batchingMs: 5, telemetryHz: 2 },
    ]);
  });

  test("--only: an id selects that workload alone, a group name or NAME* the group", () => {
    expect(selects("delsys", "delsys")).toBe(true);
    expect(selects("delsys", "delsys-loaded")).toBe(false);
    expect(selects("delsys*", "delsys-loaded")).toBe(true);
    expect(selects("timer", "timer-precision")).toBe(false);
    expect(selects("timer*", "timer-precision")).toBe(true);
    expect(selects("replay", "replay-32")).toBe(true);
    expect(selects("replay", "replay-256")).toBe(true);
    expect(selects("batching", "batching")).toBe(true);
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
