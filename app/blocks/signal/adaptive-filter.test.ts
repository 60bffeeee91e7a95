// AdaptiveFilter through BlockHarness and a tiny pipeline, against the reference loop of the
// paper's eqs. 2–4 in core-wasm/dsp/tests/fixtures/adaptive.json (gen_adaptive.py):
// |y − y_ref| <= 1e-12 · max|y_ref| per channel.
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { Frame, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, loadBlock, vectors } from "../../../tests/support/blocks";
import { memoryResources, REPO_ROOT } from "../../../tests/support/fs-resources";
import { initDspForTests } from "../../../tests/support/wasm";
import { AdaptiveFilter } from "./adaptive-filter";

beforeAll(() => initDspForTests());

type Num = number | "inf";
interface Fixture {
  inputs: { name: string; channels: number; data: number[]; times?: number[] }[];
  cases: {
    name: string;
    input: string;
    fs: number;
    G1: number;
    G2: number;
    B1: number;
    B2: number;
    order: "paper" | "mosaic";
    timed: boolean;
    y: number[];
    cutoff?: Num[];
  }[];
}

const FX = JSON.parse(
  readFileSync(join(REPO_ROOT, "core-wasm", "dsp", "tests", "fixtures", "adaptive.json"), "utf8"),
) as Fixture;

function expectClose(got: number[][], flatRef: readonly number[], channels: number, what: string) {
  expect(got.length * channels, what).toBe(flatRef.length);
  for (let c = 0; c < channels; c++) {
    let scale = 0;
    for (let e = 0; e < got.length; e++)
      scale = Math.max(scale, Math.abs(flatRef[e * channels + c]!));
    for (let e = 0; e < got.length; e++) {
      const g = got[e]![c]!;
      const r = flatRef[e * channels + c]!;
      if (Math.abs(g - r) > 1e-12 * scale) expect.fail(`${what}[${e}, ${c}]: ${g} vs ${r}`);
    }
  }
}

function inputFrame(name: string, fs: number): { frame: Frame; channels: number } {
  const inp = FX.inputs.find((i) => i.name === name)!;
  const c = inp.channels;
  const n = inp.data.length / c;
  const t = inp.times ?? Array.from({ length: n }, (_, i) => i / fs);
  const v = Array.from({ length: n }, (_, i) => inp.data.slice(i * c, (i + 1) * c));
  return { frame: Frame.from(vectorShape(c), t, v), channels: c };
}

