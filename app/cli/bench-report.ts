/**
 * `mosaic bench`: the Markdown of each workload kind (the pipelines' in bench-report-pipeline.ts)
 * and of the targets table.
 */
import { failed, fmt, fmtRateSI, load, section, table } from "./bench-format";
import { pipelineMarkdown } from "./bench-report-pipeline";
import { soakMarkdown } from "./bench-soak";
import { mean, quantile } from "./bench-stats";
import type {
  BatchingResult,
  BatchingRow,
  LearnFigure,
  LearnResult,
  ReplayResult,
  TargetRow,
  UdpResult,
  WorkloadResult,
} from "./bench-types";
import { udpLatencyLine } from "./bench-udp";

/** The section printed on stdout when workload `r` finishes. */
export function workloadMarkdown(r: WorkloadResult): string[] {
  switch (r.kind) {
    case "pipeline":
      return pipelineMarkdown(r, "##");
    case "batching":
      return batchingMarkdown(r, "##");
    case "learn":
      return learnMarkdown(r, "##");
    case "udp":
      return udpMarkdown(r, "##");
    case "replay":
      return replayMarkdown([r], "##");
    case "soak":
      return soakMarkdown(r, "##");
  }
}

export function targetsTable(rows: TargetRow[]): string[] {
  return table(
    ["workload", "metric", "MOSAIC (paper)", "target", "measured", "result", "notes"],
    rows.map((t) => [t.workload, t.metric, t.paper, t.target, t.display, verdict(t), t.note]),
  );
}

function verdict(t: TargetRow): string {
  if (t.pass === null) return t.value === null ? "not measured" : "info";
  return t.pass ? "met" : "**MISSED**";
}

/**
 * The UDP latency workload. `why` is how a failure reads: stdout says "unknown error" for a
 * failure without a message, latest.md has always written the message as it is.
 */
export function udpMarkdown(
  r: UdpResult,
  heading: string,
  why = r.error ?? "unknown error",
): string[] {
  return [...section(heading, r.title), r.ok ? udpLatencyLine(r) : `**Failed:** ${why}`, ""];
}

/**
 * The batching sweep (and the telemetry sweep): CPU, wake-ups and delivery delay per pipeline,
 * interval and telemetry rate.
 */
export function batchingMarkdown(r: BatchingResult, heading = "##"): string[] {
  if (r.rows.length === 0)
    return [...section(heading, r.title), ...failed(r.error ?? "nothing ran")];
  const telemetry = r.telemetryHz
    ? ` and \`--telemetry-hz\` ${r.telemetryHz.join(", ")} in turn`
    : " and telemetry at 20 Hz";
  const tiering = r.v8Tiering
    ? `, with ${r.v8Tiering.map(tieringName).join(", ")} V8 tier-up thresholds in turn`
    : "";
  return [
    ...section(heading, r.title),
    `Each pipeline run with \`--batching-ms\` ${r.intervalsMs.join(", ")}${telemetry}${tiering} (warm-up ` +
      `${r.warmupSeconds} s, steady state ${r.steadySeconds} s each). CPU: median of 1-s samples, % of ` +
      "one core. Wake-ups: voluntary context switches per second of the busiest thread other than the " +
      "CLI's main thread (the engine worker). Delay: delivery delay p50 / p99 (ms) since the warm-up. " +
      "Samples lost: missed ticks + drops on the acquisition chain.",
    "",
    ...table(
      [
        "pipeline",
        "batching (ms)",
        "telemetry (Hz)",
        "CPU median (%)",
        "engine wake-ups/s",
        "Sender delay p50 / p99 (ms)",
        "acquisition delay p50 / p99 (ms)",
        "UDP rate (Hz)",
        "samples lost",
        "load avg before",
      ],
      r.rows.map(batchingRow),
    ),
    "",
    ...telemetryCost(r),
    ...tieringCost(r),
  ];
}

/** "the engine's" or "V8's own" (a run's tier-up thresholds; app/host/tiering.ts). */
function tieringName(engine: boolean): string {
  return engine ? "the engine's" : "V8's own";
}

/**
 * The tiering sweep's reading: per pipeline and interval, in each pair of consecutive runs the
 * CPU median with V8's own thresholds minus that with the engine's (what the engine's save), their
 * mean and median; the pairs alternate their order, as the telemetry sweep's.
 */
