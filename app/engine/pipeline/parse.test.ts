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
  test("parses with comments and positions", () => {
    const src = "A: {\n  Type: X # x\n}\n";
    const r = parsePipelineYaml(src);
    expect(r.doc.toJS()).toEqual({ A: { Type: "X" } });
  });

  test("line and column come from the text as written (LF and CRLF)", () => {
    for (const eol of ["\n", "\r\n"]) {
      const src = `A: { P: [${eol}  1${eol}  ]}${eol}A: { P: 2 }${eol}`;
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
    const open = stage("A: { P: [ 1, 2\nB: { P: 3 }\n");
    expect(open.diagnostics).toHaveLength(1);
    expect(open.diagnostics[0]!.code).toBe("yaml-syntax");
    expect(open.diagnostics[0]!.line).toBeGreaterThan(0);
  });
});
