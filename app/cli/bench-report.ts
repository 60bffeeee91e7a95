/**
 * `mosaic bench`, report side: result types, DESIGN.md §6 targets, MOSAIC's published figures
 * (paper section V: Tables 5 and 6, Fig. 6 and 7) and the Markdown tables.
 */
import type { UdpRxFigures } from "./bench-receiver";

export type { UdpRxFigures };

export interface StatusShares {
  /** % of the steady-state telemetry lines (20 Hz) in each status. */
  ontime: number;
  idle: number;
  lagging: number;
  stumbling: number;
}

export interface BlockRow {
  name: string;
  type: string;
  desiredRate: number;
  /** Number of ΔT values (consecutive output pairs) after the warm-up. */
  n: number;
  meanDt: number;
  freq: number;
  stdDt: number;
  /** Mean compute time per `process` call after the warm-up, µs. */
  computeMeanUs: number;
  calls: number;
  /** Events dropped on the edges into the block during the measured interval. */
  dropsIn: number;
  /** Delivery delay (processing − timestamp of the oldest event of each batch) since the
   * warm-up reset, ms; n batches. */
  delay: { p50Ms: number; p99Ms: number; maxMs: number; n: number } | null;
  shares: StatusShares | null;
  /** The block's status line at the end of the run (Python blocks: call times, over budget). */
  text?: string;
}

export interface TimerFigures {
  name: string;
  desiredRate: number;
  /** Ticks fired and missed during the measured interval (after the warm-up). */
  fired: number;
  missed: number;
  latenessP50Us: number;
  latenessP99Us: number;
  latenessMaxUs: number;
}

export interface CpuFigures {
  /** Which reading the headline figures use. */
  source: "schedstat" | "stat";
  /** Steady-state 1-s samples, % of one core. */
  samples: number;
  medianPct: number;
  p90Pct: number;
  meanPct: number;
  stdPct: number;
  /** The same from /proc/<pid>/stat ticks (1 tick = 1/CLK_TCK s, i.e. 1 % in a 1-s sample). */
  ticksMedianPct: number;
  ticksMeanPct: number;
  /** Child processes of the run (Python sidecars): median and mean % of one core; 0 without. */
  childrenMedianPct: number;
  childrenMeanPct: number;
  clkTck: number;
  /** Steady-state CPU of each thread (schedstat; busiest first; threads under 0.05 % left out).
   * `main` is the CLI's main thread; the others are named by tid (Node names them all "node").
   * wakeupsPerS: voluntary context switches per second (the thread blocked and was woken). */
  threads: { thread: string; pct: number; wakeupsPerS: number; preemptedPerS: number }[];
  /** Wake-ups per second of the busiest thread other than the CLI's main thread (normally the
   * engine worker), over the steady-state window; NaN when unknown. */
  engineWakeupsPerS: number;
  trace: { t: number; pct: number; ticksPct: number; rssMiB: number; steady: boolean }[];
}

export interface PipelineResult {
  kind: "pipeline";
  id: string;
  title: string;
  /** Key into PAPER for the paper's Tables 5/6, if MOSAIC reported this pipeline. */
  paper?: "myo" | "delsys";
  file: string;
  args: string[];
  ok: boolean;
  error?: string;
  warmupSeconds: number;
  steadySeconds: number;
  /** Seconds covered by the ΔT statistics (warm-up end → stop), from the summary. */
  measuredSeconds: number;
  cpu: CpuFigures | null;
  /** CPU of a bare worker that only sleeps until each deadline at the pipeline's wake-up rate (the
   * timer rate batched by batchingMs), % of one core, and that rate (Hz). */
  wakeFloorPct?: number;
  wakeFloorHz?: number;
  /** The batching interval of the pipeline's first ScheduledTimer, ms (from its telemetry). */
  batchingMs: number;
  /** The acquisition block (the simulated device), e.g. Delsys. */
  acquisition?: string;
  /** Blocks at the acquisition rate (the first ScheduledTimer's), the paper's acquisition chain. */
  acquisitionChain: string[];
  /** Samples lost after the warm-up: ticks the timers missed plus events dropped on the edges
   * out of the acquisition chain's blocks (must be 0). */
  samplesLost: { missedTicks: number; acquisitionDrops: number; total: number } | null;
  /** The lowest on-time share (Table 6, G) of the acquisition chain's blocks, %. */
  acquisitionOnTimePct: number;
  /** What the bench's UDP receiver got from the Sender in the steady-state window. */
  udp?: UdpRxFigures;
  /** A neighbour process that burned one core during the run (the loaded variant). */
  neighbour?: { command: string; cpuPct: number };
  /** Σ of the blocks' measured `process` time over the measured interval, % of one core. */
  blocksComputePct: number;
  memory: { peakRssMiB: number; steadyRssMedianMiB: number } | null;
  blocks: BlockRow[];
  timers: TimerFigures[];
  /** Events dropped on all edges during the measured interval, and since start. */
  drops: number;
  dropsAllTime: number;
  telemetryLines: number;
  loadAvgBefore: number[];
  loadAvgAfter: number[];
  loadSeconds: number;
  lingerSeconds: number;
  killedAfterSummary: boolean;
  warnings: string[];
}

export interface ReplayResult {
  kind: "replay";
  id: string;
  title: string;
  file: string;
  args: string[];
  ok: boolean;
  error?: string;
  channels: number;
  rate: number;
  recordingSeconds: number;
  recordingBytes: number;
  virtualSeconds: number;
  /** The run's own wall time (host started → stopped), from the summary. */
  wallSeconds: number;
  /** Spawn → summary minus wallSeconds: process start, WASM, pipeline and recording load. */
  loadSeconds: number;
  channelSamplesPerSecond: number;
  /** Frames (ticks) per wall second. */
  framesPerSecond: number;
  calibration?: { virtualSeconds: number; wallSeconds: number; channelSamplesPerSecond: number };
  peakRssMiB: number;
  loadAvgBefore: number[];
  loadAvgAfter: number[];
  lingerSeconds: number;
  killedAfterSummary: boolean;
}

