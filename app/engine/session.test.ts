import { describe, expect, test } from "vitest";
import { VirtualClock } from "./clock";
import type { DataMessage, EngineMessage } from "./protocol";
import type { Runtime } from "./runtime/runtime";
import { runVirtual } from "./runtime/virtual";
import { Frame } from "./frame";
import {
  EngineSession,
  Watch,
  withBuiltInActions,
  type LoopHooks,
  type SessionPlatform,
} from "./session";
import { testCatalog } from "./test-blocks";
import { noResources } from "./testing";

/** A platform whose "real-time" loop is driven by the test through the virtual clock. */
function fakePlatform() {
  const clock = new VirtualClock(100);
  const sent: EngineMessage[] = [];
  let running: { rt: Runtime; hooks: LoopHooks } | undefined;
  const platform: SessionPlatform = {
    engine: "test",
    sharedMemory: false,
    clock: () => clock,
    resources: () => noResources,
    startLoop(rt, hooks) {
      running = { rt, hooks };
      return { stop: () => (running = undefined), wake: () => {} };
    },
    post: (m) => sent.push(m),
  };
  /** Runs `seconds` of pipeline time with telemetry every 50 ms. */
  const advance = (seconds: number) => {
    const end = clock.t + seconds;
    while (running && clock.t < end - 1e-9) {
      runVirtual(running.rt, clock, Math.min(end, clock.t + running.hooks.telemetryIntervalS));
      running.hooks.onTelemetry();
    }
  };
  return { platform, sent, clock, advance };
}

const PIPELINE = `
# a comment
T: { Type: Tick, DesiredRate: 100 }
C: { Type: Counter, Inputs: [T], Params: { Channels: 2 } }
G: { Type: Gain, Inputs: [C], Params: { Gain: 2 } }
`;

const replies = (sent: EngineMessage[]) => sent.filter((m) => m.type === "reply");

