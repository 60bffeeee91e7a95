import { describe, expect, test } from "vitest";
import { matrixShape, vectorShape, type Shape } from "../../engine";
import { BlockHarness } from "../../engine/testing";
import { convertLegacy, loadBlock, matrices, vectors } from "../../../tests/support/blocks";
import { VectorialFunction } from "./vectorial-function";

type V3 = [number, number, number];

const vec = (c: number) => ({ shape: vectorShape(c), rate: 100 });

async function run(
  params: object,
  inputs: { shape: Shape; rate?: number }[],
  feed: (h: BlockHarness) => void,
): Promise<{ t: number[]; v: number[][] }> {
  const h = await BlockHarness.create(VectorialFunction, params, { inputs });
  h.start();
  feed(h);
  return h.output();
}

/** Rodrigues' formula: v rotated by θ about the unit axis k (independent of the matrix code). */
function rodrigues(v: V3, k: V3, th: number): V3 {
  const c = Math.cos(th);
  const s = Math.sin(th);
  const kxv: V3 = [k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2], k[0] * v[1] - k[1] * v[0]];
  const kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
  return [0, 1, 2].map((i) => v[i]! * c + kxv[i]! * s + k[i]! * kv * (1 - c)) as V3;
}

/** Roll about x, then pitch about y, then yaw about z (fixed axes). */
const rpy = (v: V3, roll: number, pitch: number, yaw: number): V3 =>
  rodrigues(rodrigues(rodrigues(v, [1, 0, 0], roll), [0, 1, 0], pitch), [0, 0, 1], yaw);

const cross = (a: V3, b: V3): V3 => [
  a[1] * b[2] - a[2] * b[1],
  a[2] * b[0] - a[0] * b[2],
  a[0] * b[1] - a[1] * b[0],
];

function expectClose(actual: number[][], expected: number[][], tol = 1e-12): void {
  expect(actual.length).toBe(expected.length);
  actual.forEach((row, i) => {
    expect(row.length).toBe(expected[i]!.length);
    row.forEach((x, j) => expect(Math.abs(x - expected[i]![j]!)).toBeLessThan(tol));
  });
}

const base =
  "T: { Type: ScheduledTimer, DesiredRate: 10 }\n" +
  "A: { Type: SinGenerator, Inputs: [T], Params: { Components: 3 } }\n" +
  "B: { Type: SinGenerator, Inputs: [T], Params: { Components: 3 } }\n";

