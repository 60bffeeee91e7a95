/**
 * `mosaic bench`: the standard performance suite (DESIGN.md §6), measured like the paper's
 * section V. Every workload runs the real product, `mosaic run … --json`, as a child process
 * (the bundled dist/cli.mjs next to this bundle) and is measured from outside: CPU and memory from
 * /proc once a second, timing (the paper's Table 5) and status shares (Table 6) from the child's
 * JSON lines. Prints Markdown tables as workloads finish and writes bench/results/latest.json and
 * latest.md. See bench/README.md.
 */
import { existsSync, mkdtempSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { dirname, join, relative, resolve } from "node:path";
import { runBatching } from "./bench-batching";
import { load } from "./bench-format";
import { runLearn, runUdp } from "./bench-inproc";
import { findCli, findRoot, machineInfo, type Machine } from "./bench-machine";
import { parseBenchOptions, type BenchOptions } from "./bench-options";
import { addWakeFloor, runPipeline } from "./bench-pipeline";
import { schedstatAvailable } from "./bench-procfs";
import { runReplay } from "./bench-replay";
import { runSoak } from "./bench-soak";
import { targetsTable, workloadMarkdown } from "./bench-report";
import { resultsDocument, writeResults } from "./bench-results";
import { targets } from "./bench-targets";
import type { TargetRow, WorkloadResult } from "./bench-types";
import { loadAvg, out, progress, round } from "./bench-util";
import type { WorkloadDef } from "./bench-workloads";

/** The batching sweep compares intervals with one another: a shorter warm-up does. */
const SWEEP_WARMUP_S = 15;

/** What every workload of a suite shares. */
interface Suite {
  opts: BenchOptions;
  cli: string;
  root: string;
  useNs: boolean;
  /** A temporary folder for the replays' recordings, made on first use. */
  tmp: () => string;
}

export async function runBench(argv: string[]): Promise<number> {
  const opts = parseBenchOptions(argv);
  if ("exit" in opts) return opts.exit;
  const cli = findCli();
  if (!existsSync(cli)) {
    process.stderr.write(`mosaic bench: ${cli} not found; run node scripts/build-ts.mjs first\n`);
    return 1;
  }
  const root = findRoot(dirname(cli));
  const outDir = opts.out !== undefined ? resolve(opts.out) : join(root, "bench", "results");
  const useNs = schedstatAvailable();
  const started = new Date();
  const t0 = performance.now();
  const machine = machineInfo(root, useNs);
  printHeader(opts, started, machine);
  const results = await runWorkloads(opts, cli, root, useNs);
  machine.loadAvgAfter = loadAvg();
  const rows = targets(results);
  const seconds = round((performance.now() - t0) / 1000, 1);
  printTargets(rows);
  const doc = resultsDocument({ started, seconds, opts, machine, targets: rows, results });
  writeResults(outDir, doc);
  progress(
    `done in ${seconds} s; wrote ${relative(process.cwd(), join(outDir, "latest.json"))} and latest.md`,
  );
  return results.every((r) => r.ok) ? 0 : 1;
}

function printHeader(opts: BenchOptions, started: Date, machine: Machine): void {
  out(`# MOSAIC benchmark (${opts.quick ? "quick" : "full"})`);
  out();
  out(
    `${started.toISOString()} · commit ${machine.gitCommit?.slice(0, 12) ?? "unknown"}${machine.gitDirty ? " (uncommitted changes)" : ""} · ` +
      `Node ${machine.node} · ${machine.cpuModel}, ${machine.cores} cores · load average ${load(machine.loadAvgBefore)}`,
  );
  out();
}

function printTargets(rows: TargetRow[]): void {
  out("## Targets (DESIGN.md §6)");
  out();
  for (const l of targetsTable(rows)) out(l);
  out();
}

/** Runs the selected workloads in order, printing each one's tables as it finishes. */
async function runWorkloads(
  opts: BenchOptions,
  cli: string,
  root: string,
  useNs: boolean,
): Promise<WorkloadResult[]> {
  let tmp: string | undefined;
  const suite: Suite = {
    opts,
    cli,
    root,
    useNs,
    tmp: () => (tmp ??= mkdtempSync(join(tmpdir(), "mosaic-bench-"))),
  };
  const results: WorkloadResult[] = [];
  try {
    for (const def of opts.selected) {
      const r = await runWorkload(def, suite);
      results.push(r);
      for (const l of workloadMarkdown(r)) out(l);
    }
  } finally {
    if (tmp) rmSync(tmp, { recursive: true, force: true });
  }
  return results;
}

/** Half the steady state, at least 2 s: the timer workloads and each run of the sweep. */
const halfSteady = (steady: number): number => Math.max(2, Math.ceil(steady / 2));

async function runWorkload(def: WorkloadDef, s: Suite): Promise<WorkloadResult> {
  const { quick, warmup, steady } = s.opts;
  const { cli, root, useNs } = s;
  switch (def.kind) {
    case "pipeline": {
      const o = { cli, root, warmup, steady: def.short ? halfSteady(steady) : steady, useNs };
      const r = await runPipeline(def, o);
      await addWakeFloor(def, r, { useNs, quick });
      return r;
    }
    case "batching":
      return runBatching(def, {
        cli,
        root,
        // Relative figures: a shorter warm-up keeps the ten runs of the sweep near 5 minutes.
        warmup: Math.min(warmup, SWEEP_WARMUP_S),
        steady: halfSteady(steady),
        useNs,
      });
    case "learn":
      return runLearn(def, { quick });
    case "udp":
      return runUdp(def, { quick, root });
    case "replay":
      return runReplay(def, { cli, root, tmp: s.tmp(), quick, targetWall: quick ? 1 : 6 });
    case "soak":
      // Its own length (30 min) unless --duration or --quick says otherwise.
      return runSoak(def, {
        cli,
        root,
        warmup,
        steady: s.opts.durationGiven || quick ? steady : def.steadySeconds,
        useNs,
      });
  }
}
