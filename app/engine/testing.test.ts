import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock, type AnyBlockDefinition, type BlockContext } from "./block";
import { Frame, vectorShape } from "./frame";
import { BlockHarness, noResources } from "./testing";

/** A block that only keeps the context it was created with. */
function probe(): { def: AnyBlockDefinition; ctx: () => BlockContext } {
  let ctx: BlockContext | undefined;
  const def = defineBlock({
    type: "Probe",
    category: "Testing",
    summary: "keeps its context",
    help: "keeps its context",
    params: z.strictObject({}),
    inputs: { min: 0, max: 2 },
    create(c) {
      ctx = c;
      return {};
    },
  }) as AnyBlockDefinition;
  return { def, ctx: () => ctx! };
}

describe("BlockHarness context", () => {
  test("what the block is told: name, type, inputs, rates, clock, resources", async () => {
    const p = probe();
    const h = await BlockHarness.create(
      p.def,
      {},
      {
        inputs: [
          { shape: vectorShape(2), rate: 100, type: "Src" },
          { shape: null, isTimer: true, subscribed: false },
        ],
        now: 5,
        batchingS: 0.25,
      },
    );
    const ctx = p.ctx();
    expect(Object.keys(ctx)).toEqual([
      "name",
      "type",
      "inputs",
      "declaredRate",
      "desiredRate",
      "setDesiredRate",
      "now",
      "startTime",
      "virtual",
      "resources",
      "io",
      "output",
      "batching",
      "every",
      "at",
      "setText",
      "warn",
      "error",
      "setAwaiting",
      "reportCompute",
      "finish",
      "setSubscribed",
      "openLog",
    ]);
    expect(ctx.name).toBe("block");
    expect(ctx.type).toBe("Probe");
    expect(ctx.inputs).toEqual([
      {
        index: 0,
        source: "in0",
        block: "in0",
        port: "out",
        type: "Src",
        shape: { rows: 1, cols: 2 },
        rate: 100,
        isTimer: false,
        subscribed: true,
      },
      {
        index: 1,
        source: "in1",
        block: "in1",
        port: "out",
        shape: null,
        rate: 0,
        isTimer: true,
        subscribed: false,
      },
    ]);
    expect(ctx.declaredRate).toBeUndefined();
    expect(ctx.desiredRate).toBe(100);
    ctx.setDesiredRate(30);
    expect([ctx.desiredRate, h.desiredRate]).toEqual([30, 30]);
    expect([ctx.now(), ctx.startTime, ctx.virtual, ctx.batching]).toEqual([5, 5, true, 0.25]);
    h.tick(7);
    expect(ctx.now()).toBe(7);
    expect(ctx.resources).toBe(noResources);
    expect(ctx.io).toEqual({});
  });

  test("outputs are recorded with their metadata; bad metadata throws", async () => {
    const p = probe();
    const h = await BlockHarness.create(p.def, {});
    const ctx = p.ctx();
    const out = ctx.output(vectorShape(2), undefined, { unit: "V" });
    expect([out.name, out.idle, h.ports[0]]).toEqual(["out", false, out]);
    expect(h.metas.get("out")).toEqual({ unit: "V" });
    const f: Frame = out.frame(2);
    f.t.set([1, 2]);
    f.v.set([1, 2, 3, 4]);
    out.emit(f);
    expect(h.output()).toEqual({
      t: [1, 2],
      v: [
        [1, 2],
        [3, 4],
      ],
      frames: [2],
    });
    expect(() => ctx.output(vectorShape(2), "x", { labels: ["a"] })).toThrow(
      "output 'x': 1 channel labels for 2 values",
    );
    expect(h.out.has("x")).toBe(false);
  });

  test("timers and one-shots", async () => {
    const p = probe();
    const h = await BlockHarness.create(p.def, {});
    const ctx = p.ctx();
    const seen: number[] = [];
    const t = ctx.every(10, (times, n) => seen.push(...Array.from(times.subarray(0, n))));
    expect(h.timers[0]).toMatchObject({ hz: 10, running: false, catchUp: "all" });
    h.tick(1);
    t.start();
    expect([t.running, t.fired, t.missed]).toEqual([true, 0, 0]);
    h.ticks([2, 3]);
    t.setRate(20);
    t.stop();
    h.tick(4);
    expect([seen, h.timers[0]!.hz, t.running]).toEqual([[2, 3], 20, false]);
    ctx.every(1, () => {}, { catchUp: "skip" });
    expect(h.timers[1]!.catchUp).toBe("skip");
    const fired: number[] = [];
    ctx.at(9, (x) => fired.push(x));
    ctx.at(8, (x) => fired.push(x));
    expect([h.fireOneShot(), h.fireOneShot(), fired, ctx.now()]).toEqual([true, false, [8], 8]);
  });

  test("what the block reports", async () => {
    const p = probe();
    const h = await BlockHarness.create(p.def, {}, { inputs: [{ shape: null }] });
    const ctx = p.ctx();
    ctx.setText("hello");
    ctx.warn("w");
    ctx.error("e");
    ctx.error("e2", "detail");
    ctx.setAwaiting(3);
    ctx.reportCompute(1.5);
    ctx.reportCompute(2, 10);
    expect(ctx.setSubscribed(0, false)).toBe(true);
    expect(ctx.setSubscribed(1, false)).toBe(false);
    expect(h.finished).toBe(false);
    ctx.finish();
    const log = ctx.openLog("logs", "s", vectorShape(1))!;
    const f = new Frame(vectorShape(1), 1);
    f.n = 1;
    f.t[0] = 1;
    f.v[0] = 4;
    log.write(f);
    expect(h.text).toBe("hello");
    expect(h.warnings).toEqual(["w"]);
    expect(h.errors).toEqual(["e", "e2\ndetail"]);
    expect(h.awaiting).toBe(3);
    expect(h.computeReports).toEqual([{ ms: 1.5 }, { ms: 2, budgetMs: 10 }]);
    expect(h.subscribed).toEqual({ 0: false });
    expect(h.finished).toBe(true);
    expect(h.logs.text("logs/s.txt")).toBe("1.000000,4\n");
  });
});