describe("VectorialFunction: rotate", () => {
  test("quarter turns about each axis, by hand", async () => {
    const h = Math.PI / 2;
    const one = async (p: object, v: V3) =>
      (await run({ Operation: "rotate", ...p }, [vec(3)], (x) => x.push(vectors([0], [v])))).v[0]!;
    expectClose([await one({ Yaw: h }, [1, 0, 0])], [[0, 1, 0]]); // z: x → y
    expectClose([await one({ Roll: h }, [0, 1, 0])], [[0, 0, 1]]); // x: y → z
    expectClose([await one({ Pitch: h }, [0, 0, 1])], [[1, 0, 0]]); // y: z → x
    // Roll first, then yaw (fixed axes): y → z (roll) → z (yaw leaves z alone).
    expectClose([await one({ Roll: h, Yaw: h }, [0, 1, 0])], [[0, 0, 1]]);
    // Yaw applied last: x → x (roll) → y (yaw).
    expectClose([await one({ Roll: h, Yaw: h }, [1, 0, 0])], [[0, 1, 0]]);
  });

  test("a hand-computed rotation: Rz(yaw)·Ry(pitch)·Rx(roll) at 30°, 45°, 60°", async () => {
    // Rz(60°)·Ry(45°)·Rx(30°) multiplied out by hand, in closed form.
    const r2 = Math.SQRT2;
    const r3 = Math.sqrt(3);
    const r6 = Math.sqrt(6);
    const R = [
      [r2 / 4, r2 / 8 - 3 / 4, r6 / 8 + r3 / 4],
      [r6 / 4, r6 / 8 + r3 / 4, (3 * r2) / 8 - 1 / 4],
      [-r2 / 2, r2 / 4, r6 / 4],
    ];
    const v: V3 = [1, 2, 3];
    const want = R.map((row) => row[0]! * v[0] + row[1]! * v[1] + row[2]! * v[2]);
    const got = await run(
      { Operation: "rotate", Roll: Math.PI / 6, Pitch: Math.PI / 4, Yaw: Math.PI / 3 },
      [vec(3)],
      (h) => h.push(vectors([0], [v])),
    );
    expectClose(got.v, [want]);
  });

  test("agrees with Rodrigues' formula applied axis by axis, on [1, 3k] vectors and [R, 3] matrices", async () => {
    const [roll, pitch, yaw] = [0.3, -1.1, 2.5];
    const a: V3 = [0.5, -2, 1.25];
    const b: V3 = [-3, 0.25, 4];
    const v6 = await run(
      { Operation: "rotate", Roll: roll, Pitch: pitch, Yaw: yaw },
      [vec(6)],
      (h) =>
        h.push(
          vectors(
            [0, 1],
            [
              [...a, ...b],
              [...b, ...a],
            ],
          ),
        ),
    );
    expectClose(v6.v, [
      [...rpy(a, roll, pitch, yaw), ...rpy(b, roll, pitch, yaw)],
      [...rpy(b, roll, pitch, yaw), ...rpy(a, roll, pitch, yaw)],
    ]);
    const m = await run(
      { Operation: "rotate", Roll: roll, Pitch: pitch, Yaw: yaw },
      [{ shape: matrixShape(2, 3) }],
      (h) => h.push(matrices([0], [[a, b]])),
    );
    expectClose(m.v, [[...rpy(a, roll, pitch, yaw), ...rpy(b, roll, pitch, yaw)]]);
  });

  test("Roll, Pitch and Yaw can be changed while running", async () => {
    const h = await BlockHarness.create(
      VectorialFunction,
      { Operation: "rotate" },
      { inputs: [vec(3)] },
    );
    h.start();
    h.push(vectors([0], [[1, 0, 0]]));
    h.instance.setParam!("Yaw", Math.PI);
    h.push(vectors([1], [[1, 0, 0]]));
    expectClose(h.output().v, [
      [1, 0, 0],
      [-1, 0, 0],
    ]);
    expect(() => h.instance.setParam!("Matrix", [[1]])).toThrow("only by matmul and wrench");
  });

  test("a width that is not a multiple of 3 is refused at load, naming the input", async () => {
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "rotate" }, { inputs: [vec(4)] }),
    ).rejects.toThrow(
      "rotate: input 'in0' has shape [1, 4]; expected a width that is a multiple of 3",
    );
  });
});

