import { readFileSync } from "node:fs";
import { join } from "node:path";
import { describe, expect, test } from "vitest";
import {
  createCatalog,
  EMPTY_SHAPE,
  Frame,
  loadPipeline,
  matrixShape,
  vectorShape,
  type Shape,
} from "../../engine";
import { BlockHarness, type HarnessOptions } from "../../engine/testing";
import { BLOCKS } from "../catalog";
import { BodyRig } from "./body-rig";

interface Case {
  name: string;
  width: number;
  params: unknown;
  x: (number | null)[][];
  positions: (number | null)[][];
  orientations: (number | null)[][];
  refused: number;
}
const fx = JSON.parse(readFileSync(join(__dirname, "fixtures", "body_rig.json"), "utf8")) as {
  cases: Case[];
};

/** JSON has no NaN: the generator writes null. */
const nan = (rows: (number | null)[][]): number[][] => rows.map((r) => r.map((v) => v ?? NaN));

/** Equal within `tol`, NaN where NaN is expected (and only there). */
function expectClose(actual: number[][], expected: number[][], tol: number, what: string): void {
  expect(actual.length, what).toBe(expected.length);
  let worst = 0;
  actual.forEach((row, i) => {
    expect(row.length, `${what} event ${i}`).toBe(expected[i]!.length);
    row.forEach((v, k) => {
      const e = expected[i]![k]!;
      if (Number.isNaN(e)) expect(v, `${what} event ${i} value ${k}`).toBeNaN();
      else worst = Math.max(worst, Math.abs(v - e));
    });
  });
  expect(worst, what).toBeLessThanOrEqual(tol);
}

type HarnessInput = NonNullable<HarnessOptions["inputs"]>[number];

const vec = (c: number, rate = 100): HarnessInput => ({ shape: vectorShape(c), rate });

async function rig(params: unknown, inputs: HarnessInput[] = [vec(12)]): Promise<BlockHarness> {
  const h = await BlockHarness.create(BodyRig, params, { inputs });
  h.start();
  return h;
}

const push = (h: BlockHarness, shape: Shape, t: number[], v: number[][], port = 0): void =>
  h.push(Frame.from(shape, t, v), port);

const rec = (h: BlockHarness, port: string) => h.out.get(port)!;

describe("BodyRig against SciPy's Rotation (fixtures/gen_body_rig.py)", () => {
  test.each(fx.cases)("$name: positions and orientations within 1e-12", async (c) => {
    const h = await rig(c.params, [vec(c.width)]);
    const x = nan(c.x);
    const t = x.map((_, i) => i / 100);
    push(h, vectorShape(c.width), t, x);
    expectClose(rec(h, "positions").v, nan(c.positions), 1e-12, "positions");
    expectClose(rec(h, "orientations").v, nan(c.orientations), 1e-12, "orientations");
    expect(rec(h, "positions").t).toEqual(t);
    const refused = c.refused > 0 ? `; ${c.refused} orientations refused` : "";
    expect(h.text).toBe(`3 links from 1 input${refused}`);
    // The first refusal is warned about at once, naming the link (then one per second).
    expect(h.warnings.length > 0).toBe(c.refused > 0);
    for (const w of h.warnings) {
      expect(w).toMatch(/^link '\w+': orientation \[.*\] from input 'in0' refused/);
    }
  });

  test.each(fx.cases)("$name: one frame of n events = n frames of one", async (c) => {
    const x = nan(c.x);
    const t = x.map((_, i) => i / 100);
    const whole = await rig(c.params, [vec(c.width)]);
    push(whole, vectorShape(c.width), t, x);
    const split = await rig(c.params, [vec(c.width)]);
    x.forEach((row, i) => push(split, vectorShape(c.width), [t[i]!], [row]));
    expect(rec(split, "positions").v).toEqual(rec(whole, "positions").v);
    expect(rec(split, "orientations").v).toEqual(rec(whole, "orientations").v);
    expect(split.text).toBe(whole.text);
  });
});

