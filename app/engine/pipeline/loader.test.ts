import { describe, expect, test } from "vitest";
import { formatDiagnostic } from "../diagnostics";
import { testCatalog } from "../test-blocks";
import { loadPipeline } from "./loader";

const load = (src: string) => loadPipeline(src, "p.yaml", testCatalog);
const errors = (src: string) => load(src).diagnostics.filter((d) => d.severity === "error");

describe("loader: valid files", () => {
  test("builds the spec with inputs, rates, params defaults and placement", () => {
    const r = load(`
# comment
T: { Type: Tick, DesiredRate: 100 }
C: { Type: Counter, Inputs: [T], Params: { Channels: 3 } }
G: { Type: Gain, Inputs: [C, -T], Params: { Gain: 2 }, Path: logs/, Worker: heavy, Queue: { Policy: latest, Capacity: 4 }, Layout: { X: 1, Y: 2 } }
`);
    expect(r.diagnostics).toEqual([]);
    expect(r.ok).toBe(true);
    const g = r.spec!.byName.get("G")!;
    expect(g.inputs.map((i) => [i.block, i.port, i.subscribed])).toEqual([
      ["C", "out", true],
      ["T", "out", false],
    ]);
    expect(g.worker).toBe("heavy");
    expect(g.queue).toEqual({ policy: "latest", capacity: 4 });
    expect(g.layout).toEqual({ x: 1, y: 2 });
    expect(g.path).toBe("logs/");
    expect(r.spec!.byName.get("C")!.params).toEqual({ Channels: 3, Scale: 1 });
    expect(r.spec!.byName.get("T")!.desiredRate).toBe(100);
  });

  test("named output ports are referenced as Block.port", () => {
    const r = load(`
T: { Type: Tick, DesiredRate: 10 }
C: { Type: Counter, Inputs: [T], Params: { Channels: 4 } }
H: { Type: Halves, Inputs: [C] }
D: { Type: Drain, Inputs: [H.b, H] }
`);
    expect(r.diagnostics).toEqual([]);
    expect(r.spec!.byName.get("D")!.inputs.map((i) => i.port)).toEqual(["b", "a"]);
  });

  test("legacy positional Params are converted with one warning per block", () => {
    const r = load(`
T: { Type: Tick, DesiredRate: 10 }
C: { Type: Counter, Inputs: [T], Params: [ 3, 0.5 ] }
G: { Type: Gain, Inputs: [C], Params: [ gain:2, 1;2;3 ] }
`);
    expect(r.ok).toBe(true);
    const warnings = r.diagnostics.filter((d) => d.severity === "warning");
    expect(warnings.map((w) => w.block)).toEqual(["C", "G"]);
    expect(warnings[1]!.line).toBe(4);
    expect(r.spec!.byName.get("G")!.params).toEqual({ Gain: 2, Offsets: [1, 2, 3] });
    expect(r.spec!.byName.get("G")!.legacy).toBe(true);
  });
});

describe("loader: batching settings", () => {
  test("Pipeline: { BatchingMs } sets the pipeline's interval; a block's own BatchingMs overrides it", () => {
    const r = load(`
Pipeline: { BatchingMs: 5 }
T: { Type: Tick, DesiredRate: 100, BatchingMs: 0 }
C: { Type: Counter, Inputs: [T] }
`);
    expect(r.diagnostics).toEqual([]);
    expect(r.spec!.settings.batchingMs).toBe(5);
    expect(r.spec!.byName.get("T")!.batchingMs).toBe(0);
    expect(r.spec!.byName.get("C")!.batchingMs).toBeUndefined();
    expect(r.spec!.blocks.map((b) => b.name)).toEqual(["T", "C"]);
  });

  test("a block named Pipeline (with a Type) is still a block", () => {
    const r = load(
      `Pipeline: { Type: Tick, DesiredRate: 10 }\nC: { Type: Counter, Inputs: [Pipeline] }\n`,
    );
    expect(r.ok).toBe(true);
    expect(r.spec!.settings.batchingMs).toBeUndefined();
    expect(r.spec!.byName.get("Pipeline")!.type).toBe("Tick");
  });

  test("bad values and unknown settings are positioned errors", () => {
    const e1 = errors(`Pipeline: { BatchingMs: -1 }\nT: { Type: Tick, DesiredRate: 10 }\n`);
    expect(e1.map(formatDiagnostic)).toEqual([
      "p.yaml:1:25: error: Pipeline: BatchingMs has number -1 (expected milliseconds from 0 (wake up for every tick) to 1000, e.g. \`BatchingMs: 2\`)",
    ]);
    const e2 = errors(`Pipeline: { Batching: 2 }\nT: { Type: Tick, DesiredRate: 10 }\n`);
    expect(e2).toHaveLength(1);
    expect(e2[0]!.message).toBe("Pipeline: unknown setting 'Batching'");
    expect(e2[0]!.suggestion).toBe("BatchingMs");
    const e3 = errors(`T: { Type: Tick, DesiredRate: 10, BatchingMs: fast }\n`);
    expect(e3).toHaveLength(1);
    expect(e3[0]!.block).toBe("T");
    expect(e3[0]!.col).toBe(47);
  });
});

