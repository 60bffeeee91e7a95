import { readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { Frame, vectorShape } from "../../engine";
import { BlockHarness, noResources, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, loadBlock, vectors } from "../../../tests/support/blocks";
import { memoryResources, REPO_ROOT } from "../../../tests/support/fs-resources";
import { initDspForTests } from "../../../tests/support/wasm";
import { createCatalog, loadPipeline, Runtime, runVirtual, VirtualClock } from "../../engine";
import { BufferBlock } from "../flow/buffer";
import { SinGenerator } from "../sources/sin-generator";
import { ScheduledTimer } from "../timing/scheduled-timer";
import { BatchPredictor } from "./batch-predictor";
import { Trigger } from "./trigger";

const catalog = createCatalog([ScheduledTimer, SinGenerator, Trigger, BufferBlock, BatchPredictor]);

beforeAll(() => initDspForTests());

interface Data {
  n: number;
  d: number;
  m: number;
  x: number[];
  y: number[];
  xt: number[];
}
const fx = JSON.parse(
  readFileSync(join(REPO_ROOT, "core-wasm/learn/tests/fixtures/learn.json"), "utf8"),
) as {
  linear: Data;
  ridge: { alpha: number; intercept: boolean; predictions: number[] }[];
};

async function batch(params: object, d: number, m: number | null, files?: Record<string, string>) {
  const inputs = [{ shape: vectorShape(d), rate: 25 }];
  if (m !== null) inputs.push({ shape: vectorShape(m + d), rate: 0 });
  const h = await BlockHarness.create(BatchPredictor, params, {
    inputs,
    ...(files ? { resources: memoryResources(files) } : {}),
  });
  h.start();
  return h;
}

const run = (h: BlockHarness, action: string, arg?: unknown) =>
  h.instance.actions![action]!.run(arg);

/** The data set as the Buffer's pairs: rows [target…, data…], one frame. */
function pairsFrame(d: Data, from = 0, to = d.n): Frame {
  const rows: number[][] = [];
  for (let i = from; i < to; i++) {
    rows.push([...d.y.slice(i * d.m, (i + 1) * d.m), ...d.x.slice(i * d.d, (i + 1) * d.d)]);
  }
  return vectors(
    rows.map((_, i) => i * 0.04),
    rows,
  );
}

function maxRel(a: number[], b: number[]): number {
  let s = 1e-300;
  let e = 0;
  for (let i = 0; i < b.length; i++) {
    s = Math.max(s, Math.abs(b[i]!));
    e = Math.max(e, Math.abs(a[i]! - b[i]!));
  }
  return e / s;
}

describe("BatchPredictor", () => {
  test("rows in one frame (the Buffer's emit) are fitted at once; predictions equal scikit-learn", async () => {
    const d = fx.linear;
    const h = await batch({ Lambda: 1 }, d.d, d.m);
    expect(h.text).toBe("untrained: no rows yet");
    const xt = vectors(
      Array.from({ length: d.xt.length / d.d }, (_, i) => 100 + i),
      Array.from({ length: d.xt.length / d.d }, (_, i) => d.xt.slice(i * d.d, (i + 1) * d.d)),
    );
    h.push(xt, 0);
    expect(h.output("prediction").v[0]).toEqual([0, 0, 0]); // before any fit
    h.push(pairsFrame(d), 1);
    expect(h.text).toMatch(/^fitted on 240 rows, R² (0\.9\d|1\.00)$/);
    const fit = h.output("fit");
    expect(fit.v.length).toBe(1);
    expect(fit.v[0]![0]).toBe(240);
    h.clear();
    h.push(xt, 0);
    const ref = fx.ridge.find((c) => c.alpha === 1 && c.intercept)!.predictions;
    expect(maxRel(h.output("prediction").v.flat(), ref)).toBeLessThan(1e-9);
    // A second emit replaces the data set (Dataset: replace).
    h.push(pairsFrame(d, 0, 100), 1);
    expect(h.text).toMatch(/^fitted on 100 rows/);
  });

  test("append without AutoTrain: rows accumulate until train; clear and reset", async () => {
    const d = fx.linear;
    const h = await batch({ Dataset: "append", AutoTrain: false, Lambda: 1 }, d.d, d.m);
    h.push(pairsFrame(d, 0, 100), 1);
    h.push(pairsFrame(d, 100, 240), 1);
    expect(h.text).toBe("240 rows kept (press train)");
    expect(run(h, "train")).toMatch(
      /^fitted ridge \(λ 1\) on 240 rows, in-sample R² (0\.9\d|1\.00)$/,
    );
    expect(run(h, "inspect")).toMatch(
      /^ridge \(λ 1\): 240 rows kept, fitted on 240 rows; in-sample R² per output \[(0\.9|1\.000)/,
    );
    expect(run(h, "clear")).toBe("dropped 240 rows");
    expect(h.text).toMatch(/^trained on 240 rows, R² (0\.9\d|1\.00); no rows kept$/);
    expect(run(h, "reset")).toBe("the model is untrained");
    expect(run(h, "train")).toBe("no rows to fit");
  });

  test("MaxRows bounds the rows kept; the rest are dropped and counted", async () => {
    const d = fx.linear;
    const h = await batch({ MaxRows: 50 }, d.d, d.m);
    h.push(pairsFrame(d, 0, 80), 1);
    expect(h.text).toMatch(/^fitted on 50 rows, R² \S+; 30 rows dropped \(MaxRows\)$/);
    expect(h.warnings[0]).toMatch(/more rows than MaxRows \(50\): 30 dropped/);
  });

  test("a Buffer's emit trains it: Buffer rows → BatchPredictor", async () => {
    const buf = await BlockHarness.create(
      BufferBlock,
      {},
      {
        inputs: [{ shape: vectorShape(1) }, { shape: vectorShape(2), rate: 25 }],
      },
    );
    buf.start();
    const bp = await batch({ Lambda: 1e-6 }, 2, 1);
    // Two labelled clusters: rest (target 0) and contraction (target 1) on feature 0.
    buf.push(vectors([0], [[0]]), 0);
    buf.push(
      vectors(
        [0.04, 0.08, 0.12],
        [
          [0.1, 5],
          [0.12, 5],
          [0.08, 5],
        ],
      ),
      1,
    );
    buf.push(vectors([0.2], [[1]]), 0);
    buf.push(
      vectors(
        [0.24, 0.28, 0.32],
        [
          [1.1, 5],
          [0.9, 5],
          [1, 5],
        ],
      ),
      1,
    );
    buf.push(vectors([0.4], [[NaN]]), 0);
    buf.instance.actions!.emit!.run();
    const emitted = buf.output("pairs");
    bp.push(vectors(emitted.t, emitted.v), 1);
    expect(bp.text).toMatch(/^fitted on 6 rows/);
    bp.push(
      vectors(
        [1, 2],
        [
          [0.1, 5],
          [1, 5],
        ],
      ),
      0,
    );
    const p = bp.output("prediction").v;
    expect(p[0]![0]).toBeCloseTo(0.0, 1);
    expect(p[1]![0]).toBeCloseTo(1.0, 1);
  });

  test("save and load through a File; a File of the wrong size is refused", async () => {
    const files: Record<string, string> = {};
    const d = fx.linear;
    const h = await batch({ Model: "rff", Features: 30, Gamma: 0.05 }, d.d, d.m, files);
    h.push(pairsFrame(d), 1);
    run(h, "save", "b.json");
    await new Promise((r) => setTimeout(r, 0));
    expect(files["b.json"]).toMatch(/^\{\n {2}"format": "mosaic-model",\n {2}"version": 1,/);
    // Predicting only: one input, the model from the file.
    const g = await batch({ File: "b.json" }, d.d, null, files);
    expect(g.text).toMatch(/^trained on 240 rows, R² \S+; no rows kept \(loaded b\.json\)$/);
    const probe = vectors([1], [d.x.slice(0, d.d)]);
    h.push(probe, 0);
    g.push(probe, 0);
    expect(g.output("prediction").v[0]![0]).toBeCloseTo(h.output("prediction").v[0]![0]!, 12);
    await expect(batch({ File: "b.json" }, d.d + 1, null, files)).rejects.toThrow(
      "model file 'b.json': the model has 6 inputs but input 'in0' carries 7 values per event",
    );
  });

  test("pairs that do not fit the features, and MOSAIC's one-input form, are explained", async () => {
    await expect(
      BlockHarness.create(
        BatchPredictor,
        {},
        {
          inputs: [{ shape: vectorShape(4) }, { shape: vectorShape(3) }],
        },
      ),
    ).rejects.toThrow(/rows must be \[target…, data…\] with the 4 data values of 'in0'/);
    await expect(batch({ Buffer: "cluster_storage" }, 8, null)).rejects.toThrow(
      "reading the Buffer 'cluster_storage' by name needs Outputs (the width of its targets)",
    );
  });

  test("MOSAIC's one-input form reads the named Buffer's rows when a cluster ends, or on train", async () => {
    // cfg4's wiring: the Buffer records [target, features] between Trigger events; the predictor's
    // only input is the features.
    const yaml = (autoTrain: string) => `
T: { Type: ScheduledTimer, DesiredRate: 25 }
F: { Type: SinGenerator, Inputs: [T], Params: { Components: 2, Frequency: 0.5 } }
capture: { Type: Trigger, Params: { Labels: { rest: [0], up: [1] }, Schedule: { Seconds: 1, Pause: 0.5, Start: 0.2 } } }
store: { Type: Buffer, Inputs: [capture, -F] }
P: { Type: BatchPredictor, Inputs: [F], Params: { Buffer: store, Model: ridge, Outputs: 1, Lambda: 1e-6${autoTrain} } }
`;
    const live = async (y: string) => {
      const loaded = loadPipeline(y, "p.yaml", catalog);
      const clock = new VirtualClock(0);
      const created = await Runtime.create({
        spec: loaded.spec!,
        catalog,
        clock,
        virtual: true,
        resources: noResources,
      });
      expect(created.diagnostics).toEqual([]);
      const rt = created.runtime!;
      rt.start();
      runVirtual(rt, clock, 4);
      return rt;
    };
    const auto = await live(yaml(""));
    // Fitted when each of the two clusters ended, the second time on all the rows.
    expect(auto.invoke("P", "inspect")).toMatch(/fitted on 49 rows/);
    auto.dispose();
    const manual = await live(yaml(", AutoTrain: false"));
    expect(manual.invoke("P", "inspect")).toMatch(/fitted on 0 rows/);
    expect(manual.invoke("P", "train")).toMatch(/fitted ridge .* on 49 rows/);
    manual.dispose();
    // With a File and no Outputs the rows' width comes from the model read from the File.
    const files: Record<string, string> = {};
    const withFile = async (outputs: string) => {
      const y = yaml("").replace("Outputs: 1", `${outputs}File: m.json, AutoTrain: false`);
      const clock = new VirtualClock(0);
      const created = await Runtime.create({
        spec: loadPipeline(y, "p.yaml", catalog).spec!,
        catalog,
        clock,
        virtual: true,
        resources: memoryResources(files),
      });
      expect(created.diagnostics).toEqual([]);
      const rt = created.runtime!;
      rt.start();
      runVirtual(rt, clock, 4);
      return rt;
    };
    const first = await withFile("Outputs: 1, ");
    const fitted = first.invoke("P", "train");
    expect(fitted).toMatch(/fitted ridge .* on 49 rows, in-sample R² 0\.\d+$/);
    first.invoke("P", "save", "m.json");
    await new Promise((r) => setTimeout(r, 0));
    first.dispose();
    const second = await withFile("");
    // The same rows, aligned as the first run's: the same fit.
    expect(second.invoke("P", "train")).toBe(fitted);
    second.dispose();
    const lone = await runVirtualPipeline(
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
        "F: { Type: SinGenerator, Inputs: [T], Params: { Components: 2 } }\n" +
        "P: { Type: BatchPredictor, Inputs: [F], Params: { Buffer: nope, Outputs: 1 } }\n",
      { catalog, duration: 0.1 },
    );
    expect(lone.telemetry.events.map((e) => e.message)).toEqual([
      expect.stringMatching(/Buffer 'nope' \(Params\): there is no Buffer 'nope' in this pipeline/),
    ]);
  });

  test("MOSAIC's positional Params", () => {
    const yaml = (inputs: string, params: string) =>
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
      "F: { Type: SinGenerator, Inputs: [T], Params: { Components: 8 } }\n" +
      "L: { Type: SinGenerator, Inputs: [T], Params: { Components: 12 } }\n" +
      "cluster_storage: { Type: Buffer, Inputs: [L, -F] }\n" +
      `P: { Type: BatchPredictor, Inputs: ${inputs}, Params: ${params} }\n`;
    expect(
      convertLegacy(yaml("[F, cluster_storage]", "[cluster_storage, RR_RFF, 8, 12]"), "P"),
    ).toMatchObject({
      Buffer: "cluster_storage",
      Model: "rff",
      Inputs: 8,
      Outputs: 12,
      Lambda: 2 / 300,
      Gamma: 0.5,
      Intercept: false,
    });
    const r = loadBlock(yaml("[F]", "[cluster_storage, LDA, 8, 12]"), "P");
    expect(r.errors[0]!.message).toMatch(
      /unknown learning machine 'LDA'; expected one of RidgeRegression, RR_RFF/,
    );
  });
});
