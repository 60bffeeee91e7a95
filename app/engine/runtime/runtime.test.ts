import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock } from "../block";
import { createCatalog } from "../catalog";
import { Frame, vectorShape } from "../frame";
import { TEST_BLOCKS } from "../test-blocks";
import { runVirtualPipeline } from "../testing";
import { Scheduler } from "./scheduler";
import { StatusTracker } from "./status";

/** Emits `Count` one-event frames per input event (a bursty producer). */
const Burst = defineBlock({
  type: "Burst",
  category: "Testing",
  summary: "burst",
  help: "burst",
  params: z.strictObject({ Count: z.number().int().default(3).describe("frames per input") }),
  inputs: { min: 1, max: 1 },
  create(ctx, p) {
    const out = ctx.output(vectorShape(1));
    let k = 0;
    return {
      process(f) {
        for (let i = 0; i < f.n; i++) {
          for (let j = 0; j < p.Count; j++) {
            const o = out.frame(1);
            o.t[0] = f.t[i]!;
            o.v[0] = ++k;
            out.emit(o);
          }
        }
      },
    };
  },
});

/** Throws on every odd event. */
const Flaky = defineBlock({
  type: "Flaky",
  category: "Testing",
  summary: "flaky",
  help: "flaky",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1 },
  create(ctx) {
    const out = ctx.output(vectorShape(1));
    let k = 0;
    return {
      process(f) {
        if (k++ % 2 === 1) throw new Error("odd event");
        const o = out.frame(f.n);
        o.copyEvents(f, 0, f.n, 0);
        out.emit(o);
      },
    };
  },
});

/** y[n] = x[n] + 0.5 * (its own previous output, fed back through the graph). */
const Mix = defineBlock({
  type: "Mix",
  category: "Testing",
  summary: "feedback mixer",
  help: "feedback mixer",
  params: z.strictObject({}),
  inputs: { min: 2, max: 2 },
  create(ctx) {
    const out = ctx.output(vectorShape(1));
    let fb = 0;
    return {
      process(f, port) {
        if (port === 1) {
          fb = f.v[(f.n - 1) * f.stride]!;
          return;
        }
        const o = out.frame(f.n);
        for (let i = 0; i < f.n; i++) {
          o.t[i] = f.t[i]!;
          o.v[i] = f.v[i * f.stride]! + 0.5 * fb;
        }
        out.emit(o);
      },
    };
  },
});

const catalog = createCatalog([...TEST_BLOCKS, Burst, Flaky, Mix]);

describe("delivery", () => {
  test("breadth-first, deterministic, ports and fan-out", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 10 }
C: { Type: Counter, Inputs: [T], Params: { Channels: 4 } }
H: { Type: Halves, Inputs: [C] }
A: { Type: Gain, Inputs: [H.a], Params: { Gain: 10 } }
B: { Type: Gain, Inputs: [H.b], Params: { Gain: -1 } }
`,
      { catalog, duration: 0.25 },
    );
    expect(run.outputs.get("C")!.v).toEqual([
      [1, 1, 1, 1],
      [2, 2, 2, 2],
      [3, 3, 3, 3],
    ]);
    expect(run.outputs.get("A")!.v).toEqual([
      [10, 10],
      [20, 20],
      [30, 30],
    ]);
    expect(run.outputs.get("B")!.v).toEqual([
      [-1, -1],
      [-2, -2],
      [-3, -3],
    ]);
    expect(run.outputs.get("A")!.t).toEqual([0, 0.1, 0.2]);
  });

  test("feedback cycles run without re-entrance", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 1 }
C: { Type: Counter, Inputs: [T] }
M: { Type: Mix, Inputs: [C, G] }
G: { Type: Gain, Inputs: [M], Params: { Gain: 1 } }
`,
      { catalog, duration: 3 },
    );
    // M sees its own previous output (through G) before the next counter value.
    expect(run.outputs.get("M")!.v.map((r) => r[0])).toEqual([1, 2.5, 4.25, 6.125]);
  });

  test("drop-oldest keeps the newest events within capacity and counts drops", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 1 }
