// The feature blocks through BlockHarness and tiny pipelines, against the NumPy definitions of
// core-wasm/dsp/tests/fixtures/features.json (gen_features.py): sums within 1e-12 relative, counts
// exact, NaN where the reference is NaN.
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { Frame, matrixShape, vectorShape, type AnyBlockDefinition } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, loadBlock, vectors } from "../../../tests/support/blocks";
import { fsResources, memoryResources, REPO_ROOT } from "../../../tests/support/fs-resources";
import { initDspForTests } from "../../../tests/support/wasm";
import { Dasdv } from "./dasdv";
import { FeatureSet } from "./feature-set";
import { IntegratedAbsoluteValue } from "./integrated-absolute-value";
import { MeanAbsoluteValue } from "./mean-absolute-value";
import { Rms } from "./rms";
import { SlopeSignChanges } from "./slope-sign-changes";
import { Variance } from "./variance";
import { WaveformLength } from "./waveform-length";
import { WillisonAmplitude } from "./willison-amplitude";
import { ZeroCrossings } from "./zero-crossings";

beforeAll(() => initDspForTests());

type Num = number | "nan";
const num = (v: Num): number => (v === "nan" ? NaN : v);

interface Fixture {
  features: string[];
  streams: { name: string; channels: number; data: Num[] }[];
  cases: {
    stream: string;
    length: number;
    step: number;
    thresholds: { ZC: number; SSC: number; WAMP: number };
    ends: number[];
    expected: Num[];
  }[];
  recording: {
    length: number;
    step: number;
    thresholds: { ZC: number; SSC: number; WAMP: number };
    windows: number;
    expected: Num[];
  };
}

const FX = JSON.parse(
  readFileSync(join(REPO_ROOT, "core-wasm", "dsp", "tests", "fixtures", "features.json"), "utf8"),
) as Fixture;

/** Block, feature name in the fixture, params for a case's thresholds. */
const BLOCKS: [
  AnyBlockDefinition,
  string,
  (t: Fixture["cases"][number]["thresholds"]) => object,
][] = [
  [MeanAbsoluteValue, "MAV", () => ({})],
  [Rms, "RMS", () => ({})],
  [WaveformLength, "WL", () => ({})],
  [ZeroCrossings, "ZC", (t) => ({ Threshold: t.ZC })],
  [SlopeSignChanges, "SSC", (t) => ({ Threshold: t.SSC })],
  [SlopeSignChanges, "SSC_MOSAIC", (t) => ({ Threshold: t.SSC, Rule: "mosaic" })],
  [Variance, "VAR", () => ({})],
  [IntegratedAbsoluteValue, "IAV", () => ({})],
  [Dasdv, "DASDV", () => ({})],
  [WillisonAmplitude, "WAMP", (t) => ({ Threshold: t.WAMP })],
];

const COUNTS = new Set(["ZC", "SSC", "SSC_MOSAIC", "WAMP"]);

/** Expected values of one feature of a case: per window, C values. */
function expectedOf(expected: readonly Num[], feature: string, channels: number): number[][] {
  const f = FX.features.indexOf(feature);
  const per = FX.features.length * channels;
  const out: number[][] = [];
  for (let w = 0; w * per < expected.length; w++) {
    out.push(expected.slice(w * per + f * channels, w * per + (f + 1) * channels).map(num));
  }
  return out;
}

function expectClose(got: number[][], want: number[][], feature: string, what: string): void {
  expect(got.length, what).toBe(want.length);
  for (let w = 0; w < want.length; w++) {
    for (let c = 0; c < want[w]!.length; c++) {
      const g = got[w]![c]!;
      const e = want[w]![c]!;
      const where = `${what}: window ${w} channel ${c}`;
      if (Number.isNaN(e)) expect(g, where).toBeNaN();
      else if (COUNTS.has(feature)) expect(g, where).toBe(e);
      else if (Math.abs(g - e) > 1e-12 * Math.abs(e)) expect.fail(`${where}: ${g} vs ${e}`);
    }
  }
}