/** One figure of the learning micro-benchmark (the WASM kernels through their bindings). */
export interface LearnFigure {
  kind: "ridge" | "rff";
  /** Dimension of the normal equations: inputs for ridge, random features for RFF. */
  dim: number;
  inputs: number;
  outputs: number;
  /** Mean ns of one incremental update and its prediction (`trainPredict`, one event). */
  updateNs: number;
  /** Mean ns of one prediction (one event). */
  predictNs: number;
}

export interface LearnResult {
  kind: "learn";
  id: string;
  title: string;
  ok: boolean;
  error?: string;
  /** Seconds of running behind each figure (each of update and prediction). */
  secondsPerFigure: number;
  figures: LearnFigure[];
  loadAvgBefore: number[];
  loadAvgAfter: number[];
  /** In process: never a lingering child. */
  killedAfterSummary: false;
}

export interface UdpResult {
  kind: "udp";
  id: string;
  title: string;
  ok: boolean;
  error?: string;
  /** Datagrams timed, per second, values per datagram, the timer branch's rate. */
  samples: number;
  received: number;
  lost: number;
  rate: number;
  channels: number;
  timerHz: number;
  /** The batching interval of the host, ms. */
  batchingMs: number;
  p50Ms: number;
  p90Ms: number;
  p99Ms: number;
  maxMs: number;
  meanMs: number;
  inP50Ms: number;
  inP99Ms: number;
  outP50Ms: number;
  outP99Ms: number;
  loadAvgBefore: number[];
  loadAvgAfter: number[];
  /** In process: never a lingering child. */
  killedAfterSummary: false;
}

/** One run of the batching sweep. */
export interface BatchingRow {
  pipeline: string;
  batchingMs: number;
  ok: boolean;
  error?: string;
  cpuMedianPct: number;
  /** Voluntary context switches per second of the busiest non-main thread (the engine worker). */
  engineWakeupsPerS: number;
  sender: { p50Ms: number; p99Ms: number; maxMs: number } | null;
  acquisition: { name: string; p50Ms: number; p99Ms: number; maxMs: number } | null;
  udpRateHz: number;
  samplesLost: number | null;
  loadAvgBefore: number[];
}

export interface BatchingResult {
  kind: "batching";
  id: string;
  title: string;
  ok: boolean;
  error?: string;
  warmupSeconds: number;
  steadySeconds: number;
  intervalsMs: number[];
  rows: BatchingRow[];
  loadAvgBefore: number[];
  loadAvgAfter: number[];
  killedAfterSummary: boolean;
}

export type WorkloadResult =
  PipelineResult | ReplayResult | LearnResult | UdpResult | BatchingResult;

export interface TargetRow {
  id: string;
  workload: string;
  metric: string;
  paper: string;
  target: string;
  limit: number | null;
  /** "max": the figure must not exceed limit; "min": it must reach it. */
  sense: "max" | "min";
  unit: string;
  value: number | null;
  display: string;
  pass: boolean | null;
  note: string;
}

// ---------------------------------------------------------------------------------------------
// MOSAIC's published figures (paper section V), for the comparison columns.

interface PaperBlock {
  block: string;
  rate: number;
  meanDt: number;
  freq: number;
  stdDt: number;
  /** Table 6: G, I, L, S in % (null = "-"). */
  status: [number | null, number | null, number | null, number | null];
}

/** Keyed by our block names (the paper's row name is `block`). */
export const PAPER: Record<"myo" | "delsys", Record<string, PaperBlock>> = {
  myo: {
    Timer: {
      block: "Scheduled Timer",
      rate: 200,
      meanDt: 0.0050001,
      freq: 199.9955,
      stdDt: 0.0002417,
      status: [100, null, null, null],
    },
    Myo: {
      block: "Myo",
      rate: 200,
      meanDt: 0.0050001,
      freq: 199.9978,
      stdDt: 0.0002641,
      status: [100, null, null, null],
    },
    Amplification: {
      block: "Amplification",
      rate: 200,
      meanDt: 0.005,
      freq: 199.9993,
      stdDt: 0.0002837,
      status: [100, null, null, null],
    },
    Rectification: {
      block: "Rectification",
      rate: 200,
      meanDt: 0.005,
      freq: 199.9993,
      stdDt: 0.0003017,
      status: [100, null, null, null],
    },
    LowPass: {
      block: "Low Pass Filter",
      rate: 200,
      meanDt: 0.0049999,
      freq: 200.0042,
      stdDt: 0.0003385,
      status: [100, null, null, null],
    },
    Resampler: {
      block: "Resampler",
      rate: 25,
      meanDt: 0.0400009,
      freq: 24.9994,
      stdDt: 0.0002944,
      status: [100, null, null, null],
    },
    Predictor: {
      block: "Incremental Predictor",
      rate: 25,
      meanDt: 0.0400005,
      freq: 24.9997,
      stdDt: 0.0004624,
      status: [100, null, null, null],
    },
    Control: {
      block: "Control Algorithm",
      rate: 25,
      meanDt: 0.0400005,
      freq: 24.9997,
      stdDt: 0.0004755,
      status: [100, null, null, null],
    },
    Sender: {
      block: "UDP Sender",
      rate: 25,
      meanDt: 0.0399848,
      freq: 25.0095,
      stdDt: 0.0009457,
      status: [100, null, null, null],
    },
  },
  delsys: {
    Delsys: {
      block: "Delsys Trigno Avanti",
      rate: 1926,
      meanDt: 0.0005192,
      freq: 1926.0572,
      stdDt: 0.0003156,
      status: [99.175, 0.022, 0.802, null],
    },
    Amplification: {
      block: "Amplification",
      rate: 1926,
      meanDt: 0.0005192,
      freq: 1926.0736,
      stdDt: 0.0003523,
      status: [98.8, 0.037, 1.163, null],
    },
    Rectification: {
      block: "Rectification",
      rate: 1926,
      meanDt: 0.0005192,
      freq: 1926.0744,
      stdDt: 0.0003641,
      status: [98.666, 0.041, 1.293, null],
    },
    LowPass: {
      block: "Low Pass Filter",
      rate: 1926,
      meanDt: 0.0005192,
      freq: 1926.1146,
      stdDt: 0.000383,
      status: [98.319, 0.046, 1.635, null],
    },
    Resampler: {
      block: "Resampler",
      rate: 25,
      meanDt: 0.0399797,
      freq: 25.0127,
      stdDt: 0.0020564,
      status: [100, null, null, null],
    },
    Predictor: {
      block: "Incremental Predictor",
      rate: 25,
      meanDt: 0.0399795,
      freq: 25.0128,
      stdDt: 0.0022413,
      status: [100, null, null, null],
    },
    Control: {
      block: "Control Algorithm",
      rate: 25,
      meanDt: 0.0399796,
      freq: 25.0128,
      stdDt: 0.0022767,
      status: [100, null, null, null],
    },
    Sender: {
      block: "UDP Sender",
      rate: 25,
      meanDt: 0.0399674,
      freq: 25.0204,
      stdDt: 0.0025883,
      status: [100, null, null, null],
    },
  },
};

