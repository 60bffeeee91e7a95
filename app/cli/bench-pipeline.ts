/**
 * `mosaic bench`: a pipeline workload — `mosaic run … --json` of a pipeline in pipelines/bench/,
 * with the bench's UDP receiver on the Sender's port and, for the loaded variant, a neighbour
 * burning a core; its CPU, memory, Table 5/6 rows, timers, samples lost and UDP figures, and the
 * wake-up floor at its wake-up rate.
 */
import { closeSync, openSync, readFileSync, readSync, rmSync, statSync } from "node:fs";
import { dirname, join, relative, resolve } from "node:path";
import { TrignoSimulator } from "../devices/trigno-simulator";
import type { BlockTelemetry, Telemetry } from "../engine/runtime/runtime";
import { runChild, type ChildRun, type CpuSample, type Summary } from "./bench-proc";
import { clkTck } from "./bench-procfs";
import { BenchReceiver } from "./bench-receiver";
import { measureIoFloor, measureWakeFloor, startNeighbour, wakeRate } from "./bench-side-procs";
import { mean, quantile, std } from "./bench-stats";
import type { BlockRow, CpuFigures, PipelineResult, TimerFigures } from "./bench-types";
import { loadAvg, progress, round, sleep } from "./bench-util";
import type { PipelineDef } from "./bench-workloads";
import { TIERING_ENV } from "../host/tiering";

export interface PipelineRunOptions {
  cli: string;
  root: string;
  warmup: number;
  steady: number;
  useNs: boolean;
  /** `--batching-ms` for this run (the batching sweep). */
  batchingMs?: number;
  /** `--telemetry-hz` for this run (the telemetry sweep). */
  telemetryHz?: number;
  /** false: the run keeps V8's own tier-up thresholds (the tiering sweep; app/host/tiering.ts). */
  v8Tiering?: boolean;
}

/** `inspect` sees the child run before its figures are taken (the soak's own accounting). */
export async function runPipeline(
  def: PipelineDef,
  o: PipelineRunOptions,
  inspect?: (run: ChildRun) => void,
): Promise<PipelineResult> {
  const path = join(o.root, "pipelines", "bench", def.file);
  const file = relative(o.root, path);
  const total = o.warmup + o.steady + 0.5;
  const args = runArgs(def, o, file, total);
  const before = loadAvg();
  progress(
    `${def.id}: ${def.title}${o.batchingMs !== undefined ? `, --batching-ms ${o.batchingMs}` : ""} (${total} s)`,
  );
  const res = notRun(def, o, file, args, before);
  const recording = def.recording ? recordingFile(path) : undefined;
  if (def.recording && !recording) {
    res.error = `${file} records, but no File: param was found in it`;
    return res;
  }
  if (recording) rmSync(recording, { force: true });
  // The device end: bind the Sender's port before the pipeline starts sending.
  let rx: BenchReceiver | undefined;
  try {
    rx = await openReceiver(def, path);
  } catch (e) {
    res.error = (e as Error).message;
    return res;
  }
  const run = await runBeside(def, o, args, total, rx, res);
  inspect?.(run);
  recordRun(res, run);
  if (!run.summary) return res;
  recordSummary(res, run, run.summary, o.useNs);
  if (rx && def.udpRateHz !== undefined) {
    const w = run.windowMs;
    if (Number.isFinite(w.from)) res.udp = rx.figures(w.from, w.to, def.udpRateHz);
  }
  checkRun(res, run, o.warmup);
  if (recording) checkRecording(res, recording, def.recording!.mibPerS, total, o.root);
  return res;
}

/** The file a recording pipeline writes (its `File:` param, relative to the pipeline's folder). */
function recordingFile(pipeline: string): string | undefined {
  const m = /^\s+File:\s*(\S+)/m.exec(readFileSync(pipeline, "utf8"));
  return m ? resolve(dirname(pipeline), m[1]!) : undefined;
}

