/**
 * Rust blocks (issue 18): the template crate (templates/rust-block/) built with cargo for
 * wasm32-unknown-unknown, loaded through `rustBlock` (app/engine/rust-block.ts) and run as a
 * block: its output equals the NumPy reference (tests/fixtures/tkeo.json from gen_tkeo.py) bit
 * for bit, does not depend on how events are split into frames, repeats after reset; a module of
 * another ABI version, or no Rust block at all, is refused with what to do; a panic in the kernel
 * is an error of its block, which goes on.
 */
import { rmSync } from "node:fs";
import { join } from "node:path";
import { afterAll, beforeAll, describe, expect, it } from "vitest";
import { z } from "zod";
import { Frame, vectorShape } from "../../app/engine/frame";
import { RUST_BLOCK_ABI_VERSION, rustBlock } from "../../app/engine/rust-block";
import { BlockHarness } from "../../app/engine/testing";
import { abiVersionEdit, buildTemplate, tkeoFixture } from "../support/rust-template";
import { tempDir } from "./helpers";

interface WasmGlobal {
  Module: { new (bytes: Uint8Array): object; imports(module: object): unknown[] };
  Instance: new (module: object, imports: object) => { exports: unknown };
}

const fixture = tkeoFixture();

function tkeoBlock(wasm: Uint8Array) {
  return rustBlock({
    type: "Tkeo",
    category: "Features",
    summary: "Teager–Kaiser energy of every channel, one sample late.",
    help: "ψ[n] = x[n]² − x[n−1]·x[n+1] per channel.",
    params: z.strictObject({
      Rectify: z.boolean().default(false).describe("Output |ψ|"),
    }),
    wasm,
    wasmName: "tkeo.wasm",
  });
}

/** The fixture's input as frames of `sizes[i % sizes.length]` events (timestamps k / 1000). */
function frames(sizes: readonly number[]): Frame[] {
  const shape = vectorShape(fixture.channels);
  const out: Frame[] = [];
  let k = 0;
  for (let i = 0; k < fixture.frames; i++) {
    const n = Math.min(sizes[i % sizes.length]!, fixture.frames - k);
    const t: number[] = [];
    const v: number[][] = [];
    for (let e = 0; e < n; e++, k++) {
      t.push(k / 1000);
      v.push(fixture.input.slice(k * fixture.channels, (k + 1) * fixture.channels));
    }
    out.push(Frame.from(shape, t, v));
  }
  return out;
}

async function harness(wasm: Uint8Array, params: unknown = {}): Promise<BlockHarness> {
  return BlockHarness.create(tkeoBlock(wasm), params, {
    inputs: [{ shape: vectorShape(fixture.channels), rate: 1000 }],
  });
}

function outputValues(h: BlockHarness): number[] {
  return h.out.get("out")!.v.flat();
}

let work: string;
let tkeoWasm: Uint8Array;

beforeAll(() => {
  work = tempDir("mosaic-rust-block-");
  tkeoWasm = buildTemplate(join(work, "tkeo"));
}, 300_000);

afterAll(() => {
  rmSync(work, { recursive: true, force: true });
});

