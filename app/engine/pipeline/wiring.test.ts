import { describe, expect, test } from "vitest";
import { formatDiagnostic } from "../diagnostics";
import { testCatalog } from "../test-blocks";
import { Collector } from "./collector";
import { lineCounterOf } from "./parse";
import type { BlockSpec, InputRef } from "./spec";
import { checkWiring } from "./wiring";

const input = (ref: string, col: number): InputRef => {
  const dot = ref.indexOf(".");
  return {
    source: ref,
    block: dot < 0 ? ref : ref.slice(0, dot),
    port: dot < 0 ? "" : ref.slice(dot + 1),
    subscribed: true,
    pos: { line: 1, col },
  };
};
const block = (name: string, type: string, inputs: InputRef[], outputs = ["out"]): BlockSpec =>
  ({
    name,
    type,
    def: testCatalog.get(type)!,
    inputs,
    outputs,
    inputsPos: { line: 9, col: 9 },
  }) as unknown as BlockSpec;

function wire(blocks: BlockSpec[], names = blocks.map((b) => b.name)) {
  const c = new Collector("p.yaml", lineCounterOf(""));
  checkWiring(c, blocks, new Map(blocks.map((b) => [b.name, b])), names);
  return c.list.map(formatDiagnostic);
}

describe("wiring stage", () => {
  test("resolves default ports", () => {
    const h = block("H", "Halves", [], ["a", "b"]);
    const d = block("D", "Drain", [input("H", 1), input("H.b", 5)]);
    expect(wire([h, d])).toEqual([
      "p.yaml:9:9: error: block 'H' (Halves) has 0 inputs (expected exactly 1 input)",
    ]);
    expect(d.inputs.map((i) => i.port)).toEqual(["a", "b"]);
  });

  test("the noun agrees with the number it ends on", () => {
    expect(wire([block("D", "Drain", [])])).toEqual([
      "p.yaml:9:9: error: block 'D' (Drain) has 0 inputs (expected at least 1 input)",
    ]);
    const t = block("T", "Tick", []);
    const g = block("G", "Gain", [input("T", 3), input("T", 5), input("T", 7)]);
    expect(wire([t, g])).toEqual([
      "p.yaml:9:9: error: block 'G' (Gain) has 3 inputs (expected between 1 and 2 inputs)",
    ]);
  });

  test("missing blocks and ports, with suggestions; blocks with their own errors are not repeated", () => {
    const t = block("Timer", "Tick", []);
    const h = block("H", "Halves", [input("Timer", 3)], ["a", "b"]);
    expect(
      wire(
        [t, h, block("D", "Drain", [input("Timr", 7), input("H.c", 11), input("Broken", 15)])],
        ["Timer", "H", "D", "Broken"],
      ),
    ).toEqual([
      "p.yaml:1:7: error: block 'D': input 'Timr' is not a block in this pipeline; did you mean 'Timer'?",
      "p.yaml:1:11: error: block 'D': 'H' has no output 'c' (expected one of H.a, H.b); did you mean 'H.a'?",
    ]);
  });
});
