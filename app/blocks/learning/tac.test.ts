import { describe, expect, test } from "vitest";
import { z } from "zod";
import { createCatalog, defineBlock, loadPipeline, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, vectors } from "../../../tests/support/blocks";
import { BLOCKS } from "../catalog";
import { TAC } from "./tac";

const NAN2 = [NaN, NaN];

async function tac(params: object, inputs = 1, d = 2) {
  const h = await BlockHarness.create(TAC, params, {
    inputs: Array.from({ length: inputs }, () => ({ shape: vectorShape(d), rate: 8 })),
  });
  h.start();
  return h;
}

const run = (h: BlockHarness, action: string, arg?: unknown) =>
  h.instance.actions![action]!.run(arg);

/**
 * A simulated user in the loop: every 1/8 s it moves the cursor straight toward the target the
 * TAC shows (at `speed` per second) and sends the position. Times and steps are exact binary
 * fractions, so the numbers below are exact.
 */
function drive(h: BlockHarness, from: number, to: number, speed = 1, start = [0, 0]): number[] {
  const pos = [...start];
  const goal = [NaN, NaN];
  for (let k = Math.round(from * 8); k <= Math.round(to * 8); k++) {
    const t = k / 8;
    const shown = h.output("target").v.at(-1);
    if (shown) goal.splice(0, 2, ...shown);
    if (!Number.isNaN(goal[0]!)) {
      const dx = goal[0]! - pos[0]!;
      const dy = goal[1]! - pos[1]!;
      const d = Math.hypot(dx, dy);
      const s = Math.min(d, speed / 8);
      if (d > 0) {
        pos[0]! += (dx / d) * s;
        pos[1]! += (dy / d) * s;
      }
    }
    h.push(vectors([t], [pos]));
  }
  return pos;
}

