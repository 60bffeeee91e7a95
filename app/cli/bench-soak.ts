/**
 * `mosaic bench --only soak`: one long real-time run of a pipeline with the Python sidecar and a
 * UDP sender (pipelines/bench/python-cnn.yaml: the Delsys acquisition, an ONNX CNN in Python,
 * control, the Sender), measured as any pipeline workload (bench-pipeline.ts, with the bench's
 * receiver on the Sender's port), and then checked for what a long run must not do:
 * - memory: VmRSS of the `mosaic run` process at the start and the end of the steady state, and
 *   its maximum; after it settled (V8 sizing its heaps: a third of the run, at most 10 minutes,
 *   `rssFigures`), flat when the median of its last minute (a tenth of a shorter run) is within
 *   ±tolerance (5 %) of the median of its first (single samples swing with garbage collection:
 *   ±3 % within seconds);
 * - datagrams: every datagram the Sender handed to its socket arrived at the receiver or is
 *   counted as not sent in its status (`N datagrams sent, M not sent`): sent − received = 0;
 * - errors: every error is counted — the blocks' error counts (the summary), the error events
 *   printed and the exit code (1 exactly when a block counted one) agree; the engine's own
 *   counted losses (edge drops, missed ticks) are reported beside them.
 * Its length is the workload's 30 minutes unless `--duration` says otherwise (`--quick`: 3 s).
 */
import type { ChildRun } from "./bench-proc";
import { fmt, load, section, table } from "./bench-format";
import { runPipeline } from "./bench-pipeline";
import type { PipelineResult, SoakResult } from "./bench-types";
import { quantile } from "./bench-stats";
import { loadAvg, round } from "./bench-util";
import type { PipelineDef, SoakDef } from "./bench-workloads";

export interface SoakOptions {
  cli: string;
  root: string;
  warmup: number;
  steady: number;
  useNs: boolean;
}

/** The Sender's counts in its status text: "…: 1,234 datagrams sent, 5 not sent (reason)". */
export function senderCounts(
  text: string | undefined,
): { sent: number; notSent: number; reason: string } | null {
  const m = /: ([\d,]+) datagrams? sent(?:, ([\d,]+) not sent \((.*)\))?$/.exec(text ?? "");
  if (!m) return null;
  const num = (s: string | undefined): number => Number((s ?? "0").replace(/,/g, ""));
  return { sent: num(m[1]), notSent: num(m[2]), reason: m[3] ?? "" };
}

export async function runSoak(def: SoakDef, o: SoakOptions): Promise<SoakResult> {
  const before = loadAvg();
  const pdef: PipelineDef = {
    kind: "pipeline",
    id: def.id,
    title: def.title,
    file: def.file,
    acquisition: def.acquisition,
    udpRateHz: def.udpRateHz,
  };
  let child: ChildRun | undefined;
  const run = await runPipeline(pdef, { ...o }, (r) => (child = r));
  return soakFigures(def, o, run, child, before);
}

/**
 * Memory over the steady state (1-s VmRSS samples, MiB). The process grows while V8 sizes its
 * heaps to the run's allocation rate (the 30-minute soak of 2026-11-24: 82 → 88 MiB over its
 * first 7 minutes, then 86–89 MiB for the remaining 23), so the drift is judged after a third of
 * the run, at most MEMORY_SETTLE_S: the median of the first minute after it (a tenth of what is
 * left, for a shorter run) against the median of the last, and that slope carried over the whole
 * run must stay within the tolerance (a steady leak of 8 % per run fails though only part of it
 * is seen after settling). The growth while settling is reported beside the drift.
 */
export function rssFigures(rssMiB: number[], tolerancePct: number): NonNullable<SoakResult["rss"]> {
  const settleSamples = Math.min(MEMORY_SETTLE_S, Math.floor(rssMiB.length / 3));
  const settled = rssMiB.slice(settleSamples);
  const w = Math.max(1, Math.min(60, Math.floor(settled.length / 10)));
  const first = quantile(settled.slice(0, w), 0.5);
  const last = quantile(settled.slice(-w), 0.5);
  const start = rssMiB[0]!;
  const max = Math.max(...settled);
  const driftPct = ((last - first) / first) * 100;
  // The same slope over the whole run: a leak that grew while memory settled counts in full.
  const span = Math.max(1, settled.length - w);
  const runDriftPct = (driftPct * rssMiB.length) / span;
  return {
    samples: rssMiB.length,
    startMiB: round(start, 1),
    endMiB: round(rssMiB[rssMiB.length - 1]!, 1),
    maxMiB: round(Math.max(...rssMiB), 1),
    minMiB: round(Math.min(...rssMiB), 1),
    settleSamples,
    settleGrowthPct: round(((first - start) / start) * 100, 2),
    windowSamples: w,
    firstMedianMiB: round(first, 1),
    lastMedianMiB: round(last, 1),
    driftPct: round(driftPct, 2),
    runDriftPct: round(runDriftPct, 2),
    maxOverStartPct: round(((max - first) / first) * 100, 2),
    tolerancePct,
    flat: Math.abs(runDriftPct) <= tolerancePct,
  };
}

