import { describe, expect, test } from "vitest";
import type { BlockTypeInfo, CatalogInfo } from "../../engine/protocol";
import { completeAt } from "./completion";
import { readBlocks } from "./model";

const type = (t: Partial<BlockTypeInfo> & { type: string }): BlockTypeInfo => ({
  aliases: [],
  category: "Testing",
  summary: "",
  help: "",
  paramsSchema: { type: "object", properties: {} },
  inputs: { min: 1, max: 1, labels: [] },
  outputs: ["out"],
  timer: false,
  requiresRate: false,
  live: [],
  views: [],
  ...t,
});

const catalog: CatalogInfo = {
  types: [
    type({ type: "Tick", timer: true, requiresRate: true, inputs: { min: 0, max: 0, labels: [] } }),
    type({
      type: "Gain",
      aliases: ["Amp"],
      outputs: ["out", "peak"],
      paramsSchema: {
        type: "object",
        properties: { Gain: { type: "number" } },
        required: ["Gain"],
      },
    }),
    type({ type: "Drain", inputs: { min: 1, max: null, labels: [] } }),
  ],
};

describe("editor model", () => {
  test("reads blocks with inputs, params, rate, path and layout, in file order", () => {
    const r = readBlocks(
      "# c\nT: { Type: Tick, DesiredRate: 100, Layout: { X: 1, Y: 2 } }\n" +
        "G:\n  Type: Gain\n  Inputs: [T]\n  Params: { Gain: 2 }\n  Path: logs\n" +
        "D: { Type: Drain, Inputs: [-G.peak, T] }\n",
    );
    expect(r.errors).toEqual([]);
    expect(r.blocks.map((b) => b.name)).toEqual(["T", "G", "D"]);
    expect(r.blocks[0]).toMatchObject({ desiredRate: 100, layout: { x: 1, y: 2 }, line: 2 });
    expect(r.blocks[1]).toMatchObject({ params: { Gain: 2 }, path: "logs", line: 3 });
    expect(r.blocks[2]!.inputs[0]).toEqual({
      source: "G.peak",
      block: "G",
      port: "peak",
      subscribed: false,
    });
  });

  test("the settings entry Pipeline: { … } is not a block; a block named Pipeline is", () => {
    const settings = "T: { Type: Tick }\nPipeline:\n  Layout:\n    Groups: []\n";
    expect(readBlocks(settings).blocks.map((b) => b.name)).toEqual(["T"]);
    const block = "T: { Type: Tick }\nPipeline: { Type: Drain, Inputs: [T] }\n";
    expect(readBlocks(block).blocks.map((b) => b.name)).toEqual(["T", "Pipeline"]);
  });

  test("YAML errors are positioned; an empty text has no blocks", () => {
    expect(readBlocks("").blocks).toEqual([]);
    const r = readBlocks("T: { Type: Tick\n");
    expect(r.errors.length).toBeGreaterThan(0);
    expect(r.errors[0]!.line).toBeGreaterThan(0);
  });
});

describe("text view completion", () => {
  const at = (text: string) => completeAt(text.replace("|", ""), text.indexOf("|"), catalog);
  test("types after Type:, params in Params (flow and block style), inputs, keys", () => {
    expect(at("T: { Type: Ti| }")).toMatchObject({ from: 11 });
    expect(at("T: { Type: Ti| }")!.options.map((o) => o.label)).toEqual(["Tick", "Gain", "Drain"]);
    expect(at("G: { Type: Gain, Params: { G| } }")!.options.map((o) => o.label)).toEqual(["Gain"]);
    const block = "T: { Type: Tick }\nG:\n  Type: Gain\n  Params:\n    |";
    expect(at(block)!.options.map((o) => o.label)).toEqual(["Gain"]);
    expect(
      at("T: { Type: Tick }\nG: { Type: Gain, Inputs: [|] }")!.options.map((o) => o.label),
    ).toEqual(["T"]);
    expect(at("G:\n  Type: Gain\n  |")!.options.map((o) => o.label)).toContain("DesiredRate");
    expect(at("# just a comment|")).toBeNull();
  });
});