/** The paper's CPU figures are % of an 8-core machine (Fig. 6); in cores: × 8 / 100. */
export const PAPER_CPU = {
  myo: { pct8: 12.01, sd8: 1.73, cores: (12.01 * 8) / 100 },
  delsys: { pct8: 29.29, sd8: 2.19, cores: (29.29 * 8) / 100 },
};

// ---------------------------------------------------------------------------------------------
// Number formatting

export function fmt(x: number | null | undefined, digits: number): string {
  return x === null || x === undefined || !Number.isFinite(x) ? "-" : x.toFixed(digits);
}

function fmtPct(x: number): string {
  return !Number.isFinite(x) ? "-" : x < 10 ? `${x.toFixed(2)} %` : `${x.toFixed(1)} %`;
}

function fmtShare(x: number | null | undefined): string {
  return x === null || x === undefined || !(x > 0) ? "-" : x.toFixed(3);
}

function fmtRate(x: number): string {
  if (!Number.isFinite(x)) return "-";
  return Number.isInteger(x) ? String(x) : x.toFixed(4);
}

export function fmtRateSI(x: number): string {
  if (!Number.isFinite(x)) return "-";
  if (x >= 1e6) return `${(x / 1e6).toFixed(2)} M`;
  if (x >= 1e3) return `${(x / 1e3).toFixed(1)} k`;
  return x.toFixed(0);
}

function table(head: string[], rows: string[][]): string[] {
  const line = (cells: string[]) => `| ${cells.join(" | ")} |`;
  return [line(head), line(head.map(() => "---")), ...rows.map(line)];
}

export function load(l: number[]): string {
  return l.length ? l.map((x) => x.toFixed(2)).join(" / ") : "-";
}

// ---------------------------------------------------------------------------------------------
// Targets (DESIGN.md §6)

function pipeline(results: WorkloadResult[], id: string): PipelineResult | undefined {
  const r = results.find((w) => w.id === id);
  return r && r.kind === "pipeline" ? r : undefined;
}
function replay(results: WorkloadResult[], id: string): ReplayResult | undefined {
  const r = results.find((w) => w.id === id);
  return r && r.kind === "replay" ? r : undefined;
}

function judged(
  row: Omit<TargetRow, "pass" | "display" | "note"> & { note?: string },
  display: (v: number) => string,
  missingWhy: string | undefined,
): TargetRow {
  const v = row.value;
  if (row.limit === null && v !== null && Number.isFinite(v)) {
    // a figure reported for information, without a target
    return { ...row, display: display(v), pass: null, note: row.note ?? "" };
  }
  if (v === null || !Number.isFinite(v) || row.limit === null) {
    return {
      ...row,
      value: null,
      display: "not measured",
      pass: null,
      note: missingWhy ?? row.note ?? "",
    };
  }
  const pass = row.sense === "max" ? v <= row.limit : v >= row.limit;
  return { ...row, display: display(v), pass, note: row.note ?? "" };
}

function why(r: WorkloadResult | undefined, id: string): string {
  if (!r) return `workload '${id}' was not run (--only)`;
  return r.ok ? "" : `workload '${id}' failed: ${r.error ?? "unknown error"}`;
}