describe("AdaptiveFilter", () => {
  test.each(FX.cases.map((c) => [c.name, c] as const))(
    "%s matches the reference loop of eqs. 2–4, in one frame and sample by sample",
    async (_name, c) => {
      const { frame, channels } = inputFrame(c.input, c.fs);
      const params = {
        G1: c.G1,
        G2: c.G2,
        B1: c.B1,
        B2: c.B2,
        Derivative: c.order,
        UseTimestamps: c.timed,
      };
      const opts = { inputs: [{ shape: vectorShape(channels), rate: c.fs }] };
      const whole = await BlockHarness.create(AdaptiveFilter, params, opts);
      whole.start();
      whole.push(frame);
      expect(whole.output().t).toEqual(Array.from(frame.t.subarray(0, frame.n)));
      expectClose(whole.output().v, c.y, channels, `${c.name} y`);

      const single = await BlockHarness.create(AdaptiveFilter, params, opts);
      single.start();
      for (let i = 0; i < frame.n; i++) {
        const f = new Frame(vectorShape(channels), 1);
        f.copyEvents(frame, i, 1, 0);
        f.n = 1;
        single.push(f);
      }
      expect(single.output().v).toEqual(whole.output().v);
      // The cut-off of the last sample is in the status line and the action.
      if (c.cutoff) {
        const last = c.cutoff[c.cutoff.length - channels]!;
        const text = single.instance.actions!.cutoff!.run() as string;
        const m = /^0: (\S+) Hz$/.exec(text.split("\n")[0]!)!;
        const got = Number(m[1]);
        if (last === "inf") expect(got).toBe(Infinity);
        else expect(Math.abs(got - last)).toBeLessThanOrEqual(1e-12 * last);
      }
      whole.clear();
      whole.instance.reset!();
      whole.push(frame);
      expectClose(whole.output().v, c.y, channels, `${c.name} y after reset`);
    },
  );

  test("ΔT is 1 / desired rate by default; UseTimestamps takes it from the events", async () => {
    const x = vectors([0, 0.001, 0.003, 0.006], [[0.2], [0.6], [0.1], [0.4]]);
    const make = (UseTimestamps: boolean) =>
      BlockHarness.create(
        AdaptiveFilter,
        { G1: 0.01, G2: 1, B1: 5, B2: 2, UseTimestamps },
        { inputs: [{ shape: vectorShape(1), rate: 1000 }] },
      );
    const a = await make(false);
    const b = await make(true);
    a.push(x);
    b.push(x);
    expect(a.output().v[1]).toEqual(b.output().v[1]); // ΔT 1 ms either way
    expect(a.output().v[3]).not.toEqual(b.output().v[3]); // 3 ms apart here
  });

  test("live G1, G2, B1, B2 keep the state", async () => {
    const h = await BlockHarness.create(
      AdaptiveFilter,
      { G1: 0, G2: 0, B2: Math.log(10) },
      { inputs: [{ shape: vectorShape(1), rate: 100 }] },
    );
    h.push(vectors([0], [[1]]));
    h.instance.setParam!("B2", Math.log(20));
    h.push(vectors([0.01], [[1]]));
    const k1 = (2 * Math.PI * 10) / 100;
    const a1 = k1 / (1 + k1);
    const k2 = (2 * Math.PI * 20) / 100;
    const a2 = k2 / (1 + k2);
    expect(h.output().v[0]![0]).toBeCloseTo(a1, 14);
    expect(h.output().v[1]![0]).toBeCloseTo(a2 + (1 - a2) * a1, 14);
    expect(() => h.instance.setParam!("B1", -1)).toThrow("B1");
  });

  test("a pipeline: FilePlayer (100 Hz envelope) → AdaptiveFilter with MOSAIC 1's positional params", async () => {
    const c = FX.cases.find((x) => x.name === "mosaic_example_mosaic_order")!;
    const inp = FX.inputs.find((i) => i.name === c.input)!;
    const rows = ["time_s,a,b"];
    for (let i = 0; i < inp.data.length / 2; i++)
      rows.push(`${i / 100},${inp.data[2 * i]},${inp.data[2 * i + 1]}`);
    const run = await runVirtualPipeline(
      `
Play: { Type: FilePlayer, Params: { File: env.csv } }
Af: { Type: AdaptiveFilter, DesiredRate: 100, Inputs: [Play], Params: ['${c.B1}', '${c.B2}', '${c.G2}', '${c.G1}'] }
`,
      {
        catalog,
        duration: 10,
        resources: memoryResources({ "env.csv": rows.join("\n") }),
        record: ["Af"],
      },
    );
    expectClose(run.outputs.get("Af")!.v, c.y, 2, "pipeline y");
    expect(run.diagnostics.some((d) => d.code === "legacy-converted" && d.block === "Af")).toBe(
      true,
    );
  });

  test("legacy [B1, B2, G2, G1] converts with Derivative: mosaic; errors", async () => {
    const base =
      "T: { Type: ScheduledTimer, DesiredRate: 200 }\nS: { Type: SinGenerator, Inputs: [T] }\n";
    expect(
      convertLegacy(
        `${base}A: { Type: AdaptiveFilter, DesiredRate: 200, Inputs: [S], Params: ['0.7', '-1', '-7', '8'] }`,
        "A",
      ),
    ).toEqual({ B1: 0.7, B2: -1, G2: -7, G1: 8, Derivative: "mosaic", UseTimestamps: false });
    const r = loadBlock(
      `${base}A: { Type: AdaptiveFilter, Inputs: [S], Params: ['0.7', '-1'] }`,
      "A",
    );
    expect(r.errors[0]!.message).toContain("expected [B1 (derivative cut-off, Hz), offset B2");
    await expect(
      BlockHarness.create(AdaptiveFilter, {}, { inputs: [{ shape: vectorShape(2), rate: 0 }] }),
    ).rejects.toThrow("AdaptiveFilter needs a sampling rate for ΔT");
    expect(AdaptiveFilter.params.parse({})).toEqual({
      G1: 8,
      G2: -7,
      B1: 0.7,
      B2: -1,
      Derivative: "paper",
      UseTimestamps: false,
    });
  });
});