describe("VectorialFunction: one-input operations", () => {
  test("norm: the L2 norm of a vector, or of every row of a matrix", async () => {
    expect(
      (
        await run({ Operation: "norm" }, [vec(2)], (h) =>
          h.push(
            vectors(
              [0, 1],
              [
                [3, 4],
                [-5, 12],
              ],
            ),
          ),
        )
      ).v,
    ).toEqual([[5], [13]]);
    const h = await BlockHarness.create(
      VectorialFunction,
      { Operation: "norm" },
      {
        inputs: [{ shape: matrixShape(2, 2) }],
      },
    );
    h.start();
    h.push(
      matrices(
        [0],
        [
          [
            [3, 4],
            [0, -2],
          ],
        ],
      ),
    );
    expect(h.ports[0]!.shape).toEqual(matrixShape(2, 1));
    expect(h.output().v).toEqual([[5, 2]]);
  });

  test("matmul: y = M·x, per row of a matrix", async () => {
    const M = [
      [1, 2, 3],
      [0, -1, 0.5],
    ];
    const h = await BlockHarness.create(
      VectorialFunction,
      { Operation: "matmul", Matrix: M },
      {
        inputs: [vec(3)],
      },
    );
    h.start();
    h.push(vectors([0], [[1, 1, 2]]));
    expect(h.ports[0]!.shape).toEqual(vectorShape(2));
    expect(h.output().v).toEqual([[9, 0]]);
    h.instance.setParam!("Matrix", [
      [1, 0, 0],
      [0, 0, 1],
    ]);
    h.push(vectors([1], [[7, 8, 9]]));
    expect(h.output().v[1]).toEqual([7, 9]);
    expect(() => h.instance.setParam!("Matrix", [[1, 0, 0]])).toThrow("Matrix must stay 2 × 3");
    const m = await run({ Operation: "matmul", Matrix: M }, [{ shape: matrixShape(2, 3) }], (x) =>
      x.push(
        matrices(
          [0],
          [
            [
              [1, 0, 0],
              [0, 0, 2],
            ],
          ],
        ),
      ),
    );
    expect(m.v).toEqual([[1, 0, 6, 1]]);
  });

  test("matmul: a missing Matrix or one of the wrong width is refused at load", async () => {
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "matmul" }, { inputs: [vec(3)] }),
    ).rejects.toThrow("matmul needs Matrix: K rows of 3 numbers");
    await expect(
      BlockHarness.create(
        VectorialFunction,
        { Operation: "matmul", Matrix: [[1, 2]] },
        { inputs: [vec(3)] },
      ),
    ).rejects.toThrow("Matrix is 1 × 2, but input 'in0' has width 3; expected rows of 3 numbers");
  });

  test("integrate: trapezoidal rule over event timestamps (exact for a ramp), reset zeroes it", async () => {
    // x(t) = 2t + 1 sampled unevenly; ∫0^T x dt = T² + T.
    const times = [0, 0.1, 0.25, 0.3, 0.7, 1];
    const h = await BlockHarness.create(
      VectorialFunction,
      { Operation: "integrate" },
      {
        inputs: [vec(2)],
      },
    );
    h.start();
    h.push(
      vectors(
        times,
        times.map((t) => [2 * t + 1, -1]),
      ),
    );
    expectClose(
      h.output().v,
      times.map((t) => [t * t + t, -t]),
    );
    h.clear();
    h.instance.reset!();
    h.push(
      vectors(
        [5, 5, 6],
        [
          [1, 1],
          [3, 3],
          [3, 3],
        ],
      ),
    ); // a repeated timestamp adds nothing
    expect(h.output().v).toEqual([
      [0, 0],
      [0, 0],
      [3, 3],
    ]);
  });

  test("integrate: Integration: sum adds the inputs without Δt (MOSAIC)", async () => {
    const r = await run({ Operation: "integrate", Integration: "sum" }, [vec(1)], (h) =>
      h.push(vectors([0, 1, 2], [[1], [2], [3]])),
    );
    expect(r.v).toEqual([[1], [3], [6]]);
  });
});