/**
 * After a recording pipeline's run: the file must exist, start with the XDF magic and hold at
 * least half of what `mibPerS` over the run's `seconds` makes (start-up and the warm-up's first
 * moments are in the run, not in the file); it is deleted either way (117 MiB a run).
 */
function checkRecording(
  res: PipelineResult,
  file: string,
  mibPerS: number,
  seconds: number,
  root: string,
): void {
  let bytes = 0;
  let magic = false;
  try {
    bytes = statSync(file).size;
    const head = Buffer.alloc(4);
    const fd = openSync(file, "r");
    try {
      readSync(fd, head, 0, 4, 0);
    } finally {
      closeSync(fd);
    }
    magic = head.toString("latin1") === "XDF:";
  } catch {
    // missing: reported below
  } finally {
    rmSync(file, { force: true });
  }
  const rate = bytes / 2 ** 20 / seconds;
  res.recording = {
    file: relative(root, file),
    bytes,
    mibPerS: round(rate, 3),
    expectedMiBPerS: round(mibPerS, 3),
    magic,
  };
  if (!res.ok) return;
  if (!magic || rate < mibPerS / 2) {
    res.ok = false;
    res.error = bytes
      ? `the recording ${res.recording.file} is not what the pipeline should write: ${magic ? "" : "no XDF magic, "}${rate.toFixed(2)} MiB/s over the run (${mibPerS.toFixed(2)} expected)`
      : `the recording ${res.recording.file} was not written`;
  }
}

/**
 * After a pipeline workload (not the loaded run, not the sweep): the CPU of a bare worker waking
 * at the pipeline's wake-up rate, the floor the pipeline cannot go below on this machine, and of
 * the same worker sending the datagrams the pipeline sent (per event, at its event rate) to a
 * receiver in this process: the floor with its output.
 */
export async function addWakeFloor(
  def: PipelineDef,
  r: PipelineResult,
  o: { useNs: boolean; quick: boolean },
): Promise<void> {
  const rate = def.wakeHz ?? r.timers[0]?.desiredRate;
  if (!o.useNs || rate === undefined || !(rate > 0) || def.neighbour) return;
  const hz = def.wakeHz ?? wakeRate(rate, r.batchingMs);
  const seconds = o.quick ? 3 : 10;
  progress(
    def.wakeHz !== undefined
      ? `${def.id}: wake-up floor, a bare worker sleeping at ${hz.toFixed(1)} Hz (the device's packets)`
      : `${def.id}: wake-up floor, a bare worker sleeping at ${hz.toFixed(1)} Hz (${rate} Hz ticks, batching ${r.batchingMs} ms)`,
  );
  r.wakeFloorHz = round(hz, 2);
  r.wakeFloorPct = round(await measureWakeFloor(hz, seconds));
  const eventHz = def.udpRateHz;
  const perEvent = r.udp?.perEvent;
  if (eventHz === undefined || perEvent === undefined || !(r.udp!.datagrams > 0)) return;
  progress(
    `${def.id}: wake-up floor with the pipeline's datagrams, ${perEvent} per event at ${eventHz.toFixed(2)} Hz`,
  );
  const io = await measureIoFloor(hz, { eventHz, perEvent }, seconds);
  r.ioFloorPct = round(io.pct);
  r.ioFloorDatagramsPerS = round(io.udp.datagramsPerSecond, 1);
}

function runArgs(def: PipelineDef, o: PipelineRunOptions, file: string, total: number): string[] {
  return [
    "run",
    file,
    "--json",
    "--duration",
    String(total),
    "--warmup",
    String(o.warmup),
    ...(def.extra ?? []),
    ...(o.batchingMs !== undefined ? ["--batching-ms", String(o.batchingMs)] : []),
    ...(o.telemetryHz !== undefined ? ["--telemetry-hz", String(o.telemetryHz)] : []),
  ];
}

