// ArtifactRejection through BlockHarness and through FilePlayer → SlidingWindow → ArtifactRejection
// on both real recordings, against the NumPy rules of core-wasm/dsp/tests/fixtures/artifact.json
// (gen_artifact.py): masks, flags and counters exact.
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../catalog";
import { Frame, matrixShape, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { loadBlock } from "../../../tests/support/blocks";
import { fsResources, REPO_ROOT } from "../../../tests/support/fs-resources";
import { initDspForTests } from "../../../tests/support/wasm";
import { ArtifactRejection } from "./artifact-rejection";

beforeAll(() => initDspForTests());

type Num = number | "nan" | "inf";
const num = (v: Num): number => (v === "nan" ? NaN : v === "inf" ? Infinity : v);

interface Config {
  RailLow: number | null;
  RailHigh: number | null;
  ClipTolerance: number;
  ClipFraction: number;
  FlatThreshold: number;
  JumpFactor: Num;
  DriftThreshold: number | null;
  Mode: "hard" | "soft";
}

interface Fixture {
  reasons: string[];
  stream: { channels: number; data: Num[] };
  cases: {
    name: string;
    config: Config;
    length: number;
    step: number;
    ends: number[];
    flags: number[];
    counters: number[];
  }[];
  recordings: {
    file: string;
    name: string;
    config: Config;
    length: number;
    step: number;
    windows: number;
    counters: number[];
    rail_samples: number;
    rail_samples_in_clipped_windows: number;
    flagged: [number, number][];
  }[];
}

const FX = JSON.parse(
  readFileSync(join(REPO_ROOT, "core-wasm", "dsp", "tests", "fixtures", "artifact.json"), "utf8"),
) as Fixture;

/** The block's params for a fixture config (nulls left out). */
function params(c: Config): Record<string, unknown> {
  const p: Record<string, unknown> = {
    ClipTolerance: c.ClipTolerance,
    ClipFraction: c.ClipFraction,
    FlatThreshold: c.FlatThreshold,
    JumpFactor: num(c.JumpFactor),
    Mode: c.Mode,
  };
  if (c.RailLow !== null) p.RailLow = c.RailLow;
  if (c.RailHigh !== null) p.RailHigh = c.RailHigh;
  if (c.DriftThreshold !== null) p.DriftThreshold = c.DriftThreshold;
  return p;
}

/** Parses the `counters` action: per channel [clipping, flat, jump, drift, nonfinite, rejected]. */
function counters(h: { instance: { actions?: Record<string, { run(): unknown }> } }): number[] {
  const text = h.instance.actions!.counters!.run() as string;
  return text
    .split("\n")
    .slice(2)
    .flatMap((l) => l.split(",").slice(1).map(Number));
}

describe("ArtifactRejection", () => {
  test.each(FX.cases.map((c) => [c.name, c] as const))(
    "%s: masks, clean windows and counters follow the NumPy rules",
    async (_name, k) => {
      const c = FX.stream.channels;
      const data = FX.stream.data.map(num);
      const windows = Frame.from(
        matrixShape(k.length, c),
        k.ends.map((e) => e / 1000),
        k.ends.map((end) => data.slice((end + 1 - k.length) * c, (end + 1) * c)),
      );
      const h = await BlockHarness.create(ArtifactRejection, params(k.config), {
        inputs: [{ shape: matrixShape(k.length, c), rate: 20 }],
      });
      h.start();
      expect(h.ports.map((p) => [p.name, p.shape])).toEqual([
        ["clean", matrixShape(k.length, c)],
        ["mask", vectorShape(c)],
      ]);
      h.push(windows);
      const mask = h.output("mask");
      expect(mask.t).toEqual(k.ends.map((e) => e / 1000));
      expect(mask.v.flat()).toEqual(k.flags.map((f) => (f === 0 ? 1 : 0)));
      expect(counters(h)).toEqual(k.counters);
      const clean = h.output("clean");
      expect(clean.t).toEqual(mask.t);
      clean.v.forEach((w, i) => {
        w.forEach((x, j) => {
          const good = mask.v[i]![j % c] === 1;
          const input = windows.v[i * k.length * c + j]!;
          if (k.config.Mode === "hard" && !good) expect(x).toBe(0);
          else expect(Object.is(x, input) || (Number.isNaN(x) && Number.isNaN(input))).toBe(true);
        });
      });
      expect(h.text).toMatch(/^rejected \d+ of \d+ channel-windows \(clip \d+, flat \d+/);
      h.instance.actions!.resetCounters!.run();
      expect(h.text).toMatch(/^rejected 0 of 0 channel-windows/);
      h.instance.dispose?.();
    },
  );

  test("errors: a stream instead of windows, rails the wrong way round", async () => {
    await expect(
      BlockHarness.create(ArtifactRejection, {}, { inputs: [{ shape: vectorShape(4) }] }),
    ).rejects.toThrow(
      "input 'in0' has shape [1, 4]; ArtifactRejection judges windows [L, C] with L ≥ 3: put a " +
        "SlidingWindow before it",
    );
    const base =
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\nS: { Type: SinGenerator, Inputs: [T] }\n" +
      "W: { Type: SlidingWindow, Inputs: [S], Params: { Length: 10 } }\n";
    const r = loadBlock(
      `${base}A: { Type: ArtifactRejection, Inputs: [W], Params: { RailLow: 1, RailHigh: -1 } }`,
      "A",
    );
    expect(r.errors[0]!.param).toBe("RailLow");
    expect(r.errors[0]!.message).toContain("RailLow must be below RailHigh");
  });
});

describe("ArtifactRejection on the real recordings (FilePlayer → SlidingWindow → ArtifactRejection)", () => {
  test.each(FX.recordings.map((r) => [`${r.file}, ${r.name}`, r] as const))(
    "%s",
    async (_name, r) => {
      const p = params(r.config);
      const flow = Object.entries(p)
        .map(([k, v]) => `${k}: ${typeof v === "string" ? v : String(v)}`)
        .join(", ");
      const run = await runVirtualPipeline(
        `
Play: { Type: FilePlayer, Params: { File: pipelines/data/${r.file} } }
Win: { Type: SlidingWindow, Inputs: [Play], Params: { Length: ${r.length}, Step: ${r.step} } }
Art: { Type: ArtifactRejection, Inputs: [Win], Params: { ${flow} } }
`,
        {
          catalog,
          duration: 130,
          resources: fsResources(),
          record: ["Art"],
        },
      );
      const clean = run.outputs.get("Art")!;
      expect(clean.t).toHaveLength(r.windows);
      // Rejected windows are the zeroed ones (hard mode; no window of these recordings is all 0).
      const flagged = clean.v
        .map((w, i) => [i, w.every((x) => x === 0)] as const)
        .filter(([, zero]) => zero)
        .map(([i]) => i);
      expect(flagged).toEqual(r.flagged.map(([i]) => i));
      const node = run.runtime.nodes.find((n) => n.name === "Art")!;
      // The status line is brought up to date when the pipeline stops.
      expect(node.text).toContain(`rejected ${r.counters[5]} of ${r.windows} channel-windows`);
      expect(node.text).toContain(
        `(clip ${r.counters[0]}, flat ${r.counters[1]}, jump ${r.counters[2]}, drift ${r.counters[3]}, nonfinite ${r.counters[4]})`,
      );
      if (r.file === "emg_bursts_1000hz.csv") expect(r.counters[5]).toBe(0);
      if (r.file === "emg_fatigue_1000hz.csv" && r.name === "fixed_rails") {
        expect(r.rail_samples).toBe(38);
        expect(r.rail_samples_in_clipped_windows).toBe(38);
      }
    },
  );
});
