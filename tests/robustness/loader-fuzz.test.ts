/**
 * Fuzzes the loader with extremes of size, nesting and aliases (issue 14): many blocks, long
 * scalars, duplicate keys, lists and mappings nested from a few to tens of thousands of levels
 * (flow and block style, in Params and elsewhere), alias chains and fans (billion laughs of every
 * shape, aliases that contain themselves or name no anchor). Whatever the file: no exception,
 * an answer in bounded time, every problem a positioned diagnostic, and what loads within the
 * limits.
 */
import fc from "fast-check";
import { describe, expect, test } from "vitest";
import { catalog } from "../../app/blocks/catalog";
import { loadPipeline, LOAD_LIMITS } from "../../app/engine/pipeline/loader";

const BLOCK = "{ Type: Function, Inputs: [T], Params: { Operation: abs } }";

/** Lists or mappings nested `depth` levels, flow or block style, around a value. */
function nesting(depth: number, style: "seq" | "map" | "block", indent: number): string {
  if (style === "seq") return "[".repeat(depth) + "1" + "]".repeat(depth);
  if (style === "map") return "{ k: ".repeat(depth) + "1" + " }".repeat(depth);
  let s = "";
  for (let i = 0; i < depth; i++) s += `\n${" ".repeat(indent + i + 1)}k${i}:`;
  return s + " 1";
}

/** Anchors a0..aL, each a list of `fan` aliases to the one before. */
function aliasChain(levels: number, fan: number, indent: string): string {
  let s = `${indent}a0: &a0 [lol, lol]\n`;
  for (let i = 1; i <= levels; i++)
    s += `${indent}a${i}: &a${i} [${Array(fan)
      .fill(`*a${i - 1}`)
      .join(", ")}]\n`;
  return s;
}

const part = fc.oneof(
  // Many blocks, some of them bad, some names repeated.
  fc
    .record({ n: fc.integer({ min: 0, max: 12_000 }), dupEvery: fc.integer({ min: 0, max: 5000 }) })
    .map(({ n, dupEvery }) =>
      Array.from(
        { length: n },
        (_, i) =>
          `B${dupEvery > 0 && i % dupEvery === 0 ? 0 : i}: ${i % 97 === 5 ? "[bad]" : BLOCK}`,
      ).join("\n"),
    ),
  // Nesting in Params, in another key, or as a block.
  fc
    .record({
      depth: fc.oneof(fc.integer({ min: 0, max: 40 }), fc.constantFrom(1000, 20_000)),
      style: fc.constantFrom("seq" as const, "map" as const, "block" as const),
      where: fc.constantFrom("Params", "Layout", "block"),
    })
    .map(({ depth, style, where }) => {
      const d = style === "block" ? Math.min(depth, 2000) : depth;
      if (where === "block") return `N: ${nesting(d, style, 0)}`;
      if (style === "block")
        return `N:\n  Type: Function\n  Inputs: [T]\n  ${where}:${nesting(d, style, 2)}`;
      return `N: { Type: Function, Inputs: [T], ${where}: ${nesting(d, style, 0)} }`;
    }),
  // Alias chains: at the top, or inside a block's Params (and used there).
  fc
    .record({
      levels: fc.integer({ min: 0, max: 12 }),
      fan: fc.integer({ min: 1, max: 12 }),
      inParams: fc.boolean(),
      selfRef: fc.boolean(),
      missing: fc.boolean(),
    })
    .map(({ levels, fan, inParams, selfRef, missing }) => {
      let s = inParams
        ? `A:\n  Type: Filter\n  Inputs: [T]\n  Params:\n    Denominator: [1]\n${aliasChain(levels, fan, "    ")}    Numerator: *a${levels}\n`
        : aliasChain(levels, fan, "");
      if (selfRef) s += "S: &s [1, [2, *s]]\n";
      if (missing) s += "M: { Type: Function, Inputs: [T], Params: *nowhere }\n";
      return s;
    }),
  // Long scalars and long lines.
  fc
    .integer({ min: 0, max: 300_000 })
    .map((n) => `L: { Type: Function, Inputs: [T], Params: { Operation: ${"x".repeat(n)} } }`),
);

describe("loader under extremes of size, nesting and aliases", () => {
  test("never throws, answers in bounded time, every problem positioned", () => {
    fc.assert(
      fc.property(fc.array(part, { minLength: 1, maxLength: 3 }), (parts) => {
        const source = `T: { Type: ScheduledTimer, DesiredRate: 10 }\n${parts.join("\n")}\n`;
        const t0 = performance.now();
        const r = loadPipeline(source, "fuzz.yaml", catalog);
        const s = (performance.now() - t0) / 1000;
        expect(s, `${source.length} characters`).toBeLessThan(10);
        for (const d of r.diagnostics) {
          expect(d.file).toBe("fuzz.yaml");
          expect(d.line).toBeGreaterThanOrEqual(1);
          expect(d.col).toBeGreaterThanOrEqual(1);
          expect(d.message.length).toBeGreaterThan(0);
          expect(d.message).not.toMatch(/call stack/i);
        }
        expect(r.ok).toBe(r.diagnostics.every((d) => d.severity !== "error"));
        if (r.ok) expect(r.spec!.blocks.length).toBeLessThanOrEqual(LOAD_LIMITS.maxBlocks);
      }),
      { numRuns: 25, seed: 1414 },
    );
  }, 120_000);
});