B: { Type: Burst, Inputs: [T], Params: { Count: 5 } }
G: { Type: Gain, Inputs: [B], Params: { Gain: 1 }, Queue: { Capacity: 2 } }
`,
      { catalog, duration: 0 },
    );
    expect(run.outputs.get("G")!.v.map((r) => r[0])).toEqual([4, 5]);
    const edge = run.telemetry.edges.find((e) => e.to === "G")!;
    expect(edge).toMatchObject({ dropped: 3, delivered: 2 });
    expect(run.telemetry.blocks.find((b) => b.name === "G")!.dropsIn).toBe(3);
  });

  test("drop-newest keeps the oldest", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 1 }
B: { Type: Burst, Inputs: [T], Params: { Count: 5 } }
G: { Type: Gain, Inputs: [B], Params: { Gain: 1 }, Queue: { Policy: drop-newest, Capacity: 2 } }
`,
      { catalog, duration: 0 },
    );
    expect(run.outputs.get("G")!.v.map((r) => r[0])).toEqual([1, 2]);
  });

  test("latest delivers only the newest event", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 1 }
B: { Type: Burst, Inputs: [T], Params: { Count: 4 } }
G: { Type: Gain, Inputs: [B], Params: { Gain: 1 }, Queue: { Policy: latest } }
`,
      { catalog, duration: 1 },
    );
    expect(run.outputs.get("G")!.v.map((r) => r[0])).toEqual([4, 8]);
    expect(run.telemetry.edges.find((e) => e.to === "G")!.dropped).toBe(6);
  });

  test("-Name inputs are declared but not subscribed until subscribed at run time", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 1 }
C: { Type: Counter, Inputs: [T] }
G: { Type: Gain, Inputs: [-C], Params: { Gain: 1 } }
`,
      {
        catalog,
        duration: 0,
      },
    );
    expect(run.outputs.get("G")!.v).toEqual([]);
    const run2 = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 1 }
C: { Type: Counter, Inputs: [T] }
G: { Type: Gain, Inputs: [-C], Params: { Gain: 1 } }
`,
      { catalog, duration: 2, beforeRun: (rt) => rt.invoke("G", "subscribe", "C") },
    );
    expect(run2.outputs.get("G")!.v.map((r) => r[0])).toEqual([1, 2, 3]);
    expect(run2.telemetry.edges.find((e) => e.to === "G")!.subscribed).toBe(true);
  });

  test("a failing block reports its error and the rest keeps running", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 1 }
C: { Type: Counter, Inputs: [T] }
F: { Type: Flaky, Inputs: [C] }
G: { Type: Gain, Inputs: [C], Params: { Gain: 2 } }
`,
      { catalog, duration: 3 },
    );
    expect(run.outputs.get("G")!.v.map((r) => r[0])).toEqual([2, 4, 6, 8]);
    expect(run.outputs.get("F")!.v.map((r) => r[0])).toEqual([1, 3]);
    const f = run.telemetry.blocks.find((b) => b.name === "F")!;
    expect(f.errors).toBe(2);
    expect(f.lastError).toBe("odd event");
    expect(run.telemetry.events[0]).toMatchObject({
      level: "error",
      block: "F",
      message: "odd event",
    });
  });

  test("live params are validated before they reach the block", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 1 }
C: { Type: Counter, Inputs: [T] }
`,
      {
        catalog,
        duration: 1,
        beforeRun: (rt) => {
          expect(() => rt.setParam("C", "Scale", "big")).toThrow(/invalid value for 'Scale'/);
          expect(() => rt.setParam("C", "Channels", 3)).toThrow(
            /cannot be changed while running \(live params: Scale\)/,
          );
          expect(() => rt.invoke("C", "explode")).toThrow(
            /no action 'explode'.*subscribe, unsubscribe, reset/,
          );
          rt.setParam("C", "Scale", 10);
        },
      },
    );
    expect(run.outputs.get("C")!.v).toEqual([[10], [20]]);
  });

  test("Path logs: timestamp with microseconds, values in shortest round-trip form", async () => {
    const run = await runVirtualPipeline(
      `
T: { Type: Tick, DesiredRate: 3 }
C: { Type: Counter, Inputs: [T], Params: { Channels: 2, Scale: 0.1 }, Path: out/ }
`,
      { catalog, duration: 1, start: 1700000000 },
    );
    expect(run.logs.text("out/C.txt")).toBe(
      "1700000000.000000,0.1,0.1\n1700000000.333333,0.2,0.2\n1700000000.666667,0.30000000000000004,0.30000000000000004\n1700000001.000000,0.4,0.4\n",
    );
  });
});

describe("batching", () => {
  const pipeline = (ms: number) => `