describe("BodyRig conventions, by hand", () => {
  const one = { Links: [{ Name: "Bone", Length: 0.3 }] };
  const quarterZ = [Math.SQRT1_2, 0, 0, Math.SQRT1_2]; // 90° about z

  test("identity: the link lies along its Axis from Origin; the IMU turns it", async () => {
    const h = await rig({ ...one, Origin: [1, 2, 3] }, [vec(4)]);
    push(h, vectorShape(4), [0, 0.01], [[1, 0, 0, 0], quarterZ]);
    const p = rec(h, "positions").v;
    expect(p[0]).toEqual([1, 2, 3, 1.3, 2, 3]);
    expectClose([p[1]!], [[1, 2, 3, 1, 2.3, 3]], 1e-15, "turned 90° about z");
  });

  test("SensorToSegment q_ss: the segment is q_imu ⊗ q_ss⁻¹", async () => {
    // The sensor sits turned +90° about z on the segment; with the sensor at identity the
    // segment is turned −90°: its x axis points to −y.
    const h = await rig({ Links: [{ Name: "Bone", Length: 0.3, SensorToSegment: quarterZ }] }, [
      vec(4),
    ]);
    push(h, vectorShape(4), [0, 0.01], [[1, 0, 0, 0], quarterZ]);
    const p = rec(h, "positions").v;
    const o = rec(h, "orientations").v;
    expectClose([p[0]!], [[0, 0, 0, 0, -0.3, 0]], 1e-15, "sensor at identity");
    expectClose([o[0]!], [[Math.SQRT1_2, 0, 0, -Math.SQRT1_2]], 1e-15, "segment −90° about z");
    // Sensor turned like its mounting: the segment is back at identity.
    expectClose([p[1]!], [[0, 0, 0, 0.3, 0, 0]], 1e-15, "sensor at its mounting");
    expectClose([o[1]!], [[1, 0, 0, 0]], 1e-15, "segment at identity");
  });

  test("quaternions are normalised; q and −q give the same pose; orientations have w ≥ 0", async () => {
    const h = await rig(one, [vec(4)]);
    push(h, vectorShape(4), [0, 0.01], [quarterZ.map((v) => 5 * v), quarterZ.map((v) => -v)]);
    const p = rec(h, "positions").v;
    expectClose(p, [p[1]!, p[1]!], 0, "same pose");
    for (const q of rec(h, "orientations").v) expect(q[0]).toBeGreaterThan(0);
  });

  test("Output: vector [1, 3·(links+1)] and [1, 4·links], or matrix [links+1, 3] and [links, 4]", async () => {
    const shapes = async (params: object) =>
      (await rig(params)).ports.map((p) => [p.name, p.shape]);
    expect(await shapes({})).toEqual([
      ["positions", vectorShape(12)],
      ["orientations", vectorShape(12)],
    ]);
    expect(await shapes({ Output: "matrix" })).toEqual([
      ["positions", matrixShape(4, 3)],
      ["orientations", matrixShape(3, 4)],
    ]);
  });

  test("Euler input and SensorToSegmentEuler in the block's EulerSequence", async () => {
    // Yaw 90° (ZYX): the link along x turns to +y; a mounting of yaw 90° turns it back.
    const h = await rig(
      {
        Orientation: "euler",
        Links: [
          { Name: "A", Length: 1 },
          { Name: "B", Length: 1, SensorToSegmentEuler: [90, 0, 0] },
        ],
      },
      [vec(6)],
    );
    push(h, vectorShape(6), [0], [[90, 0, 0, 90, 0, 0]]);
    expectClose(rec(h, "positions").v, [[0, 0, 0, 0, 1, 0, 1, 0, 0]], 1e-15, "yaw");
  });
});

describe("BodyRig refused orientations", () => {
  test("a link keeps its last good orientation; NaN until its first; counted and warned", async () => {
    const h = await rig({});
    const good = [1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0];
    const zeroForearm = [...good];
    zeroForearm[4] = 0;
    zeroForearm[5] = NaN;
    const first = [...good];
    first.fill(0, 0, 4); // the upper arm has had no orientation yet
    push(h, vectorShape(12), [0], [first]);
    const p0 = rec(h, "positions").v[0]!;
    expect(p0.slice(0, 3)).toEqual([0, 0, 0]);
    for (const v of p0.slice(3)) expect(v).toBeNaN(); // the whole arm hangs from the upper arm
    expect(rec(h, "orientations").v[0]!.slice(4)).toEqual([1, 0, 0, 0, 1, 0, 0, 0]);
    const turned = [...good];
    turned.splice(4, 4, Math.SQRT1_2, 0, 0, Math.SQRT1_2);
    push(h, vectorShape(12), [0.01, 0.02], [turned, zeroForearm]);
    const p = rec(h, "positions").v;
    expect(p[2]).toEqual(p[1]); // the forearm held its turned orientation
    expectClose([p[2]!], [[0, 0, 0, 0.3, 0, 0, 0.3, 0.25, 0, 0.38, 0.25, 0]], 1e-15, "held");
    expect(h.text).toBe("3 links from 1 input; 2 orientations refused");
    expect(h.warnings).toHaveLength(1); // one per second of pipeline time
    expect(h.warnings[0]).toContain("link 'UpperArm': orientation [0, 0, 0, 0]");
    expect(h.warnings[0]).toContain("(its norm is zero)");
    push(h, vectorShape(12), [1.5], [zeroForearm]);
    expect(h.warnings[1]).toContain("link 'Forearm': orientation [0, NaN, 0, 0]");
    expect(h.warnings[1]).toContain("not a finite number");
    expect(h.warnings[1]).toContain("3 refusals so far");
  });

  test("reset forgets the held orientations and the count", async () => {
    const h = await rig({ Links: [{ Name: "Bone", Length: 0.3 }] }, [vec(4)]);
    push(
      h,
      vectorShape(4),
      [0, 0.01],
      [
        [1, 0, 0, 0],
        [0, 0, 0, 0],
      ],
    );
    expect(rec(h, "positions").v[1]).toEqual([0, 0, 0, 0.3, 0, 0]);
    h.instance.reset!();
    expect(h.text).toBe("1 link from 1 input");
    h.clear();
    push(h, vectorShape(4), [0.02], [[0, 0, 0, 0]]);
    for (const v of rec(h, "positions").v[0]!.slice(3)) expect(v).toBeNaN();
  });
});

