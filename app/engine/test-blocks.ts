/**
 * Minimal block types for the engine's own tests (the real catalog lives in app/blocks, above the
 * engine). They exercise the block API the way real blocks do.
 */
import { z } from "zod";
import { defineBlock, type AnyBlockDefinition } from "./block";
import { createCatalog } from "./catalog";
import { BlockConfigError } from "./diagnostics";
import { EMPTY_SHAPE, vectorShape } from "./frame";
import { legacyNumber, legacyPair, legacyVector } from "./pipeline/legacy";

export const TestTimer = defineBlock({
  type: "Tick",
  category: "Testing",
  summary: "test timer",
  help: "test timer",
  params: z.strictObject({}),
  legacyParams: () => ({}),
  inputs: { min: 0, max: 0 },
  timer: true,
  create(ctx) {
    const out = ctx.output(EMPTY_SHAPE);
    const t = ctx.every(ctx.desiredRate, (times, n) => {
      const f = out.frame(n);
      for (let i = 0; i < n; i++) f.t[i] = times[i]!;
      out.emit(f);
    });
    return { start: () => t.start(), stop: () => t.stop() };
  },
});

/** Counts ticks into a vector [count, ..., count] of `Channels` values. */
export const TestCounter = defineBlock({
  type: "Counter",
  category: "Testing",
  summary: "test source",
  help: "test source",
  params: z.strictObject({
    Channels: z.number().int().min(1).default(1).describe("width"),
    Scale: z.number().default(1).describe("multiplier"),
  }),
  legacyParams: (a) => ({
    Channels: legacyNumber(a[0] ?? "1", "Channels"),
    Scale: legacyNumber(a[1] ?? "1", "Scale"),
  }),
  inputs: { min: 1, max: 1 },
  live: ["Scale"],
  create(ctx, p) {
    const out = ctx.output(vectorShape(p.Channels));
    let count = 0;
    let scale = p.Scale;
    return {
      process(f) {
        const o = out.frame(f.n);
        for (let i = 0; i < f.n; i++) {
          count++;
          o.t[i] = f.t[i]!;
          for (let c = 0; c < p.Channels; c++) o.v[i * p.Channels + c] = count * scale;
        }
        out.emit(o);
      },
      reset() {
        count = 0;
      },
      setParam(name, value) {
        if (name === "Scale") scale = value as number;
      },
    };
  },
});

/** y = Gain * x; legacy `[gain:2]`. */
export const TestGain = defineBlock({
  type: "Gain",
  category: "Testing",
  summary: "test gain",
  help: "test gain",
  params: z.strictObject({
    Gain: z.number().describe("factor"),
    Offsets: z.array(z.number()).optional().describe("per-channel offsets"),
  }),
  legacyParams: (a) => {
    const { key, value } = legacyPair(a[0] ?? "");
    if (key !== "gain") throw new Error(`unknown operation '${key}'`);
    return {
      Gain: legacyNumber(value, "gain"),
      ...(a[1] ? { Offsets: legacyVector(a[1], "offsets") } : {}),
    };
  },
  inputs: { min: 1, max: 2 },
  create(ctx, p) {
    const shape = ctx.inputs[0]!.shape ?? vectorShape(1);
    if (p.Offsets && p.Offsets.length !== shape.cols) {
      throw new BlockConfigError(
        `Offsets has ${p.Offsets.length} values for ${shape.cols} channels`,
        "Offsets",
      );
    }
    const out = ctx.output(shape);
    return {
      process(f, port) {
        if (port !== 0) return;
        const o = out.frame(f.n);
        const s = f.stride;
        for (let i = 0; i < f.n; i++) {
          o.t[i] = f.t[i]!;
          for (let k = 0; k < s; k++)
            o.v[i * s + k] = f.v[i * s + k]! * p.Gain + (p.Offsets?.[k] ?? 0);
        }
        out.emit(o);
      },
    };
  },
});

/** Collects everything; no outputs. */
export const TestSink = defineBlock({
  type: "Drain",
  category: "Testing",
  summary: "test sink",
  help: "test sink",
  params: z.strictObject({}),
  inputs: { min: 1, max: Infinity },
  outputs: [],
  create() {
    return { process() {} };
  },
});

/** Two outputs: `a` (first half) and `b` (second half). */
export const TestSplit = defineBlock({
  type: "Halves",
  category: "Testing",
  summary: "test splitter",
  help: "test splitter",
  params: z.strictObject({}),
  inputs: { min: 1, max: 1 },
  outputs: ["a", "b"],
  create(ctx) {
    const w = ctx.inputs[0]!.shape?.cols ?? 2;
    const h = Math.floor(w / 2);
    const a = ctx.output(vectorShape(h), "a");
    const b = ctx.output(vectorShape(w - h), "b");
    return {
      process(f) {
        const fa = a.frame(f.n);
        const fb = b.frame(f.n);
        for (let i = 0; i < f.n; i++) {
          fa.t[i] = fb.t[i] = f.t[i]!;
          for (let k = 0; k < h; k++) fa.v[i * h + k] = f.v[i * w + k]!;
          for (let k = h; k < w; k++) fb.v[i * (w - h) + k - h] = f.v[i * w + k]!;
        }
        a.emit(fa);
        b.emit(fb);
      },
    };
  },
});

export const TEST_BLOCKS: readonly AnyBlockDefinition[] = [
  TestTimer,
  TestCounter,
  TestGain,
  TestSink,
  TestSplit,
];
export const testCatalog = createCatalog(TEST_BLOCKS);
