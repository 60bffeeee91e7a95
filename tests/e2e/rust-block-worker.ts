/**
 * Bundled for a browser Web Worker by tests/e2e/rust-block-browser.test.ts: gets the template's
 * .wasm bytes and the fixture's input, wraps the module with rustBlock (the engine's code, as the
 * browser build's engine worker runs it) and answers with the block's output, or the error.
 */
import { z } from "zod";
import { Frame, vectorShape } from "../../app/engine/frame";
import { rustBlock } from "../../app/engine/rust-block";
import { BlockHarness } from "../../app/engine/testing";

export interface WorkerRequest {
  wasm: Uint8Array;
  channels: number;
  input: number[];
  /** Events per frame. */
  split: number;
  rectify: boolean;
}

export type WorkerReply =
  { ok: true; values: number[]; frames: number } | { ok: false; message: string };

interface WorkerScope {
  onmessage: ((e: { data: WorkerRequest }) => void) | null;
  postMessage(reply: WorkerReply): void;
}

const scope = globalThis as unknown as WorkerScope;

async function run(req: WorkerRequest): Promise<WorkerReply> {
  const block = rustBlock({
    type: "Tkeo",
    category: "Features",
    summary: "Teager–Kaiser energy of every channel, one sample late.",
    help: "ψ[n] = x[n]² − x[n−1]·x[n+1] per channel.",
    params: z.strictObject({ Rectify: z.boolean().default(false).describe("Output |ψ|") }),
    wasm: req.wasm,
    wasmName: "tkeo.wasm",
  });
  const shape = vectorShape(req.channels);
  const h = await BlockHarness.create(
    block,
    { Rectify: req.rectify },
    { inputs: [{ shape, rate: 1000 }] },
  );
  const events = req.input.length / req.channels;
  let frames = 0;
  for (let k = 0; k < events; k += req.split) {
    const n = Math.min(req.split, events - k);
    const t = Array.from({ length: n }, (_, e) => (k + e) / 1000);
    const v = Array.from({ length: n }, (_, e) =>
      req.input.slice((k + e) * req.channels, (k + e + 1) * req.channels),
    );
    h.push(Frame.from(shape, t, v));
    frames++;
  }
  const out = h.out.get("out")!;
  return {
    ok: true,
    values: out.v.flat(),
    frames,
  };
}

scope.onmessage = (e) => {
  run(e.data).then(
    (reply) => scope.postMessage(reply),
    (err: unknown) =>
      scope.postMessage({ ok: false, message: err instanceof Error ? err.message : String(err) }),
  );
};