export function targets(results: WorkloadResult[]): TargetRow[] {
  const rows: TargetRow[] = [];
  const cpuRow = (id: string, workload: string, paper: string, limit: number): TargetRow => {
    const r = pipeline(results, id);
    const c = r?.ok ? r.cpu : null;
    return judged(
      {
        id: `cpu-${id}`,
        workload,
        metric: "CPU, steady-state median of 1-s samples (% of one core)",
        paper,
        target: `≤ ${limit} % of one core`,
        limit,
        sense: "max",
        unit: "% of one core",
        value: c ? c.medianPct : null,
        note: c
          ? `p90 ${fmtPct(c.p90Pct)}, mean ${fmtPct(c.meanPct)} ± ${fmtPct(c.stdPct)} (${c.samples} samples); /proc/stat ticks: median ${fmtPct(c.ticksMedianPct)}, mean ${fmtPct(c.ticksMeanPct)}` +
            (r?.wakeFloorPct !== undefined
              ? `; wake-up floor on this machine (a bare worker waking at the pipeline's ${fmt(r.wakeFloorHz, 1)} Hz, nothing else): ${fmtPct(r.wakeFloorPct)}` +
                `; engine thread ${fmt(c.engineWakeupsPerS, 0)} wake-ups/s, batching interval ${fmt(r.batchingMs, 1)} ms`
              : "")
          : "",
      },
      fmtPct,
      why(r, id),
    );
  };
  rows.push(
    cpuRow(
      "myo",
      "Myo pipeline, 8 ch @ 200 Hz",
      `${PAPER_CPU.myo.pct8} % ± ${PAPER_CPU.myo.sd8} % of 8 cores ≈ ${PAPER_CPU.myo.cores.toFixed(2)} core (≈ ${(PAPER_CPU.myo.cores * 100).toFixed(0)} % of one core)`,
      1.5,
    ),
  );
  rows.push(
    cpuRow(
      "delsys",
      "Delsys pipeline, 32 ch @ 1926 Hz",
      `${PAPER_CPU.delsys.pct8} % ± ${PAPER_CPU.delsys.sd8} % of 8 cores ≈ ${PAPER_CPU.delsys.cores.toFixed(2)} cores (≈ ${(PAPER_CPU.delsys.cores * 100).toFixed(0)} % of one core)`,
      3,
    ),
  );
  rows.push(cpuRow("hdemg", "High-density EMG, 256 ch @ 2048 Hz", "not reported", 8));
  rows.push(
    cpuRow(
      "hdemg-features",
      "High-density EMG features (MAV, WL, ZC, SSC on 200 ms windows every 25 ms), 256 ch @ 2048 Hz",
      "not reported",
      8,
    ),
  );
  {
    const r = pipeline(results, "delsys");
    rows.push(
      judged(
        {
          id: "rss-delsys",
          workload: "Memory, headless `mosaic run` of the Delsys pipeline",
          metric: "peak RSS (VmHWM), MiB",
          paper:
            "0.300 GiB ± 0.003 GiB (307 MiB) working set (Fig. 7; that figure is the 200 Hz Myo replay)",
          target: "≤ 100 MiB RSS",
          limit: 100,
          sense: "max",
          unit: "MiB",
          value: r?.ok && r.memory ? r.memory.peakRssMiB : null,
          note:
            r?.ok && r.memory
              ? `steady-state VmRSS median ${r.memory.steadyRssMedianMiB.toFixed(1)} MiB`
              : "",
        },
        (v) => `${v.toFixed(1)} MiB`,
        why(r, "delsys"),
      ),
    );
  }
  {
    const r = pipeline(results, "timer");
    const t = r?.ok ? r.timers[0] : undefined;
    const paper = "not reported; ΔT std 0.24–0.38 ms for the acquisition blocks (Table 5)";
    const note = t
      ? `batching interval ${fmt(r!.batchingMs, 0)} ms (\`--batching-ms 0\`: a wake-up for every tick); max ${t.latenessMaxUs.toFixed(0)} µs, ${t.fired} ticks fired, ${t.missed} missed`
      : "";
    rows.push(
      judged(
        {
          id: "timer-p50",
          workload: "Timer at 2 kHz, default mode, batching interval 0",
          metric: "lateness (fire − deadline), median, µs",
          paper,
          target: "median ≤ 100 µs",
          limit: 100,
          sense: "max",
          unit: "µs",
          value: t ? t.latenessP50Us : null,
          note,
        },
        (v) => `${v.toFixed(0)} µs`,
        why(r, "timer"),
      ),
    );
    rows.push(
      judged(
        {
          id: "timer-p99",
          workload: "Timer at 2 kHz, default mode, batching interval 0",
          metric: "lateness (fire − deadline), p99, µs",
          paper,
          target: "p99 ≤ 200 µs",
          limit: 200,
          sense: "max",
          unit: "µs",
          value: t ? t.latenessP99Us : null,
          note,
        },
        (v) => `${v.toFixed(0)} µs`,
        why(r, "timer"),
      ),
    );
  }
  {
    const r = pipeline(results, "timer-precision");
    const t = r?.ok ? r.timers[0] : undefined;
    rows.push(
      judged(
        {
          id: "timer-precision",
          workload: "Timer at 2 kHz, `--precision` (spin the last ~0.3 ms), batching interval 0",
          metric: "lateness median / p99, µs; CPU median",
          paper: "not available in MOSAIC",
          target: "none (information)",
          limit: null,
          sense: "max",
          unit: "µs",
          value: t ? t.latenessP99Us : null,
          note: t
            ? `max ${t.latenessMaxUs.toFixed(0)} µs, ${t.missed} of ${t.fired + t.missed} ticks missed; CPU median ${fmtPct(r!.cpu?.medianPct ?? NaN)} of one core`
            : "",
        },
        (v) => `${t!.latenessP50Us.toFixed(0)} µs / ${v.toFixed(0)} µs`,
        why(r, "timer-precision"),
      ),
    );
  }
  {
    const r = pipeline(results, "delsys");
    for (const which of ["Sender", "acquisition"] as const) {
      const name = which === "Sender" ? "Sender" : (r?.acquisition ?? "Delsys");
      const b = r?.ok ? r.blocks.find((x) => x.name === name) : undefined;
      const limit = r?.ok && Number.isFinite(r.batchingMs) ? r.batchingMs + 1 : null;
      rows.push(
        judged(
          {
            id: `delay-delsys-${which.toLowerCase()}`,
            workload: `Delsys pipeline, default batching interval: ${which === "Sender" ? "the UDP Sender" : `the acquisition block (${name})`}`,
            metric: "delivery delay (processing − event time), p99, ms",
            paper: "not reported",
            target: "p99 ≤ interval + 1 ms",
            limit,
            sense: "max",
            unit: "ms",
            value: b?.delay ? b.delay.p99Ms : null,
            note: b?.delay
              ? `interval ${fmt(r!.batchingMs, 1)} ms; p50 ${fmt(b.delay.p50Ms, 3)} ms, max ${fmt(b.delay.maxMs, 2)} ms over ${b.delay.n} batches`
              : "",
          },
          (v) => `${v.toFixed(3)} ms`,
          why(r, "delsys"),
        ),
      );
    }
  }
  const u = results.find((r): r is UdpResult => r.kind === "udp");
  rows.push(
    judged(
      {
        id: "latency-udp",
        workload: "Sensor frame in → UDP datagram out, same worker, batching interval 0",
        metric: "p99 latency",
        paper: "not reported",
        target: "p99 ≤ 1 ms",
        limit: 1,
        sense: "max",
        unit: "ms",
        value: u?.ok ? u.p99Ms : null,
        note: u?.ok
          ? `UdpReceiver → Function → UdpSender, ${u.channels} f64 per datagram at ${u.rate} Hz on loopback` +
            `${u.timerHz > 0 ? `, a ${u.timerHz} Hz timer branch on the same worker` : ""}, batching interval ${fmt(u.batchingMs, 0)} ms; p50 ` +
            `${u.p50Ms.toFixed(3)} ms, p90 ${u.p90Ms.toFixed(3)} ms, max ${u.maxMs.toFixed(2)} ms ` +
            `(${u.received}/${u.samples} timed, ${u.lost} lost); socket → Rx callback p50 ` +
            `${u.inP50Ms.toFixed(3)} / p99 ${u.inP99Ms.toFixed(3)} ms, Rx callback → datagram out p50 ` +
            `${u.outP50Ms.toFixed(3)} / p99 ${u.outP99Ms.toFixed(3)} ms`
          : "",
      },
      (v) => `${v.toFixed(3)} ms`,
      u && !u.ok ? `failed: ${u.error ?? "unknown error"}` : "not run (`--only udp`)",
    ),
  );
  for (const [id, label] of [
    ["replay-32", "Virtual-clock replay, 5-block DSP chain, 32 ch @ 1926 Hz"],
    ["replay-256", "Virtual-clock replay, 5-block DSP chain, 256 ch @ 2048 Hz"],
  ] as const) {
    const r = replay(results, id);
    rows.push(
      judged(
        {
          id,
          workload: label,
          metric: "channel-samples per wall second",
          paper: "not possible (no virtual clock)",
          target: "≥ 20 M channel-samples/s",
          limit: 20e6,
          sense: "min",
          unit: "channel-samples/s",
          value: r?.ok ? r.channelSamplesPerSecond : null,
          note: r?.ok
            ? `${r.virtualSeconds.toFixed(0)} virtual s in ${r.wallSeconds.toFixed(2)} s wall (${fmtRateSI(r.framesPerSecond)} frames/s); load ${r.loadSeconds.toFixed(2)} s not included`
            : "",
        },
        (v) => `${fmtRateSI(v)} ch-samples/s`,
        why(r, id),
      ),
    );
  }
  for (const [id, label] of [
    ["myo", "Myo pipeline, quiet machine"],
    ["delsys", "Delsys pipeline, quiet machine"],
  ] as const) {
    const r = pipeline(results, id);
    const ok = r?.ok && Number.isFinite(r.acquisitionOnTimePct);
    rows.push(
      judged(
        {
          id: `ontime-${id}`,
          workload: label,
          metric: "Table 6: on-time share (G) of the acquisition chain, lowest block, %",
          paper:
            id === "myo" ? "100 % (every block)" : "98.3–99.2 % (Delsys, Amplification, LowPass)",
          target: "≥ 99.9 % on time",
          limit: 99.9,
          sense: "min",
          unit: "%",
          value: ok ? r.acquisitionOnTimePct : null,
          note: ok
            ? `${r.acquisitionChain.join(", ")}; load average before ${load(r.loadAvgBefore)} (a busy neighbour makes blocks lag)`
            : "",
        },
        (v) => `${v.toFixed(3)} %`,
        why(r, id),
      ),
    );
  }
  {
    const quiet = results.filter(
      (r): r is PipelineResult => r.kind === "pipeline" && !r.neighbour && r.samplesLost !== null,
    );
    const total = quiet.reduce((a, r) => a + r.samplesLost!.total, 0);
    rows.push(
      judged(
        {
          id: "lost-quiet",
          workload: "Every pipeline run without a neighbour",
          metric: "samples lost after the warm-up (missed ticks + drops on the acquisition chain)",
          paper: "not reported (MOSAIC had no drop counters)",
          target: "0",
          limit: 0,
          sense: "max",
          unit: "samples",
          value: quiet.length ? total : null,
          note: quiet
            .map(
              (r) =>
                `${r.id} ${r.samplesLost!.total} (${r.samplesLost!.missedTicks} missed, ${r.samplesLost!.acquisitionDrops} dropped)`,
            )
            .join(", "),
        },
        (v) => String(v),
        "no pipeline run",
      ),
    );
  }
  {
    const r = pipeline(results, "delsys-loaded");
    const ok = r?.ok === true;
    const n = r?.neighbour
      ? `a neighbour process burned ${fmtPct(r.neighbour.cpuPct)} of a core (\`${r.neighbour.command}\`); `
      : "";
    rows.push(
      judged(
        {
          id: "lost-delsys-loaded",
          workload: "Delsys pipeline while a neighbour burns one core",
          metric: "samples lost after the warm-up (missed ticks + drops on the acquisition chain)",
          paper: "not reported",
          target: "0 samples lost under load",
          limit: 0,
          sense: "max",
          unit: "samples",
          value: ok && r.samplesLost ? r.samplesLost.total : null,
          note:
            ok && r.samplesLost
              ? `${n}${r.samplesLost.missedTicks} ticks missed, ${r.samplesLost.acquisitionDrops} dropped; acquisition chain on time ${fmt(r.acquisitionOnTimePct, 3)} % (lowest block)`
              : "",
        },
        (v) => String(v),
        why(r, "delsys-loaded"),
      ),
    );
    const x = ok ? r.udp : undefined;
    rows.push(
      judged(
        {
          id: "udp-rate-delsys-loaded",
          workload: "Delsys pipeline while a neighbour burns one core",
          metric: "UDP rate at the receiver (events/s by arrival), deviation from 25.013 Hz",
          paper: "25.0204 Hz at the UDP Sender (Table 5, quiet)",
          target: "within 0.1 % of 25.013 Hz",
          limit: 0.1,
          sense: "max",
          unit: "%",
          value: x && Number.isFinite(x.rateErrorPct) ? Math.abs(x.rateErrorPct) : null,
          note: x
            ? `${x.events} events, ${x.datagrams} of ${x.expectedDatagrams} expected datagrams in ${x.windowSeconds} s; ${x.counterGaps} missing by the counter, ${x.missingEvents} events missing by the timestamps; longest gap between events ${x.maxArrivalGapMs.toFixed(1)} ms`
            : ok
              ? "no UDP figures"
              : "",
        },
        (v) => `${fmt(x?.rateHz, 4)} Hz (${x && x.rateErrorPct < 0 ? "−" : "+"}${v.toFixed(3)} %)`,
        why(r, "delsys-loaded"),
      ),
    );
  }
  return rows;
}

