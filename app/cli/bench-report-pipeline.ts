/**
 * `mosaic bench`: the Markdown of a pipeline run — the command, the window, the CPU, memory,
 * timer, loss and UDP lines, the paper's Table 5 (timing) and Table 6 (status shares) beside
 * MOSAIC's figures, and notes on figures that read oddly.
 */
import { failed, fmt, fmtPct, fmtRate, fmtShare, load, section, table } from "./bench-format";
import { PAPER, type PaperBlock } from "./bench-paper";
import type {
  BlockRow,
  CpuFigures,
  PipelineResult,
  TimerFigures,
  UdpRxFigures,
} from "./bench-types";

/** MOSAIC's rows for a pipeline, keyed by our block names. */
type PaperRows = Record<string, PaperBlock>;

export function pipelineMarkdown(r: PipelineResult, heading = "###"): string[] {
  const head = [...section(heading, r.title), `\`mosaic ${r.args.join(" ")}\``, ""];
  if (!r.ok) return [...head, ...failed(r.error ?? "unknown error")];
  const paper = r.paper ? PAPER[r.paper] : undefined;
  const blocks = inPaperOrder(r.blocks, paper);
  return [
    ...head,
    windowLine(r),
    "",
    ...facts(r).map((l) => `- ${l}`),
    "",
    ...table5(blocks, paper),
    ...table6(blocks, paper),
    ...notes(r.blocks).flatMap((n) => [`Note: ${n}`, ""]),
  ];
}

/** What was measured over which window, and the load around it. */
function windowLine(r: PipelineResult): string {
  return (
    `Warm-up ${r.warmupSeconds} s excluded; steady state ${r.steadySeconds} s of CPU/RSS samples ` +
    `and ${r.telemetryLines} telemetry lines (20 Hz); ΔT statistics over ${r.measuredSeconds.toFixed(1)} s. ` +
    `Load average before ${load(r.loadAvgBefore)}, after ${load(r.loadAvgAfter)} (2 shared cores).`
  );
}

/** The bullet list: CPU, memory, load, timers, losses, UDP, Python blocks, warnings. */
function facts(r: PipelineResult): string[] {
  return [
    ...(r.cpu ? cpuLines(r, r.cpu) : []),
    ...(r.memory
      ? [
          `Memory: peak RSS (VmHWM) ${r.memory.peakRssMiB.toFixed(1)} MiB, steady-state VmRSS median ${r.memory.steadyRssMedianMiB.toFixed(1)} MiB`,
        ]
      : []),
    ...(r.neighbour
      ? [
          `Load: a neighbour process (\`${r.neighbour.command}\`, normal priority) burned ` +
            `${fmtPct(r.neighbour.cpuPct)} of a core for the whole run`,
        ]
      : []),
    ...r.timers.map((t) => timerLine(t, r.batchingMs)),
    ...(r.samplesLost ? [samplesLostLine(r, r.samplesLost)] : []),
    `Drops on edges: ${r.drops} after the warm-up (${r.dropsAllTime} in all); start-up (process start to ` +
      `pipeline running) ${r.loadSeconds.toFixed(2)} s`,
    ...(r.udp ? [udpRxLine(r.udp)] : []),
    ...r.blocks
      .filter((b) => b.type === "Python" && b.text)
      .map(
        (b) =>
          `Python block ${b.name} at the end (sidecar round trip, then Python's own time): ${b.text}`,
      ),
    ...(r.warnings.length ? [`Warnings: ${r.warnings.join("; ")}`] : []),
  ];
}

/** The process CPU, its child processes, the blocks' share, the wake-up floor and the threads. */
function cpuLines(r: PipelineResult, c: CpuFigures): string[] {
  const lines = [
    `CPU (% of one core, ${c.source === "schedstat" ? "per-thread schedstat" : `/proc/stat at ${c.clkTck} ticks/s`}): ` +
      `median ${fmtPct(c.medianPct)}, p90 ${fmtPct(c.p90Pct)}, mean ${fmtPct(c.meanPct)} ± ${fmtPct(c.stdPct)} ` +
      `over ${c.samples} 1-s samples (from /proc/<pid>/stat ticks: median ${fmtPct(c.ticksMedianPct)}, mean ${fmtPct(c.ticksMeanPct)})`,
  ];
  if (c.childrenMeanPct > 0) {
    lines.push(
      `Child processes (Python sidecars; not in the figure above): median ${fmtPct(c.childrenMedianPct)}, ` +
        `mean ${fmtPct(c.childrenMeanPct)} of one core`,
    );
  }
  if (Number.isFinite(r.blocksComputePct)) {
    lines.push(
      `Blocks' own compute (Σ of measured \`process\` time): ${fmtPct(r.blocksComputePct)} of one core; ` +
        "the rest of the process CPU is runtime and host work (timer wake-ups, delivery, status, " +
        "telemetry, JSON output, GC)",
    );
  }
  if (r.wakeFloorPct !== undefined) {
    lines.push(
      `Wake-up floor: a bare Node worker that only sleeps in Atomics.wait until each deadline at the ` +
        `pipeline's wake-up rate (${fmt(r.wakeFloorHz, 1)} Hz; no engine, no blocks) uses ` +
        `${fmtPct(r.wakeFloorPct)} of one core on this machine`,
    );
  }
  const rec = r.recording;
  if (rec) {
    lines.push(
      `Recording: \`${rec.file}\` ${(rec.bytes / 2 ** 20).toFixed(1)} MiB, ${fmt(rec.mibPerS, 2)} MiB/s ` +
        `over the run (the raw grid makes ${fmt(rec.expectedMiBPerS, 2)} MiB/s; start-up is in the ` +
        `run, not in the file), ${rec.magic ? "starts with the XDF magic" : "**no XDF magic**"}; ` +
        `deleted after this check`,
    );
  }
  if (r.ioFloorPct !== undefined) {
    lines.push(
      `Wake-up floor with the pipeline's output: the same worker, also sending the pipeline's ` +
        `datagrams from a connected socket to a receiver in another process ` +
        `(${fmt(r.ioFloorDatagramsPerS, 1)} datagrams/s arrived) and turning its event loop every ` +
        `50 ms, uses ${fmtPct(r.ioFloorPct)} of one core: what waking this often and sending ` +
        `this much costs here before anything is computed`,
    );
  }
  if (c.threads.length) {
    lines.push(
      `CPU by thread (steady-state mean; wake-ups = voluntary context switches per second): ` +
        c.threads
          .map(
            (t) =>
              `${t.thread} ${fmtPct(t.pct)}${Number.isFinite(t.wakeupsPerS) ? ` (${t.wakeupsPerS.toFixed(0)} wake-ups/s)` : ""}`,
          )
          .join(", "),
    );
  }
  return lines;
}

