import { describe, expect, test } from "vitest";
import { EMPTY_SHAPE, vectorShape } from "../../engine";
import { BlockHarness, runVirtualPipeline } from "../../engine/testing";
import { convertLegacy, loadBlock, ticks, vectors } from "../../../tests/support/blocks";
import { catalog } from "../catalog";
import { Stimulus } from "./stimulus";

const STOP = [NaN, NaN];

async function stimulus(params: object, opts: { skip?: boolean; subscribed?: boolean } = {}) {
  const h = await BlockHarness.create(Stimulus, params, {
    inputs: [
      { shape: EMPTY_SHAPE, rate: 10, isTimer: true, subscribed: opts.subscribed ?? false },
      ...(opts.skip ? [{ shape: vectorShape(5) }] : []),
    ],
    now: 100,
  });
  h.start();
  return h;
}

const run = (h: BlockHarness, action: string, arg?: unknown) =>
  h.instance.actions![action]!.run(arg);

/** Ticks at 10 Hz from `from` (inclusive) to `to` (exclusive), in one frame. */
const range = (from: number, to: number): number[] => {
  const out: number[] = [];
  for (let k = 0; from + k / 10 < to - 1e-9; k++) out.push(Math.round((from + k / 10) * 1e6) / 1e6);
  return out;
};

const ONE = {
  Tasks: [{ Label: "fist", Target: [1, 0.5] }],
  Rest: 0.5,
  Rise: 0.3,
  Hold: 0.2,
  Capture: 0.5,
  Fall: 0.3,
};

