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
  o: Omit<PipelineRunOptions, "batchingMs" | "telemetryHz" | "v8Tiering">,
): Promise<BatchingResult> {
  const before = loadAvg();
  const rows: BatchingRow[] = [];
  for (const id of def.pipelines) {
    const p = pipelineDef(id);
    if (!p) continue;
    for (const v of sweepVariants(def)) {
      const r = await runPipeline(p, { ...o, ...v });
      const row = sweepRow(p, v.batchingMs, v.telemetryHz ?? DEFAULT_TELEMETRY_HZ, r);
      if (v.v8Tiering !== undefined) row.v8Tiering = v.v8Tiering;
      rows.push(row);
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
    ...(def.v8Tiering ? { v8Tiering: def.v8Tiering } : {}),
    rows,
    loadAvgBefore: before,
    loadAvgAfter: loadAvg(),
    killedAfterSummary: false,
  };
}

interface SweepVariant {
  batchingMs: number;
  telemetryHz?: number;
  v8Tiering?: boolean;
}

/** The runs of a sweep for one pipeline, in order: each interval × telemetry rate × tiering. */
export function sweepVariants(def: BatchingDef): SweepVariant[] {
  const out: SweepVariant[] = [];
  for (const batchingMs of def.intervalsMs) {
    for (const hz of def.telemetryHz ?? [undefined]) {
      for (const tiering of def.v8Tiering ?? [undefined]) {
        out.push({
          batchingMs,
          ...(hz !== undefined ? { telemetryHz: hz } : {}),
          ...(tiering !== undefined ? { v8Tiering: tiering } : {}),
        });
      }
    }
  }
  return out;
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
