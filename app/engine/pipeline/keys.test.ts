import { parseDocument, type YAMLMap } from "yaml";
import { describe, expect, test } from "vitest";
import { formatDiagnostic } from "../diagnostics";
import { testCatalog } from "../test-blocks";
import { Collector } from "./collector";
import { readBlockKeys, readSettings } from "./keys";
import { mosaicView } from "./mosaic";
import { lineCounterOf } from "./parse";

/** Stage 3 on block B of `src`. */
function keys(src: string) {
  const doc = parseDocument(src);
  const map = doc.get("B", true) as YAMLMap;
  const c = new Collector("p.yaml", lineCounterOf(src));
  const k = readBlockKeys(c, "B", { line: 1, col: 1 }, map, testCatalog, mosaicView(map));
  return { k, diagnostics: c.list.map(formatDiagnostic) };
}

describe("block keys stage", () => {
  test("reads every key", () => {
    const { k, diagnostics } = keys(
      "B: { Type: Gain, DesiredRate: 50, Inputs: [ C, -T.out ], Params: [ gain:2 ], Path: logs/, Worker: w, BatchingMs: 2, Queue: { Policy: latest, Capacity: 8 }, Layout: { X: 1, Y: 2 } }\n",
    );
    expect(diagnostics).toEqual([]);
    expect(k.def?.type).toBe("Gain");
    expect(k.renamed).toBe(false);
    expect(k.desiredRate).toBe(50);
    expect(k.inputs.map((i) => [i.block, i.port, i.subscribed])).toEqual([
      ["C", "", true],
      ["T", "out", false],
    ]);
    expect([k.path, k.worker, k.batchingMs, k.queue, k.layout]).toEqual([
      "logs/",
      "w",
      2,
      { policy: "latest", capacity: 8 },
      { x: 1, y: 2 },
    ]);
    expect(k.paramsPos).toEqual({ line: 1, col: 66 });
  });

  test("each bad key is one positioned error with what was expected", () => {
    expect(keys("B: { Type: Gain, Input: [ C ] }\n").diagnostics).toEqual([
      "p.yaml:1:18: error: block 'B': unknown key 'Input' (expected one of Type, DesiredRate, Inputs, Params, Path, Layout, Worker, Queue, BatchingMs); did you mean 'Inputs'?",
    ]);
    expect(keys("B: { Type: Tick }\n").diagnostics).toEqual([
      "p.yaml:1:1: error: block 'B' (Tick) needs a DesiredRate (expected `DesiredRate: <Hz>`)",
    ]);
    expect(keys("B: { Type: Gian }\n").diagnostics).toEqual([
      "p.yaml:1:12: error: block 'B': unknown block type 'Gian'; did you mean 'Gain'?",
    ]);
    expect(
      keys("B: { Type: Gain, Path: '' , Worker: 'a b', Queue: { Policy: lates } }\n").diagnostics,
    ).toEqual([
      "p.yaml:1:24: warning: block 'B': Path '' logged to the root of the drive in the original MOSAIC; here it logs to B.txt in the log folder (the pipeline's folder, or mosaic run --log-dir)",
      "p.yaml:1:37: error: block 'B': Worker is the string \"a b\" (expected a worker name (a plain word); blocks with the same name share a thread)",
      "p.yaml:1:61: error: block 'B': Queue.Policy 'lates' is not a policy (expected one of drop-oldest, drop-newest, latest); did you mean 'latest'?",
    ]);
  });

  test("the original's old names and keys: what stage 2 found", () => {
    const old = keys("B: { Type: Timer, OutputType: 0d }\n");
    // No Timer in this catalog: the old name maps to ScheduledTimer, which is not there either.
    expect(old.diagnostics).toEqual([
      "p.yaml:1:12: error: block 'B': unknown block type 'Timer': 'Timer' is the original MOSAIC's old name of ScheduledTimer, a block that is not available yet",
    ]);
    const empty = keys("B: { Type: Gain, Path: '' }\n");
    expect(empty.k.path).toBe(".");
    expect(keys("B: { Type: FBGS }\n").diagnostics[0]).toMatch(
      /no public source of the original MOSAIC defines 'FBGS'/,
    );
  });

  test("Pipeline settings", () => {
    const src = "Pipeline: { BatchingMs: 3, Batch: 1 }\n";
    const c = new Collector("p.yaml", lineCounterOf(src));
    const settings = { batchingMs: undefined as number | undefined };
    readSettings(c, parseDocument(src).get("Pipeline", true) as YAMLMap, settings);
    expect(settings.batchingMs).toBe(3);
    expect(c.list.map(formatDiagnostic)).toEqual([
      "p.yaml:1:28: error: Pipeline: unknown setting 'Batch' (expected one of BatchingMs, Layout, Blocks (a block named Pipeline needs a Type)); did you mean 'BatchingMs'?",
    ]);
  });
});