/** The result before the run: nothing measured yet (what a run that cannot start reports). */
function notRun(
  def: PipelineDef,
  o: PipelineRunOptions,
  file: string,
  args: string[],
  before: number[],
): PipelineResult {
  return {
    kind: "pipeline",
    id: def.id,
    title: def.title,
    ...(def.paper ? { paper: def.paper } : {}),
    file,
    args,
    ok: false,
    warmupSeconds: o.warmup,
    steadySeconds: o.steady,
    measuredSeconds: NaN,
    cpu: null,
    blocksComputePct: NaN,
    memory: null,
    blocks: [],
    timers: [],
    drops: 0,
    dropsAllTime: 0,
    batchingMs: NaN,
    ...(def.acquisition ? { acquisition: def.acquisition } : {}),
    acquisitionChain: [],
    samplesLost: null,
    acquisitionOnTimePct: NaN,
    telemetryLines: 0,
    loadAvgBefore: before,
    loadAvgAfter: before,
    loadSeconds: NaN,
    lingerSeconds: NaN,
    killedAfterSummary: false,
    warnings: [],
  };
}

/** The receiver on the Sender's port, for a pipeline that sends (rejects when the port is taken). */
async function openReceiver(def: PipelineDef, path: string): Promise<BenchReceiver | undefined> {
  const port = def.udpRateHz !== undefined ? senderPort(path) : undefined;
  return port !== undefined ? BenchReceiver.open(port) : undefined;
}

/** The Sender's destination port as written in the pipeline (`Sender: { … Port: N … }`). */
function senderPort(file: string): number | undefined {
  try {
    const m = /^Sender:.*\bPort:\s*(\d+)/m.exec(readFileSync(file, "utf8"));
    return m ? Number(m[1]) : undefined;
  } catch {
    return undefined;
  }
}

/** The child run, beside the neighbour when the workload has one; the receiver closed after. */
async function runBeside(
  def: PipelineDef,
  o: PipelineRunOptions,
  args: string[],
  total: number,
  rx: BenchReceiver | undefined,
  res: PipelineResult,
): Promise<ChildRun> {
  const neighbour = def.neighbour ? startNeighbour() : undefined;
  let simulator: { close(): Promise<void> } | undefined;
  try {
    if (neighbour) await sleep(200); // let it start spinning
    if (def.simulator) simulator = await startSimulator(def.simulator);
    return await runChild({
      cli: o.cli,
      args,
      cwd: o.root,
      steadySeconds: o.steady,
      warmup: o.warmup > 0,
      timeoutSeconds: total + 60,
      ...(o.v8Tiering === false ? { env: { [TIERING_ENV]: "v8" } } : {}),
    });
  } finally {
    const burnt = neighbour?.stop();
    if (neighbour) res.neighbour = { command: neighbour.command, cpuPct: round(burnt ?? NaN, 1) };
    await simulator?.close();
    await rx?.close();
  }
}

/** The device simulator of a workload, listening before the pipeline starts (16 paired sensors). */
function startSimulator(
  s: NonNullable<PipelineDef["simulator"]>,
): Promise<{ close(): Promise<void> }> {
  return TrignoSimulator.start({
    host: "127.0.0.1",
    commandPort: s.commandPort,
    emgPort: s.emgPort,
    auxPort: s.auxPort,
    sensors: 16,
  });
}

/** What every run reports, with a summary or without. */
function recordRun(res: PipelineResult, run: ChildRun): void {
  res.loadAvgAfter = loadAvg();
  res.ok = run.ok;
  if (run.error) res.error = run.error;
  res.telemetryLines = run.telemetryLines;
  res.loadSeconds = round(run.loadSeconds);
  res.lingerSeconds = round(run.lingerSeconds);
  res.killedAfterSummary = run.killedAfterSummary;
  res.warnings = run.events
    .filter((e) => e.level !== "info")
    .map((e) => `${e.level}: ${e.block}: ${e.message}`);
}

