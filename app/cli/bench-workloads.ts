/**
 * `mosaic bench`: the workloads of the suite (DESIGN.md §6) and how `--only` selects them.
 */

export interface PipelineDef {
  kind: "pipeline";
  id: string;
  title: string;
  file: string;
  paper?: "myo" | "delsys";
  extra?: string[];
  /** The timer workloads run for half the steady-state duration. */
  short?: boolean;
  /** The acquisition block (the simulated device). */
  acquisition?: string;
  /** The rate the Sender sends events at (Hz): the bench receives on the Sender's port (read
   * from the file) and checks the rate and the gaps against this. */
  udpRateHz?: number;
  /** Run while a neighbour process burns one core. */
  neighbour?: boolean;
  /**
   * A device simulator the bench runs in its own process for the run, on these ports (the
   * pipeline's device block reads them); its CPU is not in the pipeline's figure.
   */
  simulator?: { device: "delsys"; commandPort: number; emgPort: number; auxPort: number };
  /** The engine's wake-ups per second when the device's packets pace it (the wake-up floor's rate). */
  wakeHz?: number;
  /**
   * The pipeline records to the file its `File:` param names (relative to the pipeline): the bench
   * removes it before the run, checks afterwards that it was written (XDF magic, size against
   * `mibPerS` over the run) and deletes it.
   */
  recording?: { mibPerS: number };
}
export interface BatchingDef {
  kind: "batching";
  id: string;
  title: string;
  /** Ids of the pipeline workloads swept. */
  pipelines: string[];
  intervalsMs: number[];
  /**
   * Telemetry rates (`--telemetry-hz`) run one after the other at each interval, so that their
   * difference is the cost of telemetry; left out: the CLI's default (20 Hz, as the UI) only.
   */
  telemetryHz?: number[];
  /**
   * Runs with the engine's V8 tier-up thresholds (true) and V8's own (false), one after the other
   * at each interval (the tiering sweep, app/host/tiering.ts); left out: the engine's only.
   */
  v8Tiering?: boolean[];
}
export interface ReplayDef {
  kind: "replay";
  id: string;
  title: string;
  channels: number;
  rate: number;
  recordingSeconds: number;
}
export interface LearnDef {
  kind: "learn";
  id: string;
  title: string;
  dims: number[];
  outputs: number;
}
export interface UdpDef {
  kind: "udp";
  id: string;
  title: string;
  timerHz: number;
}
/**
 * The soak: a long real-time run of one pipeline (memory drift, every datagram and every error
 * accounted for). Not part of the default suite: `--only soak`.
 */
export interface SoakDef {
  kind: "soak";
  id: string;
  title: string;
  /** In pipelines/bench/; its Sender's port is where the bench's receiver listens. */
  file: string;
  acquisition: string;
  udpRateHz: number;
  /** Steady-state seconds unless `--duration` says otherwise (`--quick`: its own 3 s). */
  steadySeconds: number;
  /** VmRSS may move this much (%) between the start and the end of the steady state. */
  memoryTolerancePct: number;
  /** Run only when `--only` names it. */
  explicit: true;
}
export type WorkloadDef = PipelineDef | ReplayDef | LearnDef | UdpDef | BatchingDef | SoakDef;

/** 1926 Hz / 77: the Delsys pipelines' 25 Hz branch (MOSAIC's 25.013 Hz). */
const DELSYS_25 = 1926 / 77;
/** 2048 Hz / 82: the high-density pipeline's 25 Hz branch. */
const HDEMG_25 = 2048 / 82;

