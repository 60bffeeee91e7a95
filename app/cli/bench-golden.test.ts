/**
 * The bench's report, byte for byte: the Markdown (latest.md and the tables printed as workloads
 * finish) and the targets rendered from fixed results. bench-fixture.json is the latest.json of a
 * `mosaic bench --quick --only myo,delsys-loaded,timer,replay-32,learn,udp,batching` run, kept as
 * it was written (machine, load averages, commit); bench-fixture.md.txt is the latest.md that run
 * wrote, re-rendered once by the report code when the sweep's table got its telemetry column. The variants change the fixture to reach the branches a quick run does not (failures,
 * workloads not run, a Python block, a lingering child, …); their expected text,
 * bench-fixture-variants.md.txt, was written by the report code before it was split into modules.
 * Regenerate it only for an intended change of the output: BENCH_GOLDEN_WRITE=1 npx vitest run
 * app/cli/bench-golden.test.ts, then review the diff.
 */
import { readFileSync, writeFileSync } from "node:fs";
import { describe, expect, test } from "vitest";
import { findings, latestMarkdown, notMeasured, type BenchDocument } from "./bench-results";
import { workloadMarkdown } from "./bench-report";
import { targets } from "./bench-targets";
import type {
  BatchingResult,
  LearnResult,
  PipelineResult,
  ReplayResult,
  UdpResult,
  WorkloadResult,
} from "./bench-types";

const here = (name: string): URL => new URL(name, import.meta.url);
const fixture = (): BenchDocument =>
  JSON.parse(readFileSync(here("bench-fixture.json"), "utf8")) as BenchDocument;

/** What `mosaic bench` derives from the results for latest.json. */
function document(d: BenchDocument, results: WorkloadResult[]): BenchDocument {
  const rows = targets(results);
  return {
    ...d,
    targets: rows,
    notMeasured: notMeasured(rows),
    findings: findings(results),
    workloads: results,
  };
}

/** The tables `mosaic bench` prints on stdout as each workload finishes. */
function printed(results: WorkloadResult[]): string[] {
  return results.flatMap(workloadMarkdown);
}

function render(d: BenchDocument): string {
  return (
    [
      latestMarkdown(d),
      "<!-- stdout -->",
      ...printed(d.workloads),
      "<!-- targets -->",
      JSON.stringify(d.targets, null, 2),
    ].join("\n") + "\n"
  );
}

function byId<K extends WorkloadResult["kind"]>(
  d: BenchDocument,
  kind: K,
  id: string,
): Extract<WorkloadResult, { kind: K }> {
  const r = d.workloads.find((w) => w.id === id && w.kind === kind);
  if (!r) throw new Error(`fixture has no ${kind} '${id}'`);
  return structuredClone(r) as Extract<WorkloadResult, { kind: K }>;
}