/** The figures of a run that printed its summary. */
function recordSummary(res: PipelineResult, run: ChildRun, s: Summary, useNs: boolean): void {
  res.measuredSeconds = round(s.measuredSeconds);
  res.cpu = cpuFigures(run, useNs);
  const steadyRss = steadySamples(run).map((x) => x.rssKiB / 1024);
  res.memory = {
    peakRssMiB: round(run.peakRssKiB / 1024, 1),
    steadyRssMedianMiB: round(quantile(steadyRss, 0.5), 1),
  };
  res.blocks = blockRows(run, s);
  res.blocksComputePct = round(
    (s.blocks.reduce((acc, b) => acc + (b.timing.computeTotalMs ?? 0), 0) /
      (s.measuredSeconds * 1000)) *
      100,
  );
  const scheduled = s.blocks.filter((b) => b.timer && b.type === "ScheduledTimer");
  res.timers = timerFigures(scheduled, baselineBlocks(run));
  res.batchingMs = scheduled[0]?.timer?.batchingMs ?? NaN;
  res.dropsAllTime = edgeDrops(s);
  res.drops = res.dropsAllTime - edgeDrops(run.baseline);
  // The device's rate: a simulator's is its timer's, a device that paces itself (Delsys over TCP)
  // has its own.
  const device = s.blocks.find((b) => b.name === res.acquisition);
  recordAcquisition(res, run, s, device?.desiredRate || scheduled[0]?.desiredRate);
}

/**
 * The acquisition chain: the blocks at the acquisition block's rate (Timer, the device, its
 * filters); samples are lost when a tick is missed or an edge out of the chain drops.
 */
function recordAcquisition(
  res: PipelineResult,
  run: ChildRun,
  s: Summary,
  acqRate: number | undefined,
): void {
  const chain = s.blocks.filter((b) => acqRate !== undefined && b.desiredRate === acqRate);
  res.acquisitionChain = chain.map((b) => b.name);
  const inChain = new Set(res.acquisitionChain);
  const edges0 = new Map((run.baseline?.edges ?? []).map((e) => [`${e.from}/${e.id}`, e.dropped]));
  const acquisitionDrops = s.edges
    .filter((e) => inChain.has(e.from))
    .reduce((a, e) => a + e.dropped - (edges0.get(`${e.from}/${e.id}`) ?? 0), 0);
  const missedTicks = res.timers.reduce((a, t) => a + t.missed, 0);
  res.samplesLost = { missedTicks, acquisitionDrops, total: missedTicks + acquisitionDrops };
  const shares = res.blocks
    .filter((b) => inChain.has(b.name) && b.shares)
    .map((b) => b.shares!.ontime);
  res.acquisitionOnTimePct = shares.length ? round(Math.min(...shares), 3) : NaN;
}

/** A run that printed a summary is still unusable without its warm-up line or telemetry. */
function checkRun(res: PipelineResult, run: ChildRun, warmup: number): void {
  if (warmup > 0 && !run.baseline) {
    res.ok = false;
    res.error = "no warmup-done line (does `mosaic run` support --warmup?)";
  }
  if (run.telemetryLines === 0 && res.ok) {
    res.ok = false;
    res.error = "no telemetry received during the steady state";
  }
}

const steadySamples = (run: ChildRun): CpuSample[] => run.samples.filter((s) => s.steady);

/** The blocks' telemetry just before the warm-up ended (all-time counters start from it). */
function baselineBlocks(run: ChildRun): Map<string, BlockTelemetry> {
  return new Map((run.baseline?.blocks ?? []).map((b) => [b.name, b]));
}

