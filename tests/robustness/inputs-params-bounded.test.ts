/**
 * Issue 14, item 12 (params): a 50 MB `Numerator` took 4.4 GB. The loader bounds what a file holds
 * (LOAD_LIMITS), and no block schema accepts a list without a maximum any more: every array in
 * every block's params (as its JSON Schema shows them) has `maxItems`, and the record params (named
 * gestures, ports) refuse more keys than MAX_ITEMS (labels: MAX_LABELS, 1000, before). A list over its bound is refused when
 * the file loads, with an error naming the bound.
 */
import { describe, expect, test } from "vitest";
import { z } from "zod";
import { catalog } from "../../app/blocks/catalog";
import { MAX_COEFFICIENTS, MAX_ITEMS } from "../../app/blocks/shared/limits";
import { catalogTypes } from "../../app/engine/catalog";
import { formatDiagnostic } from "../../app/engine/diagnostics";
import { loadPipeline } from "../../app/engine/pipeline/loader";

/** JSON-pointer-ish paths of every array in `schema` without `maxItems`. */
function unbounded(schema: unknown, path = ""): string[] {
  if (typeof schema !== "object" || schema === null) return [];
  const s = schema as Record<string, unknown>;
  const found: string[] = [];
  if (s.type === "array" && typeof s.maxItems !== "number" && !Array.isArray(s.prefixItems)) {
    found.push(path || "/");
  }
  for (const [k, v] of Object.entries(s)) {
    if (Array.isArray(v)) v.forEach((x, i) => found.push(...unbounded(x, `${path}/${k}/${i}`)));
    else if (typeof v === "object") found.push(...unbounded(v, `${path}/${k}`));
  }
  return found;
}

describe("list params are bounded", () => {
  test("every array of every block's params has a maximum", () => {
    const missing: string[] = [];
    for (const def of catalogTypes(catalog)) {
      const schema = z.toJSONSchema(def.params, { io: "input", unrepresentable: "any" });
      for (const p of unbounded(schema)) missing.push(`${def.type}${p}`);
    }
    expect(missing).toEqual([]);
  });

  test("a Filter with more coefficients than the bound is refused when the file loads", () => {
    const taps = Array.from({ length: MAX_COEFFICIENTS + 1 }, () => 0.001).join(", ");
    const src = [
      "Timer: { Type: ScheduledTimer, DesiredRate: 100 }",
      "Emg: { Type: EmgSimulator, Inputs: [Timer] }",
      `Fir: { Type: Filter, Inputs: [Emg], Params: { Numerator: [${taps}] } }`,
      "",
    ].join("\n");
    const r = loadPipeline(src, "p.yaml", catalog);
    expect(r.ok).toBe(false);
    const errors = r.diagnostics.filter((d) => d.severity === "error").map(formatDiagnostic);
    expect(errors).toHaveLength(1);
    expect(errors[0]).toMatch(/Numerator/);
    expect(errors[0]).toMatch(new RegExp(`${MAX_COEFFICIENTS}`));
  });

  test("record params refuse more keys than MAX_ITEMS (EmgSimulator Gestures, Splitter Parts; Labels had MAX_LABELS)", () => {
    const emg = catalog.get("EmgSimulator")!;
    const g = (n: number) =>
      emg.params.safeParse({
        Channels: 1,
        Gesture: "g0",
        Gestures: Object.fromEntries(Array.from({ length: n }, (_, i) => [`g${i}`, [0.5]])),
      });
    expect(g(MAX_ITEMS).error?.issues).toBeUndefined();
    const over = g(MAX_ITEMS + 1);
    expect(over.success).toBe(false);
    expect(JSON.stringify(over.error?.issues)).toMatch(`at most ${MAX_ITEMS} gestures`);
    const split = catalog.get("Splitter")!;
    const parts = (n: number) =>
      split.params.safeParse({
        Parts: Object.fromEntries(Array.from({ length: n }, (_, i) => [`p${i}`, [0]])),
      });
    expect(parts(MAX_ITEMS).error?.issues).toBeUndefined();
    expect(JSON.stringify(parts(MAX_ITEMS + 1).error?.issues)).toMatch(
      `at most ${MAX_ITEMS} ports`,
    );
  });
});
