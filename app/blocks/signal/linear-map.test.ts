import { describe, expect, test } from "vitest";
import { vectorShape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { loadBlock, vectors } from "../../../tests/support/blocks";
import { SeededRandom } from "../shared/random";
import { LinearMap } from "./linear-map";

const three = { shape: vectorShape(3) };

describe("LinearMap", () => {
  test("y = W x + b for every event", async () => {
    const h = await BlockHarness.create(
      LinearMap,
      {
        Weights: [
          [1, 2, 3],
          [0, -1, 0.5],
        ],
        Bias: [10, -10],
      },
      { inputs: [three] },
    );
    h.start();
    h.push(
      vectors(
        [1, 2],
        [
          [1, 1, 1],
          [2, 0, -4],
        ],
      ),
    );
    expect(h.ports[0]!.shape).toEqual(vectorShape(2));
    expect(h.output()).toEqual({
      t: [1, 2],
      v: [
        [16, -10.5],
        [0, -12],
      ],
      frames: [2],
    });
  });

  test("seeded random weights N(0, 1)/√C: reproducible, different per seed", async () => {
    const make = async (seed: number) => {
      const h = await BlockHarness.create(
        LinearMap,
        { Outputs: 2, Seed: seed },
        { inputs: [three] },
      );
      h.start();
      // unit vectors read out the columns of W
      h.push(
        vectors(
          [0, 1, 2],
          [
            [1, 0, 0],
            [0, 1, 0],
            [0, 0, 1],
          ],
        ),
      );
      return h.output().v;
    };
    const a = await make(42);
    expect(await make(42)).toEqual(a);
    expect(await make(7)).not.toEqual(a);
    const w = [0, 1, 2].map((c) => [a[c]![0]!, a[c]![1]!]);
    for (const col of w) for (const x of col) expect(Math.abs(x)).toBeLessThan(4 / Math.sqrt(3));
  });

  test("the generator: mulberry32 reference values and a standard normal distribution", () => {
    // First outputs of mulberry32(0) from the reference implementation (bryc/code, PRNGs.md).
    const r = new SeededRandom(0);
    const u = [r.nextUint32(), r.nextUint32(), r.nextUint32()].map((x) => x / 4294967296);
    expect(u[0]).toBeCloseTo(0.26642920868471265, 15);
    expect(u[1]).toBeCloseTo(0.0003297457005828619, 15);
    expect(u[2]).toBeCloseTo(0.2232720274478197, 15);
    const g = new SeededRandom(42);
    let s = 0;
    let s2 = 0;
    const n = 100_000;
    for (let i = 0; i < n; i++) {
      const x = g.normal();
      s += x;
      s2 += x * x;
    }
    expect(Math.abs(s / n)).toBeLessThan(0.02);
    expect(Math.abs(s2 / n - 1)).toBeLessThan(0.02);
  });

  test("errors: Weights not k × input width, Bias length, neither Outputs nor Weights", async () => {
    await expect(
      BlockHarness.create(
        LinearMap,
        {
          Weights: [
            [1, 2],
            [3, 4],
          ],
        },
        { inputs: [three] },
      ),
    ).rejects.toThrow(
      "Weights is 2 × 2, but input 'in0' has 3 channels; expected 2 rows of 3 numbers",
    );
    const base =
      "T: { Type: ScheduledTimer, DesiredRate: 10 }\nS: { Type: SinGenerator, Inputs: [T] }\n";
    expect(
      loadBlock(
        `${base}L: { Type: LinearMap, Inputs: [S], Params: { Outputs: 2, Bias: [1] } }`,
        "L",
      ).errors[0]!.message,
    ).toContain("Bias must have one value per output");
    expect(
      loadBlock(`${base}L: { Type: LinearMap, Inputs: [S] }`, "L").errors[0]!.message,
    ).toContain("give Outputs (the number of outputs) or Weights");
    expect(
      loadBlock(
        `${base}L: { Type: LinearMap, Inputs: [S], Params: { Outputs: 3, Weights: [[1]] } }`,
        "L",
      ).errors[0]!.message,
    ).toContain("Weights must have one row per output");
  });
});
