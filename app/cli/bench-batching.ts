/**
 * `mosaic bench`: the batching sweep — each of its pipelines at each `--batching-ms` (and each
 * `--telemetry-hz` of the telemetry sweep), shorter runs, the figures side by side (CPU, engine
 * wake-ups, delivery delay, UDP rate, samples lost).
 */
import { runPipeline, type PipelineRunOptions } from "./bench-pipeline";
import type { BatchingResult, BatchingRow, PipelineResult } from "./bench-types";
import { DEFAULT_TELEMETRY_HZ } from "../host/worker-protocol";
import { loadAvg, round } from "./bench-util";
import { pipelineDef, type BatchingDef, type PipelineDef } from "./bench-workloads";

export async function runBatching(
  def: BatchingDef,
  o: Omit<PipelineRunOptions, "batchingMs" | "telemetryHz">,
): Promise<BatchingResult> {
  const before = loadAvg();
  const rows: BatchingRow[] = [];
  for (const id of def.pipelines) {
    const p = pipelineDef(id);
    if (!p) continue;
    for (const ms of def.intervalsMs) {
      for (const hz of def.telemetryHz ?? [undefined]) {
        const r = await runPipeline(p, { ...o, batchingMs: ms, telemetryHz: hz });
        rows.push(sweepRow(p, ms, hz ?? DEFAULT_TELEMETRY_HZ, r));
      }
    }
  }
  const failed = rows.filter((r) => !r.ok);
  return {
    kind: "batching",
    id: def.id,
    title: def.title,
    ok: rows.length > 0 && failed.length === 0,
    ...(failed.length
      ? { error: `${failed.length} of ${rows.length} runs failed: ${failed[0]!.error ?? "?"}` }
      : {}),
    warmupSeconds: o.warmup,
    steadySeconds: o.steady,
    intervalsMs: def.intervalsMs,
    ...(def.telemetryHz ? { telemetryHz: def.telemetryHz } : {}),
    rows,
    loadAvgBefore: before,
    loadAvgAfter: loadAvg(),
    killedAfterSummary: false,
  };
}

/**
 * The sweep's row for pipeline `p` run at `ms` with telemetry at `hz`; a run at another interval
 * than asked fails.
 */
function sweepRow(p: PipelineDef, ms: number, hz: number, r: PipelineResult): BatchingRow {
  const sender = r.blocks.find((b) => b.name === "Sender")?.delay ?? null;
  const acq = r.blocks.find((b) => b.name === p.acquisition)?.delay ?? null;
  const row: BatchingRow = {
    pipeline: p.id,
    batchingMs: ms,
    telemetryHz: hz,
    ok: r.ok,
    ...(r.error ? { error: r.error } : {}),
    cpuMedianPct: r.cpu?.medianPct ?? NaN,
    engineWakeupsPerS: r.cpu?.engineWakeupsPerS ?? NaN,
    sender: sender ? { p50Ms: sender.p50Ms, p99Ms: sender.p99Ms, maxMs: sender.maxMs } : null,
    acquisition: acq
      ? { name: p.acquisition!, p50Ms: acq.p50Ms, p99Ms: acq.p99Ms, maxMs: acq.maxMs }
      : null,
    udpRateHz: round(r.udp?.rateHz ?? NaN, 4),
    samplesLost: r.samplesLost?.total ?? null,
    loadAvgBefore: r.loadAvgBefore,
  };
  if (r.ok && r.batchingMs !== ms) {
    row.ok = false;
    row.error = `the run reported a batching interval of ${r.batchingMs} ms`;
  }
  return row;
}