describe("loader: each invalid file gives one clear, positioned message", () => {
  test("unknown type with a near-miss name", () => {
    const e = errors(`T: { Type: Tick, DesiredRate: 10 }\nC: { Type: Countr, Inputs: [T] }\n`);
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({
      line: 2,
      col: 12,
      block: "C",
      suggestion: "Counter",
      code: "unknown-type",
    });
    expect(formatDiagnostic(e[0]!)).toBe(
      "p.yaml:2:12: error: block 'C': unknown block type 'Countr'; did you mean 'Counter'?",
    );
  });

  test("missing input block", () => {
    const e = errors(
      `Timer: { Type: Tick, DesiredRate: 10 }\nC: { Type: Counter, Inputs: [Timr] }\n`,
    );
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({ line: 2, col: 30, code: "missing-input", suggestion: "Timer" });
  });

  test("wrong param type", () => {
    const e = errors(
      `T: { Type: Tick, DesiredRate: 10 }\nC:\n  Type: Counter\n  Inputs: [T]\n  Params:\n    Channels: many\n`,
    );
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({ line: 6, col: 15, param: "Channels", expected: "number" });
    expect(e[0]!.message).toContain(`param 'Channels' has the string "many"`);
  });

  test("bad YAML indentation", () => {
    const e = errors(`T:\n  Type: Tick\n   DesiredRate: 10\n`);
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({ code: "yaml-syntax", line: 3, col: 4 });
    expect(e[0]!.message).toMatch(/^bad indentation/);
    const under = errors(`T:\n  Type: Tick\n DesiredRate: 10\n`);
    expect(under).toHaveLength(1);
    expect(under[0]).toMatchObject({ code: "yaml-syntax", line: 3, col: 1 });
  });

  test("a duplicate key", () => {
    const e = errors(`T: { Type: Tick, DesiredRate: 10 }\nT: { Type: Tick, DesiredRate: 20 }\n`);
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({ code: "duplicate-key", line: 2, col: 1 });
  });

  test("unknown param with suggestion, positioned at the key", () => {
    const e = errors(
      `T: { Type: Tick, DesiredRate: 10 }\nC: { Type: Counter, Inputs: [T], Params: { Chanels: 2 } }\n`,
    );
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({ line: 2, col: 44, suggestion: "Channels" });
  });

  test("unknown block key with suggestion", () => {
    const e = errors(`T: { Type: Tick, DesiredRate: 10 }\nC: { Type: Counter, Input: [T] }\n`);
    expect(e.map((d) => d.suggestion)).toContain("Inputs");
  });

  test("timer without DesiredRate", () => {
    const e = errors(`T: { Type: Tick }\n`);
    expect(e).toHaveLength(1);
    expect(e[0]!.message).toContain("needs a DesiredRate");
  });

  test("wrong number of inputs", () => {
    const e = errors(`T: { Type: Tick, DesiredRate: 10 }\nC: { Type: Counter }\n`);
    expect(e).toHaveLength(1);
    expect(e[0]).toMatchObject({ code: "input-count", expected: "exactly 1 input" });
  });

  test("a missing port names the valid ones", () => {
    const e = errors(
      `T: { Type: Tick, DesiredRate: 10 }\nC: { Type: Counter, Inputs: [T] }\nH: { Type: Halves, Inputs: [C] }\nD: { Type: Drain, Inputs: [H.c] }\n`,
    );
    expect(e).toHaveLength(1);
    expect(e[0]!.expected).toBe("one of H.a, H.b");
  });

  test("legacy params on a block without a positional form", () => {
    const e = errors(
      `T: { Type: Tick, DesiredRate: 10 }\nD: { Type: Drain, Inputs: [T], Params: [ 1 ] }\n`,
    );
    expect(e).toHaveLength(1);
    expect(e[0]!.code).toBe("legacy-unsupported");
  });

  test("bad legacy params say which argument", () => {
    const e = errors(
      `T: { Type: Tick, DesiredRate: 10 }\nC: { Type: Counter, Inputs: [T] }\nG: { Type: Gain, Inputs: [C], Params: [ gain:x ] }\n`,
    );
    expect(e).toHaveLength(1);
    expect(e[0]!.message).toContain("gain 'x' is not a number");
    expect(e[0]!.line).toBe(3);
  });

  test("empty, scalar and list documents", () => {
    expect(errors("")[0]!.code).toBe("empty");
    expect(errors("hello")[0]!.code).toBe("not-a-mapping");
    expect(errors("- a\n- b\n")[0]!.code).toBe("not-a-mapping");
  });

  test("invalid block names and non-mapping blocks", () => {
    expect(errors(`a.b: { Type: Tick, DesiredRate: 1 }`)[0]!.code).toBe("bad-name");
    expect(errors(`A: 3`)[0]!.code).toBe("bad-block");
  });
});
