/**
 * Issue 14, item 1: one client's large `load` does not freeze the other clients of `mosaic serve`
 * (and of the desktop app): the file is parsed and validated off the session's message loop, so
 * while it loads, another client's requests are answered at once. A large valid file still
 * loads (its blocks come back from the loader thread complete).
 */
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { EngineMessage } from "../../app/engine/protocol";
import { SessionHub } from "../../app/host/session-hub";
import { requireBuild, ROOT } from "../integration/helpers";

type Reply = Extract<EngineMessage, { type: "reply" }>;

function client(hub: SessionHub) {
  const replies = new Map<number, { reply: Reply; at: number }>();
  const conn = hub.connect({
    send: (m) => {
      if (m.type === "reply") replies.set(m.id, { reply: m, at: performance.now() });
    },
  });
  conn.receive({ type: "hello", version: 1 });
  return { conn, replies };
}

/** `n` blocks in a chain (about 80 characters each); `last` replaces the last block's type. */
function chain(n: number, last = "Function"): string {
  const lines = [
    "Timer: { Type: ScheduledTimer, DesiredRate: 100 }",
    "B0: { Type: EmgSimulator, Inputs: [Timer], Params: { Channels: 2 } }",
  ];
  for (let i = 1; i < n - 1; i++)
    lines.push(
      `B${i}: { Type: ${i === n - 2 ? last : "Function"}, Inputs: [B${i - 1}], Params: { Operation: abs } }`,
    );
  return lines.join("\n") + "\n";
}

async function until(cond: () => boolean, ms = 30_000): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 10));
  }
}

describe("a large load does not hold up the other clients", () => {
  let hub: SessionHub;
  beforeAll(async () => {
    requireBuild();
    hub = await SessionHub.start({
      pipelinesDir: join(ROOT, "pipelines"),
      workerPath: join(ROOT, "dist", "session.worker.mjs"),
      wasmPath: join(ROOT, "dist", "mosaic_core_bg.wasm"),
    });
  });
  afterAll(async () => {
    await hub?.close();
  });

  test("while A's 10 000-block file loads, B's requests are answered at once", async () => {
    const a = client(hub);
    const b = client(hub);
    // B's catalog is built once; from then on it is answered from memory.
    b.conn.receive({ type: "catalog", id: 1 });
    await until(() => b.replies.has(1));

    const source = chain(10_000, "NoSuchBlock");
    const t0 = performance.now();
    a.conn.receive({ type: "load", id: 1, file: "big.yaml", source });
    const latencies: number[] = [];
    let id = 2;
    while (!a.replies.has(1)) {
      const mine = id++;
      const sent = performance.now();
      b.conn.receive({ type: "catalog", id: mine });
      await until(() => b.replies.has(mine) || a.replies.has(1));
      if (b.replies.has(mine)) latencies.push(b.replies.get(mine)!.at - sent);
      await new Promise((r) => setTimeout(r, 20));
    }
    const loadS = (a.replies.get(1)!.at - t0) / 1000;
    const r = a.replies.get(1)!.reply;
    expect(r.ok).toBe(false);
    expect(r.diagnostics?.map((d) => d.message)).toEqual([
      `block 'B${10_000 - 2}': unknown block type 'NoSuchBlock'`,
    ]);
    const worst = Math.max(...latencies) / 1000;
    const summary = `A's load ${loadS.toFixed(2)} s; B: ${latencies.length} replies meanwhile, the slowest in ${worst.toFixed(3)} s`;
    expect(latencies.length, summary).toBeGreaterThanOrEqual(3);
    expect(worst, summary).toBeLessThan(Math.max(0.25, loadS / 4));
    b.conn.close();
    a.conn.close();
  }, 60_000);

  test("a large valid file loads through the loader thread, every block in its graph", async () => {
    const a = client(hub);
    a.conn.receive({ type: "load", id: 1, file: "big.yaml", source: chain(2000) });
    await until(() => a.replies.has(1));
    const r = a.replies.get(1)!.reply;
    expect(r.diagnostics).toEqual([]);
    expect(r.ok).toBe(true);
    expect(r.graph?.blocks).toHaveLength(2000);
    expect(r.graph?.blocks.at(-1)).toMatchObject({ name: "B1998", type: "Function" });
    a.conn.close();
  }, 60_000);
});
