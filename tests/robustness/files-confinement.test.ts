/**
 * Issue 14, item 8: pipelines that clients of `mosaic serve` load over the socket read and write
 * only inside the allowed folders (the examples' folder, `--data-dir`, the folder of a pipeline
 * the host loaded itself): data files, model files, `Path` logs and Python modules elsewhere are
 * refused with a message that says where they may be, and the refusal shows nothing of the file.
 * Relative paths that climb out, absolute paths, a client-claimed pipeline folder outside and
 * symbolic links out of an allowed folder are all refused. What the host loads itself (a file
 * named on its command line) keeps the freedom of `mosaic run`.
 */
import { mkdirSync, mkdtempSync, readFileSync, symlinkSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import WebSocket from "ws";
import type { Diagnostic } from "../../app/engine/diagnostics";
import type { EngineMessage } from "../../app/engine/protocol";
import { decodeWire, encodeWire } from "../../app/engine/protocol-wire";
import { AllowedFolders, nodeResources } from "../../app/host/resources";
import { serve, type Served } from "../../app/host/serve";
import { requireBuild, ROOT } from "../integration/helpers";

type Reply = Extract<EngineMessage, { type: "reply" }>;

const SECRET = "root:$6$SECRETSECRETSECRETSECRET:19000:0:99999:7:::";
const T = mkdtempSync(join(tmpdir(), "mosaic-confine-"));
const EXAMPLES = join(T, "pipelines");
const DATA = join(T, "data");
const OUTSIDE = join(T, "outside");
for (const d of [EXAMPLES, DATA, OUTSIDE]) mkdirSync(d, { recursive: true });
writeFileSync(join(DATA, "ok.csv"), "a,b\n1,2\n3,4\n");
writeFileSync(join(OUTSIDE, "secret.csv"), `${SECRET}\ndaemon:*:19000:0:99999:7:::\n`);
writeFileSync(join(OUTSIDE, "model.json"), `${SECRET}\n`);
symlinkSync(join(OUTSIDE, "secret.csv"), join(DATA, "link.csv"));

/** A pipeline: a timer, then `block` (one line, named X). */
const pipeline = (block: string): string =>
  `T: { Type: ScheduledTimer, DesiredRate: 100 }\nX: ${block}\n`;
const player = (file: string): string =>
  pipeline(`{ Type: FilePlayer, Inputs: [T], Params: { File: '${file}' } }`);
const logged = (path: string): string =>
  pipeline(`{ Type: SinGenerator, Inputs: [T], Path: '${path}' }`);

describe("pipelines loaded over the socket stay in the allowed folders", () => {
  let served: Served;
  let ws: WebSocket;
  let nextId = 1;
  const replies = new Map<number, Reply>();

  const load = async (file: string, source: string): Promise<Reply> => {
    const id = nextId++;
    ws.send(encodeWire({ type: "load", id, file, source }));
    const end = Date.now() + 20_000;
    while (!replies.has(id)) {
      if (Date.now() > end) throw new Error("no reply");
      await new Promise((r) => setTimeout(r, 10));
    }
    return replies.get(id)!;
  };
  const errors = (r: Reply): Diagnostic[] =>
    (r.diagnostics ?? []).filter((d) => d.severity === "error");

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
    ws = new WebSocket(`ws://127.0.0.1:${served.port}/ws?token=${served.token}`, {
      origin: `http://127.0.0.1:${served.port}`,
    });
    ws.on("message", (d) => {
      const m = decodeWire(String(d)) as EngineMessage;
      if (m.type === "reply") replies.set(m.id, m);
    });
    await new Promise((r) => ws.once("open", r));
    ws.send(encodeWire({ type: "hello", version: 1 }));
  }, 60_000);
  afterAll(async () => {
    ws?.close();
    await served?.close();
  });

  test("data files: inside the data folder yes; outside, climbing out or through a link no", async () => {
    expect((await load("pipelines/p.yaml", player(join(DATA, "ok.csv")))).ok).toBe(true);
    for (const file of [
      "../outside/secret.csv",
      join(OUTSIDE, "secret.csv"),
      join(DATA, "link.csv"),
    ]) {
      const r = await load("pipelines/p.yaml", player(file));
      expect(r.ok, file).toBe(false);
      const e = errors(r);
      expect(e, file).toHaveLength(1);
      expect(e[0]).toMatchObject({ block: "X", param: "File", line: 2 });
      expect(e[0]!.message).toContain("is outside the folders this pipeline may read");
      expect(e[0]!.message).toContain("--data-dir");
      expect(JSON.stringify(r)).not.toContain("SECRET");
    }
  });

  test("model files outside are refused, and nothing of them is shown", async () => {
    for (const [type, extra] of [
      ["IncrementalPredictor", ""],
      ["BatchPredictor", ", Outputs: 1"],
    ]) {
      const r = await load(
        "pipelines/p.yaml",
        pipeline(
          `{ Type: SinGenerator, Inputs: [T] }\nY: { Type: ${type}, Inputs: [X${extra ? "" : ", X"}], Params: { File: '${join(OUTSIDE, "model.json")}'${extra} } }`,
        ),
      );
      expect(r.ok, type).toBe(false);
      expect(errors(r)[0]).toMatchObject({ block: "Y", param: "File" });
      expect(errors(r)[0]!.message).toContain("is outside the folders this pipeline may read");
      expect(JSON.stringify(r)).not.toContain("SECRET");
    }
  });

  test("Path logs: in the pipeline's folder and the data folder yes, elsewhere no", async () => {
    expect((await load("pipelines/p.yaml", logged("logs/"))).ok).toBe(true);
    expect((await load("pipelines/p.yaml", logged(join(DATA, "logs/")))).ok).toBe(true);
    for (const [file, path] of [
      ["pipelines/p.yaml", join(OUTSIDE, "logs/")],
      ["pipelines/p.yaml", "../../outside/x.txt"],
      // A client names a pipeline folder of its own choosing: its relative paths are outside.
      [join(OUTSIDE, "p.yaml"), "logs/"],
    ] as const) {
      const r = await load(file, logged(path));
      expect(r.ok, path).toBe(false);
      expect(errors(r)[0]).toMatchObject({
        code: "outside-folders",
        block: "X",
        param: "Path",
        line: 2,
      });
      expect(errors(r)[0]!.message).toContain("is outside the folders this pipeline may write");
    }
  });

  test("Python modules outside are refused", async () => {
    writeFileSync(join(OUTSIDE, "f.py"), "def f(x):\n    return x\n");
    const r = await load(
      "pipelines/p.yaml",
      pipeline(
        `{ Type: SinGenerator, Inputs: [T] }\nY: { Type: Python, Inputs: [X], Params: { Module: '${join(OUTSIDE, "f.py")}', Function: f } }`,
      ),
    );
    expect(r.ok).toBe(false);
    expect(
      errors(r)
        .map((d) => d.message)
        .join("\n"),
    ).toContain("is outside the folders");
  });

  test("a pipeline the host loads itself is free, as with mosaic run; its folder joins the allowed", async () => {
    const file = join(OUTSIDE, "mine.yaml");
    const own = await served.hub.request({
      type: "load",
      file,
      source: logged(join(OUTSIDE, "own/")),
    });
    expect(own.ok).toBe(true);
    // A client may now use that folder (Apply in the editor re-loads the same file).
    expect((await load(file, logged("logs/"))).ok).toBe(true);
  });
});

describe("AllowedFolders and nodeResources", () => {
  test("reads, writes and resolves inside; refuses outside, with the folders in the message", async () => {
    const r = nodeResources(join(DATA), new AllowedFolders([DATA]));
    expect(await r.readText("ok.csv")).toBe(readFileSync(join(DATA, "ok.csv"), "utf8"));
    await r.writeText("sub/new.json", "{}");
    expect(r.resolve("x/y.py")).toBe(join(DATA, "x/y.py"));
    await expect(r.readText("../outside/secret.csv")).rejects.toThrow(
      `${join(OUTSIDE, "secret.csv")} is outside the folders this pipeline may read (${DATA})`,
    );
    await expect(r.readText("link.csv")).rejects.toThrow(/is outside the folders/);
    await expect(r.writeText(join(OUTSIDE, "w.txt"), "x")).rejects.toThrow(/may write/);
    expect(() => r.resolve(OUTSIDE)).toThrow(/may use/);
    // Without folders: anywhere (mosaic run).
    expect(await nodeResources(DATA).readText("link.csv")).toContain("SECRET");
  });
});
