import { readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { Frame, matrixShape, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, loadBlock, vectors } from "../../../tests/support/blocks";
import { memoryResources, REPO_ROOT } from "../../../tests/support/fs-resources";
import { initDspForTests } from "../../../tests/support/wasm";
import { SlidingWindow } from "./sliding-window";

beforeAll(() => initDspForTests());

interface WindowFixture {
  coefficients: { name: "hann" | "hamming" | "blackman"; size: number; values: number[] }[];
  stream: { channels: number; data: number[] };
  tapered: {
    name: "hann" | "hamming" | "blackman";
    length: number;
    step: number;
    ends: number[];
    expected: number[];
  }[];
}

const FX = JSON.parse(
  readFileSync(join(REPO_ROOT, "core-wasm", "dsp", "tests", "fixtures", "window.json"), "utf8"),
) as WindowFixture;

/** n events of `channels` values: event i, channel c = 10·i + c; t = i / 100. */
function ramp(n: number, channels: number, from = 0): Frame {
  const t = Array.from({ length: n }, (_, i) => (from + i) / 100);
  const v = Array.from({ length: n }, (_, i) =>
    Array.from({ length: channels }, (_, c) => 10 * (from + i) + c),
  );
  return vectors(t, v);
}

/** The window of `length` rows ending at event `end` of `ramp`. */
const rampWindow = (end: number, length: number, channels: number): number[] =>
  Array.from(
    { length: length * channels },
    (_, k) => 10 * (end - length + 1 + Math.floor(k / channels)) + (k % channels),
  );

async function harness(params: object, channels = 2, rate = 100) {
  const h = await BlockHarness.create(SlidingWindow, params, {
    inputs: [{ shape: vectorShape(channels), rate }],
  });
  h.start();
  return h;
}

describe("SlidingWindow", () => {
  test("Step < Length: overlapping windows [Length, C], oldest row first, stamped with the newest sample", async () => {
    const h = await harness({ Length: 4, Step: 2 });
    expect(h.ports[0]!.shape).toEqual(matrixShape(4, 2));
    expect(h.desiredRate).toBe(50);
    h.push(ramp(9, 2));
    expect(h.output().t).toEqual([0.03, 0.05, 0.07]);
    expect(h.output().v).toEqual([rampWindow(3, 4, 2), rampWindow(5, 4, 2), rampWindow(7, 4, 2)]);
  });

  test("Step = Length (the default): contiguous windows; Step > Length skips samples", async () => {
    const a = await harness({ Length: 3 });
    a.push(ramp(7, 2));
    expect(a.output().t).toEqual([0.02, 0.05]);
    expect(a.output().v).toEqual([rampWindow(2, 3, 2), rampWindow(5, 3, 2)]);
    expect(a.desiredRate).toBeCloseTo(100 / 3, 12);

    const b = await harness({ Length: 2, Step: 5 }, 1);
    b.push(ramp(13, 1));
    // Windows end at 1, 6, 11: samples 2–4 and 7–9 are never output.
    expect(b.output().v).toEqual([
      [0, 10],
      [50, 60],
      [100, 110],
    ]);
    expect(b.output().t).toEqual([0.01, 0.06, 0.11]);
    expect(b.desiredRate).toBe(20);
  });

  test("the ring carries across frames: one frame of N = N frames of one, in any split; reset empties it", async () => {
    const whole = await harness({ Length: 5, Step: 3 }, 3);
    whole.push(ramp(40, 3));
    const single = await harness({ Length: 5, Step: 3 }, 3);
    for (let i = 0; i < 40; i++) single.push(ramp(1, 3, i));
    expect(single.output().v).toEqual(whole.output().v);
    expect(single.output().t).toEqual(whole.output().t);
    const uneven = await harness({ Length: 5, Step: 3 }, 3);
    let at = 0;
    for (const n of [2, 0, 7, 1, 13, 17]) {
      if (n > 0) uneven.push(ramp(n, 3, at));
      at += n;
    }
    expect(uneven.output().v).toEqual(whole.output().v);
    // One frame with several windows emits them in one frame.
    expect(whole.output().frames).toEqual([12]);
    whole.clear();
    whole.instance.reset!();
    whole.push(ramp(4, 3, 100));
    expect(whole.output().v).toEqual([]); // 4 < Length after the reset
    whole.push(ramp(1, 3, 104));
    expect(whole.output().v).toEqual([rampWindow(104, 5, 3)]);
  });

  test("window functions are scipy.signal.get_window(name, L, fftbins=False) (|err| <= 1e-15)", async () => {
    for (const c of FX.coefficients) {
      const h = await harness({ Length: c.size, WindowFunction: c.name }, 1);
      h.push(
        vectors(
          Array.from({ length: c.size }, (_, i) => i),
          Array.from({ length: c.size }, () => [1]),
        ),
      );
      const w = h.output().v[0]!;
      for (let i = 0; i < c.size; i++) {
        expect(Math.abs(w[i]! - c.values[i]!), `${c.name}(${c.size})[${i}]`).toBeLessThanOrEqual(
          1e-15,
        );
      }
      h.instance.dispose?.();
    }
  });

  test("tapered windows of the real recording match SciPy, through a tiny pipeline", async () => {
    const d = FX.stream.data;
    const rows = ["time_s,a,b"];
    for (let i = 0; i < d.length / 2; i++)
      rows.push(`${(i / 1000).toFixed(3)},${d[2 * i]},${d[2 * i + 1]}`);
    for (const t of FX.tapered) {
      const run = await runVirtualPipeline(
        `
Play: { Type: FilePlayer, Params: { File: r.csv } }
Win: { Type: SlidingWindow, Inputs: [Play], Params: { Length: ${t.length}, Step: ${t.step}, WindowFunction: ${t.name} } }
`,
        {
          catalog,
          duration: 1,
          resources: memoryResources({ "r.csv": rows.join("\n") }),
          record: ["Win"],
        },
      );
      const out = run.outputs.get("Win")!;
      expect(out.t).toEqual(t.ends.map((e) => Number((e / 1000).toFixed(3))));
      const flat = out.v.flat();
      expect(flat).toHaveLength(t.expected.length);
      let worst = 0;
      for (let i = 0; i < flat.length; i++)
        worst = Math.max(worst, Math.abs(flat[i]! - t.expected[i]!));
      expect(worst, t.name).toBeLessThanOrEqual(1e-15);
    }
  });

  test("errors: a matrix input; Length 0", async () => {
    await expect(
      BlockHarness.create(SlidingWindow, { Length: 4 }, { inputs: [{ shape: matrixShape(3, 2) }] }),
    ).rejects.toThrow(
      "input 'in0' has shape [3, 2] (a matrix); SlidingWindow needs a vector [1, C]",
    );
    const base =
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\nS: { Type: SinGenerator, Inputs: [T] }\n";
    const r = loadBlock(
      `${base}W: { Type: SlidingWindow, Inputs: [S], Params: { Length: 0 } }`,
      "W",
    );
    expect(r.errors[0]!.param).toBe("Length");
  });

  test("legacy [length, stride, window]: Rectangular, Hamming, Hann (case-insensitive)", () => {
    const base =
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\nS: { Type: SinGenerator, Inputs: [T] }\n";
    expect(
      convertLegacy(
        `${base}W: { Type: SlidingWindow, Inputs: [S], Params: ['128', '32', 'Hamming'] }`,
        "W",
      ),
    ).toEqual({ Length: 128, Step: 32, WindowFunction: "hamming" });
    expect(
      convertLegacy(
        `${base}W: { Type: SlidingWindow, Inputs: [S], Params: ['64', '64', 'rectangular'] }`,
        "W",
      ),
    ).toEqual({ Length: 64, Step: 64, WindowFunction: "none" });
    expect(
      convertLegacy(
        `${base}W: { Type: SlidingWindow, Inputs: [S], Params: ['16', '4', 'HANN'] }`,
        "W",
      ),
    ).toEqual({ Length: 16, Step: 4, WindowFunction: "hann" });
    const bad = loadBlock(
      `${base}W: { Type: SlidingWindow, Inputs: [S], Params: ['16', '4', 'Haming'] }`,
      "W",
    );
    expect(bad.errors[0]!.message).toContain("unknown window function 'Haming'");
    expect(bad.errors[0]!.message).toContain("did you mean 'hamming'?");
  });
});
