import { describe, expect, test } from "vitest";
import { formatDiagnostic } from "../diagnostics";
import { Collector } from "./collector";
import { lineCounterOf, parsePipelineYaml, parseStage } from "./parse";

const stage = (src: string) => {
  const c = new Collector("p.yaml", lineCounterOf(src));
  const r = parseStage(c, src);
  return { ...r, diagnostics: c.list };
};

describe("parse stage", () => {
  test("a file yaml reads as it is never sees the pre-pass", () => {
    const src = "A: {\n  Type: X\n}\n";
    const r = parsePipelineYaml(src);
    expect(r.fixes).toEqual([]);
    expect(r.doc.toJS()).toEqual({ A: { Type: "X" } });
  });

  test("MOSAIC's layouts parse, and node ranges index the text as written", () => {
    const src =
      "T: { Type: Trigger, Params: [\n\trest:   0;1,\n    grip: 1;0\n]}\nS: { Type: Sink }\n";
    const r = parsePipelineYaml(src);
    expect(r.fixes.map((f) => f.kind)).toEqual(["tab", "join"]);
    expect(r.doc.errors).toEqual([]);
    const s = r.doc.getIn(["S", "Type"], true) as { range: [number, number, number] };
    expect(src.slice(s.range[0], s.range[1])).toBe("Sink");
    const seq = r.doc.getIn(["T", "Params"], true) as { range: [number, number, number] };
    expect(src.slice(seq.range[0], seq.range[1])).toBe(
      src.slice(src.indexOf("["), src.indexOf("]") + 1),
    );
  });

  test("line and column come from the text as written (LF and CRLF)", () => {
    for (const eol of ["\n", "\r\n"]) {
      const src = `A: { P: [${eol}  1${eol}]}${eol}A: { P: 2 }${eol}`;
      const r = stage(src);
      expect(r.ok).toBe(false);
      expect(r.diagnostics.map(formatDiagnostic)).toEqual([
        "p.yaml:4:1: error: duplicate key: a block (or a key inside one) is defined twice; the second definition is here",
      ]);
    }
  });

  test("syntax errors: one diagnostic, where the problem is", () => {
    const over = stage("T:\n  Type: Tick\n   DesiredRate: 10\n");
    expect(over.diagnostics).toHaveLength(1);
    expect(over.diagnostics[0]).toMatchObject({ code: "yaml-syntax", line: 3, col: 4 });
    expect(over.diagnostics[0]!.message).toMatch(/^bad indentation: this line is indented further/);
    // A missing `]` before the next block is not taken for MOSAIC's layout.
    const open = stage("A: { P: [ 1, 2\nB: { P: 3 }\n");
    expect(open.diagnostics).toHaveLength(1);
    expect(open.diagnostics[0]!.code).toBe("yaml-syntax");
    expect(open.diagnostics[0]!.line).toBeGreaterThan(0);
  });

  describe("node checks (duplicate keys, aliases)", () => {
    const limits = { maxDepth: 3, maxParamsValues: 5 };
    const errors = (src: string) =>
      parsePipelineYaml(src, limits).doc.errors.map((e) => [e.code, e.pos[0], e.message]);
    const aliases = (src: string) =>
      [...parsePipelineYaml(src, limits).aliases].map(([a, n]) => [
        a.source,
        a.range?.[0],
        n.range?.[0],
      ]);

    test("every duplicate key, in each mapping, missing keys included", () => {
      const dup = "Map keys must be unique";
      expect(errors("A: 1\nB: { x: 1, x: 2, ? , ? }\nA: 3\n")).toEqual([
        ["DUPLICATE_KEY", 16, dup],
        ["DUPLICATE_KEY", 28, dup],
        ["DUPLICATE_KEY", 30, dup],
      ]);
    });

    test("each alias stands for the latest anchor of its name before it", () => {
      const src = "a: &x [1, 2]\nb: *x\nc: &x { k: v }\nd: [*x]\ne: &s 1\nf: *s\n";
      expect(errors(src)).toEqual([]);
      expect(aliases(src)).toEqual([
        ["x", 16, 6],
        ["x", 38, 25],
        ["s", 53, 48],
      ]);
    });

    test("an alias without an anchor before it is an error at the alias", () => {
      const none = (name: string, at: number) => [
        "UNRESOLVED_ALIAS",
        at,
        `alias *${name} has no anchor &${name} before it (an anchor must come before its aliases)`,
      ];
      expect(errors("a: *nope\n")).toEqual([none("nope", 3)]);
      // An anchor after the alias does not count (YAML resolves aliases backwards only).
      expect(errors("a: [1, *x]\nb: &x 2\n")).toEqual([none("x", 7)]);
    });

    test("an alias that stands for too many values, once per alias; then it counts as one", () => {
      const large = (at: number) => [
        "ALIAS_TOO_LARGE",
        at,
        "alias *y stands for 9 values; an alias may stand for at most 5 (the values one block's Params may hold)",
      ];
      expect(errors("a: &x [1, 2, 3]\nb: &y [*x, *x]\nc: [*y, *y]\n")).toEqual([
        large(35),
        large(39),
      ]);
      expect(errors("a: &x [1, 2, 3]\nb: &y [*x, *x]\nc: &z [*y]\nd: *z\n")).toEqual([large(38)]);
    });

    test("an alias nested too deep once expanded, and one inside what it stands for", () => {
      expect(errors("a: &x [[1]]\nb: [[*x]]\n")).toEqual([
        [
          "NESTING_TOO_DEEP",
          17,
          "nesting too deep: alias *x stands for lists and mappings 2 levels deep, 5 levels here; at most 3",
        ],
      ]);
      expect(errors("a: &x [1, *x]\nb: 2\nb: 3\n")).toEqual([
        ["ALIAS_CYCLE", 10, "alias *x stands for a list or mapping that contains it"],
        ["DUPLICATE_KEY", 19, "Map keys must be unique"],
      ]);
    });
  });
});