describe("the template's Tkeo block, built with cargo and loaded through rustBlock", () => {
  it("imports nothing and speaks this MOSAIC's ABI version", () => {
    // The WebAssembly global (Node's; this program is type-checked without the DOM library).
    const wasm = (globalThis as unknown as { WebAssembly: WasmGlobal }).WebAssembly;
    const module = new wasm.Module(tkeoWasm);
    expect(wasm.Module.imports(module)).toEqual([]);
    const x = new wasm.Instance(module, {}).exports as { mosaic_abi_version(): number };
    expect(x.mosaic_abi_version()).toBe(RUST_BLOCK_ABI_VERSION);
  });

  it("equals the NumPy reference bit for bit, plain and rectified", async () => {
    for (const [params, expected] of [
      [{}, fixture.expected],
      [{ Rectify: true }, fixture.expected_rectified],
    ] as const) {
      const h = await harness(tkeoWasm, params);
      h.start();
      for (const f of frames([fixture.frames])) h.push(f);
      const got = outputValues(h);
      expect(got.length).toBe(expected.length);
      const differing = got.flatMap((v, i) => (Object.is(v, expected[i]) ? [] : [i]));
      expect(differing).toEqual([]);
      expect(h.out.get("out")!.t).toEqual(
        Array.from({ length: fixture.frames }, (_, k) => k / 1000),
      );
    }
    expect(fixture.expected.some((v) => v < 0)).toBe(true);
  });

  it("gives the same output however the events are split into frames", async () => {
    for (const sizes of [[1], [2, 5, 1], [7], [64, 3], [599, 1]]) {
      const h = await harness(tkeoWasm);
      for (const f of frames(sizes)) h.push(f);
      expect(outputValues(h)).toEqual(fixture.expected);
      expect(h.out.get("out")!.frames.length).toBeGreaterThan(1);
    }
  });

  it("repeats its output after reset, and disposes twice without error", async () => {
    const h = await harness(tkeoWasm);
    for (const f of frames([50])) h.push(f);
    const first = outputValues(h);
    h.instance.reset!();
    h.out.get("out")!.v.length = 0;
    for (const f of frames([33])) h.push(f);
    expect(outputValues(h)).toEqual(first);
    h.instance.dispose!();
    h.instance.dispose!();
  });

  it("keeps a matrix input's shape and treats its values as channels", async () => {
    const block = tkeoBlock(tkeoWasm);
    const h = await BlockHarness.create(block, {}, { inputs: [{ shape: { rows: 2, cols: 2 } }] });
    expect(h.ports[0]!.shape).toEqual({ rows: 2, cols: 2 });
    h.push(
      Frame.from(
        { rows: 2, cols: 2 },
        [0, 1, 2],
        [
          [1, 4, 4, 1],
          [3, 2, 1, 0],
          [1, 4, 4, 1],
        ],
      ),
    );
    // Value k: x0², then x1² − x0·x2 (one sample late).
    expect(h.out.get("out")!.v).toEqual([
      [0, 0, 0, 0],
      [1, 16, 16, 1],
      [3 * 3 - 1 * 1, 2 * 2 - 4 * 4, 1 * 1 - 4 * 4, 0 * 0 - 1 * 1],
    ]);
  });

  it("refuses wrong params with the schema's message and a timer input with a sentence", async () => {
    await expect(harness(tkeoWasm, { Rectify: "yes" })).rejects.toThrow(/Rectify/);
    await expect(harness(tkeoWasm, { Gain: 2 })).rejects.toThrow(/Gain/);
    await expect(
      BlockHarness.create(
        tkeoBlock(tkeoWasm),
        {},
        { inputs: [{ shape: { rows: 1, cols: 0 }, isTimer: true }] },
      ),
    ).rejects.toThrow("Tkeo processes a signal; its input in0 is a timer");
  });
});

describe("params on their way to the kernel", () => {
  const base = {
    type: "Tkeo",
    category: "Features" as const,
    summary: "Teager–Kaiser energy.",
    help: "ψ[n] = x[n]² − x[n−1]·x[n+1].",
    wasmName: "tkeo.wasm",
  };
  const inputs = { inputs: [{ shape: vectorShape(2) }] };

  it("go in kernelParams order; the kernel's Err is the block's error, in its words", async () => {
    const params = z.strictObject({
      Rectify: z.boolean().default(true).describe("Output |ψ|"),
      Gain: z.number().default(3).describe("A param this kernel does not take"),
    });
    const none = rustBlock({ ...base, params, kernelParams: [], wasm: tkeoWasm });
    const h = await BlockHarness.create(none, {}, inputs);
    h.push(
      Frame.from(
        vectorShape(2),
        [0, 1, 2],
        [
          [1, 4],
          [4, 1],
          [1, 4],
        ],
      ),
    );
    // No params reach the kernel: it does not rectify although Rectify defaults to true.
    expect(h.out.get("out")!.v[2]).toEqual([15, -15]);

    const both = rustBlock({ ...base, params, wasm: tkeoWasm });
    await expect(BlockHarness.create(both, {}, inputs)).rejects.toThrow(
      "expected 1 param (Rectify), got 2",
    );
  });

  it("must be numbers or booleans, and a transformed schema needs kernelParams", async () => {
    const text = rustBlock({
      ...base,
      params: z.strictObject({ Mode: z.string().default("fast").describe("Not a number") }),
      wasm: tkeoWasm,
    });
    await expect(BlockHarness.create(text, {}, inputs)).rejects.toThrow(
      "Tkeo: param Mode must be a number or a boolean for the Rust kernel, got string",
    );
    const transformed = z
      .strictObject({ Rectify: z.boolean().default(false).describe("Output |ψ|") })
      .transform((p) => ({ ...p }));
    expect(() => rustBlock({ ...base, params: transformed, wasm: tkeoWasm })).toThrow(
      "Tkeo: its params schema is not a z.object (a transform, a union…): say which " +
        "params the Rust kernel gets, in order, with kernelParams: [...]",
    );
    const named = rustBlock({
      ...base,
      params: transformed,
      kernelParams: ["Rectify"],
      wasm: tkeoWasm,
    });
    const h = await BlockHarness.create(named, { Rectify: true }, inputs);
    h.push(
      Frame.from(
        vectorShape(2),
        [0, 1, 2],
        [
          [1, 4],
          [4, 1],
          [1, 4],
        ],
      ),
    );
    expect(h.out.get("out")!.v[2]).toEqual([15, 15]);
  });
});

