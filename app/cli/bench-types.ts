/**
 * `mosaic bench`: the results of each workload kind and the target rows, as latest.json holds them.
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
  /** CPU of that worker when it also sends the pipeline's datagrams (as many per event, at the
   * pipeline's event rate) to a receiver in another process, % of one core, and the datagrams per
   * second that arrived meanwhile. */
  ioFloorPct?: number;
  ioFloorDatagramsPerS?: number;
  /** What the pipeline recorded (workloads with `recording`), checked and then deleted. */
  recording?: RecordingFigures;
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
  /** Telemetry per second of the run (`--telemetry-hz`); absent in results written before the
   * telemetry sweep, whose runs all had the CLI's default, 20. */
  telemetryHz?: number;
  /** false: the run kept V8's own tier-up thresholds (the tiering sweep); absent: the engine's. */
  v8Tiering?: boolean;
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
  /** The telemetry rates swept at each interval (the telemetry sweep only). */
  telemetryHz?: number[];
  /** The tier-up thresholds swept at each interval (the tiering sweep only; see BatchingRow). */
  v8Tiering?: boolean[];
  rows: BatchingRow[];
  loadAvgBefore: number[];
  loadAvgAfter: number[];
  killedAfterSummary: boolean;
}

/** The soak (bench-soak.ts): one long run and what it must not leak or lose. */
export interface SoakResult {
  kind: "soak";
  id: string;
  title: string;
  ok: boolean;
  error?: string;
  /** Every check below passed (memory flat, nothing uncounted, errors consistent). */
  pass: boolean;
  /** Why it did not, one item per failed check. */
  failures: string[];
  warmupSeconds: number;
  steadySeconds: number;
  /** VmRSS of the Python sidecar(s) (the run's child processes) over the steady state, MiB. */
  sidecarRss: { startMiB: number; endMiB: number; maxMiB: number; driftPct: number } | null;
  /** VmRSS of the `mosaic run` process over the steady state (1-s samples), MiB. */
  rss: {
    samples: number;
    startMiB: number;
    endMiB: number;
    maxMiB: number;
    minMiB: number;
    /** Samples left out while memory settles (a third of the run, at most 600), and the growth
     * over them: start → the median of the first window after, %. */
    settleSamples: number;
    settleGrowthPct: number;
    /** Samples in each of the first and the last window after settling (a minute, a tenth of
     * what is left of a shorter run). */
    windowSamples: number;
    firstMedianMiB: number;
    lastMedianMiB: number;
    /** (last − first) / first of those medians, and (max after settling − first) / first, %. */
    driftPct: number;
    /** driftPct at the same slope over the whole run (what the tolerance judges), %. */
    runDriftPct: number;
    maxOverStartPct: number;
    tolerancePct: number;
    flat: boolean;
  } | null;
  /**
   * The Sender's datagrams over the whole run: sent and not sent (counted, with the last reason)
   * as its status says, received by the bench, and sent but never received (uncounted: must be 0).
   */
  udp: {
    sent: number | null;
    notSent: number | null;
    notSentReason: string;
    received: number;
    malformed: number;
    uncounted: number | null;
  };
  /** What the engine counted as lost: edge drops and missed ticks (all time). */
  drops: { edges: number; missedTicks: number };
  /**
   * Errors: per block as its telemetry counts them (the summary), the error and warning events
   * printed, and the run's exit code (1 exactly when a block counted an error).
   */
  errors: {
    total: number;
    blocks: { name: string; errors: number; lastError: string }[];
    events: Record<string, number>;
    exitCode: number | null;
    consistent: boolean;
  };
  /** The pipeline run itself, as the pipeline workloads report it (CPU, Tables 5/6, UDP). */
  run: PipelineResult;
  loadAvgBefore: number[];
  loadAvgAfter: number[];
  killedAfterSummary: boolean;
}

export type WorkloadResult =
  PipelineResult | ReplayResult | LearnResult | UdpResult | BatchingResult | SoakResult;

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

/** A bench pipeline's recording, read back after its run. */
export interface RecordingFigures {
  /** Relative to the repository. */
  file: string;
  bytes: number;
  /** Bytes over the run's length (start-up included), MiB/s, and what the workload expects. */
  mibPerS: number;
  expectedMiBPerS: number;
  /** The file starts with the XDF magic `XDF:`. */
  magic: boolean;
}