describe("EngineSession", () => {
  test("a block's actions, then the built-in ones it does not define (its own reset once)", () => {
    const names = (own: { name: string }[]) => withBuiltInActions(own).map((a) => a.name);
    expect(names([{ name: "train" }])).toEqual(["train", "reset", "subscribe", "unsubscribe"]);
    expect(names([{ name: "reset" }, { name: "save" }])).toEqual([
      "reset",
      "save",
      "subscribe",
      "unsubscribe",
    ]);
  });

  test("hello, load (graph with schemas), start, telemetry, stop", async () => {
    const f = fakePlatform();
    const s = new EngineSession(testCatalog, f.platform);
    await s.handle({ type: "hello", version: 1 });
    expect(f.sent[0]).toMatchObject({ type: "hello", version: 1, engine: "test" });
    await s.handle({ type: "load", id: 1, file: "p.yaml", source: PIPELINE });
    const r = replies(f.sent)[0]!;
    expect(r).toMatchObject({ type: "reply", id: 1, ok: true });
    const graph = (
      r as {
        graph: {
          blocks: {
            name: string;
            paramsSchema: { properties: object };
            live: string[];
            actions: { name: string }[];
            outputs: unknown[];
          }[];
        };
      }
    ).graph;
    expect(graph.blocks.map((b) => b.name)).toEqual(["T", "C", "G"]);
    const c = graph.blocks[1]!;
    expect(Object.keys(c.paramsSchema.properties)).toEqual(["Channels", "Scale"]);
    expect(c.live).toEqual(["Scale"]);
    expect(c.actions.map((a) => a.name)).toContain("reset");
    expect(c.outputs).toEqual([{ name: "out", shape: { rows: 1, cols: 2 } }]);
    expect(f.sent.some((m) => m.type === "state" && m.state === "loaded")).toBe(true);

    await s.handle({ type: "start", id: 2 });
    f.advance(1);
    const tel = f.sent.filter((m) => m.type === "telemetry");
    expect(tel.length).toBeGreaterThanOrEqual(19);
    const last = tel.at(-1)!;
    // Every block keeps up (one call measured longer than its period on a loaded machine makes
    // it stumbling, never lagging).
    expect(
      last.type === "telemetry" &&
        last.telemetry.blocks.every((b) => b.status === "ontime" || b.status === "stumbling"),
    ).toBe(true);
    await s.handle({ type: "stop", id: 3 });
    expect(f.sent.at(-2)).toMatchObject({ type: "state", state: "stopped" });
  });

  test("watch streams decimated panel data while watched; setParam and invoke reply", async () => {
    const f = fakePlatform();
    const s = new EngineSession(testCatalog, f.platform);
    await s.handle({ type: "load", id: 1, file: "p.yaml", source: PIPELINE });
    await s.handle({ type: "start", id: 2 });
    await s.handle({ type: "watch", id: 3, block: "G", maxRate: 25 });
    f.advance(1);
    const data = f.sent.filter((m): m is DataMessage => m.type === "data");
    const events = data.reduce((n, d) => n + d.t.length, 0);
    // 100 Hz decimated to at most 25 events per second: every 4th event.
    expect(events).toBeGreaterThanOrEqual(24);
    expect(events).toBeLessThanOrEqual(26);
    expect(data[0]).toMatchObject({ block: "G", port: "out", rows: 1, cols: 2 });
    expect(data[0]!.v[0]).toBe(2);
    expect(data[0]!.v.length).toBe(data[0]!.t.length * 2);
    await s.handle({ type: "unwatch", id: 4, block: "G" });
    const before = f.sent.length;
    f.advance(0.5);
    expect(f.sent.slice(before).some((m) => m.type === "data")).toBe(false);

    await s.handle({ type: "setParam", id: 5, block: "C", param: "Scale", value: "x" });
    expect(replies(f.sent).at(-1)).toMatchObject({ id: 5, ok: false });
    expect((replies(f.sent).at(-1) as { message: string }).message).toMatch(
      /invalid value for 'Scale'/,
    );
    await s.handle({ type: "setParam", id: 6, block: "C", param: "Scale", value: 3 });
    expect(replies(f.sent).at(-1)).toMatchObject({ id: 6, ok: true });
    await s.handle({ type: "invoke", id: 7, block: "G", action: "unsubscribe", arg: "C" });
    expect(replies(f.sent).at(-1)).toMatchObject({
      id: 7,
      ok: true,
      message: "G unsubscribed from C",
    });
  });

  test("a bad pipeline replies with positioned diagnostics; bad messages are refused with a reason", async () => {
    const f = fakePlatform();
    const s = new EngineSession(testCatalog, f.platform);
    await s.handle({
      type: "load",
      id: 1,
      file: "bad.yaml",
      source: "T: { Type: Tock, DesiredRate: 1 }\n",
    });
    const r = replies(f.sent)[0] as {
      ok: boolean;
      diagnostics: { line: number; suggestion?: string }[];
    };
    expect(r.ok).toBe(false);
    expect(r.diagnostics[0]).toMatchObject({ line: 1, suggestion: "Tick" });
    await s.handle({ type: "start", id: 2 });
    expect(replies(f.sent).at(-1)).toMatchObject({
      id: 2,
      ok: false,
      message: "no pipeline is loaded",
    });
    await s.handle({ type: "launch", id: 3 });
    expect(replies(f.sent).at(-1)).toMatchObject({ id: 3, ok: false });
    expect((replies(f.sent).at(-1) as { message: string }).message).toMatch(/^invalid message/);
    await s.handle(null);
    expect(replies(f.sent).at(-1)).toMatchObject({ id: -1, ok: false });
  });

  test("catalog: every type once (no aliases) with its metadata, the params schema and the ports", async () => {
    const f = fakePlatform();
    const s = new EngineSession(testCatalog, f.platform);
    await s.handle({ type: "catalog", id: 1 });
    const r = replies(f.sent)[0]!;
    expect(r).toMatchObject({ type: "reply", id: 1, ok: true });
    const types = (r as Extract<EngineMessage, { type: "reply" }>).catalog!.types;
    const names = types.map((t) => t.type);
    expect(new Set(names).size).toBe(names.length);
    const tick = types.find((t) => t.type === "Tick")!;
    expect(tick).toMatchObject({
      category: "Testing",
      summary: "test timer",
      timer: true,
      requiresRate: true,
      inputs: { min: 0, max: 0 },
    });
    const counter = types.find((t) => t.type === "Counter")!;
    expect(Object.keys((counter.paramsSchema as { properties: object }).properties)).toEqual([
      "Channels",
      "Scale",
    ]);
    expect(counter.live).toEqual(["Scale"]);
    expect(counter.outputs).toEqual(["out"]);
    // Any number of inputs: null (JSON has no Infinity).
    expect(types.find((t) => t.type === "Drain")!.inputs.max).toBeNull();
    // Works without a pipeline, and again (cached).
    await s.handle({ type: "catalog", id: 2 });
    expect(replies(f.sent)[1]).toMatchObject({ id: 2, ok: true });
  });
});