/** The longest the soak lets memory settle before it judges the drift, s. */
export const MEMORY_SETTLE_S = 600;

/** The soak's checks from the run (pure: tested on a recorded run). */
export function soakFigures(
  def: SoakDef,
  o: Pick<SoakOptions, "warmup" | "steady">,
  run: PipelineResult,
  child: ChildRun | undefined,
  before: number[],
): SoakResult {
  // Each check adds its failures in turn: memory, the sidecar's, datagrams, errors.
  const failures: string[] = [];
  const rss = engineMemoryCheck(child, def.memoryTolerancePct, failures);
  const sidecarRss = sidecarMemoryCheck(child, def.memoryTolerancePct, failures);
  const udp = datagramCheck(run, child, failures);
  const errors = errorCheck(child, failures);
  const missedTicks = run.timers.reduce((a, t) => a + t.missed, 0);
  if (!child?.summary) failures.push(run.error ?? "the run printed no summary");
  return {
    kind: "soak",
    id: def.id,
    title: def.title,
    ok: child?.summary !== undefined,
    ...(run.error ? { error: run.error } : {}),
    pass: failures.length === 0,
    failures,
    warmupSeconds: o.warmup,
    steadySeconds: o.steady,
    rss,
    sidecarRss,
    udp,
    drops: { edges: run.dropsAllTime, missedTicks },
    errors,
    run,
    loadAvgBefore: before,
    loadAvgAfter: loadAvg(),
    killedAfterSummary: run.killedAfterSummary,
  };
}

/** The run's 1-s samples in the steady state. */
function steadySamples(child: ChildRun | undefined): ChildRun["samples"] {
  return (child?.samples ?? []).filter((s) => s.steady);
}

/** Memory of the `mosaic run` process over the steady state: flat within the tolerance. */
function engineMemoryCheck(
  child: ChildRun | undefined,
  tolerancePct: number,
  failures: string[],
): SoakResult["rss"] {
  const rssMiB = steadySamples(child).map((s) => s.rssKiB / 1024);
  if (rssMiB.length === 0) {
    failures.push("no memory samples in the steady state");
    return null;
  }
  const rss = rssFigures(rssMiB, tolerancePct);
  if (!rss.flat) {
    failures.push(
      `VmRSS moved beyond ±${rss.tolerancePct} % over the run: median ${rss.firstMedianMiB} MiB over the first ${rss.windowSamples} s after ${rss.settleSamples} s of settling, ${rss.lastMedianMiB} over the last (${rss.driftPct} %, ${rss.runDriftPct} % at that slope over the whole run)`,
    );
  }
  return rss;
}

/** The sidecar's memory (its own process, beside the engine's): start to end within the tolerance. */
function sidecarMemoryCheck(
  child: ChildRun | undefined,
  tolerancePct: number,
  failures: string[],
): SoakResult["sidecarRss"] {
  const side = steadySamples(child).map((s) => s.childrenRssKiB / 1024);
  if (!(side.length > 0 && side[0]! > 0)) return null;
  const start = side[0]!;
  const end = side[side.length - 1]!;
  const max = Math.max(...side);
  const sidecarRss = {
    startMiB: round(start, 1),
    endMiB: round(end, 1),
    maxMiB: round(max, 1),
    driftPct: round(((end - start) / start) * 100, 2),
  };
  if (Math.abs(sidecarRss.driftPct) > tolerancePct) {
    failures.push(
      `the Python sidecar's VmRSS moved beyond ±${tolerancePct} %: ${sidecarRss.startMiB} → ${sidecarRss.endMiB} MiB`,
    );
  }
  return sidecarRss;
}

/** Datagrams: the Sender's own counts against what arrived. */
function datagramCheck(
  run: PipelineResult,
  child: ChildRun | undefined,
  failures: string[],
): SoakResult["udp"] {
  const sender = child?.summary?.blocks.find((b) => b.type === "UdpSender");
  const counts = senderCounts(sender?.text);
  const received = (run.udp?.datagramsAll ?? 0) + (run.udp?.malformed ?? 0);
  const uncounted = counts ? counts.sent - received : null;
  if (counts === null)
    failures.push(`the Sender's status gives no counts: '${sender?.text ?? ""}'`);
  else if (uncounted !== 0) {
    failures.push(`${uncounted} datagrams the Sender counts as sent did not arrive`);
  }
  return {
    sent: counts?.sent ?? null,
    notSent: counts?.notSent ?? null,
    notSentReason: counts?.reason ?? "",
    received,
    malformed: run.udp?.malformed ?? 0,
    uncounted,
  };
}