export const WORKLOADS: WorkloadDef[] = [
  {
    kind: "pipeline",
    id: "myo",
    title: "(a) Myo pipeline — 8 ch @ 200 Hz",
    file: "myo.yaml",
    paper: "myo",
    acquisition: "Myo",
    udpRateHz: 25,
  },
  {
    kind: "pipeline",
    id: "delsys",
    title: "(b) Delsys pipeline — 32 ch @ 1926 Hz",
    file: "delsys.yaml",
    paper: "delsys",
    acquisition: "Delsys",
    udpRateHz: DELSYS_25,
  },
  {
    kind: "pipeline",
    id: "delsys-loaded",
    title: "(b) Delsys pipeline — 32 ch @ 1926 Hz, while a neighbour process burns one core",
    file: "delsys.yaml",
    paper: "delsys",
    acquisition: "Delsys",
    udpRateHz: DELSYS_25,
    neighbour: true,
  },
  {
    kind: "pipeline",
    id: "delsys-tcp",
    title:
      "(b′) Delsys pipeline over TCP — the Trigno simulator's 8 sensors × (EMG + accelerometer) = 32 ch @ 1925.926 Hz, 26 samples every 13.5 ms",
    file: "delsys-tcp.yaml",
    acquisition: "Delsys",
    udpRateHz: 25,
    simulator: { device: "delsys", commandPort: 50540, emgPort: 50543, auxPort: 50544 },
    wakeHz: 1 / 0.0135,
  },
  {
    kind: "pipeline",
    id: "hdemg",
    title: "(c) High-density EMG — 256 ch @ 2048 Hz",
    file: "hdemg.yaml",
    acquisition: "HDEMG",
    udpRateHz: HDEMG_25,
  },
  {
    kind: "pipeline",
    id: "hdemg-xdf",
    title:
      "(c+) High-density EMG recorded to XDF — 256 ch @ 2048 Hz, the raw grid as float32 (2 MiB/s)",
    file: "hdemg-xdf.yaml",
    acquisition: "HDEMG",
    udpRateHz: HDEMG_25,
    recording: { mibPerS: (256 * 4 * 2048) / 2 ** 20 },
  },
  {
    kind: "pipeline",
    id: "hdemg-features",
    title: "(d) High-density EMG features — 256 ch @ 2048 Hz, 200 ms windows every 25 ms",
    file: "hdemg-features.yaml",
    acquisition: "HDEMG",
    udpRateHz: 2048 / 51,
  },
  {
    kind: "pipeline",
    id: "python-cnn",
    title:
      "(e) Deep model in the Python sidecar — 32 ch @ 1926 Hz, 200-sample windows every 77 (25 Hz), ONNX 1-D CNN, control, UDP",
    file: "python-cnn.yaml",
    acquisition: "Delsys",
    udpRateHz: DELSYS_25,
  },
  {
    kind: "pipeline",
    id: "timer",
    title: "Timer at 2 kHz, default mode, batching interval 0",
    file: "timer-2khz.yaml",
    extra: ["--batching-ms", "0"],
    short: true,
  },
  {
    kind: "pipeline",
    id: "timer-precision",
    title: "Timer at 2 kHz, --precision, batching interval 0",
    file: "timer-2khz.yaml",
    extra: ["--batching-ms", "0", "--precision"],
    short: true,
  },
  {
    kind: "replay",
    id: "replay-32",
    title: "Replay 32 ch @ 1926 Hz",
    channels: 32,
    rate: 1926,
    recordingSeconds: 10,
  },
  {
    kind: "replay",
    id: "replay-256",
    title: "Replay 256 ch @ 2048 Hz",
    channels: 256,
    rate: 2048,
    recordingSeconds: 4,
  },
  {
    kind: "learn",
    id: "learn",
    title:
      "Learning kernels (WASM micro-benchmarks): ridge and RFF, incremental update and prediction",
    dims: [8, 64, 256],
    outputs: 12,
  },
  {
    kind: "udp",
    id: "udp",
    title:
      "UDP latency — datagram in → UdpReceiver → Function → UdpSender → datagram out (batching interval 0)",
    timerHz: 200,
  },
  {
    kind: "batching",
    id: "batching",
    title:
      "Batching sweep — the Delsys and Myo pipelines at --batching-ms 0, 1, 2, 5, 10: CPU, engine wake-ups, delivery delay",
    pipelines: ["delsys", "myo"],
    intervalsMs: [0, 1, 2, 5, 10],
  },
  {
    kind: "batching",
    id: "telemetry",
    title:
      "Telemetry cost — the Myo pipeline at the default batching interval with telemetry at 20 Hz (the UI's rate, the CLI's default) and at 2 Hz, in turn: CPU",
    pipelines: ["myo"],
    intervalsMs: [5], // the default (DEFAULT_BATCHING_S, app/engine/runtime/runtime.ts)
    // Pairs in alternating order (20 then 2, 2 then 20, …): a steady drift of the load cancels.
    telemetryHz: [20, 2, 2, 20, 20, 2, 2, 20],
  },
  {
    kind: "batching",
    id: "tiering",
    title:
      "V8 tiering — the Myo pipeline at the default batching interval with the engine's V8 tier-up thresholds and with V8's own, in turn: CPU",
    pipelines: ["myo"],
    intervalsMs: [5],
    // Pairs in alternating order, as the telemetry sweep's.
    v8Tiering: [false, true, true, false, false, true, true, false],
  },
  {
    kind: "soak",
    id: "soak",
    title:
      "Soak — the Delsys pipeline with the Python sidecar (ONNX CNN) and a UDP sender for 30 minutes: memory drift, datagrams and errors accounted for",
    file: "python-cnn.yaml",
    acquisition: "Delsys",
    udpRateHz: DELSYS_25,
    steadySeconds: 1800,
    memoryTolerancePct: 5,
    explicit: true,
  },
];

/** The pipeline workload `id`. */
export function pipelineDef(id: string): PipelineDef | undefined {
  return WORKLOADS.find((w): w is PipelineDef => w.kind === "pipeline" && w.id === id);
}

/**
 * Whether `--only` name `n` selects workload `id`: a workload's own id selects it alone; `NAME*`,
 * or a name that is no workload's id (`replay`), selects the group `NAME` and `NAME-…`.
 */
export function selects(n: string, id: string): boolean {
  const group = n.endsWith("*") ? n.slice(0, -1) : WORKLOADS.some((w) => w.id === n) ? null : n;
  if (group === null) return id === n;
  return id === group || id.startsWith(group + "-");
}
