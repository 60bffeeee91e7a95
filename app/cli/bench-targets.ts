/**
 * `mosaic bench`: the DESIGN.md §6 targets. One row per figure: the workload and metric, what
 * MOSAIC's paper reported, the target, what this run measured, whether it met the target and the
 * notes that explain the figure (or why it was not measured).
 */
import { fmt, fmtPct, fmtRateSI, load } from "./bench-format";
import { PAPER_CPU } from "./bench-paper";
import type {
  CpuFigures,
  PipelineResult,
  TargetRow,
  TimerFigures,
  UdpResult,
  WorkloadResult,
} from "./bench-types";

/** A target before it is judged: the workload, the metric, the paper's figure and the limit. */
type Target = Omit<TargetRow, "value" | "display" | "pass" | "note">;

/** The figure a run measured for a target, with the notes that explain it. */
interface Figure {
  value: number;
  note: string;
}

export function targets(results: WorkloadResult[]): TargetRow[] {
  return [
    ...cpuRows(results),
    recordingCostRow(results),
    memoryRow(results),
    ...timerRows(results),
    precisionRow(results),
    ...delayRows(results),
    udpLatencyRow(results),
    ...replayRows(results),
    ...onTimeRows(results),
    lostQuietRow(results),
    ...loadedRows(results),
  ];
}

// ---------------------------------------------------------------------------------------------
// Judging a figure against its target

/**
 * The row of target `t`: "not measured" (with `missingWhy` as its note) without a finite figure,
 * for information when the target has no limit, else met or missed.
 */
function judged(
  t: Target,
  f: Figure | null,
  display: (v: number) => string,
  missingWhy: string,
): TargetRow {
  const v = f?.value ?? NaN;
  if (!f || !Number.isFinite(v)) {
    return { ...t, value: null, note: missingWhy, display: "not measured", pass: null };
  }
  const pass = t.limit === null ? null : t.sense === "max" ? v <= t.limit : v >= t.limit;
  return { ...t, value: v, note: f.note, display: display(v), pass };
}

/** Why a workload's figures are missing: not selected, or failed ("" when it ran). */
function why(r: WorkloadResult | undefined, id: string): string {
  if (!r) return `workload '${id}' was not run (--only)`;
  return r.ok ? "" : `workload '${id}' failed: ${r.error ?? "unknown error"}`;
}

/** The result of workload `id` if it is of `kind`. */
function find<K extends WorkloadResult["kind"]>(
  results: WorkloadResult[],
  kind: K,
  id: string,
): Extract<WorkloadResult, { kind: K }> | undefined {
  const r = results.find((w) => w.id === id);
  return r && r.kind === kind ? (r as Extract<WorkloadResult, { kind: K }>) : undefined;
}

const us = (v: number): string => `${v.toFixed(0)} µs`;
const ms = (v: number): string => `${v.toFixed(3)} ms`;

// ---------------------------------------------------------------------------------------------
// CPU and memory

/** The paper's CPU figure (% of its 8 cores), in cores and in % of one core. */
function paperCpu(p: { pct8: number; sd8: number; cores: number }, cores: string): string {
  return `${p.pct8} % ± ${p.sd8} % of 8 cores ≈ ${p.cores.toFixed(2)} ${cores} (≈ ${(p.cores * 100).toFixed(0)} % of one core)`;
}

const CPU_TARGETS: { id: string; workload: string; paper: string; limit: number }[] = [
  {
    id: "myo",
    workload: "Myo pipeline, 8 ch @ 200 Hz",
    paper: paperCpu(PAPER_CPU.myo, "core"),
    limit: 1.5,
  },
  {
    id: "delsys",
    workload: "Delsys pipeline, 32 ch @ 1926 Hz",
    paper: paperCpu(PAPER_CPU.delsys, "cores"),
    limit: 3,
  },
  {
    id: "delsys-tcp",
    workload:
      "Delsys pipeline over TCP, Trigno simulator, 32 ch (8 sensors × EMG + accelerometer) @ 1925.926 Hz",
    paper: paperCpu(PAPER_CPU.delsys, "cores"),
    limit: 3,
  },
  { id: "hdemg", workload: "High-density EMG, 256 ch @ 2048 Hz", paper: "not reported", limit: 8 },
  {
    id: "hdemg-features",
    workload:
      "High-density EMG features (MAV, WL, ZC, SSC on 200 ms windows every 25 ms), 256 ch @ 2048 Hz",
    paper: "not reported",
    limit: 8,
  },
];