describe("TAC", () => {
  test("trials of Targets: success, completion time, path efficiency, timeout, summary", async () => {
    const h = await tac({
      Targets: [
        [1, 0],
        [1, 1],
        [6, 6],
      ],
      Tolerance: 0.125,
      Dwell: 0.5,
      TimeLimit: 3,
      Pause: 1,
    });
    expect(h.text).toBe("ready (start to begin)");
    expect(run(h, "start")).toBe("started: 3 trials");
    drive(h, 0, 1.25);
    expect(h.text).toBe("trial 1/3: inside 0.4 s");
    drive(h, 1.375, 12, 1, [1, 0]);
    // Trial 0: from [0, 0] at t 0, inside at 0.875 (|0.875 − 1| ≤ 0.125), dwell done at 1.375.
    // Trial 1 starts 1 s later (2.375) from [1, 0]: straight up, inside at 3.25, done at 3.75.
    // Trial 2 starts at 4.75 and times out at 7.75.
    const trials = h.output("trial");
    expect(trials.t).toEqual([1.375, 3.75, 7.75]);
    expect(trials.v[0]).toEqual([0, 1, 1.375, 1, 0]);
    expect(trials.v[1]).toEqual([1, 1, 1.375, 1, 0]);
    expect(trials.v[2]!.slice(0, 4)).toEqual([2, 0, NaN, NaN]);
    expect(trials.v[2]![4]).toBeCloseTo(Math.hypot(5, 5) - 3, 12); // 3 s at 1/s toward [6, 6]
    // The target output: each target when its trial starts, all NaN when it ends.
    expect(h.output("target")).toMatchObject({
      t: [0, 1.375, 2.375, 3.75, 4.75, 7.75],
      v: [[1, 0], NAN2, [1, 1], NAN2, [6, 6], NAN2],
    });
    expect(h.text).toBe(
      "finished: 2/3 succeeded (67 %), mean completion 1.38 s, mean path efficiency 1.00",
    );
    expect(run(h, "summary")).toBe(
      "2/3 succeeded (67 %), mean completion 1.38 s, mean path efficiency 1.00",
    );
  });

  test("path efficiency = straight-line distance / path travelled until the successful entry", async () => {
    const h = await tac({ Targets: [[1, 1]], Tolerance: 0.25, Dwell: 0.25, Autostart: true });
    h.push(
      vectors(
        [0, 0.25, 0.5, 0.625, 0.75, 0.875, 1],
        [
          [0, 0],
          [1, 0], // along x first…
          [1, 1], // …then along y: inside at 0.5
          [1.5, 1], // out again
          [1, 1.125], // in: the dwell starts again here
          [1.0625, 1.125],
          [1.0625, 1.125], // dwell done
        ],
      ),
    );
    const [row] = h.output("trial").v;
    // Path until the last entry: 1 + 1 + 0.5 + √(0.5² + 0.125²); straight: |[1, 1.125]|.
    const path = 2.5 + Math.hypot(0.5, 0.125);
    expect(row![0]).toBe(0);
    expect(row![1]).toBe(1);
    expect(row![2]).toBe(1); // 0.75 + Dwell
    expect(row![3]).toBeCloseTo(Math.hypot(1, 1.125) / path, 12);
    expect(row![4]).toBeCloseTo(Math.hypot(0.0625, 0.125), 12);
    // Starting inside: efficiency 1, done after the dwell.
    const g = await tac({ Targets: [[0, 0]], Tolerance: 0.5, Dwell: 0, Autostart: true });
    g.push(vectors([3], [[0.1, 0.1]]));
    expect(g.output("trial").v).toEqual([[0, 1, 0, 1, Math.hypot(0.1, 0.1)]]);
  });

  test("Metric: euclidean (scaled by per-DoF tolerances) or box", async () => {
    const inside = async (params: object, pos: number[]) => {
      const h = await tac({
        Targets: [[1, 1]],
        Dwell: 0,
        TimeLimit: 1,
        Autostart: true,
        ...params,
      });
      h.push(vectors([0], [pos]));
      return h.output("trial").v[0]?.[1] === 1;
    };
    expect(await inside({ Tolerance: 0.25 }, [1.2, 1.2])).toBe(false); // 0.283 > 0.25
    expect(await inside({ Tolerance: 0.25, Metric: "box" }, [1.2, 1.2])).toBe(true);
    expect(await inside({ Tolerance: [0.1, 1] }, [1.05, 1.8])).toBe(true); // 0.25 + 0.64 ≤ 1
    expect(await inside({ Tolerance: [0.1, 1] }, [1.09, 1.8])).toBe(false); // 0.81 + 0.64 > 1
    expect(await inside({ Tolerance: [0.1, 1], Metric: "box" }, [1.09, 1.8])).toBe(true);
    expect(await inside({ Tolerance: 0.25 }, [NaN, 1])).toBe(false); // no position, no success
  });

  test("target input: the Buffer's trigger protocol starts and ends trials", async () => {
    const h = await tac({ Tolerance: 0.125, Dwell: 0.25, TimeLimit: 10, Autostart: true }, 2);
    h.push(vectors([0.5], [[1, 0]]), 1); // before any position: starts at the first control event
    expect(h.text).toBe("waiting for a target");
    h.push(
      vectors(
        [1, 1.125],
        [
          [0, 0],
          [1, 0],
        ],
      ),
      0,
    );
    h.push(
      vectors(
        [1.25, 1.375],
        [
          [1, 0],
          [1, 0],
        ],
      ),
      0,
    );
    expect(h.output("trial").v).toEqual([[0, 1, 0.875, 1, 0]]); // from 0.5 to 1.375
    h.push(vectors([1.5], [[1, 0]]), 1); // the same target again: nothing
    h.push(vectors([2], [NAN2]), 1); // end: no trial running
    h.push(
      vectors(
        [2.5, 3],
        [
          [0, 1],
          [5, 5],
        ],
      ),
      1,
    ); // a new target, then another: trial 1 fails
    h.push(vectors([3.5], [NAN2]), 1); // trial 2 ends before success
    expect(h.output("trial").t).toEqual([1.375, 3, 3.5]);
    expect(
      h
        .output("trial")
        .v.slice(1)
        .map((r) => r.slice(0, 4)),
    ).toEqual([
      [1, 0, NaN, NaN],
      [2, 0, NaN, NaN],
    ]);
    expect(h.output("target").v).toEqual([[1, 0], NAN2, [0, 1], NAN2, [5, 5], NAN2]);
    expect(h.text).toBe(
      "waiting for a target (1/3 succeeded (33 %), mean completion 0.88 s, mean path efficiency 1.00)",
    );
    h.push(vectors([4], [[1, NaN]]), 1);
    expect(h.warnings[0]).toContain("ignored a target event with 1 NaN of 2 values");
  });

  test("Order target-control: MOSAIC's [target, control]", async () => {
    const h = await tac({ Order: "target-control", Tolerance: 0.5, Dwell: 0, Autostart: true }, 2);
    h.push(vectors([1], [[3, 3]]), 1); // a control position
    h.push(vectors([2], [[3, 3.25]]), 0); // a target
    h.push(vectors([3], [[3, 3]]), 1);
    expect(h.output("trial").v).toEqual([[0, 1, 1, 1, 0.25]]);
  });

  test("random targets: seeded, within Low and High per DoF", async () => {
    const targets = async (seed: number) => {
      const h = await tac({
        Targets: { Random: { Count: 20, Seed: seed, Low: [0, -10], High: [1, -9] } },
        Tolerance: 0.01,
        TimeLimit: 0.125,
        Pause: 0,
        Autostart: true,
      });
      for (let k = 0; k < 60; k++) h.push(vectors([k / 8], [[5, 5]]));
      return h.output("target").v.filter((v) => !Number.isNaN(v[0]!));
    };
    const a = await targets(3);
    expect(a).toHaveLength(20);
    for (const [x, y] of a) {
      expect(x).toBeGreaterThan(0);
      expect(x).toBeLessThan(1);
      expect(y).toBeGreaterThan(-10);
      expect(y).toBeLessThan(-9);
    }
    expect(await targets(3)).toEqual(a);
    expect(await targets(4)).not.toEqual(a);
  });

  test("actions: stop drops the trial in progress, start begins a new test; reset; live params", async () => {
    const h = await tac({
      Targets: [
        [1, 0],
        [0, 1],
      ],
      Tolerance: 0.125,
      Dwell: 0.5,
      Autostart: true,
    });
    drive(h, 0, 0.5);
    expect(run(h, "stop")).toBe("stopped: no trials finished");
    expect(h.output("target").v.at(-1)).toEqual(NAN2);
    expect(run(h, "stop")).toBe("not running");
    h.clear();
    h.instance.setParam!("Dwell", 0);
    run(h, "start");
    drive(h, 1, 5);
    expect(h.output("trial").v.map((r) => r.slice(0, 2))).toEqual([
      [0, 1],
      [1, 1],
    ]);
    expect(() => h.instance.setParam!("Tolerance", [1, 2, 3])).toThrow(
      "Tolerance has 3 values, but the control input 'in0' has 2 DoFs",
    );
    h.instance.reset!(); // Autostart: a new test begins at the next control event
    h.clear();
    drive(h, 10, 11);
    expect(h.output("target").v[0]).toEqual([1, 0]);
  });

  test("configuration errors", async () => {
    await expect(tac({})).rejects.toThrow("give Targets");
    await expect(tac({ Targets: [[1, 0]] }, 2)).rejects.toThrow(
      "give Targets or a target input, not both",
    );
    // With Stimulus, its captures are the trials: a list of Targets would be ignored.
    await expect(tac({ Targets: [[1, 0]], Stimulus: "Cues" })).rejects.toThrow(
      "give Targets or Stimulus, not both (the trials are the captures of Stimulus 'Cues')",
    );
    await expect(tac({ Targets: [[1, 0, 0]] })).rejects.toThrow(
      "Targets[0] has 3 values, but the control input 'in0' has 2 DoFs",
    );
    await expect(tac({ Targets: [[1, 0]], Tolerance: [1] })).rejects.toThrow(
      "Tolerance has 1 values",
    );
    await expect(tac({ Targets: [[1, 0]], Order: "target-control" })).rejects.toThrow(
      "Order target-control needs two inputs",
    );
    await expect(tac({ Targets: [[1, 0]], TimeLimit: 0 })).rejects.toThrow("must be positive");
    await expect(
      BlockHarness.create(
        TAC,
        {},
        { inputs: [{ shape: vectorShape(2) }, { shape: vectorShape(3) }] },
      ),
    ).rejects.toThrow("the target input 'in1' has 3 values, but the control input 'in0' has 2");
  });
});