// ---------------------------------------------------------------------------------------------
// Markdown

export function targetsTable(rows: TargetRow[]): string[] {
  return table(
    ["workload", "metric", "MOSAIC (paper)", "target", "measured", "result", "notes"],
    rows.map((t) => [
      t.workload,
      t.metric,
      t.paper,
      t.target,
      t.display,
      t.pass === null
        ? t.value === null
          ? "not measured"
          : "info"
        : t.pass
          ? "met"
          : "**MISSED**",
      t.note,
    ]),
  );
}

export function pipelineMarkdown(r: PipelineResult, heading = "###"): string[] {
  const out: string[] = [`${heading} ${r.title}`, ""];
  out.push(`\`mosaic ${r.args.join(" ")}\``, "");
  if (!r.ok) {
    out.push(`**Failed:** ${r.error ?? "unknown error"}`, "");
    return out;
  }
  const paper = r.paper ? PAPER[r.paper] : undefined;
  const c = r.cpu;
  const m = r.memory;
  out.push(
    `Warm-up ${r.warmupSeconds} s excluded; steady state ${r.steadySeconds} s of CPU/RSS samples ` +
      `and ${r.telemetryLines} telemetry lines (20 Hz); ΔT statistics over ${r.measuredSeconds.toFixed(1)} s. ` +
      `Load average before ${load(r.loadAvgBefore)}, after ${load(r.loadAvgAfter)} (2 shared cores).`,
    "",
  );
  const res: string[] = [];
  if (c) {
    res.push(
      `CPU (% of one core, ${c.source === "schedstat" ? "per-thread schedstat" : `/proc/stat at ${c.clkTck} ticks/s`}): ` +
        `median ${fmtPct(c.medianPct)}, p90 ${fmtPct(c.p90Pct)}, mean ${fmtPct(c.meanPct)} ± ${fmtPct(c.stdPct)} ` +
        `over ${c.samples} 1-s samples (from /proc/<pid>/stat ticks: median ${fmtPct(c.ticksMedianPct)}, mean ${fmtPct(c.ticksMeanPct)})`,
    );
    if (c.childrenMeanPct > 0) {
      res.push(
        `Child processes (Python sidecars; not in the figure above): median ${fmtPct(c.childrenMedianPct)}, ` +
          `mean ${fmtPct(c.childrenMeanPct)} of one core`,
      );
    }
    if (Number.isFinite(r.blocksComputePct)) {
      res.push(
        `Blocks' own compute (Σ of measured \`process\` time): ${fmtPct(r.blocksComputePct)} of one core; ` +
          "the rest of the process CPU is runtime and host work (timer wake-ups, delivery, status, " +
          "telemetry, JSON output, GC)",
      );
    }
    if (r.wakeFloorPct !== undefined) {
      res.push(
        `Wake-up floor: a bare Node worker that only sleeps in Atomics.wait until each deadline at the ` +
          `pipeline's wake-up rate (${fmt(r.wakeFloorHz, 1)} Hz; no engine, no blocks) uses ` +
          `${fmtPct(r.wakeFloorPct)} of one core on this machine`,
      );
    }
    if (c.threads.length) {
      res.push(
        `CPU by thread (steady-state mean; wake-ups = voluntary context switches per second): ` +
          c.threads
            .map(
              (t) =>
                `${t.thread} ${fmtPct(t.pct)}${Number.isFinite(t.wakeupsPerS) ? ` (${t.wakeupsPerS.toFixed(0)} wake-ups/s)` : ""}`,
            )
            .join(", "),
      );
    }
  }
  if (m) {
    res.push(
      `Memory: peak RSS (VmHWM) ${m.peakRssMiB.toFixed(1)} MiB, steady-state VmRSS median ${m.steadyRssMedianMiB.toFixed(1)} MiB`,
    );
  }
  if (r.neighbour) {
    res.push(
      `Load: a neighbour process (\`${r.neighbour.command}\`, normal priority) burned ` +
        `${fmtPct(r.neighbour.cpuPct)} of a core for the whole run`,
    );
  }
  for (const t of r.timers) {
    res.push(
      `Timer ${t.name} (${t.desiredRate} Hz, batching interval ${fmt(r.batchingMs, 1)} ms): ${t.fired} ticks fired, ${t.missed} missed after the warm-up; ` +
        `lateness median ${t.latenessP50Us.toFixed(0)} µs, p99 ${t.latenessP99Us.toFixed(0)} µs, max ${t.latenessMaxUs.toFixed(0)} µs`,
    );
  }
  if (r.samplesLost) {
    res.push(
      `Samples lost after the warm-up: **${r.samplesLost.total}** (${r.samplesLost.missedTicks} ticks missed, ` +
        `${r.samplesLost.acquisitionDrops} events dropped on the edges out of the acquisition chain: ` +
        `${r.acquisitionChain.join(", ")})`,
    );
  }
  res.push(
    `Drops on edges: ${r.drops} after the warm-up (${r.dropsAllTime} in all); start-up (process start to ` +
      `pipeline running) ${r.loadSeconds.toFixed(2)} s`,
  );
  if (r.udp) res.push(udpRxLine(r.udp));
  for (const b of r.blocks) {
    if (b.type === "Python" && b.text) {
      res.push(
        `Python block ${b.name} at the end (sidecar round trip, then Python's own time): ${b.text}`,
      );
    }
  }
  if (r.warnings.length) res.push(`Warnings: ${r.warnings.join("; ")}`);
  for (const l of res) out.push(`- ${l}`);
  out.push("");

  out.push(
    "Table 5 — timing consistency after the warm-up: ΔT between the timestamps of consecutive " +
      "output events (a tick is stamped with its deadline, so the jitter of waking shows in the " +
      "delivery delay, not in ΔT), compute time per call, and delivery delay (time of processing − " +
      "timestamp of the oldest event of each batch)",
    "",
  );
  const head5 = [
    "Block",
    "Type",
    "Rate (Hz)",
    "Mean ΔT (s)",
    "Freq. (Hz)",
    "Std ΔT (s)",
    "n",
    "µs/call",
    "delay p50 (ms)",
    "p99 (ms)",
    "max (ms)",
  ];
  if (paper) head5.push("MOSAIC: block", "Freq. (Hz)", "Std ΔT (s)");
  // In the paper's row order (the runtime lists blocks in creation order), extra blocks last.
  const order = paper ? Object.keys(paper) : [];
  const rank = (name: string): number => {
    const i = order.indexOf(name);
    return i < 0 ? order.length : i;
  };
  const blocks = paper
    ? r.blocks
        .map((b, i) => ({ b, i }))
        .sort((x, y) => rank(x.b.name) - rank(y.b.name) || x.i - y.i)
        .map((x) => x.b)
    : r.blocks;
  out.push(
    ...table(
      head5,
      blocks.map((b) => {
        const row = [
          b.name,
          b.type,
          fmtRate(b.desiredRate),
          b.n > 0 ? fmt(b.meanDt, 7) : "-",
          b.n > 0 ? fmt(b.freq, 4) : "-",
          b.n > 1 ? fmt(b.stdDt, 7) : "-",
          String(b.n),
          fmt(b.computeMeanUs, 2),
          fmt(b.delay?.p50Ms, 3),
          fmt(b.delay?.p99Ms, 3),
          fmt(b.delay?.maxMs, 2),
        ];
        if (paper) {
          const p = paper[b.name];
          row.push(p ? p.block : "-", p ? fmt(p.freq, 4) : "-", p ? fmt(p.stdDt, 7) : "-");
        }
        return row;
      }),
    ),
    "",
  );
  out.push(
    "Table 6 — share of the steady state in each status (% of telemetry lines): G on time, I idle, L lagging, S stumbling",
    "",
  );
  const head6 = ["Block", "G (%)", "I (%)", "L (%)", "S (%)", "drops"];
  if (paper) head6.push("MOSAIC G / I / L / S (%)");
  out.push(
    ...table(
      head6,
      blocks.map((b) => {
        const s = b.shares;
        const row = [
          b.name,
          fmtShare(s?.ontime),
          fmtShare(s?.idle),
          fmtShare(s?.lagging),
          fmtShare(s?.stumbling),
          String(b.dropsIn),
        ];
        if (paper) {
          const p = paper[b.name];
          row.push(p ? p.status.map((x) => fmtShare(x)).join(" / ") : "-");
        }
        return row;
      }),
    ),
    "",
  );
  const notes: string[] = [];
  for (const b of r.blocks) {
    if (b.desiredRate > 0 && b.freq > 1.5 * b.desiredRate) {
      notes.push(
        `${b.name} reads ${(b.freq / b.desiredRate).toFixed(1)}× its desired rate: the runtime counts ` +
          "more outputs than ticks (e.g. one per output port).",
      );
    }
    if (b.type !== "Sink" && b.type !== "UdpSender") continue;
    if (b.n === 0 || (b.shares?.idle ?? 0) > 50) {
      notes.push(
        `${b.name} (${b.type}) has no outputs: its ΔT and status come from what it consumes; ` +
          "here it has no ΔT or reads mostly idle.",
      );
    }
  }
  for (const n of notes) out.push(`Note: ${n}`, "");
  return out;
}