function tieringCost(r: BatchingResult): string[] {
  if (!r.v8Tiering || r.v8Tiering.length < 2) return [];
  const lines: string[] = [];
  for (const id of new Set(r.rows.map((x) => x.pipeline))) {
    for (const ms of r.intervalsMs) {
      const runs = r.rows.filter((x) => x.ok && x.pipeline === id && x.batchingMs === ms);
      const d = pairDifferences(runs, (x) => x.v8Tiering !== false, false, true);
      if (d.length === 0) continue;
      lines.push(
        `- ${id}, batching ${ms} ms: the engine's tier-up thresholds save ` +
          `${d.map((x) => fmt(x, 2)).join(", ")} % of one core against V8's own in ${d.length} ` +
          `pair(s) of runs (mean ${fmt(mean(d), 2)} %, median ${fmt(quantile(d, 0.5), 2)} %)`,
      );
    }
  }
  return lines.length ? [...lines, ""] : [];
}

/**
 * The telemetry sweep's reading: per pipeline and interval, the runs taken two by two in order
 * (a pair is one run at the highest telemetry rate and one at the lowest, one right after the
 * other, so that a drift of the machine's load falls on both), the CPU median at the highest
 * minus that at the lowest in each pair, their mean and their median. The sweep alternates the
 * order within pairs (20, 2, then 2, 20, …): a steady drift adds to one pair what it takes from
 * the next, so it cancels in the mean over an even number of pairs.
 */
function telemetryCost(r: BatchingResult): string[] {
  const rates = r.telemetryHz;
  if (!rates || rates.length < 2) return [];
  const hi = Math.max(...rates);
  const lo = Math.min(...rates);
  const lines: string[] = [];
  for (const id of new Set(r.rows.map((x) => x.pipeline))) {
    for (const ms of r.intervalsMs) {
      const runs = r.rows.filter((x) => x.ok && x.pipeline === id && x.batchingMs === ms);
      const d = pairDifferences(runs, (x) => x.telemetryHz, hi, lo);
      if (d.length === 0) continue;
      lines.push(
        `- ${id}, batching ${ms} ms: telemetry at ${hi} Hz instead of ${lo} Hz costs ` +
          `${d.map((x) => fmt(x, 2)).join(", ")} % of one core in ${d.length} pair(s) of runs ` +
          `(mean ${fmt(mean(d), 2)} %, median ${fmt(quantile(d, 0.5), 2)} %)`,
      );
    }
  }
  if (lines.length === 0) return [];
  const swing =
    "Single pairs swing with the machine's load (a 15-s run's median moves by a percent on a shared " +
    "machine)";
  // Results written before the order alternated have every pair high-then-low.
  const alternating = rates.some((hz, i) => i % 2 === 0 && hz === lo && rates[i + 1] === hi);
  const reading = alternating
    ? ". The pairs alternate their order (the higher rate first, then the lower first), so a " +
      "steady drift of the load cancels in the mean of an even number of pairs; the median resists " +
      "one disturbed pair."
    : "; the median of the pairs is the figure (every pair ran the higher rate first, so a drift " +
      "of the load leans all of them the same way).";
  return [...lines, "", swing + reading, ""];
}

/**
 * CPU where `key` is `hi` minus CPU where it is `lo`, in each pair of consecutive runs (runs 1–2,
 * 3–4, …) that holds one run of each, in either order.
 */
function pairDifferences<K>(
  runs: BatchingRow[],
  key: (x: BatchingRow) => K,
  hi: K,
  lo: K,
): number[] {
  const d: number[] = [];
  for (let i = 0; i + 1 < runs.length; i += 2) {
    const [a, b] = [runs[i]!, runs[i + 1]!];
    if (key(a) === hi && key(b) === lo) d.push(a.cpuMedianPct - b.cpuMedianPct);
    else if (key(a) === lo && key(b) === hi) d.push(b.cpuMedianPct - a.cpuMedianPct);
  }
  return d;
}

