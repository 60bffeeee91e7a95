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
});