/** One line about what the bench's UDP receiver got. */
export function udpRxLine(x: UdpRxFigures): string {
  const sign = x.rateErrorPct < 0 ? "−" : "+";
  return (
    `UDP at the receiver (127.0.0.1:${x.port}, the bench as the device): ${x.datagrams} datagrams in ` +
    `${x.windowSeconds} s (${fmt(x.datagramsPerSecond, 2)}/s, ${x.perEvent} per event; ${x.expectedDatagrams} expected), ` +
    `${x.events} events at **${fmt(x.rateHz, 4)} Hz** by arrival (${sign}${fmt(Math.abs(x.rateErrorPct), 3)} % ` +
    `vs ${fmt(x.expectedRateHz, 4)} Hz; ${fmt(x.timestampRateHz, 4)} Hz by their timestamps); missing: ` +
    `${x.counterGaps} datagrams by the counter, ${x.missingEvents} events by the timestamps, ` +
    `${x.incompleteEvents} incomplete events; longest gap between events ${fmt(x.maxArrivalGapMs, 1)} ms` +
    (x.malformed > 0 ? `; ${x.malformed} malformed (${x.firstMalformed ?? "?"})` : "")
  );
}

/** The batching sweep: CPU, wake-ups and delivery delay per pipeline and interval. */
export function batchingMarkdown(r: BatchingResult, heading = "##"): string[] {
  const out: string[] = [`${heading} ${r.title}`, ""];
  if (r.rows.length === 0) {
    out.push(`**Failed:** ${r.error ?? "nothing ran"}`, "");
    return out;
  }
  out.push(
    `Each pipeline run with \`--batching-ms\` ${r.intervalsMs.join(", ")} (warm-up ${r.warmupSeconds} s, ` +
      `steady state ${r.steadySeconds} s each). CPU: median of 1-s samples, % of one core. Wake-ups: ` +
      "voluntary context switches per second of the busiest thread other than the CLI's main thread " +
      "(the engine worker). Delay: delivery delay p50 / p99 (ms) since the warm-up. Samples lost: missed " +
      "ticks + drops on the acquisition chain.",
    "",
  );
  out.push(
    ...table(
      [
        "pipeline",
        "batching (ms)",
        "CPU median (%)",
        "engine wake-ups/s",
        "Sender delay p50 / p99 (ms)",
        "acquisition delay p50 / p99 (ms)",
        "UDP rate (Hz)",
        "samples lost",
        "load avg before",
      ],
      r.rows.map((x) =>
        x.ok
          ? [
              x.pipeline,
              String(x.batchingMs),
              fmt(x.cpuMedianPct, 2),
              fmt(x.engineWakeupsPerS, 0),
              x.sender ? `${fmt(x.sender.p50Ms, 3)} / ${fmt(x.sender.p99Ms, 3)}` : "-",
              x.acquisition
                ? `${x.acquisition.name}: ${fmt(x.acquisition.p50Ms, 3)} / ${fmt(x.acquisition.p99Ms, 3)}`
                : "-",
              fmt(x.udpRateHz, 4),
              x.samplesLost === null ? "-" : String(x.samplesLost),
              load(x.loadAvgBefore),
            ]
          : [
              x.pipeline,
              String(x.batchingMs),
              `failed: ${x.error ?? "?"}`,
              "-",
              "-",
              "-",
              "-",
              "-",
              load(x.loadAvgBefore),
            ],
      ),
    ),
    "",
  );
  return out;
}

