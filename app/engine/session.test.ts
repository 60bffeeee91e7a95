import { describe, expect, test } from "vitest";
import { VirtualClock } from "./clock";
import type { DataMessage, EngineMessage } from "./protocol";
import type { Runtime } from "./runtime/runtime";
import { runVirtual } from "./runtime/virtual";
import { EngineSession, type LoopHooks, type SessionPlatform } from "./session";
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
    expect(
      last.type === "telemetry" && last.telemetry.blocks.every((b) => b.status === "ontime"),
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