// ---------------------------------------------------------------------------------------------
// In pipelines, with a scripted cursor in the loop

/** A cursor that moves straight toward the latest target it receives, at Speed units per second. */
const Cursor = defineBlock({
  type: "Cursor",
  category: "Testing",
  summary: "Test cursor that moves toward its target.",
  help: "Inputs [timer, target]: on every tick, steps toward the latest finite target at Speed per second (test only).",
  params: z.strictObject({
    Dims: z.number().int().min(1).describe("DoFs"),
    Speed: z.number().positive().describe("units per second"),
  }),
  inputs: { min: 2, max: 2 },
  create(ctx, p) {
    const out = ctx.output(vectorShape(p.Dims));
    const pos = new Float64Array(p.Dims);
    const goal = new Float64Array(p.Dims).fill(NaN);
    let last = NaN;
    return {
      process(f, port) {
        if (port === 1) {
          const e = f.n - 1;
          for (let i = 0; i < p.Dims; i++) goal[i] = f.v[e * p.Dims + i]!;
          return;
        }
        const o = out.frame(f.n);
        for (let e = 0; e < f.n; e++) {
          const t = f.t[e]!;
          const dt = Number.isNaN(last) ? 0 : t - last;
          last = t;
          if (!Number.isNaN(goal[0]!)) {
            let d = 0;
            for (let i = 0; i < p.Dims; i++) d += (goal[i]! - pos[i]!) ** 2;
            d = Math.sqrt(d);
            const s = Math.min(d, p.Speed * dt);
            if (d > 0) for (let i = 0; i < p.Dims; i++) pos[i]! += ((goal[i]! - pos[i]!) / d) * s;
          }
          o.t[e] = t;
          o.v.set(pos, e * p.Dims);
        }
        out.emit(o);
      },
    };
  },
});

