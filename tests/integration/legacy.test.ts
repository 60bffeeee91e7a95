import { readFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { loadPipeline } from "../../app/engine/pipeline/loader";
import { runVirtualPipeline } from "../../app/engine/testing";
import { initDspForTests } from "../support/wasm";
import { ROOT } from "./helpers";

const FILE = join(ROOT, "pipelines/legacy/mosaic-syntax.yaml");

describe("MOSAIC's original syntax", () => {
  test("loads with exactly one warning per converted block", () => {
    const r = loadPipeline(readFileSync(FILE, "utf8"), FILE, catalog);
    expect(r.diagnostics.filter((d) => d.severity === "error")).toEqual([]);
    const warned = r.diagnostics.filter((d) => d.severity === "warning").map((d) => d.block);
    // Blocks written with positional Params; the timers and the Resampler have none.
    expect(warned).toEqual([
      "sinusoid",
      "squared",
      "doubled",
      "amplified",
      "rectified",
      "ARV_LPF",
      "firstThree",
      "joined",
    ]);
    expect(new Set(warned).size).toBe(warned.length);
    const lpf = r.spec!.byName.get("ARV_LPF")!.params as {
      Numerator: number[];
      Denominator: number[];
    };
    expect(lpf.Numerator).toEqual([0.00094469, 0.0018894, 0.00094469]);
    expect(lpf.Denominator).toEqual([1, -1.9112, 0.91498]);
    expect(r.spec!.byName.get("doubled")!.inputs[0]!.subscribed).toBe(false);
    expect(r.spec!.byName.get("firstThree")!.params).toMatchObject({ Indices: [2, 0, 1] });
  });

  test("runs: the converted blocks compute what MOSAIC's would", async () => {
    initDspForTests();
    const run = await runVirtualPipeline(readFileSync(FILE, "utf8"), {
      catalog,
      duration: 2,
      file: FILE,
    });
    const sin = run.outputs.get("sinusoid")!;
    const sq = run.outputs.get("squared")!;
    expect(sin.v[0]!.length).toBe(6);
    expect(sq.v[10]![3]).toBeCloseTo(sin.v[10]![3]! ** 2, 12);
    expect(run.outputs.get("doubled")!.v).toEqual([]);
    const joined = run.outputs.get("joined")!;
    expect(joined.v[5]!.length).toBe(3 + 6);
    expect(run.telemetry.blocks.every((b) => b.errors === 0)).toBe(true);
  });
});