function batchingRow(x: BatchingRow): string[] {
  if (!x.ok) {
    const dashes = ["-", "-", "-", "-", "-"];
    return [
      sweepRunName(x),
      String(x.batchingMs),
      String(x.telemetryHz ?? 20),
      `failed: ${x.error ?? "?"}`,
      ...dashes,
      load(x.loadAvgBefore),
    ];
  }
  return [
    sweepRunName(x),
    String(x.batchingMs),
    String(x.telemetryHz ?? 20),
    fmt(x.cpuMedianPct, 2),
    fmt(x.engineWakeupsPerS, 0),
    x.sender ? `${fmt(x.sender.p50Ms, 3)} / ${fmt(x.sender.p99Ms, 3)}` : "-",
    x.acquisition
      ? `${x.acquisition.name}: ${fmt(x.acquisition.p50Ms, 3)} / ${fmt(x.acquisition.p99Ms, 3)}`
      : "-",
    fmt(x.udpRateHz, 4),
    x.samplesLost === null ? "-" : String(x.samplesLost),
    load(x.loadAvgBefore),
  ];
}

/** A sweep row's pipeline, and "(V8's own tiering)" for a run that kept V8's thresholds. */
function sweepRunName(x: BatchingRow): string {
  return x.v8Tiering === false ? `${x.pipeline} (V8's own tiering)` : x.pipeline;
}

/** The replays' throughput, one row per recording. */
export function replayMarkdown(rs: ReplayResult[], heading = "###"): string[] {
  return [
    ...section(heading, "Virtual-clock replay throughput (5-block DSP chain)"),
    "FilePlayer (Loop) on a ScheduledTimer → Amplification → Rectification → LowPass → Resampler " +
      "(DecimatorTimer 25 Hz), `--clock virtual`. Throughput = channels × rate × virtual seconds / " +
      "the run's wall seconds (host start → stop; process start and file load reported apart).",
    "",
    ...table(
      [
        "recording",
        "virtual s",
        "wall s",
        "channel-samples/s",
        "frames/s",
        "start-up + load s",
        "peak RSS (MiB)",
        "load avg before / after",
      ],
      rs.map(replayRow),
    ),
    "",
  ];
}

function replayRow(r: ReplayResult): string[] {
  if (!r.ok) {
    return [
      `${r.channels} ch @ ${r.rate} Hz`,
      "-",
      "-",
      `failed: ${r.error ?? "?"}`,
      "-",
      "-",
      "-",
      "-",
    ];
  }
  return [
    `${r.channels} ch @ ${r.rate} Hz (${r.recordingSeconds} s, ${(r.recordingBytes / 2 ** 20).toFixed(1)} MiB CSV)`,
    r.virtualSeconds.toFixed(0),
    r.wallSeconds.toFixed(2),
    fmtRateSI(r.channelSamplesPerSecond),
    fmtRateSI(r.framesPerSecond),
    r.loadSeconds.toFixed(2),
    fmt(r.peakRssMiB, 1),
    `${load(r.loadAvgBefore)} → ${load(r.loadAvgAfter)}`,
  ];
}

/** The learning kernels: ns per update and per prediction, and the CPU of updates at 25 Hz. */
export function learnMarkdown(r: LearnResult, heading = "##"): string[] {
  if (!r.ok) return [...section(heading, r.title), ...failed(r.error ?? "unknown error")];
  const outputs = r.figures[0]?.outputs ?? 0;
  return [
    ...section(heading, r.title),
    "The mosaic-learn kernels through their WASM bindings (`LearningModel`), in the bench's own " +
      "process, one event per call as in a pipeline: an update is `trainPredict` (learn one " +
      "sample, then predict it: the IncrementalPredictor's training path), a prediction is " +
      `\`predict\`. ${outputs} outputs; ridge has D inputs, RFF has D random features on 8 ` +
      `inputs. Each figure is the mean over ${r.secondsPerFigure} s of calls. The last column is ` +
      "the CPU of one update per sample at 25 Hz (the Myo pipeline's predictor rate). Load " +
      `average before ${load(r.loadAvgBefore)}, after ${load(r.loadAvgAfter)} (2 shared cores).`,
    "",
    ...table(
      [
        "model",
        "D",
        "inputs → outputs",
        "ns per update (+ prediction)",
        "ns per prediction",
        "updates/s",
        "update at 25 Hz (% of one core)",
      ],
      r.figures.map(learnRow),
    ),
    "",
  ];
}

function learnRow(f: LearnFigure): string[] {
  return [
    f.kind,
    String(f.dim),
    `${f.inputs} → ${f.outputs}`,
    fmt(f.updateNs, 0),
    fmt(f.predictNs, 0),
    fmtRateSI(1e9 / f.updateNs),
    (f.updateNs * 25 * 1e-7).toFixed(4),
  ];
}
