/**
 * `mosaic bench`: the workloads measured in the bench's own process — the learning kernels'
 * micro-benchmark and the loopback UDP latency (app/cli/bench-udp.ts).
 */
import { join } from "node:path";
import type { LearnResult, UdpResult } from "./bench-types";
import { loadAvg, progress, round } from "./bench-util";
import type { LearnDef, UdpDef } from "./bench-workloads";

/**
 * The learning micro-benchmark, in this process: ns per incremental update (with its prediction)
 * and per prediction, through the WASM bindings the IncrementalPredictor uses.
 */
export async function runLearn(def: LearnDef, o: { quick: boolean }): Promise<LearnResult> {
  const before = loadAvg();
  const secondsPerFigure = o.quick ? 0.1 : 0.5;
  progress(`${def.id}: ridge and RFF at D = ${def.dims.join(", ")}, ${secondsPerFigure} s each`);
  const res: LearnResult = {
    kind: "learn",
    id: def.id,
    title: def.title,
    ok: true,
    secondsPerFigure,
    figures: [],
    loadAvgBefore: before,
    loadAvgAfter: before,
    killedAfterSummary: false,
  };
  try {
    const { loadDspFromDisk } = await import("../host/validate");
    const { benchLearning } = await import("../engine/dsp");
    loadDspFromDisk();
    res.figures = benchLearning(() => performance.now(), {
      dims: def.dims,
      outputs: def.outputs,
      seconds: secondsPerFigure,
    }).map((f) => ({ ...f, updateNs: round(f.updateNs, 1), predictNs: round(f.predictNs, 1) }));
  } catch (e) {
    res.ok = false;
    res.error = (e as Error).message;
  }
  res.loadAvgAfter = loadAvg();
  return res;
}

/** Loopback UDP latency through a small pipeline on one worker (app/cli/bench-udp.ts). */
export async function runUdp(def: UdpDef, o: { quick: boolean; root: string }): Promise<UdpResult> {
  const before = loadAvg();
  const samples = o.quick ? 500 : 5000;
  progress(`${def.id}: ${samples} datagrams at 500 Hz, timer branch ${def.timerHz} Hz`);
  const base = {
    kind: "udp" as const,
    id: def.id,
    title: def.title,
    loadAvgBefore: before,
    killedAfterSummary: false as const,
  };
  try {
    const { measureUdpLatency } = await import("./bench-udp");
    // (the module is bundled into the CLI; the dynamic import keeps the call site obvious)
    const r = await measureUdpLatency({
      samples,
      rate: 500,
      timerHz: def.timerHz,
      batchingMs: 0,
      workerPath: join(o.root, "dist", "engine.worker.mjs"),
      wasmPath: join(o.root, "core-wasm", "pkg", "mosaic_core_bg.wasm"),
    });
    return { ...base, ok: true, ...r, loadAvgAfter: loadAvg() };
  } catch (e) {
    return {
      ...base,
      ok: false,
      error: (e as Error).message,
      samples,
      received: 0,
      lost: 0,
      rate: 500,
      channels: 8,
      timerHz: def.timerHz,
      batchingMs: 0,
      p50Ms: NaN,
      p90Ms: NaN,
      p99Ms: NaN,
      maxMs: NaN,
      meanMs: NaN,
      inP50Ms: NaN,
      inP99Ms: NaN,
      outP50Ms: NaN,
      outP99Ms: NaN,
      loadAvgAfter: loadAvg(),
    };
  }
}
