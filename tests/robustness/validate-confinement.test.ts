/**
 * The editor's `validate` request (issue 17, defect 7) over `mosaic serve`: it instantiates the
 * blocks as a load does, so it reads files only inside the folders a client's load may read —
 * also right after the host loaded a pipeline of its own, unconfined — and it loads nothing (the
 * host's pipeline stays, no state or graph goes out).
 */
import { mkdirSync, mkdtempSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import WebSocket from "ws";
import type { EngineMessage } from "../../app/engine/protocol";
import { decodeWire, encodeWire } from "../../app/engine/protocol-wire";
import { serve, type Served } from "../../app/host/serve";
import { requireBuild, ROOT } from "../integration/helpers";

type Reply = Extract<EngineMessage, { type: "reply" }>;

const SECRET = "root:$6$SECRETSECRETSECRETSECRET:19000:0:99999:7:::";
const T = mkdtempSync(join(tmpdir(), "mosaic-validate-confine-"));
const DATA = join(T, "data");
const HOST = join(T, "host");
const OUTSIDE = join(T, "outside");
for (const d of [join(T, "pipelines"), DATA, HOST, OUTSIDE]) mkdirSync(d, { recursive: true });
writeFileSync(join(DATA, "ok.csv"), "a,b\n1,2\n3,4\n");
writeFileSync(join(OUTSIDE, "secret.csv"), `${SECRET}\n`);

const player = (file: string): string =>
  "T: { Type: ScheduledTimer, DesiredRate: 100 }\n" +
  `X: { Type: FilePlayer, Inputs: [T], Params: { File: '${file}' } }\n`;

describe("validate over the socket stays in the allowed folders", () => {
  let served: Served;
  let ws: WebSocket;
  let nextId = 1;
  const got: EngineMessage[] = [];

  const validate = async (file: string, source: string): Promise<Reply> => {
    const id = nextId++;
    ws.send(encodeWire({ type: "validate", id, file, source }));
    const end = Date.now() + 20_000;
    for (;;) {
      const r = got.find((m): m is Reply => m.type === "reply" && m.id === id);
      if (r) return r;
      if (Date.now() > end) throw new Error("no reply");
      await new Promise((done) => setTimeout(done, 10));
    }
  };

  beforeAll(async () => {
    requireBuild();
    served = await serve({
      webRoot: T,
      port: 0,
      pipelinesDir: T,
      dataDir: DATA,
      workerPath: join(ROOT, "dist", "session.worker.mjs"),
      wasmPath: join(ROOT, "dist", "mosaic_core_bg.wasm"),
    });
    // The host's own pipeline (a file named on its command line): loaded unconfined.
    const host = join(HOST, "host.yaml");
    const ok = await served.hub.request({
      type: "load",
      file: host,
      source: player(join(DATA, "ok.csv")),
    });
    expect(ok.ok).toBe(true);
    ws = new WebSocket(`ws://127.0.0.1:${served.port}/ws?token=${served.token}`, {
      origin: `http://127.0.0.1:${served.port}`,
    });
    ws.on("message", (d) => got.push(decodeWire(String(d)) as EngineMessage));
    await new Promise((r) => ws.once("open", r));
    ws.send(encodeWire({ type: "hello", version: 1 }));
  }, 60_000);
  afterAll(async () => {
    ws?.close();
    await served?.close();
  });

  test("a file outside is refused and nothing of it is shown; one inside is read", async () => {
    const outside = await validate("pipelines/p.yaml", player(join(OUTSIDE, "secret.csv")));
    expect(outside.ok).toBe(true);
    const e = (outside.diagnostics ?? []).filter((d) => d.severity === "error");
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({ block: "X", param: "File", line: 2 });
    expect(e[0]!.message).toContain("is outside the folders this pipeline may read");
    expect(JSON.stringify(outside)).not.toContain("SECRET");

    const inside = await validate("pipelines/p.yaml", player(join(DATA, "ok.csv")));
    expect(inside).toMatchObject({ ok: true, diagnostics: [] });
  });

  test("checking loads nothing: no state or graph goes out, the host's pipeline stays", async () => {
    const before = got.length;
    const r = await validate("pipelines/q.yaml", "T: { Type: ScheduledTimr }\n");
    expect(r.diagnostics?.[0]?.suggestion).toBe("ScheduledTimer");
    const after = got.slice(before);
    expect(after.filter((m) => m.type === "state" || m.type === "graph")).toEqual([]);
    expect((await served.hub.request({ type: "start" })).ok).toBe(true);
  });
});