export function replayMarkdown(rs: ReplayResult[], heading = "###"): string[] {
  const out: string[] = [`${heading} Virtual-clock replay throughput (5-block DSP chain)`, ""];
  out.push(
    "FilePlayer (Loop) on a ScheduledTimer → Amplification → Rectification → LowPass → Resampler " +
      "(DecimatorTimer 25 Hz), `--clock virtual`. Throughput = channels × rate × virtual seconds / " +
      "the run's wall seconds (host start → stop; process start and file load reported apart).",
    "",
  );
  out.push(
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
      rs.map((r) =>
        r.ok
          ? [
              `${r.channels} ch @ ${r.rate} Hz (${r.recordingSeconds} s, ${(r.recordingBytes / 2 ** 20).toFixed(1)} MiB CSV)`,
              r.virtualSeconds.toFixed(0),
              r.wallSeconds.toFixed(2),
              fmtRateSI(r.channelSamplesPerSecond),
              fmtRateSI(r.framesPerSecond),
              r.loadSeconds.toFixed(2),
              fmt(r.peakRssMiB, 1),
              `${load(r.loadAvgBefore)} → ${load(r.loadAvgAfter)}`,
            ]
          : [
              `${r.channels} ch @ ${r.rate} Hz`,
              "-",
              "-",
              `failed: ${r.error ?? "?"}`,
              "-",
              "-",
              "-",
              "-",
            ],
      ),
    ),
    "",
  );
  return out;
}