function timerLine(t: TimerFigures, batchingMs: number): string {
  return (
    `Timer ${t.name} (${t.desiredRate} Hz, batching interval ${fmt(batchingMs, 1)} ms): ${t.fired} ticks fired, ${t.missed} missed after the warm-up; ` +
    `lateness median ${t.latenessP50Us.toFixed(0)} µs, p99 ${t.latenessP99Us.toFixed(0)} µs, max ${t.latenessMaxUs.toFixed(0)} µs`
  );
}

function samplesLostLine(
  r: PipelineResult,
  lost: NonNullable<PipelineResult["samplesLost"]>,
): string {
  return (
    `Samples lost after the warm-up: **${lost.total}** (${lost.missedTicks} ticks missed, ` +
    `${lost.acquisitionDrops} events dropped on the edges out of the acquisition chain: ` +
    `${r.acquisitionChain.join(", ")})`
  );
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

/** In the paper's row order (the runtime lists blocks in creation order), extra blocks last. */
function inPaperOrder(blocks: BlockRow[], paper: PaperRows | undefined): BlockRow[] {
  if (!paper) return blocks;
  const order = Object.keys(paper);
  const rank = (name: string): number => {
    const i = order.indexOf(name);
    return i < 0 ? order.length : i;
  };
  return blocks
    .map((b, i) => ({ b, i }))
    .sort((x, y) => rank(x.b.name) - rank(y.b.name) || x.i - y.i)
    .map((x) => x.b);
}

/** Table 5: timing consistency, compute time and delivery delay; MOSAIC's figures beside. */
function table5(blocks: BlockRow[], paper: PaperRows | undefined): string[] {
  const head = [
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
  if (paper) head.push("MOSAIC: block", "Freq. (Hz)", "Std ΔT (s)");
  const row = (b: BlockRow): string[] => {
    const cells = [
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
      cells.push(p ? p.block : "-", p ? fmt(p.freq, 4) : "-", p ? fmt(p.stdDt, 7) : "-");
    }
    return cells;
  };
  return [
    "Table 5 — timing consistency after the warm-up: ΔT between the timestamps of consecutive " +
      "output events (a tick is stamped with its deadline, so the jitter of waking shows in the " +
      "delivery delay, not in ΔT), compute time per call, and delivery delay (time of processing − " +
      "timestamp of the oldest event of each batch)",
    "",
    ...table(head, blocks.map(row)),
    "",
  ];
}

/** Table 6: the share of the steady state in each status; MOSAIC's shares beside. */
function table6(blocks: BlockRow[], paper: PaperRows | undefined): string[] {
  const head = ["Block", "G (%)", "I (%)", "L (%)", "S (%)", "drops"];
  if (paper) head.push("MOSAIC G / I / L / S (%)");
  const row = (b: BlockRow): string[] => {
    const s = b.shares;
    const cells = [
      b.name,
      fmtShare(s?.ontime),
      fmtShare(s?.idle),
      fmtShare(s?.lagging),
      fmtShare(s?.stumbling),
      String(b.dropsIn),
    ];
    if (paper) {
      const p = paper[b.name];
      cells.push(p ? p.status.map((x) => fmtShare(x)).join(" / ") : "-");
    }
    return cells;
  };
  return [
    "Table 6 — share of the steady state in each status (% of telemetry lines): G on time, I idle, L lagging, S stumbling",
    "",
    ...table(head, blocks.map(row)),
    "",
  ];
}

/** Figures that read oddly and why: more outputs than ticks, blocks without outputs. */
function notes(blocks: BlockRow[]): string[] {
  const out: string[] = [];
  for (const b of blocks) {
    if (b.desiredRate > 0 && b.freq > 1.5 * b.desiredRate) {
      out.push(
        `${b.name} reads ${(b.freq / b.desiredRate).toFixed(1)}× its desired rate: the runtime counts ` +
          "more outputs than ticks (e.g. one per output port).",
      );
    }
    if (b.type !== "Sink" && b.type !== "UdpSender") continue;
    if (b.n === 0 || (b.shares?.idle ?? 0) > 50) {
      out.push(
        `${b.name} (${b.type}) has no outputs: its ΔT and status come from what it consumes; ` +
          "here it has no ΔT or reads mostly idle.",
      );
    }
  }
  return out;
}
