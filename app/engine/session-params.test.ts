/**
 * The engine's live params are the truth every client shows (issue 17, defect 1): the graph
 * carries the current values, the file's values and the text; a `setParam` is announced to every
 * client; `params-written` makes written values the file's.
 */
import { describe, expect, test } from "vitest";
import { VirtualClock } from "./clock";
import type { EngineMessage, GraphInfo } from "./protocol";
import { EngineSession, type SessionPlatform } from "./session";
import { testCatalog } from "./test-blocks";
import { noResources } from "./testing";

const PIPELINE = `# counts
T: { Type: Tick, DesiredRate: 100 }
C: { Type: Counter, Inputs: [T], Params: { Channels: 2, Scale: 3 } } # three
`;

function session() {
  const sent: EngineMessage[] = [];
  const platform: SessionPlatform = {
    engine: "test",
    sharedMemory: false,
    clock: () => new VirtualClock(0),
    resources: () => noResources,
    startLoop: () => ({ stop: () => {}, wake: () => {} }),
    post: (m) => sent.push(m),
  };
  return { s: new EngineSession(testCatalog, platform), sent };
}

const graphOf = (sent: EngineMessage[], id: number): GraphInfo =>
  (sent.find((m) => m.type === "reply" && m.id === id) as { graph: GraphInfo }).graph;
const reply = (sent: EngineMessage[], id: number) =>
  sent.find((m) => m.type === "reply" && m.id === id) as { ok: boolean; message?: string };
const paramsMessages = (sent: EngineMessage[]) =>
  sent.filter((m): m is Extract<EngineMessage, { type: "params" }> => m.type === "params");

describe("EngineSession: live params", () => {
  test("the graph has the text and each block's live values as in the file", async () => {
    const { s, sent } = session();
    await s.handle({ type: "load", id: 1, file: "p.yaml", source: PIPELINE });
    const g = graphOf(sent, 1);
    expect(g.source).toBe(PIPELINE);
    const c = g.blocks.find((b) => b.name === "C")!;
    expect(c.params).toMatchObject({ Channels: 2, Scale: 3 });
    // Only live params are compared with the file.
    expect(c.fileParams).toEqual({ Scale: 3 });
    expect(g.blocks.find((b) => b.name === "T")!.fileParams).toEqual({});
  });

  test("setParam announces the engine's values before its reply; the next graph has them", async () => {
    const { s, sent } = session();
    await s.handle({ type: "load", id: 1, file: "p.yaml", source: PIPELINE });
    await s.handle({ type: "start", id: 2 });
    const before = sent.length;
    await s.handle({ type: "setParam", id: 3, block: "C", param: "Scale", value: 10 });
    const after = sent.slice(before);
    expect(after.map((m) => m.type)).toEqual(["params", "reply"]);
    expect(after[0]).toEqual({
      type: "params",
      blocks: [{ name: "C", params: { Channels: 2, Scale: 10 }, fileParams: { Scale: 3 } }],
    });
    // A refused value announces nothing.
    await s.handle({ type: "setParam", id: 4, block: "C", param: "Scale", value: "x" });
    expect(reply(sent, 4).ok).toBe(false);
    expect(paramsMessages(sent)).toHaveLength(1);
  });

  test("params-written: the written values become the file's, with the new text", async () => {
    const { s, sent } = session();
    await s.handle({ type: "load", id: 1, file: "p.yaml", source: PIPELINE });
    await s.handle({ type: "setParam", id: 2, block: "C", param: "Scale", value: 10 });
    const text = PIPELINE.replace("Scale: 3", "Scale: 10");
    await s.handle({
      type: "params-written",
      id: 3,
      source: text,
      values: [{ block: "C", param: "Scale", value: 10 }],
    });
    expect(reply(sent, 3)).toMatchObject({ ok: true, message: "1 live value written to p.yaml" });
    expect(paramsMessages(sent).at(-1)).toEqual({
      type: "params",
      blocks: [{ name: "C", params: { Channels: 2, Scale: 10 }, fileParams: { Scale: 10 } }],
      source: text,
    });
    // A param that is not live, or a value the block refuses: nothing changes.
    for (const [id, values] of [
      [4, [{ block: "C", param: "Channels", value: 4 }]],
      [
        5,
        [
          { block: "C", param: "Scale", value: 20 },
          { block: "C", param: "Scale", value: "x" },
        ],
      ],
      [6, [{ block: "Nope", param: "Scale", value: 1 }]],
    ] as const) {
      await s.handle({ type: "params-written", id, source: "x", values: [...values] });
      expect(reply(sent, id).ok).toBe(false);
    }
    expect(paramsMessages(sent)).toHaveLength(2);
    // A later load starts from its own file.
    await s.handle({ type: "load", id: 7, file: "p.yaml", source: PIPELINE });
    expect(graphOf(sent, 7).blocks.find((b) => b.name === "C")!.fileParams).toEqual({ Scale: 3 });
  });
});
