import { readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { loadPipeline, Runtime, runVirtual, vectorShape, VirtualClock } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, vectors } from "../../../tests/support/blocks";
import { memoryResources, REPO_ROOT } from "../../../tests/support/fs-resources";
import { initDspForTests } from "../../../tests/support/wasm";
import { catalog } from "../catalog";
import { IncrementalPredictor } from "./incremental-predictor";

beforeAll(() => initDspForTests());

const STOP2 = [NaN, NaN];

async function predictor(
  params: object,
  d: number,
  m: number | null,
  files?: Record<string, string>,
): Promise<BlockHarness> {
  const inputs = [{ shape: vectorShape(d), rate: 25 }];
  if (m !== null) inputs.push({ shape: vectorShape(m), rate: 0 });
  const h = await BlockHarness.create(IncrementalPredictor, params, {
    inputs,
    ...(files ? { resources: memoryResources(files) } : {}),
  });
  h.start();
  return h;
}

const run = (h: BlockHarness, action: string, arg?: unknown) =>
  h.instance.actions![action]!.run(arg);

/** Lets pending promises (file writes and reads) settle. */
const settle = () => new Promise((r) => setTimeout(r, 0));

/** x → y = [2·x0 − x1 + 1, x0 + x1]: an exact linear map. */
const linear = (x: readonly number[]) => [2 * x[0]! - x[1]! + 1, x[0]! + x[1]!];
const point = (i: number) => [Math.sin(0.7 * i) * 3, Math.cos(0.3 * i) + i / 20];