function cpuRows(results: WorkloadResult[]): TargetRow[] {
  return CPU_TARGETS.map(({ id, workload, paper, limit }) => {
    const r = find(results, "pipeline", id);
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
      },
      r && c ? { value: c.medianPct, note: cpuNote(r, c) } : null,
      fmtPct,
      why(r, id),
    );
  });
}

/**
 * What recording costs: the HD-EMG pipeline with an XdfRecorder on its 256 channels (hdemg-xdf)
 * less the same pipeline without (hdemg), medians of one run each.
 */
function recordingCostRow(results: WorkloadResult[]): TargetRow {
  const withRec = find(results, "pipeline", "hdemg-xdf");
  const without = find(results, "pipeline", "hdemg");
  const a = withRec?.ok ? withRec.cpu : null;
  const b = without?.ok ? without.cpu : null;
  return judged(
    {
      id: "cpu-xdf-recording",
      workload:
        "Recording 256 ch @ 2048 Hz to XDF (float32, 2 MiB/s), on top of the HD-EMG pipeline",
      metric: "CPU, hdemg-xdf median − hdemg median (% of one core)",
      paper: "not reported",
      target: "≤ 2 % of one core",
      limit: 2,
      sense: "max",
      unit: "% of one core",
    },
    a && b
      ? {
          value: a.medianPct - b.medianPct,
          note:
            `hdemg-xdf ${fmtPct(a.medianPct)}, hdemg ${fmtPct(b.medianPct)} (medians of 1-s samples, one run each)` +
            (withRec!.recording
              ? `; the recording: ${fmt(withRec!.recording.mibPerS, 2)} MiB/s over the run, XDF magic checked`
              : ""),
        }
      : null,
    fmtPct,
    why(withRec, "hdemg-xdf") || why(without, "hdemg"),
  );
}

/** The spread of the CPU samples, the tick-based reading and the wake-up floor. */
function cpuNote(r: PipelineResult, c: CpuFigures): string {
  const spread =
    `p90 ${fmtPct(c.p90Pct)}, mean ${fmtPct(c.meanPct)} ± ${fmtPct(c.stdPct)} (${c.samples} samples); ` +
    `/proc/stat ticks: median ${fmtPct(c.ticksMedianPct)}, mean ${fmtPct(c.ticksMeanPct)}`;
  if (r.wakeFloorPct === undefined) return spread;
  return (
    spread +
    `; wake-up floor on this machine (a bare worker waking at the pipeline's ${fmt(r.wakeFloorHz, 1)} Hz, nothing else): ${fmtPct(r.wakeFloorPct)}` +
    (r.ioFloorPct !== undefined
      ? `, ${fmtPct(r.ioFloorPct)} when it also sends the pipeline's ${fmt(r.ioFloorDatagramsPerS, 1)} datagrams/s`
      : "") +
    `; engine thread ${fmt(c.engineWakeupsPerS, 0)} wake-ups/s, batching interval ${fmt(r.batchingMs, 1)} ms`
  );
}

function memoryRow(results: WorkloadResult[]): TargetRow {
  const r = find(results, "pipeline", "delsys");
  const m = r?.ok ? r.memory : null;
  return judged(
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
    },
    m
      ? {
          value: m.peakRssMiB,
          note: `steady-state VmRSS median ${m.steadyRssMedianMiB.toFixed(1)} MiB`,
        }
      : null,
    (v) => `${v.toFixed(1)} MiB`,
    why(r, "delsys"),
  );
}

// ---------------------------------------------------------------------------------------------
// Timers and delays

