/**
 * A model file picked in a page reaches `mosaic serve`'s engine (issue 17, defect 2): the page
 * sends the file's text as the predictor's `load` argument over the WebSocket (the engine may run
 * on another machine, without the file), and the loaded model predicts bit for bit what the
 * model that saved it predicts for the same rows. A text that is no model is refused with the
 * reason. Real CLI, real socket.
 */
import type { ChildProcess } from "node:child_process";
import { readFileSync } from "node:fs";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, test } from "vitest";
import WebSocket from "ws";
import { IncrementalPredictor } from "../../app/blocks/learning/incremental-predictor";
import { vectorShape } from "../../app/engine";
import type { DataMessage, EngineMessage } from "../../app/engine/protocol";
import { decodeWire, encodeWire } from "../../app/engine/protocol-wire";
import { BlockHarness } from "../../app/engine/testing";
import { vectors } from "../support/blocks";
import { memoryResources } from "../support/fs-resources";
import { initDspForTests } from "../support/wasm";
import { requireBuild, ROOT, startCli } from "./helpers";

const FIXTURES = join(ROOT, "tests/e2e/fixtures");
let cli: ChildProcess;
let url: URL;

beforeAll(async () => {
  requireBuild();
  initDspForTests();
  cli = startCli(["serve", join(FIXTURES, "model-predict.yaml"), "--port", "0"]);
  let out = "";
  cli.stderr!.on("data", (d: Buffer) => (out += d.toString()));
  url = await new Promise<URL>((resolve, reject) => {
    const t = setTimeout(() => reject(new Error(`no URL printed: ${out}`)), 20_000);
    cli.stdout!.on("data", (d: Buffer) => {
      out += d.toString();
      const m = /MOSAIC is at (\S+)/.exec(out);
      if (m) {
        clearTimeout(t);
        resolve(new URL(m[1]!));
      }
    });
  });
}, 30_000);

afterAll(async () => {
  if (!cli || cli.exitCode !== null) return;
  cli.kill("SIGINT");
  await new Promise((r) => cli.once("exit", r));
});

async function until(cond: () => boolean, ms = 20_000): Promise<void> {
  const end = Date.now() + ms;
  while (!cond()) {
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((r) => setTimeout(r, 20));
  }
}

/** The fixture's feature rows (a, b, c) and gesture targets (fist, open). */
function rows(): { x: number[][]; y: number[][] } {
  const lines = readFileSync(join(FIXTURES, "model-rows.csv"), "utf8").trim().split("\n").slice(1);
  const all = lines.map((l) => l.split(",").map(Number));
  return { x: all.map((r) => r.slice(0, 3)), y: all.map((r) => r.slice(3)) };
}

/** A model trained here on the fixture's rows (rff), its file's text and its predictions per row. */
async function trainedHere(): Promise<{ text: string; predict: Map<string, number[]> }> {
  const files: Record<string, string> = {};
  const h = await BlockHarness.create(
    IncrementalPredictor,
    { Model: "rff", Features: 24, Gamma: 2, Lambda: 0.01 },
    {
      inputs: [
        { shape: vectorShape(3), rate: 50 },
        { shape: vectorShape(2), rate: 0 },
      ],
      resources: memoryResources(files),
    },
  );
  h.start();
  const { x, y } = rows();
  x.forEach((row, i) => {
    h.push(vectors([i / 50], [y[i]!]), 1);
    h.push(vectors([i / 50 + 0.001], [row]), 0);
  });
  h.instance.actions!.pause!.run();
  h.instance.actions!.save!.run("trained.model.json");
  await until(() => files["trained.model.json"] !== undefined);
  const before = h.output("prediction").v.length;
  x.forEach((row, i) => h.push(vectors([10 + i / 50], [row]), 0));
  const out = h.output("prediction").v.slice(before);
  const predict = new Map(x.map((row, i) => [row.join(","), out[i]!]));
  return { text: files["trained.model.json"]!, predict };
}

describe("mosaic serve: a model file's text from the page", () => {
  test("loads over the WebSocket and predicts what the saving model did, bit for bit", async () => {
    const { text, predict } = await trainedHere();
    const ws = new WebSocket(`ws://${url.host}/ws?token=${url.searchParams.get("token")}`, {
      origin: url.origin,
    });
    const got: EngineMessage[] = [];
    ws.on("message", (d) => got.push(decodeWire(String(d)) as EngineMessage));
    await new Promise((r) => ws.once("open", r));
    ws.send(encodeWire({ type: "hello", version: 1 }));
    await until(() => got.some((m) => m.type === "state" && m.state === "running"));

    const reply = (id: number) =>
      got.find((m) => m.type === "reply" && m.id === id) as
        Extract<EngineMessage, { type: "reply" }> | undefined;
    ws.send(
      encodeWire({
        type: "invoke",
        id: 1,
        block: "Predictor",
        action: "load",
        arg: { name: "notes.json", text: '{"hello": 1}' },
      }),
    );
    await until(() => reply(1) !== undefined);
    expect(reply(1)).toMatchObject({ ok: false });
    expect(reply(1)!.message).toContain("model file 'notes.json': not a MOSAIC model file");

    ws.send(
      encodeWire({
        type: "invoke",
        id: 2,
        block: "Predictor",
        action: "load",
        arg: { name: "trained.model.json", text },
      }),
    );
    await until(() => reply(2) !== undefined);
    expect(reply(2)).toMatchObject({ ok: true });
    expect(reply(2)!.message).toMatch(/^loaded trained\.model\.json: rff/);
    const loadedAt = got.length;

    // Predictions after the load (watched from then on), paired with their rows by timestamp.
    ws.send(encodeWire({ type: "watch", id: 3, block: "Features" }));
    ws.send(encodeWire({ type: "watch", id: 4, block: "Predictor", port: "prediction" }));
    const pairs = new Map<string, number[]>();
    await until(() => {
      const data = got.slice(loadedAt).filter((m): m is DataMessage => m.type === "data");
      const feats = new Map<number, string>();
      for (const m of data.filter((d) => d.block === "Features"))
        m.t.forEach((t, e) => feats.set(t, Array.from(m.v.subarray(e * 3, e * 3 + 3)).join(",")));
      for (const m of data.filter((d) => d.block === "Predictor"))
        m.t.forEach((t, e) => {
          const f = feats.get(t);
          if (f !== undefined) pairs.set(f, Array.from(m.v.subarray(e * 2, e * 2 + 2)));
        });
      return pairs.size >= 60;
    });
    expect(pairs.size).toBe(60);
    for (const [row, p] of pairs) expect([row, p]).toEqual([row, predict.get(row)]);
    // And the model learnt the gestures: some rows predict one above 0.5.
    expect([...pairs.values()].some((p) => p.some((v) => v > 0.5))).toBe(true);
    ws.close();
  }, 60_000);
});