/** The stream of a case as vector events at 1 kHz (t = i / 1000). */
function streamFrame(name: string): { frame: Frame; channels: number } {
  const s = FX.streams.find((x) => x.name === name)!;
  const c = s.channels;
  const n = s.data.length / c;
  const t = Array.from({ length: n }, (_, i) => i / 1000);
  const v = Array.from({ length: n }, (_, i) => s.data.slice(i * c, (i + 1) * c).map(num));
  return { frame: Frame.from(vectorShape(c), t, v), channels: c };
}

/** The windows of a case as matrix events stamped with their newest sample's time. */
function windowFrame(caseIndex: number): Frame {
  const k = FX.cases[caseIndex]!;
  const s = FX.streams.find((x) => x.name === k.stream)!;
  const c = s.channels;
  const values = k.ends.map((end) =>
    s.data.slice((end + 1 - k.length) * c, (end + 1) * c).map(num),
  );
  return Frame.from(
    matrixShape(k.length, c),
    k.ends.map((e) => e / 1000),
    values,
  );
}

describe("feature blocks on window matrices and on plain streams", () => {
  test.each(BLOCKS.map(([def, f, p], i) => [`${def.type} (${f})`, i, def, f, p] as const))(
    "%s matches NumPy in both input forms, on every fixture case",
    async (_name, _i, def, feature, paramsOf) => {
      for (let ci = 0; ci < FX.cases.length; ci++) {
        const k = FX.cases[ci]!;
        const { frame, channels } = streamFrame(k.stream);
        const want = expectedOf(k.expected, feature, channels);
        const what = `${def.type} ${k.stream} L=${k.length} S=${k.step}`;

        // Window matrices (as from SlidingWindow).
        const hw = await BlockHarness.create(def, paramsOf(k.thresholds), {
          inputs: [{ shape: matrixShape(k.length, channels), rate: 1000 / k.step }],
        });
        hw.start();
        hw.push(windowFrame(ci));
        expect(hw.ports[0]!.shape).toEqual(vectorShape(channels));
        expect(hw.output().t).toEqual(k.ends.map((e) => e / 1000));
        expectClose(hw.output().v, want, feature, `${what} (windows)`);
        hw.instance.dispose?.();

        // A plain stream with Window and Hop, fed in uneven frames.
        const hs = await BlockHarness.create(
          def,
          { ...paramsOf(k.thresholds), Window: k.length, Hop: k.step },
          { inputs: [{ shape: vectorShape(channels), rate: 1000 }] },
        );
        hs.start();
        expect(hs.desiredRate).toBe(1000 / k.step);
        let at = 0;
        for (const size of [1, 5, 200, 37, 1000]) {
          const n = Math.min(size, frame.n - at);
          if (n <= 0) break;
          const part = new Frame(vectorShape(channels), n);
          part.copyEvents(frame, at, n, 0);
          part.n = n;
          hs.push(part);
          at += n;
        }
        expect(at).toBe(frame.n);
        expect(hs.output().t).toEqual(k.ends.map((e) => e / 1000));
        expectClose(hs.output().v, want, feature, `${what} (stream)`);
        // reset empties the window: the output repeats.
        const first = hs.output().v.map((r) => [...r]);
        hs.clear();
        hs.instance.reset?.();
        hs.push(frame);
        expect(hs.output().v).toEqual(first);
        hs.instance.dispose?.();
      }
    },
  );

  test("FeatureSet computes any subset in one pass, feature-major, thresholds per feature", async () => {
    const ci = 1;
    const k = FX.cases[ci]!;
    const { channels } = streamFrame(k.stream);
    const features = ["MAV", "WAMP", "SSC", "RMS", "ZC", "VAR", "IAV", "DASDV", "WL"] as const;
    const h = await BlockHarness.create(
      FeatureSet,
      {
        Features: features,
        ZCThreshold: k.thresholds.ZC,
        SSCThreshold: k.thresholds.SSC,
        WAMPThreshold: k.thresholds.WAMP,
      },
      { inputs: [{ shape: matrixShape(k.length, channels) }] },
    );
    h.start();
    h.push(windowFrame(ci));
    expect(h.ports[0]!.shape).toEqual(vectorShape(features.length * channels));
    const rows = h.output().v;
    features.forEach((f, j) => {
      const got = rows.map((r) => r.slice(j * channels, (j + 1) * channels));
      expectClose(got, expectedOf(k.expected, f, channels), f, `FeatureSet ${f}`);
    });
    h.instance.dispose?.();

    // The default is LibEMG's HTD set [MAV, ZC, SSC, WL]; SSCRule mosaic selects MOSAIC 1's rule.
    const d = await BlockHarness.create(
      FeatureSet,
      { SSCRule: "mosaic", SSCThreshold: k.thresholds.SSC, ZCThreshold: k.thresholds.ZC },
      { inputs: [{ shape: matrixShape(k.length, channels) }] },
    );
    expect((d.params as { Features: string[] }).Features).toEqual(["MAV", "ZC", "SSC", "WL"]);
    d.start();
    d.push(windowFrame(ci));
    const ssc = d.output().v.map((r) => r.slice(2 * channels, 3 * channels));
    expectClose(ssc, expectedOf(k.expected, "SSC_MOSAIC", channels), "SSC_MOSAIC", "HTD SSC");
    d.instance.dispose?.();
    expect(FeatureSet.params.safeParse({ Features: ["MAV", "MAV"] }).success).toBe(false);
  });

  test("live thresholds: a plain-stream block keeps its window history", async () => {
    const h = await BlockHarness.create(
      WillisonAmplitude,
      { Threshold: 0, Window: 4, Hop: 2 },
      { inputs: [{ shape: vectorShape(1), rate: 100 }] },
    );
    h.start();
    h.push(vectors([0, 1, 2], [[0], [1], [3]]));
    h.instance.setParam!("Threshold", 1.5);
    h.push(vectors([3, 4, 5], [[3.5], [3.5], [0]]));
    // Windows [0,1,3,3.5] (|Δ| 1, 2, 0.5 → 1 at T 1.5) and [3,3.5,3.5,0] (0.5, 0, 3.5 → 1).
    expect(h.output().v).toEqual([[1], [1]]);
    expect(h.output().t).toEqual([3, 5]);
    const m = await BlockHarness.create(
      ZeroCrossings,
      { Threshold: 0 },
      { inputs: [{ shape: matrixShape(3, 1) }] },
    );
    m.start();
    m.instance.setParam!("Threshold", 5);
    m.push(Frame.from(matrixShape(3, 1), [0], [[1, -1, 1]]));
    expect(m.output().v).toEqual([[0]]);
  });

  test("errors name the input and the fix", async () => {
    await expect(
      BlockHarness.create(MeanAbsoluteValue, {}, { inputs: [{ shape: vectorShape(3) }] }),
    ).rejects.toThrow(
      "input 'in0' is a plain stream [1, 3]: set Window (and Hop) so that MeanAbsoluteValue " +
        "windows it, or feed it windows from a SlidingWindow block",
    );
    await expect(
      BlockHarness.create(Rms, { Window: 10 }, { inputs: [{ shape: matrixShape(20, 3) }] }),
    ).rejects.toThrow(
      "already carries windows [20, 3]; Window and Hop are only for a plain stream",
    );
    const base =
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\nS: { Type: SinGenerator, Inputs: [T] }\n";
    const r = loadBlock(`${base}R: { Type: RMS, Inputs: [S], Params: { Window: 1 } }`, "R");
    expect(r.errors[0]!.param).toBe("Window");
  });

  test("legacy forms: ZC and SSC [threshold] (SSC with MOSAIC 1's rule), MAV and WL without params", () => {
    const base =
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\nS: { Type: SinGenerator, Inputs: [T] }\n" +
      "W: { Type: SlidingWindow, Inputs: [S], Params: { Length: 10 } }\n";
    expect(
      convertLegacy(`${base}Z: { Type: ZeroCrossings, Inputs: [W], Params: [0.02] }`, "Z"),
    ).toEqual({ Threshold: 0.02 });
    expect(
      convertLegacy(`${base}Z: { Type: SlopeSignChanges, Inputs: [W], Params: ['0.5'] }`, "Z"),
    ).toEqual({ Threshold: 0.5, Rule: "mosaic" });
    expect(
      convertLegacy(`${base}Z: { Type: MeanAbsoluteValue, Inputs: [W], Params: [] }`, "Z"),
    ).toEqual({});
    expect(
      convertLegacy(`${base}Z: { Type: WaveformLength, Inputs: [W], Params: [''] }`, "Z"),
    ).toEqual({});
  });
});