describe("VectorialFunction: wrench", () => {
  test("identity by default; a second input r moves the torque reference: τ − r × f", async () => {
    const w = [1, 2, 3, 0.5, -0.5, 0];
    expect(
      (await run({ Operation: "wrench" }, [vec(6)], (h) => h.push(vectors([0], [w])))).v,
    ).toEqual([w]);
    const h = await BlockHarness.create(
      VectorialFunction,
      { Operation: "wrench" },
      {
        inputs: [vec(6), vec(3)],
      },
    );
    h.start();
    h.push(vectors([0], [w]));
    expect(h.output().v).toEqual([]); // waits for r
    expect(h.text).toBe("waiting for in1");
    h.push(vectors([0.5], [[1, 0, 0]]), 1);
    h.push(vectors([1], [w]));
    // r × f = [1,0,0] × [1,2,3] = [0, −3, 2] → τ' = [0.5, 2.5, −2]
    expect(h.output().v).toEqual([[1, 2, 3, 0.5, 2.5, -2]]);
  });

  test("a sensor frame change M = [[R, 0], [[p]×R, R]] matches f' = R f, τ' = R τ + p × R f", async () => {
    const R = [
      [0, -1, 0],
      [1, 0, 0],
      [0, 0, 1],
    ]; // yaw 90°
    const p: V3 = [0.1, -0.2, 0.3];
    const px = [
      [0, -p[2], p[1]],
      [p[2], 0, -p[0]],
      [-p[1], p[0], 0],
    ];
    const pxR = px.map((row) =>
      [0, 1, 2].map((j) => row[0]! * R[0]![j]! + row[1]! * R[1]![j]! + row[2]! * R[2]![j]!),
    );
    const M = [
      ...R.map((row) => [...row, 0, 0, 0]),
      ...[0, 1, 2].map((i) => [...pxR[i]!, ...R[i]!]),
    ];
    const f: V3 = [2, -1, 4];
    const tau: V3 = [0.3, 0.7, -0.2];
    const mul = (v: V3): V3 =>
      R.map((row) => row[0]! * v[0] + row[1]! * v[1] + row[2]! * v[2]) as V3;
    const Rf = mul(f);
    const Rt = mul(tau);
    const pRf = cross(p, Rf);
    const want = [...Rf, Rt[0] + pRf[0], Rt[1] + pRf[1], Rt[2] + pRf[2]];
    const got = await run({ Operation: "wrench", Matrix: M }, [vec(6)], (h) =>
      h.push(vectors([0], [[...f, ...tau]])),
    );
    expectClose(got.v, [want], 1e-14);
  });

  test("wrench needs width 6 and a 6 × 6 Matrix", async () => {
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "wrench" }, { inputs: [vec(3)] }),
    ).rejects.toThrow("wrench: input 'in0' has shape [1, 3]; expected width 6");
    await expect(
      BlockHarness.create(
        VectorialFunction,
        { Operation: "wrench", Matrix: [[1, 2, 3, 4, 5, 6]] },
        { inputs: [vec(6)] },
      ),
    ).rejects.toThrow("wrench needs a 6 × 6 matrix");
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "wrench" }, { inputs: [vec(6), vec(2)] }),
    ).rejects.toThrow("the second input 'in1' has shape [1, 2]; expected [1, 3]");
  });
});

