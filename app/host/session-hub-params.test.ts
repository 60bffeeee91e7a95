/**
 * Live params through the session hub (issue 17, defect 1), with a real session worker: a value
 * one client sets reaches every client, a client that joins later gets the engine's values with
 * the graph, and values written back become the file's for everyone.
 */
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { EngineMessage, GraphInfo } from "../engine/protocol";
import { requireBuild, ROOT } from "../../tests/integration/helpers";
import { SessionHub } from "./session-hub";

function client(hub: SessionHub) {
  const got: EngineMessage[] = [];
  const conn = hub.connect({ send: (m) => void got.push(m) });
  conn.receive({ type: "hello", version: 1 });
  const of = <T extends EngineMessage["type"]>(type: T) =>
    got.filter((m): m is Extract<EngineMessage, { type: T }> => m.type === type);
  return { got, conn, of };
}

async function until(cond: () => boolean, ms = 10_000): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 20));
  }
}

const amplification = (g: GraphInfo | undefined) =>
  g?.blocks.find((b) => b.name === "Amplification");

describe("SessionHub: live params", () => {
  let hub: SessionHub;
  beforeAll(async () => {
    requireBuild();
    hub = await SessionHub.start({
      pipelinesDir: ROOT,
      workerPath: join(ROOT, "dist", "session.worker.mjs"),
      wasmPath: join(ROOT, "dist", "mosaic_core_bg.wasm"),
    });
  });
  afterAll(async () => {
    await hub?.close();
  });

  test("every client gets a set value; a late client gets it with the graph; write-back too", async () => {
    const source = readFileSync(join(ROOT, "pipelines", "demo.yaml"), "utf8");
    const a = client(hub);
    const b = client(hub);
    a.conn.receive({ type: "load", id: 1, file: "pipelines/demo.yaml", source });
    await until(() => a.of("reply").some((r) => r.id === 1) && b.of("graph").length > 0);
    expect(amplification(b.of("graph")[0]!.graph)).toMatchObject({
      params: { Value: 5 },
      fileParams: { Value: 5 },
    });

    a.conn.receive({ type: "setParam", id: 2, block: "Amplification", param: "Value", value: 100 });
    await until(() => b.of("params").length > 0 && a.of("reply").some((r) => r.id === 2));
    expect(b.of("params")[0]).toMatchObject({
      blocks: [{ name: "Amplification", params: { Value: 100 }, fileParams: { Value: 5 } }],
    });

    const c = client(hub);
    await until(() => c.of("graph").length > 0);
    const late = c.of("graph")[0]!.graph;
    expect(amplification(late)).toMatchObject({ params: { Value: 100 }, fileParams: { Value: 5 } });
    expect(late.source).toBe(source);

    const written = source.replace("Value: 5 }", "Value: 100 }");
    b.conn.receive({
      type: "params-written",
      id: 3,
      source: written,
      values: [{ block: "Amplification", param: "Value", value: 100 }],
    });
    await until(() => a.of("params").some((m) => m.source !== undefined));
    expect(a.of("params").at(-1)).toMatchObject({
      source: written,
      blocks: [{ name: "Amplification", fileParams: { Value: 100 } }],
    });
    const d = client(hub);
    await until(() => d.of("graph").length > 0);
    expect(d.of("graph")[0]!.graph.source).toBe(written);
    expect(amplification(d.of("graph")[0]!.graph)!.fileParams).toMatchObject({ Value: 100 });
    for (const x of [a, b, c, d]) x.conn.close();
  }, 30_000);
});
