/**
 * The session hub with a real session worker (dist/session.worker.mjs): several clients share
 * one engine, replies go to their requester, late joiners get the graph and state, panel data
 * goes to watchers only, a client that leaves does not stop the pipeline or the others' data.
 */
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import type { EngineMessage } from "../engine/protocol";
import { requireBuild, ROOT } from "../../tests/integration/helpers";
import { SessionHub, type HubConnection } from "./session-hub";

function recorder() {
  const got: EngineMessage[] = [];
  return {
    got,
    sink: { send: (m: EngineMessage) => void got.push(m) },
    of<T extends EngineMessage["type"]>(type: T) {
      return got.filter((m): m is Extract<EngineMessage, { type: T }> => m.type === type);
    },
  };
}

async function until(cond: () => boolean, ms = 5000): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 20));
  }
}

describe("SessionHub (real session worker)", () => {
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

  test("two clients share one running pipeline; a closed tab leaves the rest running", async () => {
    const a = recorder();
    const ca: HubConnection = hub.connect(a.sink);
    ca.receive({ type: "hello", version: 1 });
    expect(a.of("hello")[0]).toMatchObject({ engine: "node host", sharedMemory: true });

    // Bad input gets a reply naming the problem, to its sender only.
    ca.receive({ type: "load", id: 7 });
    await until(() => a.of("reply").length === 1);
    expect(a.of("reply")[0]).toMatchObject({ id: 7, ok: false });

    const source = readFileSync(join(ROOT, "pipelines", "demo.yaml"), "utf8");
    ca.receive({ type: "load", id: 1, file: "demo.yaml", source });
    await until(() => a.of("reply").some((r) => r.id === 1));
    const loaded = a.of("reply").find((r) => r.id === 1)!;
    expect(loaded.ok).toBe(true);
    expect(loaded.graph?.blocks.map((b) => b.name)).toContain("Emg");
    ca.receive({ type: "start", id: 2 });
    await until(() => a.of("state").some((s) => s.state === "running"));

    // A second tab joins: hello, the graph and the state at once, without reloading.
    const b = recorder();
    const cb = hub.connect(b.sink);
    cb.receive({ type: "hello", version: 1 });
    expect(b.got.map((m) => m.type)).toEqual(["hello", "graph", "state"]);
    expect(b.of("state")[0]!.state).toBe("running");

    // Both watch the simulator; both get data. Ids are each client's own.
    ca.receive({ type: "watch", id: 3, block: "Emg", maxRate: 50 });
    cb.receive({ type: "watch", id: 3, block: "Emg", maxRate: 50 });
    await until(() => a.of("data").length > 2 && b.of("data").length > 2);
    expect(a.of("reply").filter((r) => r.id === 3)).toHaveLength(1);
    expect(b.of("reply").filter((r) => r.id === 3)).toHaveLength(1);
    expect(b.of("data")[0]).toMatchObject({ block: "Emg", cols: 8 });
    expect(b.of("data")[0]!.v).toBeInstanceOf(Float64Array);

    // A closes its tab: B keeps its data and telemetry; the engine keeps running.
    ca.close();
    const before = b.of("data").length;
    const tel = b.of("telemetry").length;
    await until(() => b.of("data").length > before + 2 && b.of("telemetry").length > tel + 2);
    expect(hub.clientCount).toBe(1);
    const lastTel = b.of("telemetry").at(-1)!.telemetry;
    // Still producing (on a loaded machine it may lag; what matters is that it was not stopped).
    const emg = lastTel.blocks.find((x) => x.name === "Emg")!;
    expect(emg.status).not.toBe("idle");
    expect(emg.events).toBeGreaterThan(0);

    // B unwatches: no more data for anyone.
    cb.receive({ type: "unwatch", id: 4, block: "Emg" });
    await until(() => b.of("reply").some((r) => r.id === 4));
    await new Promise((r) => setTimeout(r, 300));
    const n = b.of("data").length;
    await new Promise((r) => setTimeout(r, 400));
    expect(b.of("data").length).toBe(n);
    cb.receive({ type: "stop", id: 5 });
    await until(() => b.of("state").some((s) => s.state === "stopped"));
    cb.close();
  }, 30_000);

  test("one client watches several outputs of a block; each goes on until it is unwatched", async () => {
    const a = recorder();
    const ca = hub.connect(a.sink);
    ca.receive({ type: "hello", version: 1 });
    const source = readFileSync(join(ROOT, "pipelines", "demo.yaml"), "utf8");
    ca.receive({ type: "load", id: 1, file: "demo.yaml", source });
    await until(() => a.of("reply").some((r) => r.id === 1));
    ca.receive({ type: "start", id: 2 });
    await until(() => a.of("state").some((s) => s.state === "running"));
    const ports = () => new Set(a.of("data").map((d) => `${d.block}.${d.port}`));
    // The participant screen watches a Stimulus's phase, cue and progress the same way.
    ca.receive({ type: "watch", id: 3, block: "Emg", port: "emg", maxRate: 50 });
    ca.receive({ type: "watch", id: 4, block: "Emg", port: "gesture", maxRate: 50 });
    await until(() => ports().has("Emg.emg") && ports().has("Emg.gesture"));
    expect(a.of("reply").filter((r) => r.id === 3 || r.id === 4)).toHaveLength(2);
    // A second tab watching the default output shares the first watch ("emg").
    const b = recorder();
    const cb = hub.connect(b.sink);
    cb.receive({ type: "hello", version: 1 });
    cb.receive({ type: "watch", id: 1, block: "Emg", maxRate: 50 });
    await until(() => b.of("data").length > 0);
    expect(new Set(b.of("data").map((d) => d.port))).toEqual(new Set(["emg"]));
    // Unwatching one output stops only that one.
    ca.receive({ type: "unwatch", id: 5, block: "Emg", port: "gesture" });
    await until(() => a.of("reply").some((r) => r.id === 5));
    await new Promise((r) => setTimeout(r, 300));
    const since = a.got.length;
    await until(() => a.got.slice(since).filter((m) => m.type === "data").length > 2);
    const later = a.got.slice(since).filter((m) => m.type === "data");
    expect(new Set(later.map((d) => (d as { port: string }).port))).toEqual(new Set(["emg"]));
    cb.close();
    ca.receive({ type: "stop", id: 6 });
    await until(() => a.of("state").some((s) => s.state === "stopped"));
    ca.close();
  }, 30_000);
});
