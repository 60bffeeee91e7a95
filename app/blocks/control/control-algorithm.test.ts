import { describe, expect, test } from "vitest";
import { Frame, loadPipeline, vectorShape, createCatalog } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { ControlAlgorithm, mosaicHandDofs } from "./control-algorithm";

const preds = (t: number[], rows: number[][]) => Frame.from(vectorShape(rows[0]!.length), t, rows);

async function harness(params: unknown, width = 2, rate = 25) {
  const h = await BlockHarness.create(ControlAlgorithm, params, {
    inputs: [{ shape: vectorShape(width), rate }],
  });
  h.start();
  return h;
}

describe("ControlAlgorithm", () => {
  test("direct: Rest + Gain·(a⁺ − a⁻), clamped activations, clipped output", async () => {
    const h = await harness({
      Strategy: "direct",
      DoFs: [
        { Name: "grasp", Positive: 0 },
        { Name: "wrist", Positive: 1, Negative: 0, Rest: 50, Gain: 50 },
      ],
      Timeout: 0,
    });
    h.push(
      preds(
        [0, 0.04, 0.08],
        [
          [0.25, 0],
          [0.5, 1],
          [1.5, -3],
        ],
      ),
    );
    expect(h.output().v).toEqual([
      [25, 50 - 12.5],
      [50, 50 + 25],
      [100, 0],
    ]);
    expect(h.output().t).toEqual([0, 0.04, 0.08]);
  });

  test("dead zone: activations at or below it are zero, the rest rescaled from zero", async () => {
    const h = await harness({ Strategy: "direct", DeadZone: 0.2, Timeout: 0 }, 1);
    h.push(preds([0, 1, 2], [[0.1], [0.2], [0.6]]));
    const v = h.output().v.map((r) => r[0]!);
    expect(v.slice(0, 2)).toEqual([0, 0]);
    expect(v[2]).toBeCloseTo(50, 12);
  });

  test("stepwise: value moves by Gain per second at full activation, using event time", async () => {
    const h = await harness(
      {
        Strategy: "stepwise",
        Gain: 10,
        DoFs: [{ Name: "x", Positive: 0, Negative: 1, Rest: 50 }],
        Timeout: 0,
      },
      2,
      25,
    );
    // First event: nominal 1/25 s; then 0.5 s and 0.1 s steps.
    h.push(
      preds(
        [0, 0.5, 0.6],
        [
          [1, 0],
          [1, 0],
          [0, 0.5],
        ],
      ),
    );
    expect(h.output().v.map((r) => r[0])).toEqual([
      50 + 10 / 25,
      50 + 10 / 25 + 5,
      50 + 10 / 25 + 5 - 0.5,
    ]);
  });

  test("slew rate limits the change per second", async () => {
    const h = await harness({ Strategy: "direct", SlewRate: 100, Timeout: 0 }, 1, 10);
    h.push(preds([0, 0.1, 0.2, 0.3], [[1], [1], [1], [0]]));
    // 100 per second at 10 Hz: at most 10 per step from 0 (the first step uses 1/rate).
    expect(h.output().v.map((r) => r[0])).toEqual([10, 20, 30, 20]);
  });

  test("watchdog sends the safe output after Timeout without predictions, until they resume", async () => {
    const h = await harness(
      {
        Strategy: "direct",
        DoFs: [{ Name: "w", Positive: 0, Rest: 50 }],
        Timeout: 0.2,
        Safe: "rest",
      },
      1,
      25,
    );
    h.clock = 1;
    h.push(preds([1], [[0.8]]));
    expect(h.oneShot?.t).toBeCloseTo(1.2, 12);
    expect(h.output().v).toEqual([[130 > 100 ? 100 : 130]]);
    h.fireOneShot();
    expect(h.output().v.at(-1)).toEqual([50]);
    expect(h.warnings[0]).toMatch(/no prediction for 0.2 s/);
    expect(h.text).toMatch(/watchdog/);
    // it keeps sending at the desired rate
    expect(h.oneShot?.t).toBeCloseTo(1.24, 12);
    h.fireOneShot();
    expect(h.output().v.length).toBe(3);
    h.push(preds([1.3], [[0.1]]));
    expect(h.text).toBe("direct, 1 DoF");
    expect(h.output().v.at(-1)).toEqual([60]);
  });

  test("indices are checked against the input width", async () => {
    await expect(harness({ DoFs: [{ Name: "x", Positive: 5 }] }, 2)).rejects.toThrow(
      /DoFs\[0\] \(x\): Positive 5 is out of range .* 2 predictions \(valid: 0–1\)/,
    );
  });

  test("MOSAIC's mapping fed with 12 predictions: the missing degrees stay at rest, one warning", async () => {
    const catalog = createCatalog([ControlAlgorithm]);
    const r = loadPipeline(
      "C: { Type: ControlAlgorithm, Inputs: [C], Params: [ 'algorithm: DirectControl' ] }\n",
      "p.yaml",
      catalog,
    );
    const h = await harness(r.spec!.blocks[0]!.params, 12);
    expect(h.warnings).toEqual([
      "input 'in0' has 12 predictions; at rest (no prediction): ElbowFlexion (13), ElbowExtension (14)",
    ]);
    // power grasp with wrist extension 0.5 and supination 1, ulnar 0.25
    h.push(preds([0], [[1, 1, 1, 1, 1, 1, 0, 0.5, 0, 1, 0.25, 0]]));
    // DOAs order: 6 fingers, flexion/extension, ulnar/radial, pronation/supination, elbows.
    expect(h.output().v).toEqual([[100, 100, 100, 100, 100, 100, 75, 62.5, 0, 0, 0]]);
    expect(h.warnings).toHaveLength(1);

    // Stepwise: prediction 12 (open) drives the fingers down; with 12 predictions it is absent.
    const s = loadPipeline(
      "C: { Type: ControlAlgorithm, Inputs: [C], Params: [ algorithm:StepwiseControl ] }\n",
      "p.yaml",
      catalog,
    );
    const hs = await harness(s.spec!.blocks[0]!.params, 13);
    expect(hs.warnings[0]).toMatch(/13 predictions; at rest .*ElbowFlexion \(13\)/);
    // One second at full thumb flexion, then 0.5 s of "open" at 1: 70·(1−0.3)/0.7 per second.
    hs.push(
      preds(
        [0, 1, 1.5],
        [
          [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
          [1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0],
          [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1],
        ],
      ),
    );
    const v = hs.output().v;
    expect(v[1]![0]).toBeCloseTo(70, 12);
    expect(v[2]![0]).toBeCloseTo(35, 12);
  });

  test("MOSAIC's positional form loads with its hand mapping", () => {
    const catalog = createCatalog([ControlAlgorithm]);
    const r = loadPipeline(
      "C: { Type: ControlAlgorithm, Params: [ algorithm:StepwiseControl ] }\n",
      "p.yaml",
      catalog,
    );
    // (input count is checked too; only the params matter here)
    const warnings = r.diagnostics.filter((d) => d.severity === "warning");
    expect(warnings).toHaveLength(1);
    expect(mosaicHandDofs()).toHaveLength(11);
    const bad = loadPipeline(
      "C: { Type: ControlAlgorithm, Params: [ algorithm:Magic ] }\n",
      "p.yaml",
      catalog,
    );
    expect(bad.diagnostics[0]!.message).toMatch(/unknown algorithm 'Magic'/);
  });
});
