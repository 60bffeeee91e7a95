import { parseDocument, type YAMLMap } from "yaml";
import { describe, expect, test } from "vitest";
import { z } from "zod";
import { defineBlock, type AnyBlockDefinition } from "../block";
import { createCatalog } from "../catalog";
import { formatDiagnostic } from "../diagnostics";
import { Collector } from "./collector";
import {
  ignoredKeysWarning,
  mappingMessage,
  MOSAIC_TYPES,
  mosaicType,
  mosaicView,
  resolvePendingRates,
  unknownTypeNote,
  type PendingRate,
} from "./mosaic";
import { lineCounterOf } from "./parse";
import type { BlockSpec } from "./spec";

const stub = (type: string, aliases?: string[]): AnyBlockDefinition =>
  defineBlock({
    type,
    ...(aliases ? { aliases } : {}),
    category: "Testing",
    summary: type,
    help: type,
    params: z.strictObject({}),
    inputs: { min: 0, max: 1 },
    create: () => ({}),
  });
const catalog = createCatalog(
  ["ScheduledTimer", "DecimatorTimer", "Function", "VectorialFunction"]
    .map((t) => stub(t))
    .concat(stub("Myo", ["MYO"])),
);

describe("the original's type names", () => {
  test("the catalog's names and aliases first, then the old names", () => {
    expect(mosaicType("Function", catalog)).toEqual({ lookup: "Function", rule: undefined });
    expect(mosaicType("MYO", catalog)).toEqual({ lookup: "MYO", rule: undefined });
    expect(mosaicType("Timer", catalog).lookup).toBe("ScheduledTimer");
    expect(mosaicType("TimerDecimator", catalog).lookup).toBe("DecimatorTimer");
    expect(mosaicType("Func_Multiplier", catalog).lookup).toBe("Function");
    expect(mosaicType("Func_Rectifier", catalog).lookup).toBe("Function");
    expect(mosaicType("vectorialFunction", catalog).lookup).toBe("VectorialFunction");
    expect(mosaicType("HannesArm", catalog).lookup).toBe("HannesGUI");
    expect(mosaicType("toString", catalog)).toEqual({ lookup: "toString", rule: undefined });
    // A block of that name in the catalog would win over the table.
    const withTimer = createCatalog([stub("Timer")]);
    expect(mosaicType("Timer", withTimer).rule).toBeUndefined();
  });

  test("old names rewrite the positional Params into the new block's form", () => {
    expect(MOSAIC_TYPES.Func_Multiplier!.args!(["5"])).toEqual(["multiply:5"]);
    expect(MOSAIC_TYPES.Func_Multiplier!.args!(["20.0"])).toEqual(["multiply:20.0"]);
    expect(() => MOSAIC_TYPES.Func_Multiplier!.args!(undefined)).toThrow(/expected the factor/);
    expect(MOSAIC_TYPES.Func_Rectifier!.args!(undefined)).toEqual(["abs:0"]);
    expect(MOSAIC_TYPES.TimerDecimator!.args!(["8"])).toEqual([]);
    expect(MOSAIC_TYPES.TimerDecimator!.rateDivisor!(["8"])).toBe(8);
    expect(() => MOSAIC_TYPES.TimerDecimator!.rateDivisor!(["2.5"])).toThrow(/not a whole number/);
    expect(() => MOSAIC_TYPES.TimerDecimator!.rateDivisor!(["0"])).toThrow(/not 1 or more/);
    expect(() => MOSAIC_TYPES.TimerDecimator!.rateDivisor!(undefined)).toThrow(/factor/);
  });

  test("what an unknown type's error adds", () => {
    expect(unknownTypeNote("HannesArm", catalog)).toBe(
      "'HannesArm' is the original MOSAIC's old name of HannesGUI, a block that is not available yet",
    );
    expect(unknownTypeNote("FBGS", catalog)).toMatch(
      /^no public source of the original MOSAIC defines 'FBGS' \(it is not a typo/,
    );
    expect(unknownTypeNote("hyperplaneFitting", catalog)).toMatch(/no public source/);
    expect(unknownTypeNote("BlenderArm", catalog)).toBe(
      "'BlenderArm' is a block of the original MOSAIC that is not available yet",
    );
    expect(unknownTypeNote("Fliter", catalog)).toBeUndefined();
  });

  test("one warning names what a block became", () => {
    const def = catalog.get("Function")!;
    expect(
      mappingMessage(
        "x5",
        "Func_Multiplier",
        def,
        MOSAIC_TYPES.Func_Multiplier,
        'Params {"Operation":"multiply","Value":5}',
      ),
    ).toBe(
      `block 'x5': 'Func_Multiplier' is the original MOSAIC's old name of Function multiply (Params: [factor]); loading it as Function with Params {"Operation":"multiply","Value":5}`,
    );
    expect(mappingMessage("arm", "MYO", catalog.get("MYO")!, undefined, undefined)).toBe(
      "block 'arm': 'MYO' is the old name of Myo; loading it as Myo",
    );
  });
});

const mapOf = (src: string) => {
  const doc = parseDocument(src);
  return { doc, map: doc.get("B", true) as YAMLMap };
};

describe("keys of older files", () => {
  test("OutputType is found per block and reported once per file", () => {
    const src = "B: { Type: Timer, OutputType: 32d, Path: '' }\n";
    const { map } = mapOf(src);
    const view = mosaicView(map);
    expect(view.ignored.map((p) => String((p.key as { value: unknown }).value))).toEqual([
      "OutputType",
    ]);
    expect(view.emptyPath).toBeDefined();
    const c = new Collector("p.yaml", lineCounterOf(src));
    ignoredKeysWarning(c, [
      { block: "B", pair: view.ignored[0]! },
      { block: "C", pair: view.ignored[0]! },
    ]);
    ignoredKeysWarning(c, []);
    expect(c.list.map(formatDiagnostic)).toEqual([
      "p.yaml:1:19: warning: OutputType (on 2 blocks: B, C) ignored: OutputType is an output-shape hint of the original's older files; our blocks take their output shape from their inputs and params",
    ]);
  });

  test("a Path other than '' is not the original's empty Path", () => {
    expect(mosaicView(mapOf("B: { Path: logs/ }\n").map).emptyPath).toBeUndefined();
    expect(mosaicView(mapOf("B: { Path: ' ' }\n").map).emptyPath).toBeUndefined();
  });
});

describe("rates from the input timer (TimerDecimator)", () => {
  const spec = (name: string, desiredRate: number | undefined, input?: string): BlockSpec =>
    ({
      name,
      type: "DecimatorTimer",
      desiredRate,
      inputs: input
        ? [{ source: input, block: input, port: "", subscribed: true, pos: { line: 1, col: 1 } }]
        : [],
    }) as unknown as BlockSpec;
  const pending = (s: BlockSpec, divisor: number): PendingRate => ({
    spec: s,
    divisor,
    at: { line: 2, col: 3 },
    warning: { message: `'${s.name}'` },
    withParams: false,
  });

  test("chains resolve in any order; the warning says the rate and where it came from", () => {
    const a = spec("a", 2000);
    const b = spec("b", undefined, "a");
    const d = spec("d", undefined, "b");
    const byName = new Map([a, b, d].map((s) => [s.name, s]));
    const c = new Collector("p.yaml", lineCounterOf(""));
    const pd = pending(d, 10);
    const pb = pending(b, 8);
    resolvePendingRates(c, [pd, pb], byName);
    expect(c.list).toEqual([]);
    expect(b.desiredRate).toBe(250);
    expect(d.desiredRate).toBe(25);
    expect(pb.warning.message).toBe("'b' with DesiredRate 250 Hz (a's 2000 Hz / 8)");
    expect(pd.warning.message).toBe("'d' with DesiredRate 25 Hz (b's 250 Hz / 10)");
  });

  test("an input without a known rate, and a cycle, are errors at the Params", () => {
    const a = spec("a", undefined);
    const b = spec("b", undefined, "a");
    const x = spec("x", undefined, "y");
    const y = spec("y", undefined, "x");
    const byName = new Map([a, b, x, y].map((s) => [s.name, s]));
    const c = new Collector("p.yaml", lineCounterOf(""));
    resolvePendingRates(c, [pending(b, 2), pending(x, 2), pending(y, 2)], byName);
    expect(c.list.map((d) => [d.code, d.block, d.line])).toEqual([
      ["missing-rate", "b", 2],
      ["missing-rate", "y", 2],
      ["missing-rate", "x", 2],
    ]);
    expect(c.list[0]!.message).toBe(
      "block 'b' (DecimatorTimer): its DesiredRate is its input's divided by 2, but input 'a' has no known rate",
    );
  });
});
