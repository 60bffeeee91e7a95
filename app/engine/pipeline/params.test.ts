import { isSeq, parseDocument, type YAMLMap } from "yaml";
import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock, type AnyBlockDefinition } from "../block";
import { formatDiagnostic } from "../diagnostics";
import { testCatalog } from "../test-blocks";
import { Collector } from "./collector";
import { objectKeys, paramsText, readParams } from "./params";
import { lineCounterOf } from "./parse";
import { positionalArgs } from "./positional";

function params(type: string | AnyBlockDefinition, src: string, args?: string[]) {
  const doc = parseDocument(src);
  const node = (doc.get("B", true) as YAMLMap).get("Params", true);
  const c = new Collector("p.yaml", lineCounterOf(src));
  const r = readParams(c, {
    block: "B",
    def: typeof type === "string" ? testCatalog.get(type)! : type,
    doc,
    node,
    pos: { line: 1, col: 9 },
    args: args ?? (isSeq(node) ? positionalArgs(node) : undefined),
  });
  return { r, diagnostics: c.list.map(formatDiagnostic) };
}

describe("params stage", () => {
  test("named params: validated, defaults applied, output ports resolved", () => {
    const { r, diagnostics } = params("Counter", "B: { Params: { Channels: 3 } }\n");
    expect(diagnostics).toEqual([]);
    expect(r).toEqual({
      ok: true,
      params: { Channels: 3, Scale: 1 },
      converted: undefined,
      outputs: ["out"],
    });
    expect(params("Halves", "B: {}\n").r.outputs).toEqual(["a", "b"]);
  });

  test("positional params: converted, then validated; the conversion is returned", () => {
    const { r, diagnostics } = params("Gain", "B: { Params: [ gain:2, 1;2 ] }\n");
    expect(diagnostics).toEqual([]);
    expect(r.converted).toEqual({ Gain: 2, Offsets: [1, 2] });
    expect(r.params).toEqual({ Gain: 2, Offsets: [1, 2] });
  });

  test("errors name the param, say what was expected and suggest", () => {
    expect(params("Counter", "B: { Params: { Chanels: 2 } }\n").diagnostics).toEqual([
      "p.yaml:1:16: error: block 'B' (Counter): unknown parameter 'Chanels' (expected one of Channels, Scale); did you mean 'Channels'?",
    ]);
    expect(params("Counter", "B: { Params: { Channels: many } }\n").diagnostics).toEqual([
      "p.yaml:1:26: error: block 'B' (Counter): param 'Channels' has the string \"many\" (expected number)",
    ]);
    expect(params("Gain", "B: { Params: [ gain:x ] }\n").diagnostics[0]).toMatch(
      /^p\.yaml:1:9: error: block 'B' \(Gain\): cannot convert positional Params \[gain:x\]: gain 'x' is not a number/,
    );
    expect(params("Drain", "B: { Params: [ 1 ] }\n").diagnostics[0]).toMatch(
      /Drain has no positional form/,
    );
    expect(params("Counter", "B: { Params: 3 }\n").diagnostics).toEqual([
      "p.yaml:1:9: error: block 'B' (Counter): Params is number 3 (expected a mapping with Channels, Scale, or MOSAIC's positional list)",
    ]);
  });

  test("no Params, and an empty positional list: the defaults", () => {
    expect(params("Counter", "B: {}\n").r).toEqual({
      ok: true,
      params: { Channels: 1, Scale: 1 },
      converted: undefined,
      outputs: ["out"],
    });
    expect(params("Counter", "B: { Params: null }\n").r.params).toEqual({ Channels: 1, Scale: 1 });
    const empty = params("Counter", "B: {}\n", [""]);
    expect(empty.diagnostics).toEqual([]);
    expect(empty.r.converted).toEqual({ Channels: 1, Scale: 1 });
  });

  test("errors after converting the positional form are at Params, and say so", () => {
    const { r, diagnostics } = params("Counter", "B: { Params: [ 0, 2 ] }\n");
    expect(r).toEqual({ ok: false, params: undefined, converted: undefined, outputs: ["out"] });
    expect(diagnostics).toEqual([
      "p.yaml:1:9: error: block 'B' (Counter): param 'Channels' is too small (number 0) (after converting the positional Params) (expected at least 1)",
    ]);
  });

  test("every issue is reported, each at its own param; Params itself when the path is empty", () => {
    expect(
      params("Counter", "B: { Params: { Channels: 0, Scale: x, Chanels: 1 } }\n").diagnostics,
    ).toEqual([
      "p.yaml:1:26: error: block 'B' (Counter): param 'Channels' is too small (number 0) (expected at least 1)",
      "p.yaml:1:36: error: block 'B' (Counter): param 'Scale' has the string \"x\" (expected number)",
      "p.yaml:1:39: error: block 'B' (Counter): unknown parameter 'Chanels' (expected one of Channels, Scale); did you mean 'Channels'?",
    ]);
    const whole = defineBlock({
      ...(testCatalog.get("Counter") as AnyBlockDefinition),
      params: z.strictObject({ A: z.number().default(1) }).refine(() => false, "never valid"),
    }) as AnyBlockDefinition;
    expect(params(whole, "B: { Params: { A: 2 } }\n").diagnostics).toEqual([
      "p.yaml:1:14: error: block 'B' (Counter): Params never valid",
    ]);
  });

  test("output ports that cannot be resolved: an error, the conversion still returned", () => {
    const def = defineBlock({
      ...(testCatalog.get("Counter") as AnyBlockDefinition),
      outputs: () => {
        throw new Error("no ports for these params");
      },
    }) as AnyBlockDefinition;
    const { r, diagnostics } = params(def, "B: { Params: [ 2 ] }\n");
    expect(r).toEqual({
      ok: false,
      params: undefined,
      converted: { Channels: 2, Scale: 1 },
      outputs: ["out"],
    });
    expect(diagnostics).toEqual([
      "p.yaml:1:9: error: block 'B' (Counter): no ports for these params",
    ]);
  });

  test("helpers", () => {
    expect(objectKeys(testCatalog.get("Counter")!.params)).toEqual(["Channels", "Scale"]);
    expect(paramsText({ Max: Infinity, Min: -Infinity })).toBe('{"Max":.inf,"Min":-.inf}');
  });
});