/** Median and p99 of the 2-kHz timer's lateness, a wake-up per tick. */
function timerRows(results: WorkloadResult[]): TargetRow[] {
  const r = find(results, "pipeline", "timer");
  const t = r?.ok ? r.timers[0] : undefined;
  const row = (
    which: "p50" | "p99",
    metric: string,
    limit: number,
    value: (t: TimerFigures) => number,
  ): TargetRow =>
    judged(
      {
        id: `timer-${which}`,
        workload: "Timer at 2 kHz, default mode, batching interval 0",
        metric: `lateness (fire − deadline), ${metric}, µs`,
        paper: "not reported; ΔT std 0.24–0.38 ms for the acquisition blocks (Table 5)",
        target: `${metric} ≤ ${limit} µs`,
        limit,
        sense: "max",
        unit: "µs",
      },
      r && t ? { value: value(t), note: timerNote(r, t) } : null,
      us,
      why(r, "timer"),
    );
  return [
    row("p50", "median", 100, (t) => t.latenessP50Us),
    row("p99", "p99", 200, (t) => t.latenessP99Us),
  ];
}

function timerNote(r: PipelineResult, t: TimerFigures): string {
  return `batching interval ${fmt(r.batchingMs, 0)} ms (\`--batching-ms 0\`: a wake-up for every tick); max ${t.latenessMaxUs.toFixed(0)} µs, ${t.fired} ticks fired, ${t.missed} missed`;
}

/** The timer in precision mode: for information, no target. */
function precisionRow(results: WorkloadResult[]): TargetRow {
  const r = find(results, "pipeline", "timer-precision");
  const t = r?.ok ? r.timers[0] : undefined;
  return judged(
    {
      id: "timer-precision",
      workload: "Timer at 2 kHz, `--precision` (spin the last ~0.3 ms), batching interval 0",
      metric: "lateness median / p99, µs; CPU median",
      paper: "not available in MOSAIC",
      target: "none (information)",
      limit: null,
      sense: "max",
      unit: "µs",
    },
    r && t
      ? {
          value: t.latenessP99Us,
          note: `max ${t.latenessMaxUs.toFixed(0)} µs, ${t.missed} of ${t.fired + t.missed} ticks missed; CPU median ${fmtPct(r.cpu?.medianPct ?? NaN)} of one core`,
        }
      : null,
    (v) => `${t!.latenessP50Us.toFixed(0)} µs / ${v.toFixed(0)} µs`,
    why(r, "timer-precision"),
  );
}

/** The delivery delay of the Delsys pipeline's Sender and acquisition block. */
function delayRows(results: WorkloadResult[]): TargetRow[] {
  const r = find(results, "pipeline", "delsys");
  return [delayRow(r, "Sender"), delayRow(r, "acquisition")];
}

function delayRow(r: PipelineResult | undefined, which: "Sender" | "acquisition"): TargetRow {
  const name = which === "Sender" ? "Sender" : (r?.acquisition ?? "Delsys");
  const delay = r?.ok ? r.blocks.find((x) => x.name === name)?.delay : undefined;
  return judged(
    {
      id: `delay-delsys-${which.toLowerCase()}`,
      workload: `Delsys pipeline, default batching interval: ${which === "Sender" ? "the UDP Sender" : `the acquisition block (${name})`}`,
      metric: "delivery delay (processing − event time), p99, ms",
      paper: "not reported",
      target: "p99 ≤ interval + 1 ms",
      limit: r?.ok && Number.isFinite(r.batchingMs) ? r.batchingMs + 1 : null,
      sense: "max",
      unit: "ms",
    },
    r && delay
      ? {
          value: delay.p99Ms,
          note: `interval ${fmt(r.batchingMs, 1)} ms; p50 ${fmt(delay.p50Ms, 3)} ms, max ${fmt(delay.maxMs, 2)} ms over ${delay.n} batches`,
        }
      : null,
    ms,
    why(r, "delsys"),
  );
}