describe("modules rustBlock refuses, with what to do", () => {
  it("a module of another ABI version", () => {
    const v2 = buildTemplate(join(work, "abi2"), [abiVersionEdit(2)]);
    expect(() => tkeoBlock(v2)).toThrow(
      "tkeo.wasm speaks Rust block ABI version 2, but this MOSAIC speaks version 1 " +
        "(docs/rust-block-abi.md): update MOSAIC, or rebuild the block from this MOSAIC's template",
    );
  }, 300_000);

  it("a WebAssembly module that is no Rust block, and bytes that are no module", () => {
    const empty = new Uint8Array([0x00, 0x61, 0x73, 0x6d, 0x01, 0x00, 0x00, 0x00]);
    expect(() => tkeoBlock(empty)).toThrow(
      "tkeo.wasm is not a MOSAIC Rust block: it exports no mosaic_abi_version",
    );
    expect(() => tkeoBlock(new TextEncoder().encode("not wasm"))).toThrow(
      /^tkeo\.wasm is not a valid WebAssembly module: /,
    );
  });
});

describe("a kernel that panics", () => {
  it("in process is an error of its block, which then starts over and goes on; in new, a load error", async () => {
    const panicking = buildTemplate(join(work, "panics"), [
      {
        file: "src/tkeo.rs",
        from: "let (x1, x2) = (self.previous[c], self.before_previous[c]);",
        to: 'assert!(!x[c].is_nan(), "NaN input");\n                let (x1, x2) = (self.previous[c], self.before_previous[c]);',
      },
      {
        file: "src/tkeo.rs",
        from: "Ok(Tkeo {",
        to: 'assert!(channels != 7, "seven channels");\n        Ok(Tkeo {',
      },
    ]);
    // A panic in the kernel's new(): the block is not created, and the message says why.
    await expect(
      BlockHarness.create(tkeoBlock(panicking), {}, { inputs: [{ shape: vectorShape(7) }] }),
    ).rejects.toThrow(
      /^tkeo\.wasm trapped in mosaic_create \(a Rust panic or an out-of-bounds access: .*unreachable.*\)$/,
    );
    const h = await harness(panicking);
    const [a, b] = frames([300]);
    h.push(a!);
    const bad = Frame.from(vectorShape(3), [1], [[0, NaN, 0]]);
    expect(() => h.push(bad)).toThrow(
      /^tkeo\.wasm trapped in mosaic_process \(a Rust panic or an out-of-bounds access: .*unreachable.*\); the kernel was created anew, its history lost$/,
    );
    // After the trap the kernel starts from zeros again: its first two outputs are 0 and x0².
    h.out.get("out")!.v.length = 0;
    h.push(b!);
    const got = h.out.get("out")!.v;
    expect(got.length).toBe(300);
    expect(got[0]).toEqual([0, 0, 0]);
    expect(got[1]).toEqual(b!.toArrays().v[0]!.map((x) => x * x));
  }, 300_000);
});