/** A frame of `n` events of `cols` channels: times from `t0` at `rate`, values event·100 + col. */
function frameOf(n: number, cols: number, first: number, rate: number, rows = 1): Frame {
  const f = new Frame({ rows, cols }, n);
  f.n = n;
  for (let i = 0; i < n; i++) {
    f.t[i] = 1000 + (first + i) / rate;
    for (let k = 0; k < rows * cols; k++) f.v[i * rows * cols + k] = (first + i) * 100 + k;
  }
  return f;
}

describe("Watch (panel data on the hot path)", () => {
  test("keeps every n-th event across frames of any size, the phase carried over", () => {
    const w = new Watch("B", "out", 1, 2, 1000, 100);
    expect(w.every).toBe(10);
    let first = 0;
    for (const n of [3, 1, 7, 10, 25, 4, 2, 48]) {
      w.add(frameOf(n, 2, first, 1000));
      first += n;
    }
    const m = w.take()!;
    const idx = [...m.t].map((t) => Math.round((t - 1000) * 1000));
    expect(idx).toEqual([0, 10, 20, 30, 40, 50, 60, 70, 80, 90]);
    expect([...m.v.subarray(0, 4)]).toEqual([0, 1, 1000, 1001]);
    expect(m.skipped).toBe(first - 10);
    expect(w.take()).toBeNull();
  });

  test("an output slower than maxRate goes whole; one flush carries at most its capacity, the newest", () => {
    const w = new Watch("B", "out", 2, 3, 50, 100);
    expect(w.every).toBe(1);
    const cap = w.capacity;
    expect(cap).toBe(Math.ceil(100 * 0.25) + 8);
    let first = 0;
    // More than the rings hold before a flush: the oldest make room, counted as skipped.
    while (first < cap + 13) {
      w.add(frameOf(4, 3, first, 50, 2));
      first += 4;
    }
    expect(w.held).toBe(cap);
    const m = w.take()!;
    expect(m).toMatchObject({ rows: 2, cols: 3, skipped: first - cap });
    expect(m.t.length).toBe(cap);
    expect(m.v.length).toBe(cap * 6);
    // In time order, ending with the newest event, values intact across the ring's wrap.
    for (let e = 0; e < cap; e++) {
      const ev = first - cap + e;
      expect(Math.round((m.t[e]! - 1000) * 50)).toBe(ev);
      expect(m.v[e * 6]).toBe(ev * 100);
      expect(m.v[e * 6 + 5]).toBe(ev * 100 + 5);
    }
    // The next flush starts empty and the rings keep working after the wrap.
    w.add(frameOf(2, 3, first, 50, 2));
    const m2 = w.take()!;
    expect(m2.t.length).toBe(2);
    expect(m2.skipped).toBe(0);
    expect(m2.v[0]).toBe(first * 100);
  });

  test("a frame larger than the rings keeps its newest events", () => {
    const w = new Watch("B", "out", 1, 1, 0, 20);
    const cap = w.capacity;
    w.add(frameOf(cap * 3, 1, 0, 1000));
    const m = w.take()!;
    expect(m.t.length).toBe(cap);
    expect(m.v[0]).toBe(cap * 2 * 100);
    expect(m.skipped).toBe(cap * 2);
  });

  test("the rings are bounded in memory whatever the rate and the shape", () => {
    const w = new Watch("H", "out", 64, 256, 2000, 100_000);
    expect(w.capacity * w.stride).toBeLessThanOrEqual(1 << 20);
    expect(w.capacity).toBeGreaterThanOrEqual(2);
  });
});