/** Every workload, with failures and the rarer lines (a full run on a bad day). */
function everything(d: BenchDocument): BenchDocument {
  const myo = byId(d, "pipeline", "myo");
  const loaded = byId(d, "pipeline", "delsys-loaded");
  const delsys: PipelineResult = {
    ...structuredClone(loaded),
    id: "delsys",
    title: "(b) Delsys pipeline — 32 ch @ 1926 Hz",
    wakeFloorHz: 481.5,
    wakeFloorPct: 0.812,
    ioFloorPct: 1.204,
    ioFloorDatagramsPerS: 75.1,
    recording: {
      file: "bench/results/delsys.xdf.tmp",
      bytes: 12_582_912,
      mibPerS: 1.9,
      expectedMiBPerS: 2,
      magic: false,
    },
    warnings: ["warning: Sender: port busy", "error: Control: out of range"],
    killedAfterSummary: true,
  };
  delete delsys.neighbour;
  delsys.cpu!.childrenMeanPct = 12.5;
  delsys.cpu!.childrenMedianPct = 11.25;
  delsys.cpu!.threads[0]!.wakeupsPerS = NaN;
  delsys.udp = {
    ...delsys.udp!,
    malformed: 2,
    firstMalformed: "short datagram",
    rateErrorPct: -0.2,
  };
  delsys.blocks.push(
    {
      ...structuredClone(delsys.blocks[0]!),
      name: "Model",
      type: "Python",
      text: "1.20 ms round trip, 0.40 ms in Python",
    },
    { ...structuredClone(delsys.blocks[0]!), name: "Twice", freq: 4000 },
    { ...structuredClone(delsys.blocks[0]!), name: "Out", type: "Sink", n: 0 },
  );
  delete loaded.udp;
  loaded.samplesLost = { missedTicks: 3, acquisitionDrops: 4, total: 7 };
  const hdemg: PipelineResult = {
    ...structuredClone(myo),
    id: "hdemg",
    title: "(c) High-density EMG",
    ok: false,
    error: "no summary within 60 s; terminated",
  };
  const timer = byId(d, "pipeline", "timer");
  const precision: PipelineResult = {
    ...structuredClone(timer),
    id: "timer-precision",
    title: "Timer at 2 kHz, --precision, batching interval 0",
    cpu: null,
    memory: null,
    samplesLost: null,
  };
  const replay = byId(d, "replay", "replay-32");
  replay.calibration = { virtualSeconds: 160, wallSeconds: 0.5, channelSamplesPerSecond: 9.9e6 };
  const replay256: ReplayResult = {
    ...structuredClone(replay),
    id: "replay-256",
    title: "Replay 256 ch @ 2048 Hz",
    channels: 256,
    rate: 2048,
    ok: false,
    error: "run stopped: error",
  };
  const learn = byId(d, "learn", "learn");
  const udp: UdpResult = { ...byId(d, "udp", "udp"), ok: false };
  const batching = byId(d, "batching", "batching");
  batching.rows[1] = {
    ...batching.rows[1]!,
    ok: false,
    error: "the run reported a batching interval of 5 ms",
  };
  batching.rows[2] = { ...batching.rows[2]!, sender: null, acquisition: null, samplesLost: null };
  const results: WorkloadResult[] = [
    myo,
    delsys,
    loaded,
    hdemg,
    timer,
    precision,
    replay,
    replay256,
    learn,
    udp,
    batching,
  ];
  return document(
    {
      ...d,
      mode: "full",
      options: { ...d.options, only: null },
      machine: { ...d.machine, gitCommit: null, gitDirty: true },
    },
    results,
  );
}

/** Nothing measured: failures only, every target "not measured". */
function nothing(d: BenchDocument): BenchDocument {
  const learn: LearnResult = { ...byId(d, "learn", "learn"), ok: false, error: "no wasm" };
  const udp: UdpResult = { ...byId(d, "udp", "udp"), ok: false, error: "EADDRINUSE" };
  const batching: BatchingResult = {
    ...byId(d, "batching", "batching"),
    ok: false,
    rows: [],
  };
  const myo: PipelineResult = { ...byId(d, "pipeline", "myo"), ok: false };
  delete myo.error;
  return document({ ...d, machine: { ...d.machine, gitDirty: false, loadAvgAfter: [] } }, [
    myo,
    learn,
    udp,
    batching,
  ]);
}

describe("bench report output (golden)", () => {
  test("latest.md of the fixture run is rendered byte for byte", () => {
    const d = fixture();
    expect(latestMarkdown(d)).toBe(readFileSync(here("bench-fixture.md.txt"), "utf8"));
  });

  test("the targets of the fixture run are those it wrote", () => {
    const d = fixture();
    expect(targets(d.workloads)).toEqual(d.targets);
  });

  test("every workload kind, failures and rare lines: Markdown, stdout tables and targets", () => {
    const d = fixture();
    const text = [
      "<!-- variant: fixture -->",
      render(d),
      "<!-- variant: everything -->",
      render(everything(d)),
      "<!-- variant: nothing -->",
      render(nothing(d)),
    ].join("\n");
    const file = here("bench-fixture-variants.md.txt");
    if (process.env.BENCH_GOLDEN_WRITE === "1") writeFileSync(file, text);
    expect(text).toBe(readFileSync(file, "utf8"));
  });
});