function udpLatencyRow(results: WorkloadResult[]): TargetRow {
  const u = results.find((r): r is UdpResult => r.kind === "udp");
  return judged(
    {
      id: "latency-udp",
      workload: "Sensor frame in → UDP datagram out, same worker, batching interval 0",
      metric: "p99 latency",
      paper: "not reported",
      target: "p99 ≤ 1 ms",
      limit: 1,
      sense: "max",
      unit: "ms",
    },
    u?.ok ? { value: u.p99Ms, note: udpLatencyNote(u) } : null,
    ms,
    u && !u.ok ? `failed: ${u.error ?? "unknown error"}` : "not run (`--only udp`)",
  );
}

function udpLatencyNote(u: UdpResult): string {
  return (
    `UdpReceiver → Function → UdpSender, ${u.channels} f64 per datagram at ${u.rate} Hz on loopback` +
    `${u.timerHz > 0 ? `, a ${u.timerHz} Hz timer branch on the same worker` : ""}, batching interval ${fmt(u.batchingMs, 0)} ms; p50 ` +
    `${u.p50Ms.toFixed(3)} ms, p90 ${u.p90Ms.toFixed(3)} ms, max ${u.maxMs.toFixed(2)} ms ` +
    `(${u.received}/${u.samples} timed, ${u.lost} lost); socket → Rx callback p50 ` +
    `${u.inP50Ms.toFixed(3)} / p99 ${u.inP99Ms.toFixed(3)} ms, Rx callback → datagram out p50 ` +
    `${u.outP50Ms.toFixed(3)} / p99 ${u.outP99Ms.toFixed(3)} ms`
  );
}

// ---------------------------------------------------------------------------------------------
// Replay throughput

const REPLAY_TARGETS = [
  { id: "replay-32", workload: "Virtual-clock replay, 5-block DSP chain, 32 ch @ 1926 Hz" },
  { id: "replay-256", workload: "Virtual-clock replay, 5-block DSP chain, 256 ch @ 2048 Hz" },
];

function replayRows(results: WorkloadResult[]): TargetRow[] {
  return REPLAY_TARGETS.map(({ id, workload }) => {
    const r = find(results, "replay", id);
    return judged(
      {
        id,
        workload,
        metric: "channel-samples per wall second",
        paper: "not possible (no virtual clock)",
        target: "≥ 20 M channel-samples/s",
        limit: 20e6,
        sense: "min",
        unit: "channel-samples/s",
      },
      r?.ok
        ? {
            value: r.channelSamplesPerSecond,
            note: `${r.virtualSeconds.toFixed(0)} virtual s in ${r.wallSeconds.toFixed(2)} s wall (${fmtRateSI(r.framesPerSecond)} frames/s); load ${r.loadSeconds.toFixed(2)} s not included`,
          }
        : null,
      (v) => `${fmtRateSI(v)} ch-samples/s`,
      why(r, id),
    );
  });
}

// ---------------------------------------------------------------------------------------------
// Status shares and samples lost

const ON_TIME_TARGETS = [
  { id: "myo", workload: "Myo pipeline, quiet machine", paper: "100 % (every block)" },
  {
    id: "delsys",
    workload: "Delsys pipeline, quiet machine",
    paper: "98.3–99.2 % (Delsys, Amplification, LowPass)",
  },
  {
    id: "delsys-tcp",
    workload: "Delsys pipeline over TCP (Trigno simulator), quiet machine",
    paper: "98.3–99.2 % (Delsys, Amplification, LowPass)",
  },
];

/** Table 6's on-time share of the acquisition chain (its lowest block). */
function onTimeRows(results: WorkloadResult[]): TargetRow[] {
  return ON_TIME_TARGETS.map(({ id, workload, paper }) => {
    const r = find(results, "pipeline", id);
    return judged(
      {
        id: `ontime-${id}`,
        workload,
        metric: "Table 6: on-time share (G) of the acquisition chain, lowest block, %",
        paper,
        target: "≥ 99.9 % on time",
        limit: 99.9,
        sense: "min",
        unit: "%",
      },
      r?.ok
        ? {
            value: r.acquisitionOnTimePct,
            note: `${r.acquisitionChain.join(", ")}; load average before ${load(r.loadAvgBefore)} (a busy neighbour makes blocks lag)`,
          }
        : null,
      (v) => `${v.toFixed(3)} %`,
      why(r, id),
    );
  });
}