/** Errors: counted by the blocks, printed as events, and the exit code, which must agree. */
function errorCheck(child: ChildRun | undefined, failures: string[]): SoakResult["errors"] {
  const blocks = (child?.summary?.blocks ?? [])
    .filter((b) => b.errors > 0)
    .map((b) => ({ name: b.name, errors: b.errors, lastError: b.lastError }));
  const total = blocks.reduce((a, b) => a + b.errors, 0);
  const events = child?.eventsByLevel ?? {};
  const exitCode = child?.summary?.exitCode ?? child?.exitCode ?? null;
  const consistent = exitCode === (total > 0 || (events.error ?? 0) > 0 ? 1 : 0);
  if (!consistent) {
    failures.push(
      `errors not accounted for: ${total} counted by blocks, ${events.error ?? 0} error events, exit code ${exitCode}`,
    );
  }
  if (total > 0) failures.push(`${total} block errors (${blocks.map((b) => b.name).join(", ")})`);
  return { total, blocks, events, exitCode, consistent };
}

/** The soak's section: the checks, then the figures of its pipeline run in one table. */
export function soakMarkdown(r: SoakResult, heading = "##"): string[] {
  const lines = [...section(heading, r.title)];
  if (!r.ok) return [...lines, `**Failed:** ${r.error ?? "no summary"}`, ""];
  const m = r.rss;
  const u = r.udp;
  const e = r.errors;
  const cpu = r.run.cpu;
  const rows: string[][] = [
    [
      "duration",
      `${r.steadySeconds} s steady state after ${r.warmupSeconds} s warm-up (load ${load(r.loadAvgBefore)} → ${load(r.loadAvgAfter)})`,
      "",
    ],
    [
      "VmRSS start / end / max (steady state)",
      m
        ? `${fmt(m.startMiB, 1)} / ${fmt(m.endMiB, 1)} / ${fmt(m.maxMiB, 1)} MiB (${m.samples} samples); settling ${m.settleSamples} s (${fmt(m.settleGrowthPct, 2)} %), then median of the first / last ${m.windowSamples} s ${fmt(m.firstMedianMiB, 1)} / ${fmt(m.lastMedianMiB, 1)} MiB: drift ${fmt(m.driftPct, 2)} % (${fmt(m.runDriftPct, 2)} % over the whole run at that slope), max ${fmt(m.maxOverStartPct, 2)} % over the first`
        : "—",
      m ? (m.flat ? `flat within ±${m.tolerancePct} %` : "**NOT FLAT**") : "**no samples**",
    ],
    [
      "Python sidecar VmRSS start / end / max",
      r.sidecarRss
        ? `${fmt(r.sidecarRss.startMiB, 1)} / ${fmt(r.sidecarRss.endMiB, 1)} / ${fmt(r.sidecarRss.maxMiB, 1)} MiB (drift ${fmt(r.sidecarRss.driftPct, 2)} %)`
        : "—",
      "",
    ],
    [
      "UDP datagrams sent / received / not sent (counted) / uncounted",
      `${u.sent ?? "?"} / ${u.received} / ${u.notSent ?? "?"}${u.notSentReason ? ` (${u.notSentReason})` : ""} / ${u.uncounted ?? "?"}`,
      u.uncounted === 0 ? "none uncounted" : "**UNCOUNTED**",
    ],
    [
      "losses the engine counted",
      `${r.drops.edges} events dropped on edges, ${r.drops.missedTicks} ticks missed`,
      "",
    ],
    [
      "errors counted by blocks / error events / warnings / exit code",
      `${e.total}${e.blocks.length ? ` (${e.blocks.map((b) => `${b.name} ${b.errors}: ${b.lastError}`).join("; ")})` : ""} / ${e.events.error ?? 0} / ${e.events.warning ?? 0} / ${e.exitCode ?? "?"}`,
      e.consistent ? "consistent" : "**INCONSISTENT**",
    ],
    [
      "CPU median (engine process; Python sidecar)",
      cpu ? `${fmt(cpu.medianPct, 1)} % ; ${fmt(cpu.childrenMedianPct, 1)} %` : "—",
      "",
    ],
    ["acquisition chain on time (lowest share)", `${fmt(r.run.acquisitionOnTimePct, 1)} %`, ""],
  ];
  lines.push(...table(["figure", "measured", "check"], rows), "");
  lines.push(r.pass ? "**Soak passed.**" : `**Soak failed:** ${r.failures.join("; ")}.`, "");
  return lines;
}
