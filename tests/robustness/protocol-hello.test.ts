/**
 * Issue 14, item 14: a `hello` in a protocol version the engine does not speak (or with no usable
 * version) is answered with the engine's `hello` naming the versions it supports and what is
 * wrong, both by an engine session (the browser's worker) and by the hub of `mosaic serve` and
 * the desktop app; such a client gets nothing else until it says a hello that works.
 */
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { VirtualClock } from "../../app/engine/clock";
import { PROTOCOL_VERSION, type EngineMessage } from "../../app/engine/protocol";
import { EngineSession } from "../../app/engine/session";
import { SessionHub } from "../../app/host/session-hub";
import { requireBuild, ROOT } from "../integration/helpers";

const BAD_HELLOS: unknown[] = [
  { type: "hello", version: 2 },
  { type: "hello", version: 0 },
  { type: "hello", version: "1" },
  { type: "hello" },
  { type: "hello", version: 1.5 },
];

function session(): { s: EngineSession; got: EngineMessage[] } {
  const got: EngineMessage[] = [];
  const s = new EngineSession(catalog, {
    engine: "test",
    sharedMemory: false,
    clock: () => new VirtualClock(0),
    resources: () => ({
      resolve: (p) => p,
      readText: () => Promise.reject(new Error("no files")),
      writeText: () => Promise.reject(new Error("no files")),
    }),
    startLoop: () => ({ stop() {}, wake() {} }),
    post: (m) => void got.push(m),
  });
  return { s, got };
}

describe("hello with a version the engine does not speak", () => {
  test("an engine session answers with the versions it supports", async () => {
    for (const raw of BAD_HELLOS) {
      const { s, got } = session();
      await s.handle(raw);
      expect(got, JSON.stringify(raw)).toHaveLength(1);
      const hello = got[0] as Extract<EngineMessage, { type: "hello" }>;
      expect(hello).toMatchObject({ type: "hello", version: PROTOCOL_VERSION, versions: [1] });
      expect(hello.error).toMatch(/^this engine speaks protocol version 1/);
    }
    const { s, got } = session();
    await s.handle({ type: "hello", version: 1 });
    expect(got).toEqual([
      {
        type: "hello",
        version: 1,
        versions: [1],
        engine: "test",
        sharedMemory: false,
      },
    ]);
  });

  describe("the hub of mosaic serve and the desktop app", () => {
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

    test("answers with the versions it supports, and sends nothing else", async () => {
      for (const raw of BAD_HELLOS) {
        const got: EngineMessage[] = [];
        const c = hub.connect({ send: (m) => void got.push(m) });
        c.receive(raw);
        expect(got, JSON.stringify(raw)).toHaveLength(1);
        expect(got[0]).toMatchObject({
          type: "hello",
          version: PROTOCOL_VERSION,
          versions: [1],
          engine: "node host",
        });
        expect((got[0] as { error?: string }).error).toMatch(
          /^this engine speaks protocol version 1/,
        );
        // Not greeted: no broadcasts.
        await hub.request({ type: "stop" });
        expect(got).toHaveLength(1);
        // A hello that works afterwards is answered as usual.
        c.receive({ type: "hello", version: 1 });
        expect(got.slice(1).map((m) => m.type)).toEqual(["hello", "state"]);
        c.close();
      }
    });
  });
});