const withCursor = createCatalog([...BLOCKS, Cursor]);

describe("TAC in a pipeline", () => {
  test("a cursor moving straight to each target: every trial succeeds, path efficiency 1", async () => {
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 50 }\n" +
      "Hand: { Type: Cursor, Inputs: [T, Test.target], Params: { Dims: 3, Speed: 2 } }\n" +
      "Test:\n" +
      "  Type: TAC\n" +
      "  Inputs: [Hand]\n" +
      "  Params:\n" +
      "    Targets: { Random: { Count: 4, Seed: 11, Low: -1, High: 1 } }\n" +
      "    Tolerance: 0.1\n" +
      "    Dwell: 0.5\n" +
      "    TimeLimit: 5\n" +
      "    Pause: 0.5\n" +
      "    Autostart: true\n";
    const r = await runVirtualPipeline(yaml, { catalog: withCursor, duration: 12 });
    const trials = r.outputs.get("Test")!;
    expect(trials.v).toHaveLength(4);
    trials.v.forEach((row, k) => {
      expect(row[0]).toBe(k);
      expect(row[1]).toBe(1);
      expect(row[2]).toBeGreaterThan(0.5);
      expect(row[3]).toBeCloseTo(1, 9);
    });
    const text = r.telemetry.blocks.find((b) => b.name === "Test")!.text;
    expect(text).toMatch(
      /^finished: 4\/4 succeeded \(100 %\), mean completion \d\.\d\d s, mean path efficiency 1\.00$/,
    );
    // Deterministic under the virtual clock.
    const again = await runVirtualPipeline(yaml, { catalog: withCursor, duration: 12 });
    expect(again.outputs.get("Test")!).toEqual(trials);
  });

  test("a control that never moves: every trial times out", async () => {
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
      "Still: { Type: SinGenerator, Inputs: [T], Params: { Components: 2, Amplitude: 0 } }\n" +
      "Test: { Type: TAC, Inputs: [Still], Params: { Targets: [[1, 0], [0, 1]], TimeLimit: 2, Pause: 1, Autostart: true } }\n";
    const r = await runVirtualPipeline(yaml, { catalog: withCursor, duration: 10, start: 50 });
    const trials = r.outputs.get("Test")!;
    expect(trials.t).toEqual([52, 55]); // 50 + 2; 52 + 1 + 2
    expect(trials.v).toEqual([
      [0, 0, NaN, NaN, 1],
      [1, 0, NaN, NaN, 1],
    ]);
  });

  test("Stimulus → TAC → Stimulus: a capture ends when its TAC trial succeeds (MOSAIC's TAC)", async () => {
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 50 }\n" +
      "Stim:\n" +
      "  Type: Stimulus\n" +
      "  Inputs: [-T, Test.trial]\n" +
      "  Params:\n" +
      "    Tasks: [{ Label: a, Target: [1, 0] }, { Label: b, Target: [0, 1] }]\n" +
      "    Rest: 1\n" +
      "    Rise: 0\n" +
      "    Hold: 0\n" +
      "    Capture: 20\n" +
      "    Fall: 0\n" +
      "    Autostart: true\n" +
      "Hand: { Type: Cursor, Inputs: [T, Stim.trigger], Params: { Dims: 2, Speed: 1 } }\n" +
      "Test: { Type: TAC, Inputs: [Hand, Stim.trigger], Params: { Tolerance: 0.1, Dwell: 1, TimeLimit: .inf, Autostart: true } }\n";
    const r = await runVirtualPipeline(yaml, {
      catalog: withCursor,
      duration: 10,
      record: ["Test"],
    });
    const trials = r.outputs.get("Test")!;
    expect(trials.v.map((row) => row.slice(0, 2))).toEqual([
      [0, 1],
      [1, 1],
    ]);
    // Trial 0: capture (and trial) from 1 s; the cursor gets the target after its own tick at
    // 1 s, so it moves from 1.02 s: inside at 1.92 s (0.9 at 1/s), dwell done at 2.92 s.
    expect(trials.t[0]).toBeCloseTo(2.92, 9);
    expect(trials.v[0]![2]).toBeCloseTo(1.92, 9);
    expect(trials.v[0]![3]).toBeCloseTo(1, 9);
    const stim = r.telemetry.blocks.find((b) => b.name === "Stim")!;
    expect(stim.text).toBe("done: 2 cues"); // two captures of 20 s ended within 10 s
  });

  test("legacy: MOSAIC's cfg7 TAC Params [TAC_stim, 2.0, 0.2] and a cfg7-like pipeline loads", () => {
    const p = convertLegacy(
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
        "Tv: { Type: SinGenerator, Inputs: [T], Params: { Components: 12 } }\n" +
        "Pred: { Type: SinGenerator, Inputs: [T], Params: { Components: 12 } }\n" +
        "increm_learning_TAC: {\n" +
        "  Type: TAC,\n" +
        "  Inputs: [ Tv, Pred ],\n" +
        "  Params: [ TAC_stim, 2.0, 0.2 ]\n" +
        "}\n",
      "increm_learning_TAC",
    );
    expect(p).toEqual({
      Stimulus: "TAC_stim",
      Dwell: 2,
      Tolerance: 0.2,
      TimeLimit: Infinity,
      Pause: 1,
      Metric: "euclidean",
      Order: "target-control",
      Autostart: true,
    });
    // cfg7_incremental_with_TAC.yaml without its devices (Myo, BlenderArm) and its predictor.
    const cfg7 =
      "timer_subs: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
      "ground_truth: {\n" +
      "  Type: Trigger,\n" +
      "  Params: [\n" +
      "    rest:    0;0;0;0;0;0;0;0;0;0;0;0,\n" +
      "    power:   1;1;1;1;1;1;0;0;0;0;0;0,\n" +
      "    flex:    0;0;0;0;0;0;1;0;0;0;0;0\n" +
      "  ]\n" +
      "}\n" +
      "incr_learn_prediction: { Type: SinGenerator, Inputs: [timer_subs], Params: [12] }\n" +
      "TAC_stim: {\n" +
      "  Type: Stimulus,\n" +
      "  Inputs: [ -timer_subs ],\n" +
      "  Params: [ 20.0,\n" +
      "    0.8;0.8;0.8;0.8;0.8;0.8;0;0;0;0;0;0,\n" +
      "    0;0;0;0;0;0;0.8;0;0;0;0;0\n" +
      "  ]\n" +
      "}\n" +
      "TAC_stim_tv: { Type: Selector, Inputs: [ TAC_stim ] }\n" +
      "controlAlgorithm2: { Type: ControlAlgorithm, Inputs: [ TAC_stim_tv ], Params: [ algorithm:DirectControl ] }\n" +
      "increm_learning_TAC: {\n" +
      "  Type: TAC,\n" +
      "  Inputs: [ TAC_stim_tv, incr_learn_prediction ],\n" +
      "  Params: [ TAC_stim, 2.0, 0.2 ]\n" +
      "}\n";
    const loaded = loadPipeline(cfg7, "cfg7.yaml", withCursor);
    expect(loaded.diagnostics.filter((d) => d.severity === "error")).toEqual([]);
    expect(
      loaded.diagnostics.filter((d) => d.code === "legacy-converted").map((d) => d.block),
    ).toEqual([
      "ground_truth",
      "incr_learn_prediction",
      "TAC_stim",
      "controlAlgorithm2",
      "increm_learning_TAC",
    ]);
    expect(loaded.spec!.byName.get("TAC_stim")!.params).toMatchObject({
      Capture: 20,
      Tasks: [{ Label: "task1" }, { Label: "task2" }],
    });
  });

  test("MOSAIC's form: the named Stimulus's captures are the trials, and a success ends the capture", async () => {
    // cfg7's wiring: the target input is the cue shown (a Selector of the Stimulus); the control
    // follows the cue exactly, so each capture succeeds after the dwell (2 s), not after 20 s.
    const yaml =
      "timer_subs: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
      "TAC_stim: { Type: Stimulus, Inputs: [ -timer_subs ], Params: { Capture: 20, Autostart: true, Tasks: [ { Label: a, Target: [0.8, 0] }, { Label: b, Target: [0, 0.8] } ] } }\n" +
      "TAC_stim_tv: { Type: Selector, Inputs: [ TAC_stim ] }\n" +
      "tac: { Type: TAC, Inputs: [ TAC_stim_tv, TAC_stim_tv ], Params: [ TAC_stim, 2.0, 0.2 ] }\n";
    const r = await runVirtualPipeline(yaml, {
      catalog: withCursor,
      duration: 20,
      start: 100,
      record: ["tac", "TAC_stim"],
    });
    const trials = r.outputs.get("tac")!;
    // [index, success, completion time, efficiency, final distance]
    expect(trials.v.map((v) => v.slice(0, 3))).toEqual([
      [0, 1, 2],
      [1, 1, 2],
    ]);
    // Rest 2, rise 1, hold 2, capture (ended by the success after 2 s), fall 1: the second
    // capture starts 8 s after the first.
    expect(trials.t.map((t) => Math.round((t - 100) * 100) / 100)).toEqual([7, 15]);
    // During the first capture (from 5 s), the status counts the trials from the Stimulus's cues.
    const during = await runVirtualPipeline(yaml, { catalog: withCursor, duration: 6, start: 100 });
    expect(during.telemetry.blocks.find((b) => b.name === "tac")!.text).toMatch(
      /^trial 1\/2: inside 1\.0 s$/,
    );
  });
});