describe("IncrementalPredictor", () => {
  test("a target stream changing every event rewrites the status at most every 0.25 s; start and stop at once", async () => {
    const h = await predictor({}, 1, 1);
    let writes = 0;
    const ctx = h as unknown as { text: string };
    let text = ctx.text;
    Object.defineProperty(ctx, "text", {
      get: () => text,
      set: (v: string) => {
        writes++;
        text = v;
      },
    });
    h.push(vectors([0], [[0.5]]), 1);
    expect(h.text).toBe("learning [0.5]: untrained");
    expect(writes).toBe(1);
    // A ramp at 25 Hz for 1 s, each target followed by its feature event.
    for (let i = 1; i <= 25; i++) {
      h.push(vectors([i / 25], [[0.5 + i / 50]]), 1);
      h.push(vectors([i / 25 + 0.001], [[i]]), 0);
    }
    expect(writes).toBeLessThanOrEqual(1 + 2 * 5);
    expect(h.text).toMatch(/^learning \[0\.9\d*\]: trained on 2\d samples/);
    h.push(vectors([1.1], [[NaN]]), 1);
    expect(h.text).toMatch(/^trained on 25 samples/);
  });

  test("trigger protocol: a target trains every later feature event until all-NaN; predictions always", async () => {
    const h = await predictor({ Lambda: 1e-6 }, 2, 2);
    expect(h.text).toBe("untrained (waiting for a target)");
    h.push(vectors([0], [point(0)]), 0); // untrained: predicts 0
    expect(h.output("prediction").v).toEqual([[0, 0]]);

    // A cued target, then 3 feature events: each is learnt, then predicted (MOSAIC's order).
    const p1 = point(1);
    h.push(vectors([0.9], [linear(p1)]), 1);
    expect(h.text).toMatch(/^learning \[/);
    h.push(vectors([1], [p1]), 0);
    const afterOne = h.output("prediction").v[1]!;
    // With an intercept, one sample is predicted as its own target.
    expect(afterOne[0]).toBeCloseTo(linear(p1)[0]!, 9);

    // A stream of targets, each followed by its features (a plain target stream).
    for (let i = 2; i < 40; i++) {
      h.push(vectors([i - 0.1], [linear(point(i))]), 1);
      h.push(vectors([i], [point(i)]), 0);
    }
    h.push(vectors([40], [STOP2]), 1);
    expect(h.text).toMatch(/^trained on 39 samples, R² 0\.\d\d$/);
    // Not training any more: a new feature event is only predicted, and exactly.
    h.push(vectors([41], [[0.5, -2]]), 0);
    const last = h.output("prediction").v.at(-1)!;
    expect(last[0]).toBeCloseTo(4, 5);
    expect(last[1]).toBeCloseTo(-1.5, 5);
    expect(run(h, "inspect")).toMatch(/^ridge \(λ 0.000001\): 39 samples learnt, 0 refused/);
    // The fit output: one event per sample learnt, [samples seen, R² per output].
    const fit = h.output("fit");
    expect(fit.t.length).toBe(39);
    expect(fit.v[0]![0]).toBe(1);
    expect(Number.isNaN(fit.v[0]![1]!)).toBe(true); // undefined after one sample
    expect(fit.v[38]![0]).toBe(39);
    expect(fit.v[38]![1]).toBeGreaterThan(0.5);
  });

  test("a partly-NaN target is ignored with a warning; pause and train; reset forgets", async () => {
    const h = await predictor({}, 2, 2);
    h.push(vectors([0], [[1, NaN]]), 1);
    expect(h.warnings[0]).toMatch(/ignored a target event with 1 NaN of 2 values/);
    h.push(vectors([0.1], [[1, 2]]), 1);
    expect(run(h, "pause")).toBe("paused: untrained");
    h.push(vectors([1, 2], [point(1), point(2)]), 0);
    expect(h.output("fit").t).toEqual([]);
    expect(run(h, "train")).toBe("learning [1, 2]");
    h.push(vectors([3, 4], [point(3), point(4)]), 0);
    expect(h.output("fit").t).toEqual([3, 4]);
    expect(run(h, "reset")).toBe("forgot 2 samples");
    expect(h.text).toMatch(/^learning \[1, 2\]: untrained/);
  });

  test("refused samples (NaN features) are counted and do not poison the model", async () => {
    const h = await predictor({}, 2, 1);
    h.push(vectors([0], [[1]]), 1);
    h.push(
      vectors(
        [1, 2, 3],
        [
          [1, 2],
          [NaN, 0],
          [2, 1],
        ],
      ),
      0,
    );
    expect(h.text).toBe("learning [1]: trained on 2 samples, R² –; 1 refused (NaN or huge)");
    h.push(vectors([4], [STOP2.slice(0, 1)]), 1);
    h.push(vectors([5], [[3, 3]]), 0);
    expect(h.output("prediction").v.at(-1)![0]).toBeCloseTo(1, 12);
  });

  test("real EMG: features of emg_bursts_1000hz.csv, trained online on 70 %, R² on the last 30 %", async () => {
    // Fixture: core-wasm/learn/tests/fixtures/emg_regression.json (gen_emg_regression.py):
    // MAV, RMS, WL, ZC, SSC of 200 ms windows every 50 ms; target: the normalised zero-phase
    // 1 Hz envelope of the EMG at each window's centre.
    const fx = JSON.parse(
      readFileSync(join(REPO_ROOT, "core-wasm/learn/tests/fixtures/emg_regression.json"), "utf8"),
    ) as { windows: number; train: number; x: number[]; y: number[]; ridge: { r2: number } };
    const r2 = async (params: object): Promise<number> => {
      const h = await predictor({ ...params, Normalize: true }, 5, 1);
      const row = (i: number) => fx.x.slice(i * 5, i * 5 + 5);
      for (let i = 0; i < fx.train; i++) {
        h.push(vectors([i * 0.05 - 0.01], [[fx.y[i]!]]), 1); // the cue
        h.push(vectors([i * 0.05], [row(i)]), 0);
      }
      h.push(vectors([fx.train * 0.05], [[NaN]]), 1);
      h.clear();
      const n = fx.windows - fx.train;
      h.push(
        vectors(
          Array.from({ length: n }, (_, k) => (fx.train + k) * 0.05),
          Array.from({ length: n }, (_, k) => row(fx.train + k)),
        ),
        0,
      );
      const pred = h.output("prediction").v.map((v) => v[0]!);
      const y = fx.y.slice(fx.train);
      const mean = y.reduce((s, v) => s + v, 0) / n;
      const sst = y.reduce((s, v) => s + (v - mean) ** 2, 0);
      const sse = y.reduce((s, v, k) => s + (v - pred[k]!) ** 2, 0);
      h.instance.dispose?.();
      return 1 - sse / sst;
    };
    const ridge = await r2({ Model: "ridge", Lambda: 1 });
    const rff = await r2({ Model: "rff", Features: 100, Gamma: 0.05, Lambda: 1 });
    // The same figures as the Rust test (core-wasm/learn/tests/emg.rs): 0.9533 and 0.9554;
    // scikit-learn's batch ridge on train-split-standardised features: 0.9534.
    expect(ridge).toBeCloseTo(0.9533, 4);
    expect(rff).toBeCloseTo(0.9554, 4);
    expect(Math.abs(ridge - fx.ridge.r2)).toBeLessThan(1e-3);
  });

  test("save, then a new block with File loads the same model; AutoSave at the end of a cluster", async () => {
    const files: Record<string, string> = {};
    const h = await predictor({ Model: "rff", Features: 20, AutoSave: true }, 2, 2, files);
    h.push(vectors([0], [[1, 0]]), 1);
    h.push(vectors([1, 2, 3], [point(1), point(2), point(3)]), 0);
    h.push(vectors([4], [STOP2]), 1); // the cluster ends: saved
    await settle();
    expect(Object.keys(files)).toEqual(["block.model.json"]);
    expect(h.text).toMatch(/\(saved to block\.model\.json\)$/);
    const text = files["block.model.json"]!;
    expect(text).toMatch(/"kind": "rff",\n {2}"inputs": 2,\n {2}"outputs": 2,/);
    expect(text).toMatch(/"samplesSeen": 3,/);

    expect(run(h, "save", "copy.json")).toBe("saving the model (3 samples) to copy.json");
    await settle();
    const g = await predictor({ File: "copy.json" }, 2, 2, files);
    expect(g.text).toMatch(/^trained on 3 samples, R² \S+ \(loaded copy\.json\)$/);
    const probe = vectors([10, 11], [point(7), point(8)]);
    h.push(probe, 0);
    g.push(probe, 0);
    const a = h.output("prediction").v.slice(-2);
    const b = g.output("prediction").v.slice(-2);
    for (let i = 0; i < 2; i++)
      for (let k = 0; k < 2; k++) expect(b[i]![k]).toBeCloseTo(a[i]![k]!, 12);

    // The load action replaces the model; reset goes back to the one the block was created with.
    const fresh = await predictor({}, 2, 2, files);
    expect(run(fresh, "load", "copy.json")).toBe("loading copy.json");
    await settle();
    expect(fresh.text).toMatch(/loaded copy\.json: rff \(D 20, γ 0.5, λ 1\)/);
    fresh.instance.reset!();
    expect(fresh.text).toBe("untrained (waiting for a target)");
  });

  test("the block's own reset action (Reset model) is what invoking 'reset' runs", async () => {
    const files: Record<string, string> = {};
    const h = await predictor({}, 2, 2, files);
    h.push(vectors([0], [[1, 0]]), 1);
    h.push(vectors([1, 2, 3], [point(1), point(2), point(3)]), 0);
    run(h, "save", "m.json");
    await settle();
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
      "F: { Type: SinGenerator, Inputs: [T], Params: { Components: 2 } }\n" +
      "P: { Type: IncrementalPredictor, Inputs: [F], Params: { File: m.json } }\n";
    const clock = new VirtualClock(0);
    const created = await Runtime.create({
      spec: loadPipeline(yaml, "p.yaml", catalog).spec!,
      catalog,
      clock,
      virtual: true,
      resources: memoryResources(files),
    });
    const rt = created.runtime!;
    rt.start();
    runVirtual(rt, clock, 0.2);
    // The built-in reset would go back to the model loaded from the File; the action forgets it.
    expect(rt.invoke("P", "reset")).toBe("forgot 3 samples");
    expect(rt.invoke("P", "inspect")).toMatch(/: 0 samples learnt/);
    rt.dispose();
  });

  test("a model file that does not fit is refused with the file and the reason", async () => {
    const files: Record<string, string> = {};
    const h = await predictor({}, 3, 1, files);
    run(h, "save", "three.json");
    await settle();
    await expect(predictor({ File: "three.json" }, 2, 1, files)).rejects.toThrow(
      "model file 'three.json': the model has 3 inputs but input 'in0' carries 2 values per event",
    );
    await expect(predictor({ File: "three.json" }, 3, 2, files)).rejects.toThrow(
      "the model has 1 outputs but the target input 'in1' carries 2 values per event",
    );
    files["bad.json"] = files["three.json"]!.replace('"format": "mosaic-model"', '"format": "x"');
    await expect(predictor({ File: "bad.json" }, 3, 1, files)).rejects.toThrow(
      "model file 'bad.json': not a MOSAIC model file",
    );
    // A missing File is not an error: the block starts untrained and save writes it.
    const g = await predictor({ File: "later.json" }, 3, 1, files);
    expect(g.text).toBe("untrained (waiting for a target) (no later.json yet)");
    // The load action reports problems as warnings.
    run(g, "load", "bad.json");
    await settle();
    expect(g.warnings.at(-1)).toMatch(/cannot load the model: model file 'bad.json'/);
  });

  test("load with a model file's text (a file picked in the page) replaces the model at once", async () => {
    const files: Record<string, string> = {};
    const h = await predictor({ Lambda: 1e-6 }, 2, 2, files);
    h.push(vectors([0], [linear(point(0))]), 1);
    h.push(
      vectors(
        [1, 2, 3, 4, 5],
        [1, 2, 3, 4, 5].map((i) => point(i)),
      ),
      0,
    );
    run(h, "save", "trained.json");
    await settle();
    const text = files["trained.json"]!;
    // A block with no target (predicts only), given the text and not a file it could read.
    const g = await predictor({ Outputs: 2 }, 2, null);
    expect(run(g, "load", { name: "trained.json", text })).toBe(
      "loaded trained.json: ridge (λ 0.000001)",
    );
    expect(g.text).toMatch(/^trained on 5 samples.*\(loaded trained\.json: ridge/);
    const probe = vectors([10, 11], [point(7), point(8)]);
    h.push(vectors([9], [STOP2]), 1);
    h.push(probe, 0);
    g.push(probe, 0);
    expect(g.output("prediction").v).toEqual(h.output("prediction").v.slice(-2));
    // A text that is no model, or one of other sizes, fails the action with the reason.
    expect(() => run(g, "load", { name: "x.json", text: "{}" })).toThrow(
      "model file 'x.json': not a MOSAIC model file",
    );
    const three = await predictor({ Outputs: 1 }, 3, null, files);
    expect(() => run(three, "load", { name: "trained.json", text })).toThrow(
      "the model has 2 inputs but input 'in0' carries 3 values per event",
    );
  });

  test("versus: the prediction before each sample is learnt and its target; NaN targets when not learning", async () => {
    const h = await predictor({ Lambda: 1e-6 }, 2, 2);
    h.push(vectors([0], [linear(point(0))]), 1);
    h.push(vectors([1, 2], [point(1), point(2)]), 0);
    const versus = h.output("versus").v;
    expect(versus).toHaveLength(2);
    // The first sample is predicted by the untrained model (0) before it is learnt.
    expect(versus[0]).toEqual([0, 0, ...linear(point(0))]);
    // The second: predicted by the model of one sample, not the one that learnt it.
    const afterOne = h.output("prediction").v[0]!;
    expect(versus[1]!.slice(0, 2)).toEqual(afterOne);
    expect(versus[1]!.slice(2)).toEqual(linear(point(0)));
    // Not learning: the prediction itself and NaN targets.
    h.push(vectors([3], [STOP2]), 1);
    h.push(vectors([4], [point(4)]), 0);
    const last = h.output("versus").v.at(-1)!;
    expect(last.slice(0, 2)).toEqual(h.output("prediction").v.at(-1));
    expect(last.slice(2).every(Number.isNaN)).toBe(true);
  });

  test("sizes are checked against the inputs", async () => {
    await expect(predictor({ Inputs: 4 }, 3, 1)).rejects.toThrow(
      "Inputs is 4 but the features input 'in0' carries 3 values per event",
    );
    await expect(predictor({ Outputs: 2 }, 3, 1)).rejects.toThrow(
      "Outputs is 2 but the target input 'in1' carries 1 values per event",
    );
    await expect(predictor({}, 3, null)).rejects.toThrow(/needs a target input/);
    const h = await predictor({ Outputs: 2 }, 3, null);
    h.push(vectors([0], [[1, 2, 3]]), 0);
    expect(h.output("prediction").v).toEqual([[0, 0]]);
  });

  test("MOSAIC's positional Params: the same model as MOSAIC 1 (γ = σ²/2, λ·2/D, no intercept)", () => {
    const yaml = (params: string) =>
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
      "F: { Type: SinGenerator, Inputs: [T], Params: { Components: 8 } }\n" +
      "Y: { Type: SinGenerator, Inputs: [T], Params: { Components: 12 } }\n" +
      `P: { Type: IncrementalPredictor, Inputs: [F, Y], Params: ${params} }\n`;
    expect(convertLegacy(yaml("[IncrementalRFF, 8, 12, 1.0, 1.0, 300]"), "P")).toMatchObject({
      Model: "rff",
      Inputs: 8,
      Outputs: 12,
      Lambda: 2 / 300,
      Gamma: 0.5,
      Features: 300,
      Intercept: false,
    });
    expect(convertLegacy(yaml("[IncrementalRFF, 8, 12]"), "P")).toMatchObject({
      Model: "rff",
      Lambda: 2 / 300,
      Gamma: 0.5,
      Features: 300,
    });
    expect(convertLegacy(yaml("[IncrementalRidgeRegression, 8, 12, 0.5]"), "P")).toMatchObject({
      Model: "ridge",
      Lambda: 0.5,
      Intercept: false,
    });
    // The older files' [d, M], without a machine (their blocks are named incr_RFF).
    expect(convertLegacy(yaml("[8,12]"), "P")).toMatchObject({
      Model: "rff",
      Inputs: 8,
      Outputs: 12,
      Features: 300,
    });
  });

  test("in a pipeline: learns from a plain target stream that arrives before the features", async () => {
    // The features are a linear map of the target (F = W·Y + b), so Y is a linear function of F.
    // Y's event reaches P before the F event computed from it: each feature event is learnt with
    // the target of its own tick. (A target stream that arrives after its features pairs each
    // feature event with the previous target, as MOSAIC's IncrementalPredictor did.)
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 50 }\n" +
      "Y: { Type: SinGenerator, Inputs: [T], Params: { Components: 2, Frequency: 0.7 } }\n" +
      "F: { Type: LinearMap, Inputs: [Y], Params: { Outputs: 3, Bias: [1, -2, 0.5], Seed: 4 } }\n" +
      "P: { Type: IncrementalPredictor, Inputs: [F, Y], Params: { Lambda: 1e-6 } }\n";
    const r = await runVirtualPipeline(yaml, { catalog, duration: 4, record: ["P", "Y"] });
    const p = r.outputs.get("P")!;
    const y = r.outputs.get("Y")!;
    expect(p.t.length).toBe(y.t.length);
    expect(p.t.length).toBeGreaterThan(150);
    const k = p.t.length - 1;
    for (let o = 0; o < 2; o++) expect(p.v[k]![o]).toBeCloseTo(y.v[k]![o]!, 6);
  });

  test("IncrementalLDA (MOSAIC's name): classes are the targets, predictions their probabilities", async () => {
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
      "F: { Type: SinGenerator, Inputs: [T], Params: { Components: 2 } }\n" +
      "Y: { Type: SinGenerator, Inputs: [T], Params: { Components: 3 } }\n" +
      "P: { Type: IncrementalPredictor, Inputs: [F, Y], Params: [IncrementalLDA, 2, 3] }\n";
    expect(convertLegacy(yaml, "P")).toMatchObject({ Model: "lda", Inputs: 2, Outputs: 3 });
    const h = await predictor({ Model: "lda" }, 2, 3);
    // Two classes: "rest" (all zeros) around (0, 1), "power" [1, 1, 0] around (1, 0).
    const rng = (i: number) => Math.sin(12.9898 * i) * 0.05;
    let t = 0;
    for (let i = 0; i < 40; i++) {
      const rest = i % 2 === 0;
      h.push(vectors([t], [rest ? [0, 0, 0] : [1, 1, 0]]), 1);
      h.push(vectors([t + 0.001], [rest ? [rng(i), 1 + rng(i + 7)] : [1 + rng(i), rng(i + 7)]]), 0);
      t += 0.04;
    }
    h.push(vectors([t], [[NaN, NaN, NaN]]), 1);
    h.clear();
    h.push(
      vectors(
        [t + 0.04, t + 0.08],
        [
          [0, 1],
          [1, 0],
        ],
      ),
      0,
    );
    const [rest, power] = h.output("prediction").v;
    expect(rest![0]).toBeLessThan(1e-6);
    expect(power![0]).toBeGreaterThan(1 - 1e-6);
    expect(power![1]).toBeCloseTo(power![0]!, 12);
    expect(power![2]).toBe(0);
    expect(h.text).toMatch(/40 samples/);
    await expect(predictor({ Model: "lda", AutoSave: true }, 2, 3)).rejects.toThrow(
      /LDA models cannot be saved/,
    );
  });
});