describe("BodyRig with several inputs", () => {
  const params = {
    Trigger: "in1",
    Links: [
      { Name: "Upper", Length: 1 },
      { Name: "Fore", Parent: "Upper", Length: 1, Input: "in1", Channel: 2 },
    ],
  };
  const quarterZ = [Math.SQRT1_2, 0, 0, Math.SQRT1_2];

  test("events of the Trigger input emit, with the others' latest orientation", async () => {
    const h = await rig(params, [vec(4), vec(6)]);
    push(h, vectorShape(4), [0], [[1, 0, 0, 0]], 0);
    expect(rec(h, "positions").t).toEqual([]); // not the trigger
    push(h, vectorShape(6), [0.001], [[9, 9, 1, 0, 0, 0]], 1);
    push(h, vectorShape(4), [0.01], [quarterZ], 0);
    push(
      h,
      vectorShape(6),
      [0.011, 0.021],
      [
        [9, 9, 1, 0, 0, 0],
        [9, 9, ...quarterZ],
      ],
      1,
    );
    const r = rec(h, "positions");
    expect(r.t).toEqual([0.001, 0.011, 0.021]);
    expectClose(
      r.v,
      [
        [0, 0, 0, 1, 0, 0, 2, 0, 0],
        [0, 0, 0, 0, 1, 0, 1, 1, 0],
        [0, 0, 0, 0, 1, 0, 0, 2, 0],
      ],
      1e-15,
      "positions",
    );
  });

  test("the desired rate is the Trigger's", async () => {
    const h = await rig(params, [vec(4, 50), vec(6, 200)]);
    expect(h.desiredRate).toBe(200);
  });
});

describe("BodyRig refuses a bad chain, naming the link", () => {
  const issues = (links: unknown[]) => {
    const r = BodyRig.params.safeParse({ Links: links });
    expect(r.success).toBe(false);
    return r.error!.issues.map((i) => ({ path: i.path.join("."), message: i.message }));
  };

  test("duplicate names, the reserved name 'base'", () => {
    expect(
      issues([
        { Name: "A", Length: 1 },
        { Name: "A", Parent: "A", Length: 1 },
        { Name: "base", Length: 1 },
      ]),
    ).toEqual([
      {
        path: "Links.1.Name",
        message: "link 'A' is defined twice (Links[0] and Links[1]); names must be unique",
      },
      {
        path: "Links.2.Name",
        message:
          "link name 'base' is reserved for the chain's Origin in the output's channel names",
      },
      { path: "Links.1.Parent", message: "link 'A' is its own parent" },
    ]);
  });

  test("an unknown parent, with the closest name", () => {
    expect(
      issues([
        { Name: "UpperArm", Length: 1 },
        { Name: "Forearm", Parent: "UperArm", Length: 1 },
      ]),
    ).toEqual([
      {
        path: "Links.1.Parent",
        message:
          "link 'Forearm': parent 'UperArm' is not a link of this chain; did you mean 'UpperArm'? " +
          "(leave Parent out for a root link, which starts at Origin)",
      },
    ]);
  });

  test("a cycle, once, at its first link", () => {
    expect(
      issues([
        { Name: "Root", Length: 1 },
        { Name: "A", Parent: "C", Length: 1 },
        { Name: "B", Parent: "A", Length: 1 },
        { Name: "C", Parent: "B", Length: 1 },
      ]),
    ).toEqual([
      {
        path: "Links.1.Parent",
        message:
          "link 'A' is its own ancestor ('A' → 'C' → 'B' → 'A'); a chain needs a root link without Parent",
      },
    ]);
  });

  test("Length or Offset, one of them; one SensorToSegment form; no zero quaternion", () => {
    expect(
      issues([
        { Name: "A" },
        { Name: "B", Length: 1, Offset: [0, 0, 1], Axis: "y" },
        { Name: "C", Length: 1, SensorToSegment: [1, 0, 0, 0], SensorToSegmentEuler: [0, 0, 0] },
        { Name: "D", Length: 1, SensorToSegment: [0, 0, 0, 0] },
      ]).map((i) => i.path),
    ).toEqual([
      "Links.0.Length",
      "Links.1.Offset",
      "Links.1.Axis",
      "Links.2.SensorToSegmentEuler",
      "Links.3.SensorToSegment",
    ]);
  });

  test("the loader positions the error on the link's key", () => {
    const r = loadPipeline(
      [
        "T: { Type: ScheduledTimer, DesiredRate: 100 }",
        "Imu: { Type: ImuSimulator, Inputs: [T], Params: { Layout: myo } }",
        "Rig:",
        "  Type: BodyRig",
        "  Inputs: [Imu]",
        "  Params:",
        "    Links:",
        "      - { Name: Upper, Length: 0.3 }",
        "      - { Name: Fore, Parent: Uper, Length: 0.25 }",
        "",
      ].join("\n"),
      "arm.yaml",
      createCatalog(BLOCKS),
    );
    const d = r.diagnostics.find((x) => x.block === "Rig")!;
    expect(d).toMatchObject({ severity: "error", param: "Links[1].Parent", line: 9 });
    expect(d.message).toContain("parent 'Uper' is not a link of this chain; did you mean 'Upper'?");
  });

  test("EulerSequence: SciPy's forms only", () => {
    for (const bad of ["XYx", "XXY", "xyy", "XY", "abc"]) {
      expect(BodyRig.params.safeParse({ EulerSequence: bad }).success, bad).toBe(false);
    }
    for (const good of ["ZYX", "xyz", "ZXZ", "yxy"]) {
      expect(BodyRig.params.safeParse({ EulerSequence: good }).success, good).toBe(true);
    }
  });
});