export function learnMarkdown(r: LearnResult, heading = "##"): string[] {
  const out: string[] = [`${heading} ${r.title}`, ""];
  if (!r.ok) {
    out.push(`**Failed:** ${r.error ?? "unknown error"}`, "");
    return out;
  }
  const outputs = r.figures[0]?.outputs ?? 0;
  out.push(
    "The mosaic-learn kernels through their WASM bindings (`LearningModel`), in the bench's own " +
      "process, one event per call as in a pipeline: an update is `trainPredict` (learn one " +
      "sample, then predict it: the IncrementalPredictor's training path), a prediction is " +
      `\`predict\`. ${outputs} outputs; ridge has D inputs, RFF has D random features on 8 ` +
      `inputs. Each figure is the mean over ${r.secondsPerFigure} s of calls. The last column is ` +
      "the CPU of one update per sample at 25 Hz (the Myo pipeline's predictor rate). Load " +
      `average before ${load(r.loadAvgBefore)}, after ${load(r.loadAvgAfter)} (2 shared cores).`,
    "",
  );
  out.push(
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
      r.figures.map((f) => [
        f.kind,
        String(f.dim),
        `${f.inputs} → ${f.outputs}`,
        fmt(f.updateNs, 0),
        fmt(f.predictNs, 0),
        fmtRateSI(1e9 / f.updateNs),
        (f.updateNs * 25 * 1e-7).toFixed(4),
      ]),
    ),
    "",
  );
  return out;
}