function cpuFigures(run: ChildRun, useNs: boolean): CpuFigures | null {
  const steady = steadySamples(run);
  if (steady.length === 0) return null;
  const pct = (s: CpuSample): number => (useNs && Number.isFinite(s.nsPct) ? s.nsPct : s.ticksPct);
  const pick = steady.map(pct);
  const ticks = steady.map((s) => s.ticksPct);
  const children = steady.map((s) => s.childrenPct);
  return {
    source: useNs ? "schedstat" : "stat",
    samples: steady.length,
    medianPct: round(quantile(pick, 0.5)),
    p90Pct: round(quantile(pick, 0.9)),
    meanPct: round(mean(pick)),
    stdPct: round(std(pick)),
    ticksMedianPct: round(quantile(ticks, 0.5)),
    ticksMeanPct: round(mean(ticks)),
    childrenMedianPct: round(quantile(children, 0.5)),
    childrenMeanPct: round(mean(children)),
    clkTck: clkTck(),
    threads: run.threads
      .filter((t) => t.pct >= 0.05)
      .map((t) => ({
        thread: t.main ? "main" : `tid ${t.tid}`,
        pct: round(t.pct),
        wakeupsPerS: round(t.voluntaryPerS, 1),
        preemptedPerS: round(t.nonvoluntaryPerS, 1),
      })),
    engineWakeupsPerS: round(run.threads.find((t) => !t.main)?.voluntaryPerS ?? NaN, 1),
    trace: run.samples.map((s) => ({
      t: round(s.t, 2),
      pct: round(pct(s)),
      ticksPct: round(s.ticksPct),
      rssMiB: round(s.rssKiB / 1024, 1),
      steady: s.steady,
    })),
  };
}

/** Table 5 and 6 rows: timing, compute, delay and status shares of each block. */
function blockRows(run: ChildRun, s: Summary): BlockRow[] {
  const base = baselineBlocks(run);
  const n = run.telemetryLines;
  return s.blocks.map((b) => {
    const c = run.statusCounts.get(b.name);
    const tm = b.timing;
    const meanDt = tm.meanDt ?? NaN;
    return {
      name: b.name,
      type: b.type,
      desiredRate: b.desiredRate,
      n: tm.n,
      meanDt,
      freq: meanDt > 0 ? 1 / meanDt : NaN,
      stdDt: tm.stdDt ?? NaN,
      computeMeanUs: tm.calls > 0 ? (tm.computeTotalMs / tm.calls) * 1000 : NaN,
      calls: tm.calls,
      dropsIn: b.dropsIn - (base.get(b.name)?.dropsIn ?? 0),
      delay: b.delay
        ? {
            p50Ms: round(b.delay.p50Ms, 4),
            p99Ms: round(b.delay.p99Ms, 4),
            maxMs: round(b.delay.maxMs, 3),
            n: b.delay.n,
          }
        : null,
      ...(b.text ? { text: b.text } : {}),
      shares:
        c && n > 0
          ? {
              ontime: (c.ontime / n) * 100,
              idle: (c.idle / n) * 100,
              lagging: (c.lagging / n) * 100,
              stumbling: (c.stumbling / n) * 100,
            }
          : null,
    };
  });
}

/** The ScheduledTimers' ticks since the warm-up and their lateness. */
function timerFigures(
  scheduled: BlockTelemetry[],
  baseline: Map<string, BlockTelemetry>,
): TimerFigures[] {
  return scheduled.map((b) => {
    const t = b.timer!;
    const b0 = baseline.get(b.name)?.timer;
    return {
      name: b.name,
      desiredRate: b.desiredRate,
      fired: t.fired - (b0?.fired ?? 0),
      missed: t.missed - (b0?.missed ?? 0),
      latenessP50Us: t.latenessP50Us,
      latenessP99Us: t.latenessP99Us,
      latenessMaxUs: round(t.latenessMaxUs, 1),
    };
  });
}

function edgeDrops(t: Telemetry | undefined): number {
  return (t?.edges ?? []).reduce((s, e) => s + e.dropped, 0);
}
