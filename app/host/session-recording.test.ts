/**
 * The Record button behind `mosaic serve` and the desktop app: a session recording asked for by a
 * client is written by the real session worker (dist/session.worker.mjs) into the data folder's
 * recordings/, confined like the client's pipeline, and every client sees its status.
 */
import { existsSync, readdirSync, readFileSync, rmSync } from "node:fs";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import { bytesSource, readXdf } from "../blocks/recording/xdf-reader";
import type { EngineMessage } from "../engine/protocol";
import { requireBuild, ROOT, tempDir } from "../../tests/integration/helpers";
import { defaultAllowedDirs, SessionHub } from "./session-hub";

function client(hub: SessionHub) {
  const got: EngineMessage[] = [];
  const conn = hub.connect({ send: (m: EngineMessage) => void got.push(m) });
  conn.receive({ type: "hello", version: 1 });
  const of = <T extends EngineMessage["type"]>(type: T) =>
    got.filter((m): m is Extract<EngineMessage, { type: T }> => m.type === type);
  const reply = (id: number) => of("reply").find((r) => r.id === id);
  return { got, conn, of, reply };
}

async function until(cond: () => boolean, ms = 15_000): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 20));
  }
}

describe("session recording through the hub (real session worker)", () => {
  let hub: SessionHub;
  const dataDir = tempDir("mosaic-data-");
  beforeAll(async () => {
    requireBuild();
    hub = await SessionHub.start({
      pipelinesDir: ROOT,
      workerPath: join(ROOT, "dist", "session.worker.mjs"),
      wasmPath: join(ROOT, "dist", "mosaic_core_bg.wasm"),
      allowedDirs: defaultAllowedDirs(ROOT, dataDir),
      dataDir,
    });
  });
  afterAll(async () => {
    await hub?.close();
    rmSync(dataDir, { recursive: true, force: true });
  });

  test("an XDF in <data>/recordings/, its status to every client, readable when stopped", async () => {
    const a = client(hub);
    const b = client(hub);
    const source = readFileSync(join(ROOT, "pipelines", "demo.yaml"), "utf8");
    a.conn.receive({ type: "load", id: 1, file: "pipelines/demo.yaml", source });
    await until(() => a.reply(1) !== undefined);
    expect(a.reply(1)!.ok).toBe(true);
    a.conn.receive({ type: "start", id: 2 });
    await until(() => a.of("state").some((s) => s.state === "running"));

    a.conn.receive({
      type: "record-start",
      id: 3,
      outputs: [{ block: "Emg" }, { block: "LowPass" }],
      format: "xdf",
    });
    await until(() => a.reply(3) !== undefined);
    expect(a.reply(3)).toMatchObject({ ok: true, message: /^recording Emg, LowPass to / });
    // The other tab sees it too, with samples counted as they are written.
    await until(() => b.of("recording").some((r) => r.recording.samples >= 200));
    expect(b.of("recording").at(-1)!.recording).toMatchObject({
      state: "recording",
      inMemory: false,
    });

    a.conn.receive({ type: "record-stop", id: 4 });
    await until(() => a.reply(4) !== undefined);
    expect(a.reply(4)).toMatchObject({ ok: true, message: /^saved .*\.xdf \(/ });
    const done = a.of("recording").at(-1)!.recording;
    expect(done.state).toBe("finished");
    expect(a.of("download")).toEqual([]);

    const folder = join(dataDir, "recordings");
    expect(done.file.startsWith(folder)).toBe(true);
    expect(readdirSync(folder)).toEqual([done.file.slice(folder.length + 1)]);
    expect(existsSync(done.file)).toBe(true);
    const xdf = readXdf(bytesSource(new Uint8Array(readFileSync(done.file))));
    expect(xdf.problem).toBe("");
    expect(xdf.streams.map((s) => s.header.name)).toEqual(["Emg", "LowPass"]);
    expect(xdf.streams.reduce((n, s) => n + s.t.length, 0)).toBe(done.samples);
    expect(xdf.streams.every((s) => s.footer !== undefined)).toBe(true);
    a.conn.receive({ type: "stop", id: 5 });
    await until(() => a.reply(5) !== undefined);
  });
});