describe("BodyRig refuses inputs that do not fit, naming the link and the param", () => {
  const fails = (params: unknown, inputs: HarnessInput[]) =>
    expect(BlockHarness.create(BodyRig, params, { inputs })).rejects;

  test("a slice out of the input's width", async () => {
    await fails({}, [vec(10)]).toMatchObject({
      name: "BlockConfigError",
      param: "Links[2].Channel",
      message:
        "link 'Hand': channels 8–11 (a quaternion w, x, y, z) are out of range for input 'in0' with " +
        "10 channels (valid: 0–9); by default a link reads the channels after the previous " +
        "link's on the same input (set Channel)",
    });
    await fails({ Orientation: "euler", Links: [{ Name: "A", Length: 1, Channel: 2 }] }, [
      vec(4),
    ]).toMatchObject({
      param: "Links[0].Channel",
      message: expect.stringContaining("3 Euler angles"),
    });
  });

  test("an unknown input, a timer, a matrix; an unknown Trigger; an input left unused", async () => {
    await fails({ Links: [{ Name: "A", Length: 1, Input: "imu" }] }, [vec(4)]).toMatchObject({
      param: "Links[0].Input",
      message: expect.stringMatching(/^link 'A': Input 'imu' is not one of its inputs \(in0\)/),
    });
    await fails({ Links: [{ Name: "A", Length: 1 }] }, [
      { shape: EMPTY_SHAPE, rate: 100, isTimer: true },
    ]).toMatchObject({ param: "Links[0].Input", message: expect.stringContaining("is a timer") });
    await fails({ Links: [{ Name: "A", Length: 1 }] }, [
      { shape: matrixShape(2, 4) },
    ]).toMatchObject({ message: expect.stringContaining("needs a vector") });
    await fails({ Links: [{ Name: "A", Length: 1 }], Trigger: "clock" }, [vec(4)]).toMatchObject({
      param: "Trigger",
    });
    await fails({ Links: [{ Name: "A", Length: 1 }] }, [vec(4), vec(4)]).toMatchObject({
      param: "Links",
      message:
        "input 'in1' feeds no link and is not the Trigger; name it in a link's Input, or remove it",
    });
  });

  test("a timer may be the Trigger: the pose at its rate", async () => {
    const h = await rig({ Links: [{ Name: "A", Length: 1, Input: "in1" }], Trigger: "in0" }, [
      { shape: EMPTY_SHAPE, rate: 50, isTimer: true },
      vec(4, 200),
    ]);
    push(h, vectorShape(4), [0], [[1, 0, 0, 0]], 1);
    push(h, EMPTY_SHAPE, [0.02, 0.04], [[], []], 0);
    expect(rec(h, "positions").v).toEqual([
      [0, 0, 0, 1, 0, 0],
      [0, 0, 0, 1, 0, 0],
    ]);
    expect(h.desiredRate).toBe(50);
  });
});