describe("feature pipelines on the real recording", () => {
  const r = FX.recording;
  const yaml = (features: string) => `
Play: { Type: FilePlayer, Params: { File: pipelines/data/emg_bursts_1000hz.csv } }
Win: { Type: SlidingWindow, Inputs: [Play], Params: { Length: ${r.length}, Step: ${r.step} } }
Set: { Type: FeatureSet, Inputs: [Win], Params: { Features: [${features}], ZCThreshold: ${r.thresholds.ZC}, SSCThreshold: ${r.thresholds.SSC}, WAMPThreshold: ${r.thresholds.WAMP} } }
Rms: { Type: RMS, Inputs: [Play], Params: { Window: ${r.length}, Hop: ${r.step} } }
Wl: { Type: WaveformLength, Inputs: [Win] }
`;

  test("FilePlayer → SlidingWindow → FeatureSet / WaveformLength, and FilePlayer → RMS(Window, Hop), match NumPy", async () => {
    const features = FX.features.filter((f) => f !== "SSC_MOSAIC");
    const run = await runVirtualPipeline(yaml(features.join(", ")), {
      catalog,
      duration: 30,
      resources: fsResources(),
      record: ["Set", "Rms", "Wl"],
    });
    const set = run.outputs.get("Set")!;
    expect(set.t).toHaveLength(r.windows);
    // Window k ends at sample L − 1 + k·S, whose time is (L − 1 + k·S) ms.
    expect(set.t[0]).toBeCloseTo((r.length - 1) / 1000, 9);
    features.forEach((f, j) => {
      const got = set.v.map((row) => [row[j]!]);
      expectClose(got, expectedOf(r.expected, f, 1), f, `pipeline FeatureSet ${f}`);
    });
    const rms = run.outputs.get("Rms")!;
    expect(rms.t).toEqual(set.t);
    expectClose(rms.v, expectedOf(r.expected, "RMS", 1), "RMS", "pipeline RMS");
    expectClose(run.outputs.get("Wl")!.v, expectedOf(r.expected, "WL", 1), "WL", "pipeline WL");
    // Rates: 1000 Hz / 50.
    const node = run.runtime.nodes.find((n) => n.name === "Rms")!;
    expect(node.desiredRate).toBeCloseTo(1000 / r.step, 9);
  });

  test("a MOSAIC 1 file: SlidingWindow, ZeroCrossings and SlopeSignChanges in positional form", async () => {
    const text =
      "time_s,a\n" +
      Array.from({ length: 12 }, (_, i) => `${i / 100},${[1, -1, 2, -2, 0.5, 3][i % 6]}`).join(
        "\n",
      );
    const run = await runVirtualPipeline(
      `
Play: { Type: FilePlayer, Params: [r.csv] }
Win: { Type: SlidingWindow, Inputs: [Play], Params: ['6', '6', 'Rectangular'] }
Zc: { Type: ZeroCrossings, Inputs: [Win], Params: ['1.5'] }
Ssc: { Type: SlopeSignChanges, Inputs: [Win], Params: ['1'] }
`,
      { catalog, duration: 1, resources: memoryResources({ "r.csv": text }) },
    );
    // [1, −1, 2, −2, 0.5, 3]: ZC with |Δ| ≥ 1.5: (1,−1) 2, (−1,2) 3, (2,−2) 4, (−2,0.5) 2.5 → 4.
    expect(run.outputs.get("Zc")!.v).toEqual([[4], [4]]);
    // MOSAIC 1's SSC: slopes −2, 3, −4, 2.5, 2.5: sign changes at 1, 2, 3 (both |Δ| ≥ 1) → 3.
    expect(run.outputs.get("Ssc")!.v).toEqual([[3], [3]]);
    expect(run.diagnostics.filter((d) => d.code === "legacy-converted")).toHaveLength(4);
  });
});
