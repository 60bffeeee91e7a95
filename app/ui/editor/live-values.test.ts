import { describe, expect, test } from "vitest";
import type { BlockInfo, GraphInfo } from "../../engine/protocol";
import { parseDocumentText } from "./doc";
import {
  applyLiveValues,
  changedParams,
  describeChanges,
  keptChanges,
  liveChanges,
  missingFromText,
  presentInText,
  writeLiveValues,
} from "./live-values";
import { readBlocks } from "./model";

const block = (b: Partial<BlockInfo> & { name: string }): BlockInfo => ({
  type: "Function",
  category: "Signal",
  summary: "",
  help: "",
  worker: "main",
  timer: false,
  desiredRate: 0,
  inputs: [],
  outputs: [],
  views: [],
  panel: "",
  live: [],
  params: {},
  paramsSchema: {},
  actions: [],
  ...b,
});

const DEMO = `# Demo: comments stay where they are.
Timer: { Type: ScheduledTimer, DesiredRate: 200 }

# Amplification: the paper's Table 5 chain.
Amplification: { Type: Function, Inputs: [Timer], Params: { Operation: multiply, Value: 5 } } # gain
Filter:
  Type: Filter
  Inputs: [Amplification]
  Params:
    # the coefficients
    Numerator: [0.5, 0.5]   # two taps
    Denominator: [1]
Clip: { Type: Function, Inputs: [Filter] }
Legacy: { Type: Func_Multiplier, Inputs: [Clip], Params: [3] }
`;

describe("live values against the file", () => {
  test("a live param whose engine value differs from the file's is changed; others are not", () => {
    const amp = block({
      name: "Amplification",
      live: ["Value", "Min"],
      params: { Operation: "multiply", Value: 100, Min: 0 },
      fileParams: { Value: 5, Min: 0 },
    });
    expect(changedParams(amp)).toEqual(["Value"]);
    // Arrays compare by value, not identity.
    const filt = block({
      name: "Filter",
      live: ["Numerator"],
      params: { Numerator: [0.5, 0.5] },
      fileParams: { Numerator: [0.5, 0.5] },
    });
    expect(changedParams(filt)).toEqual([]);
    // An engine that does not say what the file has: nothing is marked.
    expect(changedParams(block({ name: "X", live: ["Value"], params: { Value: 1 } }))).toEqual([]);
    const graph: GraphInfo = { file: "demo.yaml", blocks: [filt, amp] };
    expect(liveChanges(graph)).toEqual([
      { block: "Amplification", param: "Value", value: 100, file: 5 },
    ]);
  });

  test("writing back changes only the values: comments, order and style stay", () => {
    const r = writeLiveValues(DEMO, "demo.yaml", [
      { block: "Amplification", param: "Value", value: 100, file: 5 },
      { block: "Filter", param: "Numerator", value: [0.25, 0.75], file: [0.5, 0.5] },
      { block: "Clip", param: "Max", value: 2, file: undefined },
    ]);
    expect(r.skipped).toEqual([]);
    expect(r.written.map((c) => `${c.block}.${c.param}`)).toEqual([
      "Amplification.Value",
      "Filter.Numerator",
      "Clip.Max",
    ]);
    const want = DEMO.replace("Value: 5 }", "Value: 100 }")
      .replace("Numerator: [0.5, 0.5]", "Numerator: [0.25, 0.75]")
      .replace(
        "Clip: { Type: Function, Inputs: [Filter] }",
        "Clip: { Type: Function, Inputs: [Filter], Params: { Max: 2 } }",
      );
    expect(r.text).toBe(want);
    expect(r.text).toContain("# the coefficients\n    Numerator: [0.25, 0.75]   # two taps\n");
    expect(r.text).toContain("Value: 100 } } # gain\n");
  });

  test("what cannot be written is skipped with the reason; the rest is written", () => {
    const r = writeLiveValues(DEMO, "demo.yaml", [
      { block: "Legacy", param: "Value", value: 4, file: 3 },
      { block: "Gone", param: "Value", value: 1, file: 0 },
      { block: "Amplification", param: "Value", value: 7, file: 5 },
    ]);
    expect(r.written.map((c) => c.block)).toEqual(["Amplification"]);
    expect(r.skipped.map((s) => s.change.block)).toEqual(["Legacy", "Gone"]);
    expect(r.skipped[0]!.reason).toMatch(/positional/);
    expect(r.skipped[1]!.reason).toMatch(/Gone/);
    expect(r.text).toBe(DEMO.replace("Value: 5 }", "Value: 7 }"));
  });

  test("a text that does not parse is refused", () => {
    expect(() => writeLiveValues("A: { Type: [", "x.yaml", [])).toThrow();
  });

  test("describeChanges names the first few", () => {
    const c = (block: string, value: unknown) => ({ block, param: "Value", value, file: 0 });
    expect(describeChanges([c("A", 1)])).toBe("A.Value = 1");
    expect(describeChanges([c("A", 1), c("B", [1, 2]), c("C", 3), c("D", 4)], 2)).toBe(
      "A.Value = 1, B.Value = [1,2] and 2 more",
    );
  });
});

describe("live values against the editor's text", () => {
  test("the changes the text has, and those it lacks", () => {
    const { blocks } = readBlocks(DEMO.replace("Value: 5 }", "Value: 100 }"));
    const changes = [
      { block: "Amplification", param: "Value", value: 100, file: 5 },
      { block: "Filter", param: "Numerator", value: [0.5, 0.5], file: [1] },
      { block: "Filter", param: "Denominator", value: [2], file: [1] },
      { block: "Gone", param: "Value", value: 1, file: 0 },
    ];
    expect(presentInText(changes, blocks).map((c) => `${c.block}.${c.param}`)).toEqual([
      "Amplification.Value",
      "Filter.Numerator",
    ]);
    expect(missingFromText(changes, blocks).map((c) => `${c.block}.${c.param}`)).toEqual([
      "Filter.Denominator",
      "Gone.Value",
    ]);
  });

  test("applyLiveValues edits a document in place (the editor's undoable edit)", () => {
    const doc = parseDocumentText(DEMO, "demo.yaml");
    const r = applyLiveValues(doc, [
      { block: "Amplification", param: "Value", value: 100, file: 5 },
      { block: "Legacy", param: "Value", value: 4, file: 3 },
    ]);
    expect(r.written).toHaveLength(1);
    expect(r.skipped).toHaveLength(1);
    expect(doc.toString()).toBe(DEMO.replace("Value: 5 }", "Value: 100 }"));
  });
});

describe("live values across a reload of the same file", () => {
  test("kept: the block still has the live param and the file's value did not change", () => {
    const graph: GraphInfo = {
      file: "demo.yaml",
      blocks: [
        block({ name: "A", live: ["Value"], params: { Value: 5 }, fileParams: { Value: 5 } }),
        block({ name: "B", live: ["Value"], params: { Value: 9 }, fileParams: { Value: 9 } }),
        block({ name: "C", live: [], params: { Value: 1 }, fileParams: {} }),
      ],
    };
    const c = (name: string, value: unknown, file: unknown) => ({
      block: name,
      param: "Value",
      value,
      file,
    });
    expect(
      keptChanges([c("A", 100, 5), c("B", 100, 5), c("C", 2, 1), c("Gone", 1, 0)], graph),
    ).toEqual([c("A", 100, 5)]);
    expect(keptChanges([c("A", 100, 5)], undefined)).toEqual([]);
  });
});