const LOST_METRIC =
  "samples lost after the warm-up (missed ticks + drops on the acquisition chain)";

/** Samples lost by every pipeline that ran without a neighbour, together. */
function lostQuietRow(results: WorkloadResult[]): TargetRow {
  const quiet = results.filter(
    (r): r is PipelineResult => r.kind === "pipeline" && !r.neighbour && r.samplesLost !== null,
  );
  const lost = quiet.map((r) => ({ id: r.id, ...r.samplesLost! }));
  return judged(
    {
      id: "lost-quiet",
      workload: "Every pipeline run without a neighbour",
      metric: LOST_METRIC,
      paper: "not reported (MOSAIC had no drop counters)",
      target: "0",
      limit: 0,
      sense: "max",
      unit: "samples",
    },
    quiet.length
      ? {
          value: lost.reduce((a, l) => a + l.total, 0),
          note: lost
            .map(
              (l) => `${l.id} ${l.total} (${l.missedTicks} missed, ${l.acquisitionDrops} dropped)`,
            )
            .join(", "),
        }
      : null,
    String,
    "no pipeline run",
  );
}

const LOADED = "Delsys pipeline while a neighbour burns one core";

/** The Delsys pipeline beside a neighbour that burns one core: samples lost and the UDP rate. */
function loadedRows(results: WorkloadResult[]): TargetRow[] {
  const r = find(results, "pipeline", "delsys-loaded");
  return [lostLoadedRow(r), udpRateLoadedRow(r)];
}

function lostLoadedRow(r: PipelineResult | undefined): TargetRow {
  const lost = r?.ok ? r.samplesLost : null;
  return judged(
    {
      id: "lost-delsys-loaded",
      workload: LOADED,
      metric: LOST_METRIC,
      paper: "not reported",
      target: "0 samples lost under load",
      limit: 0,
      sense: "max",
      unit: "samples",
    },
    r && lost
      ? {
          value: lost.total,
          note: `${neighbourNote(r)}${lost.missedTicks} ticks missed, ${lost.acquisitionDrops} dropped; acquisition chain on time ${fmt(r.acquisitionOnTimePct, 3)} % (lowest block)`,
        }
      : null,
    String,
    why(r, "delsys-loaded"),
  );
}

function neighbourNote(r: PipelineResult): string {
  return r.neighbour
    ? `a neighbour process burned ${fmtPct(r.neighbour.cpuPct)} of a core (\`${r.neighbour.command}\`); `
    : "";
}

/** The rate of the Sender's events at the bench's receiver, against MOSAIC's 25.013 Hz. */
function udpRateLoadedRow(r: PipelineResult | undefined): TargetRow {
  const x = r?.ok ? r.udp : undefined;
  return judged(
    {
      id: "udp-rate-delsys-loaded",
      workload: LOADED,
      metric: "UDP rate at the receiver (events/s by arrival), deviation from 25.013 Hz",
      paper: "25.0204 Hz at the UDP Sender (Table 5, quiet)",
      target: "within 0.1 % of 25.013 Hz",
      limit: 0.1,
      sense: "max",
      unit: "%",
    },
    x
      ? {
          value: Math.abs(x.rateErrorPct),
          note: `${x.events} events, ${x.datagrams} of ${x.expectedDatagrams} expected datagrams in ${x.windowSeconds} s; ${x.counterGaps} missing by the counter, ${x.missingEvents} events missing by the timestamps; longest gap between events ${x.maxArrivalGapMs.toFixed(1)} ms`,
        }
      : null,
    (v) => `${fmt(x?.rateHz, 4)} Hz (${x && x.rateErrorPct < 0 ? "−" : "+"}${v.toFixed(3)} %)`,
    why(r, "delsys-loaded"),
  );
}
