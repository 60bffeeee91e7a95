/**
 * Fuzzes the WebSocket protocol of `mosaic serve` (issue 14): random JSON, messages of every
 * type with random fields and ids, values nested deeper than the stack, long strings, binary
 * frames and text that is not JSON. Whatever comes in, the host stays up, every message that
 * carries a numeric id gets exactly one reply with that id, a `hello` is answered with a `hello`,
 * and a well-formed request afterwards is answered as usual.
 */
import fc from "fast-check";
import { mkdtempSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import WebSocket from "ws";
import type { EngineMessage } from "../../app/engine/protocol";
import { decodeWire, encodeWire } from "../../app/engine/protocol-wire";
import { serve, type Served } from "../../app/host/serve";
import { requireBuild, ROOT } from "../integration/helpers";

const TYPES = [
  "hello",
  "load",
  "validate",
  "record-start",
  "record-stop",
  "params-written",
  "start",
  "stop",
  "catalog",
  "setParam",
  "invoke",
  "watch",
  "unwatch",
  "data",
  "",
  "__proto__",
] as const;

/** A value nested `depth` levels (arrays or objects). */
function nested(depth: number, object: boolean): string {
  return object
    ? '{"a":'.repeat(depth) + "1" + "}".repeat(depth)
    : "[".repeat(depth) + "]".repeat(depth);
}

const field = fc.oneof(
  fc.jsonValue({ maxDepth: 3 }),
  fc.string({ maxLength: 40 }),
  fc.constantFrom("Emg", "Timer", "LowPass", "out", "pipelines/demo.yaml", "reset", "subscribe"),
  fc.constantFrom(-1, 0, 1e308, -0, 3.5, Number.MAX_SAFE_INTEGER + 2),
  fc.constant(null),
);

/** An object shaped like a UI message, with random fields (the id is filled in when sent). */
const message = fc.record(
  {
    type: fc.constantFrom(...TYPES),
    id: fc.oneof(fc.constant("ID"), field),
    version: fc.oneof(fc.constant(1), field),
    file: field,
    source: fc.oneof(
      field,
      fc.constantFrom(
        "T: { Type: ScheduledTimer, DesiredRate: 10 }\n",
        "a: &a [1, *a]\n",
        "T: " + "[".repeat(500) + "]".repeat(500) + "\n",
      ),
    ),
    block: field,
    param: field,
    value: field,
    action: field,
    arg: field,
    port: field,
    maxRate: field,
    extra: field,
    values: fc.oneof(
      field,
      fc.array(fc.record({ block: field, param: field, value: field }), { maxLength: 3 }),
    ),
  },
  { requiredKeys: ["type"] },
);

/** One frame: a message, random JSON, or something that is not a message at all. */
const frame = fc.oneof(
  { weight: 6, arbitrary: message.map((m) => ({ kind: "message" as const, m })) },
  {
    weight: 2,
    arbitrary: fc.jsonValue({ maxDepth: 4 }).map((v) => ({ kind: "json" as const, v })),
  },
  {
    weight: 1,
    arbitrary: fc
      .tuple(fc.constantFrom(100, 5_000, 100_000), fc.boolean(), fc.constantFrom(...TYPES))
      .map(([depth, object, type]) => ({ kind: "deep" as const, depth, object, type })),
  },
  {
    weight: 1,
    arbitrary: fc.string({ maxLength: 200 }).map((text) => ({ kind: "text" as const, text })),
  },
  {
    weight: 1,
    arbitrary: fc
      .uint8Array({ maxLength: 64 })
      .map((bytes) => ({ kind: "binary" as const, bytes })),
  },
);

describe("the WebSocket protocol under random input", () => {
  let served: Served;
  let ws: WebSocket;
  const got: EngineMessage[] = [];

  beforeAll(async () => {
    requireBuild();
    served = await serve({
      webRoot: mkdtempSync(join(tmpdir(), "mosaic-web-")),
      port: 0,
      pipelinesDir: ROOT,
      workerPath: join(ROOT, "dist", "session.worker.mjs"),
      wasmPath: join(ROOT, "dist", "mosaic_core_bg.wasm"),
    });
    ws = new WebSocket(`ws://127.0.0.1:${served.port}/ws?token=${served.token}`, {
      origin: `http://127.0.0.1:${served.port}`,
      maxPayload: 256 * 1024 * 1024,
    });
    ws.on("message", (d) => got.push(decodeWire(String(d)) as EngineMessage));
    await new Promise((r) => ws.once("open", r));
    ws.send(encodeWire({ type: "hello", version: 1 }));
  }, 60_000);
  afterAll(async () => {
    ws?.close();
    await served?.close();
  });

  const repliesTo = (id: number) =>
    got.filter(
      (m): m is Extract<EngineMessage, { type: "reply" }> => m.type === "reply" && m.id === id,
    );

  async function until(cond: () => boolean, ms = 10_000): Promise<void> {
    const end = Date.now() + ms;
    while (!cond()) {
      if (Date.now() > end) throw new Error("timed out");
      await new Promise((r) => setTimeout(r, 10));
    }
  }

  test("every numbered message gets one reply; hellos get a hello; the host stays up", async () => {
    let nextId = 1000;
    await fc.assert(
      fc.asyncProperty(fc.array(frame, { minLength: 1, maxLength: 12 }), async (frames) => {
        const expectReply: number[] = [];
        let hellos = 0;
        const hellosBefore = got.filter((m) => m.type === "hello").length;
        for (const f of frames) {
          if (f.kind === "message") {
            const m: Record<string, unknown> = { ...f.m };
            if (m.type === "hello") {
              // Only its version is at stake here (other fields make it a malformed message).
              for (const k of Object.keys(m)) if (k !== "type" && k !== "version") delete m[k];
              hellos++;
            } else if (m.id === "ID") {
              m.id = nextId++;
              expectReply.push(m.id as number);
            } else if (typeof m.id === "number") delete m.id; // ids stay unique
            ws.send(encodeWire(m));
          } else if (f.kind === "json") {
            ws.send(JSON.stringify(f.v));
          } else if (f.kind === "deep") {
            const id = nextId++;
            expectReply.push(id);
            const value = nested(f.depth, f.object);
            // setParam's value, invoke's arg and the like accept anything: here it is deep.
            ws.send(
              `{"type":"${f.type === "hello" ? "setParam" : f.type}","id":${id},"block":"B","param":"P","action":"a","value":${value},"arg":${value}}`,
            );
          } else if (f.kind === "text") {
            ws.send(f.text);
          } else {
            ws.send(Buffer.from(f.bytes), { binary: true });
          }
        }
        await until(() => expectReply.every((id) => repliesTo(id).length > 0));
        for (const id of expectReply) expect(repliesTo(id), `id ${id}`).toHaveLength(1);
        await until(() => got.filter((m) => m.type === "hello").length >= hellosBefore + hellos);
      }),
      { numRuns: 40, seed: 14, endOnFailure: true },
    );
    // Still serving: a well-formed request is answered, the connection is open.
    const id = nextId++;
    ws.send(encodeWire({ type: "catalog", id }));
    await until(() => repliesTo(id).length === 1);
    expect(repliesTo(id)[0]!.ok).toBe(true);
    expect(ws.readyState).toBe(WebSocket.OPEN);
    expect(served.hub.clientCount).toBe(1);
  }, 120_000);
});