describe("Stimulus", () => {
  test("phases rest → rise (sin²) → hold → capture → fall (cos²) → end, with trigger and cue", async () => {
    const h = await stimulus({ ...ONE, Autostart: true });
    expect(h.subscribed).toEqual({ 0: true }); // MOSAIC's `-timer`: subscribed while running
    h.push(ticks(...range(100, 102.5)));
    const phase = h.output("phase").v.flat();
    // rest 100.0–100.4, rise 100.5–100.7, hold 100.8–100.9, capture 101.0–101.4, fall 101.5–101.7
    expect(phase).toEqual([0, 0, 0, 0, 0, 1, 1, 1, 2, 2, 3, 3, 3, 3, 3, 4, 4, 4, 5]);
    const target = h.output("target").v;
    expect(target[4]).toEqual([0, 0]);
    expect(target[6]![0]).toBeCloseTo(Math.sin(Math.PI / 6) ** 2, 12); // 0.1 s of 0.3 s: 0.25
    expect(target[7]![1]).toBeCloseTo(0.5 * Math.sin(Math.PI / 3) ** 2, 12); // 0.375
    expect(target[9]).toEqual([1, 0.5]);
    expect(target[14]).toEqual([1, 0.5]);
    expect(target[16]![0]).toBeCloseTo(Math.cos(Math.PI / 6) ** 2, 12); // 0.75
    expect(target[18]).toEqual([0, 0]); // end
    expect(h.output("cue").v.flat()).toEqual([
      NaN,
      NaN,
      NaN,
      NaN,
      NaN,
      0,
      0,
      0,
      0,
      0,
      0,
      0,
      0,
      0,
      0,
      0,
      0,
      0,
      NaN,
    ]);
    // The trigger: the target at the first tick of capture, all NaN at the first tick after it.
    expect(h.output("trigger")).toMatchObject({ t: [101, 101.5], v: [[1, 0.5], STOP] });
    // Ended: ticks are ignored and the timer is unsubscribed.
    expect(h.output("phase").t.at(-1)).toBe(101.8);
    expect(h.subscribed).toEqual({ 0: false });
    expect(h.text).toBe("done: 1 cue");
  });

  test("status text while running; the protocol starts at the first tick after start", async () => {
    const h = await stimulus({
      Labels: { rest: [0, 0], fist: [1, 0], open: [0, 1] },
      Tasks: ["fist", "open", "fist"],
      Repetitions: 4,
      Rest: 1,
      Rise: 1,
      Hold: 1,
      Capture: 5,
      Fall: 1,
    });
    expect(h.text).toBe("ready: 12 cues (start to begin)");
    expect(h.subscribed).toEqual({ 0: false });
    h.push(ticks(100, 100.1)); // not started: ignored
    expect(h.output("phase").t).toEqual([]);
    h.clock = 100.15;
    expect(run(h, "start")).toBe("starting: 12 cues");
    expect(h.subscribed).toEqual({ 0: true });
    // Cue 3 (fist, the third task) starts at 100.2 + 2 × 9 s; its capture at 121.2, to 126.2.
    h.push(ticks(...range(100.2, 121.25)));
    expect(h.text).toBe("capture: fist (3 of 12), 5.0 s left");
    h.push(ticks(123.8));
    expect(h.text).toBe("capture: fist (3 of 12), 2.4 s left");
    expect(h.output("cue").v.at(-1)).toEqual([1]);
    // Labels are numbered in Labels order: rest 0, fist 1, open 2.
    expect(
      new Set(
        h
          .output("cue")
          .v.flat()
          .filter((x) => !Number.isNaN(x)),
      ),
    ).toEqual(new Set([1, 2]));
    expect(run(h, "stop")).toBe("stopped");
    expect(h.output("trigger").v.at(-1)).toEqual(STOP); // the capture in progress is stopped
    expect(h.text).toBe("stopped at fist (3 of 12), capture");
    expect(h.subscribed).toEqual({ 0: false });
    expect(run(h, "stop")).toBe("not running");
  });

  test("progress: cue number, cue count and the next cue's label (at rest: the one about to start)", async () => {
    const h = await stimulus({
      Labels: { rest: [0, 0], fist: [1, 0], open: [0, 1] },
      Tasks: ["open", "fist"],
      Repetitions: 2,
      ...{ Rest: 0.5, Rise: 0.3, Hold: 0.2, Capture: 0.5, Fall: 0.3 },
      Autostart: true,
    });
    // Each cue lasts 1.8 s: rest 0–0.4, rise 0.5–0.7, hold 0.8–0.9, capture 1.0–1.4, fall 1.5–1.7.
    h.push(ticks(...range(100, 107.4)));
    const progress = h.output("progress");
    expect(progress.t).toEqual(h.output("phase").t);
    const at = (t: number): number[] => progress.v[progress.t.indexOf(t)]!;
    expect(at(100)).toEqual([1, 4, 2]); // resting before cue 1 (open, label 2)
    expect(at(100.6)).toEqual([1, 4, 1]); // rising to open: fist is next
    expect(at(101.8)).toEqual([2, 4, 1]); // resting before cue 2, fist
    expect(at(102)).toEqual([2, 4, 1]);
    expect(at(102.4)).toEqual([2, 4, 2]); // rising to fist: open is next (repetition 2)
    expect(at(105.5)).toEqual([4, 4, 1]); // resting before the last cue, fist
    expect(at(106)).toEqual([4, 4, NaN]); // the last cue: nothing comes next
    expect(progress.v.at(-1)).toEqual([4, 4, NaN]); // the end
    expect(h.output("phase").v.at(-1)).toEqual([5]);
  });

  test("one frame of many ticks gives what one tick per frame gives", async () => {
    const a = await stimulus({ ...ONE, Autostart: true });
    const b = await stimulus({ ...ONE, Autostart: true });
    const ts = range(100, 102.5);
    a.push(ticks(...ts));
    for (const t of ts) b.push(ticks(t));
    for (const port of ["target", "phase", "trigger", "cue", "progress"]) {
      expect(b.output(port).t).toEqual(a.output(port).t);
      expect(b.output(port).v).toEqual(a.output(port).v);
    }
  });

  test("skip: the action ends the current phase; the skip input ends a capture (e.g. a TAC trial)", async () => {
    const h = await stimulus(
      { ...ONE, Tasks: [...ONE.Tasks, { Label: "open", Target: [0, 1] }], Autostart: true },
      { skip: true },
    );
    h.push(ticks(...range(100, 100.3)));
    h.clock = 100.25;
    expect(run(h, "skip")).toBe("skipped rest: now rise");
    h.push(ticks(100.3));
    // The rise started at 100.25: 0.05 s into 0.3 s.
    expect(h.output("target").v.at(-1)![0]).toBeCloseTo(Math.sin(Math.PI / 12) ** 2, 12);
    h.push(ticks(...range(100.4, 101.0)));
    expect(h.output("phase").v.at(-1)).toEqual([3]); // capture began at 100.75
    expect(h.output("trigger").t).toEqual([100.8]);
    h.push(vectors([100.93], [[0, 1, 5, 0.9, 0.01]]), 1); // a TAC trial ends: the capture ends
    expect(h.output("trigger")).toMatchObject({ t: [100.8, 100.93], v: [[1, 0.5], STOP] });
    h.push(ticks(101.0));
    expect(h.output("phase").v.at(-1)).toEqual([4]); // falling since 100.93
    h.push(vectors([101.05], [[0, 1, 5, 0.9, 0.01]]), 1); // not capturing: ignored
    expect(h.output("trigger").t).toHaveLength(2);
  });

  test("durations can be changed while running, the current phase included", async () => {
    const h = await stimulus({ ...ONE, Autostart: true });
    h.push(ticks(...range(100, 101.2)));
    expect(h.output("phase").v.at(-1)).toEqual([3]); // capture since 101.0
    h.instance.setParam!("Capture", 2);
    h.push(ticks(...range(101.2, 103.1)));
    expect(h.output("trigger").t).toEqual([101, 103]);
  });

  test("Repetitions and a seeded Shuffle: every task once per repetition, the same order per seed", async () => {
    const order = async (seed: number) => {
      const h = await stimulus({
        Tasks: ["a", "b", "c", "d"].map((l, i) => ({ Label: l, Target: [i] })),
        Repetitions: 3,
        Shuffle: true,
        Seed: seed,
        Rest: 0,
        Rise: 0,
        Hold: 0,
        Capture: 0.1,
        Fall: 0,
        Autostart: true,
      });
      h.push(ticks(...range(100, 101.3)));
      return h
        .output("trigger")
        .v.filter((v) => !Number.isNaN(v[0]!))
        .map((v) => v[0]!);
    };
    const a = await order(7);
    expect(a).toHaveLength(12);
    for (let r = 0; r < 3; r++) expect([...a.slice(4 * r, 4 * r + 4)].sort()).toEqual([0, 1, 2, 3]);
    expect(await order(7)).toEqual(a);
    expect(await order(8)).not.toEqual(a);
  });

  test("reset stops a capture in progress and returns to the state after the pipeline start", async () => {
    const h = await stimulus({ ...ONE, Autostart: true });
    h.push(ticks(...range(100, 101.2)));
    h.clock = 101.25;
    h.instance.reset!();
    expect(h.output("trigger")).toMatchObject({ t: [101, 101.25], v: [[1, 0.5], STOP] });
    expect(h.text).toBe("starting: 1 cue");
    h.clear();
    h.push(ticks(...range(105, 106.1)));
    expect(h.output("trigger").t).toEqual([106]); // restarted at 105
  });

  test("a subscribed timer input (no `-`) stays subscribed; ticks outside a protocol are ignored", async () => {
    const h = await stimulus(ONE, { subscribed: true });
    expect(h.subscribed).toEqual({});
    h.push(ticks(100, 100.1));
    expect(h.output("target").t).toEqual([]);
    run(h, "start");
    h.push(ticks(100.2));
    expect(h.output("target").t).toEqual([100.2]);
    expect(h.subscribed).toEqual({});
  });

  test("configuration errors", async () => {
    await expect(stimulus({})).rejects.toThrow("give Tasks");
    await expect(stimulus({ Tasks: ["fist"] })).rejects.toThrow(
      "task 'fist' names a label, but there are no Labels",
    );
    await expect(stimulus({ Labels: { fist: [1] }, Tasks: ["fsit"] })).rejects.toThrow(
      "unknown label 'fsit' (labels: fist); did you mean 'fist'?",
    );
    await expect(
      stimulus({
        Tasks: [
          { Label: "a", Target: [1] },
          { Label: "b", Target: [1, 2] },
        ],
      }),
    ).rejects.toThrow("has 2 values, but the other targets have 1");
    await expect(
      stimulus({
        Tasks: [
          { Label: "a", Target: [1] },
          { Label: "a", Target: [2] },
        ],
      }),
    ).rejects.toThrow("label 'a' already has the target [1]");
    await expect(
      BlockHarness.create(Stimulus, ONE, { inputs: [{ shape: vectorShape(2) }] }),
    ).rejects.toThrow("is not a timer");
  });

  test("in a pipeline: Stimulus → Buffer records only during capture phases, with the cue's target", async () => {
    const yaml =
      "T: { Type: ScheduledTimer, DesiredRate: 100 }\n" +
      "Emg: { Type: SinGenerator, Inputs: [T], Params: { Components: 3 } }\n" +
      "Sel: { Type: Selector, Inputs: [Emg] }\n" +
      "Stim:\n" +
      "  Type: Stimulus\n" +
      "  Inputs: [-T]\n" +
      "  Params:\n" +
      "    Labels: { rest: [0, 0], fist: [1, 0], open: [0, 1] }\n" +
      "    Tasks: [fist, open, rest]\n" +
      "    Rest: 0.5\n" +
      "    Rise: 0.25\n" +
      "    Hold: 0.25\n" +
      "    Capture: 0.5\n" +
      "    Fall: 0.25\n" +
      "    Autostart: true\n" +
      "Buf: { Type: Buffer, Inputs: [Stim.trigger, Sel], Params: { Stream: true } }\n";
    const r = await runVirtualPipeline(yaml, { catalog, duration: 6, start: 1000 });
    const rows = r.outputs.get("Buf")!;
    // The data is one hop further from the timer than the trigger, so on the tick where a capture
    // begins the trigger reaches the Buffer first and that tick's sample is recorded. (With the
    // data as close to the timer as the Stimulus, the runtime's delivery order decides; with
    // MOSAIC's `-Sel`, that sample is emitted before the Buffer subscribes and is not recorded.)
    // Cue k (1.75 s each) captures in [1001 + 1.75k, 1001.5 + 1.75k): 50 ticks at 100 Hz.
    const expected = [
      [1, 0],
      [0, 1],
      [0, 0],
    ];
    expected.forEach((target, k) => {
      const start = 1001 + 1.75 * k;
      const times = rows.t.filter(
        (_, i) => rows.v[i]![0] === target[0] && rows.v[i]![1] === target[1],
      );
      expect(times).toHaveLength(50);
      expect(times[0]).toBeCloseTo(start, 9);
      expect(times.at(-1)).toBeCloseTo(start + 0.49, 9);
    });
    expect(rows.t).toHaveLength(150);
    const stim = r.telemetry.blocks.find((b) => b.name === "Stim")!;
    expect(stim.text).toBe("done: 3 cues");
    expect(r.telemetry.edges.find((e) => e.from === "T" && e.to === "Stim")!.subscribed).toBe(
      false,
    );
    expect(r.telemetry.blocks.find((b) => b.name === "Buf")!.text).toBe("3 clusters, 150 rows");
  });

  test("legacy: MOSAIC's [captureSeconds, a;b;c, …] (cfg6_batch_with_stimulus.yaml)", () => {
    const yaml =
      "timer_subs: { Type: ScheduledTimer, DesiredRate: 25 }\n" +
      "visual_stim: {\n" +
      "  Type: Stimulus,\n" +
      "  Inputs: [ -timer_subs ],\n" +
      "  Params: [ 3.0,         # duration per stimulus (s)\n" +
      "    0;0;0;0;0;0;0;0;0;0;0;0,    # rest\n" +
      "    1;1;1;1;1;1;0;0;0;0;0;0,    # power\n" +
      "    0;0;0;0;0;0;1;0;0;0;0;0,    # flex\n" +
      "    0;0;0;0;0;0;0;0;0;0;0;0,    # rest\n" +
      "    1;1;1;1;1;1;0;0;0;0;0;0,    # power\n" +
      "    0;0;0;0;0;0;1;0;0;0;0;0     # flex\n" +
      "  ]\n" +
      "}\n" +
      "visual_stim_tv: { Type: Selector, Inputs: [ visual_stim ] }\n";
    const p = convertLegacy(yaml, "visual_stim") as {
      Capture: number;
      Tasks: { Label: string; Target: number[] }[];
    };
    expect(p).toMatchObject({ Capture: 3, Rest: 2, Rise: 1, Hold: 2, Fall: 1, Autostart: false });
    expect(p.Tasks.map((t) => t.Label)).toEqual([
      "rest",
      "task1",
      "task2",
      "rest",
      "task1",
      "task2",
    ]);
    expect(p.Tasks[1]!.Target).toEqual([1, 1, 1, 1, 1, 1, 0, 0, 0, 0, 0, 0]);
    const bad = loadBlock(
      "T: { Type: ScheduledTimer, DesiredRate: 25 }\nS: { Type: Stimulus, Inputs: [-T], Params: [3.0] }\n",
      "S",
    );
    expect(bad.errors[0]!.message).toContain("expected [captureSeconds, task1, task2, …]");
  });
});
