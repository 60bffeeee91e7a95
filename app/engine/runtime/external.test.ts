/**
 * The block API for work outside `process` (a sidecar): `ctx.error` counts like an exception in
 * `process`, and `ctx.setAwaiting` holds the virtual clock until the awaited results are in.
 */
import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock } from "../block";
import { createCatalog } from "../catalog";
import { VirtualClock } from "../clock";
import { vectorShape } from "../frame";
import { loadPipeline } from "../pipeline/loader";
import { TEST_BLOCKS } from "../test-blocks";
import { noResources, runVirtualPipeline } from "../testing";
import { Runtime } from "./runtime";
import { runVirtual } from "./virtual";

/** Reports an error for every input event, as a block whose helper process failed would. */
const Failing = defineBlock({
  type: "Failing",
  category: "Testing",
  summary: "fails outside process",
  help: "calls ctx.error for every event",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1 },
  create(ctx) {
    ctx.output(vectorShape(1));
    let k = 0;
    return {
      process(f) {
        for (let i = 0; i < f.n; i++) ctx.error(`call ${++k} failed`, "Traceback: here");
      },
    };
  },
});

/** Answers each input later, from outside the engine (the test calls `answer`). */
const pending: { t: number; v: number; answer: () => void }[] = [];
const Outside = defineBlock({
  type: "Outside",
  category: "Testing",
  summary: "answers later",
  help: "hands every event to the test, which answers it later",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1 },
  create(ctx) {
    const out = ctx.output(vectorShape(1));
    return {
      process(f) {
        for (let i = 0; i < f.n; i++) {
          const t = f.t[i]!;
          const v = f.v[i]!;
          pending.push({
            t,
            v,
            answer: () => {
              pending.shift();
              const o = out.frame(1);
              o.t[0] = t;
              o.v[0] = v * 10;
              out.emit(o);
              ctx.setAwaiting(pending.length);
            },
          });
        }
        ctx.setAwaiting(pending.length);
      },
    };
  },
});

const catalog = createCatalog([...TEST_BLOCKS, Failing, Outside]);

describe("work outside process", () => {
  test("ctx.error counts every error, with an error event (rate-limited) that carries the detail", async () => {
    const run = await runVirtualPipeline(
      `
Timer: { Type: Tick, DesiredRate: 10 }
Src: { Type: Counter, Inputs: [Timer] }
F: { Type: Failing, Inputs: [Src] }
`,
      { catalog, duration: 3 },
    );
    const f = run.telemetry.blocks.find((b) => b.name === "F")!;
    expect(f.errors).toBe(31);
    expect(f.lastError).toBe("call 31 failed");
    const events = run.telemetry.events.filter((e) => e.block === "F");
    expect(events.every((e) => e.level === "error")).toBe(true);
    expect(events[0]!.message).toBe("call 1 failed\nTraceback: here");
    // One event per 2 s after the first: the count is in the telemetry, not in the events.
    expect(events.length).toBe(2);
    expect(events[1]!.message).toMatch(/^call 21 failed \(21 errors so far\)\nTraceback: here$/);
  });

  test("ctx.setAwaiting: virtual time stands still until the awaited results are in", async () => {
    const loaded = loadPipeline(
      `
Timer: { Type: Tick, DesiredRate: 10 }
Src: { Type: Counter, Inputs: [Timer] }
Far: { Type: Outside, Inputs: [Src] }
`,
      "t.yaml",
      catalog,
    );
    const clock = new VirtualClock(0);
    const { runtime } = await Runtime.create({
      spec: loaded.spec!,
      catalog,
      clock,
      virtual: true,
      resources: noResources,
      ignorePlacement: true,
    });
    const rt = runtime!;
    const got: number[] = [];
    rt.tap("Far", undefined, (f) => got.push(f.t[0]!));
    let woken = 0;
    rt.onWake = () => woken++;
    rt.start();
    expect(runVirtual(rt, clock, 1)).toBe("waiting");
    const at = clock.t;
    expect(rt.awaiting).toBe(1);
    expect(runVirtual(rt, clock, 1)).toBe("waiting"); // still waiting: time stands still
    expect(clock.t).toBe(at);
    woken = 0;
    pending[0]!.answer();
    expect(rt.awaiting).toBe(0);
    expect(woken).toBeGreaterThan(0); // the driver is told to go on
    expect(got).toEqual([at]);
    // Every tick is answered before time moves on.
    let rounds = 0;
    while (runVirtual(rt, clock, 1) === "waiting") {
      pending[0]!.answer();
      rounds++;
    }
    expect(clock.t).toBe(1);
    expect(got.length).toBe(rounds + 1);
    expect(got.length).toBe(11);
    rt.stop();
    expect(rt.awaiting).toBe(0);
    rt.dispose();
  });
});