Pipeline: { BatchingMs: ${ms} }
T: { Type: Tick, DesiredRate: 1000 }
C: { Type: Counter, Inputs: [T], Params: { Channels: 2 } }
S: { Type: Tick, DesiredRate: 25, BatchingMs: 0 }
`;

  test("virtual time wakes as a batching real-time worker would: same events, fewer frames", async () => {
    const one = await runVirtualPipeline(pipeline(0), { catalog, duration: 1 });
    const five = await runVirtualPipeline(pipeline(5), { catalog, duration: 1 });
    const c1 = one.outputs.get("C")!;
    const c5 = five.outputs.get("C")!;
    expect(c1.t).toHaveLength(1001);
    expect(c5.t).toEqual(c1.t);
    expect(c5.v).toEqual(c1.v);
    expect(Math.max(...c1.frames)).toBe(1);
    // 5 ms at 1 kHz: the 6 ticks within the interval go out together (a 25 Hz wake-up may split a batch).
    expect(Math.max(...c5.frames)).toBe(6);
    expect(c5.frames.length).toBeLessThan(c1.frames.length / 4);
    // The block's own BatchingMs: the 25 Hz timer fires alone, one tick per frame.
    expect(Math.max(...five.outputs.get("S")!.frames)).toBe(1);
    // Timestamps stay the exact deadlines: k / 1000.
    c5.t.forEach((t, k) => expect(t).toBe(k / 1000));
  });

  test("telemetry reports each timer's batching and catch-up policy", async () => {
    const run = await runVirtualPipeline(pipeline(3), { catalog, duration: 0.1 });
    const timer = (name: string) => run.telemetry.blocks.find((b) => b.name === name)!.timer!;
    expect(timer("T").batchingMs).toBe(3);
    expect(timer("S").batchingMs).toBe(0);
    expect(timer("T").catchUp).toBe("all");
  });
});

describe("scheduler", () => {
  const collect = (into: number[][]) => (times: Float64Array, n: number) =>
    into.push(Array.from(times.subarray(0, n)));
  const fireAll = (s: Scheduler, now: number) =>
    s.fireDue(now, (x, n) => (x.period > 0 ? x.onTicks(x.times, n) : x.cb(x.times[0]!)));

  test("lossless: after a stall every due tick goes out in one call, stamped with its deadline", () => {
    const s = new Scheduler(false);
    const calls: number[][] = [];
    const e = s.addPeriodic("t", 100, collect(calls));
    s.start(e, 100);
    fireAll(s, 100);
    // The worker was blocked for 35 ms: the three ticks due since go out together.
    expect(fireAll(s, 100.035)).toBe(1);
    expect(calls.length).toBe(2);
    expect(calls[0]).toEqual([100]);
    expect(calls[1]!.length).toBe(3);
    calls[1]!.forEach((t, i) => expect(t).toBe(100 + (i + 1) * 0.01));
    expect(e.missed).toBe(0);
    expect(e.fired).toBe(4);
    expect(e.next).toBeCloseTo(100.04, 12);
    // Lateness is measured against the newest deadline fired.
    expect(e.lateness!.count).toBe(2);
    expect(e.lateness!.quantile(1)).toBe(5000);
  });

  test("catchUp skip: only the newest due tick goes out, the others are counted as missed", () => {
    const s = new Scheduler(false);
    const calls: number[][] = [];
    const e = s.addPeriodic("t", 100, collect(calls), { catchUp: "skip", batchS: 0.05 });
    s.start(e, 100);
    fireAll(s, 100);
    fireAll(s, 100.035);
    expect(calls).toEqual([[100], [100.03]]);
    expect(e.missed).toBe(2);
    // A skipping timer never waits to batch.
    expect(s.nextWake()).toBe(e.next);
  });

  test("batching: the wake-up waits for the last tick within the interval, then fires them all", () => {
    const s = new Scheduler(false);
    const calls: number[][] = [];
    const e = s.addPeriodic("t", 2000, collect(calls), { batchS: 0.002 });
    s.start(e, 10);
    expect(s.nextWake()).toBe(10 + 4 / 2000);
    fireAll(s, s.nextWake());
    expect(calls).toEqual([[10, 10.0005, 10.001, 10.0015, 10.002]]);
    expect(s.nextWake()).toBeCloseTo(10 + 9 / 2000, 12);
    // A period longer than the interval: a wake-up per tick.
    const slow = s.addPeriodic("slow", 200, () => {}, { batchS: 0.002 });
    s.start(slow, 10);
    expect(s.nextWake()).toBe(10);
  });

  test("a one-shot with a latest time runs when the worker is awake from its due time on, else wakes it then", () => {
    const s = new Scheduler(true);
    const ran: number[] = [];
    const shot = s.addOneShot("player", (t) => ran.push(t));
    s.once(shot, 10.001, 10.004);
    const tick = s.addPeriodic("t", 500, () => {});
    s.start(tick, 10);
    fireAll(s, 10);
    expect(ran).toEqual([]);
    // Nothing else due before 10.004: the worker wakes for the one-shot at its latest time.
    s.stop(tick);
    expect(s.nextWake()).toBe(10.004);
    // Awake at 10.002 for something else: it runs then (stamped with its due time).
    s.start(tick, 10.002);
    fireAll(s, 10.002);
    expect(ran).toEqual([10.001]);
    // Without a latest time a one-shot wakes the worker at its due time, as before.
    s.once(shot, 11);
    s.stop(tick);
    expect(s.nextWake()).toBe(11);
  });

  test("a very long stall is delivered in bounded calls, nothing lost", () => {
    const s = new Scheduler(false);
    let total = 0;
    let largest = 0;
    const e = s.addPeriodic("t", 10000, (_t, n) => {
      total += n;
      largest = Math.max(largest, n);
    });
    s.start(e, 0);
    fireAll(s, 20); // 200 001 ticks due
    expect(total).toBe(200_001);
    expect(largest).toBe(65536);
  });

  test("an entry fired slightly early is stamped with its deadline; re-arming in the past cannot hang", () => {
    const s = new Scheduler(false);
    s.earlyTolerance = 0.0001;
    const stamps: number[] = [];
    const e = s.addOneShot("once", (t) => stamps.push(t));
    s.once(e, 10.00005);
    fireAll(s, 10);
    expect(stamps).toEqual([10.00005]);
    // A callback that always asks to run again at a time already due must not loop forever.
    const loop = s.addOneShot("loop", () => s.once(loop, 5));
    s.once(loop, 5);
    expect(fireAll(s, 10)).toBe(100_000);
  });

  test("deadlines are base + k/rate (no drift) and fire in deadline order", () => {
    const s = new Scheduler(true);
    const order: string[] = [];
    const a = s.addPeriodic("a", 10, () => order.push("a"));
    const b = s.addPeriodic("b", 4, () => order.push("b"));
    s.start(a, 0);
    s.start(b, 0);
    let t = 0;
    for (let i = 0; i < 12; i++) {
      t = s.nextDeadline();
      fireAll(s, t);
    }
    // 0: a b, .1 a, .2 a, .25 b, .3 a, .4 a, .5 a b, .6 a, .7 a, .75 b, .8 a, .9 a
    expect(order.join("")).toBe("abaabaaabaabaa");
    expect(a.next).toBe(a.k / 10);
  });
});

describe("status", () => {
  const frameAt = (t: number) => Frame.from(vectorShape(1), [t], [[0]]);

  test("rate over the last 100 outputs; on time; idle after 10 periods", () => {
    const s = new StatusTracker(100);
    for (let i = 0; i < 150; i++) s.record(frameAt(i / 100), i / 100);
    const now = 1.49;
    expect(s.rate()).toBeCloseTo(100, 9);
    expect(s.evaluate(now)).toMatchObject({ status: "ontime", lagging: false, stumbling: false });
    expect(s.evaluate(1.49 + 0.099).status).toBe("ontime");
    expect(s.evaluate(1.49 + 0.101).status).toBe("idle");
  });

  test("a late batch is lagging for as long as it was delayed, at least 100 ms, at any rate", () => {
    for (const hz of [25, 1926]) {
      const s = new StatusTracker(hz);
      s.batchS = 0.005;
      let k = 0;
      /** Outputs on time up to `t` (so the block is not idle), then the status at `t`. */
      const at = (t: number) => {
        for (; k / hz <= t; k++) s.record(frameAt(k / hz), k / hz);
        return s.evaluate(t);
      };
      const now = 10;
      at(now);
      // The late threshold: max(2 periods, 50 ms) + the batching interval.
      expect(s.lateAfter()).toBeCloseTo(Math.max(2 / hz, 0.05) + 0.005, 12);
      s.delivered(now - s.lateAfter() + 0.001, now);
      expect(at(now).status).toBe("ontime");
      s.delivered(now - 0.3, now); // 300 ms late
      expect(at(now).status).toBe("lagging");
      expect(at(now + 0.29).lagging).toBe(true);
      expect(at(now + 0.31).lagging).toBe(false);
      s.delivered(now + 0.4 - s.lateAfter() - 0.001, now + 0.4); // just late: held 100 ms
      expect(at(now + 0.49).lagging).toBe(true);
      expect(at(now + 0.51).lagging).toBe(false);
    }
  });

  test("lagging below 95 % of the desired rate", () => {
    const s = new StatusTracker(100);
    for (let i = 0; i < 100; i++) s.record(frameAt(i / 94), i / 94);
    expect(s.evaluate(99 / 94).status).toBe("lagging");
    const t = new StatusTracker(100);
    for (let i = 0; i < 100; i++) t.record(frameAt(i / 96), i / 96);
    expect(t.evaluate(99 / 96).status).toBe("ontime");
  });

  test("stumbling when one call took longer than a period, within the window; lagging wins", () => {
    const s = new StatusTracker(100);
    for (let i = 0; i < 100; i++) s.record(frameAt(i / 100), i / 100);
    s.compute(10.5, 0.5);
    expect(s.evaluate(0.99)).toMatchObject({ status: "stumbling", stumbling: true });
    // 100 more outputs later the overrun has left the window.
    for (let i = 100; i < 200; i++) s.record(frameAt(i / 100), i / 100);
    expect(s.evaluate(1.99).status).toBe("ontime");
    const l = new StatusTracker(100);
    for (let i = 0; i < 100; i++) l.record(frameAt(i / 50), i / 50);
    l.compute(20, 1);
    expect(l.evaluate(99 / 50)).toMatchObject({
      status: "lagging",
      stumbling: true,
      lagging: true,
    });
  });

  test("work reported outside process (a sidecar call) counts toward stumbling, not the CPU total", () => {
    const s = new StatusTracker(100);
    for (let i = 0; i < 100; i++) s.record(frameAt(i / 100), i / 100);
    s.external(9, 0.5); // within one period
    expect(s.evaluate(0.99).status).toBe("ontime");
    s.external(4, 0.6, 3); // beyond its own budget
    expect(s.evaluate(0.99).status).toBe("stumbling");
    expect(s.computeMaxWindow).toBe(9);
    expect(s.calls).toBe(0);
    expect(s.computeTotal).toBe(0);
    const t = new StatusTracker(100);
    for (let i = 0; i < 100; i++) t.record(frameAt(i / 100), i / 100);
    t.external(10.5, 0.5);
    expect(t.evaluate(0.99)).toMatchObject({ status: "stumbling", stumbling: true });
  });

  test("ctx.reportCompute reaches the block's status", async () => {
    const Reporter = defineBlock({
      type: "Reporter",
      category: "Testing",
      summary: "reports",
      help: "reports a 25 ms compute for every event, like a slow sidecar call",
      params: z.strictObject({}),
      inputs: { min: 1, max: 1 },
      create(ctx) {
        const out = ctx.output(vectorShape(1));
        return {
          process(f) {
            ctx.reportCompute(25);
            const o = out.frame(f.n);
            o.copyEvents(f, 0, f.n, 0);
            out.emit(o);
          },
        };
      },
    });
    const catalog = createCatalog([...TEST_BLOCKS, Reporter]);
    const run = await runVirtualPipeline(
      `
Timer: { Type: Tick, DesiredRate: 100 }
Src: { Type: Counter, Inputs: [Timer] }
Slow: { Type: Reporter, Inputs: [Src] }
Fast: { Type: Reporter, Inputs: [Src], DesiredRate: 20 }
`,
      { catalog, duration: 2 },
    );
    const by = Object.fromEntries(run.telemetry.blocks.map((b) => [b.name, b]));
    expect(by.Slow!.status).toBe("stumbling");
    expect(by.Slow!.computeMaxMs).toBe(25);
    expect(by.Src!.status).toBe("ontime");
    expect(by.Fast!.status).toBe("ontime"); // 25 ms within its 50 ms period
  });

  test("idle before the first output; a pause does not read as lagging afterwards", () => {
    const s = new StatusTracker(100);
    expect(s.evaluate(0).status).toBe("idle");
    for (let i = 0; i < 100; i++) s.record(frameAt(i / 100), i / 100);
    for (let i = 0; i < 10; i++) s.record(frameAt(10 + i / 100), 10 + i / 100);
    expect(s.evaluate(10.09)).toMatchObject({ status: "ontime" });
    expect(s.rate()).toBeCloseTo(100, 6);
  });
});