describe("VectorialFunction: two-input operations", () => {
  async function binary(op: string, a: number[][], b: number[], aShape?: Shape) {
    const h = await BlockHarness.create(
      VectorialFunction,
      { Operation: op },
      {
        inputs: [{ shape: aShape ?? vectorShape(a[0]!.length) }, vec(b.length)],
      },
    );
    h.start();
    h.push(Frame2(aShape, [0], a)); // before the operand: nothing
    expect(h.output().v).toEqual([]);
    h.push(vectors([0.5], [b]), 1);
    h.push(Frame2(aShape, [1], a));
    return h.output().v;
  }
  const Frame2 = (shape: Shape | undefined, t: number[], a: number[][]) =>
    shape && shape.rows > 1 ? matrices(t, [a]) : vectors(t, a);

  test("add, subtract (first − second), cross (first × second), dot", async () => {
    expect(await binary("add", [[1, 2, 3]], [10, 20, 30])).toEqual([[11, 22, 33]]);
    expect(await binary("subtract", [[1, 2, 3]], [10, 20, 30])).toEqual([[-9, -18, -27]]);
    expect(await binary("cross", [[1, 0, 0]], [0, 1, 0])).toEqual([[0, 0, 1]]);
    expect(await binary("cross", [[0, 1, 0]], [1, 0, 0])).toEqual([[0, 0, -1]]);
    const a: V3 = [1.5, -2, 0.25];
    const b: V3 = [3, 4, -5];
    expect(await binary("cross", [a], b)).toEqual([cross(a, b)]);
    expect(await binary("dot", [[1, 2, 3]], [4, -5, 6])).toEqual([[12]]);
  });

  test("a [1, C] second input applies to every row of a matrix", async () => {
    expect(
      await binary(
        "subtract",
        [
          [1, 2],
          [3, 4],
        ],
        [1, 1],
        matrixShape(2, 2),
      ),
    ).toEqual([[0, 1, 2, 3]]);
    expect(
      await binary(
        "dot",
        [
          [1, 2],
          [3, 4],
        ],
        [1, -1],
        matrixShape(2, 2),
      ),
    ).toEqual([[-1, -1]]);
  });

  test("the second input is sampled and held; the block emits on the first input only", async () => {
    const h = await BlockHarness.create(
      VectorialFunction,
      { Operation: "add" },
      {
        inputs: [vec(2), vec(2)],
      },
    );
    h.start();
    h.push(
      vectors(
        [0, 0.1],
        [
          [1, 1],
          [2, 2],
        ],
      ),
      1,
    );
    expect(h.output().v).toEqual([]);
    h.push(
      vectors(
        [0.2, 0.3],
        [
          [0, 0],
          [5, 5],
        ],
      ),
    );
    expect(h.output().t).toEqual([0.2, 0.3]);
    expect(h.output().v).toEqual([
      [2, 2],
      [7, 7],
    ]);
    expect(h.text).toBe("");
    h.instance.reset!();
    expect(h.text).toBe("waiting for in1");
  });

  test("wrong arity and widths are refused at load, naming the input and the expected width", async () => {
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "subtract" }, { inputs: [vec(3)] }),
    ).rejects.toThrow("subtract needs two inputs (first − second); it has only 'in0'");
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "norm" }, { inputs: [vec(3), vec(3)] }),
    ).rejects.toThrow("norm takes one input; remove the second input 'in1'");
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "cross" }, { inputs: [vec(4), vec(3)] }),
    ).rejects.toThrow("cross: input 'in0' has shape [1, 4]; expected width 3");
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "add" }, { inputs: [vec(3), vec(4)] }),
    ).rejects.toThrow(
      "add: the second input 'in1' has shape [1, 4]; expected [1, 3], the width of the first input 'in0'",
    );
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "dot" }, { inputs: [vec(3), vec(2)] }),
    ).rejects.toThrow("expected [1, 3]");
    await expect(
      BlockHarness.create(VectorialFunction, { Operation: "norm", Yaw: 1 }, { inputs: [vec(3)] }),
    ).rejects.toThrow("Yaw is used only by rotate, not by norm");
  });
});

describe("VectorialFunction: MOSAIC's positional form", () => {
  const conv = (p: string, inputs = "[A, B]") =>
    convertLegacy(`${base}V: { Type: VectorialFunction, Inputs: ${inputs}, Params: ${p} }\n`, "V");

  test("operation names are converted", () => {
    expect(conv("[subtract]")).toMatchObject({ Operation: "subtract" });
    expect(conv("[addVectors]")).toMatchObject({ Operation: "add" });
    expect(conv("[crossVector]")).toMatchObject({ Operation: "cross" });
    expect(conv("[scalarProduct]")).toMatchObject({ Operation: "dot" });
    expect(conv("[absolute_value]", "[A]")).toMatchObject({ Operation: "norm" });
    expect(conv("[integrate]", "[A]")).toMatchObject({
      Operation: "integrate",
      Integration: "sum",
    });
    expect(conv("['rotation:0.1;0.2;0.3']", "[A]")).toEqual({
      Operation: "rotate",
      Roll: 0.1,
      Pitch: 0.2,
      Yaw: 0.3,
      Integration: "trapezoid",
    });
  });

  test("unknown operations and bad angles say what was expected", () => {
    const r = loadBlock(
      `${base}V: { Type: VectorialFunction, Inputs: [A, B], Params: [subtrac] }\n`,
      "V",
    );
    expect(r.errors[0]!.message).toContain("did you mean 'subtract'?");
    const a = loadBlock(
      `${base}V: { Type: VectorialFunction, Inputs: [A], Params: ['rotation:1;2'] }\n`,
      "V",
    );
    expect(a.errors[0]!.message).toContain("rotation needs three angles roll;pitch;yaw");
  });
});
